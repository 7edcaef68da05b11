//! Scans and their segmentation to a scene directory: a mesh per group
//! ([`crate::mesh`]), the OBJ with one group per surface group, the scene
//! skeleton, the segmentation PLY and a report with a verdict. This is the
//! one call behind `campanile segment` once the segmenter has run.
//!
//! The directory holds:
//!
//! - `scene.obj`: group `surface_G` for the segmentation's group G,
//!   triangles facing the scanner;
//! - `scene.ron`: a `Scene(...)` skeleton, one surface (object) per group
//!   named as the segmentation names it, each with a material of its own;
//! - `segmentation.ply`: every point coloured by its group;
//! - `mesh-report.json`: this module's [`ReconstructionReport`].
//!
//! Verdicts, per group then overall (the worst): **failed** when a group
//! with enough points gives no triangle (**poor** when it holds under
//! [`SPECK_SHARE`] of the points: a line of edge pixels), or its mesh strays farther than
//! `hausdorff_failed_m` from the truth; **poor** beyond `hausdorff_poor_m`;
//! **ok** otherwise. Groups under `min_points` are left out and counted, not
//! judged. With a truth OBJ, a group whose name is a true surface's is
//! measured both ways (the symmetric Hausdorff distance, reported), any
//! other group against the union of the true surfaces; the gate is on how
//! far the mesh strays from the truth (its accuracy), not on how far the
//! truth is from the mesh, which also counts what the scanner never saw
//! (the floor under a cabinet, the room's corners between beams).

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::cloud::Scan;
use crate::mesh::{
    Hausdorff, MeshError, MeshMethod, MeshOptions, OneSided, Reference, TriangleMesh, hausdorff, mesh_groups, one_sided,
};
use crate::obj_file::{NamedMesh, ObjError, read_obj, write_obj};
use crate::segmentation::Segmentation;
use crate::segmentation_ply::{PlyError, write_segmentation_ply};
use crate::skeleton::{SceneSkeleton, SkeletonError};

pub use crate::segment::Verdict;

/// A group that gives no triangle is poor, not failed, when it holds
/// under this share of the scans' points (a line of edge pixels).
pub const SPECK_SHARE: f64 = 0.01;

/// One group's line of the report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GroupReport {
    /// The group's index.
    pub group: u32,
    /// The group's (and its object's) name.
    pub name: String,
    /// Its OBJ group, `None` when not meshed.
    pub obj_group: Option<String>,
    /// Points in the group.
    pub points: usize,
    /// How it was meshed.
    pub method: MeshMethod,
    /// The least-squares plane's RMS residual, metres.
    pub plane_rms_m: Option<f64>,
    /// Curved unorganised groups: the height field's triangles more than
    /// 80° from the plane (over 1 %: ball pivoting instead).
    pub folded: usize,
    /// Triangles before simplification.
    pub triangles_before: usize,
    /// Triangles written.
    pub triangles_after: usize,
    /// The simplifier's error estimate, metres.
    pub simplify_error_m: f64,
    /// Area of the mesh, m².
    pub area_m2: f64,
    /// Against the true surface of the same name.
    pub hausdorff: Option<Hausdorff>,
    /// Against all true surfaces, one way (groups with no namesake).
    pub to_truth: Option<OneSided>,
    /// The verdict.
    pub verdict: Verdict,
    /// Why, when not ok, or what was done.
    pub note: String,
}

/// What [`reconstruct`] made.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ReconstructionReport {
    /// One line per group.
    pub groups: Vec<GroupReport>,
    /// Groups meshed by planar polygons (one plane or several), scan-order
    /// neighbours and height fields.
    pub planar: usize,
    /// See `planar`.
    pub scan_grid: usize,
    /// See `planar`.
    pub height_field: usize,
    /// Groups meshed by ball pivoting.
    pub ball_pivoting: usize,
    /// Groups meshed as spheres.
    pub spheres: usize,
    /// Groups left out for having too few points.
    pub skipped: usize,
    /// Triangles before simplification, all groups.
    pub triangles_before: usize,
    /// Triangles written.
    pub triangles_after: usize,
    /// The largest symmetric Hausdorff distance to a namesake true surface.
    pub worst_hausdorff_m: Option<f64>,
    /// The worst group's verdict (ok with no group meshed is failed).
    pub verdict: Verdict,
    /// The files written.
    pub files: Vec<PathBuf>,
}

/// Why the directory could not be made.
#[derive(Debug, thiserror::Error)]
pub enum ReconstructionError {
    /// Bad options, scans or segmentation.
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// The truth OBJ could not be read.
    #[error("the truth: {0}")]
    Truth(ObjError),
    /// The OBJ could not be written.
    #[error(transparent)]
    Obj(#[from] ObjError),
    /// The skeleton could not be written.
    #[error(transparent)]
    Skeleton(#[from] SkeletonError),
    /// The PLY could not be written.
    #[error(transparent)]
    Ply(#[from] PlyError),
    /// The directory or the report could not be written.
    #[error("{}: {message}", path.display())]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
}

impl ReconstructionError {
    /// Whether the caller's input is at fault (options, scans, the
    /// segmentation, the truth file: exit 2), rather than writing the
    /// directory (exit 1).
    pub fn is_bad_input(&self) -> bool {
        matches!(self, ReconstructionError::Mesh(_) | ReconstructionError::Truth(_))
    }
}

/// Unique, non-empty object names: the segmentation's, or the OBJ group's
/// where a name is empty or taken.
fn object_names(names: &[String]) -> Vec<String> {
    let mut out: Vec<String> = Vec::with_capacity(names.len());
    for (g, name) in names.iter().enumerate() {
        let name = if name.trim().is_empty() || out.contains(name) {
            format!("surface_{g}")
        } else {
            name.clone()
        };
        out.push(name);
    }
    out
}

/// Meshes every group of `segmentation` over `scans` and writes the scene
/// directory `out` (created if needed), returning its report.
pub fn reconstruct(
    scans: &[Scan],
    segmentation: &Segmentation,
    options: &MeshOptions,
    out: &Path,
) -> Result<ReconstructionReport, ReconstructionError> {
    options.check()?;
    // The truth is read first: a bad path is found before the meshing.
    let truth = match &options.truth {
        Some(path) => Some(read_obj(path).map_err(ReconstructionError::Truth)?),
        None => None,
    };
    let meshes = mesh_groups(scans, segmentation, options)?;
    let all_truth = truth.as_ref().map(|t| {
        let mut all = TriangleMesh::default();
        t.iter().for_each(|m| all.append(&m.mesh));
        all
    });
    std::fs::create_dir_all(out).map_err(|e| ReconstructionError::Io {
        path: out.to_path_buf(),
        message: e.to_string(),
    })?;
    let total_points = scans.iter().map(Scan::len).sum::<usize>().max(1);
    let names = object_names(&segmentation.names);
    // Each group's object name, for the groups a sphere covers.
    let name_of: Vec<(u32, String)> = meshes.iter().map(|m| m.group).zip(names.iter().cloned()).collect();
    let mut groups = Vec::with_capacity(meshes.len());
    let mut written = Vec::new();
    let mut objects = Vec::new();
    for (m, name) in meshes.into_iter().zip(names) {
        let mut report = GroupReport {
            group: m.group,
            name: name.clone(),
            obj_group: None,
            points: m.points,
            method: m.method,
            plane_rms_m: m.plane_rms_m,
            folded: m.folded,
            triangles_before: m.triangles_before,
            triangles_after: m.mesh.triangles.len(),
            simplify_error_m: m.simplify_error_m,
            area_m2: m.mesh.area() + 0.0, // no "-0.00" for an empty mesh
            hausdorff: None,
            to_truth: None,
            verdict: Verdict::Ok,
            note: String::new(),
        };
        let mut judge = |verdict: Verdict, note: String| {
            report.verdict = report.verdict.max(verdict);
            if !report.note.is_empty() {
                report.note.push_str("; ");
            }
            report.note.push_str(&note);
        };
        if m.method == MeshMethod::TooFewPoints {
            judge(
                Verdict::Ok,
                format!(
                    "not meshed: {} points, fewer than min_points {}",
                    m.points, options.min_points
                ),
            );
            groups.push(report);
            continue;
        }
        if m.method == MeshMethod::PlanePieces {
            judge(
                Verdict::Ok,
                format!(
                    "{} planes, each a polygon; {} points ({:.1} % of the group's) on none of them, not meshed",
                    m.pieces,
                    m.unmeshed_points,
                    100.0 * m.unmeshed_points as f64 / m.points.max(1) as f64
                ),
            );
        }
        if let Some(ball) = &m.sphere {
            judge(
                Verdict::Ok,
                format!(
                    "a sphere of radius {:.3} m: {:.1} % of the points within {:.1} mm RMS",
                    ball.radius,
                    100.0 * ball.inliers,
                    1000.0 * ball.rms_m
                ),
            );
        }
        for slab in &m.slabs {
            judge(
                Verdict::Ok,
                format!(
                    "closed into a slab {:.1} cm thick (underside and sides added): {} points show its sides",
                    100.0 * slab.thickness_m,
                    slab.side_points
                ),
            );
        }
        if m.corners_moved > 0 {
            judge(
                Verdict::Ok,
                format!(
                    "{} outline corners closed onto the planes of the groups it meets",
                    m.corners_moved
                ),
            );
        }
        if let Some(cover) = m.covered_by {
            let name = name_of
                .iter()
                .find(|(g, _)| *g == cover)
                .map_or_else(|| cover.to_string(), |(_, n)| n.clone());
            judge(
                Verdict::Ok,
                format!("a piece of {name}'s sphere, which its mesh covers: no mesh of its own"),
            );
        } else if m.mesh.is_empty() {
            // A speck or a line of points (edge pixels a group of their own)
            // loses little; a real share of the scan lost is a failure.
            let share = m.points as f64 / total_points as f64;
            let verdict = if share < SPECK_SHARE {
                Verdict::Poor
            } else {
                Verdict::Failed
            };
            judge(
                verdict,
                format!(
                    "no triangle: its points ({:.2} % of the scans') span no area",
                    100.0 * share
                ),
            );
        }
        if let (Some(truth), Some(all)) = (&truth, &all_truth) {
            let spacing = options.hausdorff_spacing_m;
            let distance = match truth.iter().find(|t| t.group == m.name) {
                Some(t) => {
                    report.hausdorff = hausdorff(&m.mesh, Reference::Mesh(&t.mesh), spacing);
                    report
                        .hausdorff
                        .map(|h| (h.mesh_to_reference_m, "largest distance to its true surface"))
                }
                None => {
                    report.to_truth = one_sided(&m.mesh, Reference::Mesh(all), spacing);
                    report
                        .to_truth
                        .map(|d| (d.max_m, "largest distance to the true surfaces"))
                }
            };
            if let Some((d, what)) = distance {
                if d > options.hausdorff_failed_m {
                    judge(
                        Verdict::Failed,
                        format!("{what} {d:.4} m > {} m", options.hausdorff_failed_m),
                    );
                } else if d > options.hausdorff_poor_m {
                    judge(
                        Verdict::Poor,
                        format!("{what} {d:.4} m > {} m", options.hausdorff_poor_m),
                    );
                }
            }
        }
        if !m.mesh.is_empty() {
            let group = format!("surface_{}", m.group);
            report.obj_group = Some(group.clone());
            objects.push((name, vec![group.clone()]));
            written.push(NamedMesh { group, mesh: m.mesh });
        }
        groups.push(report);
    }
    let count = |method| groups.iter().filter(|g| g.method == method).count();
    let meshed = !written.is_empty();
    let mut report = ReconstructionReport {
        planar: count(MeshMethod::PlanarPolygon) + count(MeshMethod::PlanePieces),
        scan_grid: count(MeshMethod::ScanGrid),
        height_field: count(MeshMethod::HeightField),
        ball_pivoting: count(MeshMethod::BallPivoting),
        spheres: count(MeshMethod::Sphere),
        skipped: count(MeshMethod::TooFewPoints),
        triangles_before: groups.iter().map(|g| g.triangles_before).sum(),
        triangles_after: groups.iter().map(|g| g.triangles_after).sum(),
        worst_hausdorff_m: groups
            .iter()
            .filter_map(|g| g.hausdorff.map(|h| h.symmetric_m))
            .reduce(f64::max),
        verdict: groups
            .iter()
            .map(|g| g.verdict)
            .max()
            .unwrap_or(Verdict::Ok)
            .max(if meshed { Verdict::Ok } else { Verdict::Failed }),
        groups,
        files: Vec::new(),
    };
    let obj = out.join("scene.obj");
    let skeleton = out.join("scene.ron");
    let ply = out.join("segmentation.ply");
    let json = out.join("mesh-report.json");
    write_obj(
        &obj,
        &written,
        "campanile-scan: one group per surface group, triangles facing the scanner",
    )?;
    SceneSkeleton::new("scan", Path::new("scene.obj"), &objects).write(&skeleton)?;
    write_segmentation_ply(&ply, scans, segmentation)?;
    report.files = vec![obj, skeleton, ply, json.clone()];
    let text = serde_json::to_string_pretty(&report).map_err(|e| ReconstructionError::Io {
        path: json.clone(),
        message: e.to_string(),
    })?;
    std::fs::write(&json, text + "\n").map_err(|e| ReconstructionError::Io {
        path: json,
        message: e.to_string(),
    })?;
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synthetic_scan::{cabinet, room, scan_of, truth};
    use nalgebra::Vector3;

    #[test]
    fn a_box_room_with_a_cabinet_meshes_to_its_planes_within_the_noise() {
        let rects: Vec<_> = room().into_iter().chain(cabinet()).collect();
        let sigma = 0.002;
        let (scan, seg) = scan_of(&rects, Vector3::new(2.0, 1.5, 1.25), 1.5, 87.0, sigma);
        let dir = tempfile::tempdir().unwrap();
        let truth_obj = dir.path().join("truth.obj");
        write_obj(&truth_obj, &truth(&rects), "truth").unwrap();
        let options = MeshOptions {
            truth: Some(truth_obj),
            hausdorff_spacing_m: 0.05,
            ..MeshOptions::default()
        };
        let out = dir.path().join("scene");
        let report = reconstruct(&[scan], &seg, &options, &out).unwrap();
        assert_eq!(report.verdict, Verdict::Ok);
        assert_eq!(report.planar, 9);
        let group = |name: &str| report.groups.iter().find(|g| g.name == name).unwrap();
        for g in &report.groups {
            let h = g.hausdorff.unwrap();
            // Every mesh lies on its true surface within the noise (3σ).
            assert!(h.mesh_to_reference_m <= 3.0 * sigma, "{}: {h:?}", g.name);
            assert!(g.plane_rms_m.unwrap() <= 3.0 * sigma, "{}", g.name);
        }
        // Surfaces seen whole: the truth is within the band the beams never
        // reach at the room's edges (at 2.8 m, 1.5° is 7 cm, more along the
        // grazing direction); measured 8.2–8.8 cm.
        for name in ["ceiling", "wall_west", "wall_north"] {
            let h = group(name).hausdorff.unwrap();
            assert!(h.reference_to_mesh_m <= 0.1, "{name}: {h:?}");
        }
        // 96 % of the ceiling (the rest is that band).
        let ceiling = group("ceiling").area_m2;
        assert!(ceiling > 0.95 * 12.0 && ceiling < 12.0, "{ceiling}");
        // The floor behind the cabinet was never seen: the truth is far
        // from the mesh there, and that is no fault of the mesh.
        assert!(group("floor").hausdorff.unwrap().reference_to_mesh_m > 0.3);
        assert!(report.triangles_after < 300, "{}", report.triangles_after);
        assert_eq!(report.files.len(), 4);
        assert!(report.files.iter().all(|f| f.is_file()));

        // The skeleton and the OBJ read back as the solvers read them.
        let scene = campanile_config::load_scene(&out.join("scene.ron")).unwrap().value;
        assert_eq!(scene.surfaces.len(), 9);
        assert_eq!(scene.surfaces[7].name, "cabinet_west");
        assert_eq!(scene.surfaces[7].groups, vec!["surface_7".to_string()]);
        let geometry = campanile_process::scene_geometry::load_obj(&scene, &out.join("scene.obj")).unwrap();
        assert_eq!(geometry.surface_names.len(), 9);
        assert_eq!(geometry.triangles.len(), report.triangles_after);
        // Normals face the scanner: from the room's centre, every triangle
        // is seen from its front.
        let centre = Vector3::new(2.0, 1.5, 1.25);
        let obj = read_obj(&out.join("scene.obj")).unwrap();
        for m in &obj {
            for t in 0..m.mesh.triangles.len() {
                let [a, b, c] = m.mesh.corners(t);
                let facing = m.mesh.area_normal(t).dot(&(centre - (a + b + c) / 3.0));
                assert!(facing > 0.0, "{} triangle {t}", m.group);
            }
        }
    }

    #[test]
    fn a_second_scan_from_elsewhere_fills_the_first_ones_shadow() {
        // The same room scanned from its centre (organised) and from its
        // north-east (the grid dropped: an unorganised cloud, as a PLY gives).
        let rects: Vec<_> = room().into_iter().chain(cabinet()).collect();
        let (a, seg_a) = scan_of(&rects, Vector3::new(2.0, 1.5, 1.25), 1.5, 87.0, 0.002);
        let (mut b, seg_b) = scan_of(&rects, Vector3::new(3.5, 2.6, 1.6), 1.5, 87.0, 0.002);
        b.grid = None;
        let both = Segmentation {
            labels: vec![seg_a.labels[0].clone(), seg_b.labels[0].clone()],
            names: seg_a.names.clone(),
        };
        let dir = tempfile::tempdir().unwrap();
        let truth_obj = dir.path().join("truth.obj");
        write_obj(&truth_obj, &truth(&rects), "truth").unwrap();
        let options = MeshOptions {
            truth: Some(truth_obj),
            hausdorff_spacing_m: 0.05,
            ..MeshOptions::default()
        };
        let one = reconstruct(std::slice::from_ref(&a), &seg_a, &options, &dir.path().join("one")).unwrap();
        let two = reconstruct(&[a, b], &both, &options, &dir.path().join("two")).unwrap();
        let floor = |r: &ReconstructionReport| r.groups[0].clone();
        let (f1, f2) = (floor(&one), floor(&two));
        assert_eq!(f2.method, MeshMethod::PlanarPolygon);
        assert_eq!(
            f2.points,
            f1.points + seg_b.labels[0].iter().filter(|&&l| l == 0).count()
        );
        let (h1, h2) = (f1.hausdorff.unwrap(), f2.hausdorff.unwrap());
        assert!(h2.mesh_to_reference_m <= 0.006, "{h2:?}");
        // The floor the first scanner could not see behind the cabinet is
        // seen by the second: the truth's farthest point from the mesh goes
        // from 0.82 m to 0.40 m (what is left: under the cabinet and where
        // both shadows overlap), the mean distance from 5.8 to 1.4 mm, the
        // area from 10.77 to 10.93 m². (Before outlines were closed up to
        // the walls (`mesh::corners`), 10.54 to 10.79: the second scan also
        // reached more of the band along the walls that one scan misses at
        // grazing angles, which both now reach by the closing; what is left
        // is the shadow.)
        assert!(h2.reference_to_mesh_m < h1.reference_to_mesh_m - 0.3, "{h1:?} {h2:?}");
        assert!(h2.mean_m * 3.0 < h1.mean_m, "{h1:?} {h2:?}");
        assert!(f2.area_m2 > f1.area_m2 + 0.12, "{} {}", f1.area_m2, f2.area_m2);
        assert_eq!(two.verdict, Verdict::Ok);
    }

    #[test]
    fn a_missing_truth_is_bad_input_naming_the_file() {
        let rects = room();
        let (scan, seg) = scan_of(&rects, Vector3::new(2.0, 1.5, 1.25), 6.0, 84.0, 0.0);
        let dir = tempfile::tempdir().unwrap();
        let options = MeshOptions {
            truth: Some(dir.path().join("truth.obj")),
            ..MeshOptions::default()
        };
        let e = reconstruct(&[scan], &seg, &options, &dir.path().join("out")).unwrap_err();
        assert!(e.is_bad_input());
        assert!(e.to_string().starts_with("the truth: "), "{e}");
        assert!(e.to_string().contains("truth.obj"), "{e}");
    }
}

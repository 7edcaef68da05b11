//! A mesh per surface group (thesis §2.4), simplified.
//!
//! Each group of a [`Segmentation`] gets the method its points call for,
//! and says which ([`MeshMethod`]):
//!
//! - **planar** groups (the least-squares plane's RMS residual within
//!   [`MeshOptions::planar_rms_m`]), organised or not: a polygon in the
//!   plane, its outline and holes from an alpha shape, triangulated by ear
//!   clipping ([`planar_polygon`]);
//! - groups that are **spheres** within the planar tolerance: a tessellated
//!   sphere ([`sphere`]); other groups whose points lie on such a sphere
//!   (pieces of one ball) are covered by its mesh and get none of their
//!   own ([`sphere::cover_pieces`]);
//! - curved groups of **organised** scans: triangles between scan-order
//!   neighbours, refusing depth jumps ([`grid_mesh`]), one partial mesh per
//!   scan put together as the thesis does;
//! - curved groups of **unorganised** clouds: a height field over the
//!   group's plane ([`height_field`]) when it is one (at most 1 % of its
//!   triangles folded), else ball pivoting ([`ball_pivoting`]) with the
//!   scan's normals or normals estimated and turned to the scanner (no
//!   maintained Rust surface-reconstruction crate fits the workspace:
//!   `poisson_reconstruction` 0.4 needs nalgebra 0.33 and parry3d).
//!
//! Planar polygons that meet another planar group at an edge (a room's
//! corners) are closed up to it ([`corners`]). A planar top whose group
//! also holds its narrow sides (a table top) is closed into a slab, its
//! unscanned underside added ([`slab`], [`MeshOptions::close_slabs`]).
//!
//! Curved meshes are then simplified by quadric error metrics to
//! [`MeshOptions::simplify_error_m`] ([`simplification`]); the polygons are
//! already as small as their outline.
//!
//! Normals face the scanner: the pose of each scan that saw the group, or,
//! for scans without a pose, the centroid of all the scans' points (the
//! inside of a room scanned from within). `campanile igi` and the outdoor
//! solver find each triangle's visible side from their cameras; the
//! texture maps group a face's triangles by their normal, so the triangles
//! of one face must share an orientation, which facing the scanner gives.

pub mod ball_pivoting;
pub mod corners;
pub mod grid_mesh;
pub mod hausdorff;
pub mod height_field;
pub mod outline;
pub mod planar_polygon;
pub mod plane_fit;
pub mod plane_pieces;
pub mod simplification;
pub mod slab;
pub mod sphere;
pub mod triangle_mesh;

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use crate::cloud::{Scan, ScanError};
use crate::segmentation::{Segmentation, UNASSIGNED};

pub use hausdorff::{Hausdorff, OneSided, Reference, hausdorff, one_sided};
pub use triangle_mesh::TriangleMesh;

use ball_pivoting::{ball_pivoting, estimate_normals, nearest_spacing};
use grid_mesh::{GridStep, GridWindow, grid_mesh};
use height_field::height_field;
use planar_polygon::planar_polygon;
use plane_fit::PlaneFit;
use simplification::simplify;

/// Rings of a sphere's mesh ([`sphere::sphere_mesh`]): 12 rings and 24
/// segments, 528 triangles, within 0.9 % of the sphere's area.
const SPHERE_RINGS: usize = 12;

/// How groups are meshed; every figure has a documented default.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MeshOptions {
    /// A group whose least-squares plane fits its points within this RMS
    /// residual, metres, is planar (default 0.01: a centimetre-accurate
    /// scanner's noise, as the thesis's Cyra).
    pub planar_rms_m: f64,
    /// Scan-order edges longer than this many times `range × angular step`
    /// are depth jumps (default 8: surfaces up to about 83° from face-on
    /// are kept).
    pub depth_jump_factor: f64,
    /// The alpha shape keeps Delaunay triangles whose edges are at most
    /// this many times the points' spacing (default 6): a gap wider than
    /// that becomes a hole.
    pub outline_alpha_factor: f64,
    /// Outlines are simplified within this distance, metres (default 0.01),
    /// or within half the points' spacing where that is more (an outline
    /// is not known closer).
    pub outline_tolerance_m: f64,
    /// Curved meshes are simplified until the next collapse would move the
    /// surface more than this, metres (default 0.005; 0 keeps every
    /// triangle).
    pub simplify_error_m: f64,
    /// Groups with fewer points are not meshed (default 10).
    pub min_points: usize,
    /// Curved groups that are spheres within `planar_rms_m` are meshed as
    /// spheres ([`sphere`]; default true).
    pub fit_spheres: bool,
    /// Planar groups whose points show sides under the plane (a table top)
    /// are closed into slabs ([`slab`]; default true).
    pub close_slabs: bool,
    /// Ball pivoting's ball radius, in the points' spacing (the median
    /// nearest-neighbour distance; default 2): a gap wider than twice the
    /// radius stays open.
    pub ball_radius_factor: f64,
    /// The true geometry: an OBJ whose groups are named as the
    /// segmentation's groups (the simulator's truth). When given, each
    /// group's mesh is measured against its namesake.
    pub truth: Option<std::path::PathBuf>,
    /// Sample spacing for the Hausdorff distance, metres (default 0.02).
    pub hausdorff_spacing_m: f64,
    /// A mesh farther than this from the truth (symmetric Hausdorff),
    /// metres, is poor (default 0.03).
    pub hausdorff_poor_m: f64,
    /// ... and failed beyond this (default 0.10).
    pub hausdorff_failed_m: f64,
}

impl Default for MeshOptions {
    fn default() -> MeshOptions {
        MeshOptions {
            planar_rms_m: 0.01,
            depth_jump_factor: 8.0,
            outline_alpha_factor: 6.0,
            outline_tolerance_m: 0.01,
            simplify_error_m: 0.005,
            min_points: 10,
            fit_spheres: true,
            close_slabs: true,
            ball_radius_factor: 2.0,
            truth: None,
            hausdorff_spacing_m: 0.02,
            hausdorff_poor_m: 0.03,
            hausdorff_failed_m: 0.10,
        }
    }
}

/// Why groups could not be meshed.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum MeshError {
    /// An option is out of its range.
    #[error("mesh option {field}: found {value}; expected {expected}")]
    Option {
        /// The option.
        field: &'static str,
        /// Its value.
        value: f64,
        /// What it must be.
        expected: &'static str,
    },
    /// A scan is malformed.
    #[error(transparent)]
    Scan(#[from] ScanError),
    /// The segmentation does not match the scans.
    #[error("segmentation: {0}")]
    Segmentation(String),
}

impl MeshOptions {
    /// Checks every option's range.
    pub fn check(&self) -> Result<(), MeshError> {
        let checks: [(&'static str, f64, bool, &'static str); 9] = [
            (
                "planar_rms_m",
                self.planar_rms_m,
                self.planar_rms_m >= 0.0,
                "a distance ≥ 0 in metres",
            ),
            (
                "depth_jump_factor",
                self.depth_jump_factor,
                self.depth_jump_factor >= 1.0,
                "a factor ≥ 1",
            ),
            (
                "outline_alpha_factor",
                self.outline_alpha_factor,
                self.outline_alpha_factor >= 1.0,
                "a factor ≥ 1",
            ),
            (
                "outline_tolerance_m",
                self.outline_tolerance_m,
                self.outline_tolerance_m >= 0.0,
                "a distance ≥ 0 in metres",
            ),
            (
                "simplify_error_m",
                self.simplify_error_m,
                self.simplify_error_m >= 0.0,
                "a distance ≥ 0 in metres",
            ),
            (
                "ball_radius_factor",
                self.ball_radius_factor,
                self.ball_radius_factor >= 0.5,
                "a factor ≥ 0.5",
            ),
            (
                "hausdorff_spacing_m",
                self.hausdorff_spacing_m,
                self.hausdorff_spacing_m > 0.0,
                "a distance > 0 in metres",
            ),
            (
                "hausdorff_poor_m",
                self.hausdorff_poor_m,
                self.hausdorff_poor_m > 0.0,
                "a distance > 0 in metres",
            ),
            (
                "hausdorff_failed_m",
                self.hausdorff_failed_m,
                self.hausdorff_failed_m >= self.hausdorff_poor_m,
                "a distance ≥ hausdorff_poor_m in metres",
            ),
        ];
        for (field, value, ok, expected) in checks {
            if !(ok && value.is_finite()) {
                return Err(MeshError::Option { field, value, expected });
            }
        }
        Ok(())
    }
}

/// How a group was meshed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum MeshMethod {
    /// A polygon in the group's plane.
    PlanarPolygon,
    /// A polygon in each of the group's planes
    /// ([`plane_pieces::plane_pieces`]): a table's top and sides.
    PlanePieces,
    /// A sphere fitted to the group's points ([`sphere`]).
    Sphere,
    /// Scan-order neighbours of organised scans.
    ScanGrid,
    /// Curved unorganised groups that are height fields over their plane.
    HeightField,
    /// Other curved unorganised groups.
    BallPivoting,
    /// Too few points: not meshed.
    TooFewPoints,
}

/// One group's mesh and how it was made.
#[derive(Debug, Clone, PartialEq)]
pub struct GroupMesh {
    /// The group's index in the segmentation.
    pub group: u32,
    /// The group's name in the segmentation.
    pub name: String,
    /// Points in the group, over all scans.
    pub points: usize,
    /// The method.
    pub method: MeshMethod,
    /// The least-squares plane's RMS residual, metres (when there was a plane).
    pub plane_rms_m: Option<f64>,
    /// Curved unorganised groups: the height field's triangles more than
    /// 80° from the plane (over 1 %, ball pivoting was used instead).
    pub folded: usize,
    /// Triangles before simplification.
    pub triangles_before: usize,
    /// The simplifier's error estimate, metres (0 when not simplified).
    pub simplify_error_m: f64,
    /// [`MeshMethod::PlanePieces`]: the planes found.
    pub pieces: usize,
    /// [`MeshMethod::PlanePieces`]: points on none of them (thin strips
    /// between the planes, clutter), left out of the mesh.
    pub unmeshed_points: usize,
    /// [`MeshMethod::PlanarPolygon`]: the points' spacing in the plane (the
    /// median nearest-neighbour distance), metres.
    pub spacing_m: Option<f64>,
    /// [`MeshMethod::PlanarPolygon`]: polygon corners moved onto a
    /// neighbouring group's plane ([`corners`]).
    pub corners_moved: usize,
    /// [`MeshMethod::Sphere`]: the sphere.
    pub sphere: Option<sphere::SphereFit>,
    /// A group whose points lie on another group's fitted sphere (a ball
    /// that the segmentation split in pieces, denser scans): that group,
    /// whose sphere mesh covers it; its own mesh is then empty.
    pub covered_by: Option<u32>,
    /// [`MeshMethod::PlanarPolygon`], [`MeshMethod::PlanePieces`]: the
    /// slabs the planes were closed into ([`slab`]), one per plane closed.
    pub slabs: Vec<slab::Slab>,
    /// [`MeshMethod::PlanarPolygon`]: per mesh vertex, whether it is a
    /// corner of an outline (not of a hole); empty for other methods.
    pub outer: Vec<bool>,
    /// The mesh (simplified), normals facing the scanner.
    pub mesh: TriangleMesh,
}

/// Checks that `segmentation` labels every point of `scans`.
fn check_labels(scans: &[Scan], segmentation: &Segmentation) -> Result<(), MeshError> {
    if segmentation.labels.len() != scans.len() {
        return Err(MeshError::Segmentation(format!(
            "{} label lists for {} scans (expected one per scan)",
            segmentation.labels.len(),
            scans.len()
        )));
    }
    for (scan, labels) in scans.iter().zip(&segmentation.labels) {
        scan.check()?;
        if labels.len() != scan.len() {
            return Err(MeshError::Segmentation(format!(
                "scan {:?}: {} labels for {} points",
                scan.name,
                labels.len(),
                scan.len()
            )));
        }
        if let Some((point, &label)) = labels
            .iter()
            .enumerate()
            .find(|&(_, &l)| l != UNASSIGNED && l as usize >= segmentation.groups())
        {
            return Err(MeshError::Segmentation(format!(
                "scan {:?}: point {point} is in group {label}, but there are {} groups",
                scan.name,
                segmentation.groups()
            )));
        }
    }
    Ok(())
}

/// Where each group's points are: per scan, per group, the point indices
/// and (organised scans) the grid window, found in one pass per scan.
struct Membership {
    /// `points[scan][group]`: the group's point indices in that scan.
    points: Vec<Vec<Vec<u32>>>,
    /// `windows[scan][group]`: the group's grid window in that scan.
    windows: Vec<Vec<Option<GridWindow>>>,
}

impl Membership {
    fn of(scans: &[Scan], segmentation: &Segmentation) -> Membership {
        let groups = segmentation.groups();
        let mut points = Vec::with_capacity(scans.len());
        let mut windows = Vec::with_capacity(scans.len());
        for (scan, labels) in scans.iter().zip(&segmentation.labels) {
            let mut members = vec![Vec::new(); groups];
            for (i, &l) in labels.iter().enumerate() {
                if let Some(m) = members.get_mut(l as usize) {
                    m.push(i as u32);
                }
            }
            points.push(members);
            windows.push(match &scan.grid {
                Some(grid) => GridWindow::of_groups(grid, labels, groups),
                None => vec![None; groups],
            });
        }
        Membership { points, windows }
    }
}

/// Meshes every group of `segmentation` over `scans` (each group's points
/// from every scan), in group order; groups in parallel.
pub fn mesh_groups(
    scans: &[Scan],
    segmentation: &Segmentation,
    options: &MeshOptions,
) -> Result<Vec<GroupMesh>, MeshError> {
    use rayon::prelude::*;
    options.check()?;
    check_labels(scans, segmentation)?;
    let all_points = scans.iter().map(Scan::len).sum::<usize>().max(1);
    let cloud_centre = scans.iter().flat_map(|s| &s.positions).sum::<Vector3<f64>>() / all_points as f64;
    let views: Vec<Vector3<f64>> = scans
        .iter()
        .map(|s| s.pose.map_or(cloud_centre, |p| p.origin))
        .collect();
    let steps: Vec<Option<GridStep>> = scans.iter().map(GridStep::of).collect();
    let membership = Membership::of(scans, segmentation);
    let context = Context {
        scans,
        segmentation,
        options,
        views: &views,
        steps: &steps,
        membership: &membership,
    };
    let mut meshes: Vec<GroupMesh> = (0..segmentation.groups())
        .into_par_iter()
        .map(|g| context.mesh_group(g as u32))
        .collect();
    sphere::cover_pieces(&mut meshes, 2.0 * options.planar_rms_m);
    corners::close_corners(&mut meshes);
    // Planar polygons found to be slabs are closed on their outlines as
    // the corners pass left them.
    for mesh in meshes.iter_mut().filter(|m| m.method == MeshMethod::PlanarPolygon) {
        let Some(found) = mesh.slabs.first().copied() else {
            continue;
        };
        let normal = (0..mesh.mesh.triangles.len())
            .map(|t| mesh.mesh.area_normal(t))
            .sum::<Vector3<f64>>()
            .try_normalize(0.0);
        let Some(normal) = normal else { continue };
        let closing = slab::closing(&mesh.mesh, &normal, found.thickness_m);
        mesh.outer.extend(std::iter::repeat_n(false, closing.positions.len()));
        mesh.mesh.append(&closing);
        mesh.triangles_before += closing.triangles.len();
    }
    Ok(meshes)
}

/// What every group's meshing shares.
struct Context<'a> {
    scans: &'a [Scan],
    segmentation: &'a Segmentation,
    options: &'a MeshOptions,
    /// Each scan's viewpoint: its scanner, or the cloud's centre.
    views: &'a [Vector3<f64>],
    steps: &'a [Option<GridStep>],
    membership: &'a Membership,
}

impl Context<'_> {
    /// The slab under `top` (a polygon of `out`'s mesh in `plane`, facing
    /// the scanners) when the group's `points` show its sides ([`slab`]),
    /// recorded in `out`.
    fn find_slab(
        &self,
        out: &mut GroupMesh,
        top: &TriangleMesh,
        plane: &PlaneFit,
        points: &[Vector3<f64>],
        spacing: f64,
    ) -> Option<slab::Slab> {
        let options = self.options;
        if !options.close_slabs {
            return None;
        }
        let found = slab::slab_under(
            top,
            &plane.centroid,
            &plane.normal,
            points,
            2.0 * options.planar_rms_m,
            spacing,
            options.min_points,
        )?;
        out.slabs.push(found);
        Some(found)
    }

    fn mesh_group(&self, group: u32) -> GroupMesh {
        let g = group as usize;
        let options = self.options;
        let mut points = Vec::new();
        let mut view_sum = Vector3::zeros();
        let mut all_organised = true;
        // Per point: its scan's viewpoint, and its normal when every scan
        // has normals.
        let mut views = Vec::new();
        let mut normals = Some(Vec::new());
        for (s, scan) in self.scans.iter().enumerate() {
            let members = &self.membership.points[s][g];
            points.extend(members.iter().map(|&i| scan.positions[i as usize]));
            views.extend(std::iter::repeat_n(self.views[s], members.len()));
            normals = match (normals, &scan.normals) {
                (Some(mut n), Some(given)) => {
                    n.extend(members.iter().map(|&i| given[i as usize]));
                    Some(n)
                }
                (normals, _) if members.is_empty() => normals,
                _ => None,
            };
            if !members.is_empty() {
                view_sum += self.views[s] * members.len() as f64;
                all_organised &= scan.grid.is_some();
            }
        }
        let mut out = GroupMesh {
            group,
            name: self.segmentation.names[g].clone(),
            points: points.len(),
            method: MeshMethod::TooFewPoints,
            plane_rms_m: None,
            folded: 0,
            triangles_before: 0,
            simplify_error_m: 0.0,
            pieces: 0,
            unmeshed_points: 0,
            spacing_m: None,
            corners_moved: 0,
            sphere: None,
            covered_by: None,
            slabs: Vec::new(),
            outer: Vec::new(),
            mesh: TriangleMesh::default(),
        };
        let plane = (points.len() >= options.min_points.max(3))
            .then(|| PlaneFit::of(&points))
            .flatten();
        let Some(plane) = plane else {
            return out;
        };
        let plane = plane.facing(&(view_sum / points.len() as f64));
        out.plane_rms_m = Some(plane.rms_m);
        let curved = if plane.rms_m <= options.planar_rms_m {
            out.method = MeshMethod::PlanarPolygon;
            let (mesh, shape, outer) = planar_polygon(
                &points,
                &plane,
                options.outline_alpha_factor,
                options.outline_tolerance_m,
            );
            out.mesh = mesh;
            out.spacing_m = shape.map(|s| s.spacing);
            out.outer = outer;
            // Closed after the corners pass has moved the outline
            // (`mesh_groups`).
            if let Some(spacing) = out.spacing_m {
                let top = out.mesh.clone();
                self.find_slab(&mut out, &top, &plane, &points, spacing);
            }
            out.triangles_before = out.mesh.triangles.len();
            return out;
        } else if let Some(pieces) = plane_pieces::plane_pieces(
            &points,
            &views,
            options.min_points,
            2.0 * options.planar_rms_m,
            options.planar_rms_m,
        ) {
            out.method = MeshMethod::PlanePieces;
            out.pieces = pieces.len();
            out.unmeshed_points = points.len() - pieces.iter().map(|p| p.points.len()).sum::<usize>();
            let spacing = nearest_spacing(&points);
            // A slab's sides are the points no piece holds (a side tall
            // enough to be a piece is meshed as one).
            let mut held = vec![false; points.len()];
            for piece in &pieces {
                for &i in &piece.points {
                    held[i] = true;
                }
            }
            let loose: Vec<Vector3<f64>> = (0..points.len()).filter(|&i| !held[i]).map(|i| points[i]).collect();
            for piece in &pieces {
                let pts: Vec<Vector3<f64>> = piece.points.iter().map(|&i| points[i]).collect();
                let view = piece.points.iter().map(|&i| views[i]).sum::<Vector3<f64>>() / pts.len() as f64;
                let plane = piece.plane.facing(&view);
                let top = planar_polygon(&pts, &plane, options.outline_alpha_factor, options.outline_tolerance_m).0;
                out.mesh.append(&top);
                if let Some(found) = self.find_slab(&mut out, &top, &plane, &loose, spacing) {
                    out.mesh.append(&slab::closing(&top, &plane.normal, found.thickness_m));
                }
            }
            out.triangles_before = out.mesh.triangles.len();
            return out;
        } else if let Some(ball) = options
            .fit_spheres
            .then(|| sphere::fit_sphere(&points, options.planar_rms_m))
            .flatten()
        {
            out.method = MeshMethod::Sphere;
            out.mesh = sphere::sphere_mesh(&ball, SPHERE_RINGS);
            out.sphere = Some(ball);
            out.triangles_before = out.mesh.triangles.len();
            return out;
        } else if all_organised {
            out.method = MeshMethod::ScanGrid;
            let mut mesh = TriangleMesh::default();
            for (s, scan) in self.scans.iter().enumerate() {
                if let (Some(step), Some(window)) = (&self.steps[s], &self.membership.windows[s][g]) {
                    let labels = &self.segmentation.labels[s];
                    let view = &self.views[s];
                    mesh.append(&grid_mesh(
                        scan,
                        labels,
                        group,
                        window,
                        step,
                        options.depth_jump_factor,
                        view,
                    ));
                }
            }
            mesh
        } else {
            let hf = height_field(&points, &plane, options.outline_alpha_factor);
            out.folded = hf.folded;
            if hf.folded * 100 <= hf.mesh.triangles.len() {
                out.method = MeshMethod::HeightField;
                hf.mesh
            } else {
                out.method = MeshMethod::BallPivoting;
                let spacing = nearest_spacing(&points);
                let normals = normals.unwrap_or_else(|| estimate_normals(&points, &views, 2.5 * spacing));
                ball_pivoting(&points, &normals, options.ball_radius_factor * spacing)
            }
        };
        out.triangles_before = curved.triangles.len();
        out.mesh = if options.simplify_error_m > 0.0 {
            let s = simplify(&curved, options.simplify_error_m);
            out.simplify_error_m = s.error_m;
            s.mesh
        } else {
            curved
        };
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synthetic_scan::{Rect, scan_of};

    /// A 6 × 4 m wall at x = 3, scanned from the origin over ±30° in
    /// elevation every 0.5° (the scan's azimuths that miss it give no
    /// return), with uniform range noise of σ = 3 mm.
    fn wall() -> (Scan, Segmentation, Scan) {
        let rect = Rect {
            name: "wall".into(),
            axis: 0,
            at: 3.0,
            lo: [-3.0, -2.0],
            hi: [3.0, 2.0],
        };
        let (noisy, seg) = scan_of(std::slice::from_ref(&rect), Vector3::zeros(), 0.5, 30.0, 0.003);
        let (exact, _) = scan_of(&[rect], Vector3::zeros(), 0.5, 30.0, 0.0);
        (noisy, seg, exact)
    }

    #[test]
    fn a_noisy_plane_on_an_organised_grid_meshes_within_three_sigma() {
        let (scan, seg, exact) = wall();
        let sigma = 0.003;
        let plane = TriangleMesh {
            positions: vec![
                Vector3::new(3.0, -4.0, -3.0),
                Vector3::new(3.0, 4.0, -3.0),
                Vector3::new(3.0, 4.0, 3.0),
                Vector3::new(3.0, -4.0, 3.0),
            ],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
        };
        // Planarity off: scan-order neighbours, every triangle kept.
        let options = MeshOptions {
            planar_rms_m: 0.0,
            simplify_error_m: 0.0,
            ..MeshOptions::default()
        };
        let meshes = mesh_groups(std::slice::from_ref(&scan), &seg, &options).unwrap();
        let m = &meshes[0];
        assert_eq!(m.method, MeshMethod::ScanGrid);
        let grid = scan.grid.as_ref().unwrap();
        let quads = (grid.rows - 1) * (grid.cols - 1);
        assert!(!m.mesh.triangles.is_empty() && m.mesh.triangles.len() < 2 * quads);
        // Symmetric: the mesh against the true plane, the noiseless returns
        // against the mesh.
        let away = one_sided(&m.mesh, Reference::Mesh(&plane), 0.01).unwrap();
        let back = hausdorff(&m.mesh, Reference::Points(&exact.positions), 0.01).unwrap();
        let h = away.max_m.max(back.reference_to_mesh_m);
        // Measured 5.2 mm: the noise's half-width √3 σ.
        assert!(h <= 3.0 * sigma, "{h}");
        assert!((0..m.mesh.triangles.len()).all(|t| m.mesh.area_normal(t).x < 0.0));

        // Simplified to 5 mm: far fewer triangles, still within 3σ of the plane.
        let options = MeshOptions {
            planar_rms_m: 0.0,
            ..MeshOptions::default()
        };
        let simplified = &mesh_groups(std::slice::from_ref(&scan), &seg, &options).unwrap()[0];
        let away = one_sided(&simplified.mesh, Reference::Mesh(&plane), 0.01).unwrap();
        let back = hausdorff(&simplified.mesh, Reference::Points(&exact.positions), 0.01).unwrap();
        let h = away.max_m.max(back.reference_to_mesh_m);
        assert!(h <= 3.0 * sigma, "{h}");
        // Measured 41 572 → 11 065.
        assert_eq!(simplified.triangles_before, m.mesh.triangles.len());
        assert!(simplified.mesh.triangles.len() * 3 < simplified.triangles_before);

        // The default options find it planar: a polygon.
        let planar = &mesh_groups(&[scan], &seg, &MeshOptions::default()).unwrap()[0];
        assert_eq!(planar.method, MeshMethod::PlanarPolygon);
        assert!(planar.plane_rms_m.unwrap() <= sigma);
        // Measured 28: the outline's corners along the scan's curved edges.
        assert!(planar.mesh.triangles.len() <= 40, "{}", planar.mesh.triangles.len());
    }

    #[test]
    fn bad_options_and_mismatched_labels_are_refused_by_name() {
        let (scan, mut seg, _) = wall();
        let options = MeshOptions {
            depth_jump_factor: 0.5,
            ..MeshOptions::default()
        };
        let e = mesh_groups(std::slice::from_ref(&scan), &seg, &options).unwrap_err();
        assert_eq!(
            e.to_string(),
            "mesh option depth_jump_factor: found 0.5; expected a factor ≥ 1"
        );
        seg.labels[0][5] = 3;
        let e = mesh_groups(std::slice::from_ref(&scan), &seg, &MeshOptions::default()).unwrap_err();
        assert_eq!(
            e.to_string(),
            "segmentation: scan \"test scan\": point 5 is in group 3, but there are 1 groups"
        );
        seg.labels[0].pop();
        let e = mesh_groups(&[scan], &seg, &MeshOptions::default()).unwrap_err();
        assert!(e.to_string().contains("labels for"), "{e}");
    }

    #[test]
    fn a_sphere_seen_from_six_sides_without_a_grid_is_ball_pivoted() {
        // 1500 points of a 0.5 m sphere at (0, 0, 1), seen by six scanners
        // around it: unorganised scans without normals.
        let centre = Vector3::new(0.0, 0.0, 1.0);
        let (scans, seg) = crate::synthetic_scan::sphere_scans(1500, 0.5, centre);
        assert_eq!(scans.iter().map(Scan::len).sum::<usize>(), 1500);
        // By default it is fitted as the sphere it is.
        let m = &mesh_groups(&scans, &seg, &MeshOptions::default()).unwrap()[0];
        assert_eq!(m.method, MeshMethod::Sphere);
        for &p in &m.mesh.positions {
            assert!(((p - centre).norm() - 0.5).abs() < 1e-6, "{p}");
        }
        // Without sphere fits, ball pivoting.
        let options = MeshOptions {
            fit_spheres: false,
            ..MeshOptions::default()
        };
        let m = &mesh_groups(&scans, &seg, &options).unwrap()[0];
        assert_eq!(m.method, MeshMethod::BallPivoting);
        // Its height field folded over its plane.
        assert!(m.folded > 0);
        // Closed: 2n − 4 triangles, then simplified to 5 mm.
        assert_eq!(m.triangles_before, 2 * 1500 - 4);
        let t = m.mesh.triangles.len();
        let sag = (0..t)
            .map(|k| {
                let [a, b, c] = m.mesh.corners(k);
                let normal = m.mesh.area_normal(k);
                assert!(normal.dot(&((a + b + c) / 3.0 - centre)) > 0.0, "triangle {k} faces in");
                0.5 - ((a + b + c) / 3.0 - centre).norm()
            })
            .fold(0.0, f64::max);
        // Measured: 708 triangles, the flat triangles at most 7.8 mm inside
        // the sphere (the simplifier's own estimate 4.8 mm, target 5 mm).
        assert!(t < m.triangles_before / 2, "{t}");
        assert!(sag < 0.01, "{sag}");
        assert!(
            m.mesh
                .positions
                .iter()
                .all(|p| ((p - centre).norm() - 0.5).abs() < 1e-12)
        );
    }
}

//! A simulated scene rebuilt from its simulated range scans (issue 28's
//! end-to-end criterion): the meshes of the segmented groups
//! (`campanile_scan::mesh::mesh_groups`) stand in for the true surfaces
//! they were scanned from, and the world's truth is read back at points of
//! the rebuilt geometry, so that a solver run on it can be scored as one
//! run on the true geometry is.
//!
//! - **Group → surface.** Each group stands for the true surface most of
//!   its labelled points lie on ([`majority_surfaces`]), as a user naming
//!   the groups would; the group's triangles take that surface's index and
//!   material. A replaced surface that no group stands for is missing from
//!   the rebuilt scene.
//! - **Inverse global illumination.** The solver's surfaces are the
//!   scene's materials ([`super::room_igi::igi_triangles_of`]); a solve is scored by each
//!   parameter's absolute error averaged over solver seeds
//!   ([`mean_igi_errors`]), and two geometries by the worst ratio of their
//!   errors ([`worst_ratio`]).
//! - **Truth at a point.** A point of the rebuilt geometry is moved to the
//!   nearest point of the true scene, and the true albedo is read there
//!   ([`projected_cell_truth`]); on the true geometry this is the point
//!   itself.

// Channel loops index several arrays at once; they read better with an index.
#![allow(clippy::needless_range_loop)]

use campanile_process::brdf::WardMaterial;
use campanile_process::error_figures::quantile;
use campanile_process::igi::table::errors;
use campanile_process::igi::{IgiError, IgiInput, IgiOptions, recover};
use campanile_process::outdoor::{CellStatus, Grid, Reflectance};
use campanile_process::render::{Scene, SceneError, Triangle};
use campanile_scan::mesh::GroupMesh;
use campanile_scan::mesh::hausdorff::closest_on_triangle;
use campanile_scan::segmentation::{Segmentation, UNASSIGNED};
use nalgebra::Vector3;
use rayon::prelude::*;

use super::World;

/// A group's majority true surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Majority {
    /// The true surface (an index into the true scene's surfaces).
    pub surface: usize,
    /// The group's points on it.
    pub points: usize,
    /// Its share of the group's points that have a true surface.
    pub share: f64,
}

/// For each group of `found`, the true surface (in `truth`, the
/// simulator's labels of the same points) most of its points lie on;
/// `None` for a group none of whose points has a true surface.
pub fn majority_surfaces(found: &Segmentation, truth: &Segmentation) -> Vec<Option<Majority>> {
    let mut votes = vec![vec![0usize; truth.groups()]; found.groups()];
    for (labels, true_labels) in found.labels.iter().zip(&truth.labels) {
        for (&g, &s) in labels.iter().zip(true_labels) {
            if g != UNASSIGNED && s != UNASSIGNED {
                votes[g as usize][s as usize] += 1;
            }
        }
    }
    votes
        .iter()
        .map(|v| {
            let total: usize = v.iter().sum();
            let (surface, &points) = v.iter().enumerate().max_by_key(|(_, c)| **c)?;
            (points > 0).then(|| Majority {
                surface,
                points,
                share: points as f64 / total as f64,
            })
        })
        .collect()
}

/// What a group became in the rebuilt scene.
#[derive(Debug, Clone, PartialEq)]
pub struct GroupUse {
    /// The group.
    pub group: u32,
    /// The true surface it stands for.
    pub surface: usize,
    /// Its triangles in the rebuilt scene.
    pub triangles: usize,
}

/// A scene with some surfaces rebuilt from scans.
#[derive(Debug, Clone)]
pub struct ScannedScene {
    /// The rebuilt scene: the true scene's materials and surface names.
    pub scene: Scene,
    /// The groups used, in group order.
    pub groups: Vec<GroupUse>,
    /// Replaced surfaces that no group stands for: absent from `scene`.
    pub missing: Vec<usize>,
}

/// `scene` with the true triangles of the `replaced` surfaces swapped for
/// the `meshes` of the groups whose majority surface (`majority`, one per
/// group) they are; each group's triangles take that surface's index and
/// the material of its first true triangle. The surfaces in `keep_true`
/// keep their true triangles (an error budget's knob); every other surface
/// is unchanged.
pub fn scanned_scene(
    scene: &Scene,
    meshes: &[GroupMesh],
    majority: &[Option<Majority>],
    replaced: &[usize],
    keep_true: &[usize],
) -> Result<ScannedScene, SceneError> {
    let swapped = |s: usize| replaced.contains(&s) && !keep_true.contains(&s);
    let mut material_of = vec![None; scene.surfaces().len()];
    for t in scene.triangles() {
        material_of[t.surface as usize].get_or_insert(t.material);
    }
    let mut triangles: Vec<Triangle> = scene
        .triangles()
        .iter()
        .filter(|t| !swapped(t.surface as usize))
        .cloned()
        .collect();
    let mut groups = Vec::new();
    for mesh in meshes {
        let Some(Some(m)) = majority.get(mesh.group as usize) else {
            continue;
        };
        let Some(material) = material_of[m.surface].filter(|_| swapped(m.surface)) else {
            continue;
        };
        let before = triangles.len();
        for k in 0..mesh.mesh.triangles.len() {
            if let Some(t) = Triangle::new(mesh.mesh.corners(k), material, m.surface as u32) {
                triangles.push(t);
            }
        }
        groups.push(GroupUse {
            group: mesh.group,
            surface: m.surface,
            triangles: triangles.len() - before,
        });
    }
    let missing = replaced
        .iter()
        .copied()
        .filter(|&s| swapped(s) && !groups.iter().any(|g| g.surface == s && g.triangles > 0))
        .collect();
    Ok(ScannedScene {
        scene: Scene::new(triangles, scene.materials().to_vec(), scene.surfaces().to_vec())?,
        groups,
        missing,
    })
}

/// Per material of `truth`, the absolute errors of ρd, ρs, αx, αy (%) and
/// γ (°) ([`errors`]) averaged over `seeds` solves of `input` with
/// `options` and solver seeds `options.seed + first ..`; each parameter
/// over the solves that have it (a lobe's α is missing from a solve that
/// found the surface diffuse). At few gather rays one seed's error moves
/// several-fold for a glossy material, so a ratio of single solves
/// measures the seed as much as the geometry.
pub fn mean_igi_errors(
    input: &IgiInput,
    options: &IgiOptions,
    first: u64,
    seeds: u64,
    truth: &[WardMaterial],
) -> Result<Vec<[Option<f64>; 5]>, IgiError> {
    let mut sum = vec![[(0.0, 0usize); 5]; truth.len()];
    for k in 0..seeds {
        let solved = recover(
            input,
            &IgiOptions {
                seed: options.seed + first + k,
                ..*options
            },
        )?;
        for (s, total) in sum.iter_mut().enumerate() {
            let Some(m) = solved.surfaces.get(s).and_then(|r| r.material.as_ref()) else {
                continue;
            };
            for ((total, n), e) in total.iter_mut().zip(errors(m, &truth[s])) {
                if let Some(e) = e {
                    *total += e.abs();
                    *n += 1;
                }
            }
        }
    }
    Ok(sum
        .iter()
        .map(|m| m.map(|(total, n)| (n > 0).then(|| total / n as f64)))
        .collect())
}

/// The worst ratio `b / a` over the parameters both have, each error
/// floored at 0.5 % (γ at 0.1°) so that a near-zero reference does not
/// make noise look like a failure; `None` when they share none.
pub fn worst_ratio(a: &[Option<f64>; 5], b: &[Option<f64>; 5]) -> Option<f64> {
    (0..5)
        .filter_map(|k| {
            let floor = if k == 4 { 0.1 } else { 0.5 };
            Some(b[k]?.max(floor) / a[k]?.max(floor))
        })
        .reduce(f64::max)
}

/// The true albedo averaged over each cell of `grid` (laid over `scene`,
/// true or rebuilt) from `per_side`² points of the cell, each moved to the
/// nearest point of `world`'s true scene and read there. Only the true
/// triangles that can be nearest to some point of the cell are searched: a
/// point within `r` of the cell's centre `c` is nearer to a triangle `T`
/// than `d(c, T) − r`, and no farther from the nearest one than
/// `min d(c, ·) + r`.
pub fn projected_cell_truth(world: &World, grid: &Grid, scene: &Scene, per_side: usize) -> Vec<[f64; 3]> {
    let truth = world.scene.scene.triangles();
    let closest = |p: &Vector3<f64>, t: &Triangle| {
        let [a, b, c] = &t.vertices;
        closest_on_triangle(p, a, b, c)
    };
    (0..grid.cells.len())
        .into_par_iter()
        .map(|c| {
            let mut pts = grid.cell_points(scene, c, per_side);
            if pts.is_empty() {
                // A sliver narrower than the sub-samples: its centroid.
                pts.push(grid.cells[c].centre);
            }
            let centre = grid.cells[c].centre;
            let r = pts.iter().map(|p| (p - centre).norm()).fold(0.0, f64::max);
            let d: Vec<f64> = truth.iter().map(|t| (closest(&centre, t) - centre).norm()).collect();
            let nearest = d.iter().copied().fold(f64::INFINITY, f64::min);
            let candidates: Vec<usize> = (0..truth.len()).filter(|&k| d[k] <= nearest + 2.0 * r).collect();
            let mut sum = [0.0; 3];
            for p in &pts {
                let (k, q) = candidates
                    .iter()
                    .map(|&k| (k, closest(p, &truth[k])))
                    .min_by(|a, b| (a.1 - p).norm_squared().total_cmp(&(b.1 - p).norm_squared()))
                    .expect("a scene has triangles");
                // On the true surface already: the point itself (the
                // projection's rounding would move a point that lies on a
                // mortar joint's edge across it).
                let q = if (q - p).norm() < 1e-9 { *p } else { q };
                let a = world.pseudo_albedos(k, [q.x, q.y, q.z]);
                for ch in 0..3 {
                    sum[ch] += a.sun[ch];
                }
            }
            sum.map(|s| s / pts.len() as f64)
        })
        .collect()
}

/// Relative errors of one surface's cells against the truth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CellErrors {
    /// Cells some photo saw (solved or filled).
    pub seen: usize,
    /// Their area, m².
    pub seen_area_m2: f64,
    /// |ρ^se / truth − 1| over the seen cells and the three channels: median.
    pub se_median: f64,
    /// ... and 95th percentile.
    pub se_p95: f64,
    /// |ρ^sun / truth − 1|: median.
    pub sun_median: f64,
    /// ... and 95th percentile.
    pub sun_p95: f64,
}

impl CellErrors {
    /// Three Markdown table cells: the seen cells (their area), the ρ^se
    /// median / p95 and the ρ^sun median / p95, in percent ("—" when no
    /// cell was seen).
    pub fn table_cells(&self) -> String {
        if self.seen == 0 {
            return "0 | — | —".into();
        }
        format!(
            "{} ({:.0} m²) | {:.2} / {:.2} | {:.2} / {:.2}",
            self.seen,
            self.seen_area_m2,
            100.0 * self.se_median,
            100.0 * self.se_p95,
            100.0 * self.sun_median,
            100.0 * self.sun_p95
        )
    }
}

/// The errors of `refl` against `truth` (one per cell) over the seen cells
/// of the surfaces in `surfaces` (NaN figures when none was seen).
pub fn cell_errors(refl: &Reflectance, truth: &[[f64; 3]], surfaces: &[usize]) -> CellErrors {
    let (mut se, mut sun) = (Vec::new(), Vec::new());
    let mut area = 0.0;
    let mut seen = 0;
    for (c, t) in truth.iter().enumerate() {
        if refl.cells[c].status == CellStatus::Unseen || !surfaces.contains(&refl.grid.cells[c].surface) {
            continue;
        }
        seen += 1;
        area += refl.grid.cells[c].area_m2;
        for ch in 0..3 {
            se.push((refl.cells[c].rho_se[ch] / t[ch] - 1.0).abs());
            sun.push((refl.cells[c].rho_sun[ch] / t[ch] - 1.0).abs());
        }
    }
    CellErrors {
        seen,
        seen_area_m2: area,
        se_median: quantile(&mut se, 0.5),
        se_p95: quantile(&mut se, 0.95),
        sun_median: quantile(&mut sun, 0.5),
        sun_p95: quantile(&mut sun, 0.95),
    }
}

/// The errors on the scans' geometry over those on the true geometry, each
/// error floored at `floor` first (so that a near-zero reference does not
/// make noise look like a failure).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ErrorRatios {
    /// Of the ρ^se medians.
    pub se_median: f64,
    /// Of the ρ^sun medians.
    pub sun_median: f64,
    /// Of the ρ^se 95th percentiles.
    pub se_p95: f64,
    /// Of the ρ^sun 95th percentiles.
    pub sun_p95: f64,
}

/// The ratios of `on_scans` to `on_truth`; `None` when either saw no cell.
pub fn error_ratios(on_truth: &CellErrors, on_scans: &CellErrors, floor: f64) -> Option<ErrorRatios> {
    if on_truth.seen == 0 || on_scans.seen == 0 {
        return None;
    }
    let r = |a: f64, b: f64| b.max(floor) / a.max(floor);
    Some(ErrorRatios {
        se_median: r(on_truth.se_median, on_scans.se_median),
        sun_median: r(on_truth.sun_median, on_scans.sun_median),
        se_p95: r(on_truth.se_p95, on_scans.se_p95),
        sun_p95: r(on_truth.sun_p95, on_scans.sun_p95),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::campanile_day::CampanileDay;

    /// On the true geometry the nearest true point is the point itself:
    /// the projected truth is the world's own cell truth.
    #[test]
    fn on_the_true_geometry_the_projected_truth_is_the_cell_truth() {
        let day = CampanileDay::load(1, 1).unwrap();
        let scene = &day.world.scene.scene;
        let targets = day.targets().unwrap();
        let grid = Grid::with_sides(scene, &targets, 4.0, &|_| 1.0).unwrap();
        let projected = projected_cell_truth(&day.world, &grid, scene, 8);
        let direct = day.cell_truth(&grid, 8);
        assert_eq!(projected.len(), grid.cells.len());
        let worst = projected
            .iter()
            .zip(&direct)
            .flat_map(|(a, b)| (0..3).map(move |ch| (a[ch] / b[ch] - 1.0).abs()))
            .fold(0.0, f64::max);
        assert!(worst < 1e-9, "{worst}");
    }
}

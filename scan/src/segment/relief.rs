//! Layers that stand proud of a plane or are set into it: posters, boards
//! and picture frames on a wall, door panels, skirting.
//!
//! Normalized cuts (§2.3) compare clusters by their normals (eq. 2.3) and by
//! their distance, stretched across the surface by eq. 2.5's E; a poster
//! 1 cm proud of a wall, with the wall's normal and nearly its reflectance,
//! differs from it in neither, and 1 cm is a few times the range noise, far
//! under a 12 cm cluster's reach. Across many points the step is plain,
//! though: the poster's points sit 1 cm off the wall's plane on average, to
//! a fraction of a millimetre. This pass, ours and not the thesis's, looks
//! for it in every planar group after the points have their groups:
//!
//! 1. the group's plane, fitted robustly (points within 3 σ of it, σ from
//!    the median absolute residual, refitted three times); a group that is
//!    not a plane (under half its points within, or that σ over twice the
//!    scan's noise) is left alone;
//! 2. the points binned on the plane into square cells of three point
//!    spacings; a cell is **off the plane** when its mean residual is more
//!    than five of its standard errors from 0 and at least half the step
//!    asked for (`relief_step_m`, default twice the noise);
//! 3. cells off the plane on one side, joined across edges and corners,
//!    make a candidate layer; it is a **layer** when it holds at least
//!    `min_group_points` points, stands at least the step off (the median
//!    residual of its points), is flat there (their spread about that
//!    median under twice the noise) and ends in a step (two cells beyond
//!    it the mean residual is no more than 15 % of the offset toward it;
//!    the step, from there to the layer, is at least the least step): a
//!    bulge, a corner's other wall or a table's legs fail this;
//! 4. the layer's cells and the cells beside them give up the points that
//!    are nearer the layer than the surface around it, each point judged by the mean
//!    residual of its eight nearest neighbours on the plane, which puts the
//!    layer's edge within a spacing or so of the step.
//!
//! Each layer becomes a group of its own ([`Layer`] in the report).

use std::collections::{HashMap, HashSet, VecDeque};

use nalgebra::Vector3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::normals::{LocalSurface, median, nearest, point_tree, robust_spread};
use crate::cloud::Scan;
use crate::mesh::plane_fit::PlaneFit;
use crate::segmentation::UNASSIGNED;

/// A cell's mean residual must be this many standard errors off the plane.
const CELL_SIGMAS: f64 = 5.0;
/// The fewest points in a cell that is judged.
const CELL_POINTS: usize = 4;
/// Cell side, in point spacings.
const CELL_SPACINGS: f64 = 3.0;
/// Neighbours whose mean residual judges a point at a layer's edge.
const EDGE_NEIGHBOURS: usize = 8;
/// Robust plane refits.
const REFITS: usize = 3;
/// Two cells beyond a layer the mean residual may lean toward the layer by
/// no more than this share of its offset: a step, not a bend.
const BACK_ON_PLANE: f64 = 0.15;

/// `cells` and the cells beside them (edges and corners).
fn dilate<'a>(cells: impl IntoIterator<Item = &'a (i64, i64)>) -> HashSet<(i64, i64)> {
    let mut out = HashSet::new();
    for c in cells {
        for dx in -1..=1 {
            for dy in -1..=1 {
                out.insert((c.0 + dx, c.1 + dy));
            }
        }
    }
    out
}

/// A layer found in a group and made a group of its own; groups are
/// `G`: raw numbers as the pass finds them, names in the report.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Layer<G = String> {
    /// The group it was found in.
    pub from: G,
    /// Its own group.
    pub group: G,
    /// The step from the surface around it (two cells out) to its median
    /// point, along the group's plane's normal, m: positive toward the side
    /// the scanners saw the plane from.
    pub offset_m: f64,
    /// Its points.
    pub points: usize,
    /// Its points' spread about that offset (1.4826 × median absolute
    /// deviation), m.
    pub spread_m: f64,
}

impl Layer<u32> {
    /// The same layer with its groups named by `name`.
    pub fn named(&self, name: impl Fn(u32) -> String) -> Layer {
        Layer {
            from: name(self.from),
            group: name(self.group),
            offset_m: self.offset_m,
            points: self.points,
            spread_m: self.spread_m,
        }
    }
}

/// What the pass needs to know.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReliefSettings {
    /// The scans' noise across a surface, m.
    pub noise_m: f64,
    /// The least step a layer stands off its plane, m.
    pub step_m: f64,
    /// The fewest points in a layer.
    pub min_points: usize,
}

/// A layer before it has a group number: its points and figures.
struct Found {
    from: u32,
    points: Vec<(u32, u32)>,
    offset_m: f64,
    spread_m: f64,
}

/// Finds layers in every planar group of `labels` (groups `0..groups`) and
/// gives each a new group from `groups` on; returns them in that order (the
/// caller names them once groups are numbered: [`Layer::named`]).
pub fn split_layers(
    scans: &[Scan],
    surfaces: &[LocalSurface],
    labels: &mut [Vec<u32>],
    groups: usize,
    settings: &ReliefSettings,
) -> Vec<Layer<u32>> {
    let mut members: Vec<Vec<(u32, u32)>> = vec![Vec::new(); groups];
    for (s, scan_labels) in labels.iter().enumerate() {
        for (i, &g) in scan_labels.iter().enumerate() {
            if g != UNASSIGNED && (g as usize) < groups {
                members[g as usize].push((s as u32, i as u32));
            }
        }
    }
    let found: Vec<Found> = members
        .par_iter()
        .enumerate()
        .flat_map_iter(|(g, points)| layers_of(g as u32, points, scans, surfaces, settings))
        .collect();
    let mut layers = Vec::with_capacity(found.len());
    for (k, f) in found.into_iter().enumerate() {
        let group = (groups + k) as u32;
        for &(s, i) in &f.points {
            labels[s as usize][i as usize] = group;
        }
        layers.push(Layer {
            from: f.from,
            group,
            offset_m: f.offset_m,
            points: f.points.len(),
            spread_m: f.spread_m,
        });
    }
    layers
}

/// The group's plane fitted to the points within 3 σ of it; `None` when the
/// group is not a plane.
fn robust_plane(positions: &[Vector3<f64>], noise_m: f64) -> Option<PlaneFit> {
    let mut fit = PlaneFit::of(positions)?;
    let mut inside: Vec<Vector3<f64>> = Vec::with_capacity(positions.len());
    for _ in 0..REFITS {
        let residuals = positions.iter().map(|p| fit.distance(p));
        let sigma = robust_spread(residuals, 0.0).max(noise_m);
        inside.clear();
        inside.extend(positions.iter().filter(|p| fit.distance(p).abs() <= 3.0 * sigma));
        fit = PlaneFit::of(&inside)?;
    }
    // Judged by the median absolute residual: the layers it is looking
    // for are within 3 σ and would inflate an RMS.
    let spread = robust_spread(positions.iter().map(|p| fit.distance(p)), 0.0);
    let planar = 2 * inside.len() >= positions.len() && spread <= 2.0 * noise_m;
    planar.then_some(fit)
}

/// The layers of one group.
fn layers_of(
    group: u32,
    points: &[(u32, u32)],
    scans: &[Scan],
    surfaces: &[LocalSurface],
    settings: &ReliefSettings,
) -> Vec<Found> {
    let noise = settings.noise_m;
    if points.len() < 2 * settings.min_points || noise <= 0.0 {
        return Vec::new();
    }
    let positions: Vec<Vector3<f64>> = points
        .iter()
        .map(|&(s, i)| scans[s as usize].positions[i as usize])
        .collect();
    let Some(plane) = robust_plane(&positions, noise) else {
        return Vec::new();
    };
    // The side the scanners saw the plane from is positive.
    let plane = match &scans[points[0].0 as usize].pose {
        Some(pose) => plane.facing(&pose.origin),
        None => plane,
    };
    let spacings: Vec<f64> = points
        .iter()
        .map(|&(s, i)| f64::from(surfaces[s as usize].spacing_m[i as usize]))
        .filter(|v| v.is_finite() && *v > 0.0)
        .collect();
    let cell = CELL_SPACINGS * median(spacings);
    if cell <= 0.0 {
        return Vec::new();
    }
    let residual: Vec<f64> = positions.iter().map(|p| plane.distance(p)).collect();
    let on_plane: Vec<[f64; 2]> = positions.iter().map(|p| plane.project(p)).collect();
    let mut cells: HashMap<(i64, i64), Vec<u32>> = HashMap::new();
    for (k, q) in on_plane.iter().enumerate() {
        let key = ((q[0] / cell).floor() as i64, (q[1] / cell).floor() as i64);
        cells.entry(key).or_default().push(k as u32);
    }
    // Cells off the plane, by side.
    let mut off: HashMap<(i64, i64), i8> = HashMap::new();
    for (&key, members) in &cells {
        let n = members.len();
        if n < CELL_POINTS {
            continue;
        }
        let mean = members.iter().map(|&k| residual[k as usize]).sum::<f64>() / n as f64;
        let least = (CELL_SIGMAS * noise / (n as f64).sqrt()).max(0.5 * settings.step_m);
        if mean.abs() >= least {
            off.insert(key, if mean > 0.0 { 1 } else { -1 });
        }
    }
    let mut layers = Vec::new();
    let mut seen: HashSet<(i64, i64)> = HashSet::new();
    let mut keys: Vec<(i64, i64)> = off.keys().copied().collect();
    keys.sort_unstable();
    let mut tree = None;
    let mut taken = vec![false; points.len()];
    for start in keys {
        if seen.contains(&start) {
            continue;
        }
        let side = off[&start];
        let mut component = Vec::new();
        let mut queue = VecDeque::from([start]);
        seen.insert(start);
        while let Some(c) = queue.pop_front() {
            component.push(c);
            for dx in -1..=1 {
                for dy in -1..=1 {
                    let n = (c.0 + dx, c.1 + dy);
                    if off.get(&n) == Some(&side) && seen.insert(n) {
                        queue.push_back(n);
                    }
                }
            }
        }
        let inner: Vec<f64> = component
            .iter()
            .flat_map(|c| cells[c].iter().map(|&k| residual[k as usize]))
            .collect();
        if inner.len() < settings.min_points {
            continue;
        }
        let offset = median(inner.clone());
        let spread = robust_spread(inner.iter().copied(), offset);
        if offset.abs() < settings.step_m || spread > 2.0 * noise {
            continue;
        }
        // A step, not a bend: two cells out, the surface is back on the plane.
        let near = dilate(&component);
        let ring = dilate(&near);
        let outside: Vec<f64> = ring
            .difference(&near)
            .filter_map(|c| cells.get(c))
            .flat_map(|m| m.iter().map(|&k| residual[k as usize]))
            .collect();
        let Some(beyond) = (outside.len() >= CELL_POINTS).then(|| outside.iter().sum::<f64>() / outside.len() as f64)
        else {
            continue;
        };
        // The step from the surface around to the layer.
        let step = offset - beyond;
        if beyond * offset.signum() > BACK_ON_PLANE * offset.abs() || step.abs() < settings.step_m {
            continue;
        }
        // The layer's cells and their neighbours give up the points nearer
        // the layer than the plane, judged on their neighbours' mean.
        let tree = tree.get_or_insert_with(|| {
            let flat: Vec<Vector3<f64>> = on_plane.iter().map(|q| Vector3::new(q[0], q[1], 0.0)).collect();
            point_tree(&flat)
        });
        let mut candidates: Vec<(i64, i64)> = near.into_iter().collect();
        candidates.sort_unstable();
        let mut chosen = Vec::new();
        for c in candidates {
            let Some(members) = cells.get(&c) else { continue };
            for &k in members {
                let k = k as usize;
                if taken[k] {
                    continue;
                }
                let q = Vector3::new(on_plane[k][0], on_plane[k][1], 0.0);
                let around = nearest(tree, &q, EDGE_NEIGHBOURS);
                let mean = around.iter().map(|&(_, j)| residual[j]).sum::<f64>() / around.len().max(1) as f64;
                if (mean - offset).abs() < (mean - beyond).abs() {
                    taken[k] = true;
                    chosen.push(k);
                }
            }
        }
        if chosen.len() >= settings.min_points {
            layers.push(Found {
                from: group,
                points: chosen.iter().map(|&k| points[k]).collect(),
                offset_m: step,
                spread_m: spread,
            });
        } else {
            for k in chosen {
                taken[k] = false;
            }
        }
    }
    layers
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::segment::normals::local_surface;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, Normal};

    const NOISE: f64 = 0.003;

    fn settings() -> ReliefSettings {
        ReliefSettings {
            noise_m: NOISE,
            step_m: 2.0 * NOISE,
            min_points: 30,
        }
    }

    /// A 3 m × 2 m wall in the plane y = 0 seen from y > 0, points 2 cm
    /// apart with 3 mm noise along y; `height(x, z)` moves a point off the
    /// wall. Returns the split and whether each point was truly raised.
    fn wall(height: impl Fn(f64, f64) -> f64) -> (Vec<Layer<u32>>, Vec<u32>, Vec<bool>) {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let normal = Normal::new(0.0, NOISE).unwrap();
        let (mut positions, mut raised) = (Vec::new(), Vec::new());
        for i in 0..150 {
            for k in 0..100 {
                let (x, z) = (i as f64 * 0.02, k as f64 * 0.02);
                let h = height(x, z);
                positions.push(Vector3::new(x, h + normal.sample(&mut rng), z));
                raised.push(h != 0.0);
            }
        }
        let mut scan = Scan::from_positions("wall", positions);
        scan.pose = Some(crate::cloud::ScannerPose {
            origin: Vector3::new(1.5, 4.0, 1.0),
            rotation: nalgebra::Rotation3::identity(),
        });
        let surface = local_surface(&scan);
        let mut labels = vec![vec![0u32; scan.len()]];
        let layers = split_layers(&[scan], &[surface], &mut labels, 1, &settings());
        (layers, labels.remove(0), raised)
    }

    fn poster(x: f64, z: f64) -> bool {
        (1.0..1.6).contains(&x) && (0.5..1.3).contains(&z)
    }

    #[test]
    fn a_poster_one_centimetre_proud_of_a_wall_is_split_at_its_edge() {
        let (layers, labels, raised) = wall(|x, z| if poster(x, z) { 0.01 } else { 0.0 });
        assert_eq!(layers.len(), 1, "{layers:?}");
        let layer = &layers[0];
        assert_eq!((layer.from, layer.group), (0, 1));
        // Toward the scanner, within a millimetre; flat to the noise.
        assert!((layer.offset_m - 0.01).abs() < 0.001, "{layer:?}");
        assert!(layer.spread_m < 1.5 * NOISE, "{layer:?}");
        let wrong = labels.iter().zip(&raised).filter(|(l, r)| (**l == 1) != **r).count();
        let poster_points = raised.iter().filter(|r| **r).count();
        // 30 × 40 = 1200 poster points, 136 of them along its edge; at most
        // 2 % of them on the wrong side (measured 12, all at the edge).
        assert_eq!(poster_points, 1200);
        assert!(wrong <= 24, "{wrong} points on the wrong side of the step");
    }

    #[test]
    fn a_recess_is_a_layer_with_a_negative_offset() {
        let (layers, _, _) = wall(|x, z| if poster(x, z) { -0.02 } else { 0.0 });
        assert_eq!(layers.len(), 1, "{layers:?}");
        assert!((layers[0].offset_m + 0.02).abs() < 0.001, "{:?}", layers[0]);
    }

    #[test]
    fn a_step_under_the_least_one_is_left_in_the_wall() {
        // 4 mm against the least step of 6 mm (twice the noise).
        let (layers, labels, _) = wall(|x, z| if poster(x, z) { 0.004 } else { 0.0 });
        assert!(layers.is_empty(), "{layers:?}");
        assert!(labels.iter().all(|&l| l == 0));
    }

    #[test]
    fn a_gentle_bulge_and_a_curved_sheet_are_not_layers() {
        // A 1.5 cm bulge over the whole wall's middle: a bend, not a step.
        let (layers, _, _) = wall(|x, z| {
            let r2 = (x - 1.5).powi(2) + (z - 1.0).powi(2);
            0.015 * (-r2 / 0.18).exp()
        });
        assert!(layers.is_empty(), "{layers:?}");
        // A cylinder of 1 m radius over 90°: no plane.
        let (layers, _, _) = wall(|x, _| 1.0 - (1.0 - ((x - 1.5) / 1.6).powi(2)).max(0.0).sqrt());
        assert!(layers.is_empty(), "{layers:?}");
    }
}

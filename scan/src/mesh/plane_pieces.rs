//! A group that is several planes (a table's top and sides, a box, the two
//! faces of a wall's corner that one segment kept together) split into
//! them, so that each is meshed as a planar polygon
//! ([`super::planar_polygon`]) rather than from its noisy points one by
//! one: the thesis's polygon fit (§2.4) for the planes most of a building
//! and a room are made of.
//!
//! Greedy consensus: among seed points spread over the points not yet
//! taken, the one whose plane (its estimated normal through it) holds the
//! most points (normal within [`NORMAL_DEG`], within `tolerance` of the
//! plane) starts a piece; the piece's plane is refitted to those points
//! and takes every remaining point that agrees with it; repeat. Points
//! left (near edges, where normals blend two faces) go to the nearest
//! plane within the tolerance. A piece is one connected patch: its points
//! linked within [`LINK_SPACINGS`] point spacings, the largest such set
//! kept (a plane through a table top's edge strip and the underside of a
//! ball resting on it would otherwise be meshed across the empty space
//! between them). The split
//! is used only when the pieces are planar (RMS within the planar limit)
//! and together hold nearly all the points ([`COVERED`]); a curved group
//! (a sphere, a curtain) is not split and is meshed as before.

use nalgebra::Vector3;

use super::ball_pivoting::{estimate_normals, nearest_spacing};
use super::plane_fit::PlaneFit;
use crate::segment::normals::{PointTree, point_tree};

/// The largest set of `members` (indices into the tree's points) linked
/// within `link` of each other.
fn largest_patch(tree: &PointTree, points: &[Vector3<f64>], members: &[usize], link: f64) -> Vec<usize> {
    let mut label = vec![u32::MAX; points.len()];
    for &i in members {
        label[i] = u32::MAX - 1;
    }
    let mut best: Vec<usize> = Vec::new();
    for &start in members {
        if label[start] != u32::MAX - 1 {
            continue;
        }
        label[start] = start as u32;
        let mut patch = vec![start];
        let mut k = 0;
        while k < patch.len() {
            let p = points[patch[k]];
            k += 1;
            for n in tree.within_unsorted::<kiddo::SquaredEuclidean>(&[p.x, p.y, p.z], link * link) {
                let j = n.item as usize;
                if label[j] == u32::MAX - 1 {
                    label[j] = start as u32;
                    patch.push(j);
                }
            }
        }
        if patch.len() > best.len() {
            best = patch;
        }
    }
    best.sort_unstable();
    best
}

/// Largest angle between a point's normal and its piece's, degrees.
pub const NORMAL_DEG: f64 = 15.0;
/// The share of the group's points the pieces must hold. The rest (the
/// 5 cm edges of a table top, a few points each on a coarse scan, whose
/// normals blend the top's and the floor's views) is left out and counted
/// ([`super::GroupMesh::unmeshed_points`]).
pub const COVERED: f64 = 0.9;
/// The most pieces a group is split into.
pub const MAX_PIECES: usize = 12;
/// A piece must span at least this many tolerances along its longest
/// in-plane direction: a plane 2 cm thick is a plane only over metres (a
/// table's top, a wall); over a 15 cm bunny, a tolerance that wide would
/// make facets of a curved body.
pub const MIN_EXTENT_OVER_TOLERANCE: f64 = 20.0;
/// Points of one piece are linked when closer than this many times the
/// group's point spacing (its median nearest-neighbour distance): wide
/// enough for a table top seen at a grazing angle, whose rows lie several
/// spacings apart along the beams.
pub const LINK_SPACINGS: f64 = 4.0;
/// Seed points tried per piece.
const SEEDS: usize = 64;

/// One planar piece: its points (indices into the group's) and plane.
#[derive(Debug, Clone)]
pub struct PlanePiece {
    /// Indices of its points.
    pub points: Vec<usize>,
    /// Its plane (least squares over them).
    pub plane: PlaneFit,
}

/// Splits `points` (seen from `views`, one per point) into planar pieces of
/// at least `min_points` points within `tolerance_m` of their planes, of
/// RMS at most `planar_rms_m` and spanning [`MIN_EXTENT_OVER_TOLERANCE`]
/// tolerances; `None` when they are not such planes (the
/// pieces hold under [`COVERED`] of the points). One piece is a plane with
/// a few stray points (a table top with its edge strips) that pulled the
/// whole group's fit past the planar limit.
pub fn plane_pieces(
    points: &[Vector3<f64>],
    views: &[Vector3<f64>],
    min_points: usize,
    tolerance_m: f64,
    planar_rms_m: f64,
) -> Option<Vec<PlanePiece>> {
    let min_points = min_points.max(3);
    if points.len() < 2 * min_points {
        return None;
    }
    let spacing = nearest_spacing(points);
    if !(spacing > 0.0 && spacing.is_finite()) {
        return None;
    }
    let normals = estimate_normals(points, views, 2.5 * spacing);
    let tree = point_tree(points);
    let link = LINK_SPACINGS * spacing;
    let cos = NORMAL_DEG.to_radians().cos();
    let mut taken = vec![false; points.len()];
    let mut pieces = Vec::new();
    // Point i agrees with the plane through `origin` with unit `normal`.
    let agrees = |i: usize, origin: &Vector3<f64>, normal: &Vector3<f64>| {
        normals[i].dot(normal).abs() >= cos && (points[i] - origin).dot(normal).abs() <= tolerance_m
    };
    while pieces.len() < MAX_PIECES {
        let remaining: Vec<usize> = (0..points.len()).filter(|&i| !taken[i]).collect();
        if remaining.len() < min_points {
            break;
        }
        let step = (remaining.len() / SEEDS).max(1);
        let best = remaining
            .iter()
            .step_by(step)
            .filter(|&&s| normals[s].norm_squared() > 0.5)
            .map(|&s| {
                let (p, n) = (points[s], normals[s]);
                let count = remaining.iter().filter(|&&i| agrees(i, &p, &n)).count();
                (count, s)
            })
            .max_by_key(|&(count, s)| (count, std::cmp::Reverse(s)));
        let Some((count, seed)) = best else { break };
        if count < min_points {
            break;
        }
        let (p, n) = (points[seed], normals[seed]);
        let mut members: Vec<usize> = remaining.iter().copied().filter(|&i| agrees(i, &p, &n)).collect();
        let mut plane = None;
        for _ in 0..2 {
            let pts: Vec<Vector3<f64>> = members.iter().map(|&i| points[i]).collect();
            let Some(fit) = PlaneFit::of(&pts) else { break };
            members = remaining
                .iter()
                .copied()
                .filter(|&i| agrees(i, &fit.centroid, &fit.normal))
                .collect();
            plane = Some(fit);
        }
        let members = largest_patch(&tree, points, &members, link);
        let pts: Vec<Vector3<f64>> = members.iter().map(|&i| points[i]).collect();
        let Some(fit) = PlaneFit::of(&pts).or(plane) else { break };
        let along: Vec<f64> = members.iter().map(|&i| fit.project(&points[i])[0]).collect();
        let extent = along.iter().copied().fold(f64::NEG_INFINITY, f64::max)
            - along.iter().copied().fold(f64::INFINITY, f64::min);
        if members.len() < min_points || fit.rms_m > planar_rms_m || extent < MIN_EXTENT_OVER_TOLERANCE * tolerance_m {
            break;
        }
        for &i in &members {
            taken[i] = true;
        }
        pieces.push(PlanePiece {
            points: members,
            plane: fit,
        });
    }
    // Points near an edge have normals blended from both faces; each still
    // lies on one of them: the nearest plane within the tolerance takes it.
    for (i, p) in points.iter().enumerate() {
        if taken[i] {
            continue;
        }
        let nearest = pieces
            .iter()
            .enumerate()
            .map(|(k, piece)| (piece.plane.distance(p).abs(), k))
            .filter(|&(d, _)| d <= tolerance_m)
            .min_by(|a, b| a.0.total_cmp(&b.0));
        if let Some((_, k)) = nearest {
            pieces[k].points.push(i);
            taken[i] = true;
        }
    }
    let held: usize = pieces.iter().map(|p| p.points.len()).sum();
    (!pieces.is_empty() && held as f64 >= COVERED * points.len() as f64).then_some(pieces)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Points on a 1 × 1 m top at z = 0.75 and its four 0.75 m sides, on a
    /// 2 cm grid, with 3 mm of deterministic noise across each face.
    fn table() -> (Vec<Vector3<f64>>, Vec<Vector3<f64>>) {
        let mut points = Vec::new();
        let wobble = |k: usize| {
            0.003
                * ((k as f64 * 12.9898).sin() * 43758.5453)
                    .rem_euclid(1.0)
                    .mul_add(2.0, -1.0)
        };
        let n = 50;
        for i in 0..=n {
            for j in 0..=n {
                let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                let k = points.len();
                points.push(Vector3::new(u, v, 0.75 + wobble(k)));
            }
        }
        for i in 0..=n {
            for j in 1..37 {
                let (u, z) = (i as f64 / n as f64, 0.75 - j as f64 * 0.02);
                for (x, y, nx, ny) in [
                    (u, 0.0, 0.0, 1.0),
                    (u, 1.0, 0.0, 1.0),
                    (0.0, u, 1.0, 0.0),
                    (1.0, u, 1.0, 0.0),
                ] {
                    let k = points.len();
                    let w = wobble(k);
                    points.push(Vector3::new(x + nx * w, y + ny * w, z));
                }
            }
        }
        let views = points
            .iter()
            .map(|p| Vector3::new(2.0 * p.x - 0.5, 2.0 * p.y - 0.5, 2.0))
            .collect();
        (points, views)
    }

    #[test]
    fn a_table_is_split_into_its_top_and_sides() {
        let (points, views) = table();
        let pieces = plane_pieces(&points, &views, 10, 0.02, 0.01).expect("split");
        assert_eq!(
            pieces.len(),
            5,
            "{:?}",
            pieces.iter().map(|p| p.points.len()).collect::<Vec<_>>()
        );
        let top = &pieces[0];
        assert!(top.plane.normal.z.abs() > 0.999, "{:?}", top.plane.normal);
        assert!((top.plane.centroid.z - 0.75).abs() < 0.002);
        for p in &pieces {
            // Each piece within the noise of its plane (3 mm uniform:
            // σ = 1.7 mm).
            assert!(p.plane.rms_m < 0.003, "{}", p.plane.rms_m);
        }
        let held: usize = pieces.iter().map(|p| p.points.len()).sum();
        assert!(held as f64 >= 0.98 * points.len() as f64, "{held} of {}", points.len());
    }

    /// Two 1 × 1 m tops at one height, 0.5 m apart along x (two tables
    /// of one group), each with 3 mm of noise; seen from above.
    #[test]
    fn coplanar_patches_apart_are_pieces_of_their_own() {
        let mut points = Vec::new();
        for x0 in [0.0, 1.5] {
            for i in 0..=40 {
                for j in 0..=40 {
                    let k = points.len() as f64;
                    let w = 0.003 * ((k * 12.9898).sin() * 43758.5453).rem_euclid(1.0).mul_add(2.0, -1.0);
                    points.push(Vector3::new(x0 + i as f64 / 40.0, j as f64 / 40.0, 0.75 + w));
                }
            }
        }
        let views = vec![Vector3::new(1.25, 0.5, 2.5); points.len()];
        let pieces = plane_pieces(&points, &views, 10, 0.02, 0.01).expect("split");
        assert_eq!(
            pieces.len(),
            2,
            "{:?}",
            pieces.iter().map(|p| p.points.len()).collect::<Vec<_>>()
        );
        for piece in &pieces {
            // All of one top: no piece spans the 0.5 m gap.
            let xs: Vec<f64> = piece.points.iter().map(|&i| points[i].x).collect();
            let (lo, hi) = xs
                .iter()
                .fold((f64::MAX, f64::MIN), |(lo, hi), &x| (lo.min(x), hi.max(x)));
            assert!(hi - lo <= 1.0 + 1e-9, "a piece spans x {lo:.2}..{hi:.2}");
            assert_eq!(piece.points.len(), 41 * 41);
        }
    }

    #[test]
    fn a_small_curved_body_is_not_made_of_facets() {
        // The table shrunk to 15 cm: its planes are as flat as before, but
        // span under 20 tolerances (40 cm).
        let (points, views) = table();
        let small: Vec<Vector3<f64>> = points.iter().map(|p| p * 0.15).collect();
        assert!(plane_pieces(&small, &views, 10, 0.02, 0.01).is_none());
        assert!(plane_pieces(&small, &views, 10, 0.002, 0.01).is_some());
    }

    #[test]
    fn a_sphere_is_not_split() {
        let mut points = Vec::new();
        for i in 0..40 {
            for j in 0..80 {
                let (t, f) = (
                    std::f64::consts::PI * (i as f64 + 0.5) / 40.0,
                    std::f64::consts::TAU * j as f64 / 80.0,
                );
                points.push(Vector3::new(t.sin() * f.cos(), t.sin() * f.sin(), t.cos()) * 0.5);
            }
        }
        let views = vec![Vector3::new(3.0, 0.0, 0.0); points.len()];
        assert!(plane_pieces(&points, &views, 10, 0.02, 0.01).is_none());
    }
}

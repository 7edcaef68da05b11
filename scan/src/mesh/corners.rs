//! Planar groups that meet: their outlines closed up to the common edge.
//!
//! A wall's points stop short of the corner where it meets the next wall,
//! the floor or the ceiling: the last beams before the corner see both
//! surfaces in one window, and their normals and groups go either way. So
//! each polygon ([`super::planar_polygon`]) ends a few centimetres before
//! the edge it shares, and the room gets a slit along every edge, through
//! which a renderer's rays leave (the inverse global illumination then sees
//! less light coming back than there is). This pass, ours and not the
//! thesis's (§2.4 meshes each group on its own), moves every outline
//! corner (not a hole's: a hole's edge is a shadow or an opening) that lies within [`REACH_SPACINGS`] point spacings of another,
//! non-parallel planar group (its plane and its polygon) onto that plane,
//! along its own plane: onto the edge line with one such neighbour, onto
//! the point the three planes share with two (a room's corner). Polygons
//! parallel to each other (a poster on its wall) are left as they are.

use nalgebra::{Matrix3, Vector3};

use super::hausdorff::closest_on_triangle;
use super::plane_fit::PlaneFit;
use super::{GroupMesh, MeshMethod};

/// A corner moves when another group's polygon and plane are within this
/// many of its group's point spacings.
pub const REACH_SPACINGS: f64 = 4.0;
/// Triangles under this area (twice it, m²) after the moves are dropped.
const DEGENERATE_M2: f64 = 1e-9;
/// Planes closer than this to parallel, degrees, do not meet.
const LEAST_ANGLE_DEG: f64 = 20.0;

/// A planar group's plane and reach.
struct Face {
    mesh: usize,
    plane: PlaneFit,
    reach: f64,
}

/// The distance from `p` to `mesh`'s nearest triangle.
fn distance_to(mesh: &super::TriangleMesh, p: &Vector3<f64>) -> f64 {
    (0..mesh.triangles.len())
        .map(|t| {
            let [a, b, c] = mesh.corners(t);
            (closest_on_triangle(p, &a, &b, &c) - p).norm()
        })
        .fold(f64::INFINITY, f64::min)
}

/// Moves the corners of `meshes`' planar polygons onto the planes of the
/// planar groups they meet; returns how many corners moved.
pub fn close_corners(meshes: &mut [GroupMesh]) -> usize {
    let faces: Vec<Face> = meshes
        .iter()
        .enumerate()
        .filter(|(_, m)| m.method == MeshMethod::PlanarPolygon && !m.mesh.triangles.is_empty())
        .filter_map(|(k, m)| {
            let plane = PlaneFit::of(&m.mesh.positions)?;
            let reach = REACH_SPACINGS * m.spacing_m?;
            (reach > 0.0).then_some(Face { mesh: k, plane, reach })
        })
        .collect();
    let cos_least = LEAST_ANGLE_DEG.to_radians().cos();
    let mut moves: Vec<(usize, usize, Vector3<f64>)> = Vec::new();
    for a in &faces {
        let na = a.plane.normal;
        let outer = &meshes[a.mesh].outer;
        for (v, p) in meshes[a.mesh].mesh.positions.iter().enumerate() {
            // Holes' corners stay: a shadow's edge is not a meeting.
            if !outer.get(v).copied().unwrap_or(false) {
                continue;
            }
            // The other planes this corner is near, nearest first.
            let mut near: Vec<(f64, &Face)> = faces
                .iter()
                .filter(|b| b.mesh != a.mesh && b.plane.normal.dot(&na).abs() < cos_least)
                .filter_map(|b| {
                    let d = b.plane.distance(p);
                    (d.abs() <= a.reach && distance_to(&meshes[b.mesh].mesh, p) <= 2.0 * a.reach).then_some((d, b))
                })
                .collect();
            near.sort_by(|x, y| x.0.abs().total_cmp(&y.0.abs()));
            let on_edge = |(d, b): (f64, &Face)| {
                let t = b.plane.normal - b.plane.normal.dot(&na) * na;
                let along = t.dot(&b.plane.normal);
                (along.abs() > 1e-9).then(|| p - d / along * t)
            };
            let target = match near.as_slice() {
                [] => None,
                [one] => on_edge(*one),
                [first, second, ..] => {
                    let (b, c) = (first.1, second.1);
                    let m =
                        Matrix3::from_rows(&[na.transpose(), b.plane.normal.transpose(), c.plane.normal.transpose()]);
                    let rhs = Vector3::new(
                        na.dot(&a.plane.centroid),
                        b.plane.normal.dot(&b.plane.centroid),
                        c.plane.normal.dot(&c.plane.centroid),
                    );
                    // Two planes nearly parallel to each other give no
                    // corner: the nearer's edge only.
                    match (m.determinant().abs() > 0.1).then(|| m.lu().solve(&rhs)).flatten() {
                        Some(corner) => Some(corner),
                        None => on_edge(*first),
                    }
                }
            };
            if let Some(q) = target.filter(|q| (q - p).norm() <= 1.5 * a.reach) {
                moves.push((a.mesh, v, q));
            }
        }
    }
    let before: Vec<Option<super::TriangleMesh>> = meshes
        .iter()
        .enumerate()
        .map(|(k, m)| moves.iter().any(|mv| mv.0 == k).then(|| m.mesh.clone()))
        .collect();
    for &(m, v, q) in &moves {
        meshes[m].mesh.positions[v] = q;
        meshes[m].corners_moved += 1;
    }
    for (mesh, before) in meshes.iter_mut().zip(before) {
        let Some(before) = before else { continue };
        // A triangle turned over (a corner moved past its neighbour) gets
        // its corners back, until none is.
        loop {
            let mut undone = 0;
            for t in 0..before.triangles.len() {
                if before.area_normal(t).dot(&mesh.mesh.area_normal(t)) >= -DEGENERATE_M2 {
                    continue;
                }
                for v in before.triangles[t] {
                    let v = v as usize;
                    if mesh.mesh.positions[v] != before.positions[v] {
                        mesh.mesh.positions[v] = before.positions[v];
                        mesh.corners_moved -= 1;
                        undone += 1;
                    }
                }
            }
            if undone == 0 {
                break;
            }
        }
        // Corners moved onto one edge line can leave triangles of no area.
        let keep: Vec<[u32; 3]> = (0..mesh.mesh.triangles.len())
            .filter(|&t| mesh.mesh.area_normal(t).norm() > DEGENERATE_M2)
            .map(|t| mesh.mesh.triangles[t])
            .collect();
        mesh.mesh.triangles = keep;
    }
    meshes.iter().map(|m| m.corners_moved).sum()
}

#[cfg(test)]
mod tests {
    use super::super::{MeshOptions, mesh_groups};
    use super::*;
    use crate::cloud::Scan;
    use crate::segmentation::Segmentation;

    #[test]
    fn a_floor_and_a_wall_that_stop_short_meet_at_their_edge() {
        // A floor (z = 0) sampled to 5 cm short of a wall (y = 2), and the
        // wall sampled from 5 cm above the floor, both 2 cm apart; a poster
        // on the wall 1 cm proud of it (parallel: it stays as it is).
        let mut positions = Vec::new();
        let mut labels = Vec::new();
        for i in 0..=100 {
            let x = i as f64 * 0.02;
            for k in 0..=97 {
                positions.push(Vector3::new(x, k as f64 * 0.02, 0.0));
                labels.push(0);
            }
            for k in 0..48 {
                positions.push(Vector3::new(x, 2.0, 0.05 + k as f64 * 0.02));
                labels.push(1);
            }
        }
        for i in 0..30 {
            for k in 0..20 {
                positions.push(Vector3::new(0.5 + i as f64 * 0.02, 1.99, 0.4 + k as f64 * 0.02));
                labels.push(2);
            }
        }
        let scan = Scan::from_positions("corner", positions);
        let seg = Segmentation {
            labels: vec![labels],
            names: vec!["floor".into(), "wall".into(), "poster".into()],
        };
        let meshes = mesh_groups(&[scan], &seg, &MeshOptions::default()).unwrap();
        let extent = |m: &GroupMesh, axis: usize| {
            m.mesh
                .positions
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                    (lo.min(p[axis]), hi.max(p[axis]))
                })
        };
        assert!(meshes.iter().all(|m| m.method == MeshMethod::PlanarPolygon));
        // The floor reaches the wall and the wall the floor; the floor's
        // other sides and the wall's top, near nothing, stay.
        assert!(
            (extent(&meshes[0], 1).1 - 2.0).abs() < 1e-9,
            "{:?}",
            extent(&meshes[0], 1)
        );
        assert!(extent(&meshes[0], 1).0.abs() < 1e-9);
        assert!(extent(&meshes[1], 2).0.abs() < 1e-9, "{:?}", extent(&meshes[1], 2));
        assert!((extent(&meshes[1], 2).1 - 0.99).abs() < 1e-9);
        assert!((meshes[0].mesh.area() - 4.0).abs() < 1e-6, "{}", meshes[0].mesh.area());
        assert!(
            (meshes[1].mesh.area() - 2.0 * 0.99).abs() < 1e-6,
            "{}",
            meshes[1].mesh.area()
        );
        assert_eq!(meshes[2].corners_moved, 0);
        assert!(
            (meshes[2].mesh.area() - 0.58 * 0.38).abs() < 1e-6,
            "{}",
            meshes[2].mesh.area()
        );
    }
}

//! A planar group's mesh: the least-squares plane ([`PlaneFit`]), the
//! points projected into it, their outline with holes ([`AlphaShape`]),
//! simplified within a tolerance and triangulated by ear clipping. Most of
//! a building and of a room are planar (thesis §2.5.1 fits "a single plane"
//! to the floor); a polygon is their smallest exact mesh. Edges shared with
//! another surface are then closed ([`super::corners`]); free edges stay at
//! the outermost points (on average about half a spacing inside the
//! surface's true edge).

use nalgebra::Vector3;

use super::outline::{AlphaShape, triangulate};
use super::plane_fit::PlaneFit;
use super::triangle_mesh::TriangleMesh;

/// The planar polygon fit of `points`, its normal facing `viewpoint`:
/// the mesh (empty when the points have no outline) and the plane.
pub fn planar_polygon(
    points: &[Vector3<f64>],
    plane: &PlaneFit,
    alpha_factor: f64,
    tolerance_m: f64,
) -> (TriangleMesh, Option<AlphaShape>, Vec<bool>) {
    let flat: Vec<[f64; 2]> = points.iter().map(|p| plane.project(p)).collect();
    let Some(shape) = AlphaShape::of(&flat, alpha_factor) else {
        return (TriangleMesh::default(), None, Vec::new());
    };
    let mut mesh = TriangleMesh::default();
    let mut outer = Vec::new();
    // An outline cannot be known closer than the points' spacing: simplify
    // within half of it at least, so that a wall sampled a metre apart is a
    // few corners, not a jag at every point.
    let tolerance = tolerance_m.max(0.5 * shape.spacing);
    for polygon in shape.polygons(&flat, tolerance) {
        let (corners, triangles) = triangulate(&polygon);
        // `triangulate` lists the outline's corners first, then the holes'.
        let outline = polygon.exterior().0.len().saturating_sub(1);
        outer.extend((0..corners.len()).map(|k| k < outline));
        mesh.append(&TriangleMesh {
            positions: corners.into_iter().map(|q| plane.lift(q)).collect(),
            triangles,
        });
    }
    (mesh, Some(shape), outer)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_wall_with_a_window_meshes_to_its_area_facing_the_scanner() {
        // The square-with-a-hole on the wall x = 2, seen from the origin,
        // with ±3 mm of alternating noise across it.
        let points: Vec<Vector3<f64>> = super::super::outline::tests::square_with_hole()
            .into_iter()
            .enumerate()
            .map(|(i, [a, b])| Vector3::new(2.0 + if i % 2 == 0 { 0.003 } else { -0.003 }, a, b))
            .collect();
        let viewpoint = Vector3::zeros();
        let plane = PlaneFit::of(&points).unwrap().facing(&viewpoint);
        assert!((plane.rms_m - 0.003).abs() < 1e-4, "{}", plane.rms_m);
        let (mesh, shape, outer) = planar_polygon(&points, &plane, 3.0, 0.005);
        // The outline's 4 corners (a square) come first, then the hole's.
        assert_eq!(outer.iter().filter(|o| **o).count(), 4, "{outer:?}");
        assert!(outer[..4].iter().all(|o| *o), "{outer:?}");
        assert_eq!(shape.unwrap().rings.len(), 2);
        // Area within 2 % of 0.84 m² (the noise tilts the fitted plane a little).
        assert!((mesh.area() / 0.84 - 1.0).abs() < 0.02, "{}", mesh.area());
        for t in 0..mesh.triangles.len() {
            assert!(mesh.area_normal(t).x < 0.0, "triangle {t} faces away from the scanner");
        }
    }
}

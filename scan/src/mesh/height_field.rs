//! The fallback mesh for a curved group of an unorganised cloud: the
//! alpha-shape triangles of the points projected into their best plane,
//! lifted back to the points themselves — a height field over the plane.
//!
//! It is right for a surface that the plane sees once, such as a curtain,
//! a gently curved wall or a vault, and wrong for one that folds over
//! itself (a sphere, a chair): there some triangles turn edge-on or over.
//! Those are counted ([`HeightField::folded`]); a group with more than 1 %
//! of them is meshed by ball pivoting instead ([`super::ball_pivoting`]).

use nalgebra::Vector3;

use super::outline::AlphaShape;
use super::plane_fit::PlaneFit;
use super::triangle_mesh::TriangleMesh;

/// A height-field mesh and how far it is from being one.
#[derive(Debug, Clone, PartialEq)]
pub struct HeightField {
    /// The mesh, facing the plane's normal.
    pub mesh: TriangleMesh,
    /// Triangles whose normal is more than 80° from the plane's.
    pub folded: usize,
}

/// The height field of `points` over `plane` (its normal turned to the
/// viewer), with the alpha shape's `alpha_factor`.
pub fn height_field(points: &[Vector3<f64>], plane: &PlaneFit, alpha_factor: f64) -> HeightField {
    let flat: Vec<[f64; 2]> = points.iter().map(|p| plane.project(p)).collect();
    let Some(shape) = AlphaShape::of(&flat, alpha_factor) else {
        return HeightField {
            mesh: TriangleMesh::default(),
            folded: 0,
        };
    };
    let mesh = TriangleMesh {
        positions: points.to_vec(),
        triangles: shape.triangles,
    }
    .compacted();
    let cos_limit = 80f64.to_radians().cos();
    let folded = (0..mesh.triangles.len())
        .filter(|&t| {
            let n = mesh.area_normal(t);
            n.dot(&plane.normal) <= cos_limit * n.norm() || n.iter().any(|c| c.is_nan())
        })
        .count();
    HeightField { mesh, folded }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_curtain_is_a_height_field_and_a_closed_cylinder_is_not() {
        // A curtain: x = 0.1 sin(2π y / 0.5), y and z over 1 m × 1 m, every 2.5 cm.
        let curtain: Vec<Vector3<f64>> = (0..=40)
            .flat_map(|i| (0..=40).map(move |j| (i, j)))
            .map(|(i, j)| {
                let (y, z) = (i as f64 * 0.025, j as f64 * 0.025);
                Vector3::new(0.1 * (std::f64::consts::TAU * y / 0.5).sin(), y, z)
            })
            .collect();
        let plane = PlaneFit::of(&curtain).unwrap().facing(&Vector3::new(-5.0, 0.5, 0.5));
        let hf = height_field(&curtain, &plane, 3.0);
        assert_eq!(hf.folded, 0);
        assert_eq!(hf.mesh.triangles.len(), 2 * 40 * 40);
        // Every vertex is a sample: the mesh passes through the points.
        assert_eq!(hf.mesh.positions.len(), curtain.len());

        // 240° of a cylinder of radius 0.3 about z: its plane sees the
        // back behind the front.
        let cylinder: Vec<Vector3<f64>> = (-30..=30)
            .flat_map(|i| (0..=20).map(move |j| (i, j)))
            .map(|(i, j)| {
                let a = f64::from(i) * 4f64.to_radians();
                Vector3::new(0.3 * a.cos(), 0.3 * a.sin(), j as f64 * 0.05)
            })
            .collect();
        let plane = PlaneFit::of(&cylinder).unwrap();
        let hf = height_field(&cylinder, &plane, 3.0);
        assert!(
            hf.folded * 100 > hf.mesh.triangles.len(),
            "{} of {}",
            hf.folded,
            hf.mesh.triangles.len()
        );
    }
}

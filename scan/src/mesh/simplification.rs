//! Simplification by quadric error metrics (Garland and Heckbert 1997, the
//! thesis's reference [16]), through meshoptimizer's simplifier (the
//! `meshopt` crate, which vendors its C++): edges are collapsed in order of
//! the quadric error they add until the next collapse would move the
//! surface by more than the target error, in metres. Border edges collapse
//! only along the border, so outlines and holes keep their shape.

use super::triangle_mesh::TriangleMesh;

/// A simplified mesh and what simplification did.
#[derive(Debug, Clone, PartialEq)]
pub struct Simplified {
    /// The simplified mesh.
    pub mesh: TriangleMesh,
    /// Triangles before.
    pub triangles_before: usize,
    /// Triangles after.
    pub triangles_after: usize,
    /// The simplifier's own estimate of the largest deviation it caused,
    /// metres.
    pub error_m: f64,
}

/// `mesh` simplified by quadric error metrics to at most `target_error_m`.
pub fn simplify(mesh: &TriangleMesh, target_error_m: f64) -> Simplified {
    let before = mesh.triangles.len();
    let Some(centre) = mesh.bounding_box_centre() else {
        return Simplified {
            mesh: mesh.clone(),
            triangles_before: 0,
            triangles_after: 0,
            error_m: 0.0,
        };
    };
    // meshoptimizer works in f32: positions about the centre keep
    // millimetres at a kilometre's coordinates.
    let local: Vec<[f32; 3]> = mesh
        .positions
        .iter()
        .map(|p| {
            let d = p - centre;
            [d.x as f32, d.y as f32, d.z as f32]
        })
        .collect();
    let indices: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
    let mut error = 0f32;
    let kept = meshopt::simplify_decoder(
        &indices,
        &local,
        3,
        target_error_m as f32,
        meshopt::SimplifyOptions::ErrorAbsolute,
        Some(&mut error),
    );
    let simplified = TriangleMesh {
        positions: mesh.positions.clone(),
        triangles: kept.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect(),
    }
    .compacted();
    Simplified {
        triangles_after: simplified.triangles.len(),
        mesh: simplified,
        triangles_before: before,
        error_m: f64::from(error),
    }
}

/// A `n × n`-quad grid over the unit square in the plane z = 0, facing +z.
#[cfg(test)]
pub(crate) fn fine_square(n: u32) -> TriangleMesh {
    use nalgebra::Vector3;
    let positions = (0..=n)
        .flat_map(|i| (0..=n).map(move |j| Vector3::new(f64::from(i) / f64::from(n), f64::from(j) / f64::from(n), 0.0)))
        .collect();
    let at = |i: u32, j: u32| i * (n + 1) + j;
    let triangles = (0..n)
        .flat_map(|i| (0..n).map(move |j| (i, j)))
        .flat_map(|(i, j)| {
            [
                [at(i, j), at(i + 1, j), at(i + 1, j + 1)],
                [at(i, j), at(i + 1, j + 1), at(i, j + 1)],
            ]
        })
        .collect();
    TriangleMesh { positions, triangles }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_finely_triangulated_plane_collapses_to_a_handful_of_triangles() {
        let fine = fine_square(40);
        assert_eq!(fine.triangles.len(), 3200);
        let s = simplify(&fine, 1e-3);
        assert_eq!(s.triangles_before, 3200);
        // The square's two triangles, the fewest it can have.
        assert_eq!(s.triangles_after, 2);
        // The simplifier's own estimate counts its border penalty; the true
        // deviation, measured, is nil.
        assert!(s.error_m <= 1e-3, "{}", s.error_m);
        let h = super::super::hausdorff(&s.mesh, super::super::Reference::Mesh(&fine), 0.01).unwrap();
        assert!(h.symmetric_m < 1e-9, "{h:?}");
        assert!((s.mesh.area() - 1.0).abs() < 1e-9, "{}", s.mesh.area());
        assert!(s.mesh.positions.iter().all(|p| p.z == 0.0));
        assert!((0..s.mesh.triangles.len()).all(|t| s.mesh.area_normal(t).z > 0.0));
    }

    #[test]
    fn a_bent_sheet_keeps_its_bend_within_the_target() {
        // The unit square folded along x = 0.5 by 10 cm: z = 0.2 |x − 0.5|.
        let mut sheet = fine_square(40);
        for p in &mut sheet.positions {
            p.z = 0.2 * (p.x - 0.5).abs();
        }
        let s = simplify(&sheet, 1e-3);
        assert!(s.triangles_after <= 16, "{} triangles", s.triangles_after);
        // Exact: the fold line's vertices stay, so the area is unchanged.
        let area = 1.04f64.sqrt();
        assert!((s.mesh.area() - area).abs() < 1e-6, "{} against {area}", s.mesh.area());
    }
}

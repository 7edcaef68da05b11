//! A triangle mesh as data: vertices in the scene frame and triangles as
//! vertex indices, wound counter-clockwise as seen from the side the normal
//! faces (the right-hand rule; the OBJ convention).

use nalgebra::Vector3;

/// Vertices and counter-clockwise triangles.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TriangleMesh {
    /// Vertex positions, scene frame, metres.
    pub positions: Vec<Vector3<f64>>,
    /// Triangles as indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
}

impl TriangleMesh {
    /// The three corners of triangle `t`.
    pub fn corners(&self, t: usize) -> [Vector3<f64>; 3] {
        self.triangles[t].map(|i| self.positions[i as usize])
    }

    /// The (unnormalised) normal of triangle `t`: twice its area along the
    /// unit normal, by the right-hand rule.
    pub fn area_normal(&self, t: usize) -> Vector3<f64> {
        let [a, b, c] = self.corners(t);
        (b - a).cross(&(c - a))
    }

    /// The total area, square metres.
    pub fn area(&self) -> f64 {
        (0..self.triangles.len())
            .map(|t| 0.5 * self.area_normal(t).norm())
            .sum()
    }

    /// Whether the mesh has no triangle.
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }

    /// Appends `other`'s vertices and triangles.
    pub fn append(&mut self, other: &TriangleMesh) {
        let base = self.positions.len() as u32;
        self.positions.extend_from_slice(&other.positions);
        self.triangles
            .extend(other.triangles.iter().map(|t| t.map(|i| i + base)));
    }

    /// The mesh without the vertices no triangle uses (indices renumbered
    /// in their first-use order).
    pub fn compacted(&self) -> TriangleMesh {
        TriangleMesh::gathered(&self.positions, &self.triangles)
    }

    /// The mesh of `triangles` that index `positions`, holding only the
    /// positions they use (renumbered in first-use order; the cost is the
    /// triangles', not the positions').
    pub fn gathered(positions: &[Vector3<f64>], triangles: &[[u32; 3]]) -> TriangleMesh {
        let mut new_index = std::collections::HashMap::new();
        let mut used = Vec::new();
        let triangles = triangles
            .iter()
            .map(|t| {
                t.map(|i| {
                    *new_index.entry(i).or_insert_with(|| {
                        used.push(positions[i as usize]);
                        used.len() as u32 - 1
                    })
                })
            })
            .collect();
        TriangleMesh {
            positions: used,
            triangles,
        }
    }

    /// The centre of the vertices' bounding box, if there is a vertex.
    pub fn bounding_box_centre(&self) -> Option<Vector3<f64>> {
        let first = *self.positions.first()?;
        let (lo, hi) = self
            .positions
            .iter()
            .fold((first, first), |(lo, hi), p| (lo.inf(p), hi.sup(p)));
        Some(0.5 * (lo + hi))
    }

    /// Turns every triangle whose normal points away from `viewpoint` (its
    /// centroid seen from there) so that all face it.
    pub fn face_towards(&mut self, viewpoint: &Vector3<f64>) {
        for t in 0..self.triangles.len() {
            let [a, b, c] = self.corners(t);
            let centroid = (a + b + c) / 3.0;
            if self.area_normal(t).dot(&(viewpoint - centroid)) < 0.0 {
                self.triangles[t].swap(1, 2);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn area_compaction_and_facing_of_a_unit_square() {
        let mut m = TriangleMesh {
            positions: vec![
                Vector3::new(9.0, 9.0, 9.0),
                Vector3::new(0.0, 0.0, 0.0),
                Vector3::new(1.0, 0.0, 0.0),
                Vector3::new(1.0, 1.0, 0.0),
                Vector3::new(0.0, 1.0, 0.0),
            ],
            triangles: vec![[1, 2, 3], [1, 4, 3]],
        };
        assert!((m.area() - 1.0).abs() < 1e-12);
        let c = m.compacted();
        assert_eq!(c.positions.len(), 4);
        assert_eq!(c.triangles, vec![[0, 1, 2], [0, 3, 2]]);
        m.face_towards(&Vector3::new(0.5, 0.5, 5.0));
        for t in 0..2 {
            assert!(m.area_normal(t).z > 0.0);
        }
        assert_eq!(c.bounding_box_centre(), Some(Vector3::new(0.5, 0.5, 0.0)));
    }
}

//! The least-squares plane through a group's points (principal component
//! analysis: the normal is the eigenvector of the points' covariance with
//! the smallest eigenvalue), with its residuals, which tell a planar group
//! from a curved one.

use nalgebra::{Matrix3, SymmetricEigen, Vector3};

/// A plane fitted to points, with in-plane axes for 2-D work.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlaneFit {
    /// The points' mean, on the plane.
    pub centroid: Vector3<f64>,
    /// Unit normal.
    pub normal: Vector3<f64>,
    /// Unit in-plane axis along the points' largest spread.
    pub u: Vector3<f64>,
    /// Unit in-plane axis, `normal × u` (so `u, v, normal` is right-handed).
    pub v: Vector3<f64>,
    /// Root-mean-square distance of the points from the plane, metres.
    pub rms_m: f64,
    /// Largest distance of a point from the plane, metres.
    pub max_m: f64,
}

impl PlaneFit {
    /// The plane through `points`, or `None` with fewer than three points or
    /// when they are all on one line.
    pub fn of(points: &[Vector3<f64>]) -> Option<PlaneFit> {
        if points.len() < 3 {
            return None;
        }
        let n = points.len() as f64;
        let centroid = points.iter().sum::<Vector3<f64>>() / n;
        let covariance = points.iter().fold(Matrix3::zeros(), |m, p| {
            let d = p - centroid;
            m + d * d.transpose()
        }) / n;
        let eigen = SymmetricEigen::new(covariance);
        let mut order = [0usize, 1, 2];
        order.sort_by(|&a, &b| eigen.eigenvalues[a].total_cmp(&eigen.eigenvalues[b]));
        let spread = eigen.eigenvalues[order[2]];
        if eigen.eigenvalues[order[1]].is_nan() || eigen.eigenvalues[order[1]] <= 1e-12 * spread.max(1e-300) {
            return None;
        }
        let normal: Vector3<f64> = eigen.eigenvectors.column(order[0]).into_owned().normalize();
        let u: Vector3<f64> = eigen.eigenvectors.column(order[2]).into_owned().normalize();
        let mut fit = PlaneFit {
            centroid,
            normal,
            u,
            v: normal.cross(&u),
            rms_m: 0.0,
            max_m: 0.0,
        };
        let (sum_sq, max) = points.iter().fold((0.0, 0.0f64), |(s, m), p| {
            let d = fit.distance(p).abs();
            (s + d * d, m.max(d))
        });
        fit.rms_m = (sum_sq / n).sqrt();
        fit.max_m = max;
        Some(fit)
    }

    /// Signed distance of `p` from the plane, positive on the normal's side.
    pub fn distance(&self, p: &Vector3<f64>) -> f64 {
        (p - self.centroid).dot(&self.normal)
    }

    /// `p`'s in-plane coordinates along `u` and `v`.
    pub fn project(&self, p: &Vector3<f64>) -> [f64; 2] {
        let d = p - self.centroid;
        [d.dot(&self.u), d.dot(&self.v)]
    }

    /// The point of the plane at in-plane coordinates `q`.
    pub fn lift(&self, q: [f64; 2]) -> Vector3<f64> {
        self.centroid + q[0] * self.u + q[1] * self.v
    }

    /// The plane with its normal turned, if needed, to the side of
    /// `viewpoint` (`v` turned too, keeping `u, v, normal` right-handed).
    pub fn facing(mut self, viewpoint: &Vector3<f64>) -> PlaneFit {
        if self.distance(viewpoint) < 0.0 {
            self.normal = -self.normal;
            self.v = -self.v;
        }
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tilted_plane_with_known_offsets_has_its_normal_and_residuals() {
        // Points on z = 0.5 x + 1, with ±0.01 alternating offsets along the normal.
        let normal = Vector3::new(-0.5, 0.0, 1.0).normalize();
        let points: Vec<_> = (0..10)
            .flat_map(|i| (0..10).map(move |j| (i, j)))
            .map(|(i, j)| {
                let (x, y) = (i as f64 * 0.1, j as f64 * 0.2);
                let s = if (i + j) % 2 == 0 { 0.01 } else { -0.01 };
                Vector3::new(x, y, 0.5 * x + 1.0) + s * normal
            })
            .collect();
        let fit = PlaneFit::of(&points).unwrap().facing(&Vector3::new(0.0, 0.0, 10.0));
        assert!((fit.normal - normal).norm() < 1e-9, "{:?}", fit.normal);
        assert!((fit.rms_m - 0.01).abs() < 1e-9);
        assert!((fit.max_m - 0.01).abs() < 1e-9);
        assert!((fit.u.cross(&fit.v) - fit.normal).norm() < 1e-12);
        let p = Vector3::new(0.3, 0.4, 1.15);
        assert!((fit.lift(fit.project(&p)) - p).norm() < 1e-12);
        assert!(PlaneFit::of(&[Vector3::zeros(), Vector3::x(), 2.0 * Vector3::x()]).is_none());
    }
}

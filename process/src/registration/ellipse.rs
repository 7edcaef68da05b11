//! Ellipses: the direct least-squares conic fit of Fitzgibbon, Pilu and
//! Fisher (1999) in the numerically stable form of Halíř and Flusser
//! (1998), the conic's centre, semi-axes and angle, and the Sampson
//! distance of a point to it (the first-order geometric distance).
//!
//! The thesis (§3.3.1) fits an ellipse to each candidate target's white
//! region: "since the ellipse is found using a region of the image, not
//! just a few pixels, the amount of redundancy enables us to estimate the
//! parameters of the ellipse to sub-pixel accuracy".

use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};

/// A conic `A x² + B x y + C y² + D x + E y + F = 0` as its symmetric
/// matrix `[[A, B/2, D/2], [B/2, C, E/2], [D/2, E/2, F]]`, so that a point
/// `p = (x, y, 1)` is on it when `pᵀ M p = 0`.
pub type Conic = Matrix3<f64>;

/// An ellipse by its parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ellipse {
    /// Centre `(x, y)`.
    pub centre: (f64, f64),
    /// Semi-major axis.
    pub a: f64,
    /// Semi-minor axis (`b ≤ a`).
    pub b: f64,
    /// Angle of the major axis from the x axis, radians, in (−π/2, π/2].
    pub angle: f64,
}

impl Ellipse {
    /// The point at parameter `t` (radians) on the ellipse.
    pub fn point(&self, t: f64) -> (f64, f64) {
        let (s, c) = self.angle.sin_cos();
        let (x, y) = (self.a * t.cos(), self.b * t.sin());
        (self.centre.0 + c * x - s * y, self.centre.1 + s * x + c * y)
    }

    /// The ellipse's conic matrix.
    pub fn conic(&self) -> Conic {
        let (s, c) = self.angle.sin_cos();
        let (ia, ib) = (1.0 / (self.a * self.a), 1.0 / (self.b * self.b));
        // Quadratic form in the centred frame: R diag(1/a², 1/b²) Rᵀ.
        let q11 = c * c * ia + s * s * ib;
        let q22 = s * s * ia + c * c * ib;
        let q12 = c * s * (ia - ib);
        let (x0, y0) = self.centre;
        let d = -(q11 * x0 + q12 * y0);
        let e = -(q12 * x0 + q22 * y0);
        let f = q11 * x0 * x0 + 2.0 * q12 * x0 * y0 + q22 * y0 * y0 - 1.0;
        Matrix3::new(q11, q12, d, q12, q22, e, d, e, f)
    }

    /// The ellipse of a conic matrix, or `None` when the conic is not a
    /// real ellipse (a hyperbola, a parabola, an imaginary ellipse).
    pub fn from_conic(m: &Conic) -> Option<Ellipse> {
        let q = Matrix2::new(m[(0, 0)], m[(0, 1)], m[(1, 0)], m[(1, 1)]);
        let centre = q.try_inverse()? * -Vector2::new(m[(0, 2)], m[(1, 2)]);
        // The value at the centre: pᵀ M p with p the centre.
        let p = Vector3::new(centre.x, centre.y, 1.0);
        let k = (p.transpose() * m * p)[(0, 0)];
        let eig = q.symmetric_eigen();
        let (l1, l2) = (eig.eigenvalues[0], eig.eigenvalues[1]);
        // An ellipse: both eigenvalues of the sign opposite to k.
        if !(l1 * k < 0.0 && l2 * k < 0.0) {
            return None;
        }
        let (s1, s2) = ((-k / l1).sqrt(), (-k / l2).sqrt());
        let (a, b, v) = if s1 >= s2 {
            (s1, s2, eig.eigenvectors.column(0).into_owned())
        } else {
            (s2, s1, eig.eigenvectors.column(1).into_owned())
        };
        let mut angle = v.y.atan2(v.x);
        if angle <= -std::f64::consts::FRAC_PI_2 {
            angle += std::f64::consts::PI;
        } else if angle > std::f64::consts::FRAC_PI_2 {
            angle -= std::f64::consts::PI;
        }
        let e = Ellipse {
            centre: (centre.x, centre.y),
            a,
            b,
            angle,
        };
        [e.centre.0, e.centre.1, e.a, e.b, e.angle]
            .iter()
            .all(|v| v.is_finite())
            .then_some(e)
    }
}

/// The Sampson distance of `(x, y)` to conic `m`: `|pᵀ M p| / ‖∇(pᵀ M p)‖`.
pub fn sampson_distance(m: &Conic, x: f64, y: f64) -> f64 {
    let p = Vector3::new(x, y, 1.0);
    let mp = m * p;
    let value = p.dot(&mp);
    let grad = 2.0 * Vector2::new(mp.x, mp.y);
    let g = grad.norm();
    if g > 0.0 { value.abs() / g } else { f64::INFINITY }
}

/// The null vector of a 3 × 3 matrix of rank 2: the largest cross product of two of its rows.
fn null_vector(m: &Matrix3<f64>) -> Option<Vector3<f64>> {
    let rows = [m.row(0).transpose(), m.row(1).transpose(), m.row(2).transpose()];
    let best = [(0, 1), (0, 2), (1, 2)]
        .iter()
        .map(|(i, j)| rows[*i].cross(&rows[*j]))
        .max_by(|a, b| a.norm().total_cmp(&b.norm()))?;
    best.try_normalize(1e-300)
}

/// The direct least-squares ellipse through `points` (Halíř–Flusser),
/// as a conic in the points' own coordinates; `None` for fewer than 6
/// points or when no ellipse fits (points on a line, a hyperbola's arcs).
pub fn fit_conic(points: &[(f64, f64)]) -> Option<Conic> {
    let n = points.len();
    if n < 6 {
        return None;
    }
    // Condition: centre the points and scale them to unit RMS radius.
    let (mx, my) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n as f64, b + y / n as f64));
    let rms = (points
        .iter()
        .map(|(x, y)| (x - mx).powi(2) + (y - my).powi(2))
        .sum::<f64>()
        / n as f64)
        .sqrt();
    if !(rms.is_finite() && rms > 0.0) {
        return None;
    }
    let s = 1.0 / rms;
    let mut s1 = Matrix3::<f64>::zeros();
    let mut s2 = Matrix3::<f64>::zeros();
    let mut s3 = Matrix3::<f64>::zeros();
    for (x, y) in points {
        let (x, y) = ((x - mx) * s, (y - my) * s);
        let d1 = Vector3::new(x * x, x * y, y * y);
        let d2 = Vector3::new(x, y, 1.0);
        s1 += d1 * d1.transpose();
        s2 += d1 * d2.transpose();
        s3 += d2 * d2.transpose();
    }
    let t = -(s3.try_inverse()? * s2.transpose());
    let m = s1 + s2 * t;
    // C1⁻¹ M with C1 the constraint 4ac − b² (Halíř–Flusser eq. 28).
    let reduced = Matrix3::from_rows(&[
        (m.row(2) / 2.0).into_owned(),
        (-m.row(1)).into_owned(),
        (m.row(0) / 2.0).into_owned(),
    ]);
    let mut best: Option<(f64, Vector3<f64>)> = None;
    for lambda in reduced.complex_eigenvalues().iter() {
        if lambda.im.abs() > 1e-9 * (1.0 + lambda.re.abs()) {
            continue;
        }
        let Some(a1) = null_vector(&(reduced - Matrix3::identity() * lambda.re)) else {
            continue;
        };
        let constraint = 4.0 * a1[0] * a1[2] - a1[1] * a1[1];
        if constraint > 0.0 && best.is_none_or(|(c, _)| constraint > c) {
            best = Some((constraint, a1));
        }
    }
    let (_, a1) = best?;
    let a2 = t * a1;
    let normalized = Matrix3::new(
        a1[0],
        a1[1] / 2.0,
        a2[0] / 2.0,
        a1[1] / 2.0,
        a1[2],
        a2[1] / 2.0,
        a2[0] / 2.0,
        a2[1] / 2.0,
        a2[2],
    );
    // Back to the points' coordinates: p' = T p.
    let tm = Matrix3::new(s, 0.0, -mx * s, 0.0, s, -my * s, 0.0, 0.0, 1.0);
    let conic = tm.transpose() * normalized * tm;
    conic.iter().all(|v| v.is_finite()).then_some(conic)
}

/// A fitted ellipse and how well its points lie on it.
#[derive(Debug, Clone, PartialEq)]
pub struct EllipseFit {
    /// The ellipse.
    pub ellipse: Ellipse,
    /// Its conic.
    pub conic: Conic,
    /// Root mean square Sampson distance of the points kept.
    pub rms: f64,
    /// Which input points were kept (not rejected as outliers).
    pub kept: Vec<bool>,
}

/// A robust fit: fit, drop points farther than `max(3 × median, floor)`,
/// refit, twice. `None` if fewer than 6 points remain or no ellipse fits.
pub fn fit_ellipse_robust(points: &[(f64, f64)], floor: f64) -> Option<EllipseFit> {
    let mut kept = vec![true; points.len()];
    let mut conic = fit_conic(points)?;
    for _ in 0..2 {
        let d: Vec<f64> = points.iter().map(|(x, y)| sampson_distance(&conic, *x, *y)).collect();
        let mut sorted = d.clone();
        sorted.sort_by(f64::total_cmp);
        let limit = (3.0 * sorted[sorted.len() / 2]).max(floor);
        kept = d.iter().map(|v| *v <= limit).collect();
        let inliers: Vec<(f64, f64)> = points.iter().zip(&kept).filter(|(_, k)| **k).map(|(p, _)| *p).collect();
        conic = fit_conic(&inliers)?;
    }
    let ellipse = Ellipse::from_conic(&conic)?;
    let used: Vec<f64> = points
        .iter()
        .zip(&kept)
        .filter(|(_, k)| **k)
        .map(|((x, y), _)| sampson_distance(&conic, *x, *y))
        .collect();
    let rms = (used.iter().map(|d| d * d).sum::<f64>() / used.len().max(1) as f64).sqrt();
    Some(EllipseFit {
        ellipse,
        conic,
        rms,
        kept,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Ellipse {
        Ellipse {
            centre: (312.4, 207.9),
            a: 14.2,
            b: 6.3,
            angle: 0.7,
        }
    }

    #[test]
    fn exact_points_give_back_the_ellipse() {
        let e = sample();
        let points: Vec<(f64, f64)> = (0..40).map(|i| e.point(f64::from(i) * 0.157)).collect();
        let fit = Ellipse::from_conic(&fit_conic(&points).expect("fits")).expect("an ellipse");
        assert!((fit.centre.0 - e.centre.0).abs() < 1e-8 && (fit.centre.1 - e.centre.1).abs() < 1e-8);
        assert!((fit.a - e.a).abs() < 1e-8 && (fit.b - e.b).abs() < 1e-8);
        assert!((fit.angle - e.angle).abs() < 1e-9);
        // The parameters' conic and the fitted one are the same up to scale.
        let c = e.conic();
        assert!(points.iter().all(|(x, y)| sampson_distance(&c, *x, *y) < 1e-8));
    }

    #[test]
    fn an_arc_with_noise_and_outliers_fits_to_a_sixth_of_a_pixel() {
        use rand::{Rng, SeedableRng};
        let e = sample();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        // Two thirds of the ellipse, 0.1 px noise, and 8 points of an occluder's edge.
        let mut points: Vec<(f64, f64)> = (0..48)
            .map(|i| {
                let (x, y) = e.point(f64::from(i) * 0.087);
                (
                    x + 0.1 * (rng.random::<f64>() - 0.5) * 3.4,
                    y + 0.1 * (rng.random::<f64>() - 0.5) * 3.4,
                )
            })
            .collect();
        // The occluder's edge: across the middle along the minor axis, 3 px or more inside.
        let (s, c) = e.angle.sin_cos();
        points.extend((0..8).map(|i| {
            let t = -3.0 + 6.0 * f64::from(i) / 7.0;
            (e.centre.0 - s * t, e.centre.1 + c * t)
        }));
        let fit = fit_ellipse_robust(&points, 0.3).expect("fits");
        let f = fit.ellipse;
        assert!((f.centre.0 - e.centre.0).hypot(f.centre.1 - e.centre.1) < 0.15, "{f:?}");
        // Measured: 0.11 px off, a and b within 0.11 px (a direct fit to
        // two thirds of the arc, 0.1 px of noise).
        assert!((f.a - e.a).abs() < 0.15 && (f.b - e.b).abs() < 0.15, "{f:?}");
        assert!(fit.kept[48..].iter().all(|k| !k), "the occluder's points are dropped");
        assert!(fit.rms < 0.15, "{}", fit.rms);
    }

    #[test]
    fn points_on_a_line_give_no_ellipse() {
        let points: Vec<(f64, f64)> = (0..10).map(|i| (f64::from(i), 2.0 * f64::from(i))).collect();
        assert!(fit_conic(&points).and_then(|c| Ellipse::from_conic(&c)).is_none());
    }
}

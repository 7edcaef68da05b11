//! Deterministic quadrature over the upper hemisphere (local frame), for
//! directional albedos and for checking sampling densities:
//!
//! `∫_Ω g(ω) dω = ∫_0^{π/2} ∫_0^{2π} g(θ, φ) sin θ dφ dθ`
//!
//! with Gauss–Legendre in θ (nodes cluster at the pole, where a lobe at
//! normal incidence sits, and at the horizon) and the midpoint rule in φ
//! (spectrally accurate for a smooth periodic integrand). Both are exact for
//! a Lambertian integrand `cos θ` up to rounding. A lobe narrower than the
//! grid spacing (≈ π/(2 n_theta) in θ, 2π/n_phi in φ) is not resolved: use
//! n_theta ≳ 10/α and n_phi ≳ 20/α for a Ward lobe of roughness α.

use std::f64::consts::{FRAC_PI_4, PI};

use nalgebra::Vector3;

/// A product rule on the hemisphere: `n_theta` Gauss–Legendre nodes in θ
/// times `n_phi` midpoint nodes in φ.
#[derive(Debug, Clone)]
pub struct HemisphereQuadrature {
    /// (cos θ, sin θ, weight including sin θ dθ dφ) per θ node.
    theta: Vec<(f64, f64, f64)>,
    /// (cos φ, sin φ) per φ node.
    phi: Vec<(f64, f64)>,
}

impl HemisphereQuadrature {
    /// The rule with `n_theta × n_phi` nodes. With either count 0 it has no
    /// nodes and every integral is 0.
    pub fn new(n_theta: usize, n_phi: usize) -> HemisphereQuadrature {
        let dphi = if n_phi == 0 { 0.0 } else { 2.0 * PI / n_phi as f64 };
        let theta = gauss_legendre(n_theta)
            .into_iter()
            .map(|(x, w)| {
                // [-1, 1] → [0, π/2]: θ = π/4 (x + 1), dθ = π/4 dx.
                let (s, c) = (FRAC_PI_4 * (x + 1.0)).sin_cos();
                (c, s, w * FRAC_PI_4 * s * dphi)
            })
            .collect();
        let phi = (0..n_phi)
            .map(|j| {
                let (s, c) = ((j as f64 + 0.5) * dphi).sin_cos();
                (c, s)
            })
            .collect();
        HemisphereQuadrature { theta, phi }
    }

    /// `∫ g(ω) dω` over the upper hemisphere, per channel.
    pub fn integrate_rgb(&self, mut g: impl FnMut(&Vector3<f64>) -> [f64; 3]) -> [f64; 3] {
        let mut total = [0.0; 3];
        for &(ct, st, w) in &self.theta {
            let mut ring = [0.0; 3];
            for &(cp, sp) in &self.phi {
                let v = g(&Vector3::new(st * cp, st * sp, ct));
                for c in 0..3 {
                    ring[c] += v[c];
                }
            }
            for c in 0..3 {
                total[c] += w * ring[c];
            }
        }
        total
    }

    /// `∫ g(ω) dω` over the upper hemisphere.
    pub fn integrate(&self, mut g: impl FnMut(&Vector3<f64>) -> f64) -> f64 {
        self.integrate_rgb(|w| [g(w), 0.0, 0.0])[0]
    }
}

/// The `n`-point Gauss–Legendre rule on [-1, 1] as (node, weight), nodes
/// ascending: Newton's method on the Legendre recurrence from the initial
/// guess `−cos(π (i + 3/4) / (n + 1/2))`, which converges for every n.
pub(crate) fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let nf = n as f64;
    (0..n)
        .map(|i| {
            let mut x = -(PI * (i as f64 + 0.75) / (nf + 0.5)).cos();
            for _ in 0..100 {
                let (p, d) = legendre(n, x);
                let dx = p / d;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
            let (_, d) = legendre(n, x);
            (x, 2.0 / ((1.0 - x * x) * d * d))
        })
        .collect()
}

/// `P_n(x)` and `P_n'(x)` by the three-term recurrence.
fn legendre(n: usize, x: f64) -> (f64, f64) {
    let (mut p0, mut p1) = (1.0, x);
    if n == 0 {
        return (1.0, 0.0);
    }
    for k in 2..=n {
        let kf = k as f64;
        let p2 = ((2.0 * kf - 1.0) * x * p1 - (kf - 1.0) * p0) / kf;
        p0 = p1;
        p1 = p2;
    }
    let nf = n as f64;
    (p1, nf * (x * p1 - p0) / (x * x - 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_integrates_polynomials_of_degree_2n_minus_1_exactly() {
        for n in [1, 2, 5, 64, 1000] {
            let rule = gauss_legendre(n);
            let weights: f64 = rule.iter().map(|(_, w)| w).sum();
            assert!((weights - 2.0).abs() < 1e-12, "n = {n}: Σw = {weights}");
            // The highest odd degree the rule is exact for, capped at 21.
            let deg = (2 * n - 1).min(21) as i32;
            // ∫_{-1}^{1} x^deg dx = 0 for odd deg; ∫ x^(deg−1) = 2 / deg.
            let odd: f64 = rule.iter().map(|(x, w)| w * x.powi(deg)).sum();
            let even: f64 = rule.iter().map(|(x, w)| w * x.powi(deg - 1)).sum();
            assert!(odd.abs() < 1e-12, "n = {n}: {odd}");
            assert!((even - 2.0 / f64::from(deg)).abs() < 1e-12, "n = {n}: {even}");
        }
    }

    #[test]
    fn hemisphere_solid_angle_and_projected_solid_angle() {
        let q = HemisphereQuadrature::new(16, 8);
        // ∫ dω = 2π, ∫ cos θ dω = π, ∫ cos²θ sin²φ... = ∫ x² dω = 2π/3.
        assert!((q.integrate(|_| 1.0) - 2.0 * PI).abs() < 1e-12);
        assert!((q.integrate(|w| w.z) - PI).abs() < 1e-12);
        assert!((q.integrate(|w| w.x * w.x) - 2.0 * PI / 3.0).abs() < 1e-12);
        assert_eq!(HemisphereQuadrature::new(0, 8).integrate(|_| 1.0), 0.0);
    }
}

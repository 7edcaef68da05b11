//! A deterministic reference for sky irradiance, independent of the
//! spherical polygons: composite Gauss–Legendre quadrature of
//! `∫ L(ω) (ω · n) sin ξ dξ dφ` over the sky (z ≥ 0) above the tangent plane,
//! in the sky's own zenith ξ and azimuth φ (here φ from +x toward +y).
//!
//! For each φ the part of the meridian above the plane is one interval of
//! ξ, found in closed form, so the integrand is smooth on every panel
//! except where the caller says it is not: azimuths and zenith angles of
//! features (the sun's cusp, the horizon floor of eq. 5.9) become panel
//! edges. It is what the tests and the benchmark measure error against, in
//! place of a Monte Carlo estimate that could not reach 1e-4 in test time.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use nalgebra::Vector3;

/// Gauss–Legendre order per panel.
const ORDER: usize = 16;

/// How many panels cover the sky.
#[derive(Debug, Clone, PartialEq)]
pub struct ReferenceGrid {
    /// Panels over the full circle of azimuth (split at every break).
    pub azimuth_panels: usize,
    /// Panels over a quarter circle of zenith angle.
    pub zenith_panels: usize,
    /// Directions whose azimuth and zenith angle become panel edges (the sun).
    pub features: Vec<Vector3<f64>>,
    /// Further zenith angles that become panel edges, radians.
    pub zenith_breaks: Vec<f64>,
}

/// Gauss–Legendre nodes and weights on [−1, 1] (Newton on Pₙ).
fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let k = k as f64;
                    let p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
                    p0 = p1;
                    p1 = p2;
                }
                dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / dp;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
            (x, 2.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect()
}

/// Nodes and weights of a composite rule over `[a, b]` split at `breaks`,
/// with about `panels_per_unit · length` panels per piece.
fn composite(a: f64, b: f64, breaks: &[f64], panels_per_unit: f64, rule: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut edges: Vec<f64> = std::iter::once(a)
        .chain(breaks.iter().copied().filter(|x| *x > a && *x < b))
        .chain(std::iter::once(b))
        .collect();
    edges.sort_by(f64::total_cmp);
    let mut out = Vec::new();
    for w in edges.windows(2) {
        let (lo, hi) = (w[0], w[1]);
        if hi - lo <= 0.0 {
            continue;
        }
        let panels = ((hi - lo) * panels_per_unit).ceil().max(1.0) as usize;
        let h = (hi - lo) / panels as f64;
        for p in 0..panels {
            let (s, e) = (lo + h * p as f64, lo + h * (p + 1) as f64);
            for (x, wt) in rule {
                out.push((0.5 * (s + e) + 0.5 * (e - s) * x, 0.5 * (e - s) * wt));
            }
        }
    }
    out
}

/// Reference irradiance per channel from `sky` (radiance from a unit
/// direction, z ≥ 0) on the side `normal` (unit) of an unoccluded point.
pub fn reference_sky_irradiance<F: Fn([f64; 3]) -> [f64; 3]>(
    normal: &Vector3<f64>,
    sky: &F,
    grid: &ReferenceGrid,
) -> [f64; 3] {
    let n = normal.normalize();
    let rule = gauss_legendre(ORDER);
    let wrap = |phi: f64| phi.rem_euclid(TAU);
    // Azimuths where the meridian's visible interval changes form (n_x cos φ + n_y sin φ = 0),
    // and the features' azimuths.
    let phi0 = (-n.x).atan2(n.y);
    let mut azimuth_breaks = vec![wrap(phi0), wrap(phi0 + PI)];
    let mut zenith_breaks = grid.zenith_breaks.clone();
    for f in &grid.features {
        azimuth_breaks.push(wrap(f.y.atan2(f.x)));
        zenith_breaks.push(f.z.clamp(-1.0, 1.0).acos());
    }
    let phis = composite(0.0, TAU, &azimuth_breaks, grid.azimuth_panels as f64 / TAU, &rule);
    let mut e = [0.0; 3];
    for (phi, wphi) in phis {
        let (sp, cp) = phi.sin_cos();
        let a = n.x * cp + n.y * sp;
        // ω · n = sin ξ a + cos ξ n_z = ρ cos(ξ − ψ) ≥ 0 ⇔ ξ ∈ [ψ − π/2, ψ + π/2].
        let psi = a.atan2(n.z);
        let lo = (psi - FRAC_PI_2).max(0.0);
        let hi = (psi + FRAC_PI_2).min(FRAC_PI_2);
        if hi <= lo {
            continue;
        }
        let xis = composite(lo, hi, &zenith_breaks, grid.zenith_panels as f64 / FRAC_PI_2, &rule);
        for (xi, wxi) in xis {
            let (sx, cx) = xi.sin_cos();
            let d = [sx * cp, sx * sp, cx];
            let cos = (d[0] * n.x + d[1] * n.y + d[2] * n.z).max(0.0);
            let l = sky(d);
            let w = wphi * wxi * sx * cos;
            for ch in 0..3 {
                e[ch] += w * l[ch];
            }
        }
    }
    e
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_integrates_degree_31_exactly() {
        let rule = gauss_legendre(ORDER);
        let total: f64 = rule.iter().map(|(_, w)| w).sum();
        assert!((total - 2.0).abs() < 1e-14);
        let x30: f64 = rule.iter().map(|(x, w)| w * x.powi(30)).sum();
        assert!((x30 - 2.0 / 31.0).abs() < 1e-14);
    }

    #[test]
    fn uniform_sky_reference_is_exact() {
        let grid = ReferenceGrid {
            azimuth_panels: 8,
            zenith_panels: 4,
            features: vec![],
            zenith_breaks: vec![],
        };
        for beta_deg in [0.0_f64, 45.0, 90.0, 135.0] {
            let beta = beta_deg.to_radians();
            let n = Vector3::new(beta.sin() * 0.8, -beta.sin() * 0.6, beta.cos());
            let e = reference_sky_irradiance(&n, &|_d| [1.0; 3], &grid);
            let exact = PI * (1.0 + beta.cos()) / 2.0;
            assert!((e[0] - exact).abs() < 1e-12, "β {beta_deg}: {} vs {exact}", e[0]);
        }
    }
}

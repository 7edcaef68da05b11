//! Choosing the smallest model the data supports: the Bayesian information
//! criterion on relative-weighted residuals.

/// The smallest relative residual a sample is credited with (10⁻⁶): below
/// it, differences are rounding, not evidence. Without this floor, two
/// models that both fit noise-free data to 10⁻¹⁵ would be ranked by the
/// logarithm of their rounding errors.
pub const RESIDUAL_FLOOR: f64 = 1e-6;

/// `n ln(RSS / n) + k ln n` for `n` residuals weighted to relative errors,
/// `k` free parameters; the RSS is floored at `n · RESIDUAL_FLOOR²`.
pub fn bic(weighted_rss: f64, n: usize, k: usize) -> f64 {
    let n = n as f64;
    let rss = weighted_rss.max(n * RESIDUAL_FLOOR * RESIDUAL_FLOOR);
    n * (rss / n).ln() + k as f64 * n.ln()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fewer_parameters_win_when_both_fit_to_rounding() {
        assert!(bic(1e-30, 100, 3) < bic(1e-32, 100, 8));
        // With real misfit, a better fit can pay for its parameters.
        assert!(bic(0.5, 100, 8) < bic(5.0, 100, 3));
    }
}

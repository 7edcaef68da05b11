//! Bounded Levenberg–Marquardt for eq. (5.10): the weighted residuals of
//! eq. (5.9) with its analytic Jacobian, parameters held in a box by
//! projection, and the optimizer's own stopping criteria reported.
//!
//! Parameters, in this order: θ = [ln Lz, a, b, c, d, e, h]. Lz is fitted
//! through its logarithm (it is positive and spans decades); a–h are
//! bounded by [`PARAMETER_RANGES`]. Any subset may be free.
//!
//! Each iteration solves `(JᵀJ + λ diag JᵀJ) δ = −Jᵀr` over the free
//! parameters not pinned at a bound by the gradient (a parameter at a bound
//! whose gradient points out of the box is held for that step), clamps the
//! step into the box and accepts it when the cost falls (Nielsen's update
//! of λ). It stops, like MINPACK's `lmder`, on the first of:
//! - **gradient**: every unpinned column of J is orthogonal to r within
//!   `gtol` (the cosine of their angle);
//! - **reduction**: both the actual and the predicted relative reduction of
//!   the cost are below `ftol`;
//! - **step**: the step is below `xtol` relative to θ;
//! - **evaluations**: the budget is spent (not converged).

// Small dense matrices (k ≤ 7) indexed by row and column read best as
// index loops.
#![allow(clippy::needless_range_loop)]

use super::kernel::{Evaluation, evaluate};
pub use super::kernel::{Prepared, natural};

/// Names of θ's entries, for messages.
pub const PARAMETER_NAMES: [&str; 7] = ["Lz", "a", "b", "c", "d", "e", "h"];

/// The box for a, b, c, d, e and h. Each holds every sky of the Perez
/// all-weather table (all eight clearness bins, Z from 0 to 90°, Δ from
/// 0.01 to 0.6; [`crate::sky::table_extremes`]: a ∈ [−2.10, 1.35],
/// b ∈ [−3.12, 0.33], c ∈ [−4.01, 32.8], d ∈ [−7.10, 2.00],
/// e ∈ [−0.42, 2.61]) with a margin of at least 15% of its span on each
/// side, and the fifteen CIE standard skies; h (eq. 5.9's generalization)
/// spans 0.25–4.
pub const PARAMETER_RANGES: [(f64, f64); 6] = [
    (-3.0, 10.0),
    (-6.0, 0.9),
    (-10.0, 60.0),
    (-12.0, 4.0),
    (-1.0, 4.0),
    (0.25, 4.0),
];

/// The RMS weighted residual taken as exact (rounding only).
const EXACT_RMS: f64 = 1e-13;

/// Why the optimizer stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Termination {
    /// The model is the data's to rounding: the RMS weighted residual is
    /// below 10⁻¹³.
    Exact,
    /// The gradient criterion (gtol).
    Gradient,
    /// The relative reduction of the cost (ftol).
    Reduction,
    /// The relative step (xtol).
    Step,
    /// The evaluation budget ran out: not converged.
    Evaluations,
    /// No optimizer ran (a closed-form fit).
    ClosedForm,
}

impl Termination {
    /// Whether this is a convergence criterion.
    pub fn converged(self) -> bool {
        !matches!(self, Termination::Evaluations)
    }

    /// In words, for reports.
    pub fn describe(self) -> &'static str {
        match self {
            Termination::Exact => "exact (zero residual)",
            Termination::Gradient => "gradient below gtol",
            Termination::Reduction => "cost reduction below ftol",
            Termination::Step => "step below xtol",
            Termination::Evaluations => "evaluation budget spent",
            Termination::ClosedForm => "closed form",
        }
    }
}

/// Stopping tolerances and budget.
#[derive(Debug, Clone, Copy)]
pub struct Settings {
    /// Relative cost reduction.
    pub ftol: f64,
    /// Relative step.
    pub xtol: f64,
    /// Cosine between residual and Jacobian columns.
    pub gtol: f64,
    /// Residual-and-Jacobian evaluations.
    pub max_evaluations: usize,
    /// The damping λ of the first step, relative to diag JᵀJ.
    pub initial_lambda: f64,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            ftol: 1e-9,
            xtol: 1e-9,
            gtol: 1e-9,
            max_evaluations: 200,
            initial_lambda: 1e-3,
        }
    }
}

/// The bounds of θ's entry `j` (θ₀ = ln Lz is unbounded).
pub fn bounds(j: usize) -> (f64, f64) {
    if j == 0 {
        (f64::NEG_INFINITY, f64::INFINITY)
    } else {
        PARAMETER_RANGES[j - 1]
    }
}

/// The result of a minimization.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// θ at the end.
    pub theta: [f64; 7],
    /// ½ Σ wᵢ rᵢ² there.
    pub cost: f64,
    /// Why it stopped.
    pub termination: Termination,
    /// Accepted steps.
    pub iterations: usize,
    /// Evaluations of residuals and Jacobian.
    pub evaluations: usize,
    /// The free parameters (θ indices) that ended at a bound.
    pub at_bound: Vec<usize>,
    /// The reciprocal condition estimate of the column-scaled JᵀJ at the
    /// end (smallest over largest eigenvalue bound, from its Cholesky
    /// factor's diagonal): near 0, some combination of the free parameters
    /// is not determined by the samples.
    pub rcond: f64,
    /// The standard error of each free parameter (in `free`'s order), from
    /// (JᵀJ)⁻¹ scaled by the residual variance 2·cost / (n − k); NaN when
    /// JᵀJ is singular.
    pub standard_errors: [f64; 7],
}

/// Solves `m x = rhs` for a symmetric positive definite k × k `m` by
/// Cholesky; `None` when it is not positive definite. Also returns the
/// factor's smallest and largest diagonal entries.
fn cholesky_solve(m: &[[f64; 7]; 7], rhs: &[f64; 7], k: usize) -> Option<([f64; 7], f64, f64)> {
    let mut l = [[0.0; 7]; 7];
    for i in 0..k {
        for j in 0..=i {
            let mut s = m[i][j];
            for p in 0..j {
                s -= l[i][p] * l[j][p];
            }
            if i == j {
                if s <= 0.0 || !s.is_finite() {
                    return None;
                }
                l[i][i] = s.sqrt();
            } else {
                l[i][j] = s / l[j][j];
            }
        }
    }
    let mut z = [0.0; 7];
    for i in 0..k {
        let mut s = rhs[i];
        for p in 0..i {
            s -= l[i][p] * z[p];
        }
        z[i] = s / l[i][i];
    }
    let mut x = [0.0; 7];
    for i in (0..k).rev() {
        let mut s = z[i];
        for p in i + 1..k {
            s -= l[p][i] * x[p];
        }
        x[i] = s / l[i][i];
    }
    let (lo, hi) = (0..k).fold((f64::INFINITY, 0.0_f64), |(lo, hi), i| {
        (lo.min(l[i][i]), hi.max(l[i][i]))
    });
    Some((x, lo, hi))
}

/// √diag((JᵀJ)⁻¹ · 2 cost / (n − k)).
fn standard_errors(ev: &Evaluation, k: usize, n: usize) -> [f64; 7] {
    let mut out = [f64::NAN; 7];
    let variance = 2.0 * ev.cost / (n.saturating_sub(k).max(1)) as f64;
    for j in 0..k {
        let mut e = [0.0; 7];
        e[j] = 1.0;
        if let Some((col, _, _)) = cholesky_solve(&ev.jtj, &e, k) {
            out[j] = (col[j] * variance).max(0.0).sqrt();
        }
    }
    out
}

/// The reciprocal condition estimate of JᵀJ with its columns scaled to unit
/// norm: (smallest / largest Cholesky diagonal)², 0 when singular.
fn rcond(jtj: &[[f64; 7]; 7], k: usize) -> f64 {
    let mut m = [[0.0; 7]; 7];
    for i in 0..k {
        for j in 0..k {
            let s = (jtj[i][i] * jtj[j][j]).sqrt();
            m[i][j] = if s > 0.0 { jtj[i][j] / s } else { 0.0 };
        }
    }
    match cholesky_solve(&m, &[0.0; 7], k) {
        Some((_, lo, hi)) if hi > 0.0 => (lo / hi).powi(2),
        _ => 0.0,
    }
}

/// Minimizes the weighted cost over the `free` entries of θ from `start`
/// (clamped into the box), the others held. `None` when the start itself
/// cannot be evaluated.
pub fn minimize(
    prep: &Prepared,
    start: [f64; 7],
    free: &[usize],
    weights: Option<&[f64]>,
    settings: &Settings,
) -> Option<Outcome> {
    let k = free.len();
    let mut theta = start;
    for &j in free {
        let (lo, hi) = bounds(j);
        theta[j] = theta[j].clamp(lo, hi);
    }
    let scale = prep.residual_scale(weights);
    let mut ev = evaluate(prep, &theta, free, &scale)?;
    let mut evaluations = 1;
    let mut iterations = 0;
    let mut lambda = settings.initial_lambda;
    let mut nu = 2.0;
    // Whether the last evaluation was an accepted step whose reduction the
    // model predicted well (ρ ≥ ½).
    let mut trusted = false;
    let at = |theta: &[f64; 7], j: usize| {
        let (lo, hi) = bounds(j);
        let tol = 1e-12 * (hi - lo).min(1e12);
        (theta[j] <= lo + tol, theta[j] >= hi - tol)
    };
    let termination = loop {
        // Zero, or the data's own rounding: an RMS weighted residual below
        // 10⁻¹³ (a few float64 ulps of each relative residual).
        if 2.0 * ev.cost <= EXACT_RMS * EXACT_RMS * prep.len() as f64 {
            break Termination::Exact;
        }
        // Pinned: at a bound with the descent direction −g pointing out.
        let mut pinned = [false; 7];
        for (p, &j) in free.iter().enumerate() {
            let (low, high) = at(&theta, j);
            pinned[p] = (low && ev.grad[p] > 0.0) || (high && ev.grad[p] < 0.0);
        }
        let live: Vec<usize> = (0..k).filter(|&p| !pinned[p]).collect();
        let norm_r = (2.0 * ev.cost).sqrt();
        let gnorm = live
            .iter()
            .map(|&p| {
                let cn = ev.jtj[p][p].sqrt();
                if cn > 0.0 {
                    (ev.grad[p] / (cn * norm_r)).abs()
                } else {
                    0.0
                }
            })
            .fold(0.0, f64::max);
        if gnorm <= settings.gtol {
            break Termination::Gradient;
        }
        if evaluations >= settings.max_evaluations {
            break Termination::Evaluations;
        }
        // The damped step over the live parameters.
        let m = live.len();
        let mut a = [[0.0; 7]; 7];
        let mut rhs = [0.0; 7];
        let dmax = live.iter().map(|&p| ev.jtj[p][p]).fold(0.0, f64::max);
        for (u, &p) in live.iter().enumerate() {
            for (v, &q) in live.iter().enumerate() {
                a[u][v] = ev.jtj[p][q];
            }
            a[u][u] += lambda * ev.jtj[p][p].max(1e-15 * dmax).max(f64::MIN_POSITIVE);
            rhs[u] = -ev.grad[p];
        }
        let Some((delta, _, _)) = cholesky_solve(&a, &rhs, m) else {
            lambda *= nu;
            nu *= 2.0;
            if lambda > 1e20 {
                break Termination::Step;
            }
            continue;
        };
        let mut trial = theta;
        for (u, &p) in live.iter().enumerate() {
            let j = free[p];
            let (lo, hi) = bounds(j);
            trial[j] = (theta[j] + delta[u]).clamp(lo, hi);
        }
        // The step actually taken, and the reduction the model predicts.
        let mut step = [0.0; 7];
        for (p, &j) in free.iter().enumerate() {
            step[p] = trial[j] - theta[j];
        }
        let mut pred = 0.0;
        for p in 0..k {
            let mut js = 0.0;
            for q in 0..k {
                js += ev.jtj[p][q] * step[q];
            }
            pred -= ev.grad[p] * step[p] + 0.5 * step[p] * js;
        }
        let step_norm = step[..k].iter().map(|s| s * s).sum::<f64>().sqrt();
        let theta_norm = free.iter().map(|&j| theta[j] * theta[j]).sum::<f64>().sqrt();
        // The reduction test without the evaluation that would only confirm
        // it: the model, just shown to predict well, predicts less than ftol
        // of reduction from here (MINPACK evaluates the step first; the
        // reduction it finds is then at most about the prediction).
        if trusted && pred <= settings.ftol * ev.cost {
            break Termination::Reduction;
        }
        let next = evaluate(prep, &trial, free, &scale);
        evaluations += 1;
        // MINPACK's test, on accepted and refused steps alike: the cost
        // neither falls nor is predicted to fall by more than ftol.
        let small =
            |next_cost: f64| (ev.cost - next_cost).abs() <= settings.ftol * ev.cost && pred <= settings.ftol * ev.cost;
        let accepted = match next {
            Some(next) if next.cost < ev.cost => {
                let actual = ev.cost - next.cost;
                let rho = if pred > 0.0 { actual / pred } else { 0.0 };
                let stop = small(next.cost);
                theta = trial;
                ev = next;
                iterations += 1;
                lambda *= (1.0 - (2.0 * rho - 1.0).powi(3)).max(1.0 / 3.0);
                nu = 2.0;
                trusted = rho >= 0.5;
                if stop {
                    break Termination::Reduction;
                }
                true
            }
            Some(next) if small(next.cost) => break Termination::Reduction,
            _ => {
                lambda *= nu;
                nu *= 2.0;
                trusted = false;
                false
            }
        };
        if step_norm <= settings.xtol * (theta_norm + settings.xtol) {
            break Termination::Step;
        }
        if !accepted && lambda > 1e20 {
            break Termination::Step;
        }
    };
    let at_bound = free
        .iter()
        .copied()
        .filter(|&j| {
            let (low, high) = at(&theta, j);
            low || high
        })
        .collect();
    Some(Outcome {
        theta,
        cost: ev.cost,
        termination,
        iterations,
        evaluations,
        at_bound,
        rcond: rcond(&ev.jtj, k),
        standard_errors: standard_errors(&ev, k, prep.len()),
    })
}

#[cfg(test)]
mod tests {
    use super::super::SkySample;
    use super::*;

    fn samples() -> Vec<SkySample> {
        let mut out = Vec::new();
        for i in 0..12 {
            for j in 0..10 {
                out.push(SkySample {
                    xi: 0.05 + 0.12 * f64::from(i),
                    gamma: 0.03 + 0.3 * f64::from(j),
                    radiance: 0.0,
                });
            }
        }
        out
    }

    #[test]
    fn the_analytic_jacobian_matches_finite_differences() {
        let s = samples();
        let sigma: Vec<f64> = (0..s.len()).map(|i| 0.5 + 0.01 * i as f64).collect();
        let prep = Prepared::new(&s, &sigma);
        let theta = [0.3, -0.9, -0.4, 9.0, -2.7, 0.5, 0.9];
        let free: Vec<usize> = (0..7).collect();
        let scale = prep.residual_scale(None);
        let ev = evaluate(&prep, &theta, &free, &scale).expect("finite");
        // The gradient of ½Σr² by central differences.
        for j in 0..7 {
            let h = 1e-6;
            let mut p = theta;
            p[j] += h;
            let mut m = theta;
            m[j] -= h;
            let cp = evaluate(&prep, &p, &free, &scale).expect("finite").cost;
            let cm = evaluate(&prep, &m, &free, &scale).expect("finite").cost;
            let fd = (cp - cm) / (2.0 * h);
            assert!(
                (fd - ev.grad[j]).abs() < 1e-6 * (1.0 + fd.abs()),
                "θ{j}: {fd} vs {}",
                ev.grad[j]
            );
        }
    }

    #[test]
    fn a_parameter_beyond_its_bound_stops_at_the_bound_and_says_so() {
        // Data from a = −3.5, below the box's −3: the fit ends at −3, reports
        // it, and still stops by a convergence criterion.
        let mut s = samples();
        let truth = [1.0, -3.5, -0.2, 5.0, -2.0, 0.3, 1.0];
        let sigma = vec![1.0; s.len()];
        let prep = Prepared::new(&s, &sigma);
        for (i, x) in s.iter_mut().enumerate() {
            x.radiance = prep.model_at(&truth, i);
        }
        let prep = Prepared::new(&s, &sigma);
        let free = [0, 1, 2, 5];
        let start = [0.0, -1.0, -0.3, 5.0, -2.0, 0.2, 1.0];
        let out = minimize(&prep, start, &free, None, &Settings::default()).expect("runs");
        assert!(out.termination.converged(), "{:?}", out.termination);
        assert_eq!(out.theta[1], -3.0);
        assert_eq!(out.at_bound, vec![1]);
    }
}

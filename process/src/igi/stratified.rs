//! Stratified points on the unit square for the solver's Monte Carlo
//! estimates (gathering, ΔS): `n` points, one per stratum, so that the
//! estimate stays unbiased for every `n`.
//!
//! A perfect square `n = k²` uses the jittered `k × k` grid. Any other `n`
//! uses Latin hypercube sampling (one point in each of `n` columns and, by
//! a random permutation, in each of `n` rows): a `⌈√n⌉²` grid filled in
//! order would leave its last row's strata empty and bias the estimate
//! toward the others (measured on the cube with 128 gather rays: 1.8 % in
//! ρd, 4.9 % in ρs).

use rand::Rng;
use rand::seq::SliceRandom;
use rand_chacha::ChaCha8Rng;

/// The strata of `n` points.
#[derive(Debug, Clone)]
pub(crate) struct Strata {
    n: u32,
    /// The grid's side for a perfect square.
    side: Option<u32>,
    /// The row of each column (Latin hypercube), otherwise empty.
    rows: Vec<u32>,
}

impl Strata {
    /// The strata of `n ≥ 1` points; a Latin hypercube's permutation is
    /// drawn from `rng`.
    pub fn new(n: u32, rng: &mut ChaCha8Rng) -> Strata {
        let k = f64::from(n).sqrt().round() as u32;
        if k * k == n {
            return Strata {
                n,
                side: Some(k),
                rows: Vec::new(),
            };
        }
        let mut rows: Vec<u32> = (0..n).collect();
        rows.shuffle(rng);
        Strata { n, side: None, rows }
    }

    /// The jittered point of stratum `r` (< n).
    pub fn point(&self, r: u32, rng: &mut ChaCha8Rng) -> [f64; 2] {
        match self.side {
            Some(side) => {
                let (sx, sy) = (r % side, (r / side) % side);
                [
                    (f64::from(sx) + rng.random::<f64>()) / f64::from(side),
                    (f64::from(sy) + rng.random::<f64>()) / f64::from(side),
                ]
            }
            None => {
                let n = f64::from(self.n);
                [
                    (f64::from(r) + rng.random::<f64>()) / n,
                    (f64::from(self.rows[r as usize]) + rng.random::<f64>()) / n,
                ]
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use rand::SeedableRng;

    use super::*;

    /// The mean of u₀·u₁ over the points (exactly 1/4 over the square):
    /// unbiased for square and non-square counts, where the old ⌈√n⌉²
    /// grid filled in order was not.
    #[test]
    fn every_count_covers_the_square_evenly() {
        for n in [1u32, 2, 8, 16, 100, 128, 256] {
            let mut mean = 0.0;
            let trials = 2000u32;
            for t in 0..trials {
                let mut rng = ChaCha8Rng::seed_from_u64(u64::from(t));
                let s = Strata::new(n, &mut rng);
                let mut sum = 0.0;
                for r in 0..n {
                    let [a, b] = s.point(r, &mut rng);
                    assert!((0.0..1.0).contains(&a) && (0.0..1.0).contains(&b));
                    sum += a * b;
                }
                mean += sum / f64::from(n) / f64::from(trials);
            }
            // Four standard errors of the unstratified estimate (the
            // standard deviation of u₀u₁ is √(1/9 − 1/16) ≈ 0.22).
            let tol = 4.0 * 0.221 / f64::from(trials * n).sqrt();
            assert!((mean - 0.25).abs() < tol, "n = {n}: {mean} (tolerance {tol})");
        }
        // The old scheme at n = 128 (12 × 12 grid, 128 strata filled in order):
        let side = 12u32;
        let old: f64 = (0..128)
            .map(|r| (f64::from(r % side) + 0.5) / 12.0 * (f64::from(r / side) + 0.5) / 12.0)
            .sum::<f64>()
            / 128.0;
        assert!((old - 0.25).abs() > 0.02, "{old}");
    }
}

//! A response curve's codes at a bit depth, tabulated: the normalized
//! exposure at which each code begins, so that quantizing a sample is a
//! table lookup instead of a power and a sine ([`ParametricResponse`]'s
//! `f(x) = s(x^(1/γ))`).
//!
//! The table gives exactly the code the formula gives,
//! `round((2^bits − 1) · f(x))`: a sample that falls within a relative
//! [`MARGIN`] of a code boundary is worked out by the formula itself, and
//! the boundaries are correct far within that margin (they come from the
//! curve's inverse, [`ParametricResponse::exposure`], to about 1e-10
//! relative; the formula's own rounding is about 1e-15). A simulated
//! photograph is therefore the same image, code for code, either way (the
//! sensor's tests hold it). It is what the simulated cameras spend their
//! time on: a 256 × 192 photograph is 147 456 samples, and the example day
//! takes 1 227 of them.

use std::sync::{Arc, Mutex};

use super::image::max_code;
use super::response::ParametricResponse;

/// A sample this close to a code boundary (relative to the sample) is
/// quantized by the formula, not the table.
pub const MARGIN: f64 = 1e-7;

/// The boundaries of one channel's codes.
#[derive(Debug, Clone, PartialEq)]
pub struct CodeTable {
    response: ParametricResponse,
    top: f64,
    /// `starts[k]`: the normalized exposure at which code `k + 1` begins
    /// (where `top · f(x)` reaches `k + ½`), increasing.
    starts: Vec<f64>,
    /// Per bucket of `√x` (`buckets.len()` of them over `[0, 1]`), how
    /// many `starts` lie in the buckets before it: where to begin counting.
    first: Vec<u32>,
}

impl CodeTable {
    /// The table of `response` at `bits` (1–16) bits.
    pub fn new(response: ParametricResponse, bits: u8) -> CodeTable {
        let top = f64::from(max_code(bits));
        let codes = max_code(bits) as usize;
        let starts: Vec<f64> = (1..=codes).map(|k| response.exposure((k as f64 - 0.5) / top)).collect();
        // About two buckets a code, at most 16 384 (64 KiB of counts).
        let n = (2 * codes).clamp(2, 16_384);
        let mut first = vec![0u32; n];
        let mut k = 0;
        for (b, f) in first.iter_mut().enumerate() {
            while k < starts.len() && bucket(starts[k], n) < b {
                k += 1;
            }
            *f = k as u32;
        }
        CodeTable {
            response,
            top,
            starts,
            first,
        }
    }

    /// `round((2^bits − 1) · f(x))` for a normalized exposure `x` in
    /// `[0, 1]` (the formula's own clamp handles the rest).
    #[inline]
    pub fn code(&self, x: f64) -> u16 {
        if !(0.0..=1.0).contains(&x) {
            return self.exact(x);
        }
        let mut k = self.first[bucket(x, self.first.len())] as usize;
        while k < self.starts.len() && self.starts[k] <= x {
            k += 1;
        }
        let below = if k > 0 { x - self.starts[k - 1] } else { f64::INFINITY };
        let above = self.starts.get(k).map_or(f64::INFINITY, |s| s - x);
        if below.min(above) <= MARGIN * x {
            return self.exact(x);
        }
        k as u16
    }

    /// The formula, as [`CameraModel::photograph`](super::sensor::CameraModel::photograph) has always
    /// computed it.
    fn exact(&self, x: f64) -> u16 {
        (self.top * self.response.code_fraction(x)).round() as u16
    }
}

/// The bucket of `x` among `n` over `√x` in `[0, 1]`; never decreasing in
/// `x` (a correctly rounded square root, a product and a floor), which is
/// what makes `first` a lower bound of the count.
#[inline]
fn bucket(x: f64, n: usize) -> usize {
    ((x.sqrt() * n as f64) as usize).min(n - 1)
}

/// The tables of `responses` at `bits`, built once a process per camera
/// (a 12-bit table takes about a millisecond, a 16-bit one about 50) and
/// shared after that. The last few cameras are kept.
pub fn code_tables(responses: &[ParametricResponse; 3], bits: u8) -> Arc<[CodeTable; 3]> {
    type Kept = Vec<(([ParametricResponse; 3], u8), Arc<[CodeTable; 3]>)>;
    static KEPT: Mutex<Kept> = Mutex::new(Vec::new());
    let key = (*responses, bits);
    if let Some((_, t)) = KEPT
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .iter()
        .find(|(k, _)| *k == key)
    {
        return t.clone();
    }
    // Built outside the lock: another thread may have kept the same
    // camera's tables meanwhile, and then those are handed out.
    let tables = Arc::new(responses.map(|r| CodeTable::new(r, bits)));
    let mut kept = KEPT.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((_, t)) = kept.iter().find(|(k, _)| *k == key) {
        return t.clone();
    }
    if kept.len() >= 8 {
        kept.remove(0);
    }
    kept.push((key, tables.clone()));
    tables
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    fn formula(r: &ParametricResponse, bits: u8, x: f64) -> u16 {
        (f64::from(max_code(bits)) * r.code_fraction(x)).round() as u16
    }

    /// Code for code the formula's, on random exposures, on exposures at
    /// and next to every boundary, at the ends and outside `[0, 1]`, for
    /// the typical camera's curves, a linear one and a strong S-curve, at
    /// 8, 12 and 16 bits.
    #[test]
    fn the_table_gives_the_formulas_code_everywhere() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let curves = [(2.3, 0.55), (2.2, 0.5), (1.0, 0.0), (1.8, 0.95), (3.0, 0.2)];
        let mut near_margin = 0;
        for (gamma, s) in curves {
            let r = ParametricResponse::new(gamma, s).unwrap();
            for bits in [8u8, 12, 16] {
                let table = CodeTable::new(r, bits);
                assert!(
                    table.starts.windows(2).all(|w| w[0] < w[1]),
                    "γ {gamma} s {s}: starts increase"
                );
                let mut xs: Vec<f64> = (0..20_000).map(|_| rng.random::<f64>().powi(3)).collect();
                xs.extend([0.0, 1.0, -0.5, 1.5, f64::MIN_POSITIVE, 1e-300, 1.0 - f64::EPSILON]);
                for &t in table.starts.iter().step_by(7) {
                    xs.extend([
                        t,
                        t.next_up(),
                        t.next_down(),
                        t * (1.0 + 2.0 * MARGIN),
                        t * (1.0 - 2.0 * MARGIN),
                    ]);
                    near_margin += 1;
                }
                for x in xs {
                    assert_eq!(
                        table.code(x),
                        formula(&r, bits, x),
                        "γ {gamma} s {s} bits {bits} x {x:e}"
                    );
                }
            }
        }
        assert!(near_margin > 10_000, "boundaries exercised: {near_margin}");
    }

    /// The boundaries themselves are within a thousandth of the margin of
    /// where the formula's code changes: a bisection on the formula finds
    /// each one.
    #[test]
    fn the_boundaries_are_far_more_accurate_than_the_margin() {
        let r = ParametricResponse::new(2.2, 0.5).unwrap();
        let table = CodeTable::new(r, 16);
        let mut worst = 0.0f64;
        for (k, &t) in table.starts.iter().enumerate().step_by(97) {
            // The formula's boundary between codes k and k + 1 by bisection.
            let (mut lo, mut hi) = (0.0f64, 1.0f64);
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if usize::from(formula(&r, 16, mid)) > k {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            worst = worst.max((hi - t).abs() / t);
        }
        assert!(worst < MARGIN * 1e-3, "worst relative boundary error {worst:e}");
    }

    /// One build per camera: the second call hands out the same tables.
    #[test]
    fn tables_are_built_once_per_camera() {
        let r = [ParametricResponse::new(2.05, 0.31).unwrap(); 3];
        let a = code_tables(&r, 10);
        let b = code_tables(&r, 10);
        assert!(Arc::ptr_eq(&a, &b));
        assert_eq!(a[0].starts.len(), 1023);
    }
}

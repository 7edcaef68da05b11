//! Eq. (5.9) over the prepared samples, [`LANES`] samples at a time: the
//! weighted residuals, the analytic Jacobian accumulated straight into
//! JᵀJ and Jᵀr (no m × n Jacobian is stored), and the closed-form scale
//! sums of the starts.
//!
//! The samples' geometry (1/cos ξ, γ, ln γ, cos² γ) and 1/σ are computed
//! once per fit and stored as one array each, padded to a multiple of
//! [`LANES`] with samples of weight 0. Every loop runs over [`LANES`]
//! independent lanes with one accumulator per lane, so the compiler can
//! map them onto vector registers without reordering a floating-point sum
//! itself (which it may not do); the lanes' sums are added at the end. The
//! hot functions are compiled twice, for the x86-64 baseline and for
//! AVX2 + FMA, and the one the processor supports is chosen at run time.

// Lanes and small dense matrices read best as index loops.
#![allow(clippy::needless_range_loop)]

use multiversion::multiversion;
use multiversion::target::selected_target;

use super::super::seven_parameter::COS_XI_FLOOR;
use super::SkySample;
use super::elementary::{cos_0_pi, exp, exp_with, ln_normal, madd};

/// Samples evaluated together.
pub const LANES: usize = 4;

/// The samples, with everything that does not depend on θ computed once,
/// padded to a multiple of [`LANES`].
#[derive(Debug, Clone)]
pub struct Prepared {
    n: usize,
    inv_cos: Vec<f64>,
    gamma: Vec<f64>,
    ln_gamma: Vec<f64>,
    cos2: Vec<f64>,
    inv_sigma: Vec<f64>,
    y: Vec<f64>,
}

impl Prepared {
    /// `sigma[i]` is sample i's weight denominator (see the module doc of
    /// `fit`).
    pub fn new(samples: &[SkySample], sigma: &[f64]) -> Self {
        let n = samples.len().min(sigma.len());
        let mut p = Prepared {
            n,
            inv_cos: vec![0.0; n],
            gamma: vec![0.0; n],
            ln_gamma: vec![0.0; n],
            cos2: vec![0.0; n],
            inv_sigma: vec![0.0; n],
            y: vec![0.0; n],
        };
        geometry(&samples[..n], &sigma[..n], &mut p);
        // What the polynomials do not cover: ξ or γ outside [0, π]
        // (unchecked callers), γ = 0 or subnormal.
        for (i, s) in samples[..n].iter().enumerate() {
            let g = s.gamma.abs();
            if !(0.0..=std::f64::consts::PI).contains(&s.xi) {
                p.inv_cos[i] = 1.0 / s.xi.cos().max(COS_XI_FLOOR);
            }
            if g > std::f64::consts::PI || g.is_nan() {
                p.cos2[i] = g.cos().powi(2);
            }
            if !(g >= f64::MIN_POSITIVE && g.is_finite()) {
                p.ln_gamma[i] = if g > 0.0 { g.ln() } else { 0.0 };
            }
        }
        p.pad();
        p
    }

    /// Fills the arrays up to a multiple of [`LANES`] with samples that
    /// weigh nothing (1/σ = 0) and whose model is finite for any θ in the
    /// box.
    fn pad(&mut self) {
        let padded = self.n.div_ceil(LANES) * LANES;
        self.inv_cos.resize(padded, 1.0);
        self.gamma.resize(padded, 1.0);
        self.ln_gamma.resize(padded, 0.0);
        self.cos2.resize(padded, 0.0);
        self.inv_sigma.resize(padded, 0.0);
        self.y.resize(padded, 0.0);
    }

    /// Every `step`-th sample, prepared.
    pub fn strided(&self, step: usize) -> Prepared {
        let pick = |v: &[f64]| -> Vec<f64> { v[..self.n].iter().step_by(step.max(1)).copied().collect() };
        let mut p = Prepared {
            n: self.n.div_ceil(step.max(1)),
            inv_cos: pick(&self.inv_cos),
            gamma: pick(&self.gamma),
            ln_gamma: pick(&self.ln_gamma),
            cos2: pick(&self.cos2),
            inv_sigma: pick(&self.inv_sigma),
            y: pick(&self.y),
        };
        p.pad();
        p
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.n
    }

    /// Sample i's measured value.
    pub fn y(&self, i: usize) -> f64 {
        self.y[i]
    }

    /// Sample i's 1/σ.
    pub fn inv_sigma(&self, i: usize) -> f64 {
        self.inv_sigma[i]
    }

    /// Each sample's 1/σ times √wᵢ (1/σ alone without weights), padded:
    /// the factor of its residual.
    pub fn residual_scale(&self, weights: Option<&[f64]>) -> Vec<f64> {
        match weights {
            None => self.inv_sigma.clone(),
            Some(w) => {
                assert_eq!(w.len(), self.n, "one weight per sample");
                let mut s: Vec<f64> = self.inv_sigma.iter().zip(w).map(|(s, w)| s * w.sqrt()).collect();
                s.resize(self.inv_sigma.len(), 0.0);
                s
            }
        }
    }

    /// The weighted sums (Σ S y, Σ S², Σ y²) of the shape S = the model of
    /// `t` and the samples y, each divided by σ: the scale that fits S to
    /// y in closed form is Σ S y / Σ S², its residual sum of squares
    /// Σ y² − (Σ S y)² / Σ S².
    pub fn scale_sums(&self, t: &[f64; 7]) -> (f64, f64, f64) {
        if t[6] == 1.0 {
            scale_sums::<true>(self, t)
        } else {
            scale_sums::<false>(self, t)
        }
    }

    /// The model's value at sample i, for θ's natural parameters
    /// `[Lz, a, b, c, d, e, h]`.
    pub fn model_at(&self, t: &[f64; 7], i: usize) -> f64 {
        let bg = 1.0 + t[1] * exp(t[2] * self.inv_cos[i]);
        let gh = if t[6] == 1.0 {
            self.gamma[i]
        } else if self.gamma[i] > 0.0 {
            exp(t[6] * self.ln_gamma[i])
        } else {
            0.0
        };
        let sa = 1.0 + t[3] * exp(t[4] * gh) + t[5] * self.cos2[i];
        t[0] * bg * sa
    }
}

/// The θ-free parts of each sample, by the polynomials of
/// [`super::elementary`] (valid for ξ and γ in [0, π] and γ normal;
/// [`Prepared::new`] redoes the others with the library's functions).
#[multiversion(targets("x86_64+avx2+fma"))]
fn geometry(samples: &[SkySample], sigma: &[f64], p: &mut Prepared) {
    for (i, (s, sg)) in samples.iter().zip(sigma).enumerate() {
        let g = s.gamma.abs();
        let cg = cos_0_pi(g.min(std::f64::consts::PI));
        p.inv_cos[i] = 1.0 / cos_0_pi(s.xi.clamp(0.0, std::f64::consts::PI)).max(COS_XI_FLOOR);
        p.gamma[i] = g;
        p.ln_gamma[i] = ln_normal(g.max(f64::MIN_POSITIVE));
        p.cos2[i] = cg * cg;
        p.inv_sigma[i] = 1.0 / sg;
        p.y[i] = s.radiance;
    }
}

/// The cost ½Σ wᵢ rᵢ², the gradient Jᵀr and JᵀJ over the free parameters
/// (indexed 0..k in the order of `free`).
#[derive(Debug, Clone)]
pub struct Evaluation {
    /// ½ Σ wᵢ rᵢ².
    pub cost: f64,
    /// Jᵀ W r.
    pub grad: [f64; 7],
    /// Jᵀ W J (upper triangle and diagonal filled, then mirrored).
    pub jtj: [[f64; 7]; 7],
}

/// Samples computed together before their sums are taken.
const BLOCK: usize = 64;
/// A block's groups of [`LANES`].
const CHUNKS: usize = BLOCK / LANES;

/// The seven partial derivatives of L of one block of samples and their
/// residuals, weighted, one array each: `col[j]` for θ's entry j, and
/// `col[R]` the residuals.
struct Rows {
    col: [[[f64; LANES]; CHUNKS]; 8],
}

/// The index of the residuals in [`Rows::col`].
const R: usize = 7;

impl Rows {
    fn new() -> Self {
        Rows {
            col: [[[0.0; LANES]; CHUNKS]; 8],
        }
    }
}

/// Fills `rows` for the `m` ≤ [`BLOCK`] samples from `start`, each
/// residual and derivative multiplied by `scale`. `t` holds θ's natural
/// parameters; `H_ONE` says h = 1, when γ^h is γ; without `JAC` only
/// the model L (`col[0]`) is filled, all the starts' scale sums need. Each
/// loop is one operation over the block, so that each vectorizes.
#[inline(always)]
fn rows<const H_ONE: bool, const FMA: bool, const JAC: bool>(
    prep: &Prepared,
    t: &[f64; 7],
    scale: &[f64],
    start: usize,
    m: usize,
    rows: &mut Rows,
) {
    let [lz, a, b, c, d, e, h] = *t;
    let end = start + m;
    let inv_cos = &prep.inv_cos[start..end];
    let gamma = &prep.gamma[start..end];
    let ln_gamma = &prep.ln_gamma[start..end];
    let cos2 = &prep.cos2[start..end];
    let y = &prep.y[start..end];
    let scale = &scale[start..end];
    let mut e1 = [0.0; BLOCK];
    let e1 = &mut e1[..m];
    for (e1, &u) in e1.iter_mut().zip(inv_cos) {
        *e1 = exp_with::<FMA>(b * u);
    }
    let mut gh_h = [0.0; BLOCK];
    let gh: &[f64] = if H_ONE {
        gamma
    } else {
        for ((gh, &g), &lg) in gh_h.iter_mut().zip(gamma).zip(ln_gamma) {
            let v = exp_with::<FMA>(h * lg);
            *gh = if g > 0.0 { v } else { 0.0 };
        }
        &gh_h[..m]
    };
    let mut e2 = [0.0; BLOCK];
    let e2 = &mut e2[..m];
    for (e2, &g) in e2.iter_mut().zip(gh.iter()) {
        *e2 = exp_with::<FMA>(d * g);
    }
    let [c0, c1, c2, c3, c4, c5, c6, r] = &mut rows.col;
    let (c0, c1, c2, c3, c4, c5, c6, r) = (
        &mut c0.as_flattened_mut()[..m],
        &mut c1.as_flattened_mut()[..m],
        &mut c2.as_flattened_mut()[..m],
        &mut c3.as_flattened_mut()[..m],
        &mut c4.as_flattened_mut()[..m],
        &mut c5.as_flattened_mut()[..m],
        &mut c6.as_flattened_mut()[..m],
        &mut r.as_flattened_mut()[..m],
    );
    if !JAC {
        for i in 0..m {
            let bg = 1.0 + a * e1[i];
            let sa = 1.0 + c * e2[i] + e * cos2[i];
            c0[i] = lz * bg * scale[i] * sa;
        }
        return;
    }
    for i in 0..m {
        let bg = 1.0 + a * e1[i];
        let sa = 1.0 + c * e2[i] + e * cos2[i];
        let s = scale[i];
        let lbg = lz * bg * s;
        let lsa = lz * sa * s;
        let l = lbg * sa;
        r[i] = l - y[i] * s;
        c0[i] = l;
        c1[i] = lsa * e1[i];
        c2[i] = lsa * a * e1[i] * inv_cos[i];
        c3[i] = lbg * e2[i];
        let dc = lbg * c * e2[i] * gh[i];
        c4[i] = dc;
        c5[i] = lbg * cos2[i];
        c6[i] = dc * d * ln_gamma[i];
    }
}

/// The lanes' sum.
#[inline(always)]
fn sum(x: &[f64; LANES]) -> f64 {
    (x[0] + x[2]) + (x[1] + x[3])
}

/// The accumulation for K free parameters picked by `free`, with every
/// residual multiplied by `scale` (padded like the samples). `t` holds θ's
/// natural parameters; `H_ONE` says h = 1, when γ^h is γ.
#[multiversion(targets("x86_64+avx2+fma"))]
fn accumulate<const K: usize, const H_ONE: bool>(
    prep: &Prepared,
    t: &[f64; 7],
    free: [usize; K],
    scale: &[f64],
) -> Evaluation {
    if selected_target!().supports_feature_str("fma") {
        accumulate_with::<K, H_ONE, true>(prep, t, free, scale)
    } else {
        accumulate_with::<K, H_ONE, false>(prep, t, free, scale)
    }
}

// The products summed for K free parameters (4, 6, 7), as pairs of
// [`Rows::col`] indices (θ entries, [`R`] the residuals): the upper
// triangle of JᵀJ, then Jᵀr, then rᵀr, in groups of at most [`GROUP`],
// each summed over a whole block before the next, so that a group's
// accumulators stay in registers instead of going to memory and back for
// every sample (which cost a third of the fit: 1.26 → 0.79 ms a channel,
// the sums bit for bit the same).
const P4A: Pairs<5> = [(0, 0), (0, 1), (0, 2), (0, 5), (1, 1)];
const P4B: Pairs<5> = [(1, 2), (1, 5), (2, 2), (2, 5), (5, 5)];
const P4C: Pairs<5> = [(0, R), (1, R), (2, R), (5, R), (R, R)];
const P6A: Pairs<6> = [(0, 0), (0, 1), (0, 2), (0, 3), (0, 4), (0, 5)];
const P6B: Pairs<6> = [(1, 1), (1, 2), (1, 3), (1, 4), (1, 5), (2, 2)];
const P6C: Pairs<6> = [(2, 3), (2, 4), (2, 5), (3, 3), (3, 4), (3, 5)];
const P6D: Pairs<5> = [(4, 4), (4, 5), (5, 5), (0, R), (1, R)];
const P6E: Pairs<5> = [(2, R), (3, R), (4, R), (5, R), (R, R)];
const P7A: Pairs<6> = [(0, 0), (0, 1), (0, 2), (0, 3), (0, 4), (0, 5)];
const P7B: Pairs<6> = [(0, 6), (1, 1), (1, 2), (1, 3), (1, 4), (1, 5)];
const P7C: Pairs<6> = [(1, 6), (2, 2), (2, 3), (2, 4), (2, 5), (2, 6)];
const P7D: Pairs<6> = [(3, 3), (3, 4), (3, 5), (3, 6), (4, 4), (4, 5)];
const P7E: Pairs<6> = [(4, 6), (5, 5), (5, 6), (6, 6), (0, R), (1, R)];
const P7F: Pairs<6> = [(2, R), (3, R), (4, R), (5, R), (6, R), (R, R)];

/// N pairs of [`Rows::col`] indices.
type Pairs<const N: usize> = [(usize, usize); N];

/// Adds Σ over the block's first `chunks` groups of lanes of the products
/// of `pairs` (at most [`GROUP`]) to `acc`, one accumulator per pair and
/// lane.
#[inline(always)]
fn sum_group<const N: usize, const FMA: bool>(
    block: &Rows,
    chunks: usize,
    pairs: &Pairs<N>,
    acc: &mut [[f64; LANES]; GROUP],
) {
    let mut a = [[0.0; LANES]; N];
    a.copy_from_slice(&acc[..N]);
    for j in 0..chunks {
        for (g, &(p, q)) in pairs.iter().enumerate() {
            let (u, v) = (&block.col[p][j], &block.col[q][j]);
            for l in 0..LANES {
                a[g][l] = madd::<FMA>(u[l], v[l], a[g][l]);
            }
        }
    }
    acc[..N].copy_from_slice(&a);
}

/// The largest group.
const GROUP: usize = 6;

/// [`accumulate`]'s body, with fused multiply-adds when `FMA`.
#[inline(always)]
fn accumulate_with<const K: usize, const H_ONE: bool, const FMA: bool>(
    prep: &Prepared,
    t: &[f64; 7],
    free: [usize; K],
    scale: &[f64],
) -> Evaluation {
    let groups: &[&[(usize, usize)]] = match K {
        4 => &[&P4A, &P4B, &P4C],
        6 => &[&P6A, &P6B, &P6C, &P6D, &P6E],
        _ => &[&P7A, &P7B, &P7C, &P7D, &P7E, &P7F],
    };
    let mut acc = [[[0.0; LANES]; GROUP]; 6];
    let mut block = Rows::new();
    let total = prep.inv_cos.len();
    for start in (0..total).step_by(BLOCK) {
        let m = BLOCK.min(total - start);
        let chunks = (m / LANES).min(CHUNKS);
        rows::<H_ONE, FMA, true>(prep, t, scale, start, m, &mut block);
        // One call per group, each with its pairs known at compile time,
        // so that the loop over them unrolls.
        let [a0, a1, a2, a3, a4, a5] = &mut acc;
        match K {
            4 => {
                sum_group::<5, FMA>(&block, chunks, &P4A, a0);
                sum_group::<5, FMA>(&block, chunks, &P4B, a1);
                sum_group::<5, FMA>(&block, chunks, &P4C, a2);
            }
            6 => {
                sum_group::<6, FMA>(&block, chunks, &P6A, a0);
                sum_group::<6, FMA>(&block, chunks, &P6B, a1);
                sum_group::<6, FMA>(&block, chunks, &P6C, a2);
                sum_group::<5, FMA>(&block, chunks, &P6D, a3);
                sum_group::<5, FMA>(&block, chunks, &P6E, a4);
            }
            _ => {
                sum_group::<6, FMA>(&block, chunks, &P7A, a0);
                sum_group::<6, FMA>(&block, chunks, &P7B, a1);
                sum_group::<6, FMA>(&block, chunks, &P7C, a2);
                sum_group::<6, FMA>(&block, chunks, &P7D, a3);
                sum_group::<6, FMA>(&block, chunks, &P7E, a4);
                sum_group::<6, FMA>(&block, chunks, &P7F, a5);
            }
        }
    }
    // θ entry → its place among the free parameters.
    let mut place = [usize::MAX; 8];
    for (p, &j) in free.iter().enumerate() {
        place[j] = p;
    }
    let mut ev = Evaluation {
        cost: 0.0,
        grad: [0.0; 7],
        jtj: [[0.0; 7]; 7],
    };
    for (pairs, acc) in groups.iter().zip(&acc) {
        for (&(p, q), a) in pairs.iter().zip(acc) {
            let v = sum(a);
            match (p, q) {
                (R, R) => ev.cost = 0.5 * v,
                (p, R) => ev.grad[place[p]] = v,
                (p, q) => {
                    let (u, w) = (place[p], place[q]);
                    ev.jtj[u][w] = v;
                    ev.jtj[w][u] = v;
                }
            }
        }
    }
    ev
}

/// The sums of [`Prepared::scale_sums`].
#[multiversion(targets("x86_64+avx2+fma"))]
fn scale_sums<const H_ONE: bool>(prep: &Prepared, t: &[f64; 7]) -> (f64, f64, f64) {
    if selected_target!().supports_feature_str("fma") {
        scale_sums_with::<H_ONE, true>(prep, t)
    } else {
        scale_sums_with::<H_ONE, false>(prep, t)
    }
}

#[inline(always)]
fn scale_sums_with<const H_ONE: bool, const FMA: bool>(prep: &Prepared, t: &[f64; 7]) -> (f64, f64, f64) {
    let mut sy = [0.0; LANES];
    let mut ss = [0.0; LANES];
    let mut yy = [0.0; LANES];
    let t = [1.0, t[1], t[2], t[3], t[4], t[5], t[6]];
    let mut block = Rows::new();
    let total = prep.inv_cos.len();
    for start in (0..total).step_by(BLOCK) {
        let m = BLOCK.min(total - start);
        // col[0] is S/σ.
        rows::<H_ONE, FMA, false>(prep, &t, &prep.inv_sigma, start, m, &mut block);
        let s = &block.col[0].as_flattened()[..m];
        let y = &prep.y[start..start + m];
        let w = &prep.inv_sigma[start..start + m];
        for c in (0..m).step_by(LANES) {
            for l in 0..LANES {
                let (s, y) = (s[c + l], y[c + l] * w[c + l]);
                sy[l] = madd::<FMA>(s, y, sy[l]);
                ss[l] = madd::<FMA>(s, s, ss[l]);
                yy[l] = madd::<FMA>(y, y, yy[l]);
            }
        }
    }
    (sum(&sy), sum(&ss), sum(&yy))
}

/// θ's natural parameters `[Lz, a, b, c, d, e, h]`.
pub fn natural(theta: &[f64; 7]) -> [f64; 7] {
    let mut t = *theta;
    t[0] = theta[0].exp();
    t
}

/// Evaluates the cost, gradient and Gauss–Newton matrix at θ over the
/// `free` entries, each residual multiplied by `scale`
/// ([`Prepared::residual_scale`]), or `None` when something is not finite.
pub fn evaluate(prep: &Prepared, theta: &[f64; 7], free: &[usize], scale: &[f64]) -> Option<Evaluation> {
    let t = natural(theta);
    // Monomorphized for the candidates' parameter counts, so that the
    // accumulation of JᵀJ unrolls; any other pattern takes all seven and
    // keeps its own rows and columns.
    let ev = match (free, t[6] == 1.0) {
        ([0, 1, 2, 5], true) => accumulate::<4, true>(prep, &t, [0, 1, 2, 5], scale),
        ([0, 1, 2, 5], false) => accumulate::<4, false>(prep, &t, [0, 1, 2, 5], scale),
        ([0, 1, 2, 3, 4, 5], true) => accumulate::<6, true>(prep, &t, [0, 1, 2, 3, 4, 5], scale),
        ([0, 1, 2, 3, 4, 5], false) => accumulate::<6, false>(prep, &t, [0, 1, 2, 3, 4, 5], scale),
        (_, h_one) => {
            let all = if h_one {
                accumulate::<7, true>(prep, &t, [0, 1, 2, 3, 4, 5, 6], scale)
            } else {
                accumulate::<7, false>(prep, &t, [0, 1, 2, 3, 4, 5, 6], scale)
            };
            let mut ev = Evaluation {
                cost: all.cost,
                grad: [0.0; 7],
                jtj: [[0.0; 7]; 7],
            };
            for (p, &j) in free.iter().enumerate() {
                ev.grad[p] = all.grad[j];
                for (q, &k) in free.iter().enumerate() {
                    ev.jtj[p][q] = all.jtj[j][k];
                }
            }
            ev
        }
    };
    let k = free.len();
    let finite = ev.cost.is_finite()
        && ev.grad[..k].iter().all(|x| x.is_finite())
        && ev.jtj[..k].iter().all(|r| r[..k].iter().all(|x| x.is_finite()));
    finite.then_some(ev)
}

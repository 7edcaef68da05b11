//! `exp`, `ln` and `cos` as inlined, branch-free polynomials, so that
//! loops over samples vectorize (the library's calls do not), each within a
//! few ulps of the library's on the arguments the sky fit gives them.

/// `e^x` to within a few ulps of [`f64::exp`] on [−708, 709]: reduced to
/// `2^k e^r` with |r| ≤ ln 2 / 2 (Cody–Waite, ln 2 in two parts) and `e^r`
/// by its Taylor series to r¹² (truncation < 2·10⁻¹⁶); 2^k is built from
/// the bits of the rounding sum itself. Above 709 it is +∞ (the library
/// overflows at 709.78), below −708 it is 0 (the library's value there is
/// below 3·10⁻³⁰⁸), NaN stays NaN.
#[inline(always)]
pub fn exp(x: f64) -> f64 {
    exp_with::<false>(x)
}

/// `a b + c`, fused when `FMA` (for code compiled with the FMA feature;
/// elsewhere a fused multiply-add is a slow library call).
#[inline(always)]
pub fn madd<const FMA: bool>(a: f64, b: f64, c: f64) -> f64 {
    if FMA { a.mul_add(b, c) } else { a * b + c }
}

/// [`exp`], its polynomial by fused multiply-adds when `FMA`.
#[inline(always)]
pub fn exp_with<const FMA: bool>(x: f64) -> f64 {
    const LN2_HI: f64 = 6.931_471_803_691_238e-1;
    const LN2_LO: f64 = 1.908_214_929_270_587_7e-10;
    // Round to nearest by the 1.5·2⁵² trick: the sum's low mantissa bits
    // are k itself.
    const SHIFT: f64 = 6_755_399_441_055_744.0;
    const C: [f64; 13] = [
        1.0,
        1.0,
        1.0 / 2.0,
        1.0 / 6.0,
        1.0 / 24.0,
        1.0 / 120.0,
        1.0 / 720.0,
        1.0 / 5040.0,
        1.0 / 40320.0,
        1.0 / 362_880.0,
        1.0 / 3_628_800.0,
        1.0 / 39_916_800.0,
        1.0 / 479_001_600.0,
    ];
    let xc = x.clamp(-708.0, 709.0);
    let shifted = xc * std::f64::consts::LOG2_E + SHIFT;
    let k = shifted - SHIFT;
    let r = (xc - k * LN2_HI) - k * LN2_LO;
    let mut p = C[12];
    for &c in C[..12].iter().rev() {
        p = madd::<FMA>(p, r, c);
    }
    // bits(shifted) = bits(SHIFT) + k for |k| < 2⁵¹.
    let two_k = f64::from_bits(shifted.to_bits().wrapping_sub(SHIFT.to_bits()).wrapping_add(1023) << 52);
    let v = two_k * p;
    if x < -708.0 {
        0.0
    } else if x > 709.0 {
        f64::INFINITY
    } else {
        v
    }
}

/// `ln x` to within a few ulps of [`f64::ln`] for normal positive x:
/// x = 2^e m with m in [√½, √2), ln m = 2 atanh s with s = (m − 1)/(m + 1),
/// |s| < 0.172, by its series to s²¹ (truncation < 10⁻¹⁸). Not for 0,
/// subnormals, negatives, ∞ or NaN: the caller routes those to
/// [`f64::ln`].
#[inline(always)]
pub fn ln_normal(x: f64) -> f64 {
    const LN2_HI: f64 = 6.931_471_803_691_238e-1;
    const LN2_LO: f64 = 1.908_214_929_270_587_7e-10;
    const MANTISSA: u64 = (1 << 52) - 1;
    let bits = x.to_bits();
    // m in [1, 2), then halved when above √2.
    let m1 = f64::from_bits((bits & MANTISSA) | (1023 << 52));
    // The biased exponent as a float through 2⁵² (an integer conversion
    // would not vectorize).
    const TWO52: f64 = 4_503_599_627_370_496.0;
    let e1 = f64::from_bits(((bits >> 52) & 0x7ff) | TWO52.to_bits()) - (TWO52 + 1023.0);
    let high = m1 > std::f64::consts::SQRT_2;
    let m = if high { 0.5 * m1 } else { m1 };
    let e = if high { e1 + 1.0 } else { e1 };
    let s = (m - 1.0) / (m + 1.0);
    let s2 = s * s;
    let mut p = 1.0 / 21.0;
    for k in (1..10).rev() {
        p = p * s2 + 1.0 / f64::from(2 * k + 1);
    }
    let ln_m = 2.0 * s + 2.0 * s * s2 * p;
    e * LN2_HI + (ln_m + e * LN2_LO)
}

/// `cos x` to within 2.2·10⁻¹⁶ (absolute: an ulp of 1) of [`f64::cos`]
/// for x in [0, π]: cos x = −sin(x − π/2), π/2 in two parts,
/// sin by its Taylor series to y²¹ (truncation < 10⁻¹⁸ for |y| ≤ π/2).
#[inline(always)]
pub fn cos_0_pi(x: f64) -> f64 {
    const PIO2_HI: f64 = std::f64::consts::FRAC_PI_2;
    const PIO2_LO: f64 = 6.123_233_995_736_766e-17;
    let y = (x - PIO2_HI) - PIO2_LO;
    let y2 = y * y;
    // sin y = y + y³ (−1/3! + y²/5! − y⁴/7! + … + y¹⁸/21!).
    const C: [f64; 10] = [
        -1.0 / 6.0,
        1.0 / 120.0,
        -1.0 / 5040.0,
        1.0 / 362_880.0,
        -1.0 / 39_916_800.0,
        1.0 / 6_227_020_800.0,
        -1.0 / 1_307_674_368_000.0,
        1.0 / 355_687_428_096_000.0,
        -1.0 / 121_645_100_408_832_000.0,
        1.0 / 51_090_942_171_709_440_000.0,
    ];
    let mut p = C[9];
    for &c in C[..9].iter().rev() {
        p = p * y2 + c;
    }
    -(y + y * y2 * p)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_inlined_exp_is_within_4_ulps_of_the_librarys() {
        let mut worst = 0.0_f64;
        for i in -200_000..=200_000 {
            let x = f64::from(i) * 3.5e-3 + 1e-7;
            let (a, b) = (exp(x), x.exp());
            worst = worst.max((a / b - 1.0).abs());
        }
        assert!(worst < 4.0 * f64::EPSILON, "{worst:e}");
        assert_eq!(exp(800.0), f64::INFINITY);
        assert_eq!(exp(-800.0), 0.0);
        assert_eq!(exp(0.0), 1.0);
        assert!(exp(f64::NAN).is_nan());
    }

    #[test]
    fn the_inlined_ln_is_within_4_ulps_of_the_librarys() {
        let mut worst = 0.0_f64;
        for i in 1..=400_000 {
            // 10⁻¹² to π and beyond, log-spaced.
            let x = 1e-12 * (f64::from(i) * 7.5e-5).exp();
            let (a, b) = (ln_normal(x), x.ln());
            worst = worst.max((a - b).abs() / b.abs().max(1.0));
        }
        assert!(worst < 4.0 * f64::EPSILON, "{worst:e}");
        assert_eq!(ln_normal(1.0), 0.0);
    }

    #[test]
    fn the_inlined_cos_is_within_an_ulp_of_1_of_the_librarys_on_0_to_pi() {
        let mut worst = 0.0_f64;
        for i in 0..=400_000 {
            let x = std::f64::consts::PI * f64::from(i) / 400_000.0;
            worst = worst.max((cos_0_pi(x) - x.cos()).abs());
        }
        assert!(worst <= f64::EPSILON, "{worst:e}");
    }
}

//! Error figures reported against a known answer (the simulator's truth,
//! a reference render): quantiles of per-cell errors and the relative RMSE
//! of images compared over pixel blocks, where Monte Carlo noise averages out.

use crate::camera::image::RadianceImage;

/// Quantile `q` (0–1, nearest rank) of `v`, which is sorted in place; NaN when empty.
pub fn quantile(v: &mut [f64], q: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    v[((v.len() - 1) as f64 * q.clamp(0.0, 1.0)).round() as usize]
}

/// Relative RMSE of `image` against `reference` over `k × k` block means,
/// per channel, over the blocks wholly inside `mask` (`true` = use):
/// √(Σ (ā − b̄)² / Σ b̄²). NaN when no block counts or the reference is black there.
pub fn block_relative_rmse(image: &RadianceImage, reference: &RadianceImage, mask: &[bool], k: usize) -> f64 {
    let k = k.max(1);
    let (mut num, mut den) = (0.0, 0.0);
    for by in 0..image.height / k {
        for bx in 0..image.width / k {
            let px: Vec<usize> = (0..k * k)
                .map(|q| (by * k + q / k) * image.width + bx * k + q % k)
                .collect();
            if !px.iter().all(|&i| mask[i]) {
                continue;
            }
            for ch in 0..3 {
                let mean = |im: &RadianceImage| {
                    px.iter().map(|&i| f64::from(im.data[i * 3 + ch])).sum::<f64>() / px.len() as f64
                };
                num += (mean(image) - mean(reference)).powi(2);
                den += mean(reference).powi(2);
            }
        }
    }
    if den > 0.0 { (num / den).sqrt() } else { f64::NAN }
}

/// Pearson correlation of `a` with `b` (paired): whether a recovered texture
/// follows the true one, not just its mean. NaN when fewer than two pairs
/// or either side is constant.
pub fn correlation(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    if n < 2 {
        return f64::NAN;
    }
    let (a, b) = (&a[..n], &b[..n]);
    let (ma, mb) = (a.iter().sum::<f64>() / n as f64, b.iter().sum::<f64>() / n as f64);
    let cov: f64 = a.iter().zip(b).map(|(x, y)| (x - ma) * (y - mb)).sum();
    let va: f64 = a.iter().map(|x| (x - ma).powi(2)).sum();
    let vb: f64 = b.iter().map(|y| (y - mb).powi(2)).sum();
    if va > 0.0 && vb > 0.0 {
        cov / (va * vb).sqrt()
    } else {
        f64::NAN
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// b = 2a + 1 correlates at 1, b = −a at −1; a symmetric pairing whose
    /// covariance cancels at 0; one pair or a constant side is NaN.
    #[test]
    fn correlation_of_known_pairings() {
        let a = [1.0, 2.0, 3.0, 4.0];
        assert!((correlation(&a, &[3.0, 5.0, 7.0, 9.0]) - 1.0).abs() < 1e-12);
        assert!((correlation(&a, &[-1.0, -2.0, -3.0, -4.0]) + 1.0).abs() < 1e-12);
        assert!(correlation(&[-1.0, 0.0, 1.0], &[1.0, 0.0, 1.0]).abs() < 1e-12);
        assert!(correlation(&[1.0], &[2.0]).is_nan());
        assert!(correlation(&a, &[2.0; 4]).is_nan());
    }

    #[test]
    fn quantiles_by_nearest_rank() {
        let mut v = vec![5.0, 1.0, 3.0, 2.0, 4.0];
        assert_eq!(quantile(&mut v, 0.5), 3.0);
        assert_eq!(quantile(&mut v, 0.95), 5.0);
        assert_eq!(quantile(&mut v, 0.0), 1.0);
        assert!(quantile(&mut [], 0.5).is_nan());
    }

    /// A 4×4 image 10 % bright in its left half, against a flat reference:
    /// 2×2 blocks give √(½ · 0.1²) = 7.07 %; a masked-out left half gives 0;
    /// nothing in the mask gives NaN.
    #[test]
    fn block_rmse_of_a_half_bright_image() {
        let reference = RadianceImage {
            width: 4,
            height: 4,
            data: vec![1.0; 48],
        };
        let mut image = reference.clone();
        for y in 0..4 {
            for x in 0..2 {
                for c in 0..3 {
                    image.data[(y * 4 + x) * 3 + c] = 1.1;
                }
            }
        }
        let all = vec![true; 16];
        let e = block_relative_rmse(&image, &reference, &all, 2);
        assert!((e - 0.1 / 2f64.sqrt()).abs() < 1e-6, "{e}");
        let right: Vec<bool> = (0..16).map(|i| i % 4 >= 2).collect();
        assert!(block_relative_rmse(&image, &reference, &right, 2).abs() < 1e-12);
        assert!(block_relative_rmse(&image, &reference, &[false; 16], 2).is_nan());
    }
}

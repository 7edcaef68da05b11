//! Deghosting: a merge that drops samples inconsistent with a reference
//! exposure's radiance, so a moving object comes from one exposure only
//! instead of a blend of its positions.
//!
//! Per pixel and channel `c`, the reference sample is the reference exposure's
//! (the middle one, as in [`super::align`]) when it is unclipped, otherwise the
//! unclipped exposure nearest to it in the bracket's order. Sample `j` of the
//! pixel is excluded (in all channels) when, in any channel where both are
//! unclipped,
//!
//! ```text
//! |X_j − X_ref| > k · √(σ_j² + σ_ref² + (f · X_ref)²)
//! ```
//!
//! with `σ²` the variances of [`super::merge`]'s noise model (shot, read and
//! quantization noise) and `f` a relative floor for the response curve's own
//! error (a few % between exposures). The remaining samples are merged with
//! the same inverse-variance weights as [`super::merge::merge`]. Because
//! the reference is one exposure wherever it is well exposed, an object moving
//! through the bracket appears where the reference saw it, and the background
//! elsewhere. Where the reference exposure is clipped, the nearest unclipped
//! exposure decides, so a moving object there appears where that one saw it.

use rayon::prelude::*;

use super::HdrError;
use super::align::reference_index;
use super::bracket::Bracket;
use super::curve::ResponseCurve;
use super::lens::normalized_r2;
use super::merge::{MergeOptions, RadianceMap, build_tables, check_inputs, finish_pixel, gains};

/// Options of [`merge_deghosted`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DeghostOptions {
    /// Samples farther than `k_sigma` standard deviations from the reference are excluded.
    pub k_sigma: f64,
    /// Relative error floor `f` added to the noise (the curve's error between exposures).
    pub relative_floor: f64,
    /// The reference exposure (index in the bracket's order); default the middle one.
    pub reference: Option<usize>,
}

impl Default for DeghostOptions {
    /// k = 4 σ, 5 % floor, the middle exposure.
    fn default() -> Self {
        Self {
            k_sigma: 4.0,
            relative_floor: 0.05,
            reference: None,
        }
    }
}

/// What deghosting excluded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct DeghostStats {
    /// Samples (exposure × pixel) excluded.
    pub samples_excluded: u64,
    /// Pixels with at least one excluded sample.
    pub pixels_affected: u64,
    /// Pixels in the map.
    pub pixels: u64,
}

/// [`super::merge::merge`] with inconsistent samples excluded; see the module docs.
pub fn merge_deghosted(
    bracket: &Bracket,
    curve: &ResponseCurve,
    opts: &MergeOptions,
    deghost: &DeghostOptions,
) -> Result<(RadianceMap, DeghostStats), HdrError> {
    check_inputs(bracket.bits(), curve, opts)?;
    let n_img = bracket.len();
    let reference = deghost.reference.unwrap_or_else(|| reference_index(n_img));
    if reference >= n_img {
        return Err(HdrError::BadOption {
            name: "deghost reference",
            value: format!("{reference} (bracket of {n_img})"),
            expected: "an exposure index in the bracket",
        });
    }
    if !(deghost.k_sigma.is_finite() && deghost.k_sigma > 0.0) {
        return Err(HdrError::BadOption {
            name: "deghost k_sigma",
            value: deghost.k_sigma.to_string(),
            expected: "a finite number > 0",
        });
    }
    if !(deghost.relative_floor.is_finite() && deghost.relative_floor >= 0.0) {
        return Err(HdrError::BadOption {
            name: "deghost relative_floor",
            value: deghost.relative_floor.to_string(),
            expected: "a finite number ≥ 0",
        });
    }
    let t = build_tables(bracket.bits(), bracket.times_s(), curve, &opts.noise);
    let (w, h) = (bracket.width(), bracket.height());
    let codes = t.codes;
    let zmax = (codes - 1) as u16;
    let g = gains(&t, opts);
    let images: Vec<&[u16]> = bracket.images().iter().map(|im| im.data.as_slice()).collect();
    // Search order for the per-channel reference: the reference, then outwards.
    let order: Vec<usize> = std::iter::once(reference)
        .chain((1..n_img).flat_map(|d| {
            [reference.checked_add(d), reference.checked_sub(d)]
                .into_iter()
                .flatten()
                .filter(|&j| j < n_img)
        }))
        .collect();
    let k2 = deghost.k_sigma * deghost.k_sigma;
    let f2 = deghost.relative_floor * deghost.relative_floor;
    let mut map = RadianceMap {
        width: w,
        height: h,
        rgb: vec![0.0; w * h * 3],
        variance: vec![0.0; w * h * 3],
        mask: vec![0; w * h],
    };
    let stats = map
        .rgb
        .par_chunks_mut(w * 3)
        .zip(map.variance.par_chunks_mut(w * 3))
        .zip(map.mask.par_chunks_mut(w))
        .enumerate()
        .map(|(y, ((rgb_row, var_row), mask_row))| {
            let mut st = DeghostStats::default();
            let mut samples = vec![[[0.0f32; 2]; 3]; n_img];
            let mut keep = vec![true; n_img];
            for (x, mask_out) in mask_row.iter_mut().enumerate() {
                let p = (y * w + x) * 3;
                for (j, s) in samples.iter_mut().enumerate() {
                    for (c, sc) in s.iter_mut().enumerate() {
                        *sc = t.lut[(j * 3 + c) * codes + usize::from(images[j][p + c])];
                    }
                }
                keep.fill(true);
                for c in 0..3 {
                    let Some(&r) = order.iter().find(|&&j| samples[j][c][0] > 0.0) else {
                        continue;
                    };
                    let [wr, wxr] = samples[r][c];
                    let xr = f64::from(wxr) / f64::from(wr);
                    let var_r = t.var_scale[c] / f64::from(wr);
                    for (j, s) in samples.iter().enumerate() {
                        let [wj, wxj] = s[c];
                        if j == r || wj <= 0.0 || !keep[j] {
                            continue;
                        }
                        let xj = f64::from(wxj) / f64::from(wj);
                        let var = t.var_scale[c] / f64::from(wj) + var_r + f2 * xr * xr;
                        if (xj - xr).powi(2) > k2 * var {
                            keep[j] = false;
                        }
                    }
                }
                let (mut sw, mut swx) = ([0.0f32; 3], [0.0f32; 3]);
                let mut excluded = 0u64;
                for (s, &k) in samples.iter().zip(&keep) {
                    if !k {
                        excluded += 1;
                        continue;
                    }
                    for c in 0..3 {
                        sw[c] += s[c][0];
                        swx[c] += s[c][1];
                    }
                }
                st.samples_excluded += excluded;
                st.pixels_affected += u64::from(excluded > 0);
                let falloff = opts
                    .falloff
                    .map_or(1.0, |f| f.at_r2(normalized_r2(x, y, w, h)).max(1e-6) as f32);
                let k = x * 3;
                *mask_out = finish_pixel(
                    &t,
                    (sw, swx),
                    std::array::from_fn(|c| images[0][p + c] >= zmax),
                    g,
                    falloff,
                    &mut rgb_row[k..k + 3],
                    &mut var_row[k..k + 3],
                );
            }
            st
        })
        .reduce(DeghostStats::default, |a, b| DeghostStats {
            samples_excluded: a.samples_excluded + b.samples_excluded,
            pixels_affected: a.pixels_affected + b.pixels_affected,
            pixels: 0,
        });
    Ok((
        map,
        DeghostStats {
            pixels: (w * h) as u64,
            ..stats
        },
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::image::RadianceImage;
    use crate::camera::sensor::CameraModel;
    use crate::camera::test_chart::hdr_chart;
    use crate::hdr::align::tests::TIMES;
    use crate::hdr::merge::merge;
    use crate::hdr::merge::tests::true_curve;

    const SIDE: usize = 12;
    /// The object's radiance: 2–6× the background under it, unclipped up to
    /// the 4 s exposure (so its ghosts carry weight in a plain merge).
    const OBJECT: f32 = 0.12;

    /// Top-left corners of the object in exposures 0..5 (the reference is 2).
    fn corners() -> [(usize, usize); 5] {
        [(52, 4), (56, 22), (50, 40), (58, 58), (54, 76)]
    }

    fn with_object(scene: &RadianceImage, (x0, y0): (usize, usize)) -> RadianceImage {
        let mut s = scene.clone();
        for y in y0..y0 + SIDE {
            for x in x0..x0 + SIDE {
                let p = (y * s.width + x) * 3;
                s.data[p..p + 3].fill(OBJECT);
            }
        }
        s
    }

    /// Median relative error against `truth` over the object's squares (`which`).
    fn error_in(map: &RadianceMap, truth: &RadianceImage, squares: &[(usize, usize)]) -> f64 {
        let mut e: Vec<f64> = squares
            .iter()
            .flat_map(|&(x0, y0)| (y0..y0 + SIDE).flat_map(move |y| (x0..x0 + SIDE).map(move |x| (x, y))))
            .flat_map(|(x, y)| (0..3).map(move |c| (y * truth.width + x) * 3 + c))
            .map(|i| (f64::from(map.rgb[i]) / f64::from(truth.data[i]) - 1.0).abs())
            .collect();
        let mid = e.len() / 2;
        *e.select_nth_unstable_by(mid, f64::total_cmp).1
    }

    #[test]
    fn moving_object_appears_once_and_the_background_under_its_ghosts_is_restored() {
        let cam = CameraModel::typical(8);
        let (w, h) = (128, 96);
        let background = hdr_chart(w, h);
        let imgs = TIMES
            .iter()
            .zip(corners())
            .enumerate()
            .map(|(j, (&t, corner))| cam.photograph(&with_object(&background, corner), t, 60 + j as u64))
            .collect();
        let b = Bracket::new(imgs, TIMES.to_vec()).unwrap();
        let curve = true_curve(&cam);
        let opts = MergeOptions::default();
        let plain = merge(&b, &curve, &opts).unwrap();
        let (clean, stats) = merge_deghosted(&b, &curve, &opts, &DeghostOptions::default()).unwrap();
        // The true curve's gauge: exposure/radiance is 1 (gain 1), so maps compare to the scene directly.
        let ghosts: Vec<_> = corners()
            .iter()
            .enumerate()
            .filter(|&(j, _)| j != 2)
            .map(|(_, &c)| c)
            .collect();
        let truth_with_object = with_object(&background, corners()[2]);
        // Per ghost square, the median error; the worst square is the figure.
        let worst = |m: &RadianceMap| {
            ghosts
                .iter()
                .map(|&g| error_in(m, &background, &[g]))
                .fold(0.0, f64::max)
        };
        let ghost_before = worst(&plain);
        let ghost_after = worst(&clean);
        let object_before = error_in(&plain, &truth_with_object, &[corners()[2]]);
        let object_after = error_in(&clean, &truth_with_object, &[corners()[2]]);
        // Away from every square, deghosting changes nothing beyond noise.
        let (mut far, mut far_changed) = (0usize, 0usize);
        for y in 0..h {
            for x in 0..w {
                let near = corners()
                    .iter()
                    .any(|&(x0, y0)| x + 2 >= x0 && x < x0 + SIDE + 2 && y + 2 >= y0 && y < y0 + SIDE + 2);
                if near {
                    continue;
                }
                far += 1;
                let p = (y * w + x) * 3;
                far_changed += usize::from((clean.rgb[p + 1] / plain.rgb[p + 1] - 1.0).abs() > 0.02);
            }
        }
        eprintln!(
            "ghost squares, worst median relative error against the background: {ghost_before:.4} plain, \
             {ghost_after:.4} deghosted; object square against the object: {object_before:.4} plain, \
             {object_after:.4} deghosted; {} samples excluded at {} of {} pixels; \
             {far_changed} of {far} pixels away from the object changed > 2 %",
            stats.samples_excluded, stats.pixels_affected, stats.pixels
        );
        assert!(ghost_before > 0.1, "the plain merge should show ghosts: {ghost_before}");
        assert!(
            object_before > 0.2,
            "the plain merge should blend the object away: {object_before}"
        );
        assert!(ghost_after < 0.03, "background under the ghosts: {ghost_after}");
        assert!(
            object_after < 0.03,
            "the object where the reference saw it: {object_after}"
        );
        assert!(far_changed * 100 < far, "{far_changed} of {far} static pixels changed");
        assert!(clean.rgb.iter().all(|v| v.is_finite()));
        assert!(stats.pixels_affected >= (4 * SIDE * SIDE) as u64);
    }

    #[test]
    fn static_bracket_is_left_alone_and_bad_options_are_refused() {
        let cam = CameraModel::typical(8);
        let scene = hdr_chart(64, 48);
        let imgs = TIMES
            .iter()
            .enumerate()
            .map(|(j, &t)| cam.photograph(&scene, t, 5 + j as u64))
            .collect();
        let b = Bracket::new(imgs, TIMES.to_vec()).unwrap();
        let curve = true_curve(&cam);
        let plain = merge(&b, &curve, &MergeOptions::default()).unwrap();
        let (clean, stats) = merge_deghosted(&b, &curve, &MergeOptions::default(), &DeghostOptions::default()).unwrap();
        let frac = stats.samples_excluded as f64 / (stats.pixels as f64 * 5.0);
        eprintln!(
            "static bracket: {} samples excluded ({:.4} of all)",
            stats.samples_excluded, frac
        );
        assert!(frac < 0.01, "fraction of samples excluded on a static scene {frac}");
        let (d, _) = crate::hdr::align::tests::median_rel_diff(&clean, &plain);
        assert!(d < 1e-3, "median change {d}");
        let e = merge_deghosted(
            &b,
            &curve,
            &MergeOptions::default(),
            &DeghostOptions {
                reference: Some(5),
                ..Default::default()
            },
        )
        .unwrap_err();
        assert!(e.to_string().contains("5 (bracket of 5)"), "{e}");
    }
}

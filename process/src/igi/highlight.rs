//! Highlight detection per camera, surface and light (Fig. 4.4): a light's
//! highlight is in a view when some pixel of the surface sees the light's
//! mirror direction (half vector within [`MIRROR_CONE_RAD`] of the normal),
//! and it is seen when those pixels are brighter than a diffuse-only fit of
//! the surface predicts, by more than [`MIN_EXCESS`]. The background fit
//! uses the pixels farther than [`BACKGROUND_DELTA_RAD`] from every
//! light's mirror direction (all pixels when there are none).

/// Half-angle of the cone about the normal within which the half vector
/// counts as at the mirror direction: 2°.
pub const MIRROR_CONE_RAD: f64 = 0.034_906_585_039_886_59;

/// Pixels whose half vector is farther than this from the normal for every
/// light form the diffuse background: 30°.
pub const BACKGROUND_DELTA_RAD: f64 = 0.523_598_775_598_298_8;

/// The relative brightness over the diffuse background that makes a
/// highlight "seen": 10 %.
pub const MIN_EXCESS: f64 = 0.1;

/// One (view, light) pair's highlight on a surface.
#[derive(Debug, Clone, PartialEq)]
pub struct HighlightReport {
    /// Index of the view.
    pub view: usize,
    /// Index of the light.
    pub light: usize,
    /// Pixels of the surface within the mirror cone.
    pub pixels: usize,
    /// Smallest half-vector angle seen, degrees.
    pub min_delta_deg: f64,
    /// Mean of measured over diffuse-predicted radiance in the cone, minus 1.
    pub excess: f64,
    /// Whether the excess exceeds [`MIN_EXCESS`].
    pub seen: bool,
}

/// A pixel as the detector sees it: view, measured radiance (channel
/// mean), diffuse coefficient E/π (channel mean), and per light the
/// half-vector angle.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct DetectorSample {
    pub view: usize,
    pub radiance: f64,
    pub diffuse: f64,
    pub deltas: Vec<(usize, f64)>,
}

/// The reports of every (view, light) pair whose mirror cone some pixel
/// falls in.
pub(crate) fn detect(samples: &[DetectorSample]) -> Vec<HighlightReport> {
    let far = |s: &DetectorSample| s.deltas.iter().all(|(_, d)| *d > BACKGROUND_DELTA_RAD);
    let fit = |take: &dyn Fn(&DetectorSample) -> bool| {
        let (mut num, mut den) = (0.0, 0.0);
        for s in samples.iter().filter(|s| take(s) && s.radiance > 0.0) {
            let w = 1.0 / (s.radiance * s.radiance);
            num += w * s.radiance * s.diffuse;
            den += w * s.diffuse * s.diffuse;
        }
        (den > 0.0).then(|| num / den)
    };
    let rho = fit(&far).or_else(|| fit(&|_| true)).unwrap_or(0.0);
    let mut reports: Vec<HighlightReport> = Vec::new();
    for s in samples {
        for &(light, delta) in &s.deltas {
            if delta > MIRROR_CONE_RAD {
                continue;
            }
            let r = match reports.iter_mut().find(|r| r.view == s.view && r.light == light) {
                Some(r) => r,
                None => {
                    reports.push(HighlightReport {
                        view: s.view,
                        light,
                        pixels: 0,
                        min_delta_deg: f64::INFINITY,
                        excess: 0.0,
                        seen: false,
                    });
                    reports.last_mut().unwrap_or_else(|| unreachable!("just pushed"))
                }
            };
            r.pixels += 1;
            r.min_delta_deg = r.min_delta_deg.min(delta.to_degrees());
            let predicted = rho * s.diffuse;
            // A zero prediction with light arriving is an unbounded excess; cap it.
            r.excess += if predicted > 0.0 {
                s.radiance / predicted - 1.0
            } else {
                1e6
            };
        }
    }
    for r in &mut reports {
        r.excess /= r.pixels as f64;
        r.seen = r.excess > MIN_EXCESS;
    }
    reports.sort_by_key(|r| (r.view, r.light));
    reports
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_bright_mirror_cone_is_seen_and_a_flat_one_is_not() {
        let mut samples = Vec::new();
        for i in 0..100 {
            let delta = 0.01 * i as f64;
            // Diffuse 0.3 everywhere; light 0 adds a highlight in view 0 only.
            let spec = if delta < 0.05 { 0.2 } else { 0.0 };
            samples.push(DetectorSample {
                view: 0,
                radiance: 0.3 * 1.0 + spec,
                diffuse: 1.0,
                deltas: vec![(0, delta + 0.6 * f64::from(u8::from(delta > 0.9)))],
            });
            samples.push(DetectorSample {
                view: 1,
                radiance: 0.3,
                diffuse: 1.0,
                deltas: vec![(0, delta)],
            });
        }
        let r = detect(&samples);
        assert_eq!(r.len(), 2);
        assert!(r[0].seen && (r[0].excess - 0.2 / 0.3).abs() < 1e-9, "{r:?}");
        assert!(!r[1].seen && r[1].excess.abs() < 1e-9, "{r:?}");
        assert_eq!(r[1].pixels, 4);
    }
}

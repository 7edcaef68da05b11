//! Sky conditions per scan (issue 29): a clear-sky index of the sky and of
//! the sun, a cloud-cover estimate by region, a flag for clouds in the
//! sun's neighbourhood, and a condition word. Computed per day from the
//! per-scan products alone, like the extinction.
//!
//! **The clear reference.** The day's clear scans (sun triplet agreed, sky
//! fitted by eq. 5.9 within [`CLEAR_SCAN_RMS`] in every channel, and — in a
//! second pass — no cloud found by regions) give the clear sky at any sun
//! position. The clear scans' fits are first freed of the low sun's
//! reddening by the day's Langley β (§5.5.1, `sky::redden` beyond air mass
//! 2, the model the relighting stage predicts skies with); then the shape
//! (a … e, h) is the clear scan's nearest in sun zenith angle, and the
//! zenith radiance is interpolated in ln L between the clear scans around
//! the sun's zenith angle (outside them, scaled as `cos^k Zs`: k fitted
//! over the clear scans when they span 20° of zenith angle, else 0.5);
//! last, the sky is reddened for the scan's air mass. This is the same
//! formula the simulator's clear sky follows, so on the simulator it is
//! exact up to the fits' noise; on a real sky it is a model. Each region's measured mean over its own fit's mean on the clear scans
//! (the median per channel) calibrates what the model cannot know: the
//! horizon's occluders, the pixels' uneven cover of a region.
//!
//! **The indices.** Per region and channel, the measured mean over the
//! reference's mean over the same region (an even grid of directions,
//! the sun's neighbourhood left out). A region is cloudy when
//! `|ln(measured/expected)|` exceeds [`CLOUDY_DEPARTURE`] in any channel
//! (clouds are grey: brighter than the clear sky in red, often darker in
//! blue). `cloud_cover` is the solid-angle-weighted share of cloudy regions
//! among those measured; `clear_sky_index` the solid-angle-weighted mean
//! of the regions' broadband ratio (channels summed). The sun's direct
//! index is the measured normal irradiance over the day's Langley fit at
//! the scan's air mass, channels summed. The condition word follows the
//! cover in oktas ([`Condition::of_cover`]).

use serde::{Deserialize, Serialize};

use super::day::DayExtinction;
use super::regions::{REGION_COUNT, region_grid, region_solid_angle, sun_neighbourhood_grid};
use super::scan::ScanProducts;
use crate::pipeline::median;
use crate::sky::{REDDENING_ONSET_AIR_MASS, SkyAngles, SkyModel, angle_between, direction, redden};
use crate::sun::{air_mass, line_fit};

/// Largest `|ln(measured/expected)|` of a clear region in any channel
/// (0.2: on the simulator's broken-cloud day at 64 × 48, regions under
/// less than 2% cloud depart by 0.016 in the median and 0.12 at the 90th
/// percentile; regions more than half covered by 0.78 in the median and
/// 0.45 at the 10th percentile; `tests/sky_conditions.rs`).
pub const CLOUDY_DEPARTURE: f64 = 0.2;
/// Largest RMS relative residual of a channel's sky fit on a scan taken
/// as clear for the reference (4%: clear simulated scans fit within 1–2%).
pub const CLEAR_SCAN_RMS: f64 = 0.04;
/// Largest cloud cover of a scan kept in the clear reference's second pass.
pub const CLEAR_SCAN_COVER: f64 = 0.0625;
/// The smallest share of the dome's solid angle (below 80°, the sun's
/// neighbourhood left out) that must be measured for a cloud cover.
pub const MIN_MEASURED_SHARE: f64 = 0.5;
/// Grid directions per side averaged over a region for the reference.
const GRID: usize = 6;
/// The zenith-radiance exponent of `cos Zs` used when the clear scans span
/// less than [`MIN_EXPONENT_SPAN_DEG`] of sun zenith angle (the CIE clear
/// sky's zenith radiance grows about as √cos Zs).
pub const DEFAULT_ZENITH_EXPONENT: f64 = 0.5;
/// The span of sun zenith angles the clear scans need for their own exponent, degrees.
pub const MIN_EXPONENT_SPAN_DEG: f64 = 20.0;

/// The air mass beyond the onset of the low sun's reddening (§5.5.1,
/// [`REDDENING_ONSET_AIR_MASS`]) at sun zenith angle `zenith`.
fn reddening_air_mass(zenith: f64) -> f64 {
    (air_mass(zenith.min(std::f64::consts::FRAC_PI_2)) - REDDENING_ONSET_AIR_MASS).max(0.0)
}

/// The sky's condition, from the cloud cover in oktas.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Condition {
    /// Up to 1 okta (cover below 1.5/8).
    Clear,
    /// 2 to 4 oktas (below 4.5/8).
    PartlyCloudy,
    /// 5 to 7 oktas (below 7.5/8).
    Cloudy,
    /// 8 oktas.
    Overcast,
}

impl Condition {
    /// The condition of a cloud cover (0–1), rounded to oktas.
    pub fn of_cover(cover: f64) -> Condition {
        let oktas = cover * 8.0;
        if oktas < 1.5 {
            Condition::Clear
        } else if oktas < 4.5 {
            Condition::PartlyCloudy
        } else if oktas < 7.5 {
            Condition::Cloudy
        } else {
            Condition::Overcast
        }
    }

    /// The word used in the series and the alert hook.
    pub fn as_str(self) -> &'static str {
        match self {
            Condition::Clear => "clear",
            Condition::PartlyCloudy => "partly-cloudy",
            Condition::Cloudy => "cloudy",
            Condition::Overcast => "overcast",
        }
    }
}

impl std::fmt::Display for Condition {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// One scan's sky condition. A figure that cannot be computed is `None`
/// and [`SkyCondition::note`] says why.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SkyCondition {
    /// Solid-angle-weighted mean of measured/clear over the regions (channels summed).
    pub clear_sky_index: Option<f64>,
    /// Measured direct normal irradiance over the clear (Langley) one, channels summed.
    pub direct_clear_sky_index: Option<f64>,
    /// Solid-angle-weighted share of cloudy regions, 0–1.
    pub cloud_cover: Option<f64>,
    /// The sun's neighbourhood departs from clear.
    pub clouds_near_sun_region: Option<bool>,
    /// The condition word.
    pub condition: Option<Condition>,
    /// Per region ([`super::regions::REGION_COUNT`]): cloudy, clear, or `None` (not measured).
    pub cloudy_regions: Vec<Option<bool>>,
    /// Largest `|ln(measured/expected)|` over the channels per region (`None`: not measured).
    pub departures: Vec<Option<f64>>,
    /// Why a figure is missing, `; `-separated (empty when all are there).
    pub note: String,
}

/// A clear scan of the day: its sun zenith and fitted sky.
#[derive(Debug, Clone)]
struct ClearScan {
    zenith: f64,
    /// The fitted sky.
    fitted: [SkyModel; 3],
    /// The fitted sky with its reddening undone (the day's β).
    models: [SkyModel; 3],
    /// The zenith radiance of `models`.
    zenith_radiance: [f64; 3],
}

/// The day's clear sky at any sun position (module doc).
#[derive(Debug, Clone)]
pub struct ClearReference {
    scans: Vec<ClearScan>,
    beta: Option<[f64; 3]>,
    exponent: [f64; 3],
    region_gain: Vec<[f64; 3]>,
    near_sun_gain: [f64; 3],
}

fn sun_direction(s: &ScanProducts) -> [f64; 3] {
    direction(s.sun_zenith_deg.to_radians(), s.sun_azimuth_deg.to_radians())
}

/// The mean of `models` over directions `dirs` with the sun at `sun`.
fn mean_radiance(models: &[SkyModel; 3], dirs: &[[f64; 3]], sun: [f64; 3]) -> Option<[f64; 3]> {
    if dirs.is_empty() {
        return None;
    }
    let mut sum = [0.0; 3];
    for &d in dirs {
        let (xi, g) = (d[2].clamp(-1.0, 1.0).acos(), angle_between(d, sun));
        let at = SkyAngles::new(xi, g);
        (0..3).for_each(|c| sum[c] += models[c].radiance_at(&at));
    }
    Some(sum.map(|v| v / dirs.len() as f64))
}

/// The median of the finite values of `v`.
fn finite_median(mut v: Vec<f64>) -> Option<f64> {
    v.retain(|x| x.is_finite());
    median(&mut v)
}

/// Whether a scan may serve as clear for the reference (first pass).
fn clear_candidate(s: &ScanProducts) -> bool {
    s.sun.is_some()
        && !s.quality.clouds_near_sun
        && s.regions.measured.len() == REGION_COUNT
        && s.sky
            .as_ref()
            .is_some_and(|k| k.len() == 3 && k.iter().all(|c| c.rms_relative <= CLEAR_SCAN_RMS))
}

impl ClearReference {
    /// The reference from the clear scans among `scans`, with the day's
    /// extinction β per channel (`None`: no fit; no reddening is modelled);
    /// `Err` says why there is none.
    pub fn new(scans: &[&ScanProducts], beta: Option<[f64; 3]>) -> Result<ClearReference, String> {
        let mut clear: Vec<(&ScanProducts, ClearScan)> = scans
            .iter()
            .filter(|s| clear_candidate(s))
            .filter_map(|s| {
                let fitted = s.models()?;
                let zenith = s.sun_zenith_deg.to_radians();
                let models = match beta {
                    Some(b) => redden(fitted, b, -reddening_air_mass(zenith)),
                    None => fitted,
                };
                let zenith_radiance = [0, 1, 2].map(|c| models[c].radiance(0.0, zenith));
                zenith_radiance.iter().all(|z| z.is_finite() && *z > 0.0).then_some((
                    *s,
                    ClearScan {
                        zenith,
                        fitted,
                        models,
                        zenith_radiance,
                    },
                ))
            })
            .collect();
        if clear.is_empty() {
            return Err(
                "no clear scan on this day (sun triplet agreed and sky fit within 4%) to scale the clear sky".into(),
            );
        }
        clear.sort_by(|a, b| a.1.zenith.total_cmp(&b.1.zenith));
        // ln Z = α + k ln cos Zs per channel, by least squares.
        let exponent = [0, 1, 2].map(|c| {
            let pts: Vec<(f64, f64)> = clear
                .iter()
                .map(|(_, k)| (k.zenith.cos().max(0.02).ln(), k.zenith_radiance[c].ln()))
                .collect();
            let span = clear.last().map_or(0.0, |l| l.1.zenith) - clear.first().map_or(0.0, |f| f.1.zenith);
            if pts.len() >= 2 && span >= MIN_EXPONENT_SPAN_DEG.to_radians() {
                line_fit(&pts).0
            } else {
                DEFAULT_ZENITH_EXPONENT
            }
        });
        // Each region's calibration: measured over the scan's own fit, median over the clear scans.
        let mut per_region: Vec<[Vec<f64>; 3]> = vec![[Vec::new(), Vec::new(), Vec::new()]; REGION_COUNT];
        let mut near: [Vec<f64>; 3] = [Vec::new(), Vec::new(), Vec::new()];
        for (s, k) in &clear {
            let sun = sun_direction(s);
            for (r, m) in s.regions.measured.iter().enumerate() {
                let (Some(m), Some(f)) = (m, mean_radiance(&k.fitted, &region_grid(r, sun, GRID), sun)) else {
                    continue;
                };
                (0..3).for_each(|c| per_region[r][c].push(m[c] / f[c]));
            }
            if let (Some(m), Some(f)) = (
                s.regions.near_sun,
                mean_radiance(&k.fitted, &sun_neighbourhood_grid(sun, GRID), sun),
            ) {
                (0..3).for_each(|c| near[c].push(m[c] / f[c]));
            }
        }
        let gain = |v: &[Vec<f64>; 3]| [0, 1, 2].map(|c| finite_median(v[c].clone()).unwrap_or(1.0));
        Ok(ClearReference {
            scans: clear.into_iter().map(|(_, k)| k).collect(),
            beta,
            exponent,
            region_gain: per_region.iter().map(gain).collect(),
            near_sun_gain: gain(&near),
        })
    }

    /// The clear sky per channel with the sun at zenith angle `zenith` (radians).
    pub fn models_at(&self, zenith: f64) -> [SkyModel; 3] {
        let unreddened = self.unreddened_at(zenith);
        match self.beta {
            Some(b) => redden(unreddened, b, reddening_air_mass(zenith)),
            None => unreddened,
        }
    }

    /// [`ClearReference::models_at`] before the low sun's reddening.
    fn unreddened_at(&self, zenith: f64) -> [SkyModel; 3] {
        let nearest = self
            .scans
            .iter()
            .min_by(|a, b| (a.zenith - zenith).abs().total_cmp(&(b.zenith - zenith).abs()))
            .unwrap_or_else(|| unreachable!("a reference has a clear scan"));
        let below = self.scans.iter().rev().find(|k| k.zenith <= zenith);
        let above = self.scans.iter().find(|k| k.zenith >= zenith);
        [0, 1, 2].map(|c| {
            let z = match (below, above) {
                (Some(lo), Some(hi)) if hi.zenith > lo.zenith => {
                    let t = (zenith - lo.zenith) / (hi.zenith - lo.zenith);
                    ((1.0 - t) * lo.zenith_radiance[c].ln() + t * hi.zenith_radiance[c].ln()).exp()
                }
                _ => {
                    nearest.zenith_radiance[c]
                        * (zenith.cos().max(0.02) / nearest.zenith.cos().max(0.02)).powf(self.exponent[c])
                }
            };
            let shape = nearest.models[c];
            let unit = SkyModel { lz: 1.0, ..shape };
            SkyModel {
                lz: z / unit.radiance(0.0, zenith),
                ..shape
            }
        })
    }

    /// The condition of `scan` against this reference, with the day's extinction `ext`.
    pub fn condition(&self, scan: &ScanProducts, ext: &DayExtinction) -> SkyCondition {
        let mut notes: Vec<String> = Vec::new();
        let sun = sun_direction(scan);
        let models = self.models_at(scan.sun_zenith_deg.to_radians());
        let mut out = SkyCondition {
            cloudy_regions: vec![None; REGION_COUNT],
            departures: vec![None; REGION_COUNT],
            ..SkyCondition::default()
        };
        let departure = |m: [f64; 3], e: [f64; 3]| -> Option<f64> {
            let d = (0..3).map(|c| (m[c] / e[c]).ln().abs()).fold(0.0, f64::max);
            d.is_finite().then_some(d)
        };
        if scan.regions.measured.len() == REGION_COUNT {
            let (mut w_all, mut w_seen, mut w_cloudy, mut index) = (0.0, 0.0, 0.0, 0.0);
            for r in 0..REGION_COUNT {
                let grid = region_grid(r, sun, GRID);
                let w = region_solid_angle(r) * grid.len() as f64 / (GRID * GRID) as f64;
                w_all += w;
                let (Some(m), Some(f)) = (scan.regions.measured[r], mean_radiance(&models, &grid, sun)) else {
                    continue;
                };
                let e = [0, 1, 2].map(|c| f[c] * self.region_gain[r][c]);
                let Some(dep) = departure(m, e) else { continue };
                let cloudy = dep > CLOUDY_DEPARTURE;
                out.cloudy_regions[r] = Some(cloudy);
                out.departures[r] = Some(dep);
                w_seen += w;
                w_cloudy += if cloudy { w } else { 0.0 };
                index += w * m.iter().sum::<f64>() / e.iter().sum::<f64>();
            }
            if w_all > 0.0 && w_seen >= MIN_MEASURED_SHARE * w_all {
                out.cloud_cover = Some(w_cloudy / w_seen);
                out.clear_sky_index = Some(index / w_seen);
                out.condition = out.cloud_cover.map(Condition::of_cover);
            } else {
                notes.push(format!(
                    "too few sky pixels: {:.0}% of the dome measured (at least {:.0}% needed)",
                    100.0 * w_seen / w_all.max(f64::MIN_POSITIVE),
                    100.0 * MIN_MEASURED_SHARE
                ));
            }
        } else {
            notes.push("no sky regions in this scan's products (processed before regions were kept)".into());
        }
        let ring = mean_radiance(&models, &sun_neighbourhood_grid(sun, GRID), sun);
        match (scan.regions.near_sun, ring) {
            (Some(m), Some(f)) => {
                let e = [0, 1, 2].map(|c| f[c] * self.near_sun_gain[c]);
                out.clouds_near_sun_region = departure(m, e).map(|d| d > CLOUDY_DEPARTURE);
            }
            _ => notes.push("too few sky pixels in the sun's neighbourhood".into()),
        }
        match &scan.sun {
            None => notes.push("no sun measured (no direct index)".into()),
            Some(sunrec) => {
                let mut measured = 0.0;
                let mut clear = 0.0;
                let mut why = None;
                for c in 0..3 {
                    match &ext.fit[c] {
                        Ok(e) => {
                            measured += sunrec.irradiance_w_m2[c];
                            clear += e.e0 * (-e.beta * sunrec.air_mass).exp();
                        }
                        Err(w) => why = Some(w.clone()),
                    }
                }
                match why {
                    Some(w) => notes.push(format!("no extinction fit for the day ({w}): no direct index")),
                    None if clear > 0.0 && (measured / clear).is_finite() => {
                        out.direct_clear_sky_index = Some(measured / clear);
                    }
                    None => notes.push("the clear direct irradiance is zero: no direct index".into()),
                }
            }
        }
        out.note = notes.join("; ");
        out
    }
}

/// The conditions of one day's `scans` (in the order given), with the day's extinction `ext`.
pub fn day_conditions(scans: &[&ScanProducts], ext: &DayExtinction) -> Vec<SkyCondition> {
    let none = |why: &str| SkyCondition {
        cloudy_regions: vec![None; REGION_COUNT],
        departures: vec![None; REGION_COUNT],
        note: why.to_owned(),
        ..SkyCondition::default()
    };
    let beta = match &ext.fit {
        [Ok(r), Ok(g), Ok(b)] => Some([r.beta, g.beta, b.beta]),
        _ => None,
    };
    let first = match ClearReference::new(scans, beta) {
        Ok(r) => r,
        Err(why) => return scans.iter().map(|_| none(&why)).collect(),
    };
    let pass: Vec<SkyCondition> = scans.iter().map(|s| first.condition(s, ext)).collect();
    // Second pass: the reference from the scans the first found clear.
    let kept: Vec<&ScanProducts> = scans
        .iter()
        .zip(&pass)
        .filter(|(_, c)| c.cloud_cover.is_some_and(|v| v <= CLEAR_SCAN_COVER) && c.clouds_near_sun_region != Some(true))
        .map(|(s, _)| *s)
        .collect();
    match ClearReference::new(&kept, beta) {
        Ok(second) => scans.iter().map(|s| second.condition(s, ext)).collect(),
        Err(_) => pass,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cover_maps_to_oktas() {
        assert_eq!(Condition::of_cover(0.0), Condition::Clear);
        assert_eq!(Condition::of_cover(1.4 / 8.0), Condition::Clear);
        assert_eq!(Condition::of_cover(1.6 / 8.0), Condition::PartlyCloudy);
        assert_eq!(Condition::of_cover(4.6 / 8.0), Condition::Cloudy);
        assert_eq!(Condition::of_cover(7.6 / 8.0), Condition::Overcast);
        assert_eq!(Condition::PartlyCloudy.as_str(), "partly-cloudy");
    }

    #[test]
    fn the_median_ignores_non_finite_values() {
        assert_eq!(finite_median(vec![3.0, f64::NAN, 1.0, 2.0]), Some(2.0));
        assert_eq!(finite_median(vec![4.0, 1.0]), Some(2.5));
        assert_eq!(finite_median(vec![f64::NAN]), None);
    }
}

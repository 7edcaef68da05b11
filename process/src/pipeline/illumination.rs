//! Per occurrence: the sun's irradiance from its filtered frames (§5.3.1),
//! the sky model per channel from the sky scan (§5.3.2, eq. 5.9) and the
//! environment map from the environment tiles (§5.3.3).

use chrono::{DateTime, Utc};

use super::{MergedGroup, PipelineError, Purpose, StationOptics};
use crate::environment::EnvironmentMap;
use crate::hdr::merge::MASK_SATURATED;
use crate::sky::{RobustSkyFit, SkyFrame, fit_sky_robust, sky_samples};
use crate::sun::{SunFrame, SunPosition, measure_sun, sun_position, sun_solid_angle_sr};

/// Largest spread of a sun triplet, relative to its mean, that still counts
/// as agreement (AERONET's triplet criterion is 3%; the capture controller
/// retakes beyond the same figure).
pub const TRIPLET_AGREEMENT: f64 = 0.03;

/// Sky samples taken per sky frame, about (every k-th pixel in each
/// direction): more adds fitting time without changing the fit.
pub const SKY_SAMPLES_PER_FRAME: usize = 800;

/// Margin around the sun's disc left out of sky samples (3°).
pub const SUN_MARGIN_RAD: f64 = 3.0 * std::f64::consts::PI / 180.0;

/// The sun's irradiance at one time.
#[derive(Debug, Clone, PartialEq)]
pub struct SunMeasurement {
    /// Mean time of the frames measured.
    pub time: DateTime<Utc>,
    /// Irradiance normal to the sun, per channel (mean of the frames), W·m⁻².
    pub irradiance: [f64; 3],
    /// (max − min)/mean over the frames, per channel.
    pub spread: [f64; 3],
    /// Frames measured.
    pub frames: usize,
    /// Whether the frames agree within [`TRIPLET_AGREEMENT`].
    pub agrees: bool,
    /// Frames that could not be measured, and why.
    pub refused: Vec<String>,
}

/// Everything measured of the light at one occurrence.
#[derive(Debug, Clone)]
pub struct OccurrenceLight {
    /// The occurrence.
    pub occurrence: String,
    /// Whether it is held out of fitting.
    pub held_out: bool,
    /// Its reference time (the mean time of its sky scan, else of its first group).
    pub time: DateTime<Utc>,
    /// The sun at that time.
    pub sun: SunPosition,
    /// The sun's irradiance, if a sun shot was measured.
    pub sun_irradiance: Option<SunMeasurement>,
    /// The sky fit per channel, if a sky scan was fitted.
    pub sky: Option<Vec<RobustSkyFit>>,
    /// The environment's lat-long region map, if tiles were taken.
    pub environment: Option<EnvironmentMap>,
    /// What could not be done, in words.
    pub notes: Vec<String>,
}

fn sky_frame<'a>(g: &'a MergedGroup, valid: &'a [bool], optics: &StationOptics) -> SkyFrame<'a> {
    SkyFrame {
        width: g.map.width,
        height: g.map.height,
        rgb: &g.map.rgb,
        valid: Some(valid),
        camera: g.pinhole,
        mount: g.mount(&optics.mount),
        pose: g.head,
    }
}

/// The light of every occurrence in `merged` (in first-seen order), with
/// an environment map of `env_rows` × `env_cols` regions.
pub fn illumination(
    merged: &[MergedGroup],
    optics: &StationOptics,
    env_rows: usize,
    env_cols: usize,
) -> Result<Vec<OccurrenceLight>, PipelineError> {
    let mut names: Vec<&str> = Vec::new();
    for g in merged {
        if !names.contains(&g.occurrence.as_str()) {
            names.push(&g.occurrence);
        }
    }
    let mut out = Vec::new();
    for name in names {
        let groups: Vec<&MergedGroup> = merged.iter().filter(|g| g.occurrence == name).collect();
        let of = |p: &Purpose| groups.iter().copied().filter(|g| g.purpose == *p).collect::<Vec<_>>();
        let (sun_groups, sky_groups, env_groups) = (of(&Purpose::Sun), of(&Purpose::Sky), of(&Purpose::Environment));
        let mean_time = |gs: &[&MergedGroup]| super::mean_time(&gs.iter().map(|g| g.time).collect::<Vec<_>>());
        let time = if sky_groups.is_empty() {
            groups[0].time
        } else {
            mean_time(&sky_groups)
        };
        let sun_at = |t: DateTime<Utc>| {
            sun_position(t, &optics.observer, optics.delta_t_s).map_err(|e| PipelineError::Sun {
                time: t,
                message: e.to_string(),
            })
        };
        let sun = sun_at(time)?;
        let mut notes = Vec::new();

        // The sun (§5.3.1): each filtered frame measured alone, per channel.
        let sun_irradiance = if sun_groups.is_empty() {
            notes.push("no sun shot".to_owned());
            None
        } else {
            let expected = sun_solid_angle_sr(1.0);
            let mut values: Vec<[f64; 3]> = Vec::new();
            let mut refused = Vec::new();
            for g in &sun_groups {
                let pixels = g.map.width * g.map.height;
                let mut e = [0.0; 3];
                let mut ok = true;
                for (c, ec) in e.iter_mut().enumerate() {
                    // Only saturation matters here: the dark sky around the
                    // disc is underexposed through the filter, and that is
                    // what it should be.
                    let clipped: Vec<bool> = g.map.mask.iter().map(|&m| m & (MASK_SATURATED << c) != 0).collect();
                    let channel: Vec<f32> = (0..pixels).map(|p| g.map.rgb[3 * p + c]).collect();
                    let frame = SunFrame {
                        width: g.map.width,
                        height: g.map.height,
                        radiance: &channel,
                        clipped: Some(&clipped),
                        focal_px: g.pinhole.focal_px,
                        principal_px: g.pinhole.principal_px,
                        transmittance: 1.0,
                    };
                    match measure_sun(&frame, expected) {
                        Ok(d) => *ec = d.irradiance,
                        Err(err) => {
                            refused.push(format!("{} channel {c}: {err}", g.key));
                            ok = false;
                            break;
                        }
                    }
                }
                if ok {
                    values.push(e);
                }
            }
            if values.is_empty() {
                notes.push(format!("the sun could not be measured: {}", refused.join("; ")));
                None
            } else {
                let n = values.len() as f64;
                let mean = [0, 1, 2].map(|c| values.iter().map(|v| v[c]).sum::<f64>() / n);
                let spread = [0, 1, 2].map(|c| {
                    let (lo, hi) = values
                        .iter()
                        .fold((f64::INFINITY, 0.0f64), |(lo, hi), v| (lo.min(v[c]), hi.max(v[c])));
                    (hi - lo) / mean[c]
                });
                let agrees = spread.iter().all(|&s| s <= TRIPLET_AGREEMENT);
                if !agrees {
                    notes.push(format!(
                        "the sun frames disagree by {:.1}/{:.1}/{:.1}% (r/g/b): clouds near the sun?",
                        100.0 * spread[0],
                        100.0 * spread[1],
                        100.0 * spread[2]
                    ));
                }
                Some(SunMeasurement {
                    time: mean_time(&sun_groups),
                    irradiance: mean,
                    spread,
                    frames: values.len(),
                    agrees,
                    refused,
                })
            }
        };

        // The sky (§5.3.2).
        let valid_of = |g: &MergedGroup| g.map.mask.iter().map(|&m| m == 0).collect::<Vec<bool>>();
        let sky = if sky_groups.is_empty() {
            notes.push("no sky scan".to_owned());
            None
        } else {
            let masks: Vec<Vec<bool>> = sky_groups.iter().map(|g| valid_of(g)).collect();
            let frames: Vec<SkyFrame> = sky_groups
                .iter()
                .zip(&masks)
                .map(|(g, m)| sky_frame(g, m, optics))
                .collect();
            let pixels = sky_groups[0].map.width * sky_groups[0].map.height;
            let stride = ((pixels as f64 / SKY_SAMPLES_PER_FRAME as f64).sqrt().round() as usize).max(1);
            match sky_samples(&frames, sun.direction(), stride, SUN_MARGIN_RAD) {
                Ok(table) => {
                    let fits: Result<Vec<RobustSkyFit>, _> = (0..3)
                        .map(|c| fit_sky_robust(&table.sky_samples(c, sun.direction()), sun.zenith_rad))
                        .collect();
                    match fits {
                        Ok(f) => Some(f),
                        Err(e) => {
                            notes.push(format!("sky fit: {e}"));
                            None
                        }
                    }
                }
                Err(e) => {
                    notes.push(format!("sky samples: {e}"));
                    None
                }
            }
        };

        // The environment (§5.3.3).
        let environment = if env_groups.is_empty() {
            None
        } else {
            let mut map = EnvironmentMap::new(env_rows, env_cols);
            for g in &env_groups {
                let m = valid_of(g);
                if let Err(e) = map.add_frame(&sky_frame(g, &m, optics), 1) {
                    notes.push(format!("environment tile {}: {e}", g.key));
                }
            }
            Some(map)
        };
        out.push(OccurrenceLight {
            occurrence: name.to_owned(),
            held_out: groups[0].held_out,
            time,
            sun,
            sun_irradiance,
            sky,
            environment,
            notes,
        });
    }
    Ok(out)
}

/// Values toward unit directions averaged on a `size` × `size` fisheye:
/// zenith at the centre, the horizon on the inscribed circle (equidistant
/// in zenith angle), north up and east to the right (as seen from above).
/// Directions below the horizon and non-finite values are skipped; pixels
/// nothing fell in are NaN.
pub fn fisheye_average(points: impl IntoIterator<Item = ([f64; 3], f64)>, size: usize) -> Vec<f64> {
    let mut sum = vec![0.0; size * size];
    let mut count = vec![0u32; size * size];
    let half = size as f64 / 2.0;
    for (d, v) in points {
        if d[2] < 0.0 || !v.is_finite() {
            continue;
        }
        let r = d[2].clamp(-1.0, 1.0).acos() / std::f64::consts::FRAC_PI_2 * half;
        let h = (d[0] * d[0] + d[1] * d[1]).sqrt().max(1e-12);
        let (u, w) = ((half + r * d[0] / h) as usize, (half - r * d[1] / h) as usize);
        if u < size && w < size {
            sum[w * size + u] += v;
            count[w * size + u] += 1;
        }
    }
    sum.iter()
        .zip(&count)
        .map(|(s, &n)| if n > 0 { s / f64::from(n) } else { f64::NAN })
        .collect()
}

/// [`fisheye_average`] of `value(d, measured)` over the valid sky pixels of
/// an occurrence's sky scan, `d` the unit direction a pixel looks toward.
pub fn sky_fisheye(
    merged: &[MergedGroup],
    optics: &StationOptics,
    occurrence: &str,
    channel: usize,
    size: usize,
    value: impl Fn([f64; 3], f64) -> f64,
) -> Vec<f64> {
    let mut points = Vec::new();
    for g in merged
        .iter()
        .filter(|g| g.occurrence == occurrence && g.purpose == Purpose::Sky)
    {
        for y in 0..g.map.height {
            for x in 0..g.map.width {
                let p = y * g.map.width + x;
                if g.map.mask[p] != 0 {
                    continue;
                }
                let Some(d) = g.pinhole.unproject(x as f64 + 0.5, y as f64 + 0.5) else {
                    continue;
                };
                let d = g.mount(&optics.mount).to_world(g.head, d);
                if d[2] > 0.0 {
                    points.push((d, value(d, f64::from(g.map.rgb[3 * p + channel]))));
                }
            }
        }
    }
    fisheye_average(points, size)
}

//! One scan's products: from the HDR maps of one occurrence's sun triplet
//! and sky scan, the sun's irradiance (§5.3.1), the sky per channel
//! (§5.3.2, eq. 5.9, with the model chosen and why), the residuals, the
//! zenith-to-horizon profile and the quality flags. Everything the day's
//! products need is in here, so the raw frames may go once it is written.

use chrono::{DateTime, Utc};
use serde::{Deserialize, Serialize};

use super::profile::{MeridianProfile, meridian_profile};
use super::quality::QualityFlags;
use super::regions::{SkyRegions, sky_regions};
use crate::pipeline::{MergedGroup, PipelineError, Purpose, StationOptics, illumination};
use crate::sky::{ChannelSky, SkyModel};
use crate::sun::air_mass;

/// Pixels per sky frame the profile averages, about (every k-th pixel).
pub const PROFILE_PIXELS_PER_FRAME: usize = 4000;

/// The sun measured in one scan.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SunRecord {
    /// Mean time of the sun frames measured.
    pub time_utc: DateTime<Utc>,
    /// The sun's zenith angle at that time, degrees (apparent, refracted).
    pub zenith_deg: f64,
    /// Kasten–Young air mass at that zenith angle.
    pub air_mass: f64,
    /// Irradiance normal to the sun per channel (mean of the frames), W·m⁻²
    /// (full-well gauge, see [`crate::pipeline`]).
    pub irradiance_w_m2: [f64; 3],
    /// (max − min)/mean over the frames per channel.
    pub spread: [f64; 3],
    /// Frames measured.
    pub frames: usize,
    /// Frames that could not be measured, and why.
    pub refused: Vec<String>,
}

/// Everything processing keeps of one scan (one occurrence).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ScanProducts {
    /// The occurrence id (`{session}@{date}#{n}`).
    pub occurrence: String,
    /// The scan's reference time: the mean time of its sky tiles, else of its first group.
    pub time_utc: DateTime<Utc>,
    /// The sun's zenith angle at that time, degrees (apparent, refracted).
    pub sun_zenith_deg: f64,
    /// The sun's azimuth at that time, degrees from north through east.
    pub sun_azimuth_deg: f64,
    /// The sun's irradiance, if a sun frame was measured.
    pub sun: Option<SunRecord>,
    /// The sky per channel (r, g, b): eq. (5.9) parameters, model chosen
    /// and why, RMS relative residual, samples and masked fraction.
    pub sky: Option<Vec<ChannelSky>>,
    /// Measured and fitted radiance in the sun's vertical plane.
    pub profile: MeridianProfile,
    /// The measured sky by region, for the sky-condition index (empty in
    /// products written before it was kept).
    #[serde(default)]
    pub regions: SkyRegions,
    /// Quality flags.
    pub quality: QualityFlags,
    /// What could not be done, in words.
    pub notes: Vec<String>,
}

impl ScanProducts {
    /// The fitted models per channel, if any.
    pub fn models(&self) -> Option<[SkyModel; 3]> {
        let s = self.sky.as_ref()?;
        (s.len() == 3).then(|| [s[0].model, s[1].model, s[2].model])
    }

    /// The RON text of the products (deterministic: the same products give the same bytes).
    pub fn to_ron(&self) -> Result<String, ron::Error> {
        ron::ser::to_string_pretty(self, ron::ser::PrettyConfig::default())
    }
}

/// A file name for an occurrence id: letters, digits and `-` kept, every
/// other character `_` (`sky@2026-08-28#3` → `sky_2026-08-28_3`).
pub fn scan_file_stem(occurrence: &str) -> String {
    occurrence
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() || c == '-' { c } else { '_' })
        .collect()
}

/// The products of `occurrence` from its merged sun and sky groups in `merged`.
pub fn scan_products(
    merged: &[MergedGroup],
    optics: &StationOptics,
    occurrence: &str,
) -> Result<ScanProducts, PipelineError> {
    let own: Vec<MergedGroup> = merged
        .iter()
        .filter(|g| g.occurrence == occurrence && matches!(g.purpose, Purpose::Sun | Purpose::Sky))
        .cloned()
        .collect();
    let Some(first) = own.first() else {
        return Err(PipelineError::NoScan {
            occurrence: occurrence.to_owned(),
        });
    };
    let stride = {
        let pixels = first.map.width * first.map.height;
        ((pixels as f64 / PROFILE_PIXELS_PER_FRAME as f64).sqrt().round() as usize).max(1)
    };
    let light = illumination(&own, optics, 1, 1)?;
    let l = light.into_iter().next().ok_or_else(|| PipelineError::NoScan {
        occurrence: occurrence.to_owned(),
    })?;
    let sky: Option<Vec<ChannelSky>> = l.sky.as_ref().map(|fits| {
        fits.iter()
            .zip(["r", "g", "b"])
            .map(|(f, name)| ChannelSky::of_robust(name, f))
            .collect()
    });
    let models = sky
        .as_ref()
        .filter(|s| s.len() == 3)
        .map(|s| [s[0].model, s[1].model, s[2].model]);
    let profile = meridian_profile(&own, optics, occurrence, &l.sun, models.as_ref(), stride);
    let regions = sky_regions(&own, optics, occurrence, l.sun.direction(), stride);
    let sun = match &l.sun_irradiance {
        Some(m) => {
            let at = crate::sun::sun_position(m.time, &optics.observer, optics.delta_t_s).map_err(|e| {
                PipelineError::Sun {
                    time: m.time,
                    message: e.to_string(),
                }
            })?;
            Some(SunRecord {
                time_utc: m.time,
                zenith_deg: at.zenith_rad.to_degrees(),
                air_mass: air_mass(at.zenith_rad),
                irradiance_w_m2: m.irradiance,
                spread: m.spread,
                frames: m.frames,
                refused: m.refused.clone(),
            })
        }
        None => None,
    };
    let fit_figures: Option<Vec<(f64, f64)>> = sky
        .as_ref()
        .map(|s| s.iter().map(|c| (c.rms_relative, c.masked_fraction)).collect());
    let quality = QualityFlags::judge(sun.as_ref().map(|s| s.spread), fit_figures.as_deref());
    Ok(ScanProducts {
        occurrence: occurrence.to_owned(),
        time_utc: l.time,
        sun_zenith_deg: l.sun.zenith_rad.to_degrees(),
        sun_azimuth_deg: l.sun.azimuth_rad.to_degrees(),
        sun,
        sky,
        profile,
        regions,
        quality,
        notes: l.notes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn file_stems_are_plain() {
        assert_eq!(scan_file_stem("sky@2026-08-28#3"), "sky_2026-08-28_3");
        assert_eq!(scan_file_stem("a b/c"), "a_b_c");
    }
}

//! HDR radiance per group, with the filter and the lens falloff undone.

use rayon::prelude::*;

use super::{FrameGroup, PipelineError, Purpose, StationOptics};
use crate::hdr::bracket::Bracket;
use crate::hdr::curve::ResponseCurve;
use crate::hdr::merge::{MergeOptions, RadianceMap, merge};
use crate::pose::{HeadPose, Mount, Pinhole};

/// One merged group: a radiance map and where it looked.
#[derive(Debug, Clone)]
pub struct MergedGroup {
    /// The group's key.
    pub key: String,
    /// The occurrence.
    pub occurrence: String,
    /// Whether the occurrence is held out.
    pub held_out: bool,
    /// What for.
    pub purpose: Purpose,
    /// Mean capture time.
    pub time: chrono::DateTime<chrono::Utc>,
    /// Mean head reading.
    pub head: HeadPose,
    /// A photograph's own orientation when taken off the head
    /// ([`super::CapturedFrame::held_by`]); `None` for the station's head.
    pub held_by: Option<Mount>,
    /// Where the head stood, metres.
    pub position_m: [f64; 3],
    /// The intrinsics at the map's size.
    pub pinhole: Pinhole,
    /// Taken at its own focal length ([`super::CapturedFrame::focal_px`]):
    /// a zoom photograph, whose [`MergedGroup::pinhole`] is that focal
    /// length's, not the station camera's.
    pub zoom: bool,
    /// Radiance (W·m⁻²·sr⁻¹ under the full-well gauge), variance and mask.
    pub map: RadianceMap,
}

impl MergedGroup {
    /// How the camera was held: the photograph's own orientation when it
    /// was taken off the head, else the station's mount (`station`).
    pub fn mount(&self, station: &Mount) -> Mount {
        self.held_by.unwrap_or(*station)
    }
}

/// Merges every group through `curve`. Sun groups are merged frame by frame
/// (each frame is its own measurement), so they give one map per frame.
pub fn merge_groups(
    groups: &[FrameGroup],
    curve: &ResponseCurve,
    optics: &StationOptics,
) -> Result<Vec<MergedGroup>, PipelineError> {
    let jobs: Vec<(String, Vec<&super::CapturedFrame>)> = groups
        .iter()
        .flat_map(|g| {
            if *g.purpose() == Purpose::Sun {
                g.frames.iter().map(|f| (f.key.clone(), vec![f])).collect::<Vec<_>>()
            } else {
                vec![(g.key.clone(), g.frames.iter().collect())]
            }
        })
        .collect();
    jobs.par_iter()
        .map(|(key, frames)| {
            let err = |source| PipelineError::Merge {
                group: key.clone(),
                source,
            };
            let first = frames[0];
            if let Some(other) = frames.iter().find(|f| f.focal_px != first.focal_px) {
                return Err(PipelineError::MixedFocalLengths {
                    group: key.clone(),
                    first: first.focal_px,
                    other: other.key.clone(),
                    other_focal_px: other.focal_px,
                });
            }
            let bracket = Bracket::new(
                frames.iter().map(|f| f.codes.clone()).collect(),
                frames.iter().map(|f| f.exposure_s).collect(),
            )
            .map_err(err)?;
            let opts = MergeOptions {
                nd_transmittance: first.filter_transmittance,
                // The station lens's falloff; a zoom photograph's is not known.
                falloff: first.focal_px.is_none().then_some(optics.falloff),
                ..MergeOptions::default()
            };
            let map = merge(&bracket, curve, &opts).map_err(err)?;
            let n = frames.len() as f64;
            let head = HeadPose {
                pan_rad: frames.iter().map(|f| f.head.pan_rad).sum::<f64>() / n,
                tilt_rad: frames.iter().map(|f| f.head.tilt_rad).sum::<f64>() / n,
            };
            Ok(MergedGroup {
                key: key.clone(),
                occurrence: first.occurrence.clone(),
                held_out: first.held_out,
                purpose: first.purpose.clone(),
                time: super::mean_time(&frames.iter().map(|f| f.time).collect::<Vec<_>>()),
                head,
                held_by: first.held_by,
                position_m: first.position_m,
                pinhole: match first.focal_px {
                    Some(f) => Pinhole::centred(f, map.width, map.height),
                    None => optics.pinhole_at(map.width, map.height),
                },
                zoom: first.focal_px.is_some(),
                map,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::image::CodeImage;
    use crate::hdr::curve::ChannelCurve;
    use crate::pipeline::CapturedFrame;

    fn optics() -> StationOptics {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/sim-station.ron");
        StationOptics::of_station(
            &campanile_config::load_station(&path)
                .expect("the example station")
                .value,
        )
    }

    fn linear_curve() -> ResponseCurve {
        let ch = ChannelCurve {
            ln_exposure: (0..256).map(|z| ((f64::from(z) + 0.5) / 256.0).ln()).collect(),
            ln_exposure_std: vec![0.0; 256],
            support: vec![1; 256],
        };
        ResponseCurve {
            bits: 8,
            channels: [ch.clone(), ch.clone(), ch],
        }
    }

    fn frame(k: usize, exposure_s: f64, focal_px: Option<f64>) -> CapturedFrame {
        CapturedFrame {
            key: format!("o@2026-08-28/s0/t0/f{k}"),
            occurrence: "o@2026-08-28".into(),
            held_out: false,
            time: chrono::DateTime::UNIX_EPOCH,
            purpose: Purpose::View { pose: "p".into() },
            head: HeadPose {
                pan_rad: 0.0,
                tilt_rad: 0.0,
            },
            held_by: None,
            position_m: [0.0; 3],
            exposure_s,
            filter_transmittance: [1.0; 3],
            codes: CodeImage {
                width: 8,
                height: 6,
                bits: 8,
                data: vec![100; 8 * 6 * 3],
                label: format!("f{k}"),
            },
            linear: false,
            focal_px,
        }
    }

    /// A zoom photograph's map gets its own undistorted, centred pinhole
    /// and no falloff correction; the station's views keep the station's.
    #[test]
    fn a_zoom_bracket_is_merged_through_its_own_lens() {
        let o = optics();
        let group = |focal| FrameGroup {
            key: "o@2026-08-28/s0/t0".into(),
            frames: vec![frame(0, 0.01, focal), frame(1, 0.02, focal)],
        };
        let zoom = &merge_groups(&[group(Some(2442.4))], &linear_curve(), &o).expect("merged")[0];
        assert!(zoom.zoom);
        assert_eq!(zoom.pinhole.focal_px, 2442.4);
        assert_eq!(zoom.pinhole.principal_px, (4.0, 3.0));
        assert_eq!((zoom.pinhole.k1, zoom.pinhole.k2), (0.0, 0.0));
        let station = &merge_groups(&[group(None)], &linear_curve(), &o).expect("merged")[0];
        assert!(!station.zoom);
        assert_eq!(station.pinhole, o.pinhole_at(8, 6));
        // Without the falloff correction the corner keeps the centre's radiance.
        let (first, last) = (zoom.map.rgb[0], zoom.map.rgb[zoom.map.rgb.len() / 2]);
        assert_eq!(first, last);
        assert_ne!(station.map.rgb[0], station.map.rgb[station.map.rgb.len() / 2]);
    }

    #[test]
    fn a_bracket_at_two_focal_lengths_is_refused_naming_both() {
        let group = FrameGroup {
            key: "o@2026-08-28/s0/t0".into(),
            frames: vec![frame(0, 0.01, None), frame(1, 0.02, Some(2442.4))],
        };
        let err = merge_groups(&[group], &linear_curve(), &optics()).expect_err("refused");
        let text = err.to_string();
        assert!(
            text.contains("o@2026-08-28/s0/t0")
                && text.contains("the station camera's and 2442.4 px for o@2026-08-28/s0/t0/f1"),
            "{text}"
        );
    }
}

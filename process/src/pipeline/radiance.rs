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
            let bracket = Bracket::new(
                frames.iter().map(|f| f.codes.clone()).collect(),
                frames.iter().map(|f| f.exposure_s).collect(),
            )
            .map_err(err)?;
            let opts = MergeOptions {
                nd_transmittance: first.filter_transmittance,
                falloff: Some(optics.falloff),
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
                pinhole: optics.pinhole_at(map.width, map.height),
                map,
            })
        })
        .collect()
}

//! Captured frames and their grouping into shots: the frames of one target
//! (a tile, a pose) of one step form a bracket.

use chrono::{DateTime, Utc};

use crate::camera::image::CodeImage;
use crate::pose::{HeadPose, Mount};

/// What a frame was taken for (from the plan step that took it).
#[derive(Debug, Clone, PartialEq)]
pub enum Purpose {
    /// A short exposure to centre the head on the sun (not measured).
    SunCentering,
    /// A filtered frame of the sun (§5.3.1); each one is measured alone.
    Sun,
    /// A tile of a sky scan (§5.3.2).
    Sky,
    /// A tile of the environment below and around the horizon (§5.3.3).
    Environment,
    /// A view of the scene from a named pose.
    View {
        /// The pose's name.
        pose: String,
    },
    /// A view from a named pose with the lights at given levels (indoors, §4.7.2).
    Lights {
        /// The pose's name.
        pose: String,
        /// Level per light channel.
        levels: Vec<f64>,
    },
}

/// One stored frame with what processing needs of its journal line.
#[derive(Debug, Clone)]
pub struct CapturedFrame {
    /// The journal key, `"{occurrence}/s{step}/t{target}/f{frame}"`.
    pub key: String,
    /// The occurrence (session name and date) it belongs to.
    pub occurrence: String,
    /// Whether the plan holds this occurrence out of fitting.
    pub held_out: bool,
    /// When it was taken.
    pub time: DateTime<Utc>,
    /// What for.
    pub purpose: Purpose,
    /// The head's reading; for a photograph taken off the head, the head
    /// pose that goes with [`CapturedFrame::held_by`].
    pub head: HeadPose,
    /// For a photograph taken off the head (by hand, or on a plain
    /// tripod; an imported one): its own orientation as a mount
    /// ([`Mount::holding`]), which replaces the station's. `None` for the
    /// station's head, through the station's mount.
    pub held_by: Option<Mount>,
    /// Where the head (or the hand-held camera) stood, scene frame, metres.
    pub position_m: [f64; 3],
    /// The exposure the camera reports it applied, seconds.
    pub exposure_s: f64,
    /// Transmittance of the filter in the light path, per channel.
    pub filter_transmittance: [f64; 3],
    /// The raw codes.
    pub codes: CodeImage,
    /// The codes are a RAW frame's logarithmic codes
    /// ([`crate::hdr::linear_codes`]), whose response is known, not a
    /// camera's processed output.
    pub linear: bool,
    /// The lens's focal length for this frame, pixels at its size, when it
    /// is not the station camera's: a zoom photograph (the journal's
    /// `focal_px`), taken as an undistorted pinhole centred on the frame
    /// with no falloff. `None`: the station camera.
    pub focal_px: Option<f64>,
}

/// How far below the largest code a lossy (JPEG) frame's codes are taken
/// as clipped, in 8-bit codes. A channel clipped at 255 decodes from a JPEG
/// at 250–255 (the compression's error near saturation, chroma above all);
/// read as valid, those codes bend the top of the recovered curve, which
/// sets each channel's full-well gauge (`g(255) = 0`), and shift the whole
/// channel (−0.16 in ln for blue on the simulated sky day at quality 95).
/// As clipped, they get no weight in the recovery or the merge, and the
/// curve's top is its smooth continuation.
pub const LOSSY_CLIP_MARGIN: u16 = 5;

/// Marks the codes of a lossy (JPEG) frame within [`LOSSY_CLIP_MARGIN`]
/// (scaled to its depth) of the largest code as clipped (the largest
/// code); returns how many were moved.
pub fn clip_lossy_top(codes: &mut CodeImage) -> usize {
    let top = codes.max_code();
    let margin = (u32::from(LOSSY_CLIP_MARGIN) * u32::from(top) / 255) as u16;
    let from = top.saturating_sub(margin);
    let mut moved = 0;
    for z in codes.data.iter_mut().filter(|z| (from..top).contains(*z)) {
        *z = top;
        moved += 1;
    }
    moved
}

/// The frames of one target of one step: a bracket, or the sun's frames.
#[derive(Debug, Clone)]
pub struct FrameGroup {
    /// The key without its frame number, `"{occurrence}/s{step}/t{target}"`.
    pub key: String,
    /// Its frames, in journal order.
    pub frames: Vec<CapturedFrame>,
}

impl FrameGroup {
    /// The group's purpose (its first frame's).
    pub fn purpose(&self) -> &Purpose {
        &self.frames[0].purpose
    }

    /// The occurrence.
    pub fn occurrence(&self) -> &str {
        &self.frames[0].occurrence
    }
}

/// The mean of `times` (to the millisecond); the Unix epoch for none.
pub fn mean_time(times: &[DateTime<Utc>]) -> DateTime<Utc> {
    let Some(&t0) = times.first() else {
        return DateTime::UNIX_EPOCH;
    };
    let ms = times.iter().map(|t| (*t - t0).num_milliseconds() as f64).sum::<f64>() / times.len() as f64;
    t0 + chrono::Duration::milliseconds(ms.round() as i64)
}

/// Groups frames by key prefix (everything before the last `/`), keeping
/// first-seen order; centring frames are dropped.
pub fn group_frames(frames: Vec<CapturedFrame>) -> Vec<FrameGroup> {
    let mut groups: Vec<FrameGroup> = Vec::new();
    let mut index = std::collections::HashMap::new();
    for f in frames {
        if f.purpose == Purpose::SunCentering {
            continue;
        }
        let prefix = f.key.rsplit_once('/').map_or(f.key.as_str(), |(p, _)| p).to_string();
        match index.get(&prefix) {
            Some(&i) => {
                let g: &mut FrameGroup = &mut groups[i];
                g.frames.push(f);
            }
            None => {
                index.insert(prefix.clone(), groups.len());
                groups.push(FrameGroup {
                    key: prefix,
                    frames: vec![f],
                });
            }
        }
    }
    groups
}

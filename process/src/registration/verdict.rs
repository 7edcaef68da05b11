//! Whether a registered pose is to be trusted, and the figures that say so.
//!
//! - `failed`: no pose. Fewer than three targets, or no three targets
//!   agree on one.
//! - `poor`: a pose, but one of: the agreeing targets lie nearly on a line
//!   (the rotation about that line is not fixed), the reprojection error
//!   is over its limit (a wrong survey, a wrong lens model, a moved
//!   target that consensus could not single out), or the covariance says
//!   the position or the orientation is less certain than the limits.
//! - `ok`: none of these.

use serde::{Deserialize, Serialize};

/// The three verdicts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Verdict {
    /// The pose is within the limits.
    Ok,
    /// A pose, outside one of the limits (see the reasons).
    Poor,
    /// No pose.
    Failed,
}

impl std::fmt::Display for Verdict {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Verdict::Ok => "ok",
            Verdict::Poor => "poor",
            Verdict::Failed => "failed",
        })
    }
}

/// The limits a pose must meet to be `ok`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct QualityLimits {
    /// Fewest agreeing targets for a pose at all.
    pub min_targets: usize,
    /// Largest root mean square reprojection error, pixels.
    pub max_rms_px: f64,
    /// Largest one-sigma position uncertainty (any axis) as a fraction of
    /// the mean distance to the targets: 2.5e-4 is 2.5 mm at 10 m.
    pub max_sigma_position_relative: f64,
    /// Largest one-sigma orientation uncertainty (any axis), degrees.
    pub max_sigma_angle_deg: f64,
    /// Least layout spread: the targets' second principal extent over
    /// their first (0 for targets on a line, 1 for a round cloud).
    pub min_layout_spread: f64,
}

impl Default for QualityLimits {
    /// Limits whose two-sigma bounds are the simulator's goals (5 mm at
    /// 10 m, 0.05°), one pixel of reprojection error, and a layout at
    /// least a tenth as wide as it is long.
    fn default() -> Self {
        QualityLimits {
            min_targets: 3,
            max_rms_px: 1.0,
            max_sigma_position_relative: 2.5e-4,
            max_sigma_angle_deg: 0.025,
            min_layout_spread: 0.1,
        }
    }
}

/// A registration's verdict and figures.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Quality {
    /// The verdict.
    pub verdict: Verdict,
    /// Why the verdict is not `ok` (empty when it is).
    pub reasons: Vec<String>,
    /// Targets with at least one point in the photograph.
    pub targets_seen: usize,
    /// Targets the pose rests on.
    pub targets_used: usize,
    /// Points the pose rests on.
    pub points_used: usize,
    /// Targets seen but left out by consensus (false, moved or displaced).
    pub rejected_targets: Vec<u32>,
    /// Root mean square reprojection error of the points used, pixels.
    pub rms_px: Option<f64>,
    /// Largest reprojection error of the points used, pixels.
    pub max_px: Option<f64>,
    /// One-sigma position uncertainty along x, y, z (east, north, up), metres.
    pub sigma_position_m: Option<[f64; 3]>,
    /// One-sigma orientation uncertainty about x, y, z, degrees.
    pub sigma_angle_deg: Option<[f64; 3]>,
    /// Mean distance from the camera to the targets used, metres.
    pub mean_distance_m: Option<f64>,
    /// Layout spread of the targets used (see [`QualityLimits::min_layout_spread`]).
    pub layout_spread: Option<f64>,
}

impl Quality {
    /// A `failed` quality for `reason`.
    pub fn failed(reason: String, targets_seen: usize) -> Quality {
        Quality {
            verdict: Verdict::Failed,
            reasons: vec![reason],
            targets_seen,
            targets_used: 0,
            points_used: 0,
            rejected_targets: Vec::new(),
            rms_px: None,
            max_px: None,
            sigma_position_m: None,
            sigma_angle_deg: None,
            mean_distance_m: None,
            layout_spread: None,
        }
    }

    /// Judges the figures against `limits`: sets the verdict and reasons
    /// of a quality whose figures are filled in.
    pub fn judged(mut self, limits: &QualityLimits) -> Quality {
        let mut reasons = Vec::new();
        if self.targets_used < limits.min_targets {
            reasons.push(format!(
                "too few targets: {} agree, at least {} needed",
                self.targets_used, limits.min_targets
            ));
        }
        if let Some(s) = self.layout_spread
            && s < limits.min_layout_spread
        {
            reasons.push(format!(
                "degenerate layout: the targets lie nearly on a line (spread {s:.3} < {})",
                limits.min_layout_spread
            ));
        }
        if let Some(rms) = self.rms_px
            && rms > limits.max_rms_px
        {
            reasons.push(format!(
                "reprojection error {rms:.2} px rms over the limit of {} px",
                limits.max_rms_px
            ));
        }
        match (self.sigma_position_m, self.mean_distance_m) {
            (Some(s), Some(d)) => {
                let worst = s.iter().fold(0.0f64, |a, b| a.max(*b));
                let limit = limits.max_sigma_position_relative * d;
                if worst > limit {
                    reasons.push(format!(
                        "position uncertain: σ {:.1} mm over the limit of {:.1} mm at {d:.1} m",
                        worst * 1e3,
                        limit * 1e3
                    ));
                }
            }
            _ => reasons.push("the pose's covariance is singular: the targets do not fix it".into()),
        }
        if let Some(a) = self.sigma_angle_deg {
            let worst = a.iter().fold(0.0f64, |x, y| x.max(*y));
            if worst > limits.max_sigma_angle_deg {
                reasons.push(format!(
                    "orientation uncertain: σ {worst:.3}° over the limit of {}°",
                    limits.max_sigma_angle_deg
                ));
            }
        }
        self.verdict = if reasons.is_empty() { Verdict::Ok } else { Verdict::Poor };
        self.reasons = reasons;
        self
    }
}

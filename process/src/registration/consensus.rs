//! RANSAC (Fischler & Bolles 1981) over the three-point solver: draw three
//! points from three different targets, solve, count the targets every
//! point of which reprojects within the threshold, keep the pose most
//! targets agree on. A target is trusted whole or not at all, so a moved
//! or false target, or one whose corners a partial occlusion displaced,
//! drops out together.

use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::camera_pose::CameraPose;
use super::correspondence::Correspondence;
use super::p3p;
use crate::pose::Pinhole;

/// What consensus settles on.
#[derive(Debug, Clone, PartialEq)]
pub struct Consensus {
    /// The hypothesis most targets agree with.
    pub pose: CameraPose,
    /// Which input points belong to agreeing targets.
    pub inliers: Vec<bool>,
    /// Targets that agree.
    pub agreeing_targets: Vec<u32>,
    /// Hypotheses tried.
    pub hypotheses: usize,
}

/// Settings of the consensus search.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConsensusSettings {
    /// A point agrees when it reprojects within this many pixels.
    pub threshold_px: f64,
    /// Most samples drawn.
    pub max_samples: usize,
    /// Confidence of having drawn one all-inlier sample, for the adaptive stop.
    pub confidence: f64,
    /// Seed of the sampling (the result is the same for the same seed).
    pub seed: u64,
}

impl Default for ConsensusSettings {
    fn default() -> Self {
        ConsensusSettings {
            threshold_px: 4.0,
            max_samples: 500,
            confidence: 0.9999,
            seed: 0x5eed,
        }
    }
}

/// Which points agree with `pose`, judged per target (see the module doc).
pub fn agreeing(pinhole: &Pinhole, points: &[Correspondence], pose: &CameraPose, threshold_px: f64) -> Vec<bool> {
    let point_ok: Vec<bool> = points
        .iter()
        .map(|c| {
            pose.project(pinhole, &Vector3::from(c.world))
                .is_some_and(|(u, v)| (u - c.pixel.0).hypot(v - c.pixel.1) <= threshold_px)
        })
        .collect();
    let mut target_ok: std::collections::HashMap<u32, bool> = std::collections::HashMap::new();
    for (c, ok) in points.iter().zip(&point_ok) {
        *target_ok.entry(c.target).or_insert(true) &= *ok;
    }
    points.iter().map(|c| target_ok[&c.target]).collect()
}

/// A point's index in the input and its unit bearing.
type IndexedBearing = (usize, [f64; 3]);

fn targets_of(points: &[Correspondence], mask: &[bool]) -> Vec<u32> {
    let mut ids: Vec<u32> = points
        .iter()
        .zip(mask)
        .filter(|(_, m)| **m)
        .map(|(c, _)| c.target)
        .collect();
    ids.sort_unstable();
    ids.dedup();
    ids
}

/// The consensus pose of `points`, or `None` when fewer than three targets
/// have a point the lens can unproject, or no hypothesis gathers three targets.
pub fn consensus(pinhole: &Pinhole, points: &[Correspondence], settings: &ConsensusSettings) -> Option<Consensus> {
    // Bearings of every point, grouped by target.
    let mut by_target: Vec<(u32, Vec<IndexedBearing>)> = Vec::new();
    for (i, c) in points.iter().enumerate() {
        let Some(b) = pinhole.unproject(c.pixel.0, c.pixel.1) else {
            continue;
        };
        match by_target.iter_mut().find(|(t, _)| *t == c.target) {
            Some((_, v)) => v.push((i, b)),
            None => by_target.push((c.target, vec![(i, b)])),
        }
    }
    let n_targets = by_target.len();
    if n_targets < 3 {
        return None;
    }
    let mut rng = ChaCha8Rng::seed_from_u64(settings.seed);
    let mut best: Option<(usize, f64, CameraPose, Vec<bool>)> = None;
    let mut needed = settings.max_samples;
    let mut drawn = 0;
    while drawn < needed.min(settings.max_samples) {
        drawn += 1;
        let mut pick = [0usize; 3];
        pick[0] = rng.random_range(0..n_targets);
        pick[1] = loop {
            let k = rng.random_range(0..n_targets);
            if k != pick[0] {
                break k;
            }
        };
        pick[2] = loop {
            let k = rng.random_range(0..n_targets);
            if k != pick[0] && k != pick[1] {
                break k;
            }
        };
        let chosen = pick.map(|t| {
            let list = &by_target[t].1;
            list[rng.random_range(0..list.len())]
        });
        let world = chosen.map(|(i, _)| points[i].world);
        let bearings = chosen.map(|(_, b)| b);
        for pose in p3p::poses(world, bearings) {
            let mask = agreeing(pinhole, points, &pose, settings.threshold_px);
            let count = targets_of(points, &mask).len();
            // Ties go to the smaller total error of the agreeing points (MSAC-like).
            let spread: f64 = points
                .iter()
                .zip(&mask)
                .filter(|(_, m)| **m)
                .filter_map(|(c, _)| {
                    pose.project(pinhole, &Vector3::from(c.world))
                        .map(|(u, v)| (u - c.pixel.0).hypot(v - c.pixel.1))
                })
                .sum();
            let better = match &best {
                None => true,
                Some((n, s, _, _)) => count > *n || (count == *n && spread < *s),
            };
            if better {
                let w = count as f64 / n_targets as f64;
                if w > 0.0 {
                    let p_good = w.powi(3).min(1.0 - 1e-12);
                    let n = ((1.0 - settings.confidence).ln() / (1.0 - p_good).ln()).ceil();
                    needed = (n.max(20.0) as usize).min(settings.max_samples);
                }
                best = Some((count, spread, pose, mask));
            }
        }
    }
    let (count, _, pose, inliers) = best?;
    if count < 3 {
        return None;
    }
    Some(Consensus {
        pose,
        agreeing_targets: targets_of(points, &inliers),
        inliers,
        hypotheses: drawn,
    })
}

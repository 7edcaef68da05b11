//! Brackets from a time-ordered run of photographs: consecutive frames of
//! one camera, at one focal length and aperture, each starting within a
//! gap of the previous one's end, with no exposure twice.
//!
//! A frame starts a new bracket when:
//! - the gap from the previous frame's end (its start plus its exposure
//!   time) to its start exceeds the gap allowed;
//! - its focal length or f-number differs from the previous frame's
//!   (hand-taken brackets vary the time, and a zoom or aperture change is
//!   a new shot);
//! - its exposure (time and ISO) repeats one already in the bracket: the
//!   same exposure again is the next bracket of a run of auto-exposure
//!   brackets taken back to back, never a frame the merge could use twice.

use chrono::{DateTime, Utc};

/// What grouping reads of one photograph.
#[derive(Debug, Clone, PartialEq)]
pub struct GroupingInput {
    /// The photograph's true start, UTC.
    pub start: DateTime<Utc>,
    /// Its exposure time, seconds.
    pub exposure_s: f64,
    /// ISO, if known.
    pub iso: Option<f64>,
    /// f-number, if known.
    pub f_number: Option<f64>,
    /// Focal length, mm, if known.
    pub focal_length_mm: Option<f64>,
}

/// A bracket: indices of its frames in the input, and why it began.
#[derive(Debug, Clone, PartialEq)]
pub struct Group {
    /// Indices into the input, in order.
    pub frames: Vec<usize>,
    /// Why this bracket began where it did (empty for the first).
    pub began: String,
}

fn same(a: Option<f64>, b: Option<f64>) -> bool {
    match (a, b) {
        (Some(a), Some(b)) => (a - b).abs() <= 1e-9 * a.abs().max(b.abs()),
        (None, None) => true,
        _ => false,
    }
}

/// Groups `shots` (sorted by start) into brackets, allowing `gap_s`
/// seconds between a frame's end and the next frame's start.
pub fn group(shots: &[GroupingInput], gap_s: f64) -> Vec<Group> {
    let mut groups: Vec<Group> = Vec::new();
    for (i, s) in shots.iter().enumerate() {
        let began = match groups.last() {
            None => Some(String::new()),
            Some(g) => {
                let prev = &shots[g.frames[g.frames.len() - 1]];
                let end = prev.start + chrono::Duration::nanoseconds((prev.exposure_s * 1e9).round() as i64);
                let gap = (s.start - end).num_milliseconds() as f64 / 1000.0;
                if gap > gap_s {
                    Some(format!("{gap:.1} s after the previous frame's end (> {gap_s} s)"))
                } else if !same(prev.focal_length_mm, s.focal_length_mm) {
                    Some(format!(
                        "focal length {:?} mm after {:?} mm",
                        s.focal_length_mm, prev.focal_length_mm
                    ))
                } else if !same(prev.f_number, s.f_number) {
                    Some(format!("f-number {:?} after {:?}", s.f_number, prev.f_number))
                } else if g
                    .frames
                    .iter()
                    .any(|&j| same(Some(shots[j].exposure_s), Some(s.exposure_s)) && same(shots[j].iso, s.iso))
                {
                    Some(format!("exposure {} s again", s.exposure_s))
                } else {
                    None
                }
            }
        };
        match began {
            Some(began) => groups.push(Group { frames: vec![i], began }),
            None => {
                if let Some(g) = groups.last_mut() {
                    g.frames.push(i);
                }
            }
        }
    }
    groups
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shot(t_s: f64, exposure_s: f64) -> GroupingInput {
        GroupingInput {
            start: DateTime::UNIX_EPOCH + chrono::Duration::milliseconds((t_s * 1000.0) as i64),
            exposure_s,
            iso: Some(100.0),
            f_number: Some(5.6),
            focal_length_mm: Some(8.0),
        }
    }

    #[test]
    fn gaps_repeats_and_aperture_changes_split_brackets() {
        let mut shots = vec![
            shot(0.0, 13.0),  // ends at 13 s
            shot(15.0, 1.0),  // 2 s after: same bracket
            shot(17.0, 0.5),  // same
            shot(17.6, 1.0),  // 1 s again: a new bracket
            shot(40.0, 0.25), // 21.4 s after the end of the last: new
            shot(41.0, 0.5),
        ];
        shots[5].f_number = Some(8.0); // aperture change: new
        let g = group(&shots, 10.0);
        let frames: Vec<Vec<usize>> = g.iter().map(|g| g.frames.clone()).collect();
        assert_eq!(frames, vec![vec![0, 1, 2], vec![3], vec![4], vec![5]]);
        assert_eq!(g[1].began, "exposure 1 s again");
        assert_eq!(g[2].began, "21.4 s after the previous frame's end (> 10 s)");
        assert!(g[3].began.starts_with("f-number Some(8.0)"), "{}", g[3].began);
        // The same time at another ISO is another exposure.
        let mut iso = vec![shot(0.0, 0.01), shot(1.0, 0.01)];
        iso[1].iso = Some(400.0);
        assert_eq!(group(&iso, 10.0).len(), 1);
    }
}

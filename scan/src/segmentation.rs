//! A segmentation as data: every point's surface group.
//!
//! The segmenter (thesis §2.3) produces one; the simulator's scans carry the
//! true one; meshing (§2.4) and the scene skeleton read one. Groups are
//! numbered densely from 0.

/// A point that belongs to no group (no return, an outlier, a mixed pixel the
/// segmenter dropped).
pub const UNASSIGNED: u32 = u32::MAX;

/// Every point's group, scan by scan, in the order of the scans given.
#[derive(Debug, Clone, PartialEq)]
pub struct Segmentation {
    /// `labels[scan][point]`: the point's group in `0..groups`, or
    /// [`UNASSIGNED`].
    pub labels: Vec<Vec<u32>>,
    /// The groups' names (`surface_0`, … for a segmenter's groups; the true
    /// surfaces' names for the simulator's truth).
    pub names: Vec<String>,
}

impl Segmentation {
    /// The number of groups.
    pub fn groups(&self) -> usize {
        self.names.len()
    }

    /// The number of points in each group, over all scans.
    pub fn sizes(&self) -> Vec<usize> {
        let mut sizes = vec![0; self.names.len()];
        for &label in self.labels.iter().flatten() {
            if let Some(s) = sizes.get_mut(label as usize) {
                *s += 1;
            }
        }
        sizes
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_count_over_scans_and_skip_unassigned() {
        let s = Segmentation {
            labels: vec![vec![0, 1, 1, UNASSIGNED], vec![1, 0]],
            names: vec!["floor".into(), "wall".into()],
        };
        assert_eq!(s.groups(), 2);
        assert_eq!(s.sizes(), vec![2, 3]);
    }
}

//! An image point paired with its surveyed world point.

/// One point seen in a photograph whose world position is known.
#[derive(Debug, Clone, PartialEq)]
pub struct Correspondence {
    /// Which target it belongs to (several points may share a target:
    /// a coded target's four corners).
    pub target: u32,
    /// The pixel it is seen at, `(u, v)`, pixel centres at half-integers.
    pub pixel: (f64, f64),
    /// Its surveyed world position, metres.
    pub world: [f64; 3],
}

/// How many distinct targets `points` come from.
pub fn target_count(points: &[Correspondence]) -> usize {
    let mut ids: Vec<u32> = points.iter().map(|c| c.target).collect();
    ids.sort_unstable();
    ids.dedup();
    ids.len()
}

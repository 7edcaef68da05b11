//! The valid pixels of one scan's sky frames, each with its direction in
//! the world frame: what the profile and the regions average.

use crate::pipeline::{MergedGroup, Purpose, StationOptics};

/// Calls `f(direction, rgb)` for every `stride`-th pixel in each direction
/// of `occurrence`'s sky groups in `merged` that is not masked and has a
/// ray (`direction`: unit vector, world frame, z up; `rgb`: radiance per
/// channel, W·m⁻²·sr⁻¹, possibly non-finite).
pub fn for_each_sky_pixel(
    merged: &[MergedGroup],
    optics: &StationOptics,
    occurrence: &str,
    stride: usize,
    mut f: impl FnMut([f64; 3], [f64; 3]),
) {
    let stride = stride.max(1);
    for g in merged
        .iter()
        .filter(|g| g.occurrence == occurrence && g.purpose == Purpose::Sky)
    {
        let mount = g.mount(&optics.mount);
        for y in (0..g.map.height).step_by(stride) {
            for x in (0..g.map.width).step_by(stride) {
                let p = y * g.map.width + x;
                if g.map.mask[p] != 0 {
                    continue;
                }
                let Some(d) = g.pinhole.unproject(x as f64 + 0.5, y as f64 + 0.5) else {
                    continue;
                };
                f(
                    mount.to_world(g.head, d),
                    [0, 1, 2].map(|c| f64::from(g.map.rgb[3 * p + c])),
                );
            }
        }
    }
}

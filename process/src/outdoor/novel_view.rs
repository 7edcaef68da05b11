//! A view at a new time (thesis §5.5) rendered from recovered
//! pseudo-albedos, with the texture finer than the grid that the training
//! photographs show (§5.6.4, eq. 5.16), and compared with a photograph of
//! that view. Shared by `campanile process` (held-out views) and
//! `campanile outdoor render`.

use super::Reflectance;
use super::photo::Illumination;
use super::rerender::{RerenderSettings, relative_rmse, rerender, target_mask};
use super::texture_transfer::{MIN_REFERENCES, TextureSource, transfer_texture};
use crate::camera::image::RadianceImage;
use crate::render::{CameraRig, Scene};

/// A rendered view.
#[derive(Debug, Clone)]
pub struct NovelView {
    /// The grid's pseudo-albedos alone (§5.5).
    pub grid_only: RadianceImage,
    /// With the training photographs' texture (eq. 5.16), where there are
    /// any; else the grid-only render.
    pub rendered: RadianceImage,
    /// Training photographs whose texture the render carries (0: none).
    pub references: usize,
}

/// The render against a photograph of the same view.
#[derive(Debug, Clone, PartialEq)]
pub struct ViewComparison {
    /// Pixels compared: on the target surfaces, valid in the photograph.
    pub mask: Vec<bool>,
    /// Relative RMSE per pixel over the mask.
    pub rmse_pixel: f64,
    /// Relative RMSE of 4 × 4-pixel block means over the mask.
    pub rmse_block: f64,
    /// The same for the grid-only render.
    pub rmse_block_grid: f64,
    /// Blocks compared (at least half their pixels in the mask).
    pub blocks: usize,
}

/// Whether two rigs are the same camera (position, head angles, size).
pub fn same_camera(a: &CameraRig, b: &CameraRig) -> bool {
    a.width == b.width
        && a.height == b.height
        && (a.position - b.position).norm() < 1e-3
        && (a.head.pan_rad - b.head.pan_rad).abs() < 1e-6
        && (a.head.tilt_rad - b.head.tilt_rad).abs() < 1e-6
        && (a.mount.roll_rad - b.mount.roll_rad).abs() < 1e-6
        && (a.mount.pitch_rad - b.mount.pitch_rad).abs() < 1e-6
}

/// Renders `rig` under `light` with `settings` (the sources' low-resolution
/// renders should use the same pixel sampling). The texture comes from the
/// sources taken by this very camera where there are any (exact pixel
/// alignment), else from every source that sees the point; with no
/// sources, the grid alone.
pub fn render_view(
    scene: &Scene,
    refl: &Reflectance,
    rig: &CameraRig,
    light: &Illumination,
    sources: &[TextureSource],
    settings: &RerenderSettings,
) -> NovelView {
    let (grid_only, _) = rerender(scene, refl, rig, light, settings);
    let same: Vec<&TextureSource> = sources.iter().filter(|s| same_camera(&s.photo.rig, rig)).collect();
    let chosen: Vec<&TextureSource> = if same.is_empty() {
        sources.iter().collect()
    } else {
        same
    };
    if chosen.is_empty() {
        return NovelView {
            rendered: grid_only.clone(),
            grid_only,
            references: 0,
        };
    }
    let (rendered, _) = transfer_texture(scene, refl, rig, &grid_only, &chosen, MIN_REFERENCES);
    NovelView {
        grid_only,
        rendered,
        references: chosen.len(),
    }
}

/// Compares `view` with the photograph `measured` (valid pixels `valid`,
/// all when `None`) over the pixels that see a target cell. NaN figures
/// when nothing is compared.
pub fn compare_view(
    scene: &Scene,
    refl: &Reflectance,
    rig: &CameraRig,
    view: &NovelView,
    measured: &RadianceImage,
    valid: Option<&[bool]>,
) -> ViewComparison {
    let mask: Vec<bool> = target_mask(scene, refl, rig)
        .into_iter()
        .enumerate()
        .map(|(i, t)| t && valid.is_none_or(|v| v[i]))
        .collect();
    let (rmse_block, blocks) = block_rmse(&view.rendered, measured, &mask, 4).unwrap_or((f64::NAN, 0));
    ViewComparison {
        rmse_pixel: relative_rmse(&view.rendered, measured, &mask).unwrap_or(f64::NAN),
        rmse_block,
        rmse_block_grid: block_rmse(&view.grid_only, measured, &mask, 4).map_or(f64::NAN, |(r, _)| r),
        blocks,
        mask,
    }
}

/// Relative RMSE of `k × k` block means of `a` against `b` (all channels
/// summed) over blocks with at least half their pixels in the mask, and
/// the number of such blocks; `None` when there are none or `b` is black.
pub fn block_rmse(a: &RadianceImage, b: &RadianceImage, mask: &[bool], k: usize) -> Option<(f64, usize)> {
    if a.width != b.width || a.height != b.height || mask.len() != a.width * a.height || k == 0 {
        return None;
    }
    let (mut num, mut den, mut blocks) = (0.0, 0.0, 0usize);
    for by in 0..a.height / k {
        for bx in 0..a.width / k {
            let (mut sa, mut sb, mut n) = (0.0, 0.0, 0usize);
            for y in by * k..(by + 1) * k {
                for x in bx * k..(bx + 1) * k {
                    let i = y * a.width + x;
                    if mask[i] {
                        sa += (0..3).map(|c| f64::from(a.data[3 * i + c])).sum::<f64>();
                        sb += (0..3).map(|c| f64::from(b.data[3 * i + c])).sum::<f64>();
                        n += 1;
                    }
                }
            }
            if 2 * n >= k * k {
                num += (sa - sb).powi(2);
                den += sb * sb;
                blocks += 1;
            }
        }
    }
    (den > 0.0).then(|| ((num / den).sqrt(), blocks))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(w: usize, h: usize, f: impl Fn(usize, usize) -> f32) -> RadianceImage {
        let mut data = Vec::new();
        for y in 0..h {
            for x in 0..w {
                data.extend([f(x, y); 3]);
            }
        }
        RadianceImage {
            width: w,
            height: h,
            data,
        }
    }

    /// A uniform 10 % excess gives 0.1; a zero-mean checker inside each
    /// block gives 0 per block though not per pixel; blocks under half
    /// masked are skipped.
    #[test]
    fn block_rmse_averages_blocks_first() {
        let b = image(8, 8, |_, _| 2.0);
        let a = image(8, 8, |_, _| 2.2);
        let all = vec![true; 64];
        let (r, n) = block_rmse(&a, &b, &all, 4).unwrap();
        assert!((r - 0.1).abs() < 1e-6 && n == 4, "{r} {n}");
        let checker = image(8, 8, |x, y| if (x + y) % 2 == 0 { 2.5 } else { 1.5 });
        let (r, _) = block_rmse(&checker, &b, &all, 4).unwrap();
        assert!(r < 1e-9, "{r}");
        assert!((relative_rmse(&checker, &b, &all).unwrap() - 0.25).abs() < 1e-6);
        let mut left = vec![false; 64];
        for y in 0..8 {
            for x in 0..4 {
                left[y * 8 + x] = true;
            }
        }
        assert_eq!(block_rmse(&a, &b, &left, 4).unwrap().1, 2);
        assert!(block_rmse(&a, &b, &[false; 64], 4).is_none());
    }
}

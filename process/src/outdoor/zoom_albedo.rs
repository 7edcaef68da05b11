//! High-resolution pseudo-albedos from a zoom photograph (thesis §5.6.4,
//! eq. 5.16).
//!
//! The grid's cells are larger than a zoom photo's pixels, so a re-render
//! from the grid alone is blurred. The photo `I` at pixel resolution is
//! split into a low-frequency lighting and a high-frequency albedo: with
//! `Ĩ` the photo smoothed over one cell's footprint around the pixel and
//! `ρ̃` the recovered pseudo-albedo interpolated to the pixel, the lighting
//! is `Ẽ = Ĩ / ρ̃` and the pixel's pseudo-albedo
//!
//! `ρ(x, y) = I(x, y) / Ẽ(x, y) = ρ̃(x, y) · I(x, y) / Ĩ(x, y)`   (5.16)
//!
//! The thesis has one pseudo-albedo per point; here each cell has two,
//! ρ^sun and ρ^se. The detail ratio `I / Ĩ` is applied to both
//! (`ρ^sun = ρ̃^sun · I/Ĩ`, `ρ^se = ρ̃^se · I/Ĩ`), which is eq. (5.16) for
//! each of them, and which assumes that the texture finer than a cell
//! scales both alike (one material at a finer scale, as on the campanile's
//! stone). The photo's mix of sun and sky then cancels out: only its
//! spatial detail is used.
//!
//! The smoothing window is the grid's cell (times
//! [`ZoomSettings::window_cells`]) centred on the pixel's surface point, in
//! the face's texture coordinates — the cell's footprint as the zoom photo
//! sees it, whatever the perspective — so that the box average of a
//! piecewise-constant cell albedo is exactly the bilinear interpolation of
//! the cell values used for `ρ̃`. The window holds only pixels on the
//! pixel's own face, with valid radiance, and with the pixel's sun status
//! (the sun-visibility test at each pixel's surface point): a shadow edge
//! is not low frequency, and averaging across it would print the shadow
//! into the albedo. Refused pixels keep `ρ̃` and are counted by reason
//! ([`ZoomReport`]): outside the targets, invalid or masked radiance,
//! straddling a face's outline, straddling a shadow edge (or a window
//! with too little of its own sun status), or `ρ̃` or `Ĩ` about zero.
//!
//! The smoothing costs one pass over the window per pixel: `O(N · w²)` for
//! `N` pixels and a window `w` pixels wide.
//!
//! Usage: `let zoom = zoom_albedo(&scene, &refl, &photo, &light,
//! &ZoomSettings::default())?;` then `rerender_zoom(&scene, &refl, &zoom,
//! &new_light, &RerenderSettings::default())`.

use nalgebra::Vector3;
use rayon::prelude::*;

use super::OutdoorError;
use super::cell_irradiance::sun_visible;
use super::estimate::Reflectance;
use super::photo::{Illumination, Photo};
use super::rerender::{RerenderSettings, albedos_at, rerender_with_pixel_albedos};
use crate::camera::image::RadianceImage;
use crate::render::{CameraRig, Scene};

/// Knobs of the high-resolution pseudo-albedo.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ZoomSettings {
    /// Side of the smoothing window, in grid cells (1: the cell's footprint).
    pub window_cells: f64,
    /// A pixel whose interpolated `ρ̃` is at most this in some channel (a
    /// cell recovered as black) keeps `ρ̃`: `Ẽ = Ĩ / ρ̃` is undefined.
    pub min_albedo: f64,
    /// A window whose pixels of the pixel's own sun status are fewer than
    /// this fraction of its pixels on the face is refused as a shadow edge.
    pub min_same_status: f64,
    /// The photo's time and the illumination's must agree within this, seconds.
    pub time_tolerance_s: f64,
}

impl Default for ZoomSettings {
    fn default() -> Self {
        ZoomSettings {
            window_cells: 1.0,
            min_albedo: 1e-3,
            min_same_status: 0.25,
            time_tolerance_s: 120.0,
        }
    }
}

impl ZoomSettings {
    /// The settings, or the first knob out of range.
    pub fn check(&self) -> Result<(), OutdoorError> {
        let bad = |field, value, expected| Err(OutdoorError::BadZoomSetting { field, value, expected });
        if !(self.window_cells.is_finite() && self.window_cells > 0.0) {
            return bad("window_cells", self.window_cells, "a finite number of cells > 0");
        }
        if !(self.min_albedo.is_finite() && self.min_albedo >= 0.0) {
            return bad("min_albedo", self.min_albedo, "a finite albedo ≥ 0");
        }
        if !(0.0..=1.0).contains(&self.min_same_status) {
            return bad("min_same_status", self.min_same_status, "a fraction in [0, 1]");
        }
        if !(self.time_tolerance_s.is_finite() && self.time_tolerance_s >= 0.0) {
            return bad(
                "time_tolerance_s",
                self.time_tolerance_s,
                "a finite number of seconds ≥ 0",
            );
        }
        Ok(())
    }
}

/// What became of one pixel of the zoom photo.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PixelFate {
    /// Its high-resolution pseudo-albedos come from eq. (5.16).
    Used,
    /// It sees no target surface (sky, environment, a target's back).
    NonTarget,
    /// Its radiance is masked (clipped in the merge) or not finite and ≥ 0.
    InvalidRadiance,
    /// Its footprint straddles the outline of its face.
    FaceEdge,
    /// Its footprint straddles a sun-shadow edge, or its window holds too
    /// little of its own sun status: it keeps `ρ̃`.
    ShadowEdge,
    /// `ρ̃` or `Ĩ` is about zero: it keeps `ρ̃`.
    Dark,
}

/// Where a pixel's centre ray meets a target.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ZoomHit {
    /// The triangle.
    pub triangle: usize,
    /// Its face in the grid.
    pub face: usize,
    /// The grid cell at (or nearest to) the point.
    pub cell: usize,
    /// The surface point, world frame, metres.
    pub point: Vector3<f64>,
    /// Texture coordinates of the point on its face, metres.
    pub st: [f64; 2],
    /// Whether the sun is visible there at the photo's time.
    pub sunlit: bool,
}

/// How many pixels were used and refused, by reason.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ZoomReport {
    /// Pixels in the photo.
    pub pixels: usize,
    /// Pixels given an eq. (5.16) pseudo-albedo.
    pub used: usize,
    /// Pixels seeing no target.
    pub non_target: usize,
    /// Target pixels with masked or invalid radiance.
    pub invalid_radiance: usize,
    /// Target pixels on a face's outline.
    pub face_edge: usize,
    /// Target pixels at a sun-shadow edge (kept at `ρ̃`).
    pub shadow_edge: usize,
    /// Target pixels with `ρ̃` or `Ĩ` about zero.
    pub dark: usize,
    /// Used pixels whose window was cut to their own sun status.
    pub status_restricted: usize,
    /// Median side of the smoothing window, pixels (the cell's footprint).
    pub window_px: f64,
}

impl std::fmt::Display for ZoomReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} of {} pixels given eq. (5.16) pseudo-albedos (window ≈ {:.0} px, {} cut to their sun status); \
             refused: {} not on a target, {} invalid radiance, {} on a face outline, {} at a shadow edge, {} dark",
            self.used,
            self.pixels,
            self.window_px,
            self.status_restricted,
            self.non_target,
            self.invalid_radiance,
            self.face_edge,
            self.shadow_edge,
            self.dark
        )
    }
}

/// The high-resolution pseudo-albedos of one zoom photograph's view.
#[derive(Debug, Clone)]
pub struct ZoomAlbedo {
    /// The camera of the photo; the albedos are per pixel of its image.
    pub rig: CameraRig,
    /// Per pixel (row-major): the grid's `ρ̃^sun` interpolated there (zero off the targets).
    pub low_sun: Vec<[f64; 3]>,
    /// Per pixel: the grid's `ρ̃^se` interpolated there.
    pub low_se: Vec<[f64; 3]>,
    /// Per pixel: `ρ^sun` of eq. (5.16) where [`PixelFate::Used`], else `ρ̃^sun`.
    pub rho_sun: Vec<[f64; 3]>,
    /// Per pixel: `ρ^se` of eq. (5.16) where used, else `ρ̃^se`.
    pub rho_se: Vec<[f64; 3]>,
    /// Per pixel: the detail ratio `I / Ĩ` (1 where not used).
    pub detail: Vec<[f64; 3]>,
    /// Per pixel: what became of it.
    pub fate: Vec<PixelFate>,
    /// Per pixel: where its centre ray meets a target, if it does.
    pub hits: Vec<Option<ZoomHit>>,
    /// Counts.
    pub report: ZoomReport,
}

impl ZoomAlbedo {
    /// The pixels with an eq. (5.16) pseudo-albedo.
    pub fn valid(&self) -> Vec<bool> {
        self.fate.iter().map(|f| *f == PixelFate::Used).collect()
    }

    /// The pseudo-albedos a ray through pixel `(x, y)` that meets target
    /// `triangle` takes: the pixel's, if it was used and the triangle is
    /// on the pixel's face (else `None`: the grid's).
    pub fn at(&self, refl: &Reflectance, x: usize, y: usize, triangle: usize) -> Option<([f64; 3], [f64; 3])> {
        if x >= self.rig.width || y >= self.rig.height {
            return None;
        }
        let i = y * self.rig.width + x;
        let hit = self.hits[i]?;
        (self.fate[i] == PixelFate::Used && refl.grid.face_of(triangle) == Some(hit.face))
            .then(|| (self.rho_sun[i], self.rho_se[i]))
    }
}

/// The high-resolution pseudo-albedos (eq. 5.16) of the view of `photo`, a
/// zoom photograph taken under `light`, from the grid's recovered
/// pseudo-albedos `refl` (see the module doc).
///
/// Errors: a setting out of range; the photo's buffer or mask does not
/// match its camera's size;
/// `light` is not at the photo's time; no pixel of the photo sees a target
/// surface.
pub fn zoom_albedo(
    scene: &Scene,
    refl: &Reflectance,
    photo: &Photo,
    light: &Illumination,
    settings: &ZoomSettings,
) -> Result<ZoomAlbedo, OutdoorError> {
    settings.check()?;
    let rig = photo.rig;
    let (w, h) = (rig.width, rig.height);
    let n = w * h;
    let img = &photo.image;
    if img.width != w || img.height != h || img.data.len() != n * 3 {
        return Err(OutdoorError::ImageSize {
            photo: photo.label.clone(),
            width: w,
            height: h,
            values: img.data.len(),
        });
    }
    if let Some(m) = &photo.mask
        && m.len() != n
    {
        return Err(OutdoorError::MaskSize {
            photo: photo.label.clone(),
            expected: n,
            got: m.len(),
        });
    }
    if (light.time - photo.time).num_milliseconds().abs() as f64 / 1000.0 > settings.time_tolerance_s {
        return Err(OutdoorError::NoIllumination {
            photo: photo.label.clone(),
            time: photo.time,
        });
    }
    let grid = &refl.grid;
    let sun = light.sky.sun();
    let rays = rig.rays();
    // Where each pixel's centre meets a target, and its sun status.
    let hits: Vec<Option<ZoomHit>> = (0..n)
        .into_par_iter()
        .map(|i| {
            let ray = rays.ray((i % w) as f64 + 0.5, (i / w) as f64 + 0.5)?;
            let hit = scene.intersect(&ray, f64::INFINITY)?;
            let vn = grid.visible_normal(scene, hit.triangle)?;
            if vn.dot(&ray.direction) >= 0.0 {
                return None;
            }
            let cell = grid.nearest_cell(scene, hit.triangle, &hit.point)?;
            let face = grid.face_of(hit.triangle)?;
            Some(ZoomHit {
                triangle: hit.triangle,
                face,
                cell,
                point: hit.point,
                st: scene.triangles()[hit.triangle].texture_coordinates(&hit.point),
                sunlit: sun.as_ref().is_some_and(|s| sun_visible(scene, s, &hit.point, &vn)),
            })
        })
        .collect();
    let targets = hits.iter().filter(|h| h.is_some()).count();
    if targets == 0 {
        return Err(OutdoorError::NoTargetInView {
            photo: photo.label.clone(),
            pixels: n,
        });
    }
    let radiance = |i: usize| -> [f64; 3] { [0, 1, 2].map(|c| f64::from(img.data[i * 3 + c])) };
    let valid_radiance =
        |i: usize| photo.mask.as_ref().is_none_or(|m| m[i]) && radiance(i).iter().all(|v| v.is_finite() && *v >= 0.0);
    // First verdicts: off target, invalid, on a face outline, at a shadow edge.
    let neighbours = |i: usize| {
        let (x, y) = ((i % w) as i64, (i / w) as i64);
        (-1..=1i64)
            .flat_map(move |dy| (-1..=1i64).map(move |dx| (x + dx, y + dy)))
            .filter(move |&(a, b)| (a, b) != (x, y) && a >= 0 && b >= 0 && (a as usize) < w && (b as usize) < h)
            .map(move |(a, b)| b as usize * w + a as usize)
    };
    let mut fate: Vec<Option<PixelFate>> = (0..n)
        .map(|i| {
            let Some(hit) = hits[i] else {
                return Some(PixelFate::NonTarget);
            };
            if !valid_radiance(i) {
                return Some(PixelFate::InvalidRadiance);
            }
            let mut shadow_edge = false;
            for j in neighbours(i) {
                match hits[j] {
                    Some(o) if o.face == hit.face => shadow_edge |= o.sunlit != hit.sunlit,
                    _ => return Some(PixelFate::FaceEdge),
                }
            }
            shadow_edge.then_some(PixelFate::ShadowEdge)
        })
        .collect();
    let rho_sun_cells: Vec<[f64; 3]> = refl.cells.iter().map(|c| c.rho_sun).collect();
    let rho_se_cells: Vec<[f64; 3]> = refl.cells.iter().map(|c| c.rho_se).collect();
    let half = 0.5 * settings.window_cells * grid.spacing_m;
    // Pixels that may enter a window: on a target, valid, off edges.
    let smoothable: Vec<bool> = fate.iter().map(Option::is_none).collect();
    // What the window sums read, packed (half the memory of the hits).
    #[derive(Clone, Copy)]
    struct Sample {
        /// The face, or `usize::MAX` for a pixel that enters no window.
        face: usize,
        sunlit: bool,
        st: [f64; 2],
        rgb: [f32; 3],
    }
    let samples: Vec<Sample> = (0..n)
        .map(|i| match hits[i].filter(|_| smoothable[i]) {
            Some(o) => Sample {
                face: o.face,
                sunlit: o.sunlit,
                st: o.st,
                rgb: [img.data[i * 3], img.data[i * 3 + 1], img.data[i * 3 + 2]],
            },
            None => Sample {
                face: usize::MAX,
                sunlit: false,
                st: [0.0; 2],
                rgb: [0.0; 3],
            },
        })
        .collect();
    struct PixelResult {
        low: ([f64; 3], [f64; 3]),
        smoothed: Option<([f64; 3], bool, f64)>,
        refused_shadow: bool,
    }
    let results: Vec<Option<PixelResult>> = (0..n)
        .into_par_iter()
        .map(|i| {
            let hit = hits[i]?;
            let low = albedos_at(
                scene,
                refl,
                &rho_sun_cells,
                &rho_se_cells,
                hit.cell,
                hit.triangle,
                &hit.point,
                true,
            );
            if !smoothable[i] {
                return Some(PixelResult {
                    low,
                    smoothed: None,
                    refused_shadow: false,
                });
            }
            // The window's corners in the image: its bounding box.
            let [sa, ta] = scene.triangles()[hit.triangle].texture_axes;
            let (mut x0, mut x1, mut y0, mut y1) = (0usize, w, 0usize, h);
            let corners: Option<Vec<(f64, f64)>> = [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)]
                .iter()
                .map(|(a, b)| rig.project(&(hit.point + sa * (a * half) + ta * (b * half))))
                .collect();
            if let Some(c) = corners {
                let lo = |f: fn(&(f64, f64)) -> f64, m: usize| {
                    (c.iter().map(f).fold(f64::INFINITY, f64::min).floor().max(0.0) as usize).min(m)
                };
                let hi = |f: fn(&(f64, f64)) -> f64, m: usize| {
                    (c.iter().map(f).fold(f64::NEG_INFINITY, f64::max).ceil().max(0.0) as usize).min(m)
                };
                x0 = lo(|p| p.0, w);
                x1 = hi(|p| p.0, w);
                y0 = lo(|p| p.1, h);
                y1 = hi(|p| p.1, h);
            }
            let side = (x1.saturating_sub(x0)).max(y1.saturating_sub(y0)) as f64;
            let (mut sum, mut same, mut all) = ([0.0; 3], 0usize, 0usize);
            for y in y0..y1 {
                for o in &samples[y * w + x0..y * w + x1] {
                    if o.face != hit.face || (o.st[0] - hit.st[0]).abs() > half || (o.st[1] - hit.st[1]).abs() > half {
                        continue;
                    }
                    all += 1;
                    if o.sunlit == hit.sunlit {
                        same += 1;
                        for c in 0..3 {
                            sum[c] += f64::from(o.rgb[c]);
                        }
                    }
                }
            }
            if same == 0 || (same as f64) < settings.min_same_status * all as f64 {
                return Some(PixelResult {
                    low,
                    smoothed: None,
                    refused_shadow: true,
                });
            }
            Some(PixelResult {
                low,
                smoothed: Some((sum.map(|s| s / same as f64), same < all, side)),
                refused_shadow: false,
            })
        })
        .collect();
    let mut out = ZoomAlbedo {
        rig,
        low_sun: vec![[0.0; 3]; n],
        low_se: vec![[0.0; 3]; n],
        rho_sun: vec![[0.0; 3]; n],
        rho_se: vec![[0.0; 3]; n],
        detail: vec![[1.0; 3]; n],
        fate: Vec::with_capacity(n),
        hits,
        report: ZoomReport {
            pixels: n,
            ..ZoomReport::default()
        },
    };
    let mut sides = Vec::new();
    for (i, r) in results.into_iter().enumerate() {
        let Some(r) = r else {
            out.fate.push(fate[i].unwrap_or(PixelFate::NonTarget));
            continue;
        };
        let (ls, le) = r.low;
        out.low_sun[i] = ls;
        out.low_se[i] = le;
        out.rho_sun[i] = ls;
        out.rho_se[i] = le;
        if r.refused_shadow {
            fate[i] = Some(PixelFate::ShadowEdge);
        }
        if let (None, Some((smooth, restricted, side))) = (fate[i], r.smoothed) {
            let dark = ls
                .iter()
                .chain(le.iter())
                .any(|v| v.is_nan() || *v <= settings.min_albedo)
                || smooth.iter().any(|v| !(*v > 0.0 && v.is_finite()));
            if dark {
                fate[i] = Some(PixelFate::Dark);
            } else {
                let px = radiance(i);
                // Eq. (5.16): ρ = I / Ẽ with Ẽ = Ĩ / ρ̃, i.e. ρ̃ · I / Ĩ.
                let d = [0, 1, 2].map(|c| px[c] / smooth[c]);
                out.detail[i] = d;
                out.rho_sun[i] = [0, 1, 2].map(|c| ls[c] * d[c]);
                out.rho_se[i] = [0, 1, 2].map(|c| le[c] * d[c]);
                out.report.status_restricted += usize::from(restricted);
                sides.push(side);
                fate[i] = Some(PixelFate::Used);
            }
        }
        out.fate.push(fate[i].unwrap_or(PixelFate::Dark));
    }
    for f in &out.fate {
        let r = &mut out.report;
        match f {
            PixelFate::Used => r.used += 1,
            PixelFate::NonTarget => r.non_target += 1,
            PixelFate::InvalidRadiance => r.invalid_radiance += 1,
            PixelFate::FaceEdge => r.face_edge += 1,
            PixelFate::ShadowEdge => r.shadow_edge += 1,
            PixelFate::Dark => r.dark += 1,
        }
    }
    sides.sort_by(f64::total_cmp);
    out.report.window_px = sides.get(sides.len() / 2).copied().unwrap_or(0.0);
    Ok(out)
}

/// The zoom photo's view re-rendered under `light` (any time and sky) at
/// pixel resolution: [`super::rerender()`] with the pixels' eq. (5.16)
/// pseudo-albedos in place of the grid's bilinear ones where `zoom` has
/// them (§5.6.4, the thesis's Fig. 5.12c).
pub fn rerender_zoom(
    scene: &Scene,
    refl: &Reflectance,
    zoom: &ZoomAlbedo,
    light: &Illumination,
    settings: &RerenderSettings,
) -> RadianceImage {
    let f = |x: usize, y: usize, t: usize| zoom.at(refl, x, y, t);
    rerender_with_pixel_albedos(scene, refl, &zoom.rig, light, settings, Some(&f)).0
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::outdoor::estimate::{CellEstimate, CellStatus};
    use crate::outdoor::grid::Grid;
    use crate::outdoor::observation::SamplingReport;
    use crate::pose::{HeadPose, Mount, Pinhole};
    use crate::render::{Material, Triangle};
    use crate::sky::{Atmosphere, Daylight};
    use chrono::{TimeZone, Utc};

    /// An 8 m wall in the plane y = 0 facing the camera at y = −10, under a
    /// 3 m overhang at its top (z = 8; not a target): with the sun at 45°
    /// straight ahead, the top 3 m of the wall are in shadow.
    fn wall_under_overhang() -> Scene {
        let v = |x: f64, y: f64, z: f64| Vector3::new(x, y, z);
        let tris = vec![
            Triangle::new([v(-4.0, 0.0, 0.0), v(4.0, 0.0, 0.0), v(4.0, 0.0, 8.0)], 0, 0).unwrap(),
            Triangle::new([v(-4.0, 0.0, 0.0), v(4.0, 0.0, 8.0), v(-4.0, 0.0, 8.0)], 0, 0).unwrap(),
            Triangle::new([v(-6.0, -3.0, 8.0), v(6.0, -3.0, 8.0), v(6.0, 0.5, 8.0)], 0, 1).unwrap(),
            Triangle::new([v(-6.0, -3.0, 8.0), v(6.0, 0.5, 8.0), v(-6.0, 0.5, 8.0)], 0, 1).unwrap(),
        ];
        Scene::new(
            tris,
            vec![Material::diffuse("m", [0.5; 3])],
            vec!["wall".into(), "overhang".into()],
        )
        .unwrap()
    }

    fn rig() -> CameraRig {
        CameraRig {
            pinhole: Pinhole {
                focal_px: 40.0,
                principal_px: (32.0, 24.0),
                k1: 0.0,
                k2: 0.0,
                projection: crate::pose::Projection::Pinhole,
            },
            mount: Mount::default(),
            head: HeadPose {
                pan_rad: 0.0,
                tilt_rad: 0.2,
            },
            position: Vector3::new(0.0, -10.0, 4.0),
            width: 64,
            height: 48,
        }
    }

    fn uniform(scene: &Scene, rho: f64) -> Reflectance {
        let grid = Grid::new(scene, &[0], 2.0, &[Vector3::new(0.0, -10.0, 4.0)]).unwrap();
        let cells = grid
            .cells
            .iter()
            .map(|_| CellEstimate {
                rho_sun: [rho; 3],
                rho_se: [rho; 3],
                sigma_sun: [0.0; 3],
                sigma_se: [0.0; 3],
                status: CellStatus::Solved,
                condition: 1.0,
                amplification: 1.0,
                observations: 2,
                rms_relative: 0.0,
            })
            .collect();
        Reflectance {
            face_ratio: vec![[1.0; 3]; grid.faces.len()],
            grid,
            cells,
            photos: Vec::new(),
            sampling: SamplingReport::default(),
            diagnostics: Vec::new(),
        }
    }

    /// A uniform wall photographed half in shadow: the photo's radiance
    /// jumps fivefold at the shadow line, but the albedo does not. Windows
    /// restricted to their sun status give back ρ = 0.5 exactly (to 1e-9)
    /// on every used pixel; averaged across the edge they would print the
    /// shadow into the albedo (a factor 3 off for a shadowed pixel whose window
    /// is half sunlit). The edge pixels are counted.
    #[test]
    fn a_shadow_edge_is_not_printed_into_the_albedo() {
        let scene = wall_under_overhang();
        let refl = uniform(&scene, 0.5);
        let rig = rig();
        let sun_dir = Vector3::new(0.0, -1.0, 1.0).normalize();
        let day = Daylight::clear([sun_dir.x, sun_dir.y, sun_dir.z], &Atmosphere::clear());
        let time = Utc.with_ymd_and_hms(2026, 8, 29, 20, 30, 0).unwrap();
        let light = Illumination { time, sky: &day };
        let sun = light.sky.sun().unwrap();
        let n = Vector3::new(0.0, -1.0, 0.0);
        let mut data = vec![0.1f32; 64 * 48 * 3];
        let mut lit_rows = (0, 0);
        for i in 0..64 * 48 {
            let ray = rig.ray((i % 64) as f64 + 0.5, (i / 64) as f64 + 0.5).unwrap();
            if let Some(hit) = scene.intersect(&ray, f64::INFINITY).filter(|h| h.triangle < 2) {
                let lit = sun_visible(&scene, &sun, &hit.point, &n);
                if lit {
                    lit_rows.0 += 1;
                } else {
                    lit_rows.1 += 1;
                }
                let e = if lit { 50.0 } else { 10.0 };
                (0..3).for_each(|c| data[i * 3 + c] = (0.5 * e) as f32);
            }
        }
        assert!(lit_rows.0 > 200 && lit_rows.1 > 200, "{lit_rows:?}");
        let photo = Photo {
            label: "overhang".into(),
            image: RadianceImage {
                width: 64,
                height: 48,
                data,
            },
            rig,
            time,
            mask: None,
        };
        let zoom = zoom_albedo(&scene, &refl, &photo, &light, &ZoomSettings::default()).unwrap();
        let r = &zoom.report;
        assert!(r.used > 500 && r.shadow_edge >= 16 && r.status_restricted > 50, "{r}");
        assert_eq!(
            r.used + r.non_target + r.face_edge + r.shadow_edge + r.dark + r.invalid_radiance,
            64 * 48
        );
        let bad = ZoomSettings {
            window_cells: f64::NAN,
            ..ZoomSettings::default()
        };
        let err = zoom_albedo(&scene, &refl, &photo, &light, &bad).unwrap_err();
        assert!(err.to_string().contains("window_cells = NaN"), "{err}");
        for i in 0..64 * 48 {
            if zoom.fate[i] == PixelFate::Used {
                for c in 0..3 {
                    assert!(
                        (zoom.rho_sun[i][c] - 0.5).abs() < 1e-9,
                        "pixel {i}: {:?}",
                        zoom.rho_sun[i]
                    );
                    assert!((zoom.rho_se[i][c] - 0.5).abs() < 1e-9);
                }
            }
        }
    }
}

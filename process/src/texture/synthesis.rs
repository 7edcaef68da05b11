//! Texture synthesis, thesis §3.4 (Fig. 3.3): each texel on a face is the
//! weighted average of what every photograph that sees it shows there.
//!
//! For texel centre `P` and each photograph:
//! 1. `P` projects into the image through the camera's lens model;
//! 2. the photograph sees `P`: the ray from its centre of projection meets
//!    nothing before `P` (within [`SAME_POINT_REL`] of the distance). This is
//!    §3.5's visibility, decided per texel by ray casting against the whole
//!    model instead of by clipped fragments (the same answer at texel
//!    resolution; [`crate::visibility`] gives the fragments themselves);
//! 3. the weight of [`super::weight`] (viewing angle, resolution, border);
//! 4. the radiance is the mean of bilinear samples spread over the texel
//!    (`n × n` with `n = ⌈√a⌉`, at most [`MAX_SUBSAMPLES`], `a` the texel's
//!    footprint in square pixels), so a texel that covers many pixels
//!    averages them rather than picking one. A sample is kept only when
//!    the four pixels it interpolates all show the texel's face (an item
//!    buffer per photograph, §3.5 step 4: the triangle each pixel centre's
//!    ray meets first), so an occluder's or the sky's pixels beside a
//!    silhouette do not bleed onto the face. A pixel *shows* the face only
//!    when its neighbours within [`SynthesisSettings::edge_margin_px`] do
//!    too: a pixel whose centre is on the face but next to its outline
//!    integrates the sky or the surface beyond over part of its area (and
//!    the lens's blur more), so it is a mixed pixel. Measured on the
//!    simulator's tower (all faces, 0.125 m texels, three exact photos):
//!    without the margin the photographs' spread along face borders was
//!    4.3× the interior's, at the tower's corners where one photograph
//!    sees the sky beside the face and another the next face (seam
//!    figure, [`super::seam`]).
//!
//! Texels on the face that no photograph sees are counted per patch and
//! then filled from their neighbours ([`super::fill`]); their status says so.
//!
//! Registration check: a misregistered photograph shows each texel's
//! neighbourhood instead of the texel, everywhere it is used, not only at
//! face borders (a pose 0.5° off moves a 640-pixel, 60° frame about 5
//! pixels). So each photograph's samples are compared with the other
//! photographs' weighted mean on the texels they share, with the image
//! shifted by whole pixels over ±[`OFFSET_SEARCH_PX`], and the shift that
//! agrees best is refined to a fraction of a pixel
//! ([`registration_offsets`], [`PhotoOffset`]); the verdict
//! ([`super::seam::judge`]) reads it.

use rayon::prelude::*;

use super::TextureError;
use super::fill::fill_patch;
use super::patch::Patch;
use super::photo::TexturePhoto;
use super::weight::{WeightSettings, view_weight};
use crate::render::{Ray, Scene};

/// A hit within this fraction of the distance before the texel still counts
/// as the texel (rounding, and coplanar surfaces).
pub const SAME_POINT_REL: f64 = 1e-4;

/// Most sub-samples per texel side.
pub const MAX_SUBSAMPLES: usize = 4;

/// The knobs of synthesis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SynthesisSettings {
    /// The photographs' weights.
    pub weight: WeightSettings,
    /// A pixel shows a face only when every pixel within this many pixels
    /// of it (a square) shows the same face (module doc: mixed pixels).
    pub edge_margin_px: usize,
}

impl Default for SynthesisSettings {
    fn default() -> Self {
        SynthesisSettings {
            weight: WeightSettings::default(),
            edge_margin_px: 1,
        }
    }
}

/// Where a texel's value came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TexelStatus {
    /// On the face, seen by at least one photograph.
    Seen,
    /// On the face, seen by none: filled from its neighbours.
    Filled,
    /// Off the face (padding around its triangles): filled from neighbours.
    Padding,
}

/// One patch's texels.
#[derive(Debug, Clone, PartialEq)]
pub struct PatchTexture {
    /// Radiance per texel, `j · cols + i`.
    pub rgb: Vec<[f32; 3]>,
    /// Sum of the photographs' weights per texel (0 where unseen).
    pub weight: Vec<f32>,
    /// Where each value came from.
    pub status: Vec<TexelStatus>,
    /// Per texel: photographs that contributed.
    pub photos: Vec<u16>,
    /// Per texel: the photographs' weighted relative spread, the weighted
    /// standard deviation of their mean-channel values over the blend's
    /// (0 with fewer than two photographs).
    pub spread: Vec<f32>,
}

/// What synthesis found.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SynthesisReport {
    /// Texels on faces.
    pub texels_on_faces: usize,
    /// Of those, seen by no photograph (filled from neighbours).
    pub unseen: usize,
    /// Per patch: texels on the face and of those unseen.
    pub per_patch: Vec<(usize, usize)>,
    /// Per photograph: texels it contributed to.
    pub used: Vec<usize>,
    /// Per photograph: texels in its frame and facing it but hidden by another surface.
    pub occluded: Vec<usize>,
    /// Per photograph: texels in its frame seen too obliquely to count.
    pub grazing: Vec<usize>,
    /// Per photograph: its registration against the others
    /// ([`registration_offsets`]; `None` where it shares too few texels).
    pub offsets: Vec<Option<PhotoOffset>>,
}

/// How far a photograph's image must move to agree best with the other
/// photographs on the texels they share (module doc: registration check).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhotoOffset {
    /// The shift, pixels along the image's columns and rows.
    pub shift_px: [f64; 2],
    /// Texels compared.
    pub texels: usize,
}

impl PhotoOffset {
    /// The shift's length, pixels.
    pub fn length_px(&self) -> f64 {
        self.shift_px[0].hypot(self.shift_px[1])
    }
}

impl SynthesisReport {
    /// Fraction of the on-face texels seen by a photograph (1 when there are none).
    pub fn coverage(&self) -> f64 {
        if self.texels_on_faces == 0 {
            1.0
        } else {
            1.0 - self.unseen as f64 / self.texels_on_faces as f64
        }
    }
}

/// The synthesized patches and the report.
#[derive(Debug, Clone, PartialEq)]
pub struct Synthesis {
    /// One texture per patch, in the patches' order.
    pub textures: Vec<PatchTexture>,
    /// What was found.
    pub report: SynthesisReport,
}

/// What one photograph gives one texel.
enum Look {
    /// Outside the frame or behind the camera.
    Out,
    /// Too oblique.
    Grazing,
    /// Another surface is in front.
    Occluded,
    /// A weighted radiance.
    Seen(f64, [f64; 3]),
}

/// The patch each pixel centre's ray of `photo` meets first (`u32::MAX`:
/// none, or a surface without a patch), kept only where every pixel within
/// `margin` pixels meets the same patch (`u32::MAX` elsewhere, and within
/// `margin` of the frame's edge).
fn item_buffer(scene: &Scene, photo: &TexturePhoto, patch_of: &[u32], margin: usize) -> Vec<u32> {
    let (w, h) = (photo.image.width, photo.image.height);
    let rays = photo.rig.rays();
    let items: Vec<u32> = (0..w * h)
        .into_par_iter()
        .map(|k| {
            rays.ray((k % w) as f64 + 0.5, (k / w) as f64 + 0.5)
                .and_then(|r| scene.intersect(&r, f64::INFINITY))
                .map_or(u32::MAX, |hit| patch_of[hit.triangle])
        })
        .collect();
    if margin == 0 {
        return items;
    }
    (0..w * h)
        .into_par_iter()
        .map(|k| {
            let (x, y) = (k % w, k / w);
            let id = items[k];
            if x < margin || y < margin || x + margin >= w || y + margin >= h {
                return u32::MAX;
            }
            let pure = (y - margin..=y + margin).all(|yy| (x - margin..=x + margin).all(|xx| items[yy * w + xx] == id));
            if pure { id } else { u32::MAX }
        })
        .collect()
}

struct Texel<'a> {
    patch: &'a Patch,
    id: u32,
    i: usize,
    j: usize,
}

fn look(
    scene: &Scene,
    texel: &Texel,
    photo: &TexturePhoto,
    items: &[u32],
    settings: &SynthesisSettings,
    mut positions: Option<&mut Vec<(f64, f64)>>,
) -> Look {
    let Texel { patch, id, i, j } = *texel;
    let p = patch.texel_centre(i, j);
    let rig = &photo.rig;
    let to_camera = rig.position - p;
    let dist = to_camera.norm();
    if dist <= 0.0 {
        return Look::Out;
    }
    let Some((u, v)) = rig.project(&p) else {
        return Look::Out;
    };
    let (w, h) = (photo.image.width as f64, photo.image.height as f64);
    if !(u >= 0.0 && v >= 0.0 && u <= w && v <= h) {
        return Look::Out;
    }
    let cosine = patch.normal.dot(&to_camera).abs() / dist;
    let d = patch.texel_m;
    let (Some(us), Some(ut)) = (
        rig.project(&(p + patch.axes[0] * d)),
        rig.project(&(p + patch.axes[1] * d)),
    ) else {
        return Look::Out;
    };
    let footprint = ((us.0 - u) * (ut.1 - v) - (us.1 - v) * (ut.0 - u)).abs();
    let weight = view_weight(
        cosine,
        footprint,
        (u, v),
        (photo.image.width, photo.image.height),
        &settings.weight,
    );
    if weight.angle == 0.0 {
        return Look::Grazing;
    }
    let total = weight.total();
    if total <= 0.0 {
        return Look::Out;
    }
    let ray = Ray {
        origin: rig.position,
        direction: -to_camera / dist,
    };
    let visible = scene
        .intersect(&ray, dist * (1.0 + SAME_POINT_REL))
        .is_some_and(|hit| hit.t >= dist * (1.0 - SAME_POINT_REL));
    if !visible {
        return Look::Occluded;
    }
    let n = (footprint.sqrt().ceil() as usize).clamp(1, MAX_SUBSAMPLES);
    let mut sum = [0.0; 3];
    let mut k = 0usize;
    for a in 0..n {
        for b in 0..n {
            let s = patch.origin[0] + (i as f64 + (a as f64 + 0.5) / n as f64) * d;
            let t = patch.origin[1] + (j as f64 + (b as f64 + 0.5) / n as f64) * d;
            if let Some((su, sv)) = rig.project(&patch.point_at(s, t))
                && let Some(rgb) = photo.sample_where(su, sv, &|px| items[px] == id)
            {
                (0..3).for_each(|c| sum[c] += rgb[c]);
                k += 1;
                if let Some(out) = positions.as_deref_mut() {
                    out.push((su, sv));
                }
            }
        }
    }
    if k == 0 {
        // Every sample's pixels touch another surface: a silhouette.
        return Look::Occluded;
    }
    Look::Seen(total, sum.map(|x| x / k as f64))
}

/// The texture of each of `patches` from `photos` (module doc).
pub fn synthesize(
    scene: &Scene,
    patches: &[Patch],
    photos: &[TexturePhoto],
    settings: &SynthesisSettings,
) -> Result<Synthesis, TextureError> {
    synthesize_with_progress(scene, patches, photos, settings, &|| {})
}

/// [`synthesize`], calling `step` after each photograph's item buffer and
/// after each patch (`photos.len() + patches.len()` steps in all).
pub fn synthesize_with_progress(
    scene: &Scene,
    patches: &[Patch],
    photos: &[TexturePhoto],
    settings: &SynthesisSettings,
    step: &dyn Fn(),
) -> Result<Synthesis, TextureError> {
    for p in photos {
        if (p.rig.width, p.rig.height) != (p.image.width, p.image.height)
            || p.image.data.len() != p.image.width * p.image.height * 3
        {
            return Err(TextureError::BadPhoto {
                photo: p.label.clone(),
                what: format!(
                    "image {} × {} ({} values) but camera {} × {}: expected the same size, width · height · 3 values",
                    p.image.width,
                    p.image.height,
                    p.image.data.len(),
                    p.rig.width,
                    p.rig.height
                ),
            });
        }
    }
    let np = photos.len();
    let mut report = SynthesisReport {
        used: vec![0; np],
        occluded: vec![0; np],
        grazing: vec![0; np],
        offsets: vec![None; np],
        ..Default::default()
    };
    let mut patch_of = vec![u32::MAX; scene.triangles().len()];
    for (k, p) in patches.iter().enumerate() {
        for &t in &p.triangles {
            patch_of[t] = k as u32;
        }
    }
    let items: Vec<Vec<u32>> = photos
        .iter()
        .map(|p| {
            let buffer = item_buffer(scene, p, &patch_of, settings.edge_margin_px);
            step();
            buffer
        })
        .collect();
    let mut textures = Vec::with_capacity(patches.len());
    for (pi, patch) in patches.iter().enumerate() {
        let texels: Vec<(usize, usize)> = (0..patch.rows)
            .flat_map(|j| (0..patch.cols).map(move |i| (i, j)))
            .collect();
        // Per texel: radiance sum, weight, weighted sum of squared means, and per photo what it gave.
        let results: Vec<([f64; 3], f64, f64, Vec<u8>)> = texels
            .par_iter()
            .map(|&(i, j)| {
                let mut codes = vec![0u8; np];
                if patch.texel_triangle[j * patch.cols + i].is_none() {
                    return ([0.0; 3], 0.0, 0.0, codes);
                }
                let mut sum = [0.0; 3];
                let mut wsum = 0.0;
                let mut sq = 0.0;
                for (k, photo) in photos.iter().enumerate() {
                    let texel = Texel {
                        patch,
                        id: pi as u32,
                        i,
                        j,
                    };
                    match look(scene, &texel, photo, &items[k], settings, None) {
                        Look::Out => {}
                        Look::Grazing => codes[k] = 2,
                        Look::Occluded => codes[k] = 3,
                        Look::Seen(w, rgb) => {
                            codes[k] = 1;
                            (0..3).for_each(|c| sum[c] += w * rgb[c]);
                            wsum += w;
                            let y = (rgb[0] + rgb[1] + rgb[2]) / 3.0;
                            sq += w * y * y;
                        }
                    }
                }
                (sum, wsum, sq, codes)
            })
            .collect();
        let mut tex = PatchTexture {
            rgb: vec![[0.0; 3]; texels.len()],
            weight: vec![0.0; texels.len()],
            status: vec![TexelStatus::Padding; texels.len()],
            photos: vec![0; texels.len()],
            spread: vec![0.0; texels.len()],
        };
        let (mut on_face, mut unseen) = (0usize, 0usize);
        for (idx, (sum, wsum, sq, codes)) in results.into_iter().enumerate() {
            tex.photos[idx] = codes.iter().filter(|&&c| c == 1).count().min(usize::from(u16::MAX)) as u16;
            for (k, c) in codes.iter().enumerate() {
                match c {
                    1 => report.used[k] += 1,
                    2 => report.grazing[k] += 1,
                    3 => report.occluded[k] += 1,
                    _ => {}
                }
            }
            if patch.texel_triangle[idx].is_none() {
                continue;
            }
            on_face += 1;
            if wsum > 0.0 {
                tex.rgb[idx] = sum.map(|x| (x / wsum) as f32);
                tex.weight[idx] = wsum as f32;
                tex.status[idx] = TexelStatus::Seen;
                let mean = (sum[0] + sum[1] + sum[2]) / 3.0 / wsum;
                if tex.photos[idx] >= 2 && mean > 0.0 {
                    tex.spread[idx] = ((sq / wsum - mean * mean).max(0.0).sqrt() / mean) as f32;
                }
            } else {
                unseen += 1;
                tex.status[idx] = TexelStatus::Filled;
            }
        }
        fill_patch(&mut tex, patch.cols, patch.rows);
        report.texels_on_faces += on_face;
        report.unseen += unseen;
        report.per_patch.push((on_face, unseen));
        textures.push(tex);
        step();
    }
    report.offsets = registration_offsets(scene, patches, photos, &items, settings);
    Ok(Synthesis { textures, report })
}

/// Half-width of the shift search, pixels (a pose 0.5° off moves a
/// 640-pixel, 60° frame by about 5 pixels).
pub const OFFSET_SEARCH_PX: i32 = 6;

/// Every this many texels along each axis are compared (a quarter of them).
pub const OFFSET_STRIDE: usize = 2;

/// Fewest shared texels for a photograph's offset.
pub const MIN_OFFSET_TEXELS: usize = 50;

/// Most texels the whole-pixel search compares (an even subset); the
/// sub-pixel refinement uses every shared texel.
pub const SEARCH_TEXELS: usize = 2000;

/// One texel's comparison: the others' mean level, the photo's sample
/// positions, the patch.
struct Comparison {
    reference: f64,
    positions: Vec<(f64, f64)>,
    id: u32,
}

/// The registration check (module doc): for each photograph, the image
/// shift within ±[`OFFSET_SEARCH_PX`] at which its samples of the texels
/// it shares with other photographs (every [`OFFSET_STRIDE`]-th texel, off
/// the faces' borders) best match the others' weighted mean: the shift
/// minimizing the mean squared relative difference, on whole pixels (over
/// at most [`SEARCH_TEXELS`] of them), then refined by a parabola through
/// the minimum and its neighbours along each axis (over all of them). Exact poses give a shift near 0 whatever the texture; a pose off
/// by an angle moves the whole image, and the check finds the move.
fn registration_offsets(
    scene: &Scene,
    patches: &[Patch],
    photos: &[TexturePhoto],
    items: &[Vec<u32>],
    settings: &SynthesisSettings,
) -> Vec<Option<PhotoOffset>> {
    let np = photos.len();
    if np < 2 {
        return vec![None; np];
    }
    let mut texels = Vec::new();
    for (pi, patch) in patches.iter().enumerate() {
        for j in (1..patch.rows.saturating_sub(1)).step_by(OFFSET_STRIDE) {
            for i in (1..patch.cols.saturating_sub(1)).step_by(OFFSET_STRIDE) {
                if patch.texel_triangle[j * patch.cols + i].is_some() && !super::seam::on_border(patch, i, j) {
                    texels.push((pi, i, j));
                }
            }
        }
    }
    // Per texel, each photo's look; then per photo its comparisons.
    let per_texel: Vec<Vec<(usize, Comparison)>> = texels
        .par_iter()
        .map(|&(pi, i, j)| {
            let texel = Texel {
                patch: &patches[pi],
                id: pi as u32,
                i,
                j,
            };
            let mut seen = Vec::new();
            for (k, photo) in photos.iter().enumerate() {
                let mut positions = Vec::new();
                if let Look::Seen(w, rgb) = look(scene, &texel, photo, &items[k], settings, Some(&mut positions)) {
                    seen.push((k, w, (rgb[0] + rgb[1] + rgb[2]) / 3.0, positions));
                }
            }
            let (wsum, ysum) = seen.iter().fold((0.0, 0.0), |(a, b), s| (a + s.1, b + s.1 * s.2));
            seen.into_iter()
                .filter_map(|(k, w, y, positions)| {
                    let (wo, yo) = (wsum - w, ysum - w * y);
                    (wo > 0.0 && yo > 0.0).then(|| {
                        (
                            k,
                            Comparison {
                                reference: yo / wo,
                                positions,
                                id: pi as u32,
                            },
                        )
                    })
                })
                .collect()
        })
        .collect();
    let mut by_photo: Vec<Vec<Comparison>> = (0..np).map(|_| Vec::new()).collect();
    for list in per_texel {
        for (k, c) in list {
            by_photo[k].push(c);
        }
    }
    by_photo
        .iter()
        .enumerate()
        .map(|(k, comps)| {
            if comps.len() < MIN_OFFSET_TEXELS {
                return None;
            }
            let photo = &photos[k];
            let id_items = &items[k];
            // The whole-pixel search on an even subset, the refinement on all.
            let step = comps.len().div_ceil(SEARCH_TEXELS).max(1);
            let subset: Vec<&Comparison> = comps.iter().step_by(step).collect();
            let all: Vec<&Comparison> = comps.iter().collect();
            let cost_on = |set: &[&Comparison], du: f64, dv: f64| -> f64 {
                let (sum, n) = set
                    .par_iter()
                    .filter_map(|c| {
                        let (mut y, mut m) = (0.0, 0usize);
                        for &(u, v) in &c.positions {
                            if let Some(rgb) = photo.sample_where(u + du, v + dv, &|px| id_items[px] == c.id) {
                                y += (rgb[0] + rgb[1] + rgb[2]) / 3.0;
                                m += 1;
                            }
                        }
                        (m > 0).then(|| (y / m as f64 / c.reference - 1.0).powi(2))
                    })
                    .fold(|| (0.0, 0usize), |(a, b), e| (a + e, b + 1))
                    .reduce(|| (0.0, 0usize), |(a, b), (c, d)| (a + c, b + d));
                if n == 0 { f64::INFINITY } else { sum / n as f64 }
            };
            let r = OFFSET_SEARCH_PX;
            let mut best = (f64::INFINITY, 0i32, 0i32);
            for dv in -r..=r {
                for du in -r..=r {
                    let c = cost_on(&subset, f64::from(du), f64::from(dv));
                    if c < best.0 {
                        best = (c, du, dv);
                    }
                }
            }
            let (_, bu, bv) = best;
            let cost = |du: f64, dv: f64| cost_on(&all, du, dv);
            let c0 = cost(f64::from(bu), f64::from(bv));
            if !c0.is_finite() {
                return None;
            }
            // Parabola through the minimum and its neighbours along one axis.
            let refine = |minus: f64, plus: f64| {
                let curvature = minus + plus - 2.0 * c0;
                if curvature > 0.0 && minus.is_finite() && plus.is_finite() {
                    (0.5 * (minus - plus) / curvature).clamp(-0.5, 0.5)
                } else {
                    0.0
                }
            };
            let (fu, fv) = (f64::from(bu), f64::from(bv));
            let su = fu + refine(cost(fu - 1.0, fv), cost(fu + 1.0, fv));
            let sv = fv + refine(cost(fu, fv - 1.0), cost(fu, fv + 1.0));
            Some(PhotoOffset {
                shift_px: [su, sv],
                texels: comps.len(),
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use nalgebra::Vector3;

    use super::*;
    use crate::camera::image::RadianceImage;
    use crate::render::{CameraRig, Material, Triangle};
    use crate::texture::patch::patches;

    fn wall_scene(with_occluder: bool) -> Scene {
        let v = |x: f64, y: f64, z: f64| Vector3::new(x, y, z);
        let mut tris = vec![
            Triangle::new([v(0.0, 0.0, 0.0), v(4.0, 0.0, 0.0), v(4.0, 0.0, 4.0)], 0, 0).unwrap(),
            Triangle::new([v(0.0, 0.0, 0.0), v(4.0, 0.0, 4.0), v(0.0, 0.0, 4.0)], 0, 0).unwrap(),
        ];
        if with_occluder {
            // A 1 m post 2 m in front of the wall's lower left.
            tris.push(Triangle::new([v(0.5, -2.0, 0.0), v(1.5, -2.0, 0.0), v(1.5, -2.0, 1.0)], 0, 1).unwrap());
            tris.push(Triangle::new([v(0.5, -2.0, 0.0), v(1.5, -2.0, 1.0), v(0.5, -2.0, 1.0)], 0, 1).unwrap());
        }
        Scene::new(
            tris,
            vec![Material::diffuse("m", [0.5; 3])],
            vec!["wall".into(), "post".into()],
        )
        .unwrap()
    }

    /// A photograph of a wall whose radiance is a known function of x: `L = 1 + x`.
    fn photo_of(scene: &Scene, label: &str, position: Vector3<f64>, look: Vector3<f64>) -> TexturePhoto {
        let rig = CameraRig::look_at(position, look, Vector3::z(), 70f64.to_radians(), 200, 160).unwrap();
        let mut data = vec![0f32; 200 * 160 * 3];
        for y in 0..160 {
            for x in 0..200 {
                let ray = rig.ray(x as f64 + 0.5, y as f64 + 0.5).unwrap();
                let value = match scene.intersect(&ray, 1e9) {
                    Some(hit) if scene.triangles()[hit.triangle].surface == 0 => 1.0 + hit.point.x,
                    Some(_) => 100.0,
                    None => 0.0,
                };
                data[(y * 200 + x) * 3..][..3].fill(value as f32);
            }
        }
        TexturePhoto {
            label: label.into(),
            image: RadianceImage {
                width: 200,
                height: 160,
                data,
            },
            rig,
        }
    }

    /// Two photographs of a wall with a linear radiance: every texel seen,
    /// and each inside the face within 0.5% of `1 + x` at its centre
    /// (bilinear sampling of a linear function is exact up to the
    /// perspective's curvature; the footprint average of a linear function
    /// is its centre value). Texels on the face's border lose the
    /// sub-samples whose pixels touch the sky, which moves their mean
    /// inward by at most half a texel: within 0.125 of `1 + x`.
    #[test]
    fn a_linear_wall_is_recovered() {
        let scene = wall_scene(false);
        let ps = patches(&scene, Some(&["wall".into()]), 0.25, 100_000).unwrap();
        let photos = [
            photo_of(&scene, "a", Vector3::new(2.0, -6.0, 2.0), Vector3::new(0.0, 1.0, 0.0)),
            photo_of(&scene, "b", Vector3::new(5.0, -5.0, 2.0), Vector3::new(-0.5, 1.0, 0.0)),
        ];
        let syn = synthesize(&scene, &ps, &photos, &SynthesisSettings::default()).unwrap();
        assert_eq!(syn.report.texels_on_faces, 256);
        assert_eq!(syn.report.unseen, 0);
        let p = &ps[0];
        let (mut inner, mut border) = (0f64, 0f64);
        for j in 0..p.rows {
            for i in 0..p.cols {
                let x = p.texel_centre(i, j).x;
                let got = f64::from(syn.textures[0].rgb[j * p.cols + i][0]);
                if crate::texture::seam::on_border(p, i, j) {
                    border = border.max((got - (1.0 + x)).abs());
                } else {
                    inner = inner.max((got - (1.0 + x)).abs() / (1.0 + x));
                }
            }
        }
        assert!(inner < 0.005, "worst relative error inside {inner}");
        assert!(border <= 0.125, "worst error on the border {border}");
    }

    /// A post in front of the wall: the one photograph that sees the wall
    /// behind the post does not paint the post's radiance (100) on it; the
    /// texels it hides and no other photo sees are reported and filled.
    #[test]
    fn an_occluder_is_not_painted_on_the_wall() {
        let scene = wall_scene(true);
        let ps = patches(&scene, Some(&["wall".into()]), 0.25, 100_000).unwrap();
        let photos = [photo_of(
            &scene,
            "front",
            Vector3::new(1.0, -6.0, 0.5),
            Vector3::new(0.2, 1.0, 0.3),
        )];
        let syn = synthesize(&scene, &ps, &photos, &SynthesisSettings::default()).unwrap();
        let r = &syn.report;
        assert!(r.occluded[0] > 10, "{r:?}");
        assert!(r.unseen >= r.occluded[0], "{r:?}");
        let max = syn.textures[0].rgb.iter().map(|c| c[0]).fold(0f32, f32::max);
        assert!(max < 6.0, "the post's radiance leaked onto the wall: {max}");
        // Filled texels keep their status.
        let filled = syn.textures[0]
            .status
            .iter()
            .filter(|s| **s == TexelStatus::Filled)
            .count();
        assert_eq!(filled, r.unseen);
    }
}

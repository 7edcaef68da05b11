//! Diffuse albedo maps (thesis §4.6): each surface point's ρd from every
//! view that sees it, once the recovered specular light is removed and the
//! light it receives (direct from the lamps, and indirect, gathered
//! through the recovered scene) is divided out:
//!
//! ρd(x) = π (L(x) − S(x) − ΔS(x)) / (E_direct(x) + E_indirect(x)),
//!
//! where S is the recovered lobe's reflection of the lamps and ΔS its
//! reflection of the indirect light, traced along directions sampled from
//! the lobe into the recovered scene (thesis §4.6; `specular_rays`), or
//! with `specular_rays` 0 approximated as `ρs a(ωo) E_indirect / π` with
//! `a` the lobe's directional albedo toward the camera (as the solver's
//! [`super::radiosity`] takes it beyond one glossy bounce). Without ΔS a
//! glossy surface lit mostly by the room's walls keeps `ρs a / ρd` of
//! extra light in its map: measured +12 % on the room's wood floor (ρs
//! 0.05 on ρd 0.42). Dividing by the
//! full irradiance removes colour bleeding (the indirect light's colour);
//! removing S and down-weighting samples whose radiance is mostly specular
//! removes highlights. Views are combined per texel with the weight
//!
//! w = cos θ_view · (diffuse share)² · border weight,
//!
//! and where a texel has three or more samples the brightest is dropped
//! (§4.6: "the brightest sample ... is likely to contain a highlight").
//! The views' disagreement on each texel then measures the photographs'
//! noise, the gather's own spread the indirect irradiance's, and each
//! surface's texels are shrunk toward its mean by the share of their
//! variation that is texture (`shrink_noise`).
//!
//! A surface whose first map shows texture ([`TEXTURED_SHARE`]) gets two
//! things more. Its indirect irradiance is gathered again on finer cells
//! through a scene in which it wears that map (`IndirectField::gather_on`):
//! a texture sends light back to itself by way of the room, so that a
//! light patch receives more than a dark one beside it, which a uniform
//! wall cannot show. And its texels are shrunk toward their local mean,
//! not the surface's, which would pull a pattern's levels together.
//!
//! The map is a grid of square texels per triangle over its planar texture
//! coordinates (metres); a texel no view saw takes the mean of its seen
//! neighbours within [`FILL_RADIUS`] texels, else its surface's recovered ρd.

use nalgebra::Vector3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use super::error::IgiError;
use super::input::IgiInput;
use super::lamp_paths::{PathVertex, path_radiance, scattered_radiance};
use super::recover::IgiResult;
use super::relit_scene::{point_lights, recovered_scene, seen_sides};
use super::specular_albedo::SpecularAlbedo;
use super::stratified::Strata;
use crate::brdf::ShadingFrame;
use crate::render::{Material, PointLight, Ray, Scene, TexelImage, Texture, Triangle};

/// Texels searched around an unseen texel for seen ones.
pub const FILL_RADIUS: i64 = 3;

/// The albedo map's knobs (speed against error).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AlbedoMapOptions {
    /// Texel side, metres. Default 1 cm: on the simulated room a map of
    /// the true textures on 2 cm texels (each texel its box mean) leaves
    /// the posters' 5 cm stripes 4.4 % off per 4×4 block of the relit
    /// image, on 1 cm texels 1.5 % (BENCHMARKS.md).
    pub texel_m: f64,
    /// Side of the cells over which the indirect irradiance is gathered, metres.
    pub irradiance_cell_m: f64,
    /// Cosine-distributed rays per irradiance cell.
    pub irradiance_rays: u32,
    /// Scattering events per gathered path. Default 12 (see
    /// [`super::relight::RelightSettings::max_bounces`]): a cut after 4
    /// leaves the indirect light about 13 % short in a light-walled room,
    /// and the albedo maps that much high.
    pub max_bounces: u32,
    /// Pixels from the image border over which the border weight rises from 0 to 1.
    pub border_px: f64,
    /// Seed of the gathering.
    pub seed: u64,
    /// Divide by the indirect irradiance too (false: the lamps' light only,
    /// which leaves the colour bleeding in; a baseline for comparison).
    pub indirect: bool,
    /// Remove the recovered specular reflection, weight by diffuse share
    /// and drop the brightest sample (false: leaves highlights in; a baseline).
    pub remove_specular: bool,
    /// Rays sampled from the recovered lobe per glossy sample to estimate
    /// ΔS, the lobe's reflection of the room's light (module doc); 0: the
    /// uniform-light approximation `ρs a(ωo) E_indirect / π`.
    pub specular_rays: u32,
    /// Shrink each texel toward its surface's mean by the share of the
    /// texels' variation that is texture rather than the photographs'
    /// noise ([`shrink_noise`]; false: the raw per-texel means).
    pub shrink_noise: bool,
    /// Cell side, metres, of a second gather of the indirect irradiance on
    /// planar textured faces, with the first map as their texture
    /// (`IndirectField::gather_on`; default 12.5 cm); 0: none.
    pub texture_light_cell_m: f64,
    /// Cosine-distributed rays per node of that second gather (default
    /// 512). Its noise is the squares' noise: on the Mitsuba corridor's
    /// checker wall 6.25 cm cells of 128 rays put the dark squares' red
    /// +0.57, +1.72 and +0.73 % over map seeds 3–5 (the lobe unchanged);
    /// 12.5 cm cells of 512 rays, for the same rays in all, −0.25 to
    /// +0.08 %, and the light squares −0.47 to −0.76 % (BENCHMARKS.md,
    /// "Texel groups across a texture edge").
    pub texture_light_rays: u32,
}

impl Default for AlbedoMapOptions {
    fn default() -> Self {
        AlbedoMapOptions {
            texel_m: 0.01,
            irradiance_cell_m: 0.25,
            irradiance_rays: 128,
            max_bounces: 12,
            border_px: 8.0,
            seed: 3,
            indirect: true,
            remove_specular: true,
            specular_rays: 8,
            shrink_noise: true,
            texture_light_cell_m: 0.125,
            texture_light_rays: 512,
        }
    }
}

impl AlbedoMapOptions {
    fn validate(&self) -> Result<(), IgiError> {
        let err = |name, value: f64, expected| {
            Err(IgiError::Option {
                name,
                value: value.to_string(),
                expected,
            })
        };
        if !(self.texel_m > 0.0 && self.texel_m.is_finite()) {
            return err("texel_m", self.texel_m, "a finite size > 0 m");
        }
        if !(self.irradiance_cell_m > 0.0 && self.irradiance_cell_m.is_finite()) {
            return err("irradiance_cell_m", self.irradiance_cell_m, "a finite size > 0 m");
        }
        if self.irradiance_rays == 0 {
            return err("irradiance_rays", 0.0, "at least 1");
        }
        if self.texture_light_rays == 0 && self.texture_light_cell_m > 0.0 {
            return err("texture_light_rays", 0.0, "at least 1 while texture_light_cell_m > 0");
        }
        if !(self.texture_light_cell_m >= 0.0 && self.texture_light_cell_m.is_finite()) {
            return err(
                "texture_light_cell_m",
                self.texture_light_cell_m,
                "a finite size >= 0 m (0: off)",
            );
        }
        if !(self.border_px >= 0.0 && self.border_px.is_finite()) {
            return err("border_px", self.border_px, "a finite width >= 0 px");
        }
        Ok(())
    }
}

/// One triangle's texels.
#[derive(Debug, Clone, PartialEq)]
pub struct TriangleTexels {
    /// Texture coordinates of the grid's corner, metres.
    pub origin: [f64; 2],
    /// Texels along s and t.
    pub size: [usize; 2],
    /// Albedo per texel (row-major, t rows), only meaningful where `weight > 0`.
    pub albedo: Vec<[f32; 3]>,
    /// Sum of sample weights per texel (0: unseen).
    pub weight: Vec<f32>,
}

/// How a texel of the map got its value.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum TexelOrigin {
    /// Seen by at least one view (its samples' weighted mean).
    Seen,
    /// No view saw it: the mean of the seen texels in the nearest ring
    /// within [`FILL_RADIUS`] texels.
    Filled,
    /// No view saw it nor any texel within [`FILL_RADIUS`]: its surface's
    /// recovered ρd.
    SurfaceMean,
}

/// The albedo map of every triangle.
#[derive(Debug, Clone, PartialEq)]
pub struct AlbedoMap {
    /// Texel side, metres.
    pub texel_m: f64,
    /// Per triangle, in the input's order.
    pub triangles: Vec<TriangleTexels>,
    /// Per surface, the recovered ρd (for texels nobody saw).
    pub fallback: Vec<[f64; 3]>,
    /// Samples used, and samples dropped as the brightest of their texel.
    pub samples: (usize, usize),
}

/// One view's sample on a texel.
#[derive(Debug, Clone, Copy)]
struct Sample {
    texel: usize,
    albedo: [f64; 3],
    brightness: f64,
    weight: f64,
    /// Variance of `albedo` from the indirect irradiance's Monte Carlo
    /// noise (common to every view of the point).
    irradiance_noise: [f64; 3],
    /// The radiance less the specular estimate, and the lamps' irradiance,
    /// for working `albedo` out again under another indirect irradiance.
    diffuse: [f64; 3],
    e_direct: [f64; 3],
    /// The surface point, and whether it is on its triangle's seen side.
    point: Vector3<f64>,
    seen_side: bool,
}

impl Sample {
    /// ρd and its irradiance noise under the indirect irradiance `e_ind`
    /// (variance `e_ind_var`); false (unchanged) where there is no light.
    fn relit(&mut self, e_ind: [f64; 3], e_ind_var: [f64; 3]) -> bool {
        let e: [f64; 3] = [0, 1, 2].map(|c| self.e_direct[c] + e_ind[c]);
        if e.iter().any(|v| *v <= 1e-12) {
            return false;
        }
        self.albedo = [0, 1, 2].map(|c| std::f64::consts::PI * self.diffuse[c] / e[c]);
        self.irradiance_noise = [0, 1, 2].map(|c| self.albedo[c] * self.albedo[c] * e_ind_var[c] / (e[c] * e[c]));
        true
    }
}

/// One seen texel's statistics, for [`shrink_noise`].
#[derive(Debug, Clone, Copy)]
struct TexelSpread {
    triangle: usize,
    texel: usize,
    /// Σw and Σw² of its samples.
    w: f64,
    w2: f64,
    /// The weighted scatter Σw(x − m)² per channel.
    scatter: [f64; 3],
    /// The weighted mean of its samples' irradiance noise variance.
    irradiance_noise: [f64; 3],
}

impl TriangleTexels {
    fn new(tri: &Triangle, texel_m: f64) -> TriangleTexels {
        let st: Vec<[f64; 2]> = tri.vertices.iter().map(|v| tri.texture_coordinates(v)).collect();
        let lo = [0, 1].map(|k| st.iter().map(|p| p[k]).fold(f64::INFINITY, f64::min));
        let hi = [0, 1].map(|k| st.iter().map(|p| p[k]).fold(f64::NEG_INFINITY, f64::max));
        let size = [0, 1].map(|k| (((hi[k] - lo[k]) / texel_m).ceil() as usize).clamp(1, 4096));
        TriangleTexels {
            origin: lo,
            size,
            albedo: vec![[0.0; 3]; size[0] * size[1]],
            weight: vec![0.0; size[0] * size[1]],
        }
    }

    fn texel(&self, st: [f64; 2], texel_m: f64) -> (i64, i64) {
        (
            ((st[0] - self.origin[0]) / texel_m).floor() as i64,
            ((st[1] - self.origin[1]) / texel_m).floor() as i64,
        )
    }

    fn index(&self, i: i64, j: i64) -> Option<usize> {
        let (i, j) = (i.clamp(0, self.size[0] as i64 - 1), j.clamp(0, self.size[1] as i64 - 1));
        Some(j as usize * self.size[0] + i as usize)
    }
}

impl AlbedoMap {
    /// The albedo at point `p` of triangle `triangle` (module doc: unseen
    /// texels are filled from neighbours, then from the surface's ρd).
    pub fn albedo_at(&self, triangle: usize, surface: usize, tri: &Triangle, p: &Vector3<f64>) -> [f64; 3] {
        self.albedo_and_origin_at(triangle, surface, tri, p).0
    }

    /// [`AlbedoMap::albedo_at`], and how that value was obtained: seen by
    /// a view, filled from seen texels within [`FILL_RADIUS`], or the
    /// surface's recovered ρd.
    pub fn albedo_and_origin_at(
        &self,
        triangle: usize,
        surface: usize,
        tri: &Triangle,
        p: &Vector3<f64>,
    ) -> ([f64; 3], TexelOrigin) {
        let fallback = (
            self.fallback.get(surface).copied().unwrap_or([0.5; 3]),
            TexelOrigin::SurfaceMean,
        );
        let Some(t) = self.triangles.get(triangle) else {
            return fallback;
        };
        let (i, j) = t.texel(tri.texture_coordinates(p), self.texel_m);
        for r in 0..=FILL_RADIUS {
            let (mut sum, mut w) = ([0.0; 3], 0.0);
            for dj in -r..=r {
                for di in -r..=r {
                    if di.abs().max(dj.abs()) != r {
                        continue;
                    }
                    let (a, b) = (i + di, j + dj);
                    if a < 0 || b < 0 || a >= t.size[0] as i64 || b >= t.size[1] as i64 {
                        continue;
                    }
                    if let Some(k) = t.index(a, b)
                        && t.weight[k] > 0.0
                    {
                        for c in 0..3 {
                            sum[c] += f64::from(t.albedo[k][c]);
                        }
                        w += 1.0;
                    }
                }
            }
            if w > 0.0 {
                let origin = if r == 0 { TexelOrigin::Seen } else { TexelOrigin::Filled };
                return (sum.map(|v| v / w), origin);
            }
        }
        fallback
    }

    /// Builds the map from `input`'s views and `result`'s materials
    /// (module doc).
    pub fn build(input: &IgiInput, result: &IgiResult, options: &AlbedoMapOptions) -> Result<AlbedoMap, IgiError> {
        options.validate()?;
        input.validate()?;
        let scene = recovered_scene(input, result)?;
        let points = point_lights(&input.lights);
        let cameras: Vec<Vector3<f64>> = input.views.iter().map(|v| v.camera.position).collect();
        let sides = seen_sides(&scene, &cameras);
        let indirect = options
            .indirect
            .then(|| IndirectField::gather(&scene, &points, &sides, options));
        let fallback: Vec<[f64; 3]> = (0..input.surfaces.len())
            .map(|s| scene.materials()[s].albedo.mean_albedo())
            .collect();
        let lobe_albedo: Vec<Option<SpecularAlbedo>> = scene
            .materials()
            .iter()
            .map(|m| m.specular.as_ref().map(SpecularAlbedo::new))
            .collect();
        let mut triangles: Vec<TriangleTexels> = scene
            .triangles()
            .iter()
            .map(|t| TriangleTexels::new(t, options.texel_m))
            .collect();
        // Samples per triangle.
        let mut per_triangle: Vec<Vec<Sample>> = vec![Vec::new(); triangles.len()];
        let grids = &triangles;
        for (view_index, view) in input.views.iter().enumerate() {
            let cam = &view.camera;
            let (w, h) = (cam.width, cam.height);
            let rows: Vec<Vec<(usize, Sample)>> = (0..h)
                .into_par_iter()
                .map(|y| {
                    let mut rng = ChaCha8Rng::seed_from_u64(options.seed ^ SPECULAR_SEED);
                    rng.set_stream(((view_index as u64) << 32) | y as u64);
                    let mut out = Vec::new();
                    for x in 0..w {
                        if view.mask.as_ref().is_some_and(|m| !m[y * w + x]) {
                            continue;
                        }
                        let d = cam.direction(x as f64 + 0.5, y as f64 + 0.5);
                        let ray = Ray {
                            origin: cam.position,
                            direction: d,
                        };
                        let Some(hit) = scene.intersect(&ray, f64::INFINITY) else {
                            continue;
                        };
                        if input
                            .lights
                            .iter()
                            .any(|l| l.radius > 0.0 && sphere_hit(&l.position, l.radius, &ray, hit.t))
                        {
                            continue;
                        }
                        let tri = &scene.triangles()[hit.triangle];
                        let wo = -d;
                        let normal = if tri.normal.dot(&wo) >= 0.0 {
                            tri.normal
                        } else {
                            -tri.normal
                        };
                        let cos_view = normal.dot(&wo);
                        if cos_view <= 0.05 {
                            continue;
                        }
                        let radiance = [0, 1, 2].map(|c| f64::from(view.image.radiance(x, y, c)));
                        let (e_direct, mut specular) = direct(&scene, &points, tri, &hit.point, normal, &wo);
                        if !options.remove_specular {
                            specular = [0.0; 3];
                        }
                        let (e_ind, e_ind_var) = match &indirect {
                            Some(f) => f.at(hit.triangle, tri, &hit.point, sides[hit.triangle].dot(&normal) > 0.0),
                            None => ([0.0; 3], [0.0; 3]),
                        };
                        let e: [f64; 3] = [0, 1, 2].map(|c| e_direct[c] + e_ind[c]);
                        if e.iter().any(|v| *v <= 1e-12) {
                            continue;
                        }
                        // ΔS: the lobe's reflection of the indirect light (module doc).
                        if options.remove_specular && options.indirect && options.specular_rays > 0 {
                            let ds = lobe_indirect(&scene, &points, tri, &hit.point, &wo, options, &mut rng);
                            for c in 0..3 {
                                specular[c] += ds[c];
                            }
                        } else if options.remove_specular
                            && let (Some(lobe), Some(Some(table))) = (
                                scene.materials()[tri.material as usize].specular,
                                lobe_albedo.get(tri.material as usize),
                            )
                            && let Ok(frame) = ShadingFrame::new(normal, tri.texture_axes[0])
                        {
                            let a = table.at(&frame.to_local(&wo));
                            for c in 0..3 {
                                specular[c] += lobe.rho_s[c] * a * e_ind[c] * std::f64::consts::FRAC_1_PI;
                            }
                        }
                        let diffuse: [f64; 3] = [0, 1, 2].map(|c| (radiance[c] - specular[c]).max(0.0));
                        let (lm, dm) = (radiance.iter().sum::<f64>(), diffuse.iter().sum::<f64>());
                        let share = if lm > 0.0 { (dm / lm).clamp(0.0, 1.0) } else { 1.0 };
                        let edge = (x as f64 + 0.5)
                            .min(w as f64 - x as f64 - 0.5)
                            .min(y as f64 + 0.5)
                            .min(h as f64 - y as f64 - 0.5);
                        let border = if options.border_px > 0.0 {
                            (edge / options.border_px).clamp(0.0, 1.0)
                        } else {
                            1.0
                        };
                        let weight = cos_view * share * share * border;
                        if weight <= 0.0 {
                            continue;
                        }
                        let grid = &grids[hit.triangle];
                        let (i, j) = grid.texel(tri.texture_coordinates(&hit.point), options.texel_m);
                        let Some(texel) = grid.index(i, j) else {
                            continue;
                        };
                        let mut sample = Sample {
                            texel,
                            albedo: [0.0; 3],
                            brightness: lm,
                            weight,
                            irradiance_noise: [0.0; 3],
                            diffuse,
                            e_direct,
                            point: hit.point,
                            seen_side: sides[hit.triangle].dot(&normal) > 0.0,
                        };
                        if sample.relit(e_ind, e_ind_var) {
                            out.push((hit.triangle, sample));
                        }
                    }
                    out
                })
                .collect();
            for (t, s) in rows.into_iter().flatten() {
                per_triangle[t].push(s);
            }
        }
        let material: Vec<usize> = scene.triangles().iter().map(|t| t.material as usize).collect();
        let (mut used, mut dropped, mut spread) = combine(&mut triangles, &mut per_triangle, options.remove_specular);
        let textured = textured_surfaces(&triangles, &spread, &material, input.surfaces.len());
        if let Some(first_field) = &indirect
            && options.texture_light_cell_m > 0.0
        {
            let textured: Vec<bool> = (0..textured.len()).map(|s| textured[s] && planar(&scene, s)).collect();
            if textured.iter().any(|t| *t) {
                let first = AlbedoMap {
                    texel_m: options.texel_m,
                    triangles: std::mem::take(&mut triangles),
                    fallback: fallback.clone(),
                    samples: (used, dropped),
                };
                let lit = textured_scene(&scene, &first, &textured, &input.surfaces);
                triangles = first.triangles;
                let lit = lit?;
                let select: Vec<bool> = material.iter().map(|m| textured[*m]).collect();
                let field = IndirectField::gather_on(&lit, &points, &sides, options, &select);
                for (t, samples) in per_triangle.iter_mut().enumerate() {
                    if !select[t] {
                        continue;
                    }
                    let tri = &scene.triangles()[t];
                    samples.retain_mut(|s| {
                        let (e, var) = field.at(t, tri, &s.point, s.seen_side);
                        s.relit(e, var) || {
                            // Keep the first gather's figure rather than lose the view.
                            let (e, var) = first_field.at(t, tri, &s.point, s.seen_side);
                            s.relit(e, var)
                        }
                    });
                }
                (used, dropped, spread) = combine(&mut triangles, &mut per_triangle, options.remove_specular);
            }
        }
        if options.shrink_noise {
            shrink_noise(&mut triangles, &spread, &material, &textured, input.surfaces.len());
        }
        Ok(AlbedoMap {
            texel_m: options.texel_m,
            triangles,
            fallback,
            samples: (used, dropped),
        })
    }
}

/// Each texel's weighted mean of its samples (sorted in place by texel,
/// brightest first; with `drop_brightest`, the brightest of three or more
/// dropped, §4.6), written over the grids (a texel without samples left
/// unseen), and the samples used and dropped and each seen texel's spread.
fn combine(
    triangles: &mut [TriangleTexels],
    per_triangle: &mut [Vec<Sample>],
    drop_brightest: bool,
) -> (usize, usize, Vec<TexelSpread>) {
    let mut used = 0usize;
    let mut dropped = 0usize;
    let mut spread: Vec<TexelSpread> = Vec::new();
    for (t, (grid, samples)) in triangles.iter_mut().zip(per_triangle.iter_mut()).enumerate() {
        grid.albedo.fill([0.0; 3]);
        grid.weight.fill(0.0);
        samples.sort_by(|a, b| a.texel.cmp(&b.texel).then(b.brightness.total_cmp(&a.brightness)));
        let mut k = 0;
        while k < samples.len() {
            let texel = samples[k].texel;
            let end = k + samples[k..].iter().take_while(|s| s.texel == texel).count();
            // Sorted brightest first: drop it when three or more remain.
            let start = if end - k >= 3 && drop_brightest {
                dropped += 1;
                k + 1
            } else {
                k
            };
            let (mut sum, mut w, mut w2, mut irr) = ([0.0; 3], 0.0, 0.0, [0.0; 3]);
            for s in &samples[start..end] {
                for c in 0..3 {
                    sum[c] += s.weight * s.albedo[c];
                    irr[c] += s.weight * s.irradiance_noise[c];
                }
                w += s.weight;
                w2 += s.weight * s.weight;
            }
            used += end - start;
            if w > 0.0 {
                let mean = sum.map(|v| v / w);
                let mut scatter = [0.0; 3];
                for s in &samples[start..end] {
                    for c in 0..3 {
                        scatter[c] += s.weight * (s.albedo[c] - mean[c]).powi(2);
                    }
                }
                grid.albedo[texel] = mean.map(|v| v as f32);
                grid.weight[texel] = w as f32;
                spread.push(TexelSpread {
                    triangle: t,
                    texel,
                    w,
                    w2,
                    scatter,
                    irradiance_noise: irr.map(|v| v / w),
                });
            }
            k = end;
        }
    }
    (used, dropped, spread)
}

/// Whether `ray` meets the sphere before distance `limit`.
pub(crate) fn sphere_hit(centre: &Vector3<f64>, radius: f64, ray: &Ray, limit: f64) -> bool {
    let oc = ray.origin - centre;
    let b = oc.dot(&ray.direction);
    let c = oc.norm_squared() - radius * radius;
    let disc = b * b - c;
    if disc < 0.0 {
        return false;
    }
    let t = -b - disc.sqrt();
    t > 0.0 && t < limit
}

/// Seed offset of the lobe-sampled ΔS rays (apart from the gather's).
const SPECULAR_SEED: u64 = 0x5bec_u64;

/// Seed offset of the second gather on textured surfaces.
const TEXTURED_SEED: u64 = 0x7e47_u64;

/// ΔS at `p` toward `wo`: the recovered lobe's reflection of the light
/// arriving from the room's surfaces (not the lamps, whose reflection is
/// [`direct`]'s), by `options.specular_rays` stratified directions sampled
/// from the lobe, each followed through the recovered scene
/// ([`scattered_radiance`]; thesis §4.6: "tracing a perturbed reflected
/// ray into the environment"). Zero for a surface without a lobe. The
/// uniform-light approximation `ρs a E_indirect / π` misses what the lobe
/// actually mirrors: on the blue plastic board (ρd red 0.08 under ρs 0.06)
/// it left the map's red 10 % high.
fn lobe_indirect(
    scene: &Scene,
    points: &[PointLight],
    tri: &Triangle,
    p: &Vector3<f64>,
    wo: &Vector3<f64>,
    options: &AlbedoMapOptions,
    rng: &mut ChaCha8Rng,
) -> [f64; 3] {
    if scene.materials()[tri.material as usize].specular.is_none() {
        return [0.0; 3];
    }
    let v = lobe_vertex(scene, tri, p, wo);
    scattered_radiance(
        scene,
        points,
        &v,
        (options.specular_rays, options.max_bounces, true),
        rng,
    )
}

/// The path vertex at `p` seen from `wo` with the recovered specular lobe
/// of `tri`'s material alone (no diffuse part: the albedo map divides the
/// rest out).
fn lobe_vertex(scene: &Scene, tri: &Triangle, p: &Vector3<f64>, wo: &Vector3<f64>) -> PathVertex {
    let lobe_only = Material {
        name: String::new(),
        albedo: Texture::Constant([0.0; 3]),
        specular: scene.materials()[tri.material as usize].specular,
        emission: [0.0; 3],
    };
    PathVertex::at(&lobe_only, tri, p, *wo)
}

/// The lamps' irradiance at `p` (shadow-tested) and the recovered lobe's
/// reflection of them toward `wo`.
fn direct(
    scene: &Scene,
    points: &[PointLight],
    tri: &Triangle,
    p: &Vector3<f64>,
    normal: Vector3<f64>,
    wo: &Vector3<f64>,
) -> ([f64; 3], [f64; 3]) {
    let PathVertex { bsdf, origin, .. } = lobe_vertex(scene, tri, p, wo);
    let (mut e, mut s) = ([0.0; 3], [0.0; 3]);
    for l in points {
        let to = l.position - origin;
        let d2 = to.norm_squared();
        let wi = to / d2.sqrt();
        let cos = wi.dot(&normal);
        if cos <= 0.0 || scene.occluded(&Ray { origin, direction: wi }, d2.sqrt()) {
            continue;
        }
        let f = if scene.materials()[tri.material as usize].specular.is_some() {
            bsdf.eval(&wi, wo)
        } else {
            [0.0; 3]
        };
        for c in 0..3 {
            let ei = l.intensity[c] * cos / d2;
            e[c] += ei;
            s[c] += f[c] * ei;
        }
    }
    (e, s)
}

/// Indirect irradiance gathered at the nodes of a coarse barycentric
/// lattice per triangle (`n` divisions per edge, `n` from the cell size:
/// `(n + 1)(n + 2) / 2` nodes), on the side the cameras see, and
/// interpolated linearly between them. A piecewise-constant field (one
/// value per cell) puts a step of the indirect light's gradient at every
/// cell border, which the albedo map turns into a blocky error: on the
/// simulated room the relit image was 12.4 % off with constant 25 cm cells,
/// 8.6 % with constant 10 cm cells (six times the cost).
struct IndirectField {
    /// Per triangle: divisions per edge, the nodes' irradiance, node
    /// `(i, j)` (at barycentric `(i/n, j/n)`, `i + j ≤ n`) at [`node_index`],
    /// and the mean over its nodes of their estimates' variance.
    nodes: Vec<(usize, Vec<[f64; 3]>, [f64; 3])>,
}

/// Index of lattice node `(i, j)` (`i + j ≤ n`) in row-major order over `j`.
fn node_index(n: usize, i: usize, j: usize) -> usize {
    // Rows j' < j hold n + 1 − j' nodes each.
    j * (n + 1) - j * (j.saturating_sub(1)) / 2 + i
}

impl IndirectField {
    fn gather(
        scene: &Scene,
        points: &[PointLight],
        sides: &[Vector3<f64>],
        options: &AlbedoMapOptions,
    ) -> IndirectField {
        let all = vec![true; scene.triangles().len()];
        IndirectField::gather_cells(
            scene,
            points,
            sides,
            options,
            &all,
            options.irradiance_cell_m,
            options.seed,
        )
    }

    /// The second gather on the `select`ed triangles of textured surfaces
    /// ([`textured_scene`]), on cells of `options.texture_light_cell_m`.
    /// It is the light a texture sends back to itself by way of the room
    /// (a light square lights the floor in front of it, which lights the
    /// square): the first gather, through a scene of uniform surfaces,
    /// cannot see it, and the map then takes the difference as albedo. On
    /// the Mitsuba corridor's checker wall the light squares came out
    /// 1.0–2.0 % high and the dark ones 1.3–1.5 % low, 3.5–5.7 points
    /// apart within 0.8 m of the floor.
    fn gather_on(
        scene: &Scene,
        points: &[PointLight],
        sides: &[Vector3<f64>],
        options: &AlbedoMapOptions,
        select: &[bool],
    ) -> IndirectField {
        let seed = options.seed ^ TEXTURED_SEED;
        let more = AlbedoMapOptions {
            irradiance_rays: options.texture_light_rays,
            ..*options
        };
        IndirectField::gather_cells(scene, points, sides, &more, select, more.texture_light_cell_m, seed)
    }

    fn gather_cells(
        scene: &Scene,
        points: &[PointLight],
        sides: &[Vector3<f64>],
        options: &AlbedoMapOptions,
        select: &[bool],
        cell_m: f64,
        seed: u64,
    ) -> IndirectField {
        let nodes = scene
            .triangles()
            .par_iter()
            .zip(sides.par_iter())
            .enumerate()
            .map(|(ti, (tri, side))| {
                if !select.get(ti).copied().unwrap_or(false) {
                    return (0, Vec::new(), [0.0; 3]);
                }
                let longest = (0..3)
                    .map(|k| (tri.vertices[(k + 1) % 3] - tri.vertices[k]).norm())
                    .fold(0.0, f64::max);
                let n = ((longest / cell_m).ceil() as usize).clamp(1, 64);
                let mut rng = ChaCha8Rng::seed_from_u64(seed);
                rng.set_stream(ti as u64);
                let mut values = Vec::with_capacity((n + 1) * (n + 2) / 2);
                let mut variance = [0.0; 3];
                for j in 0..=n {
                    for i in 0..=n - j {
                        // Nodes on the edges and corners are pulled 0.1 % toward
                        // the centroid, so that no gather ray starts in a seam.
                        let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                        let third = 1.0 / 3.0;
                        let (u, v) = (third + (u - third) * 0.999, third + (v - third) * 0.999);
                        let p = tri.point(u, v);
                        let (e, var) = irradiance(scene, points, &p, side, options, &mut rng);
                        values.push(e);
                        for c in 0..3 {
                            variance[c] += var[c];
                        }
                    }
                }
                let count = values.len() as f64;
                (n, values, variance.map(|v| v / count))
            })
            .collect();
        IndirectField { nodes }
    }

    /// The indirect irradiance at `p` on triangle `t` (zero on the side no
    /// camera sees), interpolated linearly within the lattice's
    /// sub-triangle, and its Monte Carlo variance (the triangle's mean
    /// node variance times the interpolation weights' Σw²).
    fn at(&self, t: usize, tri: &Triangle, p: &Vector3<f64>, seen_side: bool) -> ([f64; 3], [f64; 3]) {
        if !seen_side {
            return ([0.0; 3], [0.0; 3]);
        }
        let (n, values, variance) = &self.nodes[t];
        let n = *n;
        if n == 0 {
            return ([0.0; 3], [0.0; 3]);
        }
        let (u, v) = barycentric(tri, p);
        let (mut u, mut v) = (u.clamp(0.0, 1.0), v.clamp(0.0, 1.0));
        if !(u.is_finite() && v.is_finite()) {
            return (values[0], *variance);
        }
        if u + v > 1.0 {
            let s = 1.0 / (u + v);
            u *= s;
            v *= s;
        }
        let (x, y) = (u * n as f64, v * n as f64);
        let a = (x.floor() as usize).min(n - 1);
        let b = (y.floor() as usize).min(n - 1);
        let (fu, fv) = (x - a as f64, y - b as f64);
        let node = |i: usize, j: usize| {
            let (i, j) = (i.min(n), j.min(n));
            let i = i.min(n - j);
            values[node_index(n, i, j)]
        };
        let (w, k) = if fu + fv <= 1.0 || a + b + 2 > n {
            ([1.0 - fu - fv, fu, fv], [node(a, b), node(a + 1, b), node(a, b + 1)])
        } else {
            (
                [fu + fv - 1.0, 1.0 - fv, 1.0 - fu],
                [node(a + 1, b + 1), node(a + 1, b), node(a, b + 1)],
            )
        };
        let w2: f64 = w.iter().map(|x| x * x).sum();
        (
            [0, 1, 2].map(|c| (w[0] * k[0][c] + w[1] * k[1][c] + w[2] * k[2][c]).max(0.0)),
            variance.map(|v| v * w2),
        )
    }
}

/// Indirect irradiance at `p` facing `normal`: π times the mean radiance
/// of cosine-distributed paths (direct light at their first hit counts,
/// the lamps themselves do not), their directions stratified
/// ([`super::stratified`]) and each continued by
/// [`super::lamp_paths::path_radiance`] (Russian roulette); and the
/// estimate's variance. The rays are drawn as two independently
/// stratified halves, whose difference `a − b` estimates it without the
/// bias a per-ray variance has under stratification: `(a − b)² / 4`
/// (one degree of freedom; [`IndirectField`] pools it over a triangle's
/// nodes). One ray: variance 0.
fn irradiance(
    scene: &Scene,
    points: &[PointLight],
    p: &Vector3<f64>,
    normal: &Vector3<f64>,
    options: &AlbedoMapOptions,
    rng: &mut ChaCha8Rng,
) -> ([f64; 3], [f64; 3]) {
    let (a, b) = tangents(normal);
    let origin = p + normal * 1e-6 * (1.0 + p.norm());
    let n = options.irradiance_rays;
    let halves = if n >= 2 { [n / 2, n - n / 2] } else { [n, 0] };
    let mut sums = [[0.0; 3]; 2];
    for (half, &count) in halves.iter().enumerate() {
        if count == 0 {
            continue;
        }
        let strata = Strata::new(count, rng);
        for k in 0..count {
            let [u1, u2] = strata.point(k, rng);
            let r = u1.sqrt();
            let phi = std::f64::consts::TAU * u2;
            let d = (a * (r * phi.cos()) + b * (r * phi.sin()) + normal * (1.0 - u1).max(0.0).sqrt()).normalize();
            let l = path_radiance(scene, points, Ray { origin, direction: d }, options.max_bounces, rng);
            for c in 0..3 {
                sums[half][c] += l[c];
            }
        }
    }
    let pi = std::f64::consts::PI;
    let e = [0, 1, 2].map(|c| pi * (sums[0][c] + sums[1][c]) / f64::from(n));
    let var = if halves[1] > 0 {
        [0, 1, 2].map(|c| {
            let d = pi * (sums[0][c] / f64::from(halves[0]) - sums[1][c] / f64::from(halves[1]));
            d * d / 4.0
        })
    } else {
        [0.0; 3]
    };
    (e, var)
}

/// Empirical-Bayes (Wiener) shrinkage of the texels of each surface,
/// per channel: the views that see a texel disagree by the photographs'
/// noise (and the model's view-dependent misfit), which a per-texel mean
/// passes into the map; on the simulated room's 16-path photographs a
/// constant paint came back with a 10 % median texel error. With `m_t` a
/// texel's weighted mean of its samples, `μ` the surface's mean over
/// texels, the per-sample noise variance `σ²` pooled over the surface's
/// texels seen at least twice (`Σ w (x − m_t)²` over `Σ w − Σ w² / Σ w`),
/// a texel's noise variance `N_t = σ² Σ w² / (Σ w)² + I_t`, where `I_t`
/// is the part the indirect irradiance's Monte Carlo noise puts in the
/// texel (`ρd² var(E_indirect) / E²`, common to every view, so that the
/// views' disagreement cannot show it: [`irradiance`] measures it), and the texture's
/// variance `S = max(var_t(m_t) − mean_t N_t, 0)`, each texel becomes
///
/// m_t' = μ + S / (S + N_t) · (m_t − μ),
///
/// the minimum-mean-square-error estimate of a texel whose texture and
/// noise are independent with those variances. A surface without texture
/// (S ≈ 0) comes back flat; a high-contrast texture (S ≫ N) is kept; the
/// pattern's correlation with the truth is unchanged by a common factor.
///
/// Toward the surface's mean, that estimate pulls a textured surface's
/// levels together: a two-colour checker's squares lose a share N/(S + N)
/// of their difference, which on the Mitsuba corridor's checker wall (24 %
/// spread, blue's squares 0.48 against 0.384) put the light squares' blue
/// 2.7 % low and the dark ones' 2.4 % high. So a surface textured by
/// [`TEXTURED_SHARE`] is shrunk toward each texel's local mean instead
/// (the seen texels within [`FILL_RADIUS`] on its triangle's grid: Lee's
/// local-statistics filter), with the local variance `v` in place of the
/// surface's, summed over the channels ([`local_shrink`]):
/// m_t' = m_L + max(v − N_t, 0) / v · (m_t − m_L). Inside a
/// patch of one colour the texels come toward that colour's level; across
/// an edge (`v ≫ N_t`) they are kept as they are.
fn shrink_noise(
    triangles: &mut [TriangleTexels],
    spread: &[TexelSpread],
    material: &[usize],
    textured: &[bool],
    surfaces: usize,
) {
    for s in 0..surfaces {
        let texels: Vec<&TexelSpread> = spread.iter().filter(|e| material.get(e.triangle) == Some(&s)).collect();
        let stats = [0, 1, 2].map(|c| TextureStats::of(triangles, &texels, c));
        if textured.get(s).copied().unwrap_or(false)
            && let [Some(r), Some(g), Some(b)] = &stats
        {
            let local: Vec<([f64; 3], f64)> = texels
                .iter()
                .enumerate()
                .map(|(k, t)| {
                    let noise = [r.noise[k], g.noise[k], b.noise[k]];
                    local_shrink(&triangles[t.triangle], t.texel, noise)
                })
                .collect();
            let mut gains: Vec<f64> = local.iter().map(|(_, gain)| *gain).collect();
            gains.sort_by(f64::total_cmp);
            if gains[gains.len() / 2] <= FLAT_WINDOW_GAIN {
                for (t, (v, _)) in texels.iter().zip(local) {
                    triangles[t.triangle].albedo[t.texel] = v.map(|x| x as f32);
                }
                continue;
            }
        }
        for (c, stats) in stats.iter().enumerate() {
            let Some(stats) = stats else {
                continue;
            };
            for (t, nt) in texels.iter().zip(&stats.noise) {
                let v = f64::from(triangles[t.triangle].albedo[t.texel][c]);
                let gain = if stats.signal + nt > 0.0 {
                    stats.signal / (stats.signal + nt)
                } else {
                    1.0
                };
                triangles[t.triangle].albedo[t.texel][c] = (stats.mean + gain * (v - stats.mean)) as f32;
            }
        }
    }
}

/// Texel `k` shrunk toward the mean of the seen texels within
/// [`FILL_RADIUS`] of it on `grid` ([`shrink_noise`]), its noise variance
/// `noise` per channel; as it is with fewer than three such texels. The
/// gain is one for the three channels, from their summed variances, so
/// that an edge that shows in one channel (a checker's red) keeps its
/// texels in the others too (its blue, whose squares differ by less than
/// their noise).
///
/// Returns the texel and the gain (1 where it is kept as it is).
fn local_shrink(grid: &TriangleTexels, k: usize, noise: [f64; 3]) -> ([f64; 3], f64) {
    let own = grid.albedo[k].map(f64::from);
    let (i, j) = ((k % grid.size[0]) as i64, (k / grid.size[0]) as i64);
    let (mut n, mut sum, mut sum2) = (0.0, [0.0; 3], [0.0; 3]);
    for b in (j - FILL_RADIUS).max(0)..=(j + FILL_RADIUS).min(grid.size[1] as i64 - 1) {
        for a in (i - FILL_RADIUS).max(0)..=(i + FILL_RADIUS).min(grid.size[0] as i64 - 1) {
            let q = b as usize * grid.size[0] + a as usize;
            if grid.weight[q] > 0.0 {
                n += 1.0;
                for c in 0..3 {
                    let v = f64::from(grid.albedo[q][c]);
                    sum[c] += v;
                    sum2[c] += v * v;
                }
            }
        }
    }
    if n < 3.0 {
        return (own, 1.0);
    }
    let mean = sum.map(|v| v / n);
    let var: f64 = (0..3)
        .map(|c| ((sum2[c] - n * mean[c] * mean[c]) / (n - 1.0)).max(0.0))
        .sum();
    if var <= 0.0 {
        return (mean, 0.0);
    }
    let gain = (var - noise.iter().sum::<f64>()).max(0.0) / var;
    ([0, 1, 2].map(|c| mean[c] + gain * (own[c] - mean[c])), gain)
}

/// The local form of [`shrink_noise`] is taken only where the texture is
/// flat at its window's scale: where the median texel's local gain
/// ([`local_shrink`]) is at most this, i.e. most windows hold one colour
/// and their variance is mostly noise (a checker of 40 cm squares on 1 cm
/// texels). A finer pattern (the simulated room's posters, 5 cm stripes
/// in 7 cm windows) would be blurred by its local means: there the
/// texture-to-truth correlation fell from 0.90 to 0.69, so such surfaces
/// keep the surface-wide form; so do surfaces seen too sparsely for a
/// window to hold three seen texels (the gain is then 1: the Mitsuba
/// `scalar_rgb` room's checker wall, 2.5 % of its texels seen).
const FLAT_WINDOW_GAIN: f64 = 0.25;

/// One surface's texels in one channel ([`shrink_noise`]'s terms): their
/// mean `μ`, the texture's variance `S`, and each texel's noise variance `N_t`.
struct TextureStats {
    mean: f64,
    signal: f64,
    noise: Vec<f64>,
}

impl TextureStats {
    /// Whether the texture's variance is at least the texels' mean noise
    /// variance (the surface-wide Wiener gain at least ½). Where it is
    /// not, the texture is mostly noise's guess: on the simulated room's
    /// 16-path photographs the uniform paint read a texture of 7.6 % of
    /// its mean under noise of 21 % (gain 0.11), and shrunk only locally
    /// its map came out 7.9 % off per texel against 1.4 %.
    fn texture_dominates(&self) -> bool {
        let noise = self.noise.iter().sum::<f64>() / self.noise.len().max(1) as f64;
        self.signal >= noise
    }

    /// None below 16 seen texels or without a texel seen twice.
    fn of(triangles: &[TriangleTexels], texels: &[&TexelSpread], c: usize) -> Option<TextureStats> {
        if texels.len() < 16 {
            return None;
        }
        let (mut scatter, mut dof) = (0.0, 0.0);
        for t in texels {
            let d = t.w - t.w2 / t.w;
            if d > 1e-9 * t.w {
                scatter += t.scatter[c];
                dof += d;
            }
        }
        if dof <= 0.0 {
            return None;
        }
        let sigma2 = scatter / dof;
        let values: Vec<f64> = texels
            .iter()
            .map(|t| f64::from(triangles[t.triangle].albedo[t.texel][c]))
            .collect();
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
        let noise: Vec<f64> = texels
            .iter()
            .map(|t| sigma2 * t.w2 / (t.w * t.w) + t.irradiance_noise[c])
            .collect();
        let signal = (var - noise.iter().sum::<f64>() / n).max(0.0);
        Some(TextureStats { mean, signal, noise })
    }
}

/// A surface is textured for [`IndirectField::gather_on`] and
/// [`shrink_noise`]'s local form when, in some channel, its texture's
/// standard deviation ([`TextureStats`]) is at least this share of its
/// mean and its variance at least the noise's
/// ([`TextureStats::texture_dominates`]). The untextured faces of the
/// project's RADIANCE and Mitsuba rooms spread by 0.5–1.9 %, their
/// checker walls by 24–36 %.
const TEXTURED_SHARE: f64 = 0.05;

/// Per surface, whether its map is textured ([`TEXTURED_SHARE`]).
fn textured_surfaces(
    triangles: &[TriangleTexels],
    spread: &[TexelSpread],
    material: &[usize],
    surfaces: usize,
) -> Vec<bool> {
    (0..surfaces)
        .map(|s| {
            let texels: Vec<&TexelSpread> = spread.iter().filter(|e| material.get(e.triangle) == Some(&s)).collect();
            (0..3).any(|c| {
                TextureStats::of(triangles, &texels, c).is_some_and(|st| {
                    st.mean > 0.0 && st.signal.sqrt() >= TEXTURED_SHARE * st.mean && st.texture_dominates()
                })
            })
        })
        .collect()
}

/// Whether surface `s`'s triangles share one plane (within 0.1 mm) and
/// texture axes, so that one image in texture coordinates covers it
/// ([`textured_scene`]).
fn planar(scene: &Scene, s: usize) -> bool {
    let mut tris = scene.triangles().iter().filter(|t| t.material as usize == s);
    let Some(first) = tris.next() else {
        return false;
    };
    let (n, axes) = (first.normal, first.texture_axes);
    let offset = n.dot(&first.vertices[0]);
    tris.all(|t| {
        t.texture_axes == axes
            && t.normal.dot(&n).abs() > 1.0 - 1e-9
            && t.vertices.iter().all(|v| (n.dot(v) - offset).abs() < 1e-4)
    })
}

/// The recovered scene with each textured surface's diffuse albedo the
/// first map (one [`TexelImage`] over its plane, read through
/// [`AlbedoMap::albedo_at`] at each texel's centre).
fn textured_scene(scene: &Scene, first: &AlbedoMap, textured: &[bool], names: &[String]) -> Result<Scene, IgiError> {
    let mut materials = scene.materials().to_vec();
    for (s, material) in materials.iter_mut().enumerate() {
        if !textured.get(s).copied().unwrap_or(false) {
            continue;
        }
        let members: Vec<usize> = (0..scene.triangles().len())
            .filter(|t| scene.triangles()[*t].material as usize == s)
            .collect();
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for &t in &members {
            for v in &scene.triangles()[t].vertices {
                let st = scene.triangles()[t].texture_coordinates(v);
                for k in 0..2 {
                    lo[k] = lo[k].min(st[k]);
                    hi[k] = hi[k].max(st[k]);
                }
            }
        }
        let texel_m = first.texel_m;
        let size = [0, 1].map(|k| (((hi[k] - lo[k]) / texel_m).ceil() as usize).clamp(1, 4096));
        let mean = first.fallback.get(s).copied().unwrap_or([0.5; 3]);
        let ceiling = texel_ceiling(members.iter().map(|&t| &first.triangles[t]));
        let mut texels = vec![mean.map(|v| v as f32); size[0] * size[1]];
        for &t in &members {
            let tri = &scene.triangles()[t];
            let [a0, a1] = tri.texture_axes;
            let st0 = tri.texture_coordinates(&tri.vertices[0]);
            let corners = tri.vertices.map(|v| tri.texture_coordinates(&v));
            let span = |k: usize| {
                let a = corners.iter().map(|c| c[k]).fold(f64::INFINITY, f64::min);
                let b = corners.iter().map(|c| c[k]).fold(f64::NEG_INFINITY, f64::max);
                let first = (((a - lo[k]) / texel_m).floor().max(0.0) as usize).min(size[k]);
                let last = (((b - lo[k]) / texel_m).ceil().max(0.0) as usize).min(size[k]);
                first..last
            };
            for j in span(1) {
                for i in span(0) {
                    let st = [lo[0] + (i as f64 + 0.5) * texel_m, lo[1] + (j as f64 + 0.5) * texel_m];
                    let p = tri.vertices[0] + a0 * (st[0] - st0[0]) + a1 * (st[1] - st0[1]);
                    if inside(tri, &p) {
                        let v = first.albedo_at(t, s, tri, &p);
                        texels[j * size[0] + i] = [0, 1, 2].map(|c| v[c].clamp(0.0, ceiling[c]) as f32);
                    }
                }
            }
        }
        material.albedo = Texture::Texels(TexelImage {
            origin_st: lo,
            texel_m,
            size,
            texels: texels.into(),
            mean,
        });
    }
    Ok(Scene::new(scene.triangles().to_vec(), materials, names.to_vec())?)
}

/// Per channel, the most a texel of the first map may send into the room
/// in [`textured_scene`]: the seen texels' 95th percentile plus a quarter
/// of their 5–95 % range. Texels above it are not texture: on RADIANCE's
/// corridor, whose pixels average over their area, four texels of the
/// checker wall lie behind the edge of a 1 cm lamp that a wide view sees
/// against the wall, the pixel's centre ray missing the lamp; their albedo
/// came out near 70, the map's fill spread them over their neighbours,
/// and gathered as texture they lit the wall 4–8 % brighter.
fn texel_ceiling<'a>(grids: impl Iterator<Item = &'a TriangleTexels>) -> [f64; 3] {
    let mut values: [Vec<f64>; 3] = [Vec::new(), Vec::new(), Vec::new()];
    for g in grids {
        for (v, w) in g.albedo.iter().zip(&g.weight) {
            if *w > 0.0 {
                for c in 0..3 {
                    values[c].push(f64::from(v[c]));
                }
            }
        }
    }
    values.map(|mut v| {
        if v.is_empty() {
            return f64::INFINITY;
        }
        v.sort_by(f64::total_cmp);
        let q = |f: f64| v[((v.len() - 1) as f64 * f).round() as usize];
        let (lo, hi) = (q(0.05), q(0.95));
        hi + 0.25 * (hi - lo)
    })
}

/// Whether `p` (in the triangle's plane) lies in the triangle.
fn inside(tri: &Triangle, p: &Vector3<f64>) -> bool {
    let (u, v) = barycentric(tri, p);
    u >= 0.0 && v >= 0.0 && u + v <= 1.0
}

/// The barycentric weights `(u, v)` of corners 1 and 2 of the point of
/// the triangle's plane nearest `p` (not finite for a degenerate triangle).
fn barycentric(tri: &Triangle, p: &Vector3<f64>) -> (f64, f64) {
    let (e1, e2, q) = (
        tri.vertices[1] - tri.vertices[0],
        tri.vertices[2] - tri.vertices[0],
        p - tri.vertices[0],
    );
    let (d11, d12, d22) = (e1.dot(&e1), e1.dot(&e2), e2.dot(&e2));
    let (q1, q2) = (q.dot(&e1), q.dot(&e2));
    let det = d11 * d22 - d12 * d12;
    ((d22 * q1 - d12 * q2) / det, (d11 * q2 - d12 * q1) / det)
}

fn tangents(n: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let helper = if n.x.abs() < 0.9 { Vector3::x() } else { Vector3::y() };
    let a = n.cross(&helper).normalize();
    (a, n.cross(&a))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_lattice_nodes_are_numbered_once_each_in_row_order() {
        for n in 1..9 {
            let mut k = 0;
            for j in 0..=n {
                for i in 0..=n - j {
                    assert_eq!(node_index(n, i, j), k, "n {n}, node ({i}, {j})");
                    k += 1;
                }
            }
            assert_eq!(k, (n + 1) * (n + 2) / 2);
        }
    }

    #[test]
    fn local_shrinkage_keeps_a_patterns_levels_and_takes_out_noise() {
        // Two colours side by side on a 40 × 20 grid, every texel seen,
        // uniform noise of half-width 0.05 (variance 0.05² / 3) a channel;
        // blue's two levels differ by less than the noise, as on the
        // corridor's checker wall.
        let (w, h) = (40usize, 20usize);
        let levels = [[0.6, 0.5, 0.45], [0.3, 0.45, 0.42]];
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let half = 0.05;
        let truth = |k: usize| levels[usize::from(k % w >= w / 2)];
        let grid = TriangleTexels {
            origin: [0.0; 2],
            size: [w, h],
            albedo: (0..w * h)
                .map(|k| truth(k).map(|v| (v + half * (2.0 * rand::Rng::random::<f64>(&mut rng) - 1.0)) as f32))
                .collect(),
            weight: vec![1.0; w * h],
        };
        let noise = [half * half / 3.0; 3];
        let shrunk: Vec<[f64; 3]> = (0..w * h).map(|k| local_shrink(&grid, k, noise).0).collect();
        for (side, cols) in [(0usize, 0..w / 2 - 4), (1, w / 2 + 4..w)] {
            let texels: Vec<usize> = (0..w * h).filter(|k| cols.contains(&(k % w))).collect();
            let n = texels.len() as f64;
            for c in 0..3 {
                let want = levels[side][c];
                // The level is the raw texels' (whose own mean is off by
                // the noise's 0.36 % standard error) to 0.3 %; shrunk toward
                // the grid's mean instead (Wiener, per channel), blue's
                // levels would each move 2.6 % toward the other's.
                let mean = texels.iter().map(|&k| shrunk[k][c]).sum::<f64>() / n;
                let raw = texels.iter().map(|&k| f64::from(grid.albedo[k][c])).sum::<f64>() / n;
                assert!(
                    (mean - raw).abs() < 0.003 * want,
                    "side {side}, channel {c}: {mean} against {raw}"
                );
                assert!(
                    (mean / want - 1.0).abs() < 0.012,
                    "side {side}, channel {c}: {mean} against {want}"
                );
                let rms =
                    |v: &dyn Fn(usize) -> f64| (texels.iter().map(|&k| (v(k) - want).powi(2)).sum::<f64>() / n).sqrt();
                let (before, after) = (rms(&|k| f64::from(grid.albedo[k][c])), rms(&|k| shrunk[k][c]));
                assert!(
                    after < 0.5 * before,
                    "side {side}, channel {c}: rms {after} against {before}"
                );
            }
        }
        // Next to the edge the windows hold both colours (their mean 3/7 or
        // 4/7 of the way to the other), and the red step shows in the
        // summed variance: the texels move less than a tenth of the way,
        // in every channel (blue too).
        for col in [w / 2 - 1, w / 2] {
            let texels: Vec<usize> = (0..w * h).filter(|k| k % w == col).collect();
            let side = usize::from(col >= w / 2);
            for c in 0..3 {
                let moved = texels
                    .iter()
                    .map(|&k| shrunk[k][c] - f64::from(grid.albedo[k][c]))
                    .sum::<f64>()
                    / texels.len() as f64;
                let step = levels[1 - side][c] - levels[side][c];
                assert!(
                    moved / step < 0.1,
                    "column {col}, channel {c}: moved {moved} of a step of {step}"
                );
            }
        }
    }

    #[test]
    fn the_texture_sent_into_the_room_stops_short_of_a_lamps_spill() {
        // A checker's seen texels (0.23 and 0.58, ±0.03) and four at 70
        // (a lamp's edge in the pixels behind them): the ceiling sits just
        // above the light squares' spread, far below the spill.
        let mut albedo: Vec<[f32; 3]> = (0..1000)
            .map(|k| {
                let v = if k % 2 == 0 { 0.23 } else { 0.58 } + 0.03 * ((k % 7) as f32 / 3.0 - 1.0);
                [v; 3]
            })
            .collect();
        albedo.extend([[70.0; 3]; 4]);
        let mut weight = vec![1.0; albedo.len()];
        albedo.push([500.0; 3]); // not seen: not counted
        weight.push(0.0);
        let grid = TriangleTexels {
            origin: [0.0; 2],
            size: [albedo.len(), 1],
            albedo,
            weight,
        };
        let ceiling = texel_ceiling([&grid].into_iter());
        for c in ceiling {
            // 95th percentile 0.61, 5th 0.20: 0.61 + 0.25 × 0.41.
            assert!((c - 0.7125).abs() < 1e-6, "{c}");
        }
        let empty = TriangleTexels {
            origin: [0.0; 2],
            size: [1, 1],
            albedo: vec![[1.0; 3]],
            weight: vec![0.0],
        };
        assert_eq!(texel_ceiling([&empty].into_iter()), [f64::INFINITY; 3]);
    }

    #[test]
    fn a_linear_field_is_interpolated_exactly() {
        // E(u, v) = 1 + 2u + 3v at the nodes (unpulled) reproduces itself inside.
        let tri = Triangle::new(
            [
                Vector3::new(0.0, 0.0, 0.0),
                Vector3::new(2.0, 0.0, 0.0),
                Vector3::new(0.0, 1.0, 0.0),
            ],
            0,
            0,
        )
        .unwrap();
        let n = 4;
        let mut values = Vec::new();
        for j in 0..=n {
            for i in 0..=n - j {
                let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                values.push([1.0 + 2.0 * u + 3.0 * v; 3]);
            }
        }
        let field = IndirectField {
            nodes: vec![(n, values, [0.0; 3])],
        };
        for (u, v) in [(0.1, 0.2), (0.33, 0.41), (0.7, 0.29), (0.0, 1.0), (0.95, 0.02)] {
            let p = tri.point(u, v);
            let e = field.at(0, &tri, &p, true).0[0];
            assert!((e - (1.0 + 2.0 * u + 3.0 * v)).abs() < 1e-9, "({u}, {v}): {e}");
        }
        assert_eq!(field.at(0, &tri, &tri.point(0.2, 0.2), false).0, [0.0; 3]);
    }
}

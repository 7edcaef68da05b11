//! Irradiance at each grid cell at one time (thesis §5.4): "gathering light
//! from the sun, the sky, the environment, and possibly other polygonal
//! faces occluding part of the previous three sources", with "one-bounce
//! reflection to approximate the interreflection among different faces".
//!
//! At each cell's centre, on its visible side:
//! - **sun**: the disc's normal irradiance and `max(0, n·s)`; whether the
//!   disc is visible is decided per observation ([`super::observation`]);
//! - **sky**: Appendix B adaptive subdivision of the unoccluded sky, once
//!   per face (it depends only on the normal), minus the part the scene
//!   hides, estimated from the same stratified rays as the bounce (a
//!   control variate: only the hidden part carries sampling error);
//! - **one bounce**: `m × m` stratified cosine-distributed rays. A ray that
//!   meets a *target* cell `j` brings `(ρ_sun,j E_sun,j + ρ_se,j E_sky,j)/π`
//!   — unknown pseudo-albedos, so it is kept as coefficients and summed with
//!   the current estimates ([`TimeLight::se_irradiance`]); a ray that meets a
//!   non-target surface (ground, landscape: the *environment*) brings its
//!   scene material's albedo times its direct irradiance over π; the sky
//!   part of that is computed once per square of an environment lattice
//!   whose spacing grows with the distance from the targets;
//! - **a second bounce through the environment**: each environment square
//!   also gathers the light of the target cells it sees (as coefficients,
//!   like the first bounce) and of the environment squares it sees (their
//!   albedo times their sun and sky), and passes its albedo's share on.
//!   The thesis stops at one bounce; across a narrow street from a sunlit
//!   wall the light that wall sends back through its neighbour is a fifth
//!   of the shadowed wall's `E_se` (`validation/outdoor`, RADIANCE `-ab 2`).
//!   Light reaching a target through two target bounces is left out.
//!
//! `E_se = E_sky + E_bounce` is the irradiance of eq. (5.11)–(5.12)'s
//! sky-and-environment term.

use std::collections::HashMap;

use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use super::grid::Grid;
use super::photo::Illumination;
use crate::irradiance::{SkySubdivision, sky_irradiance};
use crate::render::{Ray, Scene, SolarDisc};

/// Knobs of the gathering: accuracy against time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GatherSettings {
    /// Sky subdivision of the unoccluded sky (Appendix B).
    pub sky: SkySubdivision,
    /// One-bounce and occlusion rays per cell: `bounce_rays_per_side²`, stratified.
    pub bounce_rays_per_side: usize,
    /// Occlusion rays at environment lattice points: `environment_rays_per_side²`.
    pub environment_rays_per_side: usize,
    /// Lattice spacing on non-target surfaces within 16 m of the targets'
    /// centre, metres; it doubles with each doubling of the distance beyond.
    pub environment_spacing_m: f64,
}

impl Default for GatherSettings {
    fn default() -> Self {
        GatherSettings {
            // 2e-5 relative error against quadrature (BENCHMARKS.md, App. B).
            sky: SkySubdivision {
                tolerance: 3e-3,
                min_depth: 2,
                max_depth: 10,
            },
            bounce_rays_per_side: 20,
            environment_rays_per_side: 6,
            environment_spacing_m: 1.0,
        }
    }
}

/// Light reaching one cell, at one time.
#[derive(Debug, Clone, PartialEq)]
pub struct CellLight {
    /// Sky irradiance, occluded by the scene, W·m⁻² per channel.
    pub sky: [f64; 3],
    /// Irradiance reflected once by non-target surfaces, per channel.
    pub environment: [f64; 3],
    /// `max(0, n·s)` at the disc's centre (0 with no sun).
    pub sun_cosine: f64,
    /// One-bounce coefficients from target cells: (cell, sun coefficient,
    /// sky coefficient), so that the cell adds `ρ_sun·a_sun + ρ_se·a_sky`.
    pub reflections: Vec<(usize, [f64; 3], [f64; 3])>,
}

/// The light on every cell at one time.
#[derive(Debug, Clone)]
pub struct TimeLight {
    /// The solar disc, if the sun is up.
    pub sun: Option<SolarDisc>,
    /// Per cell, in grid order.
    pub cells: Vec<CellLight>,
}

/// Offset of secondary-ray origins off a surface, metres per metre of distance from the origin (plus 1 µm).
fn offset(p: &Vector3<f64>, n: &Vector3<f64>) -> Vector3<f64> {
    p + n * 1e-6 * (1.0 + p.norm() * 1e-3)
}

/// Whether the sun's centre is visible from `p` on the side `n`.
pub fn sun_visible(scene: &Scene, sun: &SolarDisc, p: &Vector3<f64>, n: &Vector3<f64>) -> bool {
    n.dot(&sun.direction) > 0.0
        && !scene.occluded(
            &Ray {
                origin: offset(p, n),
                direction: sun.direction,
            },
            f64::INFINITY,
        )
}

/// Two unit vectors completing unit `n` to an orthonormal basis.
fn basis(n: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let helper = if n.x.abs() < 0.9 { Vector3::x() } else { Vector3::y() };
    let a = n.cross(&helper).normalize();
    (a, n.cross(&a))
}

/// `m²` cosine-distributed directions about `n`, one jittered sample per
/// stratum of the unit square, from `seed` (the same seed, the same rays).
fn cosine_directions(n: &Vector3<f64>, m: usize, seed: u64) -> Vec<Vector3<f64>> {
    let (a, b) = basis(n);
    let m = m.max(1);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut out = Vec::with_capacity(m * m);
    for i in 0..m {
        for j in 0..m {
            let u1 = (i as f64 + rng.random::<f64>()) / m as f64;
            let u2 = (j as f64 + rng.random::<f64>()) / m as f64;
            let r = u1.sqrt();
            let phi = std::f64::consts::TAU * u2;
            out.push((a * (r * phi.cos()) + b * (r * phi.sin()) + n * (1.0 - u1).max(0.0).sqrt()).normalize());
        }
    }
    out
}

enum Hit {
    Target {
        cell: usize,
        lit: bool,
    },
    Environment {
        key: EnvKey,
        albedo: [f64; 3],
        lit_cos: f64,
    },
    Sky,
    Nothing,
}

/// An environment lattice square: triangle, side, spacing level, indices.
pub(super) type EnvKey = (usize, bool, i32, i64, i64);

/// The environment lattice square of `point` on non-target triangle `tri`
/// seen from side `front`, its spacing growing with the distance from `centre`.
pub(super) fn env_key(
    scene: &Scene,
    tri: usize,
    point: &Vector3<f64>,
    front: bool,
    centre: &Vector3<f64>,
    base_m: f64,
) -> EnvKey {
    let r = (point - centre).norm();
    let level = (r / 16.0).log2().floor().max(0.0) as i32;
    let k = base_m * 2f64.powi(level);
    let [s, t] = scene.triangles()[tri].texture_coordinates(point);
    (tri, front, level, (s / k).floor() as i64, (t / k).floor() as i64)
}

/// The sky irradiance at the centre of environment square `key`:
/// `open − π/N Σ L(hidden rays)`, `open` the unoccluded sky irradiance on its side.
pub(super) fn env_sky(
    scene: &Scene,
    key: EnvKey,
    base_m: f64,
    open: [f64; 3],
    sky: &dyn Fn(&Vector3<f64>) -> [f64; 3],
    rays_per_side: usize,
) -> [f64; 3] {
    let (p, n, seed) = env_point(scene, key, base_m);
    let hidden = hidden_sky(scene, &p, &cosine_directions(&n, rays_per_side, seed), sky);
    [0, 1, 2].map(|c| (open[c] - hidden[c]).max(0.0))
}

/// The centre of environment square `key`, its normal on the side seen,
/// and the seed of its rays.
fn env_point(scene: &Scene, key: EnvKey, base_m: f64) -> (Vector3<f64>, Vector3<f64>, u64) {
    let (ti, front, level, i, j) = key;
    let tri = &scene.triangles()[ti];
    let n = if front { tri.normal } else { -tri.normal };
    let k = base_m * 2f64.powi(level);
    let [sa, ta] = tri.texture_axes;
    let st0 = tri.texture_coordinates(&tri.vertices[0]);
    let base = tri.vertices[0] - sa * st0[0] - ta * st0[1];
    let p = base + sa * ((i as f64 + 0.5) * k) + ta * ((j as f64 + 0.5) * k);
    let seed = (ti as u64) << 40 ^ (i as u64) << 20 ^ (j as u64) ^ (level as u64) << 60;
    (p, n, seed)
}

/// What environment square `key`'s rays meet: target cells, as one-bounce
/// coefficients of its irradiance (the form of [`CellLight::reflections`]),
/// and other environment squares with their albedo and sun cosine (0 where
/// the sun is hidden), each weighted by 1/N. The light the targets and the
/// rest of the environment send to the environment, which it sends on to
/// the targets: between a sunlit wall and a building across a narrow street
/// this second bounce is a fifth of the shadowed wall's `E_se`
/// (`validation/outdoor`, against RADIANCE's `rtrace -I -ab 2`).
#[allow(clippy::too_many_arguments)]
fn env_hits(
    scene: &Scene,
    grid: &Grid,
    key: EnvKey,
    base_m: f64,
    rays_per_side: usize,
    sun: Option<&SolarDisc>,
    e_sun: [f64; 3],
    sky: &[[f64; 3]],
    centre: &Vector3<f64>,
) -> EnvHits {
    let (p, n, seed) = env_point(scene, key, base_m);
    let dirs = cosine_directions(&n, rays_per_side, seed);
    let rays = dirs.len().max(1) as f64;
    let origin = offset(&p, &n);
    let mut coef: HashMap<usize, ([f64; 3], [f64; 3])> = HashMap::new();
    let mut environment = Vec::new();
    for d in dirs {
        let Some(h) = scene.intersect(&Ray { origin, direction: d }, f64::INFINITY) else {
            continue;
        };
        let tri = &scene.triangles()[h.triangle];
        let n_hit = if tri.normal.dot(&d) < 0.0 {
            tri.normal
        } else {
            -tri.normal
        };
        let lit_cos = sun
            .filter(|s| sun_visible(scene, s, &h.point, &n_hit))
            .map_or(0.0, |s| n_hit.dot(&s.direction));
        if let Some(vn) = grid.visible_normal(scene, h.triangle) {
            let Some(cell) = grid.cell_at(scene, h.triangle, &h.point).filter(|_| vn.dot(&d) < 0.0) else {
                continue;
            };
            let cos_j = sun.map_or(0.0, |s| vn.dot(&s.direction).max(0.0));
            let e = coef.entry(cell).or_insert(([0.0; 3], [0.0; 3]));
            for ch in 0..3 {
                if lit_cos > 0.0 {
                    e.0[ch] += e_sun[ch] * cos_j / rays;
                }
                e.1[ch] += sky[cell][ch] / rays;
            }
        } else {
            let front = n_hit.dot(&tri.normal) > 0.0;
            let albedo = scene.albedo_at(h.triangle, &h.point);
            environment.push((
                env_key(scene, h.triangle, &h.point, front, centre, base_m),
                albedo.map(|a| a / rays),
                lit_cos,
            ));
        }
    }
    let mut targets: Vec<(usize, [f64; 3], [f64; 3])> = coef.into_iter().map(|(k, (a, b))| (k, a, b)).collect();
    targets.sort_by_key(|r| r.0);
    EnvHits { targets, environment }
}

/// What an environment square's rays meet ([`env_hits`]).
struct EnvHits {
    /// Target cells: (cell, sun coefficient, sky coefficient).
    targets: Vec<(usize, [f64; 3], [f64; 3])>,
    /// Environment squares: (square, albedo / N, sun cosine or 0).
    environment: Vec<(EnvKey, [f64; 3], f64)>,
}

/// π/N Σ L_sky over the rays of `dirs` from `p` that meet the scene: the
/// sky irradiance the scene hides (below the horizon, the landscape's,
/// [`crate::render::Sky::below_horizon`]; zero for most skies).
fn hidden_sky(
    scene: &Scene,
    p: &Vector3<f64>,
    dirs: &[Vector3<f64>],
    sky: &dyn Fn(&Vector3<f64>) -> [f64; 3],
) -> [f64; 3] {
    let n = dirs.len().max(1) as f64;
    let mut out = [0.0; 3];
    for d in dirs {
        let origin = p + d * 1e-6 * (1.0 + p.norm() * 1e-3);
        if scene.occluded(&Ray { origin, direction: *d }, f64::INFINITY) {
            let l = sky(d);
            for c in 0..3 {
                out[c] += std::f64::consts::PI * l[c] / n;
            }
        }
    }
    out
}

/// The unoccluded sky irradiance on a plane of unit normal `n` (App. B).
/// With a uniform radiance `L_g` below the horizon ([`Sky::below_horizon`]),
/// its part is added in closed form: the lower half-space seen from a
/// plane of normal `n` gives `π L_g (1 − n_z) / 2`.
pub(super) fn open_sky(light: &Illumination, n: &Vector3<f64>, subdivision: &SkySubdivision) -> [f64; 3] {
    let f = |d: [f64; 3]| light.sky.radiance(&Vector3::new(d[0], d[1], d[2]));
    let sky = sky_irradiance(&Vector3::zeros(), n, &f, None, subdivision)
        .map(|s| s.rgb)
        .unwrap_or([0.0; 3]);
    let below = light.sky.below_horizon();
    let k = std::f64::consts::PI * (1.0 - n.z.clamp(-1.0, 1.0)) / 2.0;
    [0, 1, 2].map(|c| sky[c] + below[c] * k)
}

/// The light on every cell of `grid` under `light`.
pub fn gather(scene: &Scene, grid: &Grid, light: &Illumination, settings: &GatherSettings) -> TimeLight {
    let sun = light.sky.sun();
    let sky_of = |d: &Vector3<f64>| light.sky.radiance(d);
    let centre = if grid.cells.is_empty() {
        Vector3::zeros()
    } else {
        grid.cells.iter().map(|c| c.centre).sum::<Vector3<f64>>() / grid.cells.len() as f64
    };
    // 1. The unoccluded sky per face.
    let face_sky: Vec<[f64; 3]> = grid
        .faces
        .par_iter()
        .map(|f| open_sky(light, &f.normal, &settings.sky))
        .collect();
    // 2. Stratified rays per cell: hidden sky and bounce hits.
    let m = settings.bounce_rays_per_side.max(1);
    let base_m = settings.environment_spacing_m.max(1e-3);
    let traced: Vec<([f64; 3], Vec<Hit>)> = grid
        .cells
        .par_iter()
        .enumerate()
        .map(|(k, c)| {
            let origin = offset(&c.centre, &c.normal);
            let dirs = cosine_directions(&c.normal, m, k as u64);
            let mut hidden = [0.0; 3];
            let hits = dirs
                .iter()
                .map(|&d| {
                    let Some(h) = scene.intersect(&Ray { origin, direction: d }, f64::INFINITY) else {
                        return Hit::Sky;
                    };
                    {
                        let l = sky_of(&d);
                        for ch in 0..3 {
                            hidden[ch] += std::f64::consts::PI * l[ch] / (m * m) as f64;
                        }
                    }
                    let tri = &scene.triangles()[h.triangle];
                    let n_hit = if tri.normal.dot(&d) < 0.0 {
                        tri.normal
                    } else {
                        -tri.normal
                    };
                    let lit_cos = sun
                        .as_ref()
                        .filter(|s| sun_visible(scene, s, &h.point, &n_hit))
                        .map_or(0.0, |s| n_hit.dot(&s.direction));
                    if let Some(vn) = grid.visible_normal(scene, h.triangle) {
                        return match grid.cell_at(scene, h.triangle, &h.point) {
                            // The back of a target (inside the building) reflects nothing.
                            Some(cell) if vn.dot(&d) < 0.0 => Hit::Target {
                                cell,
                                lit: lit_cos > 0.0,
                            },
                            _ => Hit::Nothing,
                        };
                    }
                    Hit::Environment {
                        key: env_key(
                            scene,
                            h.triangle,
                            &h.point,
                            n_hit.dot(&tri.normal) > 0.0,
                            &centre,
                            base_m,
                        ),
                        albedo: scene.albedo_at(h.triangle, &h.point),
                        lit_cos,
                    }
                })
                .collect();
            (hidden, hits)
        })
        .collect();
    let sky: Vec<[f64; 3]> = grid
        .cells
        .iter()
        .zip(&traced)
        .map(|(c, (hidden, _))| {
            let open = face_sky[c.face];
            [0, 1, 2].map(|ch| (open[ch] - hidden[ch]).max(0.0))
        })
        .collect();
    // 3. Sky irradiance on the environment lattice squares that were hit.
    let mut keys: Vec<EnvKey> = traced
        .iter()
        .flat_map(|t| t.1.iter())
        .filter_map(|h| match h {
            Hit::Environment { key, .. } => Some(*key),
            _ => None,
        })
        .collect();
    keys.sort_unstable();
    keys.dedup();
    // What those squares see in turn: targets and other environment
    // squares (the second bounce, target or environment → environment → target).
    let e_sun = sun.map_or([0.0; 3], |s| s.normal_irradiance());
    let second: HashMap<EnvKey, EnvHits> = keys
        .par_iter()
        .map(|&key| {
            let h = env_hits(
                scene,
                grid,
                key,
                base_m,
                settings.environment_rays_per_side,
                sun.as_ref(),
                e_sun,
                &sky,
                &centre,
            );
            (key, h)
        })
        .collect();
    keys.extend(second.values().flat_map(|h| h.environment.iter().map(|e| e.0)));
    keys.sort_unstable();
    keys.dedup();
    let open_cache: HashMap<(usize, bool), [f64; 3]> = {
        let mut tris: Vec<(usize, bool)> = keys.iter().map(|k| (k.0, k.1)).collect();
        tris.dedup();
        tris.sort_unstable();
        tris.dedup();
        tris.par_iter()
            .map(|&(ti, front)| {
                let n = scene.triangles()[ti].normal * if front { 1.0 } else { -1.0 };
                ((ti, front), open_sky(light, &n, &settings.sky))
            })
            .collect()
    };
    let env: HashMap<EnvKey, [f64; 3]> = keys
        .par_iter()
        .map(|&key| {
            let open = open_cache.get(&(key.0, key.1)).copied().unwrap_or([0.0; 3]);
            let e = env_sky(scene, key, base_m, open, &sky_of, settings.environment_rays_per_side);
            (key, e)
        })
        .collect();
    // The environment squares' irradiance from other environment squares.
    let env_bounce: HashMap<EnvKey, [f64; 3]> = second
        .iter()
        .map(|(key, h)| {
            let mut e = [0.0; 3];
            for (k2, albedo_n, lit_cos) in &h.environment {
                let es = env.get(k2).copied().unwrap_or([0.0; 3]);
                for ch in 0..3 {
                    e[ch] += albedo_n[ch] * (e_sun[ch] * lit_cos + es[ch]);
                }
            }
            (*key, e)
        })
        .collect();
    // 4. Assemble.
    let rays = (m * m) as f64;
    let cells = grid
        .cells
        .iter()
        .zip(&traced)
        .zip(&sky)
        .map(|((c, (_, hs)), sky_c)| {
            let mut environment = [0.0; 3];
            let mut coef: HashMap<usize, ([f64; 3], [f64; 3])> = HashMap::new();
            for h in hs {
                match h {
                    Hit::Target { cell, lit } => {
                        let e = coef.entry(*cell).or_insert(([0.0; 3], [0.0; 3]));
                        let cos_j = sun.map_or(0.0, |s| grid.cells[*cell].normal.dot(&s.direction).max(0.0));
                        for ch in 0..3 {
                            if *lit {
                                e.0[ch] += e_sun[ch] * cos_j / rays;
                            }
                            e.1[ch] += sky[*cell][ch] / rays;
                        }
                    }
                    Hit::Environment { key, albedo, lit_cos } => {
                        let es = env.get(key).copied().unwrap_or([0.0; 3]);
                        let eb = env_bounce.get(key).copied().unwrap_or([0.0; 3]);
                        for ch in 0..3 {
                            environment[ch] += albedo[ch] * (e_sun[ch] * lit_cos + es[ch] + eb[ch]) / rays;
                        }
                        for (j, a_sun, a_sky) in second.get(key).map_or(&[][..], |h| h.targets.as_slice()) {
                            let e = coef.entry(*j).or_insert(([0.0; 3], [0.0; 3]));
                            for ch in 0..3 {
                                e.0[ch] += albedo[ch] * a_sun[ch] / rays;
                                e.1[ch] += albedo[ch] * a_sky[ch] / rays;
                            }
                        }
                    }
                    Hit::Sky | Hit::Nothing => {}
                }
            }
            let mut reflections: Vec<(usize, [f64; 3], [f64; 3])> =
                coef.into_iter().map(|(k, (a, b))| (k, a, b)).collect();
            reflections.sort_by_key(|r| r.0);
            CellLight {
                sky: *sky_c,
                environment,
                sun_cosine: sun.map_or(0.0, |s| c.normal.dot(&s.direction).max(0.0)),
                reflections,
            }
        })
        .collect();
    TimeLight { sun, cells }
}

impl TimeLight {
    /// `E_se` of cell `cell` (sky + one bounce), with the current pseudo-albedos
    /// `rho_sun`, `rho_se` of the target cells.
    pub fn se_irradiance(&self, cell: usize, rho_sun: &[[f64; 3]], rho_se: &[[f64; 3]]) -> [f64; 3] {
        let c = &self.cells[cell];
        let mut e = [0.0; 3];
        for ch in 0..3 {
            e[ch] = c.sky[ch] + c.environment[ch];
            for (j, a_sun, a_sky) in &c.reflections {
                e[ch] += rho_sun[*j][ch] * a_sun[ch] + rho_se[*j][ch] * a_sky[ch];
            }
        }
        e
    }

    /// `E_sun` of cell `cell` where the disc is visible, per channel.
    pub fn sun_irradiance(&self, cell: usize) -> [f64; 3] {
        let k = self.cells[cell].sun_cosine;
        self.sun.map_or([0.0; 3], |s| s.normal_irradiance().map(|e| e * k))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::{Material, Triangle, UniformSky};

    /// A horizontal target square under a uniform sky of radiance L, with
    /// nothing else in the scene: E_sky = π L exactly, no bounce.
    #[test]
    fn open_plane_under_uniform_sky_gets_pi_l() {
        let v = |x: f64, y: f64| Vector3::new(x, y, 0.0);
        let tris = vec![
            Triangle::new([v(0.0, 0.0), v(2.0, 0.0), v(2.0, 2.0)], 0, 0).unwrap(),
            Triangle::new([v(0.0, 0.0), v(2.0, 2.0), v(0.0, 2.0)], 0, 0).unwrap(),
        ];
        let scene = Scene::new(tris, vec![Material::diffuse("m", [0.5; 3])], vec!["floor".into()]).unwrap();
        let grid = Grid::new(&scene, &[0], 1.0, &[Vector3::new(1.0, 1.0, 5.0)]).unwrap();
        let sky = UniformSky {
            radiance: [1.0, 2.0, 3.0],
        };
        let light = Illumination {
            time: chrono::DateTime::UNIX_EPOCH,
            sky: &sky,
        };
        let t = gather(&scene, &grid, &light, &GatherSettings::default());
        for (k, c) in t.cells.iter().enumerate() {
            for ch in 0..3 {
                let want = std::f64::consts::PI * (ch as f64 + 1.0);
                assert!((c.sky[ch] - want).abs() < 1e-6 * want, "cell {k}: {:?}", c.sky);
            }
            assert!(c.reflections.is_empty() && c.environment == [0.0; 3]);
        }
    }

    /// Two facing walls 1 m apart, 100 m wide: the one-bounce coefficient
    /// sums to the view factor (≈1 for the infinite case, a bit less here).
    #[test]
    fn facing_walls_see_each_other() {
        let q = |x: f64, flip: bool| {
            let a = Vector3::new(x, -50.0, -50.0);
            let b = Vector3::new(x, 50.0, -50.0);
            let c = Vector3::new(x, 50.0, 50.0);
            let d = Vector3::new(x, -50.0, 50.0);
            if flip {
                [
                    Triangle::new([a, c, b], 0, 1).unwrap(),
                    Triangle::new([a, d, c], 0, 1).unwrap(),
                ]
            } else {
                [
                    Triangle::new([a, b, c], 0, 0).unwrap(),
                    Triangle::new([a, c, d], 0, 0).unwrap(),
                ]
            }
        };
        let mut tris = q(0.0, false).to_vec();
        tris.extend(q(1.0, true));
        let scene = Scene::new(
            tris,
            vec![Material::diffuse("m", [0.5; 3])],
            vec!["a".into(), "b".into()],
        )
        .unwrap();
        // Target: wall a, seen from x > 0; wall b is environment.
        let grid = Grid::new(&scene, &[0, 1], 25.0, &[Vector3::new(0.5, 0.0, 0.0)]).unwrap();
        let sky = UniformSky { radiance: [1.0; 3] };
        let light = Illumination {
            time: chrono::DateTime::UNIX_EPOCH,
            sky: &sky,
        };
        let t = gather(&scene, &grid, &light, &GatherSettings::default());
        let centre = grid
            .cells
            .iter()
            .position(|c| c.surface == 0 && c.centre.y.abs() < 13.0 && c.centre.z.abs() < 13.0)
            .unwrap();
        // Rays that met the other wall: Σ a_sky / E_sky(j) = hits / rays.
        let share: f64 = t.cells[centre]
            .reflections
            .iter()
            .map(|r| r.2[0] / t.cells[r.0].sky[0])
            .sum();
        // Every ray from the centre meets the other wall (view factor > 0.99).
        assert!(share > 0.97 && share <= 1.0 + 1e-9, "view factor {share}");
    }
}

//! Inverse radiosity (§4.3) on the cells of [`super::geometry`]: the
//! diffuse radiance each cell sends out is read from the photographs, with
//! the current estimate of its specular part removed (the ΔS correction of
//! §4.5.1), and the indirect irradiance of every cell is gathered from the
//! radiance of the others.
//!
//! The radiance leaving a point y toward a point x is modelled as
//!
//! `L(y→x) = B(y) + ρs(y) [Σₗ K(ωₗ, ω_x) Iₗ cos θₗ / dₗ² + a(ω_x) E_ind(y) / π]`
//!
//! with `B` the cell's diffuse radiance (measured), the direct highlight of
//! each light toward x (which is what makes a glossy wall throw a bright
//! spot on its neighbours: the "mirror cones" of §4.5.1), and the lobe's
//! reflection of the light arriving at y from elsewhere, followed by one
//! lobe-sampled ray (a glossy floor mirrors the bright patch under a lamp),
//! and beyond that taken as `a E_ind(y) / π` with `a` the lobe's
//! directional albedo toward x ([`SpecularAlbedo`]). The
//! indirect irradiance of a cell is the cell-average of `∫ L(y→x) cos θ dω`,
//! estimated from `gather_rays` cosine-distributed rays leaving points
//! drawn uniformly over the cell, so that a sharp bright spot narrower than
//! a cell is averaged over the cell rather than sampled at its centre.
//! [`RadiosityField::gather_points`] gathers the same integral at given
//! points instead (the observations', `IgiOptions::point_gather_rays`: a
//! diagnostic of the cells' resolution).

use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use super::geometry::{Geometry, SURFACE_OFFSET};
use super::input::IgiInput;
use super::observation::light_terms;
use super::specular_albedo::SpecularAlbedo;
use super::stratified::{GroupedMean, Strata, variance_groups};
use crate::brdf::{ShadingFrame, WardLobe, WardMaterial, WardSampler, cosine_direction};
use crate::render::Ray;

/// Glossy reflections followed per gather ray (module doc of
/// [`RadiosityField::radiance_toward`]).
pub(crate) const REFLECTION_DEPTH: u32 = 1;

/// The direct irradiance of a cell is averaged over this many points per
/// side of the cell (a lamp 30 cm from a wall changes its irradiance
/// several times across a 30 cm cell: the centre's value is not the mean).
const DIRECT_POINTS: usize = 4;

/// A surface's lobe with its sampler and kernel worked out once per pass
/// for the ray casting ([`RadiosityField::radiance_toward`], ΔS).
#[derive(Debug, Clone, Copy)]
pub(crate) struct SurfaceLobe {
    /// The lobe.
    pub lobe: WardLobe,
    /// Its sampler (and kernel).
    pub sampler: WardSampler,
}

impl SurfaceLobe {
    /// The evaluators of `lobe`.
    pub fn new(lobe: WardLobe) -> SurfaceLobe {
        SurfaceLobe {
            lobe,
            sampler: WardSampler::new(&lobe),
        }
    }
}

/// Each surface's lobe under `materials` (`None`: diffuse or unknown).
pub(crate) fn surface_lobes(materials: &[Option<WardMaterial>]) -> Vec<Option<SurfaceLobe>> {
    materials
        .iter()
        .map(|m| m.and_then(|m| m.lobe).map(SurfaceLobe::new))
        .collect()
}

/// Per-cell quantities of the radiosity solution.
#[derive(Debug, Clone)]
pub(crate) struct RadiosityField {
    /// Diffuse radiance B per cell (cell average), W·m⁻²·sr⁻¹.
    pub diffuse: Vec<[f64; 3]>,
    /// Per cell, B / E (the diffuse radiance per unit irradiance, ρd / π
    /// of the cell), when the indirect irradiance is known: the radiance
    /// at a point of the cell is then this times the point's irradiance
    /// ([`Self::diffuse_at`]), so that a lamp's sharp spot keeps its shape
    /// within the cell. `None` before the first gathering.
    pub reflectance: Option<Vec<[f64; 3]>>,
    /// Whether any observation fell in the cell.
    pub observed: Vec<bool>,
    /// Indirect irradiance per cell (cell average), W·m⁻².
    pub e_indirect: Vec<[f64; 3]>,
    /// The variance of [`Self::e_indirect`]'s Monte Carlo estimate, per
    /// cell and channel, measured from independently stratified groups of
    /// the gather's rays ([`Self::gather`]); the fit takes it
    /// out of its normal equations (`ward_fit`, regression dilution).
    pub e_indirect_variance: Vec<[f64; 3]>,
    /// `IgiOptions::correct_noise`: [`Self::gather`] measures its
    /// variance, and [`Self::e_indirect_at`] interpolates between cells
    /// (else it reads the point's cell).
    pub correct_noise: bool,
    /// Per observation, the indirect irradiance gathered at its own point
    /// and its variance ([`Self::gather_points`]), when
    /// `IgiOptions::point_gather_rays` asks for it.
    pub point_indirect: Option<Vec<([f64; 3], [f64; 3])>>,
    /// Direct irradiance, the cell's average ([`DIRECT_POINTS`]), W·m⁻².
    pub e_direct: Vec<[f64; 3]>,
    /// Direct irradiance at the cell's [`DIRECT_POINTS`]² points (row
    /// `i` along the triangle's first edge), `None` for points outside
    /// the triangle.
    pub e_direct_points: Vec<[Option<[f64; 3]>; DIRECT_POINTS * DIRECT_POINTS]>,
    /// Lights visible from some point of the cell.
    pub visible: Vec<Vec<usize>>,
    /// Per triangle, the unit normal of the side the cameras see.
    pub side: Vec<Vector3<f64>>,
}

impl RadiosityField {
    /// The empty field: visibility and direct light per cell, on the side
    /// of each triangle given by `side`.
    pub fn new(geometry: &Geometry, input: &IgiInput, side: Vec<Vector3<f64>>) -> RadiosityField {
        let n = geometry.cell_count();
        type PerCell = (Vec<usize>, [f64; 3], [Option<[f64; 3]>; DIRECT_POINTS * DIRECT_POINTS]);
        let per_cell: Vec<PerCell> = (0..n)
            .into_par_iter()
            .map(|cell| {
                let tri = geometry.cell_triangle(cell);
                let frame = geometry.frame(tri, &side[tri]);
                let mut e = [0.0; 3];
                let mut points = [None; DIRECT_POINTS * DIRECT_POINTS];
                let mut visible = vec![false; input.lights.len()];
                let mut count = 0u32;
                let mut at = |p: &Vector3<f64>| {
                    let mut ep = [0.0; 3];
                    for t in light_terms(geometry, input, p, &frame, None) {
                        visible[t.light] = true;
                        for c in 0..3 {
                            ep[c] += t.irradiance[c];
                        }
                    }
                    ep
                };
                for (k, slot) in points.iter_mut().enumerate() {
                    let f = [
                        ((k / DIRECT_POINTS) as f64 + 0.5) / DIRECT_POINTS as f64,
                        ((k % DIRECT_POINTS) as f64 + 0.5) / DIRECT_POINTS as f64,
                    ];
                    let Some(p) = geometry.cell_point(cell, f) else {
                        continue;
                    };
                    let ep = at(&p);
                    count += 1;
                    for c in 0..3 {
                        e[c] += ep[c];
                    }
                    *slot = Some(ep);
                }
                if count == 0
                    && let Some(p) = geometry.cell_centre(cell)
                {
                    e = at(&p);
                    count = 1;
                }
                let e = e.map(|v| v / f64::from(count.max(1)));
                ((0..visible.len()).filter(|&l| visible[l]).collect(), e, points)
            })
            .collect();
        let mut visible = Vec::with_capacity(n);
        let mut e_direct = Vec::with_capacity(n);
        let mut e_direct_points = Vec::with_capacity(n);
        for (v, e, p) in per_cell {
            visible.push(v);
            e_direct.push(e);
            e_direct_points.push(p);
        }
        RadiosityField {
            diffuse: vec![[0.0; 3]; n],
            reflectance: None,
            observed: vec![false; n],
            e_indirect: vec![[0.0; 3]; n],
            e_indirect_variance: vec![[0.0; 3]; n],
            correct_noise: false,
            point_indirect: None,
            e_direct,
            e_direct_points,
            visible,
            side,
        }
    }

    /// The direct irradiance at point `y` of cell `cell`, bilinear between
    /// the cell's [`DIRECT_POINTS`]² points (`f`: the fractional position
    /// in the cell); points outside the triangle take the cell's average.
    fn direct_at(&self, cell: usize, f: [f64; 2]) -> [f64; 3] {
        let points = &self.e_direct_points[cell];
        let n = DIRECT_POINTS as f64;
        let (x, y) = (
            (f[0] * n - 0.5).clamp(0.0, n - 1.0),
            (f[1] * n - 0.5).clamp(0.0, n - 1.0),
        );
        // x, y ≥ 0: truncation is the floor.
        let (i0, j0) = ((x as usize).min(DIRECT_POINTS - 2), (y as usize).min(DIRECT_POINTS - 2));
        let (fx, fy) = (x - i0 as f64, y - j0 as f64);
        let mut e = [0.0; 3];
        for (di, wx) in [(0, 1.0 - fx), (1, fx)] {
            for (dj, wy) in [(0, 1.0 - fy), (1, fy)] {
                let v = points[(i0 + di) * DIRECT_POINTS + j0 + dj].unwrap_or(self.e_direct[cell]);
                for c in 0..3 {
                    e[c] += wx * wy * v[c];
                }
            }
        }
        e
    }

    /// The diffuse radiance leaving point `y` of triangle `tri` (in cell
    /// `cell`): the cell's reflectance times the point's direct irradiance
    /// plus its indirect irradiance (interpolated between cells,
    /// [`Self::e_indirect_at`]), once known; the cell's mean before.
    pub fn diffuse_at(&self, geometry: &Geometry, tri: usize, y: &Vector3<f64>) -> (usize, [f64; 3]) {
        let (cell, f) = geometry.cell_with_fraction(tri, y);
        let Some(r) = &self.reflectance else {
            return (cell, self.diffuse[cell]);
        };
        let e = self.direct_at(cell, f);
        let (e_indirect, _) = self.e_indirect_in(geometry.n, cell, f);
        (cell, [0, 1, 2].map(|c| r[cell][c] * (e[c] + e_indirect[c])))
    }

    /// The radiance leaving point `y` of triangle `tri` in unit direction
    /// `toward` (world), under the surface estimates `materials` (module
    /// doc). With `depth` > 0, the lobe's reflection of indirect light is
    /// estimated by one lobe-sampled ray (a glossy wall mirrors the bright
    /// patch under a lamp, not the average of its surroundings), recursively
    /// with `depth − 1`; at depth 0 it is `a E_ind / π`. `lobes` are the
    /// surfaces' lobes under the estimates ([`surface_lobes`]).
    #[allow(clippy::too_many_arguments)]
    pub fn radiance_toward(
        &self,
        geometry: &Geometry,
        input: &IgiInput,
        lobes: &[Option<SurfaceLobe>],
        albedos: &[Option<SpecularAlbedo>],
        tri: usize,
        y: &Vector3<f64>,
        toward: &Vector3<f64>,
        depth: u32,
        rng: &mut ChaCha8Rng,
    ) -> [f64; 3] {
        let (cell, mut l) = self.diffuse_at(geometry, tri, y);
        let surface = geometry.triangles()[tri].surface as usize;
        let Some(SurfaceLobe { lobe, sampler }) = lobes.get(surface).copied().flatten() else {
            return l;
        };
        let frame = geometry.frame(tri, toward);
        let wo = frame.to_local(toward);
        let kernel = sampler.kernel();
        let mut k = [0.0; 3];
        for &li in &self.visible[cell] {
            let light = &input.lights[li];
            let to = light.position - y;
            let d2 = to.norm_squared();
            let wi = frame.to_local(&(to / d2.sqrt()));
            if wi.z <= 0.0 {
                continue;
            }
            let kd = kernel.eval(&wi, &wo) * wi.z / d2;
            for c in 0..3 {
                k[c] += kd * light.intensity[c];
            }
        }
        let reflected = if depth > 0 {
            let mut r = [0.0; 3];
            let u = [rng.random::<f64>(), rng.random::<f64>()];
            if let Some(wi) = sampler.sample(&wo, u)
                && let Some(weight) = sampler.weight(&wi, &wo)
            {
                let direction = frame.to_world(&wi);
                let origin = y + frame.normal * SURFACE_OFFSET * (1.0 + y.norm());
                if let Some(li) =
                    self.radiance_along(geometry, input, lobes, albedos, origin, direction, depth - 1, rng)
                {
                    r = li.map(|v| v * weight);
                }
            }
            r
        } else {
            let a = albedos.get(surface).and_then(|a| a.as_ref()).map_or(1.0, |a| a.at(&wo));
            self.e_indirect[cell].map(|e| a * e * std::f64::consts::FRAC_1_PI)
        };
        for c in 0..3 {
            l[c] += lobe.rho_s[c] * (k[c] + reflected[c]);
        }
        l
    }

    /// The radiance that reaches `origin` along `direction` (unit, world):
    /// [`Self::radiance_toward`] at the first surface the ray meets, with
    /// `depth`; `None` when it meets none.
    #[allow(clippy::too_many_arguments)]
    pub fn radiance_along(
        &self,
        geometry: &Geometry,
        input: &IgiInput,
        lobes: &[Option<SurfaceLobe>],
        albedos: &[Option<SpecularAlbedo>],
        origin: Vector3<f64>,
        direction: Vector3<f64>,
        depth: u32,
        rng: &mut ChaCha8Rng,
    ) -> Option<[f64; 3]> {
        let hit = geometry.intersect(&Ray { origin, direction }, f64::INFINITY)?;
        Some(self.radiance_toward(
            geometry,
            input,
            lobes,
            albedos,
            hit.triangle,
            &hit.point,
            &-direction,
            depth,
            rng,
        ))
    }

    /// The indirect irradiance at point `p` of triangle `tri` and its
    /// estimate's variance: with [`Self::correct_noise`] bilinear between
    /// the centres of the point's cell and its three nearest neighbours on
    /// the triangle's grid (cells wholly outside the triangle left out,
    /// the weights renormalized; the variance `Σ wᵢ² Varᵢ` of independent
    /// cells); without, the point's cell's value. On the Mitsuba studio
    /// (`validation/igi`) cell-constant values left the checker wall's weak
    /// lobe ρs +1.9 to +3.7 % over seeds 1–3 at 12 cells a side, +0.6 to
    /// +2.2 % interpolated.
    pub fn e_indirect_at(&self, geometry: &Geometry, tri: usize, p: &Vector3<f64>) -> ([f64; 3], [f64; 3]) {
        let (cell, f) = geometry.cell_with_fraction(tri, p);
        self.e_indirect_in(geometry.n, cell, f)
    }

    /// [`Self::e_indirect_at`] at fractional position `f` of cell `cell`
    /// on a grid of `n` cells a side.
    fn e_indirect_in(&self, n: usize, cell: usize, f: [f64; 2]) -> ([f64; 3], [f64; 3]) {
        if !self.correct_noise {
            return (self.e_indirect[cell], self.e_indirect_variance[cell]);
        }
        let base = cell - cell % (n * n);
        let (i, j) = ((cell - base) / n, (cell - base) % n);
        // The neighbour toward the point along each axis, and its weight.
        let step = |k: usize, t: f64| -> (Option<usize>, f64) {
            if t >= 0.5 {
                ((k + 1 < n).then_some(k + 1), t - 0.5)
            } else {
                (k.checked_sub(1), 0.5 - t)
            }
        };
        let (ni, ti) = step(i, f[0]);
        let (nj, tj) = step(j, f[1]);
        let mut mean = [0.0; 3];
        let mut variance = [0.0; 3];
        let mut total = 0.0;
        let mut add = |ci: Option<usize>, cj: Option<usize>, w: f64| {
            let (Some(ci), Some(cj)) = (ci, cj) else {
                return;
            };
            // A cell the diagonal leaves (almost) wholly outside has no value.
            if w <= 0.0 || ci + cj >= n {
                return;
            }
            let c = base + ci * n + cj;
            for k in 0..3 {
                mean[k] += w * self.e_indirect[c][k];
                variance[k] += w * w * self.e_indirect_variance[c][k];
            }
            total += w;
        };
        add(Some(i), Some(j), (1.0 - ti) * (1.0 - tj));
        add(ni, Some(j), ti * (1.0 - tj));
        add(Some(i), nj, (1.0 - ti) * tj);
        add(ni, nj, ti * tj);
        if total <= 0.0 {
            return (self.e_indirect[cell], self.e_indirect_variance[cell]);
        }
        (mean.map(|v| v / total), variance.map(|v| v / (total * total)))
    }

    /// Gathers the indirect irradiance of every cell (module doc) from the
    /// current diffuse radiance and surface estimates.
    pub fn gather(
        &mut self,
        geometry: &Geometry,
        input: &IgiInput,
        materials: &[Option<WardMaterial>],
        albedos: &[Option<SpecularAlbedo>],
        rays: u32,
        seed: u64,
    ) {
        let lobes = surface_lobes(materials);
        let e: Vec<([f64; 3], [f64; 3])> = (0..geometry.cell_count())
            .into_par_iter()
            .map(|cell| {
                if geometry.cell_centre(cell).is_none() {
                    return ([0.0; 3], [0.0; 3]);
                }
                let tri = geometry.cell_triangle(cell);
                let frame = geometry.frame(tri, &self.side[tri]);
                let mut rng = ChaCha8Rng::seed_from_u64(seed);
                rng.set_stream(cell as u64);
                self.gather_over(geometry, input, &lobes, albedos, &frame, rays, &mut rng, |rng| {
                    let f = [rng.random::<f64>(), rng.random::<f64>()];
                    geometry.cell_point(cell, f)
                })
            })
            .collect();
        (self.e_indirect, self.e_indirect_variance) = e.into_iter().unzip();
    }

    /// Gathers the indirect irradiance at each of `points` (a point and
    /// the frame of the side it is seen from) with `rays` rays each, into
    /// [`Self::point_indirect`]: read there, not between cells, by
    /// [`Self::e_indirect_of`].
    #[allow(clippy::too_many_arguments)]
    pub fn gather_points(
        &mut self,
        geometry: &Geometry,
        input: &IgiInput,
        materials: &[Option<WardMaterial>],
        albedos: &[Option<SpecularAlbedo>],
        points: &[(Vector3<f64>, ShadingFrame)],
        rays: u32,
        seed: u64,
    ) {
        let lobes = surface_lobes(materials);
        let e: Vec<([f64; 3], [f64; 3])> = points
            .par_iter()
            .enumerate()
            .map(|(k, (p, frame))| {
                let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x7047_6174);
                rng.set_stream(k as u64);
                self.gather_over(geometry, input, &lobes, albedos, frame, rays, &mut rng, |_| Some(*p))
            })
            .collect();
        self.point_indirect = Some(e);
    }

    /// The mean of `∫ L cos θ dω` over `rays` cosine-distributed rays
    /// leaving the points `point` draws, and its variance (module doc).
    #[allow(clippy::too_many_arguments)]
    fn gather_over(
        &self,
        geometry: &Geometry,
        input: &IgiInput,
        lobes: &[Option<SurfaceLobe>],
        albedos: &[Option<SpecularAlbedo>],
        frame: &ShadingFrame,
        rays: u32,
        rng: &mut ChaCha8Rng,
        mut point: impl FnMut(&mut ChaCha8Rng) -> Option<Vector3<f64>>,
    ) -> ([f64; 3], [f64; 3]) {
        // Independently stratified groups, so that the estimate's
        // variance is measured without bias (with
        // `IgiOptions::correct_noise`; otherwise one set and no
        // variance).
        let groups = if self.correct_noise {
            variance_groups(rays)
        } else {
            vec![rays]
        };
        let mut acc = GroupedMean::new(groups.len());
        for (g, n) in groups.into_iter().enumerate() {
            let strata = Strata::new(n, rng);
            for r in 0..n {
                let Some(p) = point(rng) else {
                    continue;
                };
                acc.count(g, 1);
                let u = strata.point(r, rng);
                let Some(d) = cosine_direction(u) else {
                    continue;
                };
                let direction = frame.to_world(&d);
                let origin = p + frame.normal * SURFACE_OFFSET * (1.0 + p.norm());
                if let Some(l) = self.radiance_along(
                    geometry,
                    input,
                    lobes,
                    albedos,
                    origin,
                    direction,
                    REFLECTION_DEPTH,
                    rng,
                ) {
                    acc.add(g, l);
                }
            }
        }
        acc.mean_and_variance(std::f64::consts::PI)
    }

    /// The indirect irradiance at observation `index` (at `tri`, `p`) and
    /// its variance: gathered at the point when [`Self::point_indirect`]
    /// holds it, else [`Self::e_indirect_at`].
    pub fn e_indirect_of(
        &self,
        geometry: &Geometry,
        index: usize,
        tri: usize,
        p: &Vector3<f64>,
    ) -> ([f64; 3], [f64; 3]) {
        match &self.point_indirect {
            Some(e) => e[index],
            None => self.e_indirect_at(geometry, tri, p),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A field linear over a triangle's grid (each cell holding the value
    /// at its centre) is read back exactly between the centres, and the
    /// variance of the interpolated value is `Σ wᵢ² Varᵢ`: a quarter of a
    /// cell's at a point midway between four centres.
    #[test]
    fn indirect_irradiance_is_interpolated_between_cells() {
        let input = crate::igi::input::unit_cube();
        let n = 8;
        let geometry = Geometry::new(&input.triangles, &input.surfaces, n).unwrap();
        let side = geometry.triangles().iter().map(|t| t.normal).collect();
        let mut field = RadiosityField::new(&geometry, &input, side);
        field.correct_noise = true;
        let value = |i: f64, j: f64| 1.0 + 2.0 * i / n as f64 + 3.0 * j / n as f64;
        for cell in 0..geometry.cell_count() {
            let (i, j) = ((cell % (n * n)) / n, cell % n);
            let v = value(i as f64 + 0.5, j as f64 + 0.5);
            field.e_indirect[cell] = [v, 2.0 * v, 0.0];
            field.e_indirect_variance[cell] = [1.0; 3];
        }
        let tri = 3;
        for (i, j, f) in [
            (1, 1, [0.5, 0.5]),
            (2, 3, [0.9, 0.2]),
            (4, 1, [0.1, 0.7]),
            (0, 5, [0.6, 0.55]),
        ] {
            let cell = tri * n * n + i * n + j;
            let p = geometry.cell_point(cell, f).unwrap();
            let (e, var) = field.e_indirect_at(&geometry, tri, &p);
            let truth = value(i as f64 + f[0], j as f64 + f[1]);
            assert!(
                (e[0] - truth).abs() < 1e-9,
                "cell ({i}, {j}) at {f:?}: {e:?} against {truth}"
            );
            assert!((e[1] - 2.0 * truth).abs() < 1e-9);
            assert!(var[0] <= 1.0 && var[0] >= 0.25 - 1e-12, "{var:?}");
        }
        // Midway between four centres.
        let cell = tri * n * n + 2 * n + 2;
        let p = geometry.cell_point(cell, [1.0, 1.0]).unwrap();
        let (_, var) = field.e_indirect_at(&geometry, tri, &p);
        assert!((var[0] - 0.25).abs() < 1e-9, "{var:?}");
        // Beside the diagonal, the cells beyond it are left out: the value
        // stays between its neighbours' (no zero from an empty cell).
        let cell = tri * n * n + 3 * n + 4;
        let p = geometry.cell_point(cell, [0.7, 0.2]).unwrap();
        let (e, _) = field.e_indirect_at(&geometry, tri, &p);
        assert!(
            e[0] >= value(3.5, 3.5) - 1e-9 && e[0] <= value(3.5, 4.5) + 1e-9,
            "{e:?}"
        );
        // Without interpolation, the point's cell.
        field.correct_noise = false;
        let (e, var) = field.e_indirect_at(&geometry, tri, &p);
        assert_eq!((e[0], var[0]), (value(3.5, 4.5), 1.0));
    }

    /// A cube whose cells each send out a radiance linear in their
    /// centre's height (`materials` none, so the radiance is the cell's).
    fn field(n: usize) -> (IgiInput, Geometry, RadiosityField) {
        let input = crate::igi::input::unit_cube();
        let geometry = Geometry::new(&input.triangles, &input.surfaces, n).unwrap();
        let side = geometry.triangles().iter().map(|t| t.normal).collect();
        let mut field = RadiosityField::new(&geometry, &input, side);
        field.correct_noise = true;
        for cell in 0..geometry.cell_count() {
            if let Some(c) = geometry.cell_centre(cell) {
                field.diffuse[cell] = [1.0 + 2.0 * c.z, 1.0, 0.0];
            }
        }
        (input, geometry, field)
    }

    /// Inside a closed room of uniform radiance 1 every ray meets a
    /// surface of radiance 1: E = π at any point, with no variance.
    #[test]
    fn a_point_in_a_uniform_closed_room_gathers_pi() {
        let (input, geometry, mut field) = field(4);
        for d in field.diffuse.iter_mut() {
            *d = [1.0; 3];
        }
        let tri = 0;
        let frame = geometry.frame(tri, &field.side[tri]);
        let p = geometry.cell_point(0, [0.3, 0.4]).unwrap();
        let none = vec![None; input.surfaces.len()];
        let no_albedos = vec![None; input.surfaces.len()];
        field.gather_points(&geometry, &input, &none, &no_albedos, &[(p, frame)], 256, 1);
        let (e, var) = field.e_indirect_of(&geometry, 0, tri, &p);
        for c in 0..3 {
            assert!((e[c] - std::f64::consts::PI).abs() < 1e-9, "{e:?}");
            assert!(var[c].abs() < 1e-12, "{var:?}");
        }
    }

    /// Points drawn uniformly over a cell, each gathered at its own
    /// point, average to the cell's gather (the same integral over the
    /// cell) within four standard errors of the two estimates' measured
    /// noise, on a floor cell under a wall radiance that varies with
    /// height; and without [`RadiosityField::point_indirect`] an
    /// observation reads the cells.
    #[test]
    fn point_gathers_average_to_the_cell_gather() {
        let (input, geometry, mut field) = field(4);
        let none = vec![None; input.surfaces.len()];
        let no_albedos = vec![None; input.surfaces.len()];
        field.gather(&geometry, &input, &none, &no_albedos, 4096, 7);
        // The first triangle whose normal is +z (the floor, seen from
        // inside), and its cell nearest the corner.
        let tri = (0..geometry.triangles().len())
            .find(|&t| geometry.triangles()[t].normal.z > 0.9)
            .unwrap();
        let n = geometry.n;
        let cell = tri * n * n;
        let frame = geometry.frame(tri, &field.side[tri]);
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mut points = Vec::new();
        while points.len() < 256 {
            if let Some(p) = geometry.cell_point(cell, [rng.random(), rng.random()]) {
                points.push((p, frame));
            }
        }
        let (p0, _) = points[0];
        assert_eq!(
            field.e_indirect_of(&geometry, 0, tri, &p0),
            field.e_indirect_at(&geometry, tri, &p0)
        );
        field.gather_points(&geometry, &input, &none, &no_albedos, &points, 512, 11);
        let e = field.point_indirect.as_ref().unwrap();
        let k = e.len() as f64;
        let mean = e.iter().map(|v| v.0[0]).sum::<f64>() / k;
        // The spread of the points' values covers both the rays' noise
        // and the field's variation over the cell.
        let spread = e.iter().map(|v| (v.0[0] - mean).powi(2)).sum::<f64>() / (k - 1.0);
        let sigma = (spread / k + field.e_indirect_variance[cell][0]).sqrt();
        let cell_value = field.e_indirect[cell][0];
        assert!(sigma > 0.0 && sigma < 0.01 * cell_value, "σ {sigma}");
        assert!(
            (mean - cell_value).abs() < 4.0 * sigma,
            "points {mean} against the cell {cell_value} (σ {sigma})"
        );
        // The green channel is uniform: E = π exactly at every point.
        assert!(e.iter().all(|v| (v.0[1] - std::f64::consts::PI).abs() < 1e-9));
    }
}

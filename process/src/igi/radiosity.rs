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

use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use super::geometry::{Geometry, SURFACE_OFFSET};
use super::input::IgiInput;
use super::observation::light_terms;
use super::specular_albedo::SpecularAlbedo;
use super::stratified::Strata;
use crate::brdf::{WardKernel, WardMaterial, cosine_direction};
use crate::render::Ray;

/// Glossy reflections followed per gather ray (module doc of
/// [`RadiosityField::radiance_toward`]).
pub(crate) const REFLECTION_DEPTH: u32 = 1;

/// Per-cell quantities of the radiosity solution.
#[derive(Debug, Clone)]
pub(crate) struct RadiosityField {
    /// Diffuse radiance B per cell, W·m⁻²·sr⁻¹.
    pub diffuse: Vec<[f64; 3]>,
    /// Whether any observation fell in the cell.
    pub observed: Vec<bool>,
    /// Indirect irradiance per cell (cell average), W·m⁻².
    pub e_indirect: Vec<[f64; 3]>,
    /// Direct irradiance at the cell's representative point, W·m⁻².
    pub e_direct: Vec<[f64; 3]>,
    /// Lights visible from the cell's representative point.
    pub visible: Vec<Vec<usize>>,
    /// Per triangle, the unit normal of the side the cameras see.
    pub side: Vec<Vector3<f64>>,
}

impl RadiosityField {
    /// The empty field: visibility and direct light per cell, on the side
    /// of each triangle given by `side`.
    pub fn new(geometry: &Geometry, input: &IgiInput, side: Vec<Vector3<f64>>) -> RadiosityField {
        let n = geometry.cell_count();
        let per_cell: Vec<(Vec<usize>, [f64; 3])> = (0..n)
            .into_par_iter()
            .map(|cell| {
                let Some(p) = geometry.cell_centre(cell) else {
                    return (Vec::new(), [0.0; 3]);
                };
                let tri = geometry.cell_triangle(cell);
                let frame = geometry.frame(tri, &side[tri]);
                let terms = light_terms(geometry, input, &p, &frame, None);
                let mut e = [0.0; 3];
                for t in &terms {
                    for c in 0..3 {
                        e[c] += t.irradiance[c];
                    }
                }
                (terms.iter().map(|t| t.light).collect(), e)
            })
            .collect();
        let (visible, e_direct) = per_cell.into_iter().unzip();
        RadiosityField {
            diffuse: vec![[0.0; 3]; n],
            observed: vec![false; n],
            e_indirect: vec![[0.0; 3]; n],
            e_direct,
            visible,
            side,
        }
    }

    /// The radiance leaving point `y` of triangle `tri` in unit direction
    /// `toward` (world), under the surface estimates `materials` (module
    /// doc). With `depth` > 0, the lobe's reflection of indirect light is
    /// estimated by one lobe-sampled ray (a glossy wall mirrors the bright
    /// patch under a lamp, not the average of its surroundings), recursively
    /// with `depth − 1`; at depth 0 it is `a E_ind / π`.
    #[allow(clippy::too_many_arguments)]
    pub fn radiance_toward(
        &self,
        geometry: &Geometry,
        input: &IgiInput,
        materials: &[Option<WardMaterial>],
        albedos: &[Option<SpecularAlbedo>],
        tri: usize,
        y: &Vector3<f64>,
        toward: &Vector3<f64>,
        depth: u32,
        rng: &mut ChaCha8Rng,
    ) -> [f64; 3] {
        let cell = geometry.cell(tri, y);
        let mut l = self.diffuse[cell];
        let surface = geometry.triangles()[tri].surface as usize;
        let Some(lobe) = materials.get(surface).and_then(|m| m.as_ref()).and_then(|m| m.lobe) else {
            return l;
        };
        let frame = geometry.frame(tri, toward);
        let wo = frame.to_local(toward);
        let kernel = WardKernel::new(&lobe);
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
            if let Some(wi) = lobe.sample(&wo, u) {
                let pdf = lobe.pdf(&wi, &wo);
                if pdf > 0.0 && pdf.is_finite() {
                    let weight = kernel.eval(&wi, &wo) * wi.z / pdf;
                    let direction = frame.to_world(&wi);
                    let origin = y + frame.normal * SURFACE_OFFSET * (1.0 + y.norm());
                    if let Some(hit) = geometry.intersect(&Ray { origin, direction }, f64::INFINITY) {
                        let li = self.radiance_toward(
                            geometry,
                            input,
                            materials,
                            albedos,
                            hit.triangle,
                            &hit.point,
                            &-direction,
                            depth - 1,
                            rng,
                        );
                        r = li.map(|v| v * weight);
                    }
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
        let e: Vec<[f64; 3]> = (0..geometry.cell_count())
            .into_par_iter()
            .map(|cell| {
                if geometry.cell_centre(cell).is_none() {
                    return [0.0; 3];
                }
                let tri = geometry.cell_triangle(cell);
                let frame = geometry.frame(tri, &self.side[tri]);
                let mut rng = ChaCha8Rng::seed_from_u64(seed);
                rng.set_stream(cell as u64);
                let strata = Strata::new(rays, &mut rng);
                let mut sum = [0.0; 3];
                let mut count = 0u32;
                for r in 0..rays {
                    let f = [rng.random::<f64>(), rng.random::<f64>()];
                    let Some(p) = geometry.cell_point(cell, f) else {
                        continue;
                    };
                    count += 1;
                    let u = strata.point(r, &mut rng);
                    let Some(d) = cosine_direction(u) else {
                        continue;
                    };
                    let direction = frame.to_world(&d);
                    let origin = p + frame.normal * SURFACE_OFFSET * (1.0 + p.norm());
                    let Some(hit) = geometry.intersect(&Ray { origin, direction }, f64::INFINITY) else {
                        continue;
                    };
                    let l = self.radiance_toward(
                        geometry,
                        input,
                        materials,
                        albedos,
                        hit.triangle,
                        &hit.point,
                        &-direction,
                        REFLECTION_DEPTH,
                        &mut rng,
                    );
                    for c in 0..3 {
                        sum[c] += l[c];
                    }
                }
                if count == 0 {
                    return [0.0; 3];
                }
                sum.map(|s| s * std::f64::consts::PI / f64::from(count))
            })
            .collect();
        self.e_indirect = e;
    }
}

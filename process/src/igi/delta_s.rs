//! The indirect specular term ΔS (§4.5.1): at a sample, the light that
//! other surfaces send into the specular lobe, per unit ρs,
//!
//! `S_ind(x, ωo) = ∫ K(α, ωi, ωo) L(y(ωi) → x) cos θi dωi`,
//!
//! estimated by one bounce of Monte Carlo around the mirror cone: incident
//! directions are drawn from the lobe itself (Walter's half-vector
//! sampling, stratified), so a lobe of any width costs the same few rays.
//! The lobe is the current roughness estimate, held fixed while ρd, ρs and
//! α are refitted, and the whole is iterated (Fig. 4.6).

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use super::geometry::{Geometry, SURFACE_OFFSET};
use super::input::IgiInput;
use super::observation::Observation;
use super::radiosity::{REFLECTION_DEPTH, RadiosityField};
use super::specular_albedo::SpecularAlbedo;
use super::stratified::Strata;
use crate::brdf::{WardKernel, WardLobe, WardMaterial};
use crate::render::Ray;

/// `S_ind` per channel for every observation, with the lobe shape
/// `shapes[surface]` (`None`: no specular term, zero).
#[allow(clippy::too_many_arguments)]
pub(crate) fn indirect_specular(
    geometry: &Geometry,
    input: &IgiInput,
    field: &RadiosityField,
    materials: &[Option<WardMaterial>],
    albedos: &[Option<SpecularAlbedo>],
    observations: &[Observation],
    shapes: &[Option<WardLobe>],
    rays: u32,
    seed: u64,
) -> Vec<[f64; 3]> {
    observations
        .par_iter()
        .enumerate()
        .map(|(i, o)| {
            let Some(lobe) = shapes.get(o.surface).copied().flatten() else {
                return [0.0; 3];
            };
            let kernel = WardKernel::new(&lobe);
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            rng.set_stream(i as u64);
            let strata = Strata::new(rays, &mut rng);
            let mut sum = [0.0; 3];
            let origin = o.point + o.frame.normal * SURFACE_OFFSET * (1.0 + o.point.norm());
            for r in 0..rays {
                let u = strata.point(r, &mut rng);
                let Some(wi) = lobe.sample(&o.wo, u) else {
                    continue;
                };
                let pdf = lobe.pdf(&wi, &o.wo);
                if !(pdf > 0.0 && pdf.is_finite()) {
                    continue;
                }
                let weight = kernel.eval(&wi, &o.wo) * wi.z / pdf;
                let direction = o.frame.to_world(&wi);
                let Some(hit) = geometry.intersect(&Ray { origin, direction }, f64::INFINITY) else {
                    continue;
                };
                let l = field.radiance_toward(
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
                    sum[c] += weight * l[c];
                }
            }
            sum.map(|s| s / f64::from(rays))
        })
        .collect()
}

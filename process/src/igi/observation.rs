//! Samples: every usable pixel becomes an observation of one surface point
//! seen from one direction, with the direct light of each known source at
//! that point (shadow-tested) precomputed, since it does not depend on the
//! BRDF. Pixels are dropped, and counted, when masked, when their ray
//! meets a bulb before a surface (a light inside the view), when they see
//! nothing, or when the view is more grazing than the option allows.

use nalgebra::Vector3;
use rayon::prelude::*;

use super::geometry::{Geometry, SURFACE_OFFSET};
use super::input::{IgiInput, IgiOptions};
use crate::brdf::ShadingFrame;
use crate::render::Ray;

/// The direct light of one source at a sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct LightTerm {
    /// Index of the light.
    pub light: usize,
    /// Unit direction toward the light, local frame.
    pub wi: Vector3<f64>,
    /// Irradiance on the surface from this light, `I cos θi / d²` per channel, W·m⁻².
    pub irradiance: [f64; 3],
    /// Angle between the half vector and the normal, radians (0 at the mirror direction).
    pub delta: f64,
}

/// One pixel's observation of a surface point.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Observation {
    /// Surface index.
    pub surface: usize,
    /// Triangle index.
    pub triangle: usize,
    /// Radiosity cell.
    pub cell: usize,
    /// The point, world frame.
    pub point: Vector3<f64>,
    /// Shading frame on the side the camera sees.
    pub frame: ShadingFrame,
    /// Unit direction toward the camera, local frame.
    pub wo: Vector3<f64>,
    /// Measured radiance per channel.
    pub radiance: [f64; 3],
    /// Index of the view.
    pub view: usize,
    /// Column and row of the pixel among the view's pixels used (every
    /// `pixel_stride`-th).
    pub pixel: [usize; 2],
    /// Direct light from each visible source.
    pub lights: Vec<LightTerm>,
    /// Direct irradiance, the sum of the terms.
    pub e_direct: [f64; 3],
    /// Side of the pixel's patch on the surface, metres: distance × pixel
    /// angle (× stride) / √cos θ (the geometric mean of its two sides).
    pub footprint_m: f64,
}

/// Why pixels were not used, per view.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct DroppedPixels {
    /// Masked out.
    pub masked: usize,
    /// The ray met a bulb first.
    pub light_in_view: usize,
    /// The ray left the scene.
    pub no_surface: usize,
    /// Seen more grazing than `max_view_angle_rad`.
    pub grazing: usize,
    /// Used.
    pub used: usize,
}

/// Pixels whose centre ray passes within this many pixels of a bulb's disc
/// are dropped with those whose centre ray meets it: a pixel is an area
/// (its corners 0.71 px from its centre), and one that covers part of a
/// bulb (a real camera's, a supersampled render's, or one whose centre ray
/// the renderer's slightly different projection sends onto the bulb) holds
/// the bulb's radiance, hundreds of times the wall's. On a RADIANCE room at
/// 64×64, four such pixels in 16 000 took a wall's lobe away and put its ρd
/// 16 % high. 1.5 px was too wide: on the simulated room it dropped the
/// metal sphere's limb beside a bulb (its ρd 8.3 % off, 2.2 % at 0.75 px).
pub const BULB_MARGIN_PX: f64 = 0.75;

/// The direct light terms at `point` (frame `frame`), shadow-tested.
pub(crate) fn light_terms(
    geometry: &Geometry,
    input: &IgiInput,
    point: &Vector3<f64>,
    frame: &ShadingFrame,
    wo: Option<&Vector3<f64>>,
) -> Vec<LightTerm> {
    let origin = point + frame.normal * SURFACE_OFFSET * (1.0 + point.norm());
    let mut terms = Vec::with_capacity(input.lights.len());
    for (i, l) in input.lights.iter().enumerate() {
        let to = l.position - origin;
        let d2 = to.norm_squared();
        let d = d2.sqrt();
        if !(d > l.radius && d > 0.0) {
            continue;
        }
        let w = to / d;
        let cos = w.dot(&frame.normal);
        if cos <= 0.0 || geometry.occluded(&Ray { origin, direction: w }, d - l.radius) {
            continue;
        }
        let wi = frame.to_local(&w);
        let delta = wo.map_or(0.0, |wo| {
            let h = (wi + wo).normalize();
            h.z.clamp(-1.0, 1.0).acos()
        });
        terms.push(LightTerm {
            light: i,
            wi,
            irradiance: l.intensity.map(|v| v * cos / d2),
            delta,
        });
    }
    terms
}

/// Every usable pixel of every view, and the per-view drop counts.
pub(crate) fn observations(
    geometry: &Geometry,
    input: &IgiInput,
    options: &IgiOptions,
) -> (Vec<Observation>, Vec<DroppedPixels>) {
    let cos_max = options.max_view_angle_rad.cos();
    let stride = options.pixel_stride;
    let mut all = Vec::new();
    let mut dropped = Vec::new();
    for (vi, view) in input.views.iter().enumerate() {
        let cam = &view.camera;
        let rows: Vec<(Vec<Observation>, DroppedPixels)> = (0..cam.height)
            .step_by(stride)
            .collect::<Vec<_>>()
            .par_iter()
            .map(|&y| {
                let pixel_rad = cam.vfov_rad / cam.height as f64;
                let mut obs = Vec::new();
                let mut d = DroppedPixels::default();
                for x in (0..cam.width).step_by(stride) {
                    if view.mask.as_ref().is_some_and(|m| !m[y * cam.width + x]) {
                        d.masked += 1;
                        continue;
                    }
                    let direction = cam.direction(x as f64 + 0.5, y as f64 + 0.5);
                    let ray = Ray {
                        origin: cam.position,
                        direction,
                    };
                    let hit = geometry.intersect(&ray, f64::INFINITY);
                    let limit = hit.map_or(f64::INFINITY, |h| h.t);
                    let bulb = input.lights.iter().any(|l| {
                        l.radius > 0.0 && {
                            let oc = cam.position - l.position;
                            // The bulb widened by BULB_MARGIN_PX pixels at its distance.
                            let r = l.radius + BULB_MARGIN_PX * pixel_rad * oc.norm();
                            let b = oc.dot(&direction);
                            let c = oc.norm_squared() - r * r;
                            let disc = b * b - c;
                            disc >= 0.0 && (-b + disc.sqrt()) > 0.0 && (-b - disc.sqrt()) < limit
                        }
                    });
                    if bulb {
                        d.light_in_view += 1;
                        continue;
                    }
                    let Some(hit) = hit else {
                        d.no_surface += 1;
                        continue;
                    };
                    let frame = geometry.frame(hit.triangle, &-direction);
                    let wo = frame.to_local(&-direction);
                    if wo.z < cos_max {
                        d.grazing += 1;
                        continue;
                    }
                    let lights = light_terms(geometry, input, &hit.point, &frame, Some(&wo));
                    let mut e_direct = [0.0; 3];
                    for t in &lights {
                        for c in 0..3 {
                            e_direct[c] += t.irradiance[c];
                        }
                    }
                    d.used += 1;
                    obs.push(Observation {
                        surface: geometry.triangles()[hit.triangle].surface as usize,
                        triangle: hit.triangle,
                        cell: geometry.cell(hit.triangle, &hit.point),
                        point: hit.point,
                        frame,
                        wo,
                        radiance: [0, 1, 2].map(|c| f64::from(view.image.radiance(x, y, c))),
                        view: vi,
                        pixel: [x / stride, y / stride],
                        lights,
                        e_direct,
                        footprint_m: (hit.point - cam.position).norm() * pixel_rad * stride as f64 / wo.z.sqrt(),
                    });
                }
                (obs, d)
            })
            .collect();
        let mut total = DroppedPixels::default();
        for (obs, d) in rows {
            all.extend(obs);
            total.masked += d.masked;
            total.light_in_view += d.light_in_view;
            total.no_surface += d.no_surface;
            total.grazing += d.grazing;
            total.used += d.used;
        }
        dropped.push(total);
    }
    (all, dropped)
}

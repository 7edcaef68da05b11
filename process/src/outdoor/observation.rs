//! What the photographs say about each cell (thesis §5.4: "each grid point
//! is projected onto the photographs to which it is visible and a radiance
//! value is taken from each photograph").
//!
//! Every valid pixel of every photo is traced through its centre. Where it
//! meets a target cell on the cell's visible side, it contributes its
//! radiance to that cell's observation in that photo, with a weight:
//! - the cosine of the viewing angle (grazing views blur the texture);
//! - the distance from the image border, ramping from 0 at the edge to 1
//!   at [`BORDER_RAMP`] of the shorter side (vignetting, distortion);
//! - zero within [`MIRROR_EXCLUSION_DEG`] of the sun's mirror direction.
//!
//! A pixel's radiance is the mean over its whole footprint (the camera
//! integrates over the pixel), so the footprint must lie on the cell it is
//! credited to: rays through the pixel's four corners must meet the same
//! face, and with [`Footprint::Square`] the same lattice square. A pixel
//! straddling a building edge otherwise mixes a sunlit wall into a shaded
//! one (measured on the simulated campanile: corner cells 2× too bright),
//! and one straddling two cells blurs the texture across them.
//!
//! Sunlit or shadowed is decided by the sun-visibility test, not by hand: a
//! shadow ray toward the disc's centre from the points seen through the
//! four pixel corners. Pixels whose four answers disagree straddle a shadow
//! edge and are dropped; pixels that agree go to the cell's sunlit or its
//! shadowed observation for that photo.

use std::collections::HashMap;

use rayon::prelude::*;

use super::OutdoorError;
use super::cell_irradiance::sun_visible;
use super::grid::Grid;
use super::photo::{Illumination, Photo};
use crate::render::Scene;

/// Fraction of the shorter image side over which the border weight ramps up.
pub const BORDER_RAMP: f64 = 0.08;

/// Views within this angle of the sun's mirror direction are excluded, degrees.
pub const MIRROR_EXCLUSION_DEG: f64 = 10.0;

/// Views more grazing than this (cosine of the viewing angle) are dropped.
pub const MIN_VIEW_COSINE: f64 = 0.1;

/// Where a pixel's footprint must lie for the pixel to be used.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Footprint {
    /// Only the centre ray is checked (the pixel may straddle faces).
    Centre,
    /// All four corners on the centre's face.
    Face,
    /// All four corners in the centre's lattice square of the centre's face.
    Square,
}

/// Inset of the corner rays from the pixel's corners, pixels (a ray
/// exactly on the corner would land on the neighbour as often as not).
const CORNER_INSET: f64 = 0.02;

/// One photo's measurement of one cell in one lighting state.
#[derive(Debug, Clone, PartialEq)]
pub struct Observation {
    /// The cell.
    pub cell: usize,
    /// The photo (index into the photos given).
    pub photo: usize,
    /// The time (index into the illuminations given).
    pub time: usize,
    /// Whether the sun was seen from the cell's pixels.
    pub sunlit: bool,
    /// Weighted mean radiance, W·m⁻²·sr⁻¹ per channel.
    pub radiance: [f64; 3],
    /// Sum of pixel weights.
    pub weight: f64,
    /// Pixels averaged.
    pub pixels: usize,
}

/// Pixels dropped, by reason, over all photos.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SamplingReport {
    /// Pixels that met a target cell and were used.
    pub used: usize,
    /// Pixels straddling a shadow edge.
    pub shadow_edge: usize,
    /// Pixels near the sun's mirror direction.
    pub mirror: usize,
    /// Pixels seeing a target too obliquely.
    pub grazing: usize,
    /// Pixels with a non-finite or negative radiance.
    pub invalid: usize,
    /// Pixels whose footprint leaves the face or cell of their centre ([`Footprint`]).
    pub mixed: usize,
}

struct Acc {
    sum: [f64; 3],
    weight: f64,
    pixels: usize,
}

/// The observations of every target cell in `photos`; `times[k]` is the
/// index into `lights` of photo k's time; pixels whose footprint is not
/// within `footprint` of their centre's cell are dropped.
pub fn observe(
    scene: &Scene,
    grid: &Grid,
    photos: &[Photo],
    lights: &[Illumination],
    times: &[usize],
    footprint: Footprint,
) -> Result<(Vec<Observation>, SamplingReport), OutdoorError> {
    for (k, p) in photos.iter().enumerate() {
        let (w, h) = (p.image.width, p.image.height);
        if p.image.data.len() != w * h * 3 || w == 0 || h == 0 {
            return Err(OutdoorError::ImageSize {
                photo: p.label.clone(),
                width: w,
                height: h,
                values: p.image.data.len(),
            });
        }
        if let Some(m) = &p.mask
            && m.len() != w * h
        {
            return Err(OutdoorError::MaskSize {
                photo: p.label.clone(),
                expected: w * h,
                got: m.len(),
            });
        }
        if times.get(k).is_none_or(|&t| t >= lights.len()) {
            return Err(OutdoorError::NoIllumination {
                photo: p.label.clone(),
                time: p.time,
            });
        }
    }
    let per_photo: Vec<(Vec<Observation>, SamplingReport)> = photos
        .par_iter()
        .enumerate()
        .map(|(k, p)| observe_photo(scene, grid, p, k, times[k], &lights[times[k]], footprint))
        .collect();
    let mut all = Vec::new();
    let mut report = SamplingReport::default();
    for (obs, r) in per_photo {
        all.extend(obs);
        report.used += r.used;
        report.shadow_edge += r.shadow_edge;
        report.mirror += r.mirror;
        report.grazing += r.grazing;
        report.invalid += r.invalid;
        report.mixed += r.mixed;
    }
    Ok((all, report))
}

fn observe_photo(
    scene: &Scene,
    grid: &Grid,
    photo: &Photo,
    index: usize,
    time: usize,
    light: &Illumination,
    footprint: Footprint,
) -> (Vec<Observation>, SamplingReport) {
    let (w, h) = (photo.image.width, photo.image.height);
    let sun = light.sky.sun();
    let ramp = BORDER_RAMP * w.min(h) as f64;
    let mirror_cos = MIRROR_EXCLUSION_DEG.to_radians().cos();
    let mut acc: HashMap<(usize, bool), Acc> = HashMap::new();
    let mut report = SamplingReport::default();
    for y in 0..h {
        for x in 0..w {
            if photo.mask.as_ref().is_some_and(|m| !m[y * w + x]) {
                continue;
            }
            let (u, v) = (x as f64 + 0.5, y as f64 + 0.5);
            let Some(ray) = photo.rig.ray(u, v) else { continue };
            let Some(hit) = scene.intersect(&ray, f64::INFINITY) else {
                continue;
            };
            let Some(n) = grid.visible_normal(scene, hit.triangle) else {
                continue;
            };
            let Some(cell) = grid.cell_at(scene, hit.triangle, &hit.point) else {
                continue;
            };
            let to_camera = -ray.direction;
            let cos_view = n.dot(&to_camera);
            if cos_view < MIN_VIEW_COSINE {
                report.grazing += 1;
                continue;
            }
            // The points seen through the footprint's corners.
            let (lo, hi) = (CORNER_INSET, 1.0 - CORNER_INSET);
            let face = grid.face_of(hit.triangle);
            let lattice = grid.cells[cell].lattice;
            let mut corners = Vec::with_capacity(4);
            for (du, dv) in [(lo, lo), (hi, lo), (lo, hi), (hi, hi)] {
                let Some(hh) = photo
                    .rig
                    .ray(x as f64 + du, y as f64 + dv)
                    .and_then(|r| scene.intersect(&r, f64::INFINITY))
                else {
                    continue;
                };
                corners.push(hh);
            }
            let pure = match footprint {
                Footprint::Centre => true,
                Footprint::Face => corners.len() == 4 && corners.iter().all(|h| grid.face_of(h.triangle) == face),
                Footprint::Square => {
                    corners.len() == 4
                        && corners.iter().all(|h| {
                            grid.face_of(h.triangle) == face
                                && grid
                                    .nearest_cell(scene, h.triangle, &h.point)
                                    .is_some_and(|c| grid.cells[c].lattice == lattice)
                        })
                }
            };
            if !pure {
                report.mixed += 1;
                continue;
            }
            let l = [0, 1, 2].map(|c| f64::from(photo.image.radiance(x, y, c)));
            if l.iter().any(|v| !v.is_finite() || *v < 0.0) {
                report.invalid += 1;
                continue;
            }
            let sunlit = match &sun {
                Some(s) if n.dot(&s.direction) > 0.0 => {
                    let mirror = n * (2.0 * n.dot(&s.direction)) - s.direction;
                    if mirror.dot(&to_camera) > mirror_cos {
                        report.mirror += 1;
                        continue;
                    }
                    let mut seen = 0;
                    let mut asked = 0;
                    for hh in corners.iter().chain(std::iter::once(&hit)) {
                        let nn = grid.visible_normal(scene, hh.triangle).unwrap_or(n);
                        asked += 1;
                        if sun_visible(scene, s, &hh.point, &nn) {
                            seen += 1;
                        }
                    }
                    if seen > 0 && seen < asked {
                        report.shadow_edge += 1;
                        continue;
                    }
                    seen > 0
                }
                _ => false,
            };
            let border = [u, w as f64 - u, v, h as f64 - v]
                .into_iter()
                .fold(f64::INFINITY, f64::min);
            let weight = cos_view * (border / ramp).clamp(0.0, 1.0);
            if weight <= 0.0 {
                continue;
            }
            report.used += 1;
            let a = acc.entry((cell, sunlit)).or_insert(Acc {
                sum: [0.0; 3],
                weight: 0.0,
                pixels: 0,
            });
            for c in 0..3 {
                a.sum[c] += weight * l[c];
            }
            a.weight += weight;
            a.pixels += 1;
        }
    }
    let mut obs: Vec<Observation> = acc
        .into_iter()
        .map(|((cell, sunlit), a)| Observation {
            cell,
            photo: index,
            time,
            sunlit,
            radiance: a.sum.map(|s| s / a.weight),
            weight: a.weight,
            pixels: a.pixels,
        })
        .collect();
    obs.sort_by_key(|o| (o.cell, o.sunlit));
    (obs, report)
}

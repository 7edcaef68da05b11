//! `campanile demo --held-out-budget`: where the held-out re-render's error
//! comes from, one term at a time, against the simulator's truth (a
//! diagnostic, not part of the station's method).
//!
//! For each held-out view it renders the simulator's view again: twice at
//! the photographs' own samples per pixel with other seeds (the
//! photographs' Monte Carlo noise, which a real camera does not have), and
//! once at many samples (a nearly noise-free reference `R`). Then it
//! compares, over the held-out comparison's own mask and 4 × 4 blocks:
//!
//! - the re-render under the predicted light against the HDR measurement
//!   (the figure `process` reports);
//! - the measurement against `R` scaled by the radiance gauge `s` (the
//!   HDR map's units against the simulator's: least squares over the mask):
//!   the photograph's noise plus the HDR merge;
//! - the re-render under the predicted light, the held-out time's own
//!   measured light, and the true light, against `R` (`s · R` in gauge
//!   units): the method's error without the photograph's noise, and the
//!   share of the light's prediction;
//! - the re-render under the true light with the true albedos averaged per
//!   cell: the pseudo-albedo model's own floor (cells, bilinear
//!   interpolation, one bounce, the grid's irradiance);
//! - the re-render at 4 × 4 rays per pixel: its own sampling.

use crate::Result;
use anyhow::anyhow;
use campanile_process::camera::image::RadianceImage;
use campanile_process::outdoor::{CellStatus, Illumination, Reflectance, RerenderSettings, rerender};
use campanile_process::pipeline::{measured_sky, predicted_sky};
use campanile_process::render::{CameraRig, RenderSettings, Scene, render};
use campanile_process::report::{Section, Table};
use campanile_process::sun::sun_position;
use campanile_sim::world::World;

use crate::process::outdoor_stage::rig_of;
use crate::process::{Outdoor, Processed};
use campanile_process::outdoor::novel_view::block_rmse;

/// One term of the budget for one view: relative RMSE per pixel and per 4 × 4 block.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Term {
    pub view: String,
    pub term: String,
    pub pixel: f64,
    pub block: f64,
}

fn scaled(img: &RadianceImage, s: f64) -> RadianceImage {
    RadianceImage {
        width: img.width,
        height: img.height,
        data: img.data.iter().map(|&v| (f64::from(v) * s) as f32).collect(),
    }
}

/// Least-squares gauge `s` with `meas ≈ s · reference` over the mask.
fn gauge(meas: &RadianceImage, reference: &RadianceImage, mask: &[bool]) -> f64 {
    let (mut num, mut den) = (0.0, 0.0);
    for (i, _) in mask.iter().enumerate().filter(|(_, m)| **m) {
        for c in 0..3 {
            let a = f64::from(meas.data[3 * i + c]);
            let b = f64::from(reference.data[3 * i + c]);
            num += a * b;
            den += b * b;
        }
    }
    if den > 0.0 { num / den } else { 1.0 }
}

fn term(view: &str, name: &str, a: &RadianceImage, b: &RadianceImage, mask: &[bool], factor: f64) -> Term {
    Term {
        view: view.to_owned(),
        term: name.to_owned(),
        pixel: campanile_process::outdoor::rerender::relative_rmse(a, b, mask).unwrap_or(f64::NAN) * factor,
        block: block_rmse(a, b, mask, 4).map_or(f64::NAN, |(r, _)| r) * factor,
    }
}

/// The reflectance with every seen cell's ρ^sun and ρ^se replaced by the
/// world's albedo averaged over 16 × 16 points of the cell.
fn true_reflectance(scene: &Scene, refl: &Reflectance, world: &World) -> Reflectance {
    let mut out = refl.clone();
    for (k, est) in out.cells.iter_mut().enumerate() {
        if est.status == CellStatus::Unseen {
            continue;
        }
        let cell = &refl.grid.cells[k];
        let pts = refl.grid.cell_points(scene, k, 16);
        if pts.is_empty() {
            continue;
        }
        let mut m = [0.0; 3];
        for p in &pts {
            let a = world.pseudo_albedos(cell.triangle, [p.x, p.y, p.z]).sky_environment;
            (0..3).for_each(|c| m[c] += a[c] / pts.len() as f64);
        }
        est.rho_se = m;
        est.rho_sun = m;
    }
    out
}

/// The simulator's render of `rig` at `time` with `spp` paths per pixel.
fn simulate(
    world: &World,
    rig: &CameraRig,
    time: chrono::DateTime<chrono::Utc>,
    spp: u32,
    bounces: u32,
    seed: u64,
) -> Result<RadianceImage> {
    let daylight = world
        .daylight(time)
        .map_err(|e| anyhow!("{e}"))?
        .ok_or_else(|| anyhow!("the world has no daylight"))?;
    let lighting = campanile_process::render::Lighting {
        sky: Some(&daylight),
        points: &[],
        spheres: &[],
    };
    Ok(render(
        &world.scene.scene,
        rig,
        &lighting,
        &RenderSettings {
            samples_per_pixel: spp,
            max_bounces: bounces,
            seed,
            ..RenderSettings::default()
        },
    ))
}

/// The floor of the held-out comparison: the relative RMSE (per pixel, per
/// 4 × 4 block, over the comparison's mask) of one simulated photograph's
/// Monte Carlo noise at the capture's `photo_spp` and `bounces`, from two
/// renders of each held-out view with other seeds (their difference / √2).
/// A real camera has no such noise; no re-render can beat it here.
pub fn photo_floor(p: &Processed, o: &Outdoor, world: &World, photo_spp: u32, bounces: u32) -> Result<Vec<Term>> {
    o.products
        .held_out
        .iter()
        .map(|v| {
            let g = group_of(p, &v.label)?;
            let rig = rig_of(p, g);
            let a = simulate(world, &rig, g.time, photo_spp, bounces, 0xA11CE)?;
            let b = simulate(world, &rig, g.time, photo_spp, bounces, 0xB0B)?;
            Ok(term(
                &v.label,
                &format!("photo noise: two {photo_spp}-spp simulator renders, /√2"),
                &a,
                &b,
                &v.mask,
                std::f64::consts::FRAC_1_SQRT_2,
            ))
        })
        .collect()
}

/// The merged group of held-out view `label`.
fn group_of<'a>(p: &'a Processed, label: &str) -> Result<&'a campanile_process::pipeline::MergedGroup> {
    p.merged
        .iter()
        .find(|g| g.key == label)
        .ok_or_else(|| anyhow!("held-out view {label} not among the merged groups").into())
}

/// Per view, the least-squares gauge of the HDR map against the simulator's radiance.
pub type Gauges = Vec<(String, f64)>;

/// The budget of every held-out view. `photo_spp` and `bounces` are the
/// capture's; `reference_spp` the reference's samples per pixel.
pub fn budget(
    p: &Processed,
    o: &Outdoor,
    world: &World,
    photo_spp: u32,
    bounces: u32,
    reference_spp: u32,
) -> Result<(Vec<Term>, Gauges)> {
    let scene = &o.scene.scene;
    let refl = &o.products.reflectance;
    let truth_refl = true_reflectance(scene, refl, world);
    let mut terms = Vec::new();
    let mut gauges = Vec::new();
    for v in &o.products.held_out {
        let g = group_of(p, &v.label)?;
        let rig = rig_of(p, g);
        let daylight = world
            .daylight(g.time)
            .map_err(|e| anyhow!("{e}"))?
            .ok_or_else(|| anyhow!("the world has no daylight"))?;
        let sim = |spp: u32, seed: u64| simulate(world, &rig, g.time, spp, bounces, seed);
        let mask = &v.mask;
        let name = v.label.as_str();
        terms.push(term(
            name,
            "reported: re-render (predicted light, photos' texture) vs HDR photo",
            &v.rendered,
            &v.measured,
            mask,
            1.0,
        ));
        let (a, b) = (sim(photo_spp, 0xA11CE)?, sim(photo_spp, 0xB0B)?);
        terms.push(term(
            name,
            &format!("photo noise: two {photo_spp}-spp simulator renders, /√2"),
            &a,
            &b,
            mask,
            std::f64::consts::FRAC_1_SQRT_2,
        ));
        let reference = sim(reference_spp, 0xC0FFEE)?;
        let s = gauge(&v.measured, &reference, mask);
        gauges.push((name.to_owned(), s));
        let gauge_ref = scaled(&reference, s);
        terms.push(term(
            name,
            &format!("HDR photo vs {reference_spp}-spp reference × gauge"),
            &v.measured,
            &gauge_ref,
            mask,
            1.0,
        ));
        terms.push(term(
            name,
            "re-render (predicted light, photos' texture) vs reference × gauge",
            &v.rendered,
            &gauge_ref,
            mask,
            1.0,
        ));
        let (grid_only, _) = rerender(
            scene,
            refl,
            &rig,
            &Illumination {
                time: g.time,
                sky: &predicted_sky(
                    &p.light,
                    &sun_position(g.time, &p.optics.observer, p.optics.delta_t_s).map_err(|e| anyhow!("{e}"))?,
                )?,
            },
            &RerenderSettings::default(),
        );
        terms.push(term(
            name,
            "re-render (predicted light, grid alone) vs reference × gauge",
            &grid_only,
            &gauge_ref,
            mask,
            1.0,
        ));
        let sun = sun_position(g.time, &p.optics.observer, p.optics.delta_t_s).map_err(|e| anyhow!("{e}"))?;
        let predicted = predicted_sky(&p.light, &sun)?;
        let fine = RerenderSettings {
            samples_per_side: 4,
            ..RerenderSettings::default()
        };
        let (r4, _) = rerender(
            scene,
            refl,
            &rig,
            &Illumination {
                time: g.time,
                sky: &predicted,
            },
            &fine,
        );
        terms.push(term(
            name,
            "re-render 4×4 rays/pixel (predicted) vs reference × gauge",
            &r4,
            &gauge_ref,
            mask,
            1.0,
        ));
        if let Some(Ok(mut own)) = p.light.iter().find(|l| l.occurrence == g.occurrence).map(measured_sky) {
            own.sun_direction = sun.direction();
            let (r, _) = rerender(
                scene,
                refl,
                &rig,
                &Illumination {
                    time: g.time,
                    sky: &own,
                },
                &RerenderSettings::default(),
            );
            terms.push(term(
                name,
                "re-render (held-out time's measured light) vs reference × gauge",
                &r,
                &gauge_ref,
                mask,
                1.0,
            ));
        }
        let true_light = Illumination {
            time: g.time,
            sky: &daylight,
        };
        let (r, _) = rerender(scene, refl, &rig, &true_light, &RerenderSettings::default());
        terms.push(term(
            name,
            "re-render (true light) vs reference",
            &r,
            &reference,
            mask,
            1.0,
        ));
        let (r, _) = rerender(scene, &truth_refl, &rig, &true_light, &RerenderSettings::default());
        terms.push(term(
            name,
            "re-render (true light, true cell albedos) vs reference",
            &r,
            &reference,
            mask,
            1.0,
        ));
    }
    Ok((terms, gauges))
}

/// The budget as a report section.
pub fn section(terms: &[Term], gauges: &[(String, f64)]) -> Section {
    Section {
        title: "Held-out error budget (diagnostic)".into(),
        paragraphs: vec![
            "Each term compares two images over the held-out comparison's mask: relative RMSE per pixel and of 4 × 4-pixel block means. The reference is the simulator's render of the same view at many samples per pixel; the gauge scales it to the HDR maps' units.".into(),
            gauges
                .iter()
                .map(|(v, s)| format!("{v}: gauge {s:.4}"))
                .collect::<Vec<_>>()
                .join("; "),
        ],
        tables: vec![Table {
            caption: "Terms".into(),
            header: vec!["view".into(), "term".into(), "per pixel".into(), "per 4×4 block".into()],
            rows: terms
                .iter()
                .map(|t| {
                    vec![
                        t.view.clone(),
                        t.term.clone(),
                        format!("{:.2}%", 100.0 * t.pixel),
                        format!("{:.2}%", 100.0 * t.block),
                    ]
                })
                .collect(),
        }],
        figures: Vec::new(),
    }
}

/// The held-out comparison beside its floor, as a report section.
pub fn floor_section(o: &Outdoor, floor: &[Term]) -> Section {
    Section {
        title: "Held-out comparison against its floor".into(),
        paragraphs: vec![
            "The floor is one simulated photograph's own Monte Carlo noise (two renders of the view with other seeds at the capture's samples per pixel, their difference / √2), over the comparison's mask: the simulator's artefact, which a real camera does not have, and which no re-render can beat.".into(),
        ],
        tables: vec![Table {
            caption: "Relative RMSE of the re-render against the HDR photograph, and the floor".into(),
            header: vec![
                "view".into(),
                "re-render, per pixel".into(),
                "floor, per pixel".into(),
                "re-render, per 4×4 block".into(),
                "floor, per 4×4 block".into(),
            ],
            rows: o
                .products
                .held_out
                .iter()
                .zip(floor)
                .map(|(v, f)| {
                    vec![
                        v.label.clone(),
                        format!("{:.2}%", 100.0 * v.rmse_pixel),
                        format!("{:.2}%", 100.0 * f.pixel),
                        format!("{:.2}%", 100.0 * v.rmse_block),
                        format!("{:.2}%", 100.0 * f.block),
                    ]
                })
                .collect(),
        }],
        figures: Vec::new(),
    }
}

//! Outdoor reflectance on plain files (thesis ch. 5), as `campanile
//! outdoor recover|render` runs it: pseudo-albedos from posed HDR
//! photographs under a known sun and sky, with their files and verdicts,
//! and views at new times rendered from them and compared with photographs.

use std::path::{Path, PathBuf};

use anyhow::{Context, anyhow};
use campanile_process::outdoor::light_file::{TimeLight, load_light};
use campanile_process::outdoor::novel_view::{ViewComparison, compare_view, render_view};
use campanile_process::outdoor::photo_file::{PosedView, load_photos};
use campanile_process::outdoor::rerender::{Reference, RerenderSettings};
use campanile_process::outdoor::scene_file::{OutdoorScene, load_scene};
use campanile_process::outdoor::texture_transfer::texture_sources;
use campanile_process::outdoor::{
    CellStatus, Illumination, Photo, Reflectance, ReflectanceSettings, recover_reflectance,
};
use campanile_process::quality::{ProductQuality, Quality, QualityReport, gates};
use serde::{Deserialize, Serialize};

use crate::progress::bar;
use crate::{Error, Result};

/// What `outdoor recover` takes.
#[derive(Debug, Clone)]
pub struct RecoverOptions {
    /// The scene description (RON).
    pub scene: PathBuf,
    /// The photographs (RON).
    pub photos: PathBuf,
    /// The sun and sky at each photo's time (RON).
    pub light: PathBuf,
    /// Output directory.
    pub out: PathBuf,
    /// The side of the grid's cells on the surfaces, metres.
    pub grid_spacing: f64,
    /// The quality thresholds.
    pub thresholds: Quality,
}

/// What a recovery made (its files are written, but for `quality.json`).
pub struct Recovered {
    /// The scene.
    pub scene: OutdoorScene,
    /// The pseudo-albedos.
    pub reflectance: Reflectance,
    /// Photos used.
    pub photos: usize,
    /// Distinct light times used.
    pub times: usize,
    /// The solver's time, seconds.
    pub seconds: f64,
    /// `albedo/materials.ron`.
    pub materials: PathBuf,
    /// The verdicts: each sky used, then the pseudo-albedos.
    pub quality: QualityReport,
}

/// What `outdoor render` takes.
#[derive(Debug, Clone)]
pub struct RenderOptions {
    /// The directory `outdoor recover` wrote.
    pub recovered: PathBuf,
    /// The views to render (RON, the photos format; images optional).
    pub photos: PathBuf,
    /// The sun and sky at each view's time (RON).
    pub light: PathBuf,
    /// Output directory.
    pub out: PathBuf,
    /// The scene description, instead of the one recovery.json names.
    pub scene: Option<PathBuf>,
    /// The grid's pseudo-albedos alone.
    pub grid_only: bool,
    /// Rays per pixel side.
    pub pixel_samples: Option<u16>,
    /// The quality thresholds.
    pub thresholds: Quality,
}

/// One rendered view.
pub struct RenderedView {
    /// The photo's label.
    pub label: String,
    /// Training photos that lent it texture.
    pub references: usize,
    /// The comparison with its photograph, if it has one.
    pub compared: Option<ViewComparison>,
}

/// What a render made (its files are written, but for `quality.json`).
pub struct Rendered {
    /// Each view, in the photos file's order.
    pub views: Vec<RenderedView>,
    /// The verdicts of the views compared with photographs.
    pub quality: QualityReport,
}

/// What `outdoor render` needs of a recovery: `RECOVERED/recovery.json`.
#[derive(Debug, Serialize, Deserialize)]
struct Recovery {
    scene: PathBuf,
    photos: PathBuf,
    light: PathBuf,
    grid_spacing_m: f64,
    /// Photos the fit left out as outliers (they lend no texture).
    outliers: Vec<String>,
}

/// The light of each photo's time, within the solver's tolerance.
fn illuminations<'a>(views: &[PosedView], lights: &'a [TimeLight], light_file: &Path) -> Result<Vec<&'a TimeLight>> {
    let tolerance = ReflectanceSettings::default().time_tolerance_s;
    views
        .iter()
        .map(|v| {
            lights
                .iter()
                .min_by_key(|l| (l.time - v.time).num_milliseconds().abs())
                .filter(|l| ((l.time - v.time).num_milliseconds().abs() as f64) <= 1e3 * tolerance)
                .ok_or_else(|| {
                    Error::input(format!(
                        "photo {}: {} has no light within {tolerance} s of {} (it has: {})",
                        v.label,
                        light_file.display(),
                        v.time.to_rfc3339(),
                        lights
                            .iter()
                            .map(|l| l.time.to_rfc3339())
                            .collect::<Vec<_>>()
                            .join(", ")
                    ))
                })
        })
        .collect()
}

fn absolute(p: &Path) -> Result<PathBuf> {
    Ok(std::fs::canonicalize(p).with_context(|| format!("{}: cannot resolve", p.display()))?)
}

fn file_name(label: &str) -> String {
    label
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '@' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

pub fn recover(args: &RecoverOptions) -> Result<Recovered> {
    let q = &args.thresholds;
    let scene = load_scene(&args.scene)?;
    let views = load_photos(&args.photos)?;
    let lights = load_light(&args.light)?;
    for v in &views {
        if v.image.is_none() {
            return Err(Error::input(format!(
                "{}: photo {} has no image: recovery needs every photo's HDR radiance image",
                args.photos.display(),
                v.label
            )));
        }
    }
    let used = illuminations(&views, &lights, &args.light)?;
    let photos: Vec<Photo> = views.iter().filter_map(PosedView::photo).collect();
    // One illumination per light used, at its own time (photos match it within the tolerance).
    let mut light_set: Vec<&TimeLight> = Vec::new();
    for l in used {
        if !light_set.iter().any(|k| k.time == l.time) {
            light_set.push(l);
        }
    }
    let illum: Vec<Illumination> = light_set
        .iter()
        .map(|l| Illumination {
            time: l.time,
            sky: &l.sky,
        })
        .collect();
    let settings = ReflectanceSettings {
        spacing_m: args.grid_spacing,
        ..ReflectanceSettings::default()
    };
    let b = bar(1, "pseudo-albedos");
    let t = std::time::Instant::now();
    let (refl, _) = recover_reflectance(&scene.scene, &scene.targets, &photos, &illum, &settings)
        .map_err(|e| anyhow!("pseudo-albedos: {e}"))?;
    b.finish_and_clear();
    let seconds = t.elapsed().as_secs_f64();

    std::fs::create_dir_all(&args.out).with_context(|| format!("{}: cannot create", args.out.display()))?;
    let materials = campanile_process::outdoor::atlas::write_materials(&scene.scene, &refl, &args.out.join("albedo"))?;
    write_cells(&scene, &refl, &args.out)?;

    // Verdicts: each sky used, then the pseudo-albedos, which inherit them.
    let mut products: Vec<ProductQuality> = light_set
        .iter()
        .map(|l| {
            gates::sky(&format!("sky {}", l.time.to_rfc3339()), &l.channels, q)
                .with_note(format!("from {}", l.sky_source))
        })
        .collect();
    let mut albedo = gates::pseudo_albedos(&refl, q);
    for p in &products {
        albedo.inherit(p);
    }
    for l in &light_set {
        albedo = albedo.with_note(format!(
            "{}: sun irradiance {:?} W/m² ({}), its direction {}",
            l.time.to_rfc3339(),
            l.sky.measured.sun_irradiance,
            l.sun_source,
            l.sun_direction_source
        ));
    }
    for v in views.iter().filter(|v| v.bad_pixels > 0) {
        albedo = albedo.with_note(format!(
            "photo {}: {} pixels with a negative or non-finite channel left out",
            v.label, v.bad_pixels
        ));
    }
    products.push(albedo);
    let report = QualityReport::new(products, q);

    let outliers: Vec<String> = refl
        .photos
        .iter()
        .filter(|c| c.outlier)
        .map(|c| c.label.clone())
        .collect();
    let recovery = Recovery {
        scene: absolute(&args.scene)?,
        photos: absolute(&args.photos)?,
        light: absolute(&args.light)?,
        grid_spacing_m: args.grid_spacing,
        outliers,
    };
    crate::partial_file::write(
        &args.out.join("recovery.json"),
        serde_json::to_string_pretty(&recovery)
            .map_err(anyhow::Error::from)?
            .as_bytes(),
    )?;
    let json = serde_json::json!({
        "grid_spacing_m": refl.grid.spacing_m,
        "cells": refl.cells.len(),
        "status": {
            "solved": refl.count(CellStatus::Solved),
            "never_sunlit": refl.count(CellStatus::NeverSunlit),
            "never_shadowed": refl.count(CellStatus::NeverShadowed),
            "ill_conditioned": refl.count(CellStatus::IllConditioned),
            "unseen": refl.count(CellStatus::Unseen),
        },
        "photos": refl.photos.iter().map(|c| serde_json::json!({"photo": c.label, "observations": c.observations, "trimmed_mean_log_ratio": c.median_log_ratio, "outlier": c.outlier})).collect::<Vec<_>>(),
        "pixels": {"used": refl.sampling.used, "shadow_edge": refl.sampling.shadow_edge, "mirror": refl.sampling.mirror, "grazing": refl.sampling.grazing, "invalid": refl.sampling.invalid, "mixed": refl.sampling.mixed},
        "light": light_set.iter().map(|l| serde_json::json!({
            "time": l.time.to_rfc3339(),
            "sun_direction": l.sky.measured.sun_direction,
            "sun_direction_from": l.sun_direction_source,
            "sun_irradiance": l.sky.measured.sun_irradiance,
            "sun_irradiance_from": l.sun_source,
            "below_horizon": l.sky.below_horizon,
            "sky": l.sky_source,
        })).collect::<Vec<_>>(),
        "diagnostics": refl.diagnostics,
        "seconds": seconds,
    });
    crate::partial_file::write(
        &args.out.join("outdoor.json"),
        serde_json::to_string_pretty(&json)
            .map_err(anyhow::Error::from)?
            .as_bytes(),
    )?;

    Ok(Recovered {
        scene,
        reflectance: refl,
        photos: photos.len(),
        times: light_set.len(),
        seconds,
        materials,
        quality: report,
    })
}

/// `cells.csv` and `cell_points.csv`.
fn write_cells(scene: &OutdoorScene, refl: &Reflectance, out: &Path) -> Result<()> {
    use std::fmt::Write as _;
    let names = scene.scene.surfaces();
    let mut cells = String::from(
        "cell,surface,status,x,y,z,nx,ny,nz,area_m2,rho_sun_r,rho_sun_g,rho_sun_b,rho_se_r,rho_se_g,rho_se_b,\
         sigma_sun_g,sigma_se_g,rms_relative,observations\n",
    );
    let mut points = String::from("cell,x,y,z\n");
    for (k, (c, e)) in refl.grid.cells.iter().zip(&refl.cells).enumerate() {
        let status = match e.status {
            CellStatus::Solved => "solved",
            CellStatus::NeverSunlit => "never_sunlit",
            CellStatus::NeverShadowed => "never_shadowed",
            CellStatus::IllConditioned => "ill_conditioned",
            CellStatus::Unseen => "unseen",
            CellStatus::FromFile => "from_file",
        };
        let _ = writeln!(
            cells,
            "{k},{},{status},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{}",
            names[c.surface],
            c.centre.x,
            c.centre.y,
            c.centre.z,
            c.normal.x,
            c.normal.y,
            c.normal.z,
            c.area_m2,
            e.rho_sun[0],
            e.rho_sun[1],
            e.rho_sun[2],
            e.rho_se[0],
            e.rho_se[1],
            e.rho_se[2],
            e.sigma_sun[1],
            e.sigma_se[1],
            e.rms_relative,
            e.observations
        );
        // A sliver of a cell may hold none of the 4 × 4 sub-samples: its centroid then.
        let mut pts = refl.grid.cell_points(&scene.scene, k, 4);
        if pts.is_empty() {
            pts.push(c.centre);
        }
        for p in pts {
            let _ = writeln!(points, "{k},{:.6},{:.6},{:.6}", p.x, p.y, p.z);
        }
    }
    crate::partial_file::write(&out.join("cells.csv"), cells.as_bytes())?;
    crate::partial_file::write(&out.join("cell_points.csv"), points.as_bytes())
}

pub fn render(args: &RenderOptions) -> Result<Rendered> {
    let q = &args.thresholds;
    let record = args.recovered.join("recovery.json");
    let text = std::fs::read_to_string(&record).map_err(|e| {
        Error::input(format!(
            "{}: {e} (expected the output directory of `campanile outdoor recover`)",
            record.display()
        ))
    })?;
    let rec: Recovery = serde_json::from_str(&text).map_err(|e| {
        Error::input(format!(
            "{}: {e} (expected recovery.json as `outdoor recover` writes it)",
            record.display()
        ))
    })?;
    let scene = load_scene(args.scene.as_deref().unwrap_or(&rec.scene))?;
    let refl = campanile_process::outdoor::atlas::read_materials(
        &scene.scene,
        &args.recovered.join("albedo").join("materials.ron"),
    )?;
    let views = load_photos(&args.photos)?;
    let lights = load_light(&args.light)?;
    let used = illuminations(&views, &lights, &args.light)?;

    // The training photographs, as texture sources (§5.6.4).
    let (training, training_lights) = if args.grid_only {
        (Vec::new(), Vec::new())
    } else {
        let t =
            load_photos(&rec.photos).with_context(|| format!("the training photos named in {}", record.display()))?;
        let l = load_light(&rec.light).with_context(|| format!("the training light named in {}", record.display()))?;
        (t, l)
    };
    let training_used = if training.is_empty() {
        Vec::new()
    } else {
        illuminations(&training, &training_lights, &rec.light)?
    };
    let training_photos: Vec<Photo> = training
        .iter()
        .filter(|v| !rec.outliers.contains(&v.label))
        .filter_map(PosedView::photo)
        .collect();
    let training_illum: Vec<(chrono::DateTime<chrono::Utc>, Illumination)> = training
        .iter()
        .zip(&training_used)
        .map(|(v, l)| {
            (
                v.time,
                Illumination {
                    time: l.time,
                    sky: &l.sky,
                },
            )
        })
        .collect();
    let references: Vec<Reference> = training_photos
        .iter()
        .filter_map(|p| {
            training_illum
                .iter()
                .find(|(t, _)| *t == p.time)
                .map(|(_, light)| Reference { photo: p, light })
        })
        .collect();
    let defaults = RerenderSettings::default();
    let settings = RerenderSettings {
        samples_per_side: args.pixel_samples.map_or(defaults.samples_per_side, usize::from),
        ..defaults
    };
    let b = bar(views.len() as u64 + 1, "re-renders");
    let sources = texture_sources(&scene.scene, &refl, &references, &settings);
    b.inc(1);

    std::fs::create_dir_all(&args.out).with_context(|| format!("{}: cannot create", args.out.display()))?;
    let mut products = Vec::new();
    let mut views_out = Vec::new();
    let mut figures = Vec::new();
    for (v, l) in views.iter().zip(&used) {
        let light = Illumination {
            time: v.time,
            sky: &l.sky,
        };
        let view = render_view(&scene.scene, &refl, &v.rig, &light, &sources, &settings);
        let path = args.out.join(format!("{}.exr", file_name(&v.label)));
        crate::igi::write_exr(&view.rendered, &path)?;
        let mut entry = serde_json::json!({
            "view": v.label,
            "file": path.file_name().map(|f| f.to_string_lossy().into_owned()),
            "texture_references": view.references,
        });
        if let Some(measured) = &v.image {
            let c = compare_view(&scene.scene, &refl, &v.rig, &view, measured, v.mask.as_deref());
            entry["rmse_block_4x4"] = serde_json::json!(c.rmse_block);
            entry["rmse_block_4x4_grid_only"] = serde_json::json!(c.rmse_block_grid);
            entry["rmse_pixel"] = serde_json::json!(c.rmse_pixel);
            entry["blocks"] = serde_json::json!(c.blocks);
            products.push(gates::outdoor_render(&v.label, c.rmse_block, c.blocks, q));
            views_out.push(RenderedView {
                label: v.label.clone(),
                references: view.references,
                compared: Some(c),
            });
        } else {
            views_out.push(RenderedView {
                label: v.label.clone(),
                references: view.references,
                compared: None,
            });
        }
        figures.push(entry);
        b.inc(1);
    }
    b.finish_and_clear();
    crate::partial_file::write(
        &args.out.join("render.json"),
        serde_json::to_string_pretty(&serde_json::json!({"views": figures, "grid_only": args.grid_only}))
            .map_err(anyhow::Error::from)?
            .as_bytes(),
    )?;
    Ok(Rendered {
        views: views_out,
        quality: QualityReport::new(products, q),
    })
}

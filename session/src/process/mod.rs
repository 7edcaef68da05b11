//! A captured session to radiance, light and reflectance, with a
//! machine-readable summary of every figure (what `campanile process`
//! does on an outdoor or room session).

pub mod outdoor_report;
pub mod outdoor_stage;
pub mod report_sections;
pub mod room;
mod session_frames;

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use campanile_process::hdr::curve_plot::curve_plot_svg;
use campanile_process::hdr::debevec::DebevecOptions;
use campanile_process::pipeline::{
    MergedGroup, OccurrenceLight, Purpose, StationOptics, calibrate_response, group_frames, illumination, merge_groups,
};
use campanile_process::quality::{ProductQuality, Quality, gates};

use campanile_process::report::{Report, Section};
use campanile_process::sky::{ChannelSky, SkyFile};
use serde::Serialize;

use crate::progress::bar;
use crate::verdicts::thresholds;
use crate::{Error, Result};

pub use session_frames::SessionInputs;

/// What `process` measured, for `summary.json` and the report.
#[derive(Debug, Serialize)]
pub struct Summary {
    pub session: String,
    pub frames: usize,
    pub groups: usize,
    pub response: ResponseSummary,
    pub occurrences: Vec<OccurrenceSummary>,
    pub stage_seconds: Vec<(String, f64)>,
}

#[derive(Debug, Serialize)]
pub struct ResponseSummary {
    pub bracket: String,
    pub reason: String,
    pub residual_rms: [f64; 3],
    pub condition_estimate: [f64; 3],
}

#[derive(Debug, Serialize)]
pub struct OccurrenceSummary {
    pub occurrence: String,
    pub held_out: bool,
    pub time: String,
    pub sun_zenith_deg: f64,
    pub sun_azimuth_deg: f64,
    pub sun_irradiance: Option<[f64; 3]>,
    pub sun_triplet_spread: Option<[f64; 3]>,
    pub sky: Option<SkyFile>,
    pub environment_regions_seen: Option<usize>,
    pub notes: Vec<String>,
}

/// The products of stages 1 and 2, in memory, for the demo and the report.
pub struct Processed {
    pub inputs: SessionInputs,
    pub optics: StationOptics,
    pub calibration: campanile_process::hdr::debevec::Calibration,
    pub merged: Vec<MergedGroup>,
    pub light: Vec<OccurrenceLight>,
    pub summary: Summary,
    /// The thresholds, and the verdicts of the response, each radiance
    /// map and each occurrence's sun, sky and environment.
    pub thresholds: Quality,
    pub quality: Vec<ProductQuality>,
}

/// For a session made by `campanile session import`: each product's notes
/// say what it rests on that was estimated or stated rather than measured
/// (the camera from EXIF, the time from a stated clock offset, no sky
/// frames), from the session's import record.
pub fn note_import_estimates(session: &Path, quality: &mut Vec<ProductQuality>) -> Result<()> {
    let Some(record) =
        campanile_capture::import::record::ImportRecord::read(session).map_err(|e| Error::input(e.to_string()))?
    else {
        return Ok(());
    };
    let mut import = ProductQuality::new(format!("session import {}", record.folder), Vec::new());
    import.notes = record
        .estimated
        .iter()
        .map(|e| format!("estimated, not measured ({}): {}", e.what, e.how))
        .collect();
    for q in quality.iter_mut() {
        let notes: Vec<String> = record
            .estimates_for(&q.product)
            .map(|e| format!("estimated, not measured ({}): {}", e.what, e.how))
            .collect();
        q.notes.extend(notes);
    }
    quality.push(import);
    Ok(())
}

/// The pseudo-albedos' verdict: what they inherited from the response and
/// the training occurrences' sun and sky (the light they are divided by),
/// with the photos the outlier test dropped as notes.
pub fn outdoor_quality(p: &Processed, o: &Outdoor) -> ProductQuality {
    let mut q = ProductQuality::new("pseudo-albedos", Vec::new());
    let training: Vec<&str> = p
        .light
        .iter()
        .filter(|l| !l.held_out)
        .map(|l| l.occurrence.as_str())
        .collect();
    for upstream in &p.quality {
        let from_training = training
            .iter()
            .any(|occ| upstream.product == format!("sun {occ}") || upstream.product == format!("sky {occ}"));
        if upstream.product == "response" || from_training {
            q.inherit(upstream);
        }
    }
    for photo in o.products.reflectance.photos.iter().filter(|c| c.outlier) {
        q.notes.push(format!(
            "photo {} left out as an outlier (trimmed mean log ratio {:.3})",
            photo.label, photo.median_log_ratio
        ));
    }
    // Light estimated rather than measured is gated on its stated
    // uncertainty, so the pseudo-albedos are never `ok` in silence: the
    // model's scale is known to ±15% at best and the sky pixels' to their
    // spread, above the 2% the thesis's figures rest on, so with the
    // default gate they come out `poor`, the reason in the check.
    if let Some(worst) = o
        .products
        .estimated
        .iter()
        .map(|(_, e)| e.scale_uncertainty())
        .max_by(f64::total_cmp)
    {
        let check = campanile_process::quality::Check::new(
            format!(
                "relative uncertainty of the estimated light (sun or sky not measured at {} of the training times)",
                o.products.estimated.len()
            ),
            worst,
            p.thresholds.outdoor.estimated_light,
            campanile_process::quality::Better::Lower,
        );
        q.own_verdict = q.own_verdict.max(check.verdict);
        q.verdict = q.verdict.max(check.verdict);
        q.checks.push(check);
    }
    for (occ, e) in &o.products.estimated {
        q.notes.push(format!("light of {occ} estimated: {}", e.describe()));
        q.notes.extend(e.notes.iter().map(|n| format!("light of {occ}: {n}")));
    }
    for view in &o.products.predicted_from_model {
        q.notes.push(format!(
            "held-out view {view}: light predicted from the CIE clear-sky model scaled as the estimated training lights, not measured"
        ));
    }
    q
}

/// A zoom photograph's verdict: the share of its target pixels given
/// high-resolution pseudo-albedos (eq. 5.16), and its re-render with them
/// at its own time against the photograph; it inherits the pseudo-albedos'
/// verdict, which it scales.
pub fn zoom_quality(p: &Processed, z: &outdoor_stage::ZoomView, albedos: &ProductQuality) -> ProductQuality {
    let r = &z.albedo.report;
    let on_target = r.pixels - r.non_target;
    let coverage = if on_target == 0 {
        0.0
    } else {
        r.used as f64 / on_target as f64
    };
    let mut q = ProductQuality::new(
        format!("zoom {}", z.label),
        vec![
            campanile_process::quality::Check::new(
                format!(
                    "fraction of the {on_target} target pixels given eq. (5.16) pseudo-albedos ({} at a face's outline, {} at a shadow edge, {} invalid, {} dark)",
                    r.face_edge, r.shadow_edge, r.invalid_radiance, r.dark
                ),
                coverage,
                p.thresholds.outdoor.zoom_coverage,
                campanile_process::quality::Better::Higher,
            ),
            gates::outdoor_render(&z.label, z.rmse_block, z.blocks, &p.thresholds)
                .checks
                .remove(0),
        ],
    );
    q.notes.push(format!(
        "re-rendered at its own time under the {} light; with the grid's pseudo-albedos alone {:.1}% per 4x4 block, {:.1}% per pixel (with eq. 5.16 {:.1}%)",
        z.light,
        100.0 * z.rmse_block_grid,
        100.0 * z.rmse_pixel_grid,
        100.0 * z.rmse_pixel
    ));
    q.inherit(albedos);
    q
}

/// Stages 1 and 2 on the session in `dir` (stage 2, the sun, sky and
/// environment, only with `env` = its map's rows and columns), through the
/// calibration file `camera_calibration` when given (see
/// [`SessionInputs::calibrated`]).
pub fn process_session(
    dir: &Path,
    scene: Option<&Path>,
    debevec: &DebevecOptions,
    env: Option<(usize, usize)>,
    thresholds_file: Option<&Path>,
    camera_calibration: Option<&Path>,
) -> Result<Processed> {
    let mut stages = Vec::new();
    let t = Instant::now();
    let mut inputs = SessionInputs::open(dir, scene)?;
    if let Some(path) = camera_calibration {
        inputs = inputs.calibrated(path)?;
    }
    let q = thresholds(thresholds_file, Some(&inputs.plan))?;
    let optics = StationOptics::of_station(&inputs.station);
    let b = bar(0, "reading frames");
    let frames = inputs.frames(&b)?;
    b.finish_and_clear();
    let frame_count = frames.len();
    stages.push(("read and check frames".to_owned(), t.elapsed().as_secs_f64()));

    let t = Instant::now();
    let groups = group_frames(frames);
    let (calibration, choice) = calibrate_response(&groups, debevec)?;
    stages.push(("response (Debevec–Malik)".to_owned(), t.elapsed().as_secs_f64()));
    let planned = inputs.planned_exposures(&choice.group, choice.exposures);
    let linear = groups.iter().flat_map(|g| &g.frames).all(|f| f.linear);
    let response_quality = if linear {
        gates::known_response()
    } else {
        gates::response(&calibration, choice.exposures, planned, &q)
    }
    .with_note(format!("bracket {}: {}", choice.group, choice.reason));

    let t = Instant::now();
    let b = bar(1, "merging HDR");
    let merged = merge_groups(&groups, &calibration.curve, &optics)?;
    b.finish_and_clear();
    stages.push((format!("HDR merge ({} maps)", merged.len()), t.elapsed().as_secs_f64()));

    let light = match env {
        Some((rows, cols)) => {
            let t = Instant::now();
            let light = illumination(&merged, &optics, rows, cols)?;
            stages.push(("sun, sky, environment".to_owned(), t.elapsed().as_secs_f64()));
            light
        }
        None => Vec::new(),
    };

    let mut quality = vec![response_quality.clone()];
    for g in &merged {
        let mut p = gates::radiance(&g.key, &g.map, matches!(g.purpose, Purpose::Sun), &q);
        p.inherit(&response_quality);
        quality.push(p);
    }
    quality.extend(light.iter().flat_map(|l| light_quality(l, &response_quality, &q)));

    let occurrences = light
        .iter()
        .map(|l| OccurrenceSummary {
            occurrence: l.occurrence.clone(),
            held_out: l.held_out,
            time: l.time.to_rfc3339(),
            sun_zenith_deg: l.sun.zenith_rad.to_degrees(),
            sun_azimuth_deg: l.sun.azimuth_rad.to_degrees(),
            sun_irradiance: l.sun_irradiance.as_ref().map(|s| s.irradiance),
            sun_triplet_spread: l.sun_irradiance.as_ref().map(|s| s.spread),
            sky: sky_file(l),
            environment_regions_seen: l
                .environment
                .as_ref()
                .map(|m| m.regions.iter().filter(|r| r.count > 0).count()),
            notes: l.notes.clone(),
        })
        .collect();
    let summary = Summary {
        session: dir.display().to_string(),
        frames: frame_count,
        groups: groups.len(),
        response: ResponseSummary {
            bracket: choice.group.clone(),
            reason: choice.reason.clone(),
            residual_rms: [0, 1, 2].map(|c| calibration.channels[c].residual_rms),
            condition_estimate: [0, 1, 2].map(|c| calibration.channels[c].condition_estimate),
        },
        occurrences,
        stage_seconds: stages,
    };
    Ok(Processed {
        inputs,
        optics,
        calibration,
        merged,
        light,
        summary,
        thresholds: q,
        quality,
    })
}

/// The verdicts of an occurrence's sun, sky and environment, each
/// inheriting the response's. A sun shot or sky scan that was taken but
/// gave no product is `failed`, with the reason.
fn light_quality(l: &OccurrenceLight, response: &ProductQuality, q: &Quality) -> Vec<ProductQuality> {
    let occ = &l.occurrence;
    let not_made = |what: &str, absent: &str| {
        (!l.notes.iter().any(|n| n == absent))
            .then(|| ProductQuality::not_made(format!("{what} {occ}"), format!("not measured: {}", l.notes.join("; "))))
    };
    let sun = match &l.sun_irradiance {
        Some(s) => Some(gates::sun(occ, s.spread, s.frames, &s.refused, q)),
        None => not_made("sun", "no sun shot"),
    };
    let sky = match (&l.sky, sky_file(l)) {
        (Some(_), Some(file)) => Some(gates::sky(occ, &file.channels, q)),
        _ => not_made("sky", "no sky scan"),
    };
    let env = l.environment.as_ref().map(|m| gates::environment(occ, m, q));
    [sun, sky, env]
        .into_iter()
        .flatten()
        .map(|mut p| {
            p.inherit(response);
            p
        })
        .collect()
}

/// The report sections of stages 1 and 2 (with the simulator's truth beside the figures, if given).
pub fn stage_sections(p: &Processed, truth: Option<&report_sections::Truth>) -> Result<Vec<Section>> {
    Ok(vec![
        report_sections::response(p, truth)?,
        report_sections::sun(p, truth)?,
        report_sections::sky(p, truth)?,
        report_sections::environment(p)?,
        report_sections::speed(p),
    ])
}

/// The scene (geometry and the description's materials) and the outdoor
/// stages' products, when the session has a scene with views.
pub struct Outdoor {
    pub scene: campanile_sim::world::LoadedScene,
    pub products: outdoor_stage::OutdoorProducts,
}

/// Stages 3–5: pseudo-albedos from the training views, the held-out views
/// re-rendered. `None` when the session has no scene or no views.
///
/// The scene's triangles come from its OBJ; non-target surfaces (the
/// ground, the landscape), which light the targets as environment, take the
/// albedo the scene's materials give them (through the simulator's scene
/// loader, the only loader of scene files with materials so far).
pub fn outdoor_stages(
    p: &Processed,
    settings: &campanile_process::outdoor::ReflectanceSettings,
) -> Result<Option<Outdoor>> {
    let Some(geometry) = p.inputs.geometry()? else {
        return Ok(None);
    };
    if !p.merged.iter().any(|g| matches!(g.purpose, Purpose::View { .. })) {
        return Ok(None);
    }
    let Some((description, _)) = p.inputs.scene.as_ref() else {
        return Ok(None);
    };
    let description = description.clone();
    let scene = campanile_sim::world::from_description(description, &geometry)
        .with_context(|| format!("loading the scene geometry {}", geometry.display()))?;
    let b = bar(1, "pseudo-albedos");
    let products = outdoor_stage::outdoor(p, &scene.scene, settings)?;
    b.finish_and_clear();
    Ok(Some(Outdoor { scene, products }))
}

/// Writes the pseudo-albedo atlases and materials, and the held-out renders.
pub fn write_outdoor(o: &Outdoor, out: &Path) -> Result<()> {
    campanile_process::outdoor::atlas::write_materials(&o.scene.scene, &o.products.reflectance, &out.join("albedo"))?;
    std::fs::create_dir_all(out.join("held-out")).with_context(|| format!("{}: cannot create", out.display()))?;
    for v in &o.products.held_out {
        let map = campanile_process::hdr::merge::RadianceMap {
            width: v.rendered.width,
            height: v.rendered.height,
            rgb: v.rendered.data.clone(),
            variance: vec![0.0; v.rendered.data.len()],
            mask: vec![0; v.rendered.width * v.rendered.height],
        };
        let path = out.join("held-out").join(format!("{}.exr", file_name(&v.label)));
        campanile_process::exr_io::write_radiance_exr(&map, &path)
            .with_context(|| format!("{}: cannot write", path.display()))?;
    }
    if !o.products.zoom.is_empty() {
        std::fs::create_dir_all(out.join("zoom")).with_context(|| format!("{}: cannot create", out.display()))?;
    }
    for z in &o.products.zoom {
        let a = &z.albedo;
        let stem = file_name(&z.label);
        for (name, image) in [
            ("albedo-sun", crate::scene_render::albedo_image(&a.rho_sun, &a.rig)),
            ("albedo-se", crate::scene_render::albedo_image(&a.rho_se, &a.rig)),
            ("grid-albedo-se", crate::scene_render::albedo_image(&a.low_se, &a.rig)),
            ("render", z.rendered.clone()),
        ] {
            crate::igi::write_exr(&image, &out.join("zoom").join(format!("{stem}-{name}.exr")))?;
        }
        // Which pixels were given eq. (5.16) pseudo-albedos (white); the
        // others keep the grid's.
        let used: Vec<u8> = a.valid().iter().map(|&u| if u { 255 } else { 0 }).collect();
        let png = out.join("zoom").join(format!("{stem}-used.png"));
        image::save_buffer(
            &png,
            &used,
            a.rig.width as u32,
            a.rig.height as u32,
            image::ExtendedColorType::L8,
        )
        .with_context(|| format!("{}: cannot write", png.display()))?;
    }
    let zoom: Vec<serde_json::Value> = o
        .products
        .zoom
        .iter()
        .map(|z| {
            let r = &z.albedo.report;
            serde_json::json!({
                "view": z.label,
                "light": z.light,
                "focal_px": z.albedo.rig.pinhole.focal_px,
                "pixels": {"total": r.pixels, "used": r.used, "non_target": r.non_target, "invalid_radiance": r.invalid_radiance, "face_edge": r.face_edge, "shadow_edge": r.shadow_edge, "dark": r.dark},
                "window_px": r.window_px,
                "rmse_block_4x4": z.rmse_block,
                "rmse_block_4x4_grid_only": z.rmse_block_grid,
                "rmse_pixel": z.rmse_pixel,
                "rmse_pixel_grid_only": z.rmse_pixel_grid,
                "blocks": z.blocks,
            })
        })
        .collect();
    let summary: Vec<serde_json::Value> = o
        .products
        .held_out
        .iter()
        .map(|v| serde_json::json!({"view": v.label, "rmse_pixel": v.rmse_pixel, "rmse_block_4x4": v.rmse_block, "texture_references": v.references, "rmse_block_4x4_grid_only": v.rmse_block_grid}))
        .collect();
    let refl = &o.products.reflectance;
    let photos: Vec<serde_json::Value> = refl
        .photos
        .iter()
        .map(|c| serde_json::json!({"photo": c.label, "observations": c.observations, "trimmed_mean_log_ratio": c.median_log_ratio, "outlier": c.outlier}))
        .collect();
    let json = serde_json::json!({
        "grid_spacing_m": refl.grid.spacing_m,
        "cells": refl.cells.len(),
        "photos": photos,
        "pixels": {"used": refl.sampling.used, "shadow_edge": refl.sampling.shadow_edge, "mirror": refl.sampling.mirror, "grazing": refl.sampling.grazing, "invalid": refl.sampling.invalid, "mixed": refl.sampling.mixed},
        "diagnostics": refl.diagnostics,
        "held_out": summary,
        "zoom": zoom,
        "stage_seconds": o.products.seconds,
    });
    std::fs::write(out.join("outdoor.json"), serde_json::to_vec_pretty(&json)?)
        .with_context(|| format!("{}: cannot write", out.display()))?;
    Ok(())
}

/// Median and p95 relative errors of ρ_se, then of ρ_sun, against the truth.
pub type AlbedoQuantiles = (f64, f64, f64, f64);

/// The outdoor report sections; `truth(triangle, point)` gives true albedos.
pub fn outdoor_sections(
    p: &Processed,
    o: &Outdoor,
    truth: Option<&dyn Fn(usize, [f64; 3]) -> [f64; 3]>,
    strip_frames: usize,
) -> Result<(Vec<Section>, Option<AlbedoQuantiles>)> {
    let scene = &o.scene.scene;
    let view = p
        .merged
        .iter()
        .find(|g| !g.held_out && matches!(g.purpose, Purpose::View { .. }))
        .ok_or_else(|| anyhow::anyhow!("no training view"))?;
    let rig = campanile_process::render::CameraRig {
        pinhole: view.pinhole,
        mount: view.mount(&p.optics.mount),
        head: view.head,
        position: nalgebra::Vector3::from(view.position_m),
        width: view.map.width,
        height: view.map.height,
    };
    let mut albedo = outdoor_report::albedo_section(scene, &o.products, &rig, truth)?;
    let figures = truth.map(|t| {
        let mut e = outdoor_report::albedo_errors(scene, &o.products.reflectance, t);
        outdoor_report::add_albedo_errors(&mut albedo, &mut e)
    });
    let held = outdoor_report::held_out_section(&o.products)?;
    let strip = outdoor_report::day_strip(p, scene, &o.products, &rig, strip_frames)?;
    let overcast = outdoor_report::overcast_strip(p, scene, &o.products, &rig)?;
    let mut sections = vec![albedo, held, strip, overcast];
    if !o.products.zoom.is_empty() {
        sections.push(outdoor_report::zoom_section(&o.products)?);
    }
    Ok((sections, figures))
}

/// Writes a report page (through a temporary file).
pub fn write_report(report: &Report, path: &Path) -> Result<()> {
    crate::partial_file::write(path, report.to_html().as_bytes())
}

/// The sky fits of an occurrence as a sky file.
pub fn sky_file(l: &OccurrenceLight) -> Option<SkyFile> {
    let fits = l.sky.as_ref()?;
    Some(SkyFile {
        sun_zenith_deg: l.sun.zenith_rad.to_degrees(),
        sun_azimuth_deg: l.sun.azimuth_rad.to_degrees(),
        channels: fits
            .iter()
            .zip(["r", "g", "b"])
            .map(|(f, name)| ChannelSky::of_robust(name, f))
            .collect(),
    })
}

fn file_name(key: &str) -> String {
    key.chars()
        .map(|c| if c.is_ascii_alphanumeric() || c == '-' { c } else { '_' })
        .collect()
}

/// Writes the curve, the views' radiance, the light per occurrence and the summary.
pub fn write_outputs(p: &Processed, out: &Path) -> Result<()> {
    let mkdir = |d: &Path| std::fs::create_dir_all(d).with_context(|| format!("{}: cannot create", d.display()));
    mkdir(out)?;
    mkdir(&out.join("radiance"))?;
    mkdir(&out.join("light"))?;
    let write = |path: PathBuf, bytes: &[u8]| crate::partial_file::write(&path, bytes);
    write(
        out.join("response.csv"),
        p.calibration.curve.to_csv(&p.calibration.method).as_bytes(),
    )?;
    let svg = curve_plot_svg(&p.calibration.curve, "recovered camera response (full-well gauge)")?;
    write(out.join("response.svg"), svg.as_bytes())?;
    for g in p.merged.iter().filter(|g| matches!(g.purpose, Purpose::View { .. })) {
        let path = out.join("radiance").join(format!("{}.exr", file_name(&g.key)));
        campanile_process::exr_io::write_radiance_exr(&g.map, &path)
            .with_context(|| format!("{}: cannot write", path.display()))?;
    }
    for l in &p.light {
        let Some(env) = &l.environment else { continue };
        // Lat-long, elevation +90° on the top row, azimuth 0° (north) at the
        // left, east next; regions nothing fell in are zero with mask bits set.
        let (w, h) = (env.cols, env.rows);
        let mut map = campanile_process::hdr::merge::RadianceMap {
            width: w,
            height: h,
            rgb: vec![0.0; w * h * 3],
            variance: vec![0.0; w * h * 3],
            mask: vec![0; w * h],
        };
        for y in 0..h {
            for x in 0..w {
                let r = &env.regions[(h - 1 - y) * w + x];
                let i = y * w + x;
                if r.count == 0 {
                    map.mask[i] = 0b111_111;
                    continue;
                }
                for (c, (m, v)) in r.mean.iter().zip(r.variance()).enumerate() {
                    map.rgb[3 * i + c] = *m as f32;
                    map.variance[3 * i + c] = v as f32;
                }
            }
        }
        let path = out
            .join("light")
            .join(format!("{}-environment.exr", file_name(&l.occurrence)));
        campanile_process::exr_io::write_radiance_exr(&map, &path)
            .with_context(|| format!("{}: cannot write", path.display()))?;
    }
    for o in &p.summary.occurrences {
        if let Some(sky) = &o.sky {
            let path = out.join("light").join(format!("{}.ron", file_name(&o.occurrence)));
            crate::partial_file::write_ron(sky, &path)?;
        }
    }
    let json = serde_json::to_vec_pretty(&p.summary)?;
    write(out.join("summary.json"), &json)?;
    Ok(())
}

//! The demo's room (thesis §4.7.2): `examples/room-igi.ron` captured on
//! the simulated station through the capture controller (each pose under
//! each lamp alone and all on, a calibration bracket, metered brackets of
//! the bulbs), processed as `campanile process` processes a room session
//! (response, HDR merge, rectified views and a `campanile igi` scene file,
//! the lamps triangulated from their bulbs, Ward BRDFs, albedo maps), and
//! relit under two lamps the capture never used, beside the simulator's
//! render of the same lamps.

use std::path::Path;
use std::time::Instant;

use crate::Result;
use anyhow::anyhow;
use campanile_process::igi::format_table;
use campanile_process::igi::table::errors;
use campanile_process::report::{ColourScale, Figure, Section, Table, false_colour_png, flagged, tonemapped_png};
use campanile_sim::world::examples_dir;
use campanile_sim::world::igi_photograph::PhotoSettings;
use campanile_sim::world::room_igi::{ROOM_BOUNCES, RoomIgi, igi_lights_of, new_lamps, relit_block_error};

use crate::igi::{write_albedo_maps, write_exr};
use crate::process;

/// The camera the room is relit from.
pub const RELIT_CAMERA: &str = "wide-sw";

/// What the room run measured.
/// Table cells more than this far from the truth are flagged (percent;
/// γ in degrees).
const FLAG_PCT: f64 = 10.0;
const FLAG_DEG: f64 = 2.0;

pub struct RoomRun {
    /// The report section.
    pub section: Section,
    /// Relative RMSE of the relit image against the simulator's, over 4×4-pixel blocks.
    pub relit_rmse: f64,
    /// The same for the true materials through the same renderer (Monte Carlo noise floor).
    pub noise_floor_rmse: f64,
    /// Worst lamp position error from triangulation, millimetres.
    pub triangulation_mm: f64,
    /// Worst lamp intensity error from triangulation, relative.
    pub intensity_relative: f64,
    /// Seconds to photograph, to recover (lamps, BRDFs, albedo maps) and to relight.
    pub photograph_s: f64,
    /// See `photograph_s`.
    pub recover_s: f64,
    /// See `photograph_s`.
    pub relight_s: f64,
    /// The verdicts of the room session's products.
    pub quality: Vec<campanile_process::quality::ProductQuality>,
}

fn rel(got: f64, truth: f64) -> f64 {
    if truth.abs() > 0.0 {
        (got / truth - 1.0).abs()
    } else {
        got.abs()
    }
}

/// Runs the room into `dir/room` (`quick`: smaller images, fewer rays).
pub fn room(dir: &Path, quick: bool, host: &dyn super::DemoHost) -> Result<RoomRun> {
    let out = dir.join("room");
    let station = campanile_config::document::load_station(&examples_dir().join("sim-station.ron"))
        .map_err(|e| anyhow!("{e}"))?
        .value;
    let world = RoomIgi::load(&examples_dir().join("room-scene.ron"), &station).map_err(|e| anyhow!("{e}"))?;
    // Capture the room on the simulated station, as `campanile capture`
    // would on a real one, then `campanile process` it: the response from
    // the session's calibration bracket, every bracket merged, the views
    // with every lamp on rectified into a scene file, the lamps triangulated.
    let session = out.join("session");
    let plan = examples_dir().join("room-igi.ron");
    // Paths of up to ROOM_BOUNCES scattering events: cut shorter, the
    // photographs miss interreflected light the solver models (ρd low).
    let bounces = ROOM_BOUNCES.to_string();
    let (samples, scale) = if quick { ("8", 0.25) } else { ("16", 0.5) };
    let t = Instant::now();
    host.capture(
        &plan,
        &examples_dir().join("sim-station.ron"),
        &session,
        &["--sim-samples", samples, "--sim-bounces", &bounces],
    )?;
    let photograph_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let processed = process::process_session(
        &session,
        None,
        &campanile_process::hdr::debevec::DebevecOptions::default(),
        None,
        None,
        None,
    )?;
    let processed_dir = out.join("processed");
    process::write_outputs(&processed, &processed_dir)?;
    let products = process::room::room_stage(&processed, &processed_dir, &process::room::RoomOptions { scale, quick })?;
    for w in &products.recovered.loaded.warnings {
        host.note(&format!("warning: {w}"));
    }
    let r = &products.recovered;
    let recover_s = t.elapsed().as_secs_f64();
    let quality = process::room::room_quality(&processed, &products)
        .into_iter()
        .map(|mut q| {
            q.product = format!("room: {}", q.product);
            q
        })
        .collect();
    let (wide_w, wide_h) = products.views.first().map_or((0, 0), |v| v.size);
    let truth = world.true_materials().map_err(|e| anyhow!("{e}"))?;
    let truth_opt: Vec<_> = truth.iter().copied().map(Some).collect();
    std::fs::write(out.join("materials.txt"), format_table(&r.result, &truth_opt, None))?;
    write_albedo_maps(r, &out.join("albedo"))?;

    // Lamps. The triangulated intensities are in the camera's units, which
    // differ from W/sr by the response's gauge error (the recovered curve's
    // mean offset from the simulator's, per channel); the lamps' own error
    // is measured with that factor divided out, and both are reported.
    let camera = campanile_sim::camera::CameraOptions::default().model;
    let curve = &processed.calibration.curve;
    let top = f64::from((1u32 << curve.bits) - 1);
    let gauge: [f64; 3] = [0, 1, 2].map(|c| {
        let codes: Vec<f64> = (0..=34).map(|k| top * (0.1 + 0.8 * f64::from(k) / 34.0)).collect();
        let mean = codes
            .iter()
            .map(|&z| curve.ln_exposure(c, z) - camera.true_ln_exposure(z, c))
            .sum::<f64>()
            / codes.len() as f64;
        mean.exp()
    });
    let (mut worst_mm, mut worst_i, mut worst_raw) = (0.0f64, 0.0f64, 0.0f64);
    let mut lamp_rows = Vec::new();
    for (name, t) in &r.loaded.triangulated {
        if let Some((_, b)) = world.lamps.iter().find(|(n, _)| n == name) {
            let mm = (t.light.position - b.center).norm() * 1e3;
            let ti = b.radiance.map(|l| l * std::f64::consts::PI * b.radius * b.radius);
            let raw = (0..3).map(|c| rel(t.light.intensity[c], ti[c])).fold(0.0, f64::max);
            let di = (0..3)
                .map(|c| rel(t.light.intensity[c] / gauge[c], ti[c]))
                .fold(0.0, f64::max);
            worst_mm = worst_mm.max(mm);
            worst_i = worst_i.max(di);
            worst_raw = worst_raw.max(raw);
            lamp_rows.push(vec![
                name.clone(),
                format!("{mm:.2} mm"),
                format!("{:.4} / {:.4} m", b.radius, t.light.radius),
                format!("{:.2} %", 100.0 * di),
                format!("{:.2} %", 100.0 * raw),
            ]);
        }
    }

    // Materials beside the truth.
    let mut table = Table {
        caption: format!(
            "The room's materials (thesis Table 4.1 format): true / recovered (error); channel R for ρd and ρs, as in the thesis's table; ⚠ more than {FLAG_PCT} % (γ: {FLAG_DEG}°) off"
        ),
        header: ["surface", "model (why)", "ρd", "ρs", "αx", "αy", "γ"]
            .map(String::from)
            .to_vec(),
        rows: Vec::new(),
    };
    for (s, t) in r.result.surfaces.iter().zip(&truth) {
        let Some(m) = s.material else { continue };
        let e = errors(&m, t);
        let lobe = m
            .lobe
            .map(|l| campanile_process::igi::table::nearest_representation(&l, t.lobe.map_or(0.0, |l| l.gamma_rad)));
        let cell = |tv: Option<f64>, g: Option<f64>, e: Option<f64>, unit: &str| match (tv, g) {
            (Some(tv), Some(g)) => {
                let text = format!("{tv:.3} / {g:.3} ({:.1}{unit})", e.unwrap_or(f64::NAN));
                let bound = if unit == "°" { FLAG_DEG } else { FLAG_PCT };
                if e.is_none_or(|e| e.is_nan() || e > bound) {
                    flagged(text)
                } else {
                    text
                }
            }
            // A true parameter the fit has none of (a lobe not recovered).
            (Some(tv), None) => flagged(format!("{tv:.3} / —")),
            (None, Some(g)) => format!("— / {g:.3}"),
            (None, None) => "—".into(),
        };
        table.rows.push(vec![
            s.name.clone(),
            format!("{:?} ({})", s.model, s.reason),
            cell(Some(t.rho_d[0]), Some(m.rho_d[0]), e[0], "%"),
            cell(
                Some(t.lobe.map_or(0.0, |l| l.rho_s[0])),
                Some(lobe.map_or(0.0, |l| l.rho_s[0])),
                e[1],
                "%",
            ),
            cell(t.lobe.map(|l| l.alpha_x), lobe.map(|l| l.alpha_x), e[2], "%"),
            cell(t.lobe.map(|l| l.alpha_y), lobe.map(|l| l.alpha_y), e[3], "%"),
            cell(
                t.lobe.map(|l| l.gamma_rad.to_degrees()),
                lobe.map(|l| l.gamma_rad.to_degrees()),
                e[4],
                "°",
            ),
        ]);
    }

    // Relit under new lamps, beside the simulator.
    let bulbs = new_lamps();
    let lights = igi_lights_of(&bulbs);
    let t = Instant::now();
    let relit = r.relight(&lights, RELIT_CAMERA, quick)?;
    let relight_s = t.elapsed().as_secs_f64();
    let (_, camera) = r
        .loaded
        .cameras
        .iter()
        .find(|(n, _)| n == RELIT_CAMERA)
        .ok_or_else(|| anyhow!("no camera {RELIT_CAMERA}"))?;
    // The reference with as many stratified paths per pixel as the relit
    // image (crate::igi::settings), so that the two renders' noise
    // (the floor) stays well below the relit error.
    let samples = crate::igi::settings(quick).2.indirect_samples;
    let sim = world.photograph(
        &bulbs,
        &[],
        camera,
        &PhotoSettings {
            indirect_samples: samples,
            max_bounces: ROOM_BOUNCES,
            seed: 99,
        },
    );
    let scene_true = world.scene();
    let same = campanile_process::igi::relight::relight(
        scene_true,
        None,
        &lights,
        camera,
        &campanile_process::igi::relight::RelightSettings {
            indirect_samples: samples,
            max_bounces: ROOM_BOUNCES,
            seed: 5,
        },
    );
    write_exr(&relit, &out.join("relit.exr"))?;
    write_exr(&sim, &out.join("simulator.exr"))?;
    let relit_rmse = relit_block_error(&relit, &sim).ok_or_else(|| anyhow!("the simulator's render is black"))?;
    let noise_floor_rmse = relit_block_error(&same, &sim).ok_or_else(|| anyhow!("the simulator's render is black"))?;
    let (w, h) = (sim.width, sim.height);
    let mut sorted: Vec<f32> = sim.data.iter().copied().filter(|v| *v < 20.0).collect();
    sorted.sort_by(f32::total_cmp);
    let white = f64::from(sorted.get(sorted.len() * 99 / 100).copied().unwrap_or(1.0)).max(1e-6);
    let err: Vec<f64> = (0..w * h)
        .map(|i| {
            let a: f64 = (0..3).map(|c| f64::from(relit.data[i * 3 + c])).sum();
            let b: f64 = (0..3).map(|c| f64::from(sim.data[i * 3 + c])).sum();
            if b > 0.0 && b < 60.0 { a / b - 1.0 } else { f64::NAN }
        })
        .collect();
    // The headline result: the relit room beside the simulator's render,
    // full width, then the error map.
    let radiance = ColourScale::Radiance {
        white,
        unit: "radiance, W·m⁻²·sr⁻¹ (one exposure for both)".into(),
    };
    let figures = vec![
        Figure::Row(vec![
            Figure::Map {
                bytes: tonemapped_png("relit", w, h, &relit.data, 1.0 / white)?,
                caption: format!("Relit with the recovered materials ({RELIT_CAMERA}, two new lamps)"),
                scale: radiance.clone(),
            },
            Figure::Map {
                bytes: tonemapped_png("simulator", w, h, &sim.data, 1.0 / white)?,
                caption: "The simulator's render of the same lamps (true materials)".into(),
                scale: radiance,
            },
        ]),
        Figure::Map {
            bytes: false_colour_png("relit error", w, h, &err, (-0.3, 0.3))?,
            caption: "Relit / simulator − 1 per pixel".into(),
            scale: ColourScale::Diverging {
                low: -0.3,
                high: 0.3,
                unit: "relative error (relit / simulator − 1)".into(),
            },
        },
    ];
    let section = Section {
        title: "Indoor: the room relit (inverse global illumination, §4.7.2)".into(),
        paragraphs: vec![
            format!(
                "The simulated room ({} surfaces sharing specular parameters) captured on the simulated station ({}: each pose under each lamp alone and all on, a calibration bracket, metered brackets up at the bulbs; {} frames stored, the auto-brackets' extra exposures included) and processed as `campanile process` does: response from the session's bracket, HDR merge, {} views with every lamp on rectified to {}×{} px, each lamp triangulated from its bulb in the views that hold it unclipped (§4.7.2): worst position error {worst_mm:.2} mm, intensity {:.2} % once the camera's gauge error ({:+.2} / {:+.2} / {:+.2} %, the response's) is divided out, {:.2} % in the camera's units.",
                r.loaded.input.surfaces.len(),
                plan.file_name().and_then(|n| n.to_str()).unwrap_or_default(),
                processed.summary.frames,
                products.views.len(),
                wide_w,
                wide_h,
                100.0 * worst_i,
                100.0 * (gauge[0] - 1.0),
                100.0 * (gauge[1] - 1.0),
                100.0 * (gauge[2] - 1.0),
                100.0 * worst_raw
            ),
            format!(
                "Relit under two lamps the capture never used: relative RMSE {:.1} % over 4×4-pixel blocks (the issue's goal: 3 %); the true materials through the same renderer give {:.1} % (Monte Carlo noise floor). The metal sphere's faceted highlight falls in no view, so it is recovered as diffuse only, as the model choice says.",
                100.0 * relit_rmse,
                100.0 * noise_floor_rmse
            ),
            format!(
                "Capture {photograph_s:.1} s (simulated), processing (response, HDR, rectification, lamps, BRDFs, albedo maps) {recover_s:.1} s, relighting {relight_s:.1} s."
            ),
        ],
        tables: vec![
            table,
            Table {
                caption: "Lamps triangulated from HDR images of their bulbs: error against the simulator".into(),
                header: [
                    "lamp",
                    "position error",
                    "radius true / found",
                    "intensity error (gauge divided out)",
                    "in the camera's units",
                ]
                .map(String::from)
                .to_vec(),
                rows: lamp_rows,
            },
        ],
        figures,
    };
    Ok(RoomRun {
        section,
        relit_rmse,
        noise_floor_rmse,
        triangulation_mm: worst_mm,
        intensity_relative: worst_i,
        photograph_s,
        recover_s,
        relight_s,
        quality,
    })
}

//! `campanile demo`: the whole station on the simulated hardware, in one
//! command: capture a day at the campanile, process it, write a report.

mod held_out_budget;
mod indoor;
mod room;

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use campanile_process::report::Report;
use campanile_sim::world::{World, examples_dir, load_scene};
use clap::{Args, Parser};

use super::capture::CaptureArgs;
use super::process::{self, report_sections::Truth};

/// Run the whole station on simulated hardware and write a report.
///
/// With no hardware and no arguments, it:
///   1. builds the simulated station (examples/sim-station.ron);
///   2. captures a simulated day at the campanile (examples/campanile-day.ron:
///      four training times and one held-out time; --quick: two and one);
///   3. processes it (response, HDR, sun, sky, environment, pseudo-albedos,
///      the held-out time re-rendered under the predicted light);
///   4. recovers the BRDFs of the thesis's simulated cube (inverse global
///      illumination, §4.7.1);
///   5. photographs the simulated room under its lamps, triangulates the
///      lamps, recovers its BRDFs and albedo maps and relights it under new
///      lamps (§4.7.2), beside the simulator's render;
///   6. writes OUT/report.html, with every figure beside the simulator's truth.
///
/// The session directories and every product stay in OUT.
///
/// Example:
///   campanile demo --out campanile-demo
///   campanile demo --quick --out demo-quick
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct DemoArgs {
    /// Where to write the sessions, the products and report.html.
    #[arg(long, value_name = "DIR", default_value = "campanile-demo")]
    out: PathBuf,
    /// A smaller, faster run (two training times, fewer views): what the tests use.
    #[arg(long)]
    quick: bool,
    /// Diagnostic: after the held-out comparison, measure where its error
    /// comes from, term by term, against the simulator (renders the held-out
    /// views again at many samples per pixel; adds a report section and
    /// OUT/held-out-budget.json).
    #[arg(long)]
    held_out_budget: bool,
    /// Development: reuse OUT/campanile-session if it is there instead of
    /// capturing the day again (the capture is most of the demo's time).
    #[arg(long)]
    reuse_session: bool,
}

/// The demo's headline figures (besides campanile-processed/summary.json), for tests.
#[derive(Debug, serde::Serialize)]
struct Figures {
    cube_worst_relative: f64,
    cube_worst_gamma_deg: f64,
    room_relit_rmse: f64,
    room_noise_floor_rmse: f64,
    room_triangulation_mm: f64,
    room_intensity_relative: f64,
    albedo_se_median: Option<f64>,
    albedo_se_p95: Option<f64>,
    albedo_sun_median: Option<f64>,
    albedo_sun_p95: Option<f64>,
    held_out_rmse_pixel_block: Vec<(f64, f64)>,
    /// Per held-out view, the floor: one simulated photograph's own Monte
    /// Carlo noise (per pixel, per 4 × 4 block) over the same mask.
    held_out_floor_pixel_block: Vec<(f64, f64)>,
}

/// Parses a `capture` command line, as the user would type it.
#[derive(Debug, Parser)]
struct CaptureLine {
    #[command(flatten)]
    args: CaptureArgs,
}

/// Captures `plan` on the simulated `station` into `session` (cleared
/// first) through `campanile capture`, with `extra` arguments.
pub fn capture_simulated(plan: &Path, station: &Path, session: &Path, extra: &[&str]) -> Result<()> {
    if session.exists() {
        std::fs::remove_dir_all(session).with_context(|| format!("{}: cannot clear", session.display()))?;
    }
    let mut line: Vec<&std::ffi::OsStr> = vec![
        "capture".as_ref(),
        plan.as_os_str(),
        "--station".as_ref(),
        station.as_os_str(),
        "--out".as_ref(),
        session.as_os_str(),
    ];
    line.extend(extra.iter().map(std::ffi::OsStr::new));
    let line = CaptureLine::try_parse_from(line)?;
    if super::capture::run(line.args)? != super::EXIT_OK {
        bail!(
            "the simulated capture of {} did not complete (see above)",
            plan.display()
        );
    }
    Ok(())
}

pub fn run(args: DemoArgs) -> Result<()> {
    let wall = Instant::now();
    let examples = examples_dir();
    if !examples.join("sim-station.ron").is_file() {
        bail!(
            "the example files are not at {}: run the demo from a clone of the repository",
            examples.display()
        );
    }
    let session = args.out.join("campanile-session");
    if args.reuse_session && !session.join("journal.jsonl").is_file() {
        return Err(super::exit::bad_input(format!(
            "--reuse-session: {} holds no captured session ({} is missing); run the demo once without \
             --reuse-session to capture one",
            args.out.display(),
            session.join("journal.jsonl").display()
        )));
    }
    std::fs::create_dir_all(&args.out).with_context(|| format!("{}: cannot create", args.out.display()))?;
    let station = examples.join("sim-station.ron");
    let plan = examples.join(if args.quick {
        "campanile-quick.ron"
    } else {
        "campanile-day.ron"
    });
    let scene = examples.join("campanile-scene.ron");

    // 1–2. Capture.
    eprintln!("capturing {} on the simulated station …", plan.display());
    let t = Instant::now();
    // Three bounces: the light the ground reflects onto shaded walls,
    // which the pseudo-albedo model includes (one bounce would omit it).
    // Eight paths per pixel (four in the quick run), each splitting into 4
    // branches at the surface it shows: the photographs' noise was the
    // largest term of the pseudo-albedo and held-out errors (BENCHMARKS.md,
    // "Path splitting at the first surface"; 8 against 4 paths: medians
    // 1.9 % / 2.0 % against 2.3 % / 2.2 %, for 14 s more of a 133 s demo).
    let spp = if args.quick { "4" } else { "8" };
    if !(args.reuse_session && session.is_dir()) {
        capture_simulated(&plan, &station, &session, &["--sim-samples", spp, "--sim-bounces", "3"])?;
    }
    let capture_s = t.elapsed().as_secs_f64();

    // 3. Process.
    eprintln!("processing {} …", session.display());
    let processed = process::process_session(
        &session,
        Some(&scene),
        &campanile_process::hdr::debevec::DebevecOptions::default(),
        Some((18, 36)),
        None,
    )?;
    let products = args.out.join("campanile-processed");
    process::write_outputs(&processed, &products)?;

    // 4. Report.
    let station_cfg = campanile_config::load_station(&station)
        .map_err(|e| anyhow::anyhow!("{e}"))?
        .value;
    let world = World::new(&station_cfg, load_scene(&scene).context("loading the campanile scene")?);
    let truth = Truth {
        camera: campanile_sim::camera::CameraOptions::default().model,
        world: &world,
    };
    let mut sections = process::stage_sections(&processed, Some(&truth))?;
    let mut speed = sections.pop().unwrap_or_default();

    // Outdoors: pseudo-albedos, the held-out time, the day.
    eprintln!("recovering pseudo-albedos and re-rendering the held-out time …");
    let outdoor = process::outdoor_stages(&processed, &Default::default())?;
    let mut quality = processed.quality.clone();
    let mut albedo_figures = None;
    let mut held_out_rmse = Vec::new();
    let mut held_out_floor = Vec::new();
    if let Some(o) = &outdoor {
        quality.push(process::outdoor_quality(&processed, o));
        process::write_outdoor(o, &products)?;
        let truth_albedo = |triangle: usize, point: [f64; 3]| world.pseudo_albedos(triangle, point).sky_environment;
        let (outdoor_sections, figures) =
            process::outdoor_sections(&processed, o, Some(&truth_albedo), if args.quick { 4 } else { 7 })?;
        sections.extend(outdoor_sections);
        albedo_figures = figures;
        held_out_rmse = o
            .products
            .held_out
            .iter()
            .map(|v| (v.rmse_pixel, v.rmse_block))
            .collect();
        // The floor: the held-out photographs' own noise (a real camera has none).
        let floor = held_out_budget::photo_floor(&processed, o, &world, spp.parse()?, 3)?;
        held_out_floor = floor.iter().map(|t| (t.pixel, t.block)).collect();
        sections.push(held_out_budget::floor_section(o, &floor));
        if args.held_out_budget {
            let t = Instant::now();
            let (terms, gauges) = held_out_budget::budget(&processed, o, &world, spp.parse()?, 3, 64)?;
            for term in &terms {
                eprintln!(
                    "held-out budget {:>12} {:<70} pixel {:6.2}%  block {:5.2}%",
                    term.view,
                    term.term,
                    100.0 * term.pixel,
                    100.0 * term.block
                );
            }
            eprintln!("held-out budget gauges {gauges:?} ({:.1} s)", t.elapsed().as_secs_f64());
            std::fs::write(
                args.out.join("held-out-budget.json"),
                serde_json::to_vec_pretty(&serde_json::json!({"terms": terms, "gauges": gauges}))?,
            )
            .with_context(|| format!("{}: cannot write", args.out.display()))?;
            sections.push(held_out_budget::section(&terms, &gauges));
        }
        for (stage, s) in &o.products.seconds {
            speed.tables[0].rows.push(vec![stage.clone(), format!("{s:.2}")]);
        }
    }

    // Indoors: the thesis's cube.
    eprintln!("recovering the cube's BRDFs (inverse global illumination) …");
    let (px, samples) = if args.quick { (64, 16) } else { (96, 32) };
    let cube = indoor::cube(px, samples, &args.out)?;
    sections.push(cube.section);
    eprintln!("the room: lamps, BRDFs, albedo maps, relit under new lamps …");
    let room = room::room(&args.out, args.quick)?;
    sections.push(room.section);
    quality.extend(room.quality);
    let quality = campanile_process::quality::QualityReport::new(quality, &processed.thresholds);
    let rows = &mut speed.tables[0].rows;
    rows.insert(
        0,
        vec!["simulated capture (the whole plan)".into(), format!("{capture_s:.2}")],
    );
    rows.push(vec![
        "cube: photographs (simulator)".into(),
        format!("{:.2}", cube.photograph_s),
    ]);
    rows.push(vec![
        "cube: inverse global illumination".into(),
        format!("{:.2}", cube.recover_s),
    ]);
    rows.push(vec![
        "room: photographs (simulator)".into(),
        format!("{:.2}", room.photograph_s),
    ]);
    rows.push(vec![
        "room: lamps, BRDFs, albedo maps".into(),
        format!("{:.2}", room.recover_s),
    ]);
    rows.push(vec![
        "room: relit under new lamps".into(),
        format!("{:.2}", room.relight_s),
    ]);
    sections.push(speed);
    let figures = Figures {
        cube_worst_relative: cube.worst_relative,
        cube_worst_gamma_deg: cube.worst_gamma_deg,
        room_relit_rmse: room.relit_rmse,
        room_noise_floor_rmse: room.noise_floor_rmse,
        room_triangulation_mm: room.triangulation_mm,
        room_intensity_relative: room.intensity_relative,
        albedo_se_median: albedo_figures.map(|f| f.0),
        albedo_se_p95: albedo_figures.map(|f| f.1),
        albedo_sun_median: albedo_figures.map(|f| f.2),
        albedo_sun_p95: albedo_figures.map(|f| f.3),
        held_out_rmse_pixel_block: held_out_rmse,
        held_out_floor_pixel_block: held_out_floor,
    };
    let json = serde_json::to_vec_pretty(&figures)?;
    std::fs::write(args.out.join("demo-figures.json"), json)
        .with_context(|| format!("{}: cannot write", args.out.display()))?;
    let report = Report {
        title: "Campanile demo: a simulated day at the bell tower".into(),
        summary: Vec::new(),
        intro: vec![
            format!(
                "The plan {} was captured on the simulated station {} and processed; every figure stands beside the simulator's truth.",
                plan.file_name().and_then(|n| n.to_str()).unwrap_or_default(),
                station.file_name().and_then(|n| n.to_str()).unwrap_or_default()
            ),
            format!("Sessions and products are in {}.", display(&args.out)),
        ],
        quality: Some(quality.clone()),
        sections,
    };
    let path = args.out.join("report.html");
    process::write_report(&report, &path)?;
    outln!(
        "demo finished in {:.1} s: {} ({} figures)",
        wall.elapsed().as_secs_f64(),
        path.display(),
        report.figure_count()
    )?;
    crate::cli::verdicts::finish(&quality, &args.out.join("quality.json"))
}

fn display(p: &Path) -> String {
    p.display().to_string()
}

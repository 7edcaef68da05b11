//! A whole `campanile process` run on a session directory: which kind of
//! session it is (outdoor, room or sky-only), its stages in order, its
//! products and its report page. What the run measured comes back for the
//! caller to print; the verdicts for it to write (`quality.json`) and act on.

use std::io::Write;
use std::path::PathBuf;

use anyhow::Context;
use campanile_process::hdr::debevec::DebevecOptions;
use campanile_process::outdoor::ReflectanceSettings;
use campanile_process::quality::{Quality, QualityReport};
use campanile_process::report::Report;
use campanile_process::sky_series::{ScanProducts, Shard, SkySeries};

use crate::igi::Written;
use crate::process::room::{self, RoomOptions, RoomProducts};
use crate::process::{
    Outdoor, Processed, SessionInputs, note_import_estimates, outdoor_quality, outdoor_sections, outdoor_stages,
    process_session, stage_sections, write_outdoor, write_outputs, write_report,
};
use crate::sky_series::{self, ScanRun, SkySeriesOptions};
use crate::{Error, Result};

/// What to run on a session, as `campanile process` takes it.
#[derive(Debug, Clone)]
pub struct ProcessOptions {
    /// The session directory.
    pub session: PathBuf,
    /// Output directory.
    pub out: PathBuf,
    /// The scene file, when the session's snapshot cannot find its geometry.
    pub scene: Option<PathBuf>,
    /// Response recovery.
    pub debevec: DebevecOptions,
    /// Environment map elevation bands and azimuth sectors.
    pub env: (usize, usize),
    /// A quality thresholds file.
    pub thresholds: Option<PathBuf>,
    /// Room sessions: the rectified views' scale and the solver's speed.
    pub room: RoomOptions,
    /// Outdoor sessions: the pseudo-albedo grid's cell side, metres.
    pub grid_spacing_m: f64,
    /// Sky-only sessions: the response curve (CSV).
    pub response: Option<PathBuf>,
    /// A calibrated camera (`campanile sky calibrate`'s or `campanile
    /// station calibrate-mount`'s file) used instead of the station's
    /// camera intrinsics and mount, and, when it measured the head's place,
    /// instead of the scene poses' positions.
    pub camera_calibration: Option<PathBuf>,
    /// Sky-only sessions: process only this share of the scans.
    pub shard: Option<Shard>,
    /// Sky-only sessions: merge these shard output directories instead.
    pub merge_shards: Option<Vec<PathBuf>>,
    /// Sky-only sessions: process this one occurrence, then the day.
    pub occurrence: Option<String>,
}

/// The kind of session a directory holds, from its plan.
#[derive(Debug, Clone)]
pub enum SessionKind {
    /// Views of a scene outdoors: response, HDR, sun, sky, environment,
    /// pseudo-albedos and held-out views.
    Outdoor,
    /// Views of a room under its lamps: response, HDR, inverse global illumination.
    Room,
    /// Sun shots, sky scans and brackets at head angles: a sky time series,
    /// under these thresholds.
    SkyOnly(Box<Quality>),
}

/// The kind of session in `opts.session`; bad input when there is no such
/// directory or the options are for another kind.
pub fn kind(opts: &ProcessOptions) -> Result<SessionKind> {
    if !opts.session.is_dir() {
        return Err(Error::input(format!(
            "{}: no such session directory (give the directory `campanile capture --out` wrote)",
            opts.session.display()
        )));
    }
    let inputs = SessionInputs::open(&opts.session, opts.scene.as_deref())?;
    if sky_series::is_sky_only(&inputs.plan) {
        let q = crate::verdicts::thresholds(opts.thresholds.as_deref(), Some(&inputs.plan))?;
        return Ok(SessionKind::SkyOnly(Box::new(q)));
    }
    if opts.response.is_some() || opts.shard.is_some() || opts.merge_shards.is_some() || opts.occurrence.is_some() {
        return Err(Error::input(format!(
            "{}: --response, --shard, --merge-shards and --occurrence are for sky-only sessions (sun shots, sky scans and brackets at head angles); this session's plan has views of a scene",
            opts.session.display()
        )));
    }
    Ok(if room::is_room_session(&inputs.plan) {
        SessionKind::Room
    } else {
        SessionKind::Outdoor
    })
}

/// What an outdoor run made (its products and report are written).
pub struct OutdoorRun {
    /// Stages 1 and 2.
    pub processed: Processed,
    /// The outdoor stages, when the session has a scene with views.
    pub outdoor: Option<Outdoor>,
    /// Every product's verdict.
    pub quality: QualityReport,
}

/// Processes an outdoor session into `opts.out`: stages 1–2 and their
/// outputs, the outdoor stages and theirs, and `report.html`.
pub fn outdoor(opts: &ProcessOptions) -> Result<OutdoorRun> {
    let out = &opts.out;
    let processed = process_session(
        &opts.session,
        opts.scene.as_deref(),
        &opts.debevec,
        Some(opts.env),
        opts.thresholds.as_deref(),
        opts.camera_calibration.as_deref(),
    )?;
    write_outputs(&processed, out)?;
    let settings = ReflectanceSettings {
        spacing_m: opts.grid_spacing_m,
        ..Default::default()
    };
    let outdoor = outdoor_stages(&processed, &settings)?;
    let mut sections = stage_sections(&processed, None)?;
    if let Some(o) = &outdoor {
        write_outdoor(o, out)?;
        let speed = sections.pop();
        sections.extend(outdoor_sections(&processed, o, None, 6)?.0);
        if let Some(mut speed) = speed {
            for (stage, s) in &o.products.seconds {
                speed.tables[0].rows.push(vec![stage.clone(), format!("{s:.2}")]);
            }
            sections.push(speed);
        }
    }
    let mut quality = processed.quality.clone();
    if let Some(o) = &outdoor {
        let albedos = outdoor_quality(&processed, o);
        for z in &o.products.zoom {
            quality.push(crate::process::zoom_quality(&processed, z, &albedos));
        }
        quality.insert(processed.quality.len(), albedos);
    }
    note_import_estimates(&opts.session, &mut quality)?;
    let quality = QualityReport::new(quality, &processed.thresholds);
    let report = Report {
        title: format!("Campanile: {}", opts.session.display()),
        summary: crate::report_summary::from_quality(&quality),
        intro: vec![format!(
            "Session {}, processed by campanile {}.",
            opts.session.display(),
            env!("CARGO_PKG_VERSION")
        )],
        quality: Some(quality.clone()),
        sections,
    };
    write_report(&report, &out.join("report.html"))?;
    Ok(OutdoorRun {
        processed,
        outdoor,
        quality,
    })
}

/// What a room run made (its products and report are written).
pub struct RoomRun {
    /// Stages 1 (response and HDR).
    pub processed: Processed,
    /// The room stage's products.
    pub products: RoomProducts,
    /// The recovered materials' files under `OUT/room/igi`.
    pub written: Written,
    /// Every product's verdict.
    pub quality: QualityReport,
}

/// Processes a room session into `opts.out`: the response and HDR, the
/// room stage (inverse global illumination) and its products, and
/// `report.html`.
pub fn room(opts: &ProcessOptions) -> Result<RoomRun> {
    let out = &opts.out;
    let processed = process_session(
        &opts.session,
        opts.scene.as_deref(),
        &opts.debevec,
        None,
        opts.thresholds.as_deref(),
        opts.camera_calibration.as_deref(),
    )?;
    write_outputs(&processed, out)?;
    let products = room::room_stage(&processed, out, &opts.room)?;
    let mut sections = stage_sections(&processed, None)?;
    let mut speed = sections.pop().unwrap_or_default();
    sections.truncate(1); // the response; indoors there is no sun, sky or environment
    sections.push(room::room_section(&products)?);
    for (stage, s) in &products.seconds {
        speed.tables[0].rows.push(vec![stage.clone(), format!("{s:.2}")]);
    }
    sections.push(speed);
    let quality = QualityReport::new(room::room_quality(&processed, &products), &processed.thresholds);
    let written = crate::igi::write_products(&products.recovered, &out.join("room").join("igi"), &quality)?;
    let report = Report {
        title: format!("Campanile: {}", opts.session.display()),
        summary: crate::report_summary::from_quality(&quality),
        intro: vec![format!(
            "Room session {}, processed by campanile {}.",
            opts.session.display(),
            env!("CARGO_PKG_VERSION")
        )],
        quality: Some(quality.clone()),
        sections,
    };
    write_report(&report, &out.join("report.html"))?;
    Ok(RoomRun {
        processed,
        products,
        written,
        quality,
    })
}

/// How a sky-only run went.
pub enum SkyWork {
    /// `--occurrence`: this scan processed, then the day recomputed.
    Scan(String, Box<ScanProducts>),
    /// `--merge-shards`: these directories merged, this many scan files copied.
    Merged(usize, usize),
    /// Every new scan processed.
    New(Box<ScanRun>),
}

/// What a sky-only run made (its products and report are written).
pub struct SkyRun {
    /// What was done.
    pub work: SkyWork,
    /// The day's (or days') series.
    pub series: SkySeries,
    /// The verdicts: with `--occurrence` that scan's, else the whole series'.
    pub quality: QualityReport,
}

/// Processes a sky-only session into `opts.out` under thresholds `q`:
/// one occurrence, merged shards or every new scan; then the day and
/// `report.html`. Scans that failed are in [`ScanRun::failed`]; see
/// [`SkyRun::failure`].
pub fn sky_only(opts: &ProcessOptions, q: &Quality) -> Result<SkyRun> {
    let out = &opts.out;
    let series_opts = SkySeriesOptions {
        out: out.clone(),
        response: opts.response.clone(),
        shard: opts.shard,
        debevec: opts.debevec,
        camera_calibration: opts.camera_calibration.clone(),
    };
    std::fs::create_dir_all(out).with_context(|| format!("{}: cannot create", out.display()))?;
    let (work, series) = match (&opts.occurrence, &opts.merge_shards) {
        (Some(occurrence), _) => {
            let scan = sky_series::process_scan(&opts.session, occurrence, &series_opts)?;
            let series = sky_series::recompute_day(out)?;
            (SkyWork::Scan(occurrence.clone(), Box::new(scan)), series)
        }
        (None, Some(dirs)) => {
            let (copied, series) = sky_series::merge_shards(&opts.session, dirs, &series_opts)?;
            (SkyWork::Merged(dirs.len(), copied), series)
        }
        (None, None) => {
            let run = sky_series::process_new_scans(&opts.session, &series_opts)?;
            let series = run.series.clone();
            (SkyWork::New(Box::new(run)), series)
        }
    };
    // With --occurrence, the verdicts (and the exit status) are that scan's;
    // otherwise the whole series'.
    let judged = series
        .scans
        .iter()
        .filter(|s| opts.occurrence.as_ref().is_none_or(|o| &s.occurrence == o));
    let quality = sky_series::series_quality(judged, q);
    let run = match &work {
        SkyWork::New(run) => Some(run.as_ref()),
        _ => None,
    };
    let report = sky_series::report(&opts.session, &series, run, Some(quality.clone()))?;
    write_report(&report, &out.join("report.html"))?;
    Ok(SkyRun { work, series, quality })
}

impl SkyRun {
    /// The error for scans that failed (not marked processed): bad input
    /// when every one failed on a damaged or unreadable input.
    pub fn failure(&self) -> Option<Error> {
        let SkyWork::New(run) = &self.work else {
            return None;
        };
        if run.failed.is_empty() {
            return None;
        }
        let message = format!(
            "{} scans failed (listed above); they were not marked processed",
            run.failed.len()
        );
        Some(if run.failed_on_input == run.failed.len() {
            Error::input(message)
        } else {
            Error::Work(anyhow::anyhow!(message))
        })
    }
}

impl RoomRun {
    /// Writes the run to `out`: the materials and files (as `campanile
    /// igi`), then the stages' seconds; the scene file's warnings to `err`.
    pub fn write_lines(&self, opts: &ProcessOptions, out: &mut dyn Write, err: &mut dyn Write) -> Result<()> {
        for w in &self.products.recovered.loaded.warnings {
            writeln!(err, "warning: {w}")?;
        }
        crate::igi::write_summary(&self.products.recovered, &self.written, out)?;
        writeln!(
            out,
            "processed {} → {} (scene file {})",
            opts.session.display(),
            opts.out.display(),
            self.products.scene_file.display()
        )?;
        for (stage, s) in self
            .processed
            .summary
            .stage_seconds
            .iter()
            .chain(&self.products.seconds)
        {
            writeln!(out, "  {stage:<44} {s:>7.2} s")?;
        }
        Ok(())
    }
}

impl OutdoorRun {
    /// Writes the run to `out`: the held-out views' errors, the stages'
    /// seconds, and per occurrence the sun, the sky and any notes.
    pub fn write_lines(&self, opts: &ProcessOptions, out: &mut dyn Write) -> Result<()> {
        for v in self.outdoor.iter().flat_map(|o| &o.products.held_out) {
            writeln!(
                out,
                "  held out {:<32} relative RMSE {:.2}% per pixel, {:.2}% per 4×4 block ({} training photos' texture; grid alone {:.2}%)",
                v.label,
                100.0 * v.rmse_pixel,
                100.0 * v.rmse_block,
                v.references,
                100.0 * v.rmse_block_grid
            )?;
        }
        writeln!(out, "processed {} → {}", opts.session.display(), opts.out.display())?;
        for (stage, s) in &self.processed.summary.stage_seconds {
            writeln!(out, "  {stage:<28} {s:>7.2} s")?;
        }
        for o in &self.processed.summary.occurrences {
            let sky = o.sky.as_ref().map_or("no sky".to_owned(), |s| {
                format!(
                    "sky {} (rms {:.1}%)",
                    s.channels[1].chosen,
                    100.0 * s.channels.iter().map(|c| c.rms_relative).fold(0.0, f64::max)
                )
            });
            let sun = o.sun_irradiance.map_or("no sun".to_owned(), |e| {
                format!("sun {:.0}/{:.0}/{:.0} W·m⁻²", e[0], e[1], e[2])
            });
            writeln!(out, "  {:<28} {sun}; {sky}", o.occurrence)?;
            for n in &o.notes {
                writeln!(out, "    note: {n}")?;
            }
        }
        Ok(())
    }
}

impl SkyRun {
    /// Writes the run to `out`: what was processed or merged, each day's
    /// extinction β and how many scans are flagged; the scans that failed
    /// to `err`.
    pub fn write_lines(&self, opts: &ProcessOptions, out: &mut dyn Write, err: &mut dyn Write) -> Result<()> {
        let dir = &opts.out;
        match &self.work {
            SkyWork::Scan(occurrence, scan) => writeln!(
                out,
                "processed {occurrence} → {}: flags [{}]",
                campanile_process::sky_series::scan_path(dir, occurrence).display(),
                scan.quality.names()
            )?,
            SkyWork::Merged(dirs, copied) => writeln!(
                out,
                "merged {dirs} shard directories ({copied} scan files copied): {} scans in {}",
                self.series.scans.len(),
                dir.display()
            )?,
            SkyWork::New(run) => {
                let rate = if run.scan_seconds > 0.0 {
                    run.processed.len() as f64 / run.scan_seconds
                } else {
                    0.0
                };
                writeln!(
                    out,
                    "sky series {} → {}{}",
                    opts.session.display(),
                    dir.display(),
                    opts.shard.map_or(String::new(), |s| format!(" (shard {s})"))
                )?;
                writeln!(
                    out,
                    "  processed {} scans in {:.2} s ({rate:.2} scans/s); {} already done, {} in other shards, {} still being captured",
                    run.processed.len(),
                    run.scan_seconds,
                    run.already_done,
                    run.other_shards,
                    run.incomplete.len()
                )?;
                writeln!(out, "  response: {}", run.response)?;
            }
        }
        for d in &self.series.days {
            let beta: Vec<String> = d
                .fit
                .iter()
                .map(|f| {
                    f.as_ref()
                        .map_or_else(|e| format!("none ({e})"), |e| format!("{:.4}", e.beta))
                })
                .collect();
            writeln!(
                out,
                "  {}: β r/g/b {} from {} scans ({} left out)",
                d.date,
                beta.join(" / "),
                d.points.len(),
                d.left_out
            )?;
        }
        let flagged = self
            .series
            .scans
            .iter()
            .filter(|s| !s.quality.names().is_empty())
            .count();
        writeln!(
            out,
            "  {} scans in the series, {flagged} flagged",
            self.series.scans.len()
        )?;
        if self.failure().is_some()
            && let SkyWork::New(run) = &self.work
        {
            for (occ, why) in &run.failed {
                writeln!(err, "  failed {occ}: {why}")?;
            }
        }
        Ok(())
    }
}

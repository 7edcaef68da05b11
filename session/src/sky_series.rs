//! `campanile process` on a sky-only session: the sky time series.
//!
//! Per scan (occurrence), in parallel: its sun and sky frames are read,
//! merged to HDR through the response, and reduced to
//! [`ScanProducts`] in `OUT/scans/`; then, once that file is on disk, the
//! occurrence is added to `SESSION/processed/products.ron` (when OUT is
//! the session's own `processed/`), after which the station may delete its
//! raw frames. The per-day products are recomputed from `OUT/scans/` alone.
//!
//! The station's hook calls [`process_scan`] for each finished occurrence
//! (or [`process_new_scans`] for everything new) and then [`recompute_day`].

use std::collections::{BTreeSet, HashSet};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Instant;

use crate::Result;
use anyhow::{Context, anyhow};
use campanile_capture::schedule::{ShotKind as PlannedKind, TimelineOptions, timeline};
use campanile_capture::store::{FrameEntry, JournalEntry, PROCESSED_DIR, ProcessedProducts};
use campanile_config::Plan;
use campanile_config::plan::{Aim, Step};
use campanile_process::hdr::curve::ResponseCurve;
use campanile_process::hdr::curve_plot::curve_plot_svg;
use campanile_process::hdr::debevec::DebevecOptions;
use campanile_process::pipeline::{StationOptics, calibrate_response, group_frames, merge_groups};
use campanile_process::quality::{Quality, QualityReport, gates};
use campanile_process::report::{Report, Section, Table};
use campanile_process::sky_series::{ScanProducts, Shard, SkySeries, scan_path, scan_products, store, write_scan};
use rayon::prelude::*;

use crate::process::SessionInputs;

/// How to process a sky-only session.
#[derive(Debug, Clone)]
pub struct SkySeriesOptions {
    /// Output directory (the session's `processed/` by default).
    pub out: PathBuf,
    /// A response curve (CSV from `campanile hdr calibrate` or a session's
    /// `processed/response.csv`); without it, `OUT/response.csv` of an
    /// earlier run, else the session's calibration bracket.
    pub response: Option<PathBuf>,
    /// Only this share of the scans.
    pub shard: Option<Shard>,
    /// Response recovery options (for the session's calibration bracket).
    pub debevec: DebevecOptions,
    /// A calibrated camera (`CameraCalibration(...)` from `campanile sky
    /// calibrate`) that replaces the session station's camera intrinsics
    /// and mount: a mis-set sky camera's frames are sampled through it.
    pub camera_calibration: Option<PathBuf>,
}

/// The optics the scans are processed with: the session's station, its
/// camera and mount replaced by `opts`' calibration where one is given.
fn optics_of(inputs: &SessionInputs, opts: &SkySeriesOptions) -> Result<StationOptics> {
    let Some(path) = &opts.camera_calibration else {
        return Ok(StationOptics::of_station(&inputs.station));
    };
    let cal =
        campanile_config::document::load_camera_calibration(path).map_err(|e| crate::Error::input(e.to_string()))?;
    let station = cal
        .value
        .apply_to(&inputs.station)
        .map_err(|e| crate::Error::input(format!("{}: {e}", path.display())))?;
    Ok(StationOptics::of_station(&station))
}

impl SkySeriesOptions {
    /// Whether the products list of `session` is kept up to date: only when
    /// OUT is the session's own `processed/` and the run is not a shard
    /// (concurrent shards would race on the one file; `--merge-shards`
    /// lists their scans).
    fn lists_products(&self, session: &Path) -> bool {
        self.shard.is_none() && same_dir(&self.out, &session.join(PROCESSED_DIR))
    }
}

fn same_dir(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => a == b,
    }
}

/// What a run did.
#[derive(Debug)]
pub struct ScanRun {
    /// Occurrences processed now, in id order.
    pub processed: Vec<String>,
    /// Occurrences skipped because their products exist.
    pub already_done: usize,
    /// Occurrences left to other shards.
    pub other_shards: usize,
    /// Occurrences still being captured (not every promised shot journaled).
    pub incomplete: Vec<String>,
    /// Occurrences that failed, and why.
    pub failed: Vec<(String, String)>,
    /// How many of them failed on bad input (a damaged frame file: exit 2).
    pub failed_on_input: usize,
    /// Where the response came from.
    pub response: String,
    /// Seconds spent on the scans (reading, merging, fitting, writing).
    pub scan_seconds: f64,
    /// The day's products, recomputed from every per-scan file in OUT.
    pub series: SkySeries,
}

/// Whether every step of `plan` is a sky or sun step (sun shots, sky scans,
/// and brackets aimed at head angles or the sun, e.g. a calibration
/// bracket): such a session is processed as a sky time series. Brackets
/// alone are one too when the plan names a scene (a sky station's
/// calibration day, which gives the series its response); with no scene
/// and no scan (an astro camera's bracket) they are merged into HDR views
/// as any session's brackets are.
pub fn is_sky_only(plan: &Plan) -> bool {
    let steps = || plan.sessions.iter().flat_map(|s| &s.steps);
    let sky_or_sun = steps().all(|step| match step {
        Step::SunShot { .. } | Step::SkyScan { .. } => true,
        Step::Bracket { aim, .. } | Step::AutoBracket { aim, .. } => !matches!(aim, Aim::Pose(_)),
        _ => false,
    });
    sky_or_sun
        && (plan.scene.is_some() || steps().any(|step| matches!(step, Step::SunShot { .. } | Step::SkyScan { .. })))
}

/// The occurrence and plan step of a frame key `"{occurrence}/s{step}/…"`.
fn occurrence_and_step(key: &str) -> Option<(&str, usize)> {
    let mut parts = key.split('/');
    let occ = parts.next()?;
    let step = parts.next()?.strip_prefix('s')?.parse().ok()?;
    Some((occ, step))
}

fn step_of<'a>(inputs: &'a SessionInputs, key: &str) -> Option<&'a Step> {
    let (occ, step) = occurrence_and_step(key)?;
    inputs.session_of(occ)?.steps.get(step)
}

/// The occurrences with a sun shot or a sky scan in the journal, in id order.
fn scan_occurrences(inputs: &SessionInputs) -> BTreeSet<String> {
    inputs
        .reader
        .frames()
        .filter(|f| {
            matches!(
                step_of(inputs, &f.key),
                Some(Step::SunShot { .. } | Step::SkyScan { .. })
            )
        })
        .filter_map(|f| occurrence_and_step(&f.key).map(|(o, _)| o.to_owned()))
        .collect()
}

/// Which occurrences are finished: those of the plan's timeline whose
/// promised data shots are all journaled (taken or missed); an occurrence
/// the timeline does not know (or every one, when the timeline cannot be
/// rebuilt) is finished once a later occurrence has journaled something.
struct Finished {
    /// Occurrences of the timeline, and whether each is finished.
    planned: std::collections::HashMap<String, bool>,
    /// The occurrence of the journal's last line.
    last: Option<String>,
}

impl Finished {
    fn of(inputs: &SessionInputs) -> Finished {
        let journaled: HashSet<&str> = inputs.reader.entries().iter().map(JournalEntry::key).collect();
        let planned = timeline(&inputs.plan, &inputs.station, None, &TimelineOptions::default())
            .map(|t| {
                t.occurrences
                    .iter()
                    .map(|o| {
                        let done = o
                            .shots
                            .iter()
                            .filter(|s| s.promised && s.kind == PlannedKind::Data)
                            .all(|s| journaled.contains(s.key.as_str()));
                        (o.key.clone(), done)
                    })
                    .collect()
            })
            .unwrap_or_default();
        Finished {
            planned,
            last: last_occurrence(inputs),
        }
    }

    fn contains(&self, occurrence: &str) -> bool {
        match self.planned.get(occurrence) {
            Some(&done) => done,
            None => self.last.as_deref() != Some(occurrence),
        }
    }
}

fn last_occurrence(inputs: &SessionInputs) -> Option<String> {
    inputs
        .reader
        .entries()
        .last()
        .and_then(|e| occurrence_and_step(e.key()).map(|(o, _)| o.to_owned()))
}

/// The response for the session: `--response`, else `OUT/response.csv`
/// from an earlier run, else calibrated from the session's calibration
/// bracket (and saved as `OUT/response.csv`, so later runs and the scans of
/// the same day share it even after the bracket's raw frames are deleted).
fn response(inputs: &SessionInputs, opts: &SkySeriesOptions) -> Result<(ResponseCurve, String)> {
    let saved = opts.out.join("response.csv");
    let read = |p: &Path| -> Result<ResponseCurve> {
        let text = std::fs::read_to_string(p).with_context(|| format!("{}: cannot read the response", p.display()))?;
        ResponseCurve::from_csv(&text, p).map_err(|e| anyhow!("{e}").into())
    };
    if let Some(p) = &opts.response {
        let curve = read(p)?;
        if !saved.is_file() {
            store::write_atomic(&saved, &std::fs::read(p)?)?;
        }
        return Ok((curve, format!("given: {}", p.display())));
    }
    if saved.is_file() {
        return Ok((read(&saved)?, format!("{} (an earlier run's)", saved.display())));
    }
    let is_bracket = |e: &FrameEntry| matches!(step_of(inputs, &e.key), Some(Step::Bracket { .. }));
    let bar = crate::progress::bar(0, "calibration bracket");
    let frames = inputs.frames_where(&bar, is_bracket)?;
    bar.finish_and_clear();
    if frames.is_empty() {
        bail!(
            "{}: a sky-only session with no calibration bracket (a Bracket step of two or more unfiltered \
             exposures): pass a response curve with --response FILE.csv (from `campanile hdr calibrate`, or \
             another session's processed/response.csv)",
            inputs.reader.dir().display()
        );
    }
    let groups = group_frames(frames);
    let (calibration, choice) = calibrate_response(&groups, &opts.debevec)
        .with_context(|| format!("{}: the calibration bracket", inputs.reader.dir().display()))?;
    let csv = calibration.curve.to_csv(&calibration.method);
    store::write_atomic(&saved, csv.as_bytes())?;
    let svg = curve_plot_svg(&calibration.curve, "recovered camera response (full-well gauge)")?;
    store::write_atomic(&opts.out.join("response.svg"), svg.as_bytes())?;
    // The curve as saved (to the CSV's precision): every scan of the day,
    // in this run or a later one, in any shard, goes through the same numbers.
    let curve = ResponseCurve::from_csv(&csv, &saved).map_err(|e| anyhow!("{e}"))?;
    Ok((curve, format!("calibrated from {}: {}", choice.group, choice.reason)))
}

/// One scan's products from the session's frames (nothing written).
fn scan(
    inputs: &SessionInputs,
    optics: &StationOptics,
    curve: &ResponseCurve,
    occurrence: &str,
) -> Result<ScanProducts> {
    let bar = indicatif::ProgressBar::hidden();
    let frames = inputs.frames_where(&bar, |e| {
        occurrence_and_step(&e.key).is_some_and(|(o, _)| o == occurrence)
            && matches!(
                step_of(inputs, &e.key),
                Some(Step::SunShot { .. } | Step::SkyScan { .. })
            )
    })?;
    let groups = group_frames(frames);
    let merged = merge_groups(&groups, curve, optics)?;
    Ok(scan_products(&merged, optics, occurrence)?)
}

fn add_to_products(session: &Path, lock: &Mutex<()>, occurrences: &[String]) -> Result<()> {
    let _held = lock
        .lock()
        .map_err(|_| anyhow!("the products list's lock was poisoned"))?;
    let mut list = ProcessedProducts::read(session)?;
    list.occurrences.extend(occurrences.iter().cloned());
    list.write(session)?;
    Ok(())
}

/// Processes one finished occurrence of the sky-only session in `session`:
/// writes `OUT/scans/<occurrence>.ron` and then (OUT being the session's
/// `processed/`, no shard) lists it in `SESSION/processed/products.ron`.
/// Does not recompute the day: call [`recompute_day`] after.
pub fn process_scan(session: &Path, occurrence: &str, opts: &SkySeriesOptions) -> Result<ScanProducts> {
    let inputs = SessionInputs::open(session, None)?;
    let optics = optics_of(&inputs, opts)?;
    let (curve, _) = response(&inputs, opts)?;
    let products = scan(&inputs, &optics, &curve, occurrence).with_context(|| format!("scan {occurrence}"))?;
    write_scan(&opts.out, &products)?;
    if opts.lists_products(session) {
        add_to_products(session, &Mutex::new(()), &[occurrence.to_owned()])?;
    }
    Ok(products)
}

/// Recomputes the per-day products in `out` from its per-scan files alone.
pub fn recompute_day(out: &Path) -> Result<SkySeries> {
    Ok(store::write_day(out)?)
}

/// Processes every finished scan of `session` in this shard that has no
/// products yet (in `OUT/scans/`, or listed in the session's products list),
/// then recomputes the day.
pub fn process_new_scans(session: &Path, opts: &SkySeriesOptions) -> Result<ScanRun> {
    let inputs = SessionInputs::open(session, None)?;
    let optics = optics_of(&inputs, opts)?;
    let listed = ProcessedProducts::read(session)?;
    let lists = opts.lists_products(session);
    let finished = Finished::of(&inputs);
    let (mut todo, mut already_done, mut other_shards, mut incomplete) = (Vec::new(), 0, 0, Vec::new());
    for occ in scan_occurrences(&inputs) {
        if scan_path(&opts.out, &occ).is_file() || (lists && listed.contains(&occ)) {
            already_done += 1;
        } else if opts.shard.is_some_and(|s| !s.contains(&occ)) {
            other_shards += 1;
        } else if !finished.contains(&occ) {
            incomplete.push(occ);
        } else {
            todo.push(occ);
        }
    }
    let t = Instant::now();
    // A session that holds only a calibration bracket (no scan at all)
    // still gets its response: that is what it was captured for (a
    // station's curve, before `station run --process --response`).
    let calibration_only = already_done + other_shards + incomplete.len() == 0
        && opts.response.is_none()
        && !opts.out.join("response.csv").is_file()
        && inputs
            .reader
            .frames()
            .any(|f| matches!(step_of(&inputs, &f.key), Some(Step::Bracket { .. })));
    let (curve, response_source) = if todo.is_empty() && !calibration_only {
        (None, "not needed (no new scan)".to_owned())
    } else {
        let (c, s) = response(&inputs, opts)?;
        (Some(c), s)
    };
    let lock = Mutex::new(());
    let bar = crate::progress::bar(todo.len() as u64, "sky scans");
    let outcomes: Vec<(String, Result<()>)> = match &curve {
        None => Vec::new(),
        Some(curve) => todo
            .par_iter()
            .map(|occ| {
                let r = scan(&inputs, &optics, curve, occ)
                    .and_then(|p| Ok(write_scan(&opts.out, &p)?))
                    .and_then(|_| {
                        if lists {
                            add_to_products(session, &lock, std::slice::from_ref(occ))
                        } else {
                            Ok(())
                        }
                    });
                bar.inc(1);
                (occ.clone(), r)
            })
            .collect(),
    };
    bar.finish_and_clear();
    let scan_seconds = t.elapsed().as_secs_f64();
    let mut processed = Vec::new();
    let mut failed = Vec::new();
    let mut failed_on_input = 0;
    for (occ, r) in outcomes {
        match r {
            Ok(()) => processed.push(occ),
            Err(e) => {
                failed_on_input += usize::from(e.is_bad_input());
                failed.push((occ, format!("{e:#}")));
            }
        }
    }
    let series = recompute_day(&opts.out)?;
    Ok(ScanRun {
        processed,
        already_done,
        other_shards,
        incomplete,
        failed,
        failed_on_input,
        response: response_source,
        scan_seconds,
        series,
    })
}

/// Merges shard outputs: copies the per-scan files of `shards` into OUT,
/// lists every scan in OUT in the session's products list (OUT being the
/// session's `processed/`), and recomputes the day.
pub fn merge_shards(session: &Path, shards: &[PathBuf], opts: &SkySeriesOptions) -> Result<(usize, SkySeries)> {
    let copied = store::merge_scan_dirs(&opts.out, shards)?;
    for shard in shards {
        let (mine, theirs) = (opts.out.join("response.csv"), shard.join("response.csv"));
        if !mine.is_file() && theirs.is_file() {
            store::write_atomic(&mine, &std::fs::read(&theirs)?)?;
        }
    }
    let series = recompute_day(&opts.out)?;
    if same_dir(&opts.out, &session.join(PROCESSED_DIR)) {
        let occurrences: Vec<String> = series.scans.iter().map(|s| s.occurrence.clone()).collect();
        add_to_products(session, &Mutex::new(()), &occurrences)?;
    }
    Ok((copied, series))
}

/// The verdicts of these scans of a series: each one's sun and sky.
pub fn series_quality<'a>(scans: impl Iterator<Item = &'a ScanProducts>, thresholds: &Quality) -> QualityReport {
    let products = scans.flat_map(|s| gates::scan(s, thresholds)).collect();
    QualityReport::new(products, thresholds)
}

/// The report page of the series.
pub fn report(
    session: &Path,
    series: &SkySeries,
    run: Option<&ScanRun>,
    quality: Option<QualityReport>,
) -> Result<Report> {
    let mut sections = campanile_process::sky_series::sky_series_sections(series)?;
    if let Some(r) = run {
        let rate = if r.scan_seconds > 0.0 {
            r.processed.len() as f64 / r.scan_seconds
        } else {
            0.0
        };
        sections.push(Section {
            title: "Speed".into(),
            paragraphs: vec![format!("Response: {}.", r.response)],
            tables: vec![Table {
                caption: "this run".into(),
                header: vec!["what".into(), "value".into()],
                rows: vec![
                    vec!["scans processed".into(), r.processed.len().to_string()],
                    vec!["scans already done (skipped)".into(), r.already_done.to_string()],
                    vec!["scans of other shards".into(), r.other_shards.to_string()],
                    vec!["scans still being captured".into(), r.incomplete.len().to_string()],
                    vec!["scans failed".into(), r.failed.len().to_string()],
                    vec!["seconds on scans".into(), format!("{:.2}", r.scan_seconds)],
                    vec!["scans per second".into(), format!("{rate:.2}")],
                ],
            }],
            figures: Vec::new(),
        });
    }
    Ok(Report {
        title: format!("Campanile sky time series: {}", session.display()),
        summary: quality
            .as_ref()
            .map(crate::report_summary::from_quality)
            .unwrap_or_default(),
        intro: vec![format!(
            "Sky-only session {}, processed by campanile {}: every figure below is recomputed from the per-scan products in scans/.",
            session.display(),
            env!("CARGO_PKG_VERSION")
        )],
        quality,
        sections,
    })
}

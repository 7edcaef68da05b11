//! `campanile station run --process --response CSV` end to end (issue 12):
//! the example sky station (`examples/sky-station.ron`, a sun triplet and a
//! sky scan, here every 2 hours for 2 days) on the 64×48
//! `examples/sky-sim-station.ron`, with a storage budget of 1.5 MB (the two
//! days take about 4 MB).
//!
//! 1. Day 1 without `--process` (`--days 1`): the store goes over budget,
//!    the station warns, and nothing is deleted (no scan is processed).
//! 2. The same store with `--process --response CSV` for both days: day 1's
//!    settled scans are processed when the run reaches them, day 2's as
//!    they finish; frames are deleted only of scans whose products exist
//!    (listed in `processed/products.ron`, `processed/scans/<id>.ron` on
//!    disk), and the store ends within budget.
//!
//! Each day's `processed/sky-series.csv` is then checked row by row: one
//! row per scan, the sun's direct normal irradiance and the fitted sky
//! (rebuilt from the row's eq. 5.9 parameters) against the simulator's
//! truth. The response given is the simulator's own (`sim_response`): the
//! plan has no calibration bracket.

mod common;
mod sim_response;

use std::collections::{BTreeMap, HashSet};
use std::path::{Path, PathBuf};

use campanile_capture::store::{JournalEntry, PROCESSED_DIR, ProcessedProducts, SessionReader};
use campanile_capture::unattended::Heartbeat;
use campanile_capture::unattended::day_rollover::{day_dir, existing_days};
use campanile_process::pipeline::TRIPLET_AGREEMENT;
use campanile_process::sky::{SkyModel, angle_between, direction};
use campanile_process::sky_series::{scan_path, series_width};
use campanile_sim::world::{World, load_scene};
use chrono::{DateTime, NaiveDate, Utc};
use common::campanile;

const BUDGET_BYTES: u64 = 1_500_000;
/// Direct normal sun irradiance per channel (the triplet's mean) against
/// the simulator's, on every scan.
const SUN_TOLERANCE: f64 = 0.08;
/// RMS relative error of the row's sky against the simulator's (above 10°
/// elevation, more than 10° from the sun), per channel.
const SKY_TOLERANCE: f64 = 0.10;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// Runs `campanile ARGS…`, which must succeed; returns stdout and stderr.
fn run(args: &[&str]) -> (String, String) {
    let out = campanile(args);
    let (stdout, stderr) = (text(&out.stdout), text(&out.stderr));
    assert!(
        out.status.success(),
        "campanile {args:?}\nstdout:\n{stdout}\nstderr:\n{stderr}"
    );
    (stdout, stderr)
}

/// The frames of `dir`'s journal: (key, file, pruned).
fn frames(dir: &Path) -> Vec<(String, PathBuf, bool)> {
    let reader = SessionReader::open(dir).unwrap();
    let pruned = reader.pruned_keys();
    reader
        .entries()
        .iter()
        .filter_map(JournalEntry::frame)
        .map(|f| (f.key.clone(), dir.join(&f.file), pruned.contains(f.key.as_str())))
        .collect()
}

fn occurrence_of(key: &str) -> &str {
    key.split('/').next().unwrap_or_default()
}

#[test]
fn station_run_processes_each_scan_and_the_budget_deletes_only_processed_frames() {
    let tmp = tempfile::tempdir().unwrap();
    let sim_response::TwoDaySkyStation {
        plan,
        station_path,
        station,
        response,
    } = sim_response::two_day_sky_station(tmp.path());
    let store = tmp.path().join("store");
    let budget = BUDGET_BYTES.to_string();
    let base = [
        "station",
        "run",
        "--sim-bounces",
        "1",
        plan.to_str().unwrap(),
        "--station",
        station_path.to_str().unwrap(),
        "--store",
        store.to_str().unwrap(),
        "--budget",
        &budget,
    ];
    let day = |d: u32| NaiveDate::from_ymd_opt(2026, 6, d).unwrap();

    // 1. Day 1 without --process: over budget, nothing deletable.
    let mut first = base.to_vec();
    first.extend(["--days", "1"]);
    let (stdout, stderr) = run(&first);
    println!("{stdout}");
    assert!(stdout.contains("pruned               0 frames, 0 bytes"), "{stdout}");
    assert!(
        stderr.contains("the storage budget is exceeded and no more processed frames can be deleted"),
        "{stderr}"
    );
    let beat = Heartbeat::read(&store).unwrap();
    assert!(beat.store_bytes > BUDGET_BYTES, "{} bytes", beat.store_bytes);
    let day1 = frames(&day_dir(&store, day(21)));
    assert!(day1.len() > 100, "{} frames", day1.len());
    assert!(day1.iter().all(|(_, file, pruned)| !pruned && file.is_file()));
    assert!(!day_dir(&store, day(21)).join(PROCESSED_DIR).exists());

    // 2. Both days with --process.
    let mut second = base.to_vec();
    second.extend(["--process", "--response", response.to_str().unwrap()]);
    let (stdout, _) = run(&second);
    println!("{stdout}");
    assert!(
        stdout.contains("every occurrence of the plan's days is settled"),
        "{stdout}"
    );
    assert_eq!(existing_days(&store).unwrap(), [day(21), day(22)]);

    let scene = root().join("examples/sky-scene.ron");
    let world = World::new(&station, load_scene(&scene).unwrap());
    let (mut pruned_frames, mut pruned_scans, mut kept_bytes, mut rows_total, mut flagged) =
        (0, HashSet::new(), 0u64, 0, 0);
    let mut worst_sun = [0.0f64; 3];
    let mut worst_sky = [0.0f64; 3];
    let mut beyond: Vec<(String, f64, f64)> = Vec::new();
    for d in [day(21), day(22)] {
        let dir = day_dir(&store, d);
        let out = dir.join(PROCESSED_DIR);
        let listed = ProcessedProducts::read(&dir).unwrap();
        let all = frames(&dir);
        let scans: HashSet<&str> = all.iter().map(|(k, _, _)| occurrence_of(k)).collect();
        for (key, file, pruned) in &all {
            let occ = occurrence_of(key);
            if *pruned {
                // Deleted only once the scan's products exist.
                assert!(listed.contains(occ), "{key} pruned, {occ} not listed");
                assert!(scan_path(&out, occ).is_file(), "{key} pruned, no products of {occ}");
                assert!(!file.exists(), "{} still on disk", file.display());
                pruned_frames += 1;
                pruned_scans.insert(occ.to_owned());
            } else {
                assert!(file.is_file(), "{} is gone", file.display());
                kept_bytes += std::fs::metadata(file).unwrap().len();
            }
        }

        // The day's time series: one row per scan.
        let csv = std::fs::read_to_string(out.join("sky-series.csv")).unwrap();
        let mut lines = csv.lines().filter(|l| !l.starts_with('#'));
        let header: Vec<&str> = lines.next().unwrap().split(',').collect();
        assert_eq!(header.len(), series_width());
        let col = |name: &str| {
            header
                .iter()
                .position(|h| *h == name)
                .unwrap_or_else(|| panic!("no column {name}"))
        };
        let rows: BTreeMap<String, Vec<String>> = lines
            .map(|l| {
                let cells: Vec<String> = l.split(',').map(str::to_owned).collect();
                assert_eq!(cells.len(), header.len(), "{l}");
                (cells[0].clone(), cells)
            })
            .collect();
        let row_ids: HashSet<&str> = rows.keys().map(String::as_str).collect();
        assert_eq!(row_ids, scans, "{d}: one row per scan");
        assert_eq!(listed.occurrences.len(), scans.len(), "{d}: every scan listed");
        rows_total += rows.len();

        // Each row against the simulator's truth.
        let reports = campanile_process::sky_series::read_scans(&out).unwrap();
        for (id, r) in &rows {
            let cell = |name: &str| -> f64 {
                r[col(name)]
                    .parse()
                    .unwrap_or_else(|_| panic!("{id}: {name} = {:?}", r[col(name)]))
            };
            let time = DateTime::parse_from_rfc3339(&r[col("time_utc")])
                .unwrap()
                .with_timezone(&Utc);
            let scan = reports.iter().find(|s| &s.occurrence == id).unwrap();
            let sun = scan
                .sun
                .as_ref()
                .unwrap_or_else(|| panic!("{id}: no sun {:?}", scan.notes));
            // The triplet's agreement decides the flag (at 64×48 the disc
            // covers a tenth of a pixel, and the simulator's sampling of it
            // makes the three frames differ by a few percent: the flag is
            // then a false alarm, the mean still within the bound).
            let flags = &r[col("flags")];
            let spread = sun.spread.iter().copied().fold(0.0, f64::max);
            assert_eq!(
                flags.contains("clouds_near_sun"),
                spread > TRIPLET_AGREEMENT,
                "{id}: spread {spread} and flags [{flags}]"
            );
            flagged += usize::from(spread > TRIPLET_AGREEMENT);
            let truth = world.daylight(sun.time_utc).unwrap().unwrap().sun_irradiance();
            for (c, ch) in ["r", "g", "b"].iter().enumerate() {
                let got = cell(&format!("sun_e_{ch}_w_m2"));
                assert_eq!(got, sun.irradiance_w_m2[c], "{id}: the row is the scan's");
                let rel = (got / truth[c] - 1.0).abs();
                worst_sun[c] = worst_sun[c].max(rel);
                beyond.push((format!("{id} sun {ch}"), rel, SUN_TOLERANCE));
            }
            let daylight = world.daylight(time).unwrap().unwrap();
            let sun_dir = daylight.sun_direction;
            let dirs: Vec<[f64; 3]> = (0..14)
                .flat_map(|k| {
                    (0..36)
                        .map(move |j| direction((6.0 * f64::from(k)).to_radians(), (10.0 * f64::from(j)).to_radians()))
                })
                .filter(|v| v[2] > 10f64.to_radians().sin() && angle_between(*v, sun_dir) > 10f64.to_radians())
                .collect();
            for (c, ch) in ["r", "g", "b"].iter().enumerate() {
                let p = |x: &str| cell(&format!("sky_{x}_{ch}"));
                let model = SkyModel {
                    lz: cell(&format!("sky_lz_{ch}_w_m2_sr")),
                    a: p("a"),
                    b: p("b"),
                    c: p("c"),
                    d: p("d"),
                    e: p("e"),
                    h: p("h"),
                };
                let ms = dirs
                    .iter()
                    .map(|&v| {
                        (model.radiance(v[2].acos(), angle_between(v, sun_dir)) / daylight.sky_radiance(v)[c] - 1.0)
                            .powi(2)
                    })
                    .sum::<f64>()
                    / dirs.len() as f64;
                worst_sky[c] = worst_sky[c].max(ms.sqrt());
                beyond.push((format!("{id} sky {ch}"), ms.sqrt(), SKY_TOLERANCE));
            }
        }
    }
    println!(
        "{rows_total} rows ({flagged} flagged clouds_near_sun); pruned {pruned_frames} frames of {} scans; kept {kept_bytes} bytes of frames; worst sun r/g/b {worst_sun:.4?}; worst sky RMS r/g/b {worst_sky:.4?}",
        pruned_scans.len()
    );
    assert!(pruned_frames > 0, "the budget forced deletions");
    assert!(rows_total >= 12, "{rows_total} rows");
    let beat = Heartbeat::read(&store).unwrap();
    assert!(beat.store_bytes <= BUDGET_BYTES, "{} bytes kept", beat.store_bytes);
    let failed: Vec<_> = beyond.iter().filter(|(_, v, bound)| v.is_nan() || v >= bound).collect();
    assert!(failed.is_empty(), "beyond bounds: {failed:?}");
}

//! Sky conditions (issue 29) against the simulator's truth: one day of
//! `examples/sky-station.ron` on `examples/sky-sim-station.ron` (64 × 48)
//! under a seeded broken-cloud layer (`--sim-broken-clouds`,
//! `sim::world::broken_clouds`), run as `campanile station run --process
//! --on-condition-change CMD` runs it (the library's station run and scan
//! processor), then every scan's regions, sun neighbourhood and cloud cover
//! scored against the layer's truth at the scan's time.
//!
//! The cheap test keeps every third scan of the plan (one every 30
//! minutes); the ignored one, the benchmark's figure, keeps all of them
//! (one every 10 minutes):
//! `cargo test --test sky_conditions -- --ignored --nocapture`.

mod sim_response;

use std::path::{Path, PathBuf};
use std::time::Instant;

use campanile_capture::unattended::StationOptions;
use campanile_capture::unattended::day_rollover::{day_dir, existing_days};
use campanile_process::sky_series::{SkySeries, read_scans};
use campanile_session::capture_inputs::Inputs;
use campanile_session::condition_hook::ConditionHook;
use campanile_session::scan_processor::{SkySeriesProcessor, StationHook};
use campanile_session::station_run::{StationRun, broken_clouds_for, run_simulated};
use campanile_sim::world::broken_clouds::Detection;

/// The layer's seed: a day with clear spells (the reference needs clear
/// scans) and scattered, broken and near-overcast hours.
const SEED: u64 = 7;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Runs one broken-cloud day keeping every `every`-th scan; returns the
/// day's series, its score and the hook's log lines.
fn broken_cloud_day(every: usize) -> (SkySeries, Detection, Vec<String>) {
    let mut inputs = Inputs::from_files(
        &root().join("examples/sky-station.ron"),
        &root().join("examples/sky-sim-station.ron"),
        Some(1),
    )
    .unwrap();
    inputs.timeline.occurrences = std::mem::take(&mut inputs.timeline.occurrences)
        .into_iter()
        .step_by(every)
        .collect();
    let clouds = broken_clouds_for(&inputs, SEED).unwrap();
    // In memory when the machine has /dev/shm (as station_days does): the
    // test is about the index, not about waiting on fsynced frames.
    let shm = Path::new("/dev/shm");
    let tmp = if shm.is_dir() {
        tempfile::tempdir_in(shm).unwrap()
    } else {
        tempfile::tempdir().unwrap()
    };
    let response = tmp.path().join("response.csv");
    sim_response::write_true_response(&response, inputs.station.camera.bit_depth);
    let log = tmp.path().join("hook.log");
    let script = tmp.path().join("hook.sh");
    std::fs::write(&script, format!("echo \"$#|$*\" >> '{}'\n", log.display())).unwrap();
    let run = StationRun {
        store: tmp.path().join("sky"),
        options: StationOptions::default(),
        // As the station tests render (station_days): 2 paths a pixel, 1 bounce.
        samples: 2,
        bounces: 1,
        outages: Vec::new(),
        broken_clouds: Some(SEED),
        on_condition_change: None,
    };
    let mut hook = StationHook(SkySeriesProcessor {
        response,
        thresholds: inputs.plan.plan.value.quality.clone().unwrap_or_default(),
        camera_calibration: None,
        on_condition_change: Some(ConditionHook::new(format!("sh '{}'", script.display()))),
    });
    run_simulated(&run, &inputs, &mut hook, &|_| Ok(()))
        .unwrap()
        .expect("the station day finishes");
    let days = existing_days(&run.store).unwrap();
    assert_eq!(days.len(), 1);
    let out = day_dir(&run.store, days[0]).join("processed");
    let series = SkySeries::new(read_scans(&out).unwrap());
    assert_eq!(series.scans.len(), inputs.timeline.occurrences.len());
    let score = clouds.score(&series);
    let lines = std::fs::read_to_string(&log)
        .unwrap_or_default()
        .lines()
        .map(str::to_owned)
        .collect();
    // The series files carry the new columns.
    let csv = std::fs::read_to_string(out.join("sky-series.csv")).unwrap();
    let header = csv.lines().find(|l| !l.starts_with('#')).unwrap();
    for column in [
        "clear_sky_index",
        "direct_clear_sky_index",
        "cloud_cover",
        "clouds_near_sun_region",
        "sky_condition",
    ] {
        assert!(header.split(',').any(|c| c == column), "{column} missing: {header}");
    }
    (series, score, lines)
}

fn print(score: &Detection, every: usize) {
    println!(
        "broken-cloud day (seed {SEED}, every {every} scan(s)): {} scans, {} scored",
        score.scans, score.scored
    );
    let r = &score.regions;
    println!(
        "regions: {} hits, {} misses, {} false alarms, {} correct clear: hit rate {:.3}, false-alarm rate {:.3}, accuracy {:.3}",
        r.hits,
        r.misses,
        r.false_alarms,
        r.correct_rejections,
        r.hit_rate(),
        r.false_alarm_rate(),
        r.accuracy()
    );
    let n = &score.near_sun;
    println!(
        "clouds near the sun: {} hits, {} misses, {} false alarms, {} correct clear: hit rate {:.3}, false-alarm rate {:.3}",
        n.hits,
        n.misses,
        n.false_alarms,
        n.correct_rejections,
        n.hit_rate(),
        n.false_alarm_rate()
    );
    println!(
        "cloud cover: mean |error| {:.3}; condition word right in {} of {}",
        score.cover_mean_abs_error, score.condition_agreements, score.scored
    );
    // The departure from clear by the truth's cloud fraction: what the threshold is chosen on.
    for (lo, hi) in [(0.0, 0.02), (0.02, 0.1), (0.1, 0.25), (0.25, 0.5), (0.5, 1.01)] {
        let mut d: Vec<f64> = score
            .departures
            .iter()
            .filter(|(f, _)| (lo..hi).contains(f))
            .map(|&(_, d)| d)
            .collect();
        d.sort_by(f64::total_cmp);
        let q = |p: f64| {
            d.get(((d.len() as f64 - 1.0) * p).round() as usize)
                .copied()
                .unwrap_or(f64::NAN)
        };
        println!(
            "  true cloud fraction {lo:.2}–{hi:.2}: {} regions, departure p10 {:.3} median {:.3} p90 {:.3} max {:.3}",
            d.len(),
            q(0.1),
            q(0.5),
            q(0.9),
            q(1.0)
        );
    }
    for (occ, p, t, pw, tw) in &score.rows {
        println!("  {occ}: cover {p:.3} (true {t:.3}) {pw} (true {tw})");
    }
}

/// The bounds both runs are held to (measured: see BENCHMARKS.md).
fn check(series: &SkySeries, score: &Detection, hook_lines: &[String], path: &Path) {
    // Every scan has a condition or says why not; no NaN anywhere.
    for (s, c) in series.scans.iter().zip(&series.conditions) {
        assert!(
            c.cloud_cover.is_some() || !c.note.is_empty(),
            "{}: no cover and no reason",
            s.occurrence
        );
        for v in [c.clear_sky_index, c.direct_clear_sky_index, c.cloud_cover]
            .into_iter()
            .flatten()
        {
            assert!(v.is_finite(), "{}: {v}", s.occurrence);
        }
    }
    assert!(
        score.scored * 10 >= score.scans * 8,
        "{} of {} scans scored",
        score.scored,
        score.scans
    );
    // Measured on the 30-minute day: hit rate 0.963, false-alarm rate
    // 0.177 (most in regions 10–25% covered, which the truth calls clear
    // and whose departure straddles the threshold), near the sun 25 of 28
    // right, cover 0.179 too high on average (a partly covered region
    // counts whole).
    assert!(score.regions.hit_rate() >= 0.9, "{path:?}: {:?}", score.regions);
    assert!(
        score.regions.false_alarm_rate() <= 0.25,
        "{path:?}: {:?}",
        score.regions
    );
    assert!(score.near_sun.accuracy() >= 0.8, "{path:?}: {:?}", score.near_sun);
    assert!(
        score.cover_mean_abs_error <= 0.25,
        "{path:?}: {}",
        score.cover_mean_abs_error
    );
    // The hook ran on each change and only then: eight arguments, the
    // new condition first and differing from the old.
    assert!(!hook_lines.is_empty());
    for line in hook_lines {
        let (count, args) = line.split_once('|').unwrap();
        assert_eq!(count, "8", "{line}");
        let words: Vec<&str> = args.split(' ').collect();
        assert!(
            ["clear", "partly-cloudy", "cloudy", "overcast"].contains(&words[0]),
            "{line}"
        );
        assert_ne!(words[0], words[1], "{line}");
    }
}

#[test]
fn a_broken_cloud_day_is_detected_against_the_truth() {
    let wall = Instant::now();
    let (series, score, lines) = broken_cloud_day(3);
    print(&score, 3);
    check(&series, &score, &lines, Path::new("every 3"));
    println!("{} hook runs; wall {:.1} s", lines.len(), wall.elapsed().as_secs_f64());
}

#[test]
#[ignore = "the benchmark's full day (every scan); run with --ignored --nocapture"]
fn a_full_broken_cloud_day_is_detected_against_the_truth() {
    let wall = Instant::now();
    let (series, score, lines) = broken_cloud_day(1);
    print(&score, 1);
    check(&series, &score, &lines, Path::new("every scan"));
    println!("{} hook runs; wall {:.1} s", lines.len(), wall.elapsed().as_secs_f64());
}

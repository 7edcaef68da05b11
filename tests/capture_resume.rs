//! Crash and resume: a session killed at 20 seeded points (the store's
//! storage "dies" at its n-th write, leaving torn files exactly as a killed
//! process would) and resumed each time ends frame for frame equal to an
//! uninterrupted run: the same keys, checksums and frame numbers, and no
//! key twice.
//!
//! A one-session plan (a fixed bracket, an auto-bracket and a sky scan
//! above 30°, 41 frames promised) keeps 22 runs quick, and a static radiance field
//! stands in for the world: the simulated sky moves with the clock, and a
//! resumed run reaches a shot at another simulated moment than an
//! uninterrupted one (the shots before it are skipped), so only a scene
//! that does not change with time can give bit-identical frames. The
//! frames are otherwise made exactly as in a full run (head, filter,
//! sensor noise seeded per shot).

use std::collections::HashSet;
use std::path::Path;
use std::sync::Arc;

use campanile_capture::controller::{self, NoProgress, RunOptions};
use campanile_capture::schedule::{Timeline, TimelineOptions, timeline};
use campanile_capture::store::fault::CrashingStorage;
use campanile_capture::store::{FsStorage, JournalEntry, Provenance, SessionStore, Snapshot};
use campanile_config::camera::Resolution;
use campanile_config::plan::Plan;
use campanile_config::{Station, load_station};
use campanile_process::camera::image::RadianceImage;
use campanile_sim::camera::{FrameSource, View};
use campanile_sim::station::{SimOptions, SimStation};
use campanile_sim::world::rig::{mount, pinhole_at};

const PLAN: &str = r#"Plan(
    name: "resume test",
    start_date: "2026-08-28",
    sessions: [(
        name: "one",
        trigger: Clock(time: "20:00:00"),
        steps: [
            Bracket(aim: PanTilt(pan_deg: 30.0, tilt_deg: 10.0), exposures_s: [0.001, 0.004, 0.016]),
            AutoBracket(aim: PanTilt(pan_deg: -60.0, tilt_deg: 20.0), max_frames: 7),
            SkyScan(min_elevation_deg: 30.0, overlap: 0.2),
        ],
    )],
)"#;

/// A sky that does not change with time: a gradient with elevation and
/// azimuth, and a bright patch, spanning about 12 stops.
struct StaticSky {
    station: Station,
}

impl FrameSource for StaticSky {
    fn radiance(&self, view: &View) -> RadianceImage {
        let pin = pinhole_at(&self.station.camera, view.width, view.height);
        let m = mount(&self.station.head.mount);
        let mut data = Vec::with_capacity(view.width * view.height * 3);
        for y in 0..view.height {
            for x in 0..view.width {
                let d = pin.unproject(x as f64 + 0.5, y as f64 + 0.5).unwrap_or([0.0, 0.0, 1.0]);
                let w = m.to_world(view.head, d);
                let el = w[2].clamp(-1.0, 1.0).asin();
                let base = 2.0 + 6.0 * el.max(0.0) + 0.5 * w[0];
                let patch = if w[1] > 0.9 && w[2] > 0.2 { 2000.0 } else { 0.0 };
                let shade = if w[2] < 0.0 { 0.01 } else { 1.0 };
                let l = (base.max(0.05) * shade + patch) as f32;
                data.extend([l * 0.9, l, l * 1.2]);
            }
        }
        RadianceImage {
            width: view.width,
            height: view.height,
            data,
        }
    }
}

/// A seeded xorshift64 draw in `lo..hi`.
fn draw(state: &mut u64, lo: u64, hi: u64) -> u64 {
    *state ^= *state << 13;
    *state ^= *state >> 7;
    *state ^= *state << 17;
    lo + *state % (hi - lo)
}

fn station() -> Station {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/sim-station.ron");
    let mut s = load_station(&path).expect("the example station loads").value;
    s.camera.resolution = Resolution { width: 48, height: 36 };
    s
}

fn plan() -> Plan {
    ron::from_str(PLAN).expect("the test plan parses")
}

fn snapshot() -> Snapshot {
    Snapshot {
        plan_ron: PLAN.into(),
        station_ron: "(test)".into(),
        scene_ron: None,
        provenance: Provenance {
            campanile_version: "test".into(),
            created_utc: chrono::DateTime::default(),
            calibration: Vec::new(),
            sources: None,
        },
    }
}

/// One run against a fresh simulated station (a new process), starting a
/// minute before the session. The error, if the store crashed.
fn run_once<S: campanile_capture::store::Storage>(
    t: &Timeline,
    store: &mut SessionStore<S>,
) -> Result<controller::RunReport, controller::RunError> {
    let st = station();
    let plan = plan();
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_time()
        .start_paused(true)
        .build()
        .unwrap();
    runtime.block_on(async {
        let options = SimOptions {
            origin: t.occurrences[0].start - chrono::TimeDelta::seconds(60),
            ..SimOptions::default()
        };
        let source = Arc::new(StaticSky { station: st.clone() });
        let mut sim = SimStation::start(&st, source, options).await.unwrap();
        let clock = sim.clock();
        controller::run(
            t,
            &plan,
            &st,
            store,
            &mut sim,
            &clock,
            &RunOptions::default(),
            &mut NoProgress,
        )
        .await
    })
}

/// (key, crc32c, sequence) of every journaled frame, and the missed keys.
fn journal(dir: &Path) -> (Vec<(String, u32, u64)>, Vec<String>) {
    let (store, _) = SessionStore::resume(dir).unwrap();
    let mut frames = Vec::new();
    let mut missed = Vec::new();
    for e in store.entries() {
        match e {
            JournalEntry::Done(f) | JournalEntry::Late(f) => frames.push((f.key.clone(), f.crc32c, f.sequence)),
            JournalEntry::Missed(m) => missed.push(m.key.clone()),
            JournalEntry::Pruned(_) | JournalEntry::Outage(_) => {
                panic!("a capture journals no pruning or outage: {e:?}")
            }
        }
    }
    assert!(store.verify().unwrap().is_ok(), "{}", dir.display());
    (frames, missed)
}

#[test]
fn twenty_crashes_and_resumes_equal_an_uninterrupted_run() {
    let st = station();
    let t = timeline(&plan(), &st, None, &TimelineOptions::default()).unwrap();
    let promised = t.frames_promised();
    let tmp = tempfile::tempdir().unwrap();

    let whole = tmp.path().join("whole");
    let mut store = SessionStore::create(&whole, snapshot()).unwrap();
    let report = run_once(&t, &mut store).unwrap();
    let (expected, missed) = journal(&whole);
    assert!(missed.is_empty(), "{missed:?}");
    println!(
        "uninterrupted: {} frames ({promised} promised), {} metering captures, auto-brackets {:?}",
        report.frames, report.metering_captures, report.auto_brackets
    );

    let crashed = tmp.path().join("crashed");
    let mut rng = 2026u64;
    let mut crashes = 0;
    let mut points = Vec::new();
    // The first run crashes after the session is created (about 12 writes); each later one within about two frames (six writes a frame).
    let n = draw(&mut rng, 30, 40);
    let mut store = SessionStore::create_with(CrashingStorage::new(FsStorage, n), &crashed, snapshot()).unwrap();
    let mut result = run_once(&t, &mut store);
    loop {
        match result {
            Ok(_) => break,
            Err(e) => {
                crashes += 1;
                points.push(store.storage().crash_point().map(|p| p.operation.to_string()));
                drop(store);
                assert!(crashes <= 20, "crashed more than planned: {e}");
                // Resuming writes too (it cuts torn lines, removes orphans),
                // so a crash may strike there as well; resume again.
                store = loop {
                    let n = if crashes < 20 { draw(&mut rng, 2, 12) } else { u64::MAX };
                    match SessionStore::resume_with(CrashingStorage::new(FsStorage, n), &crashed) {
                        Ok((s, _)) => break s,
                        Err(e) => {
                            crashes += 1;
                            points.push(Some(format!("during resume: {e}")));
                        }
                    }
                };
                result = run_once(&t, &mut store);
            }
        }
    }
    assert_eq!(crashes, 20, "every crash point is reached before the session ends");
    println!("crash points: {points:?}");
    let (got, missed) = journal(&crashed);
    assert!(missed.is_empty(), "{missed:?}");
    let keys: HashSet<&str> = got.iter().map(|(k, _, _)| k.as_str()).collect();
    assert_eq!(keys.len(), got.len(), "no key is journaled twice");
    let mut got_sorted = got.clone();
    got_sorted.sort();
    let mut expected_sorted = expected.clone();
    expected_sorted.sort();
    assert_eq!(got_sorted, expected_sorted, "same frames, checksums and frame numbers");
    println!("resumed 20 times: {} frames, equal to the uninterrupted run", got.len());
}

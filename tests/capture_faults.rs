//! Faults: 2% dropped and 2% corrupted bytes on every serial link, the
//! head disconnected for 20 s mid-session, and two camera timeouts; the
//! session starts 90 s late. The session completes: the retries and the
//! reconnect are counted (and logged), the frames are journaled `late`,
//! and the one shot whose step allows no retry is journaled `missed` with
//! the camera's reason.

use std::path::Path;
use std::sync::Arc;
use std::time::Duration;

use campanile_capture::controller::{self, NoProgress, RunOptions};
use campanile_capture::schedule::{TimelineOptions, timeline};
use campanile_capture::store::{JournalEntry, Provenance, SessionStore, Snapshot};
use campanile_config::camera::Resolution;
use campanile_config::plan::Plan;
use campanile_config::{Station, load_station};
use campanile_process::camera::image::RadianceImage;
use campanile_sim::camera::{CameraOptions, FrameSource, View};
use campanile_sim::faults::{CameraFaultPlan, Device, FaultPlan, LinkFaults, Outage};
use campanile_sim::station::{SimOptions, SimStation};
use campanile_sim::world::rig::{mount, pinhole_at};

const PLAN: &str = r#"Plan(
    name: "fault test",
    start_date: "2026-08-28",
    sessions: [(
        name: "one",
        trigger: Clock(time: "20:00:00"),
        steps: [
            Bracket(aim: PanTilt(pan_deg: 30.0, tilt_deg: 10.0), exposures_s: [0.001, 0.004, 0.016],
                    on_error: (retries: 0, then: Continue)),
            SkyScan(min_elevation_deg: 30.0, overlap: 0.2, on_error: (retries: 3, then: Skip)),
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

fn station() -> Station {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/sim-station.ron");
    let mut s = load_station(&path).expect("the example station loads").value;
    s.camera.resolution = Resolution { width: 48, height: 36 };
    s
}

#[test]
fn a_session_completes_through_link_faults_a_disconnect_and_camera_timeouts_and_journals_the_outages() {
    let st = station();
    let plan: Plan = ron::from_str(PLAN).unwrap();
    let t = timeline(&plan, &st, None, &TimelineOptions::default()).unwrap();
    let start = t.occurrences[0].start;
    let keys: Vec<&str> = t.occurrences[0].shots.iter().map(|s| s.key.as_str()).collect();
    let tmp = tempfile::tempdir().unwrap();
    let snapshot = Snapshot {
        plan_ron: PLAN.into(),
        station_ron: "(test)".into(),
        scene_ron: None,
        provenance: Provenance {
            campanile_version: "test".into(),
            created_utc: chrono::DateTime::default(),
            calibration: Vec::new(),
            sources: None,
        },
    };
    let mut store = SessionStore::create(tmp.path(), snapshot).unwrap();
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_time()
        .start_paused(true)
        .build()
        .unwrap();
    let (report, link_retries) = runtime.block_on(async {
        let mut options = SimOptions {
            // The station comes up 90 s after the session's trigger.
            origin: start + chrono::TimeDelta::seconds(90),
            camera: CameraOptions {
                // Frames are numbered 64 per shot: shot 1's first attempt
                // (no retries allowed) and shot 10's first attempt time out.
                faults: CameraFaultPlan {
                    timeout_on: vec![64, 640],
                    ..CameraFaultPlan::none()
                },
                ..CameraOptions::default()
            },
            faults: FaultPlan {
                link: Some(LinkFaults {
                    drop_chance: 0.02,
                    corrupt_chance: 0.02,
                }),
                outages: vec![Outage {
                    device: Device::Head,
                    after: Duration::from_secs(20),
                    duration: Duration::from_secs(20),
                }],
                ..FaultPlan::default()
            },
            ..SimOptions::default()
        };
        // The link soak test's driver policy: 30 ms per attempt, up to 500.
        options.retry.timeout = Duration::from_millis(30);
        options.retry.max_attempts = 500;
        let source = Arc::new(StaticSky { station: st.clone() });
        let mut sim = SimStation::start(&st, source, options).await.unwrap();
        let clock = sim.clock();
        let report = controller::run(
            &t,
            &plan,
            &st,
            &mut store,
            &mut sim,
            &clock,
            &RunOptions::default(),
            &mut NoProgress,
        )
        .await
        .unwrap();
        (report, sim.head.link_stats().map(|s| s.retries))
    });
    println!("report: {report:?}");
    println!("head link retries since the reconnect: {link_retries:?}");
    let (mut late, mut missed, mut outages) = (0, Vec::new(), Vec::new());
    for e in store.entries() {
        match e {
            JournalEntry::Late(f) => {
                late += 1;
                assert!(f.meta.late_by_s.unwrap() >= 90.0);
            }
            JournalEntry::Done(f) => panic!("{} is not journaled late", f.key),
            JournalEntry::Missed(m) => missed.push((m.key.clone(), m.reason.clone())),
            JournalEntry::Outage(o) => outages.push(o.clone()),
            JournalEntry::Pruned(_) => panic!("nothing is pruned: {e:?}"),
        }
    }
    println!("late frames {late}, missed {missed:?}");
    for o in &outages {
        println!("outage: {} {} s", o.device, (o.end - o.start).as_seconds_f64());
    }
    // The journal's outages: the camera's two timeouts, each until its next
    // frame (under 2 s), and the head's 20 s disconnect, from its first
    // failed call to its first answer after the reconnect, which backs off
    // 1, 2, 4, 8, 16 s (so 20 s plus at most one 16 s wait and a shot).
    let length = |o: &campanile_capture::store::OutageEntry| (o.end - o.start).as_seconds_f64();
    let camera: Vec<f64> = outages.iter().filter(|o| o.device == "camera").map(length).collect();
    let head: Vec<f64> = outages.iter().filter(|o| o.device == "head").map(length).collect();
    assert_eq!(camera.len(), 2, "{outages:?}");
    assert!(camera.iter().all(|&s| s > 0.0 && s < 2.0), "{camera:?}");
    assert_eq!(head.len(), 1, "{outages:?}");
    assert!((20.0..=38.0).contains(&head[0]), "head outage {} s", head[0]);
    assert!(outages.iter().all(|o| !o.open), "{outages:?}");
    assert_eq!(outages.len(), 3, "{outages:?}");
    assert_eq!(missed.len(), 1, "{missed:?}");
    assert_eq!(missed[0].0, keys[1]);
    assert!(missed[0].1.contains("camera"), "{}", missed[0].1);
    assert_eq!(late, t.frames_promised() - 1);
    assert!(
        report.retries >= 2,
        "the timeout and the disconnect are retried: {report:?}"
    );
    assert!(report.reconnects >= 1, "the head is reconnected: {report:?}");
    assert!(store.verify().unwrap().is_ok());
}

/// A plan of about 2 minutes: four brackets of 4, 8 and 16 s.
const LONG_PLAN: &str = r#"Plan(
    name: "late test",
    start_date: "2026-08-28",
    sessions: [(
        name: "one",
        trigger: Clock(time: "20:00:00"),
        steps: [
            Bracket(aim: PanTilt(pan_deg: 30.0, tilt_deg: 10.0), exposures_s: [4.0, 8.0, 16.0]),
            Bracket(aim: PanTilt(pan_deg: 60.0, tilt_deg: 10.0), exposures_s: [4.0, 8.0, 16.0]),
            Bracket(aim: PanTilt(pan_deg: 90.0, tilt_deg: 10.0), exposures_s: [4.0, 8.0, 16.0]),
            Bracket(aim: PanTilt(pan_deg: 120.0, tilt_deg: 10.0), exposures_s: [4.0, 8.0, 16.0]),
        ],
    )],
)"#;

/// Run the first `shots` shots of LONG_PLAN (all if `None`) into the
/// session in `dir` (created if absent, else resumed), on a fault-free
/// station that comes up `delay_s` after the session's trigger.
fn run_started_at(dir: &Path, shots: Option<usize>, delay_s: i64) {
    let st = station();
    let plan: Plan = ron::from_str(LONG_PLAN).unwrap();
    let mut t = timeline(&plan, &st, None, &TimelineOptions::default()).unwrap();
    if let Some(n) = shots {
        t.occurrences[0].shots.truncate(n);
    }
    let snapshot = Snapshot {
        plan_ron: LONG_PLAN.into(),
        station_ron: "(test)".into(),
        scene_ron: None,
        provenance: Provenance {
            campanile_version: "test".into(),
            created_utc: chrono::DateTime::default(),
            calibration: Vec::new(),
            sources: None,
        },
    };
    let mut store = if dir.join("journal.jsonl").exists() {
        SessionStore::resume(dir).unwrap().0
    } else {
        SessionStore::create(dir, snapshot).unwrap()
    };
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_time()
        .start_paused(true)
        .build()
        .unwrap();
    runtime.block_on(async {
        let options = SimOptions {
            origin: t.occurrences[0].start + chrono::TimeDelta::seconds(delay_s),
            ..SimOptions::default()
        };
        let source = Arc::new(StaticSky { station: st.clone() });
        let mut sim = SimStation::start(&st, source, options).await.unwrap();
        let clock = sim.clock();
        controller::run(
            &t,
            &plan,
            &st,
            &mut store,
            &mut sim,
            &clock,
            &RunOptions::default(),
            &mut NoProgress,
        )
        .await
        .unwrap();
    });
}

/// Each frame of the session in `dir`: (key, seconds behind its planned
/// time, `late_by_s` if journaled late).
fn behind_plan(dir: &Path) -> Vec<(String, f64, Option<f64>)> {
    let st = station();
    let plan: Plan = ron::from_str(LONG_PLAN).unwrap();
    let t = timeline(&plan, &st, None, &TimelineOptions::default()).unwrap();
    let occ = &t.occurrences[0];
    let offsets = campanile_capture::schedule::duration::start_offsets(&occ.shots, &st, occ.sun);
    let (store, _) = SessionStore::resume(dir).unwrap();
    store
        .entries()
        .iter()
        .map(|e| {
            let f = e.frame().expect("every shot is taken");
            let i = occ.shots.iter().position(|s| s.key == f.key).unwrap();
            let planned = occ.start + chrono::TimeDelta::from_std(offsets[i]).unwrap();
            let late_by = matches!(e, JournalEntry::Late(_)).then(|| f.meta.late_by_s.unwrap());
            (f.key.clone(), (f.meta.time - planned).as_seconds_f64(), late_by)
        })
        .collect()
}

/// Issue 21: `late` means late against the plan. A resume 75 s after the
/// trigger, with the first half of the occurrence done, takes the rest
/// less than the 60 s tolerance behind their planned times (the trigger
/// plus each shot's estimated start): they are not late (they used to be
/// journaled late by the occurrence's 75 s). A whole run that starts 75 s
/// late is late by about that, frame by frame, against the plan.
#[test]
fn frames_are_late_only_against_their_planned_time() {
    let tmp = tempfile::tempdir().unwrap();
    let resumed = tmp.path().join("resumed");
    run_started_at(&resumed, Some(6), -10);
    run_started_at(&resumed, None, 75);
    let frames = behind_plan(&resumed);
    assert_eq!(frames.len(), 12);
    for (key, by, late_by) in &frames[6..] {
        assert!((0.0..60.0).contains(by), "{key} is {by} s behind its plan");
        assert_eq!(*late_by, None, "{key} is {by} s behind its plan");
    }
    let delayed = tmp.path().join("delayed");
    run_started_at(&delayed, None, 75);
    for (key, by, late_by) in behind_plan(&delayed) {
        assert!((75.0..85.0).contains(&by), "{key} is {by} s behind its plan");
        let late_by = late_by.unwrap_or_else(|| panic!("{key} is {by} s behind but not late"));
        assert!((late_by - by).abs() < 1e-6, "{key}: late_by_s {late_by}, {by} s behind");
    }
}

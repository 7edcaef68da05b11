//! What the tests of real-station cameras share: a plan run through the
//! session controller on the wall clock, on a station whose camera is real
//! software (an INDI server, Aravis's fake camera) and whose serial head is
//! a Pelco-D emulator behind an in-memory link.

use std::path::{Path, PathBuf};
use std::time::Duration;

use campanile_capture::clock::SystemClock;
use campanile_capture::controller::{self, NoProgress, RunOptions, RunReport};
use campanile_capture::schedule::{TimelineOptions, timeline};
use campanile_capture::station::{PortOpener, StationOptions, StationRig, open_station_camera};
use campanile_capture::store::{FrameEntry, JournalEntry, Provenance, SessionStore, Snapshot};
use campanile_firmware_link::emulator::Emulator;
use campanile_firmware_link::pelco_d::device::{PelcoConfig, PelcoDevice};
use chrono::{DateTime, Utc};

/// The example stations' serial head (/dev/ttyUSB0), a Pelco-D emulator
/// that turns all the way round.
struct PelcoBench(std::sync::Mutex<Vec<Emulator<PelcoDevice>>>);

impl PortOpener for PelcoBench {
    type Port = tokio::io::DuplexStream;

    async fn open(&self, link: &campanile_config::link::SerialLink) -> std::io::Result<Self::Port> {
        assert_eq!(link.port, "/dev/ttyUSB0", "only the head is serial");
        let (host, dev) = campanile_firmware_link::transport::memory::duplex(4096);
        let cfg = PelcoConfig {
            speed: 90_000,
            pan_range: (-18_000, 17_999),
            ..PelcoConfig::default()
        };
        let emu = Emulator::spawn(PelcoDevice::new(cfg), dev, Duration::from_millis(2));
        self.0.lock().unwrap().push(emu);
        Ok(host)
    }
}

/// What a plan run left: the controller's report, the journal's frames and
/// lines, and the session directory.
pub struct PlanRun {
    pub report: RunReport,
    pub entries: Vec<JournalEntry>,
    pub frames: Vec<FrameEntry>,
    pub dir: PathBuf,
    /// When the plan's session was triggered.
    pub start: DateTime<Utc>,
    _tmp: tempfile::TempDir,
}

/// The text of `examples/NAME`.
pub fn example(name: &str) -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples").join(name)).unwrap()
}

/// Runs a one-session plan of `steps` (RON), triggered 3 s from now, on
/// the station `station_text` (RON) through the session controller into a
/// new session store. `during` runs on a thread of its own beside the
/// run, given the session directory.
pub async fn run_plan(station_text: &str, steps: &str, during: impl FnOnce(PathBuf) + Send + 'static) -> PlanRun {
    let tmp = tempfile::tempdir().unwrap();
    let station_file = tmp.path().join("station.ron");
    std::fs::write(&station_file, station_text).unwrap();
    let station = campanile_config::load_station(&station_file).unwrap().value;
    let start = Utc::now() + chrono::TimeDelta::seconds(3);
    let plan_text = format!(
        r#"Plan(
    name: "camera test",
    start_date: "{}",
    sessions: [(
        name: "one",
        trigger: Clock(time: "{}"),
        steps: [{steps}],
    )],
)"#,
        start.format("%Y-%m-%d"),
        start.format("%H:%M:%S")
    );
    let plan: campanile_config::Plan = ron::from_str(&plan_text).unwrap();
    let t = timeline(&plan, &station, None, &TimelineOptions { days: Some(1) }).unwrap();
    assert!(t.uncovered.is_empty(), "{:?}", t.uncovered);
    let camera = open_station_camera(&station.camera).await.unwrap();
    let bench = PelcoBench(std::sync::Mutex::new(Vec::new()));
    let mut rig = StationRig::connect(&station, bench, camera, StationOptions::default())
        .await
        .unwrap();
    let snapshot = Snapshot {
        plan_ron: plan_text,
        station_ron: station_text.to_owned(),
        scene_ron: None,
        provenance: Provenance {
            campanile_version: "test".into(),
            created_utc: DateTime::default(),
            calibration: Vec::new(),
            sources: None,
        },
    };
    let dir = tmp.path().join("session");
    let mut store = SessionStore::create(&dir, snapshot).unwrap();
    let beside = {
        let dir = dir.clone();
        std::thread::spawn(move || during(dir))
    };
    let report = controller::run(
        &t,
        &plan,
        &station,
        &mut store,
        &mut rig,
        &SystemClock,
        &RunOptions::default(),
        &mut NoProgress,
    )
    .await
    .unwrap();
    beside.join().unwrap();
    let entries = store.entries().to_vec();
    let frames = entries.iter().filter_map(JournalEntry::frame).cloned().collect();
    PlanRun {
        report,
        entries,
        frames,
        dir,
        start,
        _tmp: tmp,
    }
}

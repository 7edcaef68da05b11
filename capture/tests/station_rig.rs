//! A real station's devices (examples/real-station.ron: Pelco-D head,
//! FW102C wheel, Enttec DMX lights) built from its config over ports that
//! lead to the firmware emulators through firmware-link's fault injector:
//! links that disconnect after N bytes and ports that stay absent for a
//! while are reopened with capped exponential backoff, under paused time;
//! and the session controller completes a session through such drops.

use std::collections::HashMap;
use std::path::Path;
use std::sync::Mutex;
use std::time::Duration;

use campanile_capture::clock::Clock;
use campanile_capture::controller::{self, DeviceKind, NoProgress, Rig, RunOptions};
use campanile_capture::device::{
    Camera, CameraInfo, CaptureSettings, DeviceError, ExposureRange, ExposureTime, FilterWheel, Frame, Gain, GainRange,
    Level, Lights, PanTilt, Pose,
};
use campanile_capture::driver::backoff::Backoff;
use campanile_capture::schedule::{TimelineOptions, timeline};
use campanile_capture::station::{PortOpener, StationError, StationOptions, StationRig};
use campanile_capture::store::{JournalEntry, Provenance, SessionStore, Snapshot};
use campanile_config::head::HeadProtocol;
use campanile_config::link::SerialLink;
use campanile_config::plan::Plan;
use campanile_config::{Station, load_station};
use campanile_firmware_link::emulator::Emulator;
use campanile_firmware_link::enttec::device::DmxDevice;
use campanile_firmware_link::flir_ptu::device::{PtuConfig, PtuDevice};
use campanile_firmware_link::fw102c::device::WheelDevice;
use campanile_firmware_link::link::device::{DeviceConfig, LinkDevice};
use campanile_firmware_link::pelco_d::device::{PelcoConfig, PelcoDevice};
use campanile_firmware_link::transport::fault::{FaultConfig, FaultyStream};
use campanile_firmware_link::transport::memory::duplex;
use chrono::{DateTime, Utc};
use tokio::io::DuplexStream;
use tokio::time::Instant;

fn real_station() -> Station {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/real-station.ron");
    load_station(&path).expect("the example station loads").value
}

/// What one port does: the emulator behind it, after how many bytes its
/// first connection drops, and how many opens after that fail (the device
/// is away).
#[derive(Debug, Clone, Copy)]
struct PortPlan {
    drop_after: Option<u64>,
    absent_opens: u32,
}

/// The emulators behind the real station's three ports, one per
/// connection (a fresh emulator per open, like a power-cycled device).
#[derive(Default)]
struct Bench {
    /// The head's protocol (Pelco-D unless set).
    head_protocol: Option<HeadProtocol>,
    plans: HashMap<String, PortPlan>,
    opens: Mutex<HashMap<String, u32>>,
    heads: Mutex<Vec<Emulator<PelcoDevice>>>,
    wheels: Mutex<Vec<Emulator<WheelDevice>>>,
    lights: Mutex<Vec<Emulator<DmxDevice>>>,
    /// FLIR and campanile-link heads, kept running.
    other_heads: Mutex<Vec<Box<dyn std::any::Any + Send>>>,
}

impl Bench {
    fn new(plans: &[(&str, PortPlan)]) -> Self {
        Self {
            plans: plans.iter().map(|(p, plan)| ((*p).to_owned(), *plan)).collect(),
            ..Self::default()
        }
    }

    fn opens(&self, port: &str) -> u32 {
        self.opens.lock().unwrap().get(port).copied().unwrap_or(0)
    }
}

const TICK: Duration = Duration::from_millis(2);

impl PortOpener for Bench {
    type Port = FaultyStream<DuplexStream>;

    async fn open(&self, link: &SerialLink) -> std::io::Result<Self::Port> {
        let n = {
            let mut opens = self.opens.lock().unwrap();
            let n = opens.entry(link.port.clone()).or_insert(0);
            *n += 1;
            *n
        };
        let plan = self.plans.get(&link.port).copied().unwrap_or(PortPlan {
            drop_after: None,
            absent_opens: 0,
        });
        if n > 1 && n <= 1 + plan.absent_opens {
            return Err(std::io::Error::new(
                std::io::ErrorKind::NotFound,
                format!("{}: no such device (unplugged)", link.port),
            ));
        }
        let (host, dev) = duplex(4096);
        match link.port.as_str() {
            "/dev/ttyUSB0" if self.head_protocol == Some(HeadProtocol::FlirPtu) => {
                let cfg = PtuConfig {
                    speed: 16_000,
                    ..PtuConfig::default()
                };
                let emu = Emulator::spawn(PtuDevice::new(cfg), dev, TICK);
                self.other_heads.lock().unwrap().push(Box::new(emu));
            }
            "/dev/ttyUSB0" if self.head_protocol == Some(HeadProtocol::CampanileLink) => {
                let emu = Emulator::spawn(LinkDevice::new(DeviceConfig::default()), dev, TICK);
                self.other_heads.lock().unwrap().push(Box::new(emu));
            }
            "/dev/ttyUSB0" => {
                let cfg = PelcoConfig {
                    speed: 9_000,
                    ..PelcoConfig::default()
                };
                self.heads
                    .lock()
                    .unwrap()
                    .push(Emulator::spawn(PelcoDevice::new(cfg), dev, TICK));
            }
            "/dev/ttyUSB1" => self
                .wheels
                .lock()
                .unwrap()
                .push(Emulator::spawn(WheelDevice::new(6), dev, TICK)),
            "/dev/ttyUSB2" => self
                .lights
                .lock()
                .unwrap()
                .push(Emulator::spawn(DmxDevice::new(1234), dev, TICK)),
            other => {
                return Err(std::io::Error::new(
                    std::io::ErrorKind::NotFound,
                    format!("{other}: no such device"),
                ));
            }
        }
        let faults = FaultConfig {
            disconnect_after: if n == 1 { plan.drop_after } else { None },
            ..FaultConfig::none(u64::from(n))
        };
        Ok(FaultyStream::new(host, faults))
    }
}

/// The controller's calendar on tokio's (paused) clock.
#[derive(Clone, Copy)]
struct TestClock {
    utc: DateTime<Utc>,
    at: Instant,
}

impl Clock for TestClock {
    fn now(&self) -> DateTime<Utc> {
        self.utc + chrono::TimeDelta::from_std(self.at.elapsed()).unwrap_or_default()
    }

    async fn sleep_until(&self, t: DateTime<Utc>) {
        if let Ok(d) = (t - self.utc).to_std() {
            tokio::time::sleep_until(self.at + d).await;
        }
    }
}

/// A camera whose codes are proportional to the exposure (1000 codes at
/// 10 ms); exposures are rounded to 100 µs, as V4L2 counts them.
struct FlatCamera {
    clock: TestClock,
    sequence: u64,
}

impl Camera for FlatCamera {
    fn info(&self) -> CameraInfo {
        CameraInfo {
            model: "flat test camera".into(),
            width: 8,
            height: 6,
            bits: 12,
            exposure: ExposureRange {
                min: ExposureTime::from_micros(100).unwrap(),
                max: ExposureTime::from_seconds(2.0).unwrap(),
                step: ExposureTime::from_micros(100).unwrap(),
            },
            gain: GainRange {
                min: Gain::UNITY,
                max: Gain::from_db(18.0).unwrap(),
                step_db: 0.0,
            },
            exposure_table: None,
            linear: false,
        }
    }

    async fn capture(&mut self, settings: CaptureSettings) -> Result<Frame, DeviceError> {
        let actual = self.info().exposure_applied(settings.exposure)?;
        let timestamp = self.clock.now();
        tokio::time::sleep(actual.duration()).await;
        self.sequence += 1;
        let code = (actual.seconds() / 0.01 * 1000.0).min(4095.0) as u16;
        Ok(Frame {
            width: 8,
            height: 6,
            bits: 12,
            data: vec![code; 8 * 6 * 3],
            exposure_requested: settings.exposure,
            exposure_actual: actual,
            gain: settings.gain,
            sequence: self.sequence - 1,
            timestamp,
            temperature_c: None,
            file: None,
        })
    }
}

fn clock() -> TestClock {
    TestClock {
        utc: DateTime::parse_from_rfc3339("2026-08-28T19:59:00Z").unwrap().to_utc(),
        at: Instant::now(),
    }
}

fn options() -> StationOptions {
    StationOptions {
        backoff: Backoff {
            attempts: 5,
            first: Duration::from_millis(500),
            cap: Duration::from_secs(2),
        },
        ..StationOptions::default()
    }
}

/// Move the head back and forth until its link fails; returns the moves made.
async fn move_until_the_link_drops<R: Rig>(rig: &mut R) -> usize {
    for i in 0..100 {
        let pose = Pose::from_degrees(if i % 2 == 0 { 40.0 } else { 10.0 }, 5.0);
        let r = match rig.head().move_to(pose).await {
            Ok(()) => rig.head().wait_idle(Duration::from_secs(10)).await.map(|_| ()),
            Err(e) => Err(e),
        };
        match r {
            Ok(()) => {}
            Err(DeviceError::Link(_)) => return i,
            Err(e) => panic!("move {i}: expected a link failure, got {e}"),
        }
    }
    panic!("the head's link never dropped");
}

/// Each device's link drops after some bytes and its port is absent for
/// the next opens; `reconnect` reopens it after exactly the backoff's
/// waits (0.5, 1, 2 s), and the reopened device obeys.
#[tokio::test(start_paused = true)]
async fn every_serial_device_is_reopened_with_capped_exponential_backoff() {
    let station = real_station();
    let bench = Bench::new(&[
        (
            "/dev/ttyUSB0",
            PortPlan {
                drop_after: Some(2000),
                absent_opens: 2,
            },
        ),
        (
            "/dev/ttyUSB1",
            PortPlan {
                drop_after: Some(30),
                absent_opens: 3,
            },
        ),
        (
            "/dev/ttyUSB2",
            PortPlan {
                drop_after: Some(60),
                absent_opens: 1,
            },
        ),
    ]);
    let camera = FlatCamera {
        clock: clock(),
        sequence: 0,
    };
    let mut rig = StationRig::connect(&station, bench, camera, options()).await.unwrap();

    // The head: its link drops mid-move; two absent opens, then back.
    let moves = move_until_the_link_drops(&mut rig).await;
    assert!(moves >= 1, "the link dropped before the first move completed");
    let t0 = Instant::now();
    rig.reconnect(DeviceKind::Head).await.unwrap();
    let waited = t0.elapsed();
    // Waits 0.5 + 1 s, plus the handshake's position queries (ms).
    assert!(
        waited >= Duration::from_millis(1500) && waited < Duration::from_millis(1600),
        "{waited:?}"
    );
    // The configured pan runs 0..360°: 200° goes over the wire as −160°
    // and is reported as 200° again.
    rig.head().move_to(Pose::from_degrees(200.0, 30.0)).await.unwrap();
    let at = rig.head().wait_idle(Duration::from_secs(30)).await.unwrap();
    assert!(at.within(&Pose::from_degrees(200.0, 30.0), rig.head().limits().resolution));

    // The wheel: a few slot changes exhaust its 30 bytes; three absent opens.
    let mut dropped = false;
    for slot in [1u8, 2, 3, 4, 5, 0, 1, 2] {
        match rig.wheel().unwrap().select(slot).await {
            Ok(()) => {}
            Err(DeviceError::Link(_)) => {
                dropped = true;
                break;
            }
            Err(e) => panic!("select {slot}: {e}"),
        }
    }
    assert!(dropped, "the wheel's link never dropped");
    let t0 = Instant::now();
    rig.reconnect(DeviceKind::Wheel).await.unwrap();
    let waited = t0.elapsed();
    // 0.5 + 1 + 2 s.
    assert!(
        waited >= Duration::from_millis(3500) && waited < Duration::from_millis(3600),
        "{waited:?}"
    );
    rig.wheel().unwrap().select(4).await.unwrap();
    assert_eq!(rig.wheel().unwrap().current().await.unwrap(), 4);

    // The lights: a few levels (each sends the 3 configured channels,
    // framed) exhaust 60 bytes; one absent open.
    let lamp = rig.light_channel(1).unwrap();
    assert_eq!(lamp.0, 1, "config channel 2 is DMX channel 2, trait channel 1");
    let level = Level::new(0.5).unwrap();
    let mut dropped = false;
    for _ in 0..20 {
        match rig.lights().unwrap().set_level(lamp, level).await {
            Ok(()) => {}
            Err(DeviceError::Link(_)) => {
                dropped = true;
                break;
            }
            Err(e) => panic!("set level: {e}"),
        }
    }
    assert!(dropped, "the lights' link never dropped");
    let t0 = Instant::now();
    rig.reconnect(DeviceKind::Lights).await.unwrap();
    assert!(t0.elapsed() >= Duration::from_millis(500) && t0.elapsed() < Duration::from_millis(600));
    rig.lights().unwrap().set_level(lamp, level).await.unwrap();
    tokio::time::sleep(Duration::from_millis(20)).await;
    // Ground truth on the emulators behind the last connections, and the
    // opens: one, the absent ones, the one that worked.
    let bench = rig.opener();
    assert_eq!(
        [
            bench.opens("/dev/ttyUSB0"),
            bench.opens("/dev/ttyUSB1"),
            bench.opens("/dev/ttyUSB2")
        ],
        [4, 5, 3]
    );
    // Pelco-D's wire position of 200° is −160°, 1/100°.
    assert_eq!(
        bench.heads.lock().unwrap().last().unwrap().firmware().position(),
        (-16_000, 3_000)
    );
    assert_eq!(bench.wheels.lock().unwrap().last().unwrap().firmware().position(), 5);
    assert_eq!(
        bench.lights.lock().unwrap().last().unwrap().firmware().universe()[1],
        128
    );
    assert_eq!(rig.connections(), 3 + 3);
}

const PLAN: &str = r#"Plan(
    name: "rig test",
    start_date: "2026-08-28",
    sessions: [(
        name: "one",
        trigger: Clock(time: "20:00:00"),
        steps: [
            Bracket(aim: PanTilt(pan_deg: 200.0, tilt_deg: 10.0), exposures_s: [0.001, 0.004, 0.016],
                    filter: Some("nd1"), on_error: (retries: 3, then: Continue)),
            Bracket(aim: PanTilt(pan_deg: 30.0, tilt_deg: 40.0), exposures_s: [0.001, 0.004],
                    filter: Some("nd2"), on_error: (retries: 3, then: Continue)),
            Bracket(aim: PanTilt(pan_deg: 300.0, tilt_deg: -20.0), exposures_s: [0.002, 0.008],
                    filter: Some("clear"), on_error: (retries: 3, then: Continue)),
        ],
    )],
)"#;

/// The controller runs a session on the real station's devices while the
/// head's link drops (its port then absent for two opens) and the wheel's
/// (absent for one): every frame is stored, at the asked poses, and the
/// two reconnects are counted.
#[tokio::test(start_paused = true)]
async fn a_session_completes_on_the_real_station_through_link_drops() {
    let station = real_station();
    let plan: Plan = ron::from_str(PLAN).unwrap();
    let t = timeline(&plan, &station, None, &TimelineOptions::default()).unwrap();
    let promised = t.frames_promised();
    assert_eq!(promised, 7);
    let bench = Bench::new(&[
        (
            "/dev/ttyUSB0",
            PortPlan {
                drop_after: Some(700),
                absent_opens: 2,
            },
        ),
        (
            "/dev/ttyUSB1",
            PortPlan {
                drop_after: Some(25),
                absent_opens: 1,
            },
        ),
    ]);
    let clock = clock();
    let camera = FlatCamera { clock, sequence: 0 };
    let mut rig = StationRig::connect(&station, bench, camera, options()).await.unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let snapshot = Snapshot {
        plan_ron: PLAN.into(),
        station_ron: "(test)".into(),
        scene_ron: None,
        provenance: Provenance {
            campanile_version: "test".into(),
            created_utc: DateTime::default(),
            calibration: Vec::new(),
            sources: None,
        },
    };
    let mut store = SessionStore::create(tmp.path(), snapshot).unwrap();
    let report = controller::run(
        &t,
        &plan,
        &station,
        &mut store,
        &mut rig,
        &clock,
        &RunOptions::default(),
        &mut NoProgress,
    )
    .await
    .unwrap();
    println!("{report:?}");
    let frames: Vec<_> = store
        .entries()
        .iter()
        .filter_map(|e| match e {
            JournalEntry::Done(f) => Some(f),
            _ => None,
        })
        .collect();
    assert_eq!(frames.len(), promised, "{:?}", store.entries());
    assert_eq!(report.missed, 0);
    assert!(report.reconnects >= 2, "{report:?}");
    let bench = rig.opener();
    // Head: the first connection, two absent opens, the one that worked.
    assert_eq!(bench.opens("/dev/ttyUSB0"), 4);
    assert_eq!(bench.opens("/dev/ttyUSB1"), 3);
    // Every frame reached the pose it asked for, to the head's 0.01°.
    for f in &frames {
        let (asked, got) = (f.meta.pose_requested.unwrap(), f.meta.pose_reached.unwrap());
        assert!(
            (asked.pan_deg - got.pan_deg).abs() <= 0.0101 && (asked.tilt_deg - got.tilt_deg).abs() <= 0.0101,
            "{}: asked {asked:?}, reached {got:?}",
            f.key
        );
    }
    // Exposures are recorded as the camera rounded them (100 µs steps).
    for f in &frames {
        let r = f.meta.exposure_actual_s / 1e-4;
        assert!((r - r.round()).abs() < 1e-9, "{}", f.meta.exposure_actual_s);
    }
}

/// A station whose devices share a port, or name a simulator port, is
/// refused before anything is opened, naming the devices and the port.
#[tokio::test(start_paused = true)]
async fn shared_and_simulated_ports_are_refused_by_name() {
    let mut station = real_station();
    station.filter_wheel.as_mut().unwrap().link.as_mut().unwrap().port = "/dev/ttyUSB0".into();
    let camera = FlatCamera {
        clock: clock(),
        sequence: 0,
    };
    let Err(err) = StationRig::connect(&station, Bench::default(), camera, options()).await else {
        panic!("connected");
    };
    assert!(matches!(err, StationError::SharedPort { .. }), "{err}");
    assert_eq!(
        err.to_string(),
        "the head and the filter wheel both use port \"/dev/ttyUSB0\"; each device needs a port of its own"
    );
    let mut station = real_station();
    station.lights.as_mut().unwrap().link.port = "sim:lights".into();
    let camera = FlatCamera {
        clock: clock(),
        sequence: 0,
    };
    let Err(err) = StationRig::connect(&station, Bench::default(), camera, options()).await else {
        panic!("connected");
    };
    assert!(
        err.to_string()
            .starts_with("port \"sim:lights\" of the lights is a simulated port"),
        "{err}"
    );
}

/// The FLIR PTU and campanile-link heads too: the link drops mid-move, the
/// port is absent for two opens, and the reopened head (limits read anew
/// from the unit) reaches the next pose.
#[tokio::test(start_paused = true)]
async fn flir_and_campanile_link_heads_are_reopened_with_backoff() {
    for protocol in [HeadProtocol::FlirPtu, HeadProtocol::CampanileLink] {
        let mut station = real_station();
        station.head.protocol = protocol;
        let mut bench = Bench::new(&[(
            "/dev/ttyUSB0",
            PortPlan {
                drop_after: Some(1500),
                absent_opens: 2,
            },
        )]);
        bench.head_protocol = Some(protocol);
        let camera = FlatCamera {
            clock: clock(),
            sequence: 0,
        };
        let mut rig = StationRig::connect(&station, bench, camera, options()).await.unwrap();
        move_until_the_link_drops(&mut rig).await;
        let t0 = Instant::now();
        rig.reconnect(DeviceKind::Head).await.unwrap();
        let waited = t0.elapsed();
        assert!(
            waited >= Duration::from_millis(1500) && waited < Duration::from_millis(1700),
            "{protocol:?}: {waited:?}"
        );
        let target = Pose::from_degrees(20.0, 10.0);
        rig.head().move_to(target).await.unwrap();
        let at = rig.head().wait_idle(Duration::from_secs(30)).await.unwrap();
        let tol = rig.head().limits().resolution;
        assert!(
            at.within(
                &target,
                campanile_capture::device::Angle::from_radians(tol.radians() * 1.01)
            ),
            "{protocol:?}: {at:?}"
        );
        assert_eq!(rig.opener().opens("/dev/ttyUSB0"), 4, "{protocol:?}");
    }
}

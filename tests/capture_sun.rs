//! Sun shots and auto-brackets in the simulated world (the campanile
//! scene, its true sun and clear sky).
//!
//! - Sun shots at three solar positions (morning, noon, evening): every
//!   data frame's optical axis lies within 1° of the true sun (from the
//!   world's ephemeris at the frame's time and the head's true pose), and
//!   the disc is found and unsaturated.
//! - Auto-brackets on the sky and on the building: fewer frames than a
//!   fixed 7-frame bracket, and every pixel well exposed in at least one.

use std::path::Path;
use std::sync::Arc;

use campanile_capture::controller::auto_bracket::{self, WELL_EXPOSED};
use campanile_capture::controller::metering::Codes;
use campanile_capture::controller::{self, NoProgress, RunOptions, aim, sun_shot};
use campanile_capture::schedule::{SceneGeometry, TimelineOptions, timeline};
use campanile_capture::store::{JournalEntry, Provenance, SessionStore, ShotKind, Snapshot};
use campanile_config::camera::Resolution;
use campanile_config::{load_plan, load_station};
use campanile_process::camera::image::CodeImage;
use campanile_sim::station::{SimOptions, SimStation};
use campanile_sim::world::{World, load_scene};

#[test]
fn sun_shots_are_centred_and_unsaturated_and_auto_brackets_are_short() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let scene_path = root.join("examples/campanile-scene.ron");
    let tmp = tempfile::tempdir().unwrap();
    let plan_path = tmp.path().join("plan.ron");
    let plan_text = format!(
        r#"Plan(
    name: "sun test",
    start_date: "2026-08-28",
    scene: Some({scene:?}),
    sessions: [
        (name: "morning", trigger: SolarElevation(elevation_deg: 25.0, motion: Rising),
         steps: [SunShot(filters: ["nd3", "nd4", "nd5"], triplet: true)]),
        (name: "noon", trigger: SolarAzimuth(azimuth_deg: 180.0),
         steps: [
            SunShot(filters: ["nd3", "nd4", "nd5"], triplet: true),
            AutoBracket(aim: PanTilt(pan_deg: 90.0, tilt_deg: 40.0), max_frames: 7),
            AutoBracket(aim: Pose("view-se"), max_frames: 7),
         ]),
        (name: "evening", trigger: SolarElevation(elevation_deg: 12.0, motion: Setting),
         steps: [SunShot(filters: ["nd3", "nd4", "nd5"], triplet: true)]),
    ],
)"#,
        scene = scene_path.to_str().unwrap()
    );
    std::fs::write(&plan_path, &plan_text).unwrap();
    let plan = load_plan(&plan_path).unwrap();
    let mut station = load_station(&root.join("examples/sim-station.ron")).unwrap().value;
    station.camera.resolution = Resolution {
        width: 256,
        height: 192,
    };
    let scene = plan.scene.as_ref().unwrap();
    let geometry = SceneGeometry::load(&scene.value, &scene.source.base_dir()).unwrap();
    let t = timeline(&plan.plan.value, &station, Some(&geometry), &TimelineOptions::default()).unwrap();
    let mut world = World::new(&station, load_scene(&scene_path).unwrap());
    world.quality.samples_per_pixel = 8;
    world.quality.max_bounces = 2;
    let world = Arc::new(world);
    let snapshot = Snapshot {
        plan_ron: plan_text.clone(),
        station_ron: "(test)".into(),
        scene_ron: None,
        provenance: Provenance {
            campanile_version: "test".into(),
            created_utc: chrono::DateTime::default(),
            calibration: Vec::new(),
            sources: None,
        },
    };
    let dir = tmp.path().join("session");
    let mut store = SessionStore::create(&dir, snapshot).unwrap();
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_time()
        .start_paused(true)
        .build()
        .unwrap();
    let (report, truths) = runtime.block_on(async {
        let options = SimOptions {
            origin: t.occurrences[0].start - chrono::TimeDelta::seconds(60),
            position_m: [40.0, -40.0, 1.5],
            ..SimOptions::default()
        };
        let mut sim = SimStation::start(&station, world.clone(), options).await.unwrap();
        let clock = sim.clock();
        let report = controller::run(
            &t,
            &plan.plan.value,
            &station,
            &mut store,
            &mut sim,
            &clock,
            &RunOptions::default(),
            &mut NoProgress,
        )
        .await
        .unwrap();
        (report, sim.camera.truth_log())
    });
    println!(
        "frames {}, missed {}, saturation retakes {}",
        report.frames, report.missed, report.saturation_retakes
    );
    assert_eq!(report.missed, 0);

    let mount = aim::mount(&station);
    let mut worst: f64 = 0.0;
    let mut sun_frames = 0;
    for e in store.entries() {
        let JournalEntry::Done(f) = e else { continue };
        if !f.key.contains("/s0/") || f.meta.kind != ShotKind::Data {
            continue;
        }
        let truth = truths
            .iter()
            .find(|t| t.sequence == f.sequence)
            .expect("the frame's truth");
        let axis = mount.to_world(truth.view.head, [0.0, 0.0, 1.0]);
        let sun = world.sun(truth.view.time).unwrap().direction();
        let off = aim::angle_between_deg(axis, sun);
        let codes: CodeImage = store.read_frame(f).unwrap();
        let disc = sun_shot::find_disc(Codes::from(&codes));
        let Some(disc) = disc else {
            let max = codes.data.iter().max();
            panic!(
                "{}: no disc; {off}° off; max code {max:?}; notes {:?}",
                f.key, f.meta.notes
            );
        };
        println!(
            "{}: {:.4}° from the true sun, filter {:?}, {:.6} s, disc peak {:.2} of full scale",
            f.key, off, f.meta.filter, f.meta.exposure_actual_s, disc.peak_fraction
        );
        assert!(off < 1.0, "{}: {off}°", f.key);
        assert!(!disc.saturated(), "{}: {disc:?}", f.key);
        worst = worst.max(off);
        sun_frames += 1;
    }
    assert_eq!(sun_frames, 9, "three triplets");
    println!("sun frames {sun_frames}, worst centring error {worst:.4}°");

    assert_eq!(report.auto_brackets.len(), 2);
    for a in &report.auto_brackets {
        let mut frames = Vec::new();
        for f in 1..=a.max_frames {
            if let Some(e) = store.frame_entry(&format!("{}/f{f}", a.target)) {
                frames.push((e.meta.exposure_actual_s, store.read_frame(e).unwrap()));
            }
        }
        let codes: Vec<_> = frames.iter().map(|(t, c)| (*t, Codes::from(c))).collect();
        let coverage = auto_bracket::coverage(&codes);
        println!(
            "auto-bracket {}: {} frames (fixed bracket: 7), exposures {:?}, pixels not in {WELL_EXPOSED:?} of full scale in any frame: {}",
            a.target,
            frames.len(),
            frames.iter().map(|f| f.0).collect::<Vec<_>>(),
            coverage.uncovered()
        );
        assert_eq!(frames.len(), a.frames);
        assert!(a.frames < 7, "{a:?}");
        assert_eq!(coverage.uncovered(), 0, "{a:?}");
    }
}

//! A camera with a DSLR's stepped shutter (`exposure: (…, steps: Thirds)`
//! on the simulated station): every exposure a plan or an auto-bracket
//! asks for is snapped to the nearest ⅓-stop nominal, and the journal keeps
//! both, the plan's request and the speed the camera used.

mod common;

use campanile_capture::store::{FrameEntry, JournalEntry, SessionReader};
use campanile_config::shutter::THIRD_STOPS_S;
use common::campanile;
use std::path::Path;

#[test]
fn plans_and_auto_brackets_snap_to_the_third_stop_table() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let tmp = tempfile::tempdir().unwrap();
    let station_text = std::fs::read_to_string(root.join("examples/sim-station.ron"))
        .unwrap()
        .replace(
            "exposure: (min_s: 0.00001, max_s: 30.0),",
            "exposure: (min_s: 0.000125, max_s: 30.0, steps: Thirds),",
        );
    assert!(station_text.contains("steps: Thirds"));
    let station = tmp.path().join("dslr-station.ron");
    std::fs::write(&station, station_text).unwrap();
    let scene = root.join("examples/campanile-scene.ron");
    let requested = [0.001, 1.0 / 300.0, 0.0111, 1.0 / 30.0, 0.1, 1.0 / 3.0];
    let expected = [1.0 / 1000.0, 1.0 / 320.0, 1.0 / 100.0, 1.0 / 30.0, 1.0 / 10.0, 0.3];
    let plan = format!(
        r#"Plan(
    name: "stepped shutter",
    start_date: "2026-08-28",
    scene: Some({scene:?}),
    sessions: [(
        name: "dslr",
        trigger: Clock(time: "19:00:00"),
        steps: [
            Bracket(aim: PanTilt(pan_deg: 180.0, tilt_deg: 20.0), exposures_s: [{}]),
            AutoBracket(aim: Sun, max_frames: 5),
        ],
    )],
)"#,
        requested.map(|t| format!("{t:?}")).join(", ")
    );
    let plan_file = tmp.path().join("plan.ron");
    std::fs::write(&plan_file, plan).unwrap();
    let day = tmp.path().join("day");
    let out = campanile(&[
        "-q",
        "capture",
        "--sim-bounces",
        "1",
        plan_file.to_str().unwrap(),
        "--station",
        station.to_str().unwrap(),
        "--out",
        day.to_str().unwrap(),
    ]);
    let text = |b: &[u8]| String::from_utf8_lossy(b).into_owned();
    assert_eq!(out.status.code(), Some(0), "{}{}", text(&out.stdout), text(&out.stderr));
    let reader = SessionReader::open(&day).unwrap();
    let frames: Vec<&FrameEntry> = reader.entries().iter().filter_map(JournalEntry::frame).collect();

    // The fixed bracket: the plan's request journaled as asked, the nominal
    // the camera used beside it.
    let bracket: Vec<&&FrameEntry> = frames.iter().filter(|f| f.key.contains("/s0/")).collect();
    assert_eq!(bracket.len(), requested.len());
    for (f, (asked, used)) in bracket.iter().zip(requested.iter().zip(expected)) {
        assert!(
            (f.meta.exposure_requested_s - asked).abs() < 1e-12,
            "{}: {:?}",
            f.key,
            f.meta
        );
        assert!(
            (f.meta.exposure_actual_s - used).abs() < 1e-12,
            "{}: {:?}",
            f.key,
            f.meta
        );
    }

    // Every frame, the auto-bracket's and its metering's included, was
    // taken at a table speed within ⅙ stop (plus the nominals' rounding)
    // of what was asked.
    let auto: Vec<&&FrameEntry> = frames.iter().filter(|f| f.key.contains("/s1/")).collect();
    assert!(auto.len() >= 2, "{} auto-bracket frames", auto.len());
    for f in &frames {
        let used = f.meta.exposure_actual_s;
        assert!(
            THIRD_STOPS_S.iter().any(|t| (t - used).abs() < 1e-12),
            "{}: {used} s is not a ⅓-stop speed",
            f.key
        );
        let off = (used / f.meta.exposure_requested_s).log2().abs();
        assert!(off < 1.0 / 6.0 + 0.1, "{}: {off} stop from the request", f.key);
    }
    // The auto-bracket's data frames (after its metering frame f0) stay
    // about its 4 stops apart on the table.
    let mut times: Vec<f64> = auto
        .iter()
        .filter(|f| !f.key.ends_with("/f0"))
        .map(|f| f.meta.exposure_actual_s)
        .collect();
    println!("auto-bracket data frames at {times:?} s");
    times.sort_by(f64::total_cmp);
    for w in times.windows(2) {
        let stops = (w[1] / w[0]).log2();
        assert!((stops - 4.0).abs() < 0.35, "{} → {} s is {stops} stops", w[0], w[1]);
    }
}

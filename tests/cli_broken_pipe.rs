//! Every subcommand with its standard output a closed pipe (`campanile … |
//! head -0`): no panic (exit 101, "panicked"), no "Broken pipe" error; a
//! closed pipe ends the output and the command exits 0, as `ripgrep` does.

use std::path::Path;
use std::process::{Command, Stdio};

/// Runs `campanile ARGS…` with its standard output a pipe whose read end is
/// closed before the child starts; (exit code, stderr).
fn with_closed_stdout(args: &[&str]) -> (Option<i32>, String) {
    let (reader, writer) = std::io::pipe().expect("a pipe");
    drop(reader);
    let out = Command::new(env!("CARGO_BIN_EXE_campanile"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .stdin(Stdio::null())
        .stdout(writer)
        .stderr(Stdio::piped())
        .output()
        .expect("the binary runs");
    (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned())
}

/// Runs `campanile ARGS…` normally; its standard output.
fn stdout_of(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_campanile"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("the binary runs");
    assert_eq!(
        out.status.code(),
        Some(0),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("utf-8")
}

/// A uniform sky's samples (zenith, azimuth, r, g, b).
fn sky_samples(dir: &Path) -> String {
    let mut csv = String::from("zenith_deg,azimuth_deg,r,g,b\n");
    for z in (0..86).step_by(5) {
        for a in (0..360).step_by(15) {
            csv += &format!("{z},{a},0.05,0.08,0.13\n");
        }
    }
    let path = dir.join("scan.csv");
    std::fs::write(&path, csv).expect("write");
    path.display().to_string()
}

/// A tiny simulated station (48×36 frames) and a one-frame plan.
fn tiny_capture(dir: &Path) -> (String, String) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let station = std::fs::read_to_string(root.join("examples/sim-station.ron"))
        .expect("example")
        .replace(
            "resolution: (width: 256, height: 192)",
            "resolution: (width: 48, height: 36)",
        );
    assert!(
        station.contains("width: 48"),
        "the example station's resolution line moved"
    );
    let scene = root.join("examples/campanile-scene.ron");
    let plan = format!(
        r#"Plan(
    name: "pipe test",
    start_date: "2026-08-28",
    scene: Some({scene:?}),
    sessions: [(
        name: "one",
        trigger: Clock(time: "20:00:00"),
        steps: [Bracket(aim: PanTilt(pan_deg: 10.0, tilt_deg: 15.0), exposures_s: [0.002])],
    )],
)"#
    );
    let (p, s) = (dir.join("plan.ron"), dir.join("station.ron"));
    std::fs::write(&p, plan).expect("write");
    std::fs::write(&s, station).expect("write");
    (p.display().to_string(), s.display().to_string())
}

/// A heartbeat as `station run` writes it, fresh.
fn heartbeat(store: &Path) -> String {
    std::fs::create_dir_all(store).expect("mkdir");
    let now = chrono::Utc::now().to_rfc3339();
    let beat = format!(
        r#"{{"written_utc": "{now}", "wall_utc": "{now}", "pid": 1, "state": "waiting", "detail": "",
        "last_frame_utc": null, "last_frame_key": null, "devices": [], "free_disk_bytes": null,
        "store_bytes": 0, "budget_bytes": null, "frames_today": 0, "day": null, "session_dir": null}}"#
    );
    std::fs::write(store.join("heartbeat.json"), beat).expect("write");
    store.display().to_string()
}

#[test]
fn no_subcommand_panics_or_complains_on_a_closed_stdout() {
    let tmp = tempfile::tempdir().expect("temp");
    let t = tmp.path();
    let samples = sky_samples(t);
    let sky = t.join("sky.ron");
    std::fs::write(
        &sky,
        stdout_of(&[
            "sky",
            "fit",
            &samples,
            "--sun-zenith-deg",
            "40",
            "--sun-azimuth-deg",
            "190",
        ]),
    )
    .expect("write");
    let sky = sky.display().to_string();
    let dirs = t.join("dirs.csv");
    std::fs::write(&dirs, "zenith_deg,azimuth_deg\n10,20\n30,40\n").expect("write");
    let dirs = dirs.display().to_string();
    let times = t.join("times.csv");
    std::fs::write(
        &times,
        "time_utc,latitude_deg,longitude_deg\n2026-08-28T20:00:00Z,37.87,-122.26\n",
    )
    .expect("write");
    let times = times.display().to_string();
    let (plan, station) = tiny_capture(t);
    let session = t.join("session").display().to_string();
    let store = heartbeat(&t.join("store"));

    let cases: Vec<Vec<&str>> = vec![
        vec!["--help"],
        vec!["--version"],
        vec![
            "config",
            "check",
            "examples/sim-station.ron",
            "examples/campanile-day.ron",
        ],
        vec![
            "plan",
            "check",
            "examples/campanile-day.ron",
            "--station",
            "examples/sim-station.ron",
        ],
        vec!["hdr", "calibrate", "--help"],
        vec!["hdr", "merge", "--help"],
        vec!["hdr", "lens", "--help"],
        vec![
            "sun",
            "--lat",
            "37.87",
            "--lon",
            "-122.26",
            "--time",
            "2026-08-28T20:00:00Z",
        ],
        vec!["sun", "--csv", &times],
        vec![
            "sky",
            "fit",
            &samples,
            "--sun-zenith-deg",
            "40",
            "--sun-azimuth-deg",
            "190",
        ],
        vec![
            "sky",
            "predict",
            &sky,
            "--sun-zenith-deg",
            "30",
            "--sun-azimuth-deg",
            "180",
        ],
        vec!["sky", "eval", &sky, &dirs],
        vec!["sky", "map", "--help"],
        vec!["env", "fit", "--help"],
        vec!["env", "predict", "--help"],
        vec!["igi", "--help"],
        vec![
            "capture",
            "--sim-bounces",
            "1",
            &plan,
            "--station",
            &station,
            "--out",
            &session,
        ],
        vec!["station", "run", "--help"],
        vec!["station", "status", &store],
        vec!["process", "--help"],
        vec!["devices"],
        vec!["devices", "test", "--station", "examples/sim-station.ron"],
        vec!["render", "--help"],
        vec!["demo", "--help"],
    ];
    let mut failures = Vec::new();
    for args in &cases {
        let (code, stderr) = with_closed_stdout(args);
        if code != Some(0) || stderr.contains("panicked") || stderr.contains("Broken pipe") {
            failures.push(format!("campanile {}: exit {code:?}\n{stderr}", args.join(" ")));
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} commands failed:\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n")
    );
}

//! `campanile station status` checks that the station's process runs: a
//! `station run` child killed with SIGKILL (which cannot write `stopped`)
//! leaves a fresh heartbeat that says `capturing` or `waiting`; status must
//! say "not running (killed?)" and exit 1, not "fresh" and exit 0. While
//! the child runs, status says it runs and exits 0.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use campanile_capture::unattended::Heartbeat;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The small simulated sky station's plan, one day, with its scene by absolute path.
fn one_day_plan(dir: &Path) -> PathBuf {
    let plan = dir.join("plan.ron");
    let text = std::fs::read_to_string(root().join("examples/sky-station.ron"))
        .unwrap()
        .replace("days: 3", "days: 1")
        .replace(
            "Some(\"sky-scene.ron\")",
            &format!(
                "Some({:?})",
                root().join("examples/sky-scene.ron").display().to_string()
            ),
        );
    assert!(text.contains("days: 1"), "the example plan's days line moved");
    std::fs::write(&plan, text).unwrap();
    plan
}

fn status(store: &Path) -> (Option<i32>, String) {
    let out = common::campanile(&["station", "status", store.to_str().unwrap()]);
    (out.status.code(), String::from_utf8_lossy(&out.stdout).into_owned())
}

#[test]
fn a_killed_station_is_reported_not_running_and_a_live_one_running() {
    let tmp = tempfile::tempdir().unwrap();
    let plan = one_day_plan(tmp.path());
    let store = tmp.path().join("store");
    let mut child = Command::new(env!("CARGO_BIN_EXE_campanile"))
        .args([
            "-q",
            "station",
            "run",
            "--sim-bounces",
            "1",
            plan.to_str().unwrap(),
            "--station",
            "examples/sky-sim-station.ron",
            "--store",
            store.to_str().unwrap(),
        ])
        .current_dir(root())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let deadline = Instant::now() + Duration::from_secs(120);
    loop {
        if let Ok(b) = Heartbeat::read(&store)
            && b.frames_today >= 1
        {
            break;
        }
        assert!(child.try_wait().unwrap().is_none(), "the run ended before any frame");
        assert!(Instant::now() < deadline, "no frame within 120 s");
        std::thread::sleep(Duration::from_millis(10));
    }

    // Alive: the heartbeat's pid is the child, on this host.
    let (code, text) = status(&store);
    assert_eq!(code, Some(0), "{text}");
    assert!(
        text.contains(&format!("pid {} on this host: running", child.id())) && text.contains("fresh"),
        "{text}"
    );

    child.kill().unwrap(); // SIGKILL
    child.wait().unwrap();
    let beat = Heartbeat::read(&store).unwrap();
    assert!(
        beat.state.claims_running(),
        "a killed station cannot write {:?}",
        beat.state
    );
    let (code, text) = status(&store);
    assert_eq!(code, Some(1), "{text}");
    assert!(
        text.contains("not running (killed?)") && text.contains(&format!("pid {} is gone", beat.pid)),
        "{text}"
    );
    assert!(!text.contains("fresh"), "{text}");
}

#[test]
fn a_heartbeat_without_host_or_start_time_is_judged_by_age() {
    let tmp = tempfile::tempdir().unwrap();
    let now = chrono::Utc::now().to_rfc3339();
    // As an older campanile wrote it: no host, boot_id or start_ticks.
    let beat = format!(
        r#"{{"written_utc": "{now}", "wall_utc": "{now}", "pid": 4194304, "state": "capturing", "detail": "",
        "last_frame_utc": null, "last_frame_key": null, "devices": [], "free_disk_bytes": null,
        "store_bytes": 0, "budget_bytes": null, "frames_today": 0, "day": null, "session_dir": null}}"#
    );
    std::fs::write(tmp.path().join("heartbeat.json"), beat).unwrap();
    let (code, text) = status(tmp.path());
    assert_eq!(code, Some(0), "{text}");
    assert!(
        text.contains("whether pid 4194304 still runs cannot be checked") && text.contains("fresh"),
        "{text}"
    );
    // From another host: judged by age.
    let mut beat = Heartbeat::read(tmp.path()).unwrap();
    beat.host = Some("no-such-host.invalid".into());
    beat.start_ticks = Some(1);
    beat.write(tmp.path()).unwrap();
    let (code, text) = status(tmp.path());
    assert_eq!(code, Some(0), "{text}");
    assert!(text.contains("on host no-such-host.invalid, not this one"), "{text}");
}

//! `campanile capture` end to end. Disk full: a simulated session
//! on a directory with a byte quota stops cleanly with a clear message and
//! a valid journal; `campanile capture --resume DIR` alone (the plan and
//! station from the session's snapshots), with the space freed, completes
//! it: every shot of an uninterrupted run once, in order, the frames
//! before the stop untouched. A resume given another station than the
//! snapshot's is refused.

mod common;

use campanile_capture::store::{JournalEntry, SessionStore};
use common::campanile;
use std::path::Path;

/// The example station with 48×36 frames.
fn write_inputs(dir: &Path) -> (String, String) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let station = std::fs::read_to_string(root.join("examples/sim-station.ron"))
        .unwrap()
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
    name: "disk test",
    start_date: "2026-08-28",
    scene: Some({scene:?}),
    sessions: [(
        name: "one",
        trigger: Clock(time: "20:00:00"),
        steps: [
            Bracket(aim: PanTilt(pan_deg: 10.0, tilt_deg: 15.0), exposures_s: [0.0005, 0.002, 0.008, 0.032]),
            Bracket(aim: PanTilt(pan_deg: 100.0, tilt_deg: 5.0), exposures_s: [0.001, 0.004, 0.016, 0.064]),
        ],
    )],
)"#
    );
    let (p, s) = (dir.join("plan.ron"), dir.join("station.ron"));
    std::fs::write(&p, plan).unwrap();
    std::fs::write(&s, station).unwrap();
    (p.display().to_string(), s.display().to_string())
}

/// (key, crc) of every frame journaled, in order.
fn frames(dir: &Path) -> Vec<(String, u32)> {
    let (store, _) = SessionStore::resume(dir).unwrap();
    store
        .entries()
        .iter()
        .filter_map(|e| match e {
            JournalEntry::Done(f) | JournalEntry::Late(f) => Some((f.key.clone(), f.crc32c)),
            JournalEntry::Missed(_) | JournalEntry::Pruned(_) | JournalEntry::Outage(_) => None,
        })
        .collect()
}

fn dir_size(dir: &Path) -> u64 {
    let mut total = 0;
    for e in std::fs::read_dir(dir).unwrap() {
        let e = e.unwrap();
        let m = e.metadata().unwrap();
        total += if m.is_dir() { dir_size(&e.path()) } else { m.len() };
    }
    total
}

#[test]
fn a_full_disk_stops_cleanly_and_resume_alone_completes_the_session() {
    let tmp = tempfile::tempdir().unwrap();
    let (plan, station) = write_inputs(tmp.path());

    // The uninterrupted run.
    let whole = tmp.path().join("whole");
    let out = campanile(&[
        "-q",
        "capture",
        "--sim-bounces",
        "1",
        &plan,
        "--station",
        &station,
        "--out",
        whole.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let reference = frames(&whole);
    assert_eq!(reference.len(), 8);

    // Half the space the whole session needs.
    let quota = dir_size(&whole) / 2;
    let dir = tmp.path().join("full");
    let out = campanile(&[
        "-q",
        "capture",
        "--sim-bounces",
        "1",
        &plan,
        "--station",
        &station,
        "--out",
        dir.to_str().unwrap(),
        "--sim-disk-quota",
        &quota.to_string(),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("disk full while writing"), "{stderr}");
    assert!(
        stderr.contains(&format!("campanile capture --resume {}", dir.display())),
        "{stderr}"
    );
    // The journal is valid and holds a prefix of the uninterrupted run.
    let partial = frames(&dir);
    assert!(!partial.is_empty() && partial.len() < reference.len(), "{partial:?}");
    assert_eq!(partial[..], reference[..partial.len()]);
    assert!(dir_size(&dir) <= quota, "{} > {quota}", dir_size(&dir));

    // Given another station than the snapshot's, a resume is refused.
    let other = tmp.path().join("other-station.ron");
    std::fs::write(
        &other,
        std::fs::read_to_string(&station).unwrap().replace("seed: 1", "seed: 2"),
    )
    .unwrap();
    let out = campanile(&[
        "capture",
        "--sim-bounces",
        "1",
        &plan,
        "--station",
        other.to_str().unwrap(),
        "--resume",
        dir.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("began with another plan or station"), "{stderr}");

    // Space freed: `--resume DIR` alone completes the session.
    let out = campanile(&["-q", "capture", "--sim-bounces", "1", "--resume", dir.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("with its own plan.ron and station.ron"), "{stderr}");
    // Every shot once, in order; the frames stored before the stop are
    // untouched. (The shots after it are taken later on the simulated
    // calendar than in the uninterrupted run, so under the moving sun
    // their pixels differ: the keys are compared, not their checksums.)
    let done = frames(&dir);
    let keys = |v: &[(String, u32)]| v.iter().map(|(k, _)| k.clone()).collect::<Vec<_>>();
    assert_eq!(keys(&done), keys(&reference));
    assert_eq!(done[..partial.len()], partial[..]);
    let verify = SessionStore::resume(&dir).unwrap().0.verify().unwrap();
    assert!(verify.is_ok());
    assert_eq!(verify.frames_checked, 8);
}

#[test]
fn fault_flags_are_checked() {
    for (flag, value, expected) in [
        (
            "--sim-camera-timeout-chance",
            "1.5",
            "expected a chance between 0 and 1",
        ),
        ("--sim-outage", "tripod:1:2", "expected DEVICE:AFTER_S:DURATION_S"),
        ("--sim-outage", "head:-1:2", "expected DEVICE:AFTER_S:DURATION_S"),
        // Beyond what the link soak proves (issue 21).
        ("--sim-drop-chance", "0.1", "expected a chance between 0 and 0.05"),
        ("--sim-corrupt-chance", "0.06", "expected a chance between 0 and 0.05"),
    ] {
        let out = campanile(&[
            "capture",
            "--sim-bounces",
            "1",
            "examples/campanile-day.ron",
            "--station",
            "examples/sim-station.ron",
            "--out",
            "/nonexistent/never",
            flag,
            value,
        ]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{flag} {value}: {stderr}");
        assert!(stderr.contains(expected), "{flag} {value}: {stderr}");
    }
    // Fault flags on a real station are a usage error.
    let out = campanile(&[
        "capture",
        "--sim-bounces",
        "1",
        "examples/campanile-day.ron",
        "--station",
        "examples/real-station.ron",
        "--out",
        "/nonexistent/never",
        "--sim-camera-timeout-chance",
        "0.1",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("are for simulated stations"), "{stderr}");
}

/// The camera-timeout and outage flags reach the simulated station: with a
/// fifth of the frames timing out and the head away for 10 s just after
/// the session starts, every frame is still stored, through retries and a
/// reconnect that the summary counts.
#[test]
fn camera_timeouts_and_a_head_outage_from_the_command_line() {
    let tmp = tempfile::tempdir().unwrap();
    let (plan, station) = write_inputs(tmp.path());
    let dir = tmp.path().join("faults");
    let out = campanile(&[
        "-q",
        "capture",
        "--sim-bounces",
        "1",
        &plan,
        "--station",
        &station,
        "--out",
        dir.to_str().unwrap(),
        "--sim-camera-timeout-chance",
        "0.2",
        "--sim-outage",
        "head:61:10",
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let line = stdout.lines().find(|l| l.contains("this run")).expect("a summary line");
    let count = |what: &str| -> usize {
        let words: Vec<&str> = line.split([' ', ',']).filter(|w| !w.is_empty()).collect();
        let i = words.iter().position(|w| *w == what).expect(what);
        words[i - 1].parse().unwrap()
    };
    println!("{line}");
    assert_eq!(count("frames"), 8, "{line}");
    assert!(count("retries") >= 2, "{line}");
    assert!(count("reconnects") >= 1, "{line}");
    assert_eq!(frames(&dir).len(), 8);
}

/// A real station in a build without its camera driver: nothing is
/// opened or created, and the message says how to get the driver.
#[test]
fn a_real_station_without_its_camera_driver_is_refused_clearly() {
    if cfg!(feature = "v4l") {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("real");
    let out = campanile(&[
        "capture",
        "--sim-bounces",
        "1",
        "examples/campanile-day.ron",
        "--station",
        "examples/real-station.ron",
        "--out",
        dir.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("opening the camera of station examples/real-station.ron: camera failure: this campanile was built without the V4L2 camera driver; rebuild with `--features v4l`"),
        "{stderr}"
    );
    assert!(!dir.exists(), "no session directory is made");
}

/// Issue 21: 5 % byte drop + 5 % corruption on every link (the edge of
/// the range the flags accept) starts, and the session completes.
#[test]
fn link_faults_at_five_percent_start_and_the_session_completes() {
    let tmp = tempfile::tempdir().unwrap();
    let (plan, station) = write_inputs(tmp.path());
    let dir = tmp.path().join("links");
    let out = campanile(&[
        "-q",
        "capture",
        "--sim-bounces",
        "1",
        &plan,
        "--station",
        &station,
        "--out",
        dir.to_str().unwrap(),
        "--sim-drop-chance",
        "0.05",
        "--sim-corrupt-chance",
        "0.05",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert_eq!(frames(&dir).len(), 8);
}

/// Issue 21: a start that fails (links too bad for the simulated head)
/// leaves no session directory behind, or an existing empty one empty,
/// and its message names the device once, without cable advice.
#[test]
fn a_start_that_fails_leaves_no_session_behind() {
    let tmp = tempfile::tempdir().unwrap();
    let (plan, station) = write_inputs(tmp.path());
    let text = std::fs::read_to_string(&station).unwrap();
    let bad = text.replace("link_drop_chance: 0.0", "link_drop_chance: 0.45");
    assert_ne!(bad, text, "the example station's simulation line moved");
    std::fs::write(&station, bad).unwrap();
    let absent = tmp.path().join("absent");
    let empty = tmp.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    for dir in [&absent, &empty] {
        let out = campanile(&[
            "-q",
            "capture",
            "--sim-bounces",
            "1",
            &plan,
            "--station",
            &station,
            "--out",
            dir.to_str().unwrap(),
        ]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{stderr}");
        assert!(
            stderr.contains("connecting to sim:head: no valid reply after 5000 attempt(s)"),
            "{stderr}"
        );
        assert_eq!(stderr.matches("no valid reply").count(), 1, "{stderr}");
        assert!(!stderr.contains("cable") && !stderr.contains("power"), "{stderr}");
    }
    assert!(!absent.exists());
    assert_eq!(std::fs::read_dir(&empty).unwrap().count(), 0);
}

/// Issue 21: a quota too small for even the snapshot leaves no directory
/// behind (it left `DIR/frames/`, which both a new capture and --resume
/// refused); the same command without the quota then starts in it.
#[test]
fn a_quota_too_small_to_start_leaves_nothing_and_a_new_capture_starts() {
    let tmp = tempfile::tempdir().unwrap();
    let (plan, station) = write_inputs(tmp.path());
    let dir = tmp.path().join("tiny");
    let d = dir.to_str().unwrap();
    let out = campanile(&[
        "-q",
        "capture",
        "--sim-bounces",
        "1",
        &plan,
        "--station",
        &station,
        "--out",
        d,
        "--sim-disk-quota",
        "100",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("quota of 100 bytes reached"), "{stderr}");
    assert!(!dir.exists(), "{:?}", std::fs::read_dir(&dir).map(|d| d.count()));
    let out = campanile(&[
        "-q",
        "capture",
        "--sim-bounces",
        "1",
        &plan,
        "--station",
        &station,
        "--out",
        d,
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(frames(&dir).len(), 8);
}

/// Issue 21: a resume that repairs says what it repaired even under -q
/// (which hides the log), and the log reads as words, not a Rust struct.
#[test]
fn resume_repairs_are_printed_under_quiet_and_logged_in_words() {
    let tmp = tempfile::tempdir().unwrap();
    let (plan, station) = write_inputs(tmp.path());
    let dir = tmp.path().join("torn");
    let d = dir.to_str().unwrap();
    // Stop after the snapshot and a frame or two: a quota just big enough.
    let out = campanile(&[
        "-q",
        "capture",
        "--sim-bounces",
        "1",
        &plan,
        "--station",
        &station,
        "--out",
        d,
        "--sim-disk-quota",
        "20000",
    ]);
    assert_eq!(out.status.code(), Some(1), "{}", String::from_utf8_lossy(&out.stderr));
    let tear = || {
        use std::io::Write;
        let mut j = std::fs::OpenOptions::new()
            .append(true)
            .open(dir.join("journal.jsonl"))
            .unwrap();
        j.write_all(b"{\"status\":\"do").unwrap();
    };
    tear();
    let out = campanile(&[
        "-q",
        "capture",
        "--sim-bounces",
        "1",
        "--resume",
        d,
        "--sim-disk-quota",
        "20000",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("repaired: cut a torn journal line of 13 bytes"),
        "{stderr}"
    );
    assert!(!stderr.contains("see the log"), "{stderr}");
    tear();
    let out = campanile(&[
        "capture",
        "--sim-bounces",
        "1",
        "--resume",
        d,
        "--sim-disk-quota",
        "20000",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("resumed"), "{stderr}");
    assert!(
        !stderr.contains("ResumeReport {") && !stderr.contains("torn_line"),
        "{stderr}"
    );
    assert!(stderr.contains("cut a torn journal line of 13 bytes"), "{stderr}");
}

/// Issue 21: each resume of a session with missed shots used to add
/// another `missed` line per shot. The journal holds at most one per
/// shot, and the summary counts shots.
#[test]
fn resumes_that_miss_the_same_shots_add_no_missed_lines() {
    let tmp = tempfile::tempdir().unwrap();
    let (plan, station) = write_inputs(tmp.path());
    let dir = tmp.path().join("missed");
    let d = dir.to_str().unwrap();
    let faults = ["--sim-camera-error-chance", "0.6"];
    let mut args = vec![
        "-q",
        "capture",
        "--sim-bounces",
        "1",
        &plan,
        "--station",
        &station,
        "--out",
        d,
    ];
    args.extend(faults);
    let first = campanile(&args);
    assert_eq!(
        first.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&first.stderr)
    );
    let mut summaries = Vec::new();
    for _ in 0..2 {
        let mut args = vec!["-q", "capture", "--sim-bounces", "1", "--resume", d];
        args.extend(faults);
        let out = campanile(&args);
        let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
        let line = stdout
            .lines()
            .find(|l| l.contains("shots missed"))
            .expect("a summary")
            .to_owned();
        summaries.push(line);
    }
    let (store, _) = SessionStore::resume(&dir).unwrap();
    let mut per_key = std::collections::HashMap::new();
    for e in store.entries() {
        if let JournalEntry::Missed(m) = e {
            *per_key.entry(m.key.clone()).or_insert(0) += 1;
        }
    }
    assert!(!per_key.is_empty(), "the camera errors missed no shot");
    assert!(per_key.values().all(|&n| n == 1), "{per_key:?}");
    let distinct = per_key.keys().filter(|k| !store.completed(k)).count();
    for line in &summaries {
        let n: usize = line.split_whitespace().last().unwrap().parse().unwrap();
        assert!(n <= 8 && n >= distinct, "{line} with {distinct} shots missed now");
    }
    let last: usize = summaries[1].split_whitespace().last().unwrap().parse().unwrap();
    assert_eq!(last, distinct, "{summaries:?}");
}

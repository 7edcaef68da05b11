//! A full simulated day: `campanile capture` runs the example day plan
//! (sun shots, sky scans, environment tiles and views at four times, plus
//! the held-out time) on the simulated station, and the session directory
//! holds exactly the frames `plan check` promised, none missed. The wall
//! time is printed, not asserted.

mod common;

use common::campanile;
use std::collections::HashSet;

/// The "frames promised" figure of `plan check`'s totals.
fn promised_by_plan_check() -> usize {
    let out = campanile(&[
        "plan",
        "check",
        "examples/campanile-day.ron",
        "--station",
        "examples/sim-station.ron",
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    let line = text
        .lines()
        .find(|l| l.trim_start().starts_with("frames promised"))
        .expect("plan check prints the frames promised");
    line.split_whitespace()
        .nth(2)
        .and_then(|n| n.parse().ok())
        .expect("a count")
}

#[test]
fn a_simulated_day_stores_every_promised_frame() {
    let promised = promised_by_plan_check();
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("day");
    let start = std::time::Instant::now();
    let out = campanile(&[
        "-q",
        "capture",
        "--sim-bounces",
        "1",
        "examples/campanile-day.ron",
        "--station",
        "examples/sim-station.ron",
        "--out",
        dir.to_str().unwrap(),
    ]);
    let wall = start.elapsed();
    let stdout = String::from_utf8_lossy(&out.stdout);
    println!("{stdout}");
    println!("wall time of the simulated day: {:.1} s", wall.as_secs_f64());
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let journal = std::fs::read_to_string(dir.join("journal.jsonl")).unwrap();
    let mut keys = HashSet::new();
    let (mut frames, mut missed) = (0, 0);
    // Journal lines are flat JSON; the fields read here are plain strings.
    let field = |line: &str, name: &str| -> Option<String> {
        let start = line.find(&format!("\"{name}\":\""))? + name.len() + 4;
        let len = line[start..].find('"')?;
        Some(line[start..start + len].to_owned())
    };
    for line in journal.lines() {
        let key = field(line, "key").expect("every line has a key");
        assert!(keys.insert(key.clone()), "{key} journaled twice");
        match field(line, "status").as_deref() {
            Some("done" | "late") => {
                frames += 1;
                assert!(dir.join(field(line, "file").unwrap()).is_file());
            }
            _ => missed += 1,
        }
    }
    let files = std::fs::read_dir(dir.join("frames")).unwrap().count();
    println!("promised {promised}, journaled frames {frames}, files {files}, missed {missed}");
    assert_eq!(missed, 0);
    // The day plan has no auto-brackets: every frame is promised.
    assert_eq!(frames, promised);
    assert_eq!(files, promised);
    assert!(stdout.contains(&format!("frames promised      {promised}")), "{stdout}");
}

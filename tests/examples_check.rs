//! The shipped examples pass their own checks: `config check` on every
//! example file, and `plan check` on every example plan with the station
//! its header comment names, each exiting 0.

mod common;

use std::path::Path;

use common::campanile;

/// Every `examples/*.ron`, as paths relative to the repository root, sorted.
fn examples() -> Vec<String> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files: Vec<String> = std::fs::read_dir(root.join("examples"))
        .expect("examples/")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .map(|p| p.strip_prefix(root).expect("inside").display().to_string())
        .collect();
    files.sort();
    files
}

/// The station a plan's header comment names: the file after `--station`,
/// or else an `examples/…station.ron` given to `config check`.
fn station_named_in(text: &str) -> Option<String> {
    let words: Vec<&str> = text
        .lines()
        .take_while(|l| l.starts_with("//") || l.trim().is_empty())
        .flat_map(str::split_whitespace)
        .collect();
    let is_station = |w: &&str| w.starts_with("examples/") && w.ends_with("station.ron");
    words
        .windows(2)
        .find(|w| w[0] == "--station" && is_station(&w[1]))
        .map(|w| w[1])
        .or_else(|| words.iter().copied().find(|w| is_station(w)))
        .map(str::to_owned)
}

#[test]
fn every_example_passes_config_check_and_every_plan_passes_plan_check() {
    let mut failures = Vec::new();
    let mut plans = 0;
    for file in examples() {
        let out = campanile(&["config", "check", &file]);
        if out.status.code() != Some(0) {
            failures.push(format!(
                "config check {file}: exit {:?}\n{}",
                out.status.code(),
                String::from_utf8_lossy(&out.stderr)
            ));
        }
        let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(&file)).expect("read");
        if !text.lines().any(|l| l.starts_with("Plan(")) {
            continue;
        }
        plans += 1;
        let Some(station) = station_named_in(&text) else {
            failures.push(format!(
                "{file}: its header comment names no examples/…station.ron to check it on"
            ));
            continue;
        };
        let out = campanile(&["plan", "check", &file, "--station", &station]);
        if out.status.code() != Some(0) {
            failures.push(format!(
                "plan check {file} --station {station}: exit {:?}\n{}{}",
                out.status.code(),
                String::from_utf8_lossy(&out.stdout),
                String::from_utf8_lossy(&out.stderr)
            ));
        }
    }
    assert_eq!(plans, 6, "the example plans");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn a_face_never_sunlit_is_listed_as_a_warning_and_does_not_fail_the_check() {
    let out = campanile(&[
        "plan",
        "check",
        "examples/campanile-quick.ron",
        "--station",
        "examples/sim-station.ron",
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{stdout}");
    assert!(
        stdout.contains("face \"north-face\" is not sunlit at the start of any occurrence")
            && stdout.contains("(a warning: every shot is still taken"),
        "{stdout}"
    );
}

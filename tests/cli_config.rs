//! The `campanile` command line, run as a user would: `config check` on the
//! shipped examples and on broken files, exit codes, and help.

use std::path::Path;
mod common;

use common::campanile;

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

#[test]
fn config_check_passes_on_every_example_and_summarizes_them() {
    let mut files: Vec<String> = std::fs::read_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join("examples"))
        .expect("examples/")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .map(|p| {
            p.strip_prefix(env!("CARGO_MANIFEST_DIR"))
                .expect("inside")
                .display()
                .to_string()
        })
        .collect();
    files.sort();
    let args: Vec<&str> = ["config", "check"]
        .into_iter()
        .chain(files.iter().map(String::as_str))
        .collect();
    let out = campanile(&args);
    let stdout = text(&out.stdout);
    assert_eq!(
        out.status.code(),
        Some(0),
        "stdout:\n{stdout}\nstderr:\n{}",
        text(&out.stderr)
    );
    // 18: four stations, six plans, four scenes, four targets files.
    assert_eq!(stdout.matches(": valid ").count(), 18, "{stdout}");
    // The six plans were checked against the four stations.
    assert_eq!(stdout.matches("  runs on station").count(), 24, "{stdout}");
    assert!(stdout.contains("equidistant fisheye, 512×512 px"), "{stdout}");
    assert!(stdout.contains("37.8721°N, 122.2578°W"), "{stdout}");
    assert!(stdout.contains("session \"held-out\" (held out)"), "{stdout}");
}

#[test]
fn a_bad_file_exits_2_with_file_line_column_and_field() {
    let out = campanile(&["config", "check", "config/tests/malformed/latitude-out-of-range.ron"]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = text(&out.stderr);
    assert!(
        stderr.contains("config/tests/malformed/latitude-out-of-range.ron:6:23: field `site.latitude_deg`: found 95.0"),
        "{stderr}"
    );
}

#[test]
fn a_missing_file_exits_2_and_says_so() {
    let out = campanile(&["config", "check", "examples/no-such-file.ron"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        text(&out.stderr).contains("examples/no-such-file.ron: cannot read the file"),
        "{}",
        text(&out.stderr)
    );
}

#[test]
fn a_plan_that_does_not_fit_a_station_fails_the_check() {
    let out = campanile(&[
        "config",
        "check",
        "config/tests/malformed/plan-unknown-filter-slot.ron",
        "examples/sim-station.ron",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        text(&out.stdout).contains("does NOT run on station"),
        "{}",
        text(&out.stdout)
    );
    assert!(text(&out.stderr).contains(":13:35: field `sessions[0].steps[0].filters[0]`: found \"nd9\""));
}

#[test]
fn usage_errors_exit_2_and_help_exits_0() {
    assert_eq!(campanile(&["frobnicate"]).status.code(), Some(2));
    assert_eq!(
        campanile(&["config", "check"]).status.code(),
        Some(2),
        "FILE is required"
    );
    let help = campanile(&["--help"]);
    assert_eq!(help.status.code(), Some(0));
    let h = text(&help.stdout);
    assert!(
        h.contains("config") && h.contains("--log-format") && h.contains("Exit status"),
        "{h}"
    );
    let h = text(&campanile(&["config", "check", "--help"]).stdout);
    assert!(h.contains("top-level value") && h.contains("head's limits"), "{h}");
}

#[test]
fn json_logs_are_accepted() {
    let out = campanile(&[
        "--log-format",
        "json",
        "-v",
        "config",
        "check",
        "examples/sim-station.ron",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
}

//! `campanile plan check` as a user runs it: the example day, a plan with a
//! trigger that never fires, and a missing file.

mod common;

use common::campanile;

/// The example day on the simulated station is fully covered: exit 0, the
/// five sessions in time order with their local (PDT) times, and totals.
#[test]
fn the_example_day_is_fully_covered() {
    let dir = tempfile::tempdir().expect("temp dir");
    let ron = dir.path().join("timeline.ron");
    let ron_arg = ron.to_str().expect("utf-8 path");
    let out = campanile(&[
        "plan",
        "check",
        "examples/campanile-day.ron",
        "--station",
        "examples/sim-station.ron",
        "--ron",
        ron_arg,
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let order: Vec<usize> = ["morning@", "noon@", "held-out@", "afternoon@", "evening@"]
        .iter()
        .map(|k| {
            stdout
                .find(&format!("  {k}2026-08-28"))
                .unwrap_or_else(|| panic!("{k} in {stdout}"))
        })
        .collect();
    assert!(order.windows(2).all(|w| w[0] < w[1]), "time order: {stdout}");
    assert!(stdout.contains("Timeline (5 occurrences)"), "{stdout}");
    // The held-out session is at 20:30 UTC, 13:30 in Berkeley.
    let held_out = stdout
        .lines()
        .find(|l| l.trim_start().starts_with("held-out@"))
        .unwrap_or_else(|| panic!("{stdout}"));
    assert!(
        held_out.contains("2026-08-28 20:30:00") && held_out.contains("2026-08-28 13:30:00 PDT"),
        "{held_out}"
    );
    assert!(stdout.contains("frames promised"), "{stdout}");
    assert!(stdout.contains("Will not cover: nothing"), "{stdout}");
    // The RON timeline holds every planned shot: as many keys as frames promised.
    let promised: usize = stdout
        .lines()
        .find_map(|l| l.trim().strip_prefix("frames promised"))
        .and_then(|v| v.split_whitespace().next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no total in {stdout}"));
    let text = std::fs::read_to_string(&ron).expect("timeline written");
    assert_eq!(
        text.matches("key: \"").count() - 5,
        promised,
        "shot keys = frames promised"
    );
}

/// A trigger that cannot fire (80° at 37.9°N in August) exits 1 and names
/// the session, the day and the highest the sun gets.
#[test]
fn an_unreachable_trigger_exits_1_and_is_named() {
    let dir = tempfile::tempdir().expect("temp dir");
    let plan = dir.path().join("high.ron");
    std::fs::write(
        &plan,
        r#"Plan(
    name: "too high",
    start_date: "2026-08-28",
    sessions: [
        (name: "overhead", trigger: SolarElevation(elevation_deg: 80.0, motion: Rising),
         steps: [SunShot(filters: ["nd4", "nd5"], triplet: true)]),
        (name: "ok", trigger: Clock(time: "20:00:00"), steps: [SunShot(filters: ["nd5"])]),
    ],
)
"#,
    )
    .expect("write plan");
    let station = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/sim-station.ron");
    let out = campanile(&[
        "plan",
        "check",
        plan.to_str().expect("utf-8"),
        "--station",
        station.to_str().expect("utf-8"),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{stdout}");
    assert!(stdout.contains("Will not cover (1)"), "{stdout}");
    assert!(
        stdout.contains("session \"overhead\": the sun never reaches 80° on 2026-08-28 (highest 61."),
        "{stdout}"
    );
    assert!(stdout.contains("ok@2026-08-28"), "{stdout}");
}

/// A missing plan exits 2 and names the path.
#[test]
fn a_missing_file_exits_2_with_its_path() {
    let out = campanile(&[
        "plan",
        "check",
        "examples/no-such-plan.ron",
        "--station",
        "examples/sim-station.ron",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("examples/no-such-plan.ron"), "{stderr}");
}

/// A plan that does not run on the station (an ND slot it lacks) is bad input: exit 2.
#[test]
fn a_plan_that_does_not_fit_the_station_exits_2() {
    let dir = tempfile::tempdir().expect("temp dir");
    let plan = dir.path().join("nd9.ron");
    std::fs::write(
        &plan,
        r#"Plan(name: "nd9", start_date: "2026-08-28", sessions: [
    (name: "s", trigger: Clock(time: "20:00:00"), steps: [SunShot(filters: ["nd9"])]),
])
"#,
    )
    .expect("write plan");
    let out = campanile(&[
        "plan",
        "check",
        plan.to_str().expect("utf-8"),
        "--station",
        "examples/sim-station.ron",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("nd9"), "{stderr}");
}

//! Every file in `tests/malformed/` is a broken configuration whose first
//! line states the error it must produce: `// expect: LINE:COL FIELD`
//! (FIELD `-` when no field applies). A second line `// with-station: FILE`
//! checks a plan against that station. Each must fail with exactly that
//! position and field, through the same loader the command line uses, and
//! none may panic.

use std::path::{Path, PathBuf};

use campanile_config::{ConfigErrors, Document, check_plan_on_station, load, load_station};

struct Case {
    path: PathBuf,
    line: usize,
    col: usize,
    field: Option<String>,
    station: Option<PathBuf>,
}

fn cases() -> Vec<Case> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/malformed");
    let mut out = Vec::new();
    for entry in std::fs::read_dir(&dir).expect("tests/malformed exists") {
        let path = entry.expect("readable dir entry").path();
        if path.extension().is_none_or(|e| e != "ron") {
            continue;
        }
        let bytes = std::fs::read(&path).expect("readable case");
        let head = String::from_utf8_lossy(&bytes);
        let mut lines = head.lines();
        let expect = lines
            .next()
            .and_then(|l| l.strip_prefix("// expect: "))
            .unwrap_or_else(|| panic!("{}: first line must be `// expect: LINE:COL FIELD`", path.display()));
        let (pos, field) = expect.split_once(' ').expect("LINE:COL FIELD");
        let (line, col) = pos.split_once(':').expect("LINE:COL");
        let station = lines
            .next()
            .and_then(|l| l.strip_prefix("// with-station: "))
            .map(|s| dir.join(s.trim()));
        out.push(Case {
            path,
            line: line.parse().expect("line number"),
            col: col.parse().expect("column number"),
            field: (field != "-").then(|| field.to_owned()),
            station,
        });
    }
    out.sort_by(|a, b| a.path.cmp(&b.path));
    out
}

fn first_error(case: &Case) -> ConfigErrors {
    match (load(&case.path), &case.station) {
        (Err(e), _) => e,
        (Ok(Document::Plan(plan)), Some(station)) => {
            let station = load_station(station).expect("the reference station is valid");
            check_plan_on_station(&plan, &station.value).expect_err("the plan must not run on the station")
        }
        (Ok(_), _) => panic!("{}: loaded without error", case.path.display()),
    }
}

#[test]
fn at_least_25_malformed_files_each_fail_at_the_stated_position_and_field() {
    let cases = cases();
    assert!(cases.len() >= 25, "only {} malformed cases", cases.len());
    let mut failures = Vec::new();
    for case in &cases {
        let errors = first_error(case);
        let e = &errors.0[0];
        let got = (e.position, e.field.clone());
        let want = (Some((case.line, case.col)), case.field.clone());
        if got != want {
            failures.push(format!("{}: got {got:?}, want {want:?}: {e}", case.path.display()));
            continue;
        }
        // The message a user sees names file:line:column and the field.
        let shown = e.to_string();
        let prefix = format!("{}:{}:{}: ", case.path.display(), case.line, case.col);
        if !shown.starts_with(&prefix) {
            failures.push(format!("message does not start with {prefix:?}: {shown}"));
        }
        if let Some(field) = &case.field
            && !shown.contains(&format!("field `{field}`"))
            && field != "(top level)"
        {
            failures.push(format!("message does not name field {field}: {shown}"));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn validation_reports_every_problem_not_just_the_first() {
    let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/sim-station.ron"))
        .expect("example exists")
        .replace("latitude_deg: 37.8721", "latitude_deg: 91.0")
        .replace("bit_depth: 12", "bit_depth: 11")
        .replace("baud: 115200),\n        address", "baud: 1),\n        address");
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/edited-station.ron");
    let errors = campanile_config::load_text(&path, text).expect_err("three problems");
    let fields: Vec<_> = errors.0.iter().map(|e| e.field.clone().unwrap_or_default()).collect();
    assert_eq!(fields, ["site.latitude_deg", "camera.bit_depth", "head.link.baud"]);
}

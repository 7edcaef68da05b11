//! `campanile process` refuses bad settings before it reads anything, with
//! the value and what was expected.

mod common;

use common::campanile;

/// `--grid-spacing` takes a cell side in metres within [0.1, 50]: 0.01 m
/// (a billion cells on the tower) and a word are refused, naming the option
/// and the range; no output directory is created.
#[test]
fn a_grid_spacing_out_of_range_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    for (value, expected) in [("0.01", "[0.1, 50] m"), ("two", "invalid float")] {
        let o = campanile(&[
            "process",
            tmp.path().to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--grid-spacing",
            value,
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{value}: {err}");
        assert!(
            err.contains("--grid-spacing") && err.contains(expected),
            "{value}: {err}"
        );
        assert!(!out.exists());
    }
}

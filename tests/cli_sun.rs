//! `campanile sun` as a user runs it: one instant, a station, a table.

mod common;

use common::campanile;

fn field(stdout: &str, name: &str) -> f64 {
    stdout
        .lines()
        .find_map(|l| l.strip_prefix(name))
        .and_then(|v| v.trim().parse().ok())
        .unwrap_or_else(|| panic!("no {name} in {stdout}"))
}

#[test]
fn the_nrel_spa_test_case_from_the_command_line() {
    let out = campanile(&[
        "sun",
        "--time",
        "2003-10-17T19:30:30Z",
        "--lat",
        "39.742476",
        "--lon",
        "-105.1786",
        "--elevation-m",
        "1830.14",
        "--pressure-mbar",
        "820",
        "--temperature-c",
        "11",
        "--delta-t-s",
        "67",
        "--time-zone",
        "America/Denver",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let s = String::from_utf8_lossy(&out.stdout);
    assert!((field(&s, "zenith_deg") - 50.11162).abs() < 1e-5, "{s}");
    assert!((field(&s, "azimuth_deg") - 194.34024).abs() < 1e-5, "{s}");
    assert!(s.contains("sunrise         2003-10-17 13:12:4"), "{s}");
}

#[test]
fn a_station_file_supplies_the_site_and_time_zone() {
    let out = campanile(&[
        "sun",
        "--time",
        "2026-08-28T20:30:00Z",
        "--station",
        "examples/sim-station.ron",
    ]);
    assert_eq!(out.status.code(), Some(0));
    let s = String::from_utf8_lossy(&out.stdout);
    assert!(s.contains("13:30:00 PDT") && s.contains("Campanile, Berkeley"), "{s}");
    // Late August, 37.9°N, shortly after local solar noon: about 61° up, just west of south.
    let (el, az) = (field(&s, "elevation_deg"), field(&s, "azimuth_deg"));
    assert!((55.0..65.0).contains(&el) && (180.0..200.0).contains(&az), "{s}");
}

#[test]
fn a_csv_table_round_trips_and_bad_rows_are_named() {
    let dir = tempfile::tempdir().expect("temp dir");
    let input = dir.path().join("in.csv");
    let output = dir.path().join("out.csv");
    std::fs::write(
        &input,
        "station,time_utc,latitude_deg,longitude_deg\nsvalbard,2026-06-21T00:00:00Z,78.22,15.6\nquito,2026-03-20T17:20:00Z,-0.18,-78.47\n",
    )
    .expect("write");
    let out = campanile(&[
        "sun",
        "--csv",
        input.to_str().expect("utf-8"),
        "--out",
        output.to_str().expect("utf-8"),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let table = std::fs::read_to_string(&output).expect("written");
    let rows: Vec<Vec<&str>> = table.lines().map(|l| l.split(',').collect()).collect();
    assert_eq!(rows[0][0], "station");
    // Midnight sun at Svalbard: above the horizon at midnight UTC in June.
    assert!(rows[1][6].parse::<f64>().expect("elevation") > 5.0, "{table}");
    // Quito near the March equinox at local noon: the sun within 3° of the zenith.
    assert!(rows[2][4].parse::<f64>().expect("zenith") < 3.0, "{table}");

    std::fs::write(&input, "time_utc,latitude_deg,longitude_deg\nyesterday,10,10\n").expect("write");
    let out = campanile(&["sun", "--csv", input.to_str().expect("utf-8")]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("row 2, column `time_utc`: found \"yesterday\""), "{err}");
}

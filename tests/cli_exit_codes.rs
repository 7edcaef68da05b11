//! Exit statuses, pinned for every command: 2 for every bad input (an
//! argument, a value, a configuration or input file), 1 for a failure
//! while working, 0 for success. Also: numbers in errors are short, and a
//! failed `--out` leaves no `.partial` file.

mod common;

use std::path::Path;

use common::campanile;

/// (arguments, expected exit status, a piece of the expected message on stderr).
type Case = (Vec<String>, i32, &'static str);

fn case(args: &[&str], code: i32, says: &'static str) -> Case {
    (args.iter().map(|s| (*s).to_owned()).collect(), code, says)
}

fn files(dir: &Path) {
    let write = |name: &str, text: &str| std::fs::write(dir.join(name), text).expect("write");
    write("bad-sky.csv", "zenith_deg,azimuth_deg,r,g,b\n10,20,abc,1,1\n");
    write("bad-env.csv", "region,r\nx,1\n");
    write("no-channels.csv", "id,zenith_deg,azimuth_deg,weight\n1,10,20,0.5\n");
    write("two-channels.csv", "zenith_deg,azimuth_deg,y,radiance\n10,20,1,1\n");
    write("only-r.csv", "id,zenith_deg,azimuth_deg,r,note\n1,10,20,0.5,clear\n");
    write(
        "sky.ron",
        "(sun_zenith_deg: 40.0, sun_azimuth_deg: 180.0, channels: [(channel: \"g\", \
         model: (lz: 0.07, a: -1.0, b: -0.4, c: 12.0, d: -3.2, e: 0.5, h: 0.9), chosen: \"SevenParameter\", \
         reason: \"test\", rms_relative: 0.0, samples: 100, masked_fraction: 0.0)])",
    );
    write("bad.ron", "SkyFile(\n");
    write(
        "times.csv",
        "time_utc,latitude_deg,longitude_deg\n2026-08-28T20:00:00Z,37.87,-122.26\n",
    );
    write(
        "bad-times.csv",
        "time_utc,latitude_deg,longitude_deg\n2026-08-28T20:00:00Z,37.87,-122.26\n2026-08-28T20:00:00Z,95,0\n",
    );
    std::fs::create_dir_all(dir.join("not-a-session")).expect("mkdir");
    std::fs::create_dir_all(dir.join("unrelated")).expect("mkdir");
    write("unrelated/notes.txt", "mine\n");
}

#[test]
fn every_command_exits_2_on_bad_input_1_on_failure_and_0_on_success() {
    let tmp = tempfile::tempdir().expect("temp");
    let t = tmp.path();
    files(t);
    let p = |name: &str| t.join(name).display().to_string();
    let (bad_sky, bad_env, bad_ron, times, bad_times) = (
        p("bad-sky.csv"),
        p("bad-env.csv"),
        p("bad.ron"),
        p("times.csv"),
        p("bad-times.csv"),
    );
    let (no_channels, two_channels, only_r, sky) = (
        p("no-channels.csv"),
        p("two-channels.csv"),
        p("only-r.csv"),
        p("sky.ron"),
    );
    let sun = ["--sun-zenith-deg", "40", "--sun-azimuth-deg", "10"];
    let fit = |samples: &str, more: &[&str]| {
        let mut args = vec!["sky", "fit"];
        args.push(samples);
        args.extend_from_slice(more);
        args.iter().map(|s| (*s).to_owned()).collect::<Vec<String>>()
    };
    let (missing, not_session, unrelated) = (p("no-such-file.ron"), p("not-a-session"), p("unrelated"));
    let now = "2026-08-28T20:00:00Z";
    let cases: Vec<Case> = vec![
        // Bad input: 2.
        case(&["frobnicate"], 2, "unrecognized subcommand"),
        case(
            &["config", "check", "config/tests/malformed/latitude-out-of-range.ron"],
            2,
            "found 95",
        ),
        case(
            &["plan", "check", &missing, "--station", "examples/sim-station.ron"],
            2,
            "cannot read",
        ),
        case(
            &["hdr", "calibrate", &missing, "--times", "1", "--out", &p("c.csv")],
            2,
            "No such file",
        ),
        case(
            &[
                "hdr",
                "merge",
                &missing,
                "--times",
                "1",
                "--curve",
                &missing,
                "--out",
                &p("m.exr"),
            ],
            2,
            "No such file",
        ),
        case(
            &["hdr", "lens", "--flat", &missing, "--out", &p("l.txt")],
            2,
            "No such file",
        ),
        case(
            &["sun", "--lat", "95", "--lon", "0", "--time", now],
            2,
            "--lat: found 95; expected degrees from -90 to 90",
        ),
        case(
            &["sun", "--lat", "1e308", "--lon", "0", "--time", now],
            2,
            "--lat: found 1e308;",
        ),
        case(
            &[
                "sun",
                "--lat",
                "30",
                "--lon",
                "0",
                "--pressure-mbar",
                "-5",
                "--time",
                now,
            ],
            2,
            "--pressure-mbar: found -5; expected more than 0 and at most 2000 mbar",
        ),
        case(&["sun", "--csv", &bad_times], 2, "row 3"),
        case(
            &[
                "sky",
                "fit",
                &bad_sky,
                "--sun-zenith-deg",
                "40",
                "--sun-azimuth-deg",
                "10",
            ],
            2,
            "found \"abc\"",
        ),
        // The sun from a site: values out of their domains, a time that is
        // not RFC 3339, two sites, a time without a site.
        case(
            &["sky", "fit", &missing, "--lat", "95", "--lon", "0", "--time", now],
            2,
            "--lat: found 95; expected degrees from -90 to 90, north positive",
        ),
        case(
            &["sky", "fit", &missing, "--lat", "-1e308", "--lon", "0", "--time", now],
            2,
            "--lat: found -1e308;",
        ),
        case(
            &["sky", "fit", &missing, "--lat", "30", "--lon", "360", "--time", now],
            2,
            "--lon: found 360; expected degrees from -180 up to (not including) 360, east positive",
        ),
        case(
            &["sky", "fit", &missing, "--lat", "30", "--lon", "-180.5", "--time", now],
            2,
            "--lon: found -180.5;",
        ),
        case(
            &[
                "sky",
                "fit",
                &missing,
                "--lat",
                "30",
                "--lon",
                "10",
                "--elevation-m",
                "2e7",
                "--time",
                now,
            ],
            2,
            "--elevation-m: found 20000000; expected metres above sea level",
        ),
        case(
            &[
                "sky",
                "fit",
                &missing,
                "--lat",
                "30",
                "--lon",
                "10",
                "--time",
                "yesterday",
            ],
            2,
            "invalid value 'yesterday' for '--time <TIME>': expected an RFC 3339 instant such as 2026-08-28T20:30:00Z",
        ),
        case(
            &[
                "sky",
                "fit",
                &missing,
                "--lat",
                "30",
                "--lon",
                "10",
                "--time",
                "2026-08-28 20:00",
            ],
            2,
            "expected an RFC 3339 instant",
        ),
        case(
            &[
                "sky",
                "fit",
                &missing,
                "--lat",
                "30",
                "--lon",
                "10",
                "--station",
                "examples/sim-station.ron",
                "--time",
                now,
            ],
            2,
            "cannot be used with",
        ),
        case(
            &["sky", "fit", &missing, "--time", now],
            2,
            "<--station <STATION>|--lat <LAT>>",
        ),
        case(
            &["sky", "predict", &missing, "--lat", "95", "--lon", "0", "--time", now],
            2,
            "--lat: found 95;",
        ),
        case(
            &[
                "env",
                "predict",
                &missing,
                "--sky-irradiance",
                "1,1,1",
                "--sun-irradiance",
                "1,1,1",
                "--lat",
                "30",
                "--lon",
                "-200",
                "--time",
                now,
            ],
            2,
            "--lon: found -200;",
        ),
        // The channel columns.
        (
            fit(&only_r, &[&sun[..], &["--columns", "r,q"]].concat()),
            2,
            "channel column `q` is not in the header (it has: id,zenith_deg,azimuth_deg,r,note)",
        ),
        (
            fit(&only_r, &[&sun[..], &["--columns", "r,zenith_deg"]].concat()),
            2,
            "channel column `zenith_deg` cannot be a channel: it is a direction column",
        ),
        (
            fit(&only_r, &[&sun[..], &["--columns", "r,r"]].concat()),
            2,
            "channel column `r` cannot be a channel: it is named twice",
        ),
        (
            fit(&only_r, &[&sun[..], &["--columns", "note"]].concat()),
            2,
            "column `note`: found \"clear\"; expected a radiance",
        ),
        (
            fit(&only_r, &sun),
            2,
            "no channel columns: the header has id,zenith_deg,azimuth_deg,r,note",
        ),
        (
            fit(&no_channels, &sun),
            2,
            "no channel columns: the header has id,zenith_deg,azimuth_deg,weight",
        ),
        (
            fit(&two_channels, &sun),
            2,
            "the channel column is ambiguous: the header has y, radiance",
        ),
        case(
            &["sky", "eval", &sky, &only_r, "--compare"],
            2,
            "--compare needs the sky's channels: channel column `g` is not in the header",
        ),
        case(
            &[
                "sky",
                "predict",
                &missing,
                "--sun-zenith-deg",
                "40",
                "--sun-azimuth-deg",
                "10",
            ],
            2,
            "cannot read",
        ),
        case(&["sky", "eval", &bad_ron, &times], 2, "bad.ron:"),
        case(&["sky", "map", &missing, "--out", &p("m.exr")], 2, "cannot read"),
        case(&["env", "fit", &bad_env], 2, "no `g` column"),
        case(
            &[
                "env",
                "predict",
                &missing,
                "--sky-irradiance",
                "1,1,1",
                "--sun-irradiance",
                "1,1,1",
                "--sun-zenith-deg",
                "10",
                "--sun-azimuth-deg",
                "10",
            ],
            2,
            "cannot read",
        ),
        case(&["igi", &missing, "--out", &p("igi")], 2, "no-such-file.ron"),
        case(
            &[
                "capture",
                "--sim-bounces",
                "1",
                &missing,
                "--station",
                "examples/sim-station.ron",
                "--out",
                &p("s"),
            ],
            2,
            "cannot read",
        ),
        case(
            &[
                "station",
                "run",
                &missing,
                "--station",
                "examples/sky-sim-station.ron",
                "--store",
                &p("store"),
            ],
            2,
            "cannot read",
        ),
        case(
            &["station", "status", &unrelated, "--max-age", "-5"],
            2,
            "--max-age: found -5",
        ),
        case(&["process", &p("no-such-session")], 2, "no-such-session"),
        case(&["process", &not_session], 2, "is not a session directory"),
        case(&["devices", "test", "--station", &missing], 2, "cannot read"),
        case(
            &[
                "devices",
                "test",
                "--station",
                "examples/sim-station.ron",
                "--move-limit-s",
                "0",
            ],
            2,
            "--move-limit-s",
        ),
        case(
            &[
                "render",
                "--scene",
                "examples/campanile-scene.ron",
                "--station",
                "examples/sim-station.ron",
                "--materials",
                &missing,
                "--pose",
                "view-se",
                "--time",
                now,
                "--overcast",
                "150",
                "--out",
                &p("r.png"),
            ],
            2,
            "--overcast: found 150; expected a fraction from 0 to 1",
        ),
        case(
            &[
                "render",
                "--scene",
                "examples/campanile-scene.ron",
                "--station",
                "examples/sim-station.ron",
                "--materials",
                &missing,
                "--pose",
                "view-se",
                "--time",
                now,
                "--width",
                "0",
                "--out",
                &p("r.png"),
            ],
            2,
            "--width 0",
        ),
        case(
            &["demo", "--reuse-session", "--out", &unrelated],
            2,
            "campanile-session/journal.jsonl is missing",
        ),
        // A failure while working: 1 (/sys is read-only).
        case(
            &["sun", "--csv", &times, "--out", "/sys/campanile-positions.csv"],
            1,
            "/sys/campanile-positions.csv",
        ),
        case(
            &[
                "plan",
                "check",
                "examples/campanile-day.ron",
                "--station",
                "examples/sim-station.ron",
                "--ron",
                "/sys/timeline.ron",
            ],
            1,
            "/sys/timeline.ron",
        ),
        case(&["station", "status", &unrelated], 1, "heartbeat.json"),
        // Success: 0.
        case(&["sun", "--lat", "37.87", "--lon", "-122.26", "--time", now], 0, ""),
        case(&["sun", "--csv", &times, "--out", &p("positions.csv")], 0, ""),
        case(&["config", "check", "examples/sim-station.ron"], 0, ""),
        case(&["sky", "eval", &sky, &only_r], 0, ""),
    ];
    let mut wrong = Vec::new();
    for (args, code, says) in &cases {
        let out = campanile(&args.iter().map(String::as_str).collect::<Vec<_>>());
        let stderr = String::from_utf8_lossy(&out.stderr);
        if out.status.code() != Some(*code) || !stderr.contains(says) || stderr.contains("panicked") {
            wrong.push(format!(
                "campanile {}: exit {:?}, expected {code} with {says:?}\n{}",
                args.join(" "),
                out.status.code(),
                stderr.chars().take(600).collect::<String>()
            ));
        }
    }
    assert!(
        wrong.is_empty(),
        "{} of {} cases wrong:\n{}",
        wrong.len(),
        cases.len(),
        wrong.join("\n")
    );
    // Nothing was written into the unrelated directory.
    assert_eq!(std::fs::read_dir(&unrelated).expect("dir").count(), 1);
}

#[test]
fn a_failed_out_leaves_no_partial_file() {
    let tmp = tempfile::tempdir().expect("temp");
    files(tmp.path());
    let out_csv = tmp.path().join("positions.csv");
    let out = campanile(&[
        "sun",
        "--csv",
        tmp.path().join("bad-times.csv").to_str().expect("utf-8"),
        "--out",
        out_csv.to_str().expect("utf-8"),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    // The row's reason once, not twice (message and source).
    assert_eq!(stderr.matches("invalid latitude 95").count(), 1, "{stderr}");
    assert!(
        stderr.contains("row 3: site latitude_deg = 95: invalid latitude 95"),
        "{stderr}"
    );
    let left: Vec<String> = std::fs::read_dir(tmp.path())
        .expect("dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with("positions"))
        .collect();
    assert!(left.is_empty(), "left behind: {left:?}");
}

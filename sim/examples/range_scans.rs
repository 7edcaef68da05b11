//! The simulated range scanner's example scans: five scans of the example
//! room and five of the bell tower (`sim::world::range_scanner`), written
//! as files that `campanile-scan` reads, with each scan's counts and a
//! read-back check.
//!
//! ```text
//! cargo run --release -p campanile-sim --example range_scans -- /tmp/scans
//! cargo run --release -p campanile-sim --example range_scans -- /tmp/scans --format e57 --rows 360 --columns 720 --seed 7
//! cargo run --release -p campanile-sim --example range_scans -- /tmp/scans --truth
//! ```
//!
//! Arguments: the directory to write, then optionally `--format ply|e57`
//! (PLY: one file per scan, `room-sw.ply` …; E57: `room.e57` and
//! `building.e57`), `--rows N` and `--columns N` (default 180 × 360: 1°
//! steps in azimuth, 0.78° in elevation from −60° to 80°), `--seed N`, and
//! `--truth`: also write every point's true surface beside the scans
//! (`room.truth.json`, `room-sw.truth` …; the format is
//! `sim::world::range_truth`'s), which the scan files do not hold.
//! Prints one line per scan: beams, returns, misses, grazing losses,
//! dropouts, depth-edge beams and mixed pixels; then the verdict: `ok`
//! when every file (and the truth) reads back with the points written,
//! `failed` (exit 3) otherwise.

use std::path::PathBuf;
use std::process::ExitCode;

use campanile_sim::world::range_scanner::{
    ScanFileFormat, ScannerSettings, building_poses, building_scene, room_poses, room_scene, scan_scene, write_scans,
};
use campanile_sim::world::range_truth::{read_truth, write_truth};

const USAGE: &str = "usage: range_scans DIR [--format ply|e57] [--rows N] [--columns N] [--seed N] [--truth]\n\
example: cargo run --release -p campanile-sim --example range_scans -- /tmp/scans --format e57\n\
example: cargo run --release -p campanile-sim --example range_scans -- /tmp/scans --truth   (true surfaces beside the scans)";

fn main() -> ExitCode {
    match run() {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(3),
        Err(e) => {
            eprintln!("range_scans: {e}");
            ExitCode::from(if e.starts_with("usage") { 2 } else { 1 })
        }
    }
}

fn run() -> Result<bool, String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = |why: &str| format!("{USAGE}\n({why})");
    let mut dir = None;
    let mut format = ScanFileFormat::Ply;
    let mut settings = ScannerSettings::new(180, 360);
    let mut truth = false;
    let mut it = args.iter();
    while let Some(arg) = it.next() {
        let mut value = |name: &str| {
            it.next()
                .cloned()
                .ok_or_else(|| usage(&format!("{name} needs a value")))
        };
        let number = |name: &str, v: String| {
            v.parse::<u64>()
                .map_err(|_| usage(&format!("{name} {v:?}: expected a whole number")))
        };
        match arg.as_str() {
            "--help" | "-h" => {
                println!("{USAGE}");
                return Ok(true);
            }
            "--format" => {
                format = match value("--format")?.as_str() {
                    "ply" => ScanFileFormat::Ply,
                    "e57" => ScanFileFormat::E57,
                    other => return Err(usage(&format!("--format {other:?}: expected ply or e57"))),
                }
            }
            "--rows" => settings.rows = number("--rows", value("--rows")?)? as usize,
            "--columns" => settings.columns = number("--columns", value("--columns")?)? as usize,
            "--seed" => settings.seed = number("--seed", value("--seed")?)?,
            "--truth" => truth = true,
            other if dir.is_none() && !other.starts_with('-') => dir = Some(PathBuf::from(other)),
            other => return Err(usage(&format!("unexpected argument {other:?}"))),
        }
    }
    let dir = dir.ok_or_else(|| usage("no directory given"))?;
    settings.check().map_err(|e| usage(&e.to_string()))?;
    let mut ok = true;
    for (set, scene, poses) in [
        ("room", room_scene().map_err(|e| e.to_string())?, room_poses()),
        (
            "building",
            building_scene().map_err(|e| e.to_string())?,
            building_poses(),
        ),
    ] {
        let clock = std::time::Instant::now();
        let scans = scan_scene(&scene, &poses, &settings).map_err(|e| e.to_string())?;
        let seconds = clock.elapsed().as_secs_f64();
        for (scan, c) in scans.scans.iter().zip(&scans.counts) {
            println!(
                "{:<12} beams {:>8} returns {:>8} misses {:>7} grazing {:>6} dropouts {:>6} edges {:>6} mixed {:>6}",
                scan.name, c.beams, c.returns, c.misses, c.grazing, c.dropouts, c.edges, c.mixed
            );
        }
        let files = write_scans(&dir, set, &scans, format).map_err(|e| e.to_string())?;
        let written: usize = scans.scans.iter().map(|s| s.len()).sum();
        let clock = std::time::Instant::now();
        let read: usize = files
            .iter()
            .map(|f| campanile_scan::read::read_scan(f).map(|s| s.iter().map(|s| s.len()).sum::<usize>()))
            .sum::<Result<usize, _>>()
            .map_err(|e| e.to_string())?;
        let read_seconds = clock.elapsed().as_secs_f64();
        println!(
            "{set}: {} scans, {written} points in {seconds:.2} s, {} file(s) in {}; read back {read} points in {read_seconds:.2} s",
            scans.scans.len(),
            files.len(),
            dir.display()
        );
        ok &= read == written;
        if truth {
            let index = write_truth(&dir, set, &scans, format).map_err(|e| e.to_string())?;
            let (_, back) = read_truth(&index).map_err(|e| e.to_string())?;
            let same = back == scans.truth;
            println!(
                "{set}: truth of {} surfaces in {} ({})",
                back.names.len(),
                index.display(),
                if same { "reads back" } else { "DIFFERS on reading back" }
            );
            ok &= same;
        }
    }
    println!("verdict: {}", if ok { "ok" } else { "failed" });
    Ok(ok)
}

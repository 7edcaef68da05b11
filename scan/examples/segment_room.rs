//! Segments the analytic box room and prints time and quality: the bench
//! for `scan::segment` (BENCHMARKS.md).
//!
//! ```sh
//! cargo run --release -p campanile-scan --example segment_room -- 1200 450 0.005
//! ```
//! Arguments: azimuth steps, elevation steps, range noise in m; then any of
//! `curtain`, `target`, `nofine`, `novote`, `unorganised` (no grid, no
//! pose), `verbose`.

use std::time::Instant;

use campanile_scan::segment::metrics::compare;
use campanile_scan::segment::params::Overrides;
use campanile_scan::segment::room_fixture::{RoomScan, scan_room};
use campanile_scan::segment::segment;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let number = |k: usize, default: f64| args.get(k).and_then(|a| a.parse::<f64>().ok()).unwrap_or(default);
    let flag = |name: &str| args.iter().any(|a| a == name);
    let spec = RoomScan {
        cols: number(0, 480.0) as usize,
        rows: number(1, 180.0) as usize,
        noise_m: number(2, 0.005),
        curtain: flag("curtain"),
        target: flag("target"),
        ..RoomScan::default()
    };
    let (mut scan, truth) = scan_room(&spec);
    if flag("unorganised") {
        scan.grid = None;
        scan.pose = None;
    }
    let overrides = Overrides {
        fine: flag("nofine").then_some(false),
        boundary_voting: flag("novote").then_some(false),
        ..Overrides::default()
    };
    let start = Instant::now();
    let (found, report) = match segment(std::slice::from_ref(&scan), &overrides, &|_| {}) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("segment_room: {e}");
            std::process::exit(1);
        }
    };
    let seconds = start.elapsed().as_secs_f64();
    let metrics = match compare(std::slice::from_ref(&scan), &found, &truth) {
        Ok(m) => m,
        Err(e) => {
            eprintln!("segment_room: {e}");
            std::process::exit(1);
        }
    };
    println!(
        "points {} nodes {}/{} groups {} time {seconds:.2} s ({})",
        scan.len(),
        report.coarse_nodes,
        report.fine_nodes,
        report.groups,
        report
            .stages
            .iter()
            .map(|s| format!("{} {:.2}", s.stage, s.seconds))
            .collect::<Vec<_>>()
            .join(", ")
    );
    println!(
        "right {:.4} boundary mean {:.4} m median {:.4} m merged {:?} split {:?}",
        metrics.right_fraction,
        metrics.boundary_mean_m.unwrap_or(f64::INFINITY),
        metrics.boundary_median_m.unwrap_or(f64::INFINITY),
        metrics.merged,
        metrics.split
    );
    println!("verdict {:?}: {}", report.verdict, report.verdict_reason);
    if flag("verbose") {
        for c in &report.parameters {
            println!("  {} = {:.4} ({})", c.name, c.value, c.reason);
        }
        println!("  sizes {:?}", report.sizes);
        for s in report.splits.iter().take(40) {
            println!(
                "  split {:?} nodes {} smaller {} ncut {:.4} nwacut {:.4} {} ({})",
                s.pass, s.nodes, s.smaller_side, s.ncut, s.nwacut, s.accepted, s.reason
            );
        }
        println!("  targets {:?}", report.targets);
    }
}

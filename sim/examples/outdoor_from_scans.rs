//! Issue 28's end-to-end criterion on the simulated tower: the geometry the
//! range scans give (`scan::segment` → `scan::mesh::mesh_groups`) fed to
//! the outdoor reflectance solver (thesis §5.4, eqs. 5.11–5.12) in place of
//! the tower's true geometry, on the same photographs (the campanile day's
//! four training times from its four views, rendered from the true scene)
//! under the same known sun and sky; each tower surface's pseudo-albedo
//! errors from both, and their ratio (the issue asks for within 1.5×).
//!
//! - **Scans.** The tower from the five poses of
//!   `tests/range_segmentation.rs` (`building_poses`), segmented with the
//!   derived parameters, every group meshed (`MeshOptions` defaults, but
//!   for `--outline-tolerance`).
//! - **Target surfaces.** Each group stands for the true surface most of
//!   its points lie on (`world::scanned_scene::majority_surfaces`); the
//!   groups standing for a tower surface (`TOWER`: four faces, pillars,
//!   roof) replace its true triangles and are the solver's targets under
//!   that surface's name. The ground and the landscape keep their true
//!   geometry (the scans see only the ground near the tower, and the solver
//!   needs the whole environment for the light it reflects).
//! - **Truth.** Both grids are scored the same way: a cell's truth is the
//!   world's albedo averaged over 64² points of the cell, each moved to the
//!   nearest point of the true scene (`projected_cell_truth`; on the true
//!   geometry, the point itself). Errors are |ρ / truth − 1| over the cells
//!   some photo saw (solved or filled) and the three channels, median and
//!   95th percentile.
//! - **Verdict.** `failed` (exit 3) when, on a tower surface seen in both
//!   runs, the median of ρ_se or ρ_sun from the scans is more than 1.5×
//!   that from the true geometry, or the whole tower's 95th percentile is
//!   (each error floored at 0.5 % first, so that a near-zero reference
//!   does not make noise look like a failure); else `poor` when a surface
//!   the true geometry's photographs see has no seen cell on the scans'
//!   geometry (the segmenter merged it into another); else `ok`. The seen
//!   area of the scans' geometry against the true one's is printed with it.
//!
//! `cargo run -p campanile-sim --example outdoor_from_scans [-- ROWS COLS]
//! [--textured] [--spp N] [--width PX] [--spacing M] [--outline-tolerance M]`
//! (scanner grid, default 90 × 180 as `tests/range_segmentation.rs`;
//! photographs 128 × 96 at 64 samples per pixel, the tower's materials
//! flattened to their mean albedo unless `--textured`, a 2 m grid, as
//! `tests/outdoor_error_budget.rs`; the planar outlines simplified within
//! 0.01 m, `MeshOptions`' default).
//! `CAMPANILE_TRUE_SURFACES=south-face` keeps those surfaces' true
//! triangles in place of their groups' meshes (the error budget: which
//! surface's geometry costs what).

use std::time::Instant;

use campanile_scan::mesh::MeshOptions;
use campanile_sim::world::tower_from_scans::{TowerError, TowerSetup, compare_tower};

/// The bound on the ratio of errors.
const BOUND: f64 = 1.5;

fn usage(message: String) -> ! {
    eprintln!(
        "{message}\nusage: outdoor_from_scans [ROWS COLS] [--textured] [--spp N] [--width PX] [--spacing M] [--outline-tolerance M]"
    );
    std::process::exit(2);
}

/// The value after `flag`, parsed, or `default`.
fn option<T: std::str::FromStr>(args: &[String], flag: &str, default: T) -> T {
    match args.iter().position(|a| a == flag) {
        None => default,
        Some(i) => args
            .get(i + 1)
            .and_then(|v| v.parse().ok())
            .unwrap_or_else(|| usage(format!("{flag}: expected a positive number after it"))),
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut positional = Vec::new();
    let mut k = 0;
    while k < args.len() {
        if args[k] == "--textured" {
            k += 1;
        } else if args[k].starts_with("--") {
            k += 2;
        } else {
            positional.push(&args[k]);
            k += 1;
        }
    }
    let grid_arg = |i: usize, d: usize| {
        positional.get(i).map_or(d, |a| {
            a.parse()
                .ok()
                .filter(|&v| v > 0)
                .unwrap_or_else(|| usage(format!("scanner grid: {a:?} is not a positive whole number")))
        })
    };
    let base = TowerSetup::default();
    let setup = TowerSetup {
        scan_grid: (grid_arg(0, base.scan_grid.0), grid_arg(1, base.scan_grid.1)),
        width: option(&args, "--width", base.width),
        samples_per_pixel: option(&args, "--spp", base.samples_per_pixel),
        textured: args.iter().any(|a| a == "--textured"),
        spacing_m: option(&args, "--spacing", base.spacing_m),
        mesh: MeshOptions {
            outline_tolerance_m: option(&args, "--outline-tolerance", base.mesh.outline_tolerance_m),
            ..base.mesh.clone()
        },
        keep_true: std::env::var("CAMPANILE_TRUE_SURFACES")
            .map(|v| v.split(',').map(|s| s.trim().to_string()).collect())
            .unwrap_or_default(),
    };
    if setup.samples_per_pixel == 0 || setup.width < 4 {
        usage(format!(
            "--spp {}, --width {}: expected at least 1 sample and 4 pixels",
            setup.samples_per_pixel, setup.width
        ));
    }
    let tolerance = setup.mesh.outline_tolerance_m;
    if !(setup.spacing_m.is_finite() && setup.spacing_m > 0.0 && tolerance.is_finite() && tolerance >= 0.0) {
        usage(format!(
            "--spacing {}, --outline-tolerance {}: expected a positive grid spacing and a tolerance of 0 or more, metres",
            setup.spacing_m, setup.mesh.outline_tolerance_m
        ));
    }
    let t = Instant::now();
    let run = compare_tower(&setup).unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(if matches!(e, TowerError::UnknownSurface { .. }) {
            2
        } else {
            1
        });
    });
    let m = &run.metrics;
    let (rows, cols) = setup.scan_grid;
    eprintln!(
        "scans {rows} × {cols}: {} points, {} groups, {:.2} % on the right surface, merged {:?}; all in {:.1} s",
        m.points,
        m.found_groups,
        100.0 * m.right_fraction,
        m.merged,
        t.elapsed().as_secs_f64()
    );
    for g in &run.groups {
        let mesh = &run.meshes[g.group as usize];
        let share = run.majority[g.group as usize].map_or(0.0, |m| m.share);
        eprintln!(
            "  {} ({} points, {:.1} % on it, {:?}, plane RMS {}) → {}: {} triangles, {:.0} m² (the true surface: {:.0} m²)",
            mesh.name,
            mesh.points,
            100.0 * share,
            mesh.method,
            mesh.plane_rms_m.map_or("—".into(), |r| format!("{:.1} mm", 1e3 * r)),
            run.surfaces[g.surface],
            g.triangles,
            mesh.mesh.area(),
            run.true_area_m2[g.surface]
        );
    }
    for name in &setup.keep_true {
        eprintln!("  {name}: its true triangles");
    }
    for (what, s) in [
        ("the true geometry", &run.on_truth),
        ("the scans' geometry", &run.on_scans),
    ] {
        let r = &s.reflectance;
        eprintln!(
            "{what}: {} cells, {} seen ({:.0} m²), {} solved",
            r.grid.cells.len(),
            r.grid.cells.len() - r.count(campanile_process::outdoor::CellStatus::Unseen),
            s.seen_area_m2,
            r.count(campanile_process::outdoor::CellStatus::Solved)
        );
    }

    println!(
        "| surface | true geometry: cells seen (area) | ρ_se median / p95 (%) | ρ_sun median / p95 (%) | scans' geometry: cells seen (area) | ρ_se median / p95 (%) | ρ_sun median / p95 (%) | ratio of medians ρ_se / ρ_sun | ratio of p95 ρ_se / ρ_sun |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for l in &run.lines {
        let (rm, rp) = l.ratios.map_or(("—".into(), "—".into()), |r| {
            (
                format!("{:.2}× / {:.2}×", r.se_median, r.sun_median),
                format!("{:.2}× / {:.2}×", r.se_p95, r.sun_p95),
            )
        });
        println!(
            "| {} | {} | {} | {rm} | {rp} |",
            l.name,
            l.on_truth.table_cells(),
            l.on_scans.table_cells()
        );
    }
    let (worst, absent) = (run.worst_ratio(), run.absent());
    let verdict = if worst > BOUND {
        "failed"
    } else if !absent.is_empty() {
        "poor"
    } else {
        "ok"
    };
    println!(
        "verdict: {verdict} (worst ratio {worst:.2}×, bound {BOUND}×, over every surface's medians and the whole tower's p95; seen on the true geometry but absent from the scans': {absent:?}; the scans' geometry has {:.0} % of the true geometry's seen area)",
        100.0 * run.coverage()
    );
    if verdict == "failed" {
        std::process::exit(3);
    }
}

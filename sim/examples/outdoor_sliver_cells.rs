//! What the outdoor solver's per-triangle cells cost (the error budget of
//! `outdoor_from_scans`): the grid of thesis §5.4 is laid "on each
//! triangle", so a lattice square that spans several triangles of a face
//! becomes several smaller cells, each seen by fewer pixels. This runs the
//! solver on the campanile day's true geometry twice, on the same
//! photographs: as modelled (two triangles a face), and with every tower
//! triangle cut into N slivers fanned from one corner (the same planes, no
//! geometric error), as an ear-clipped scan outline is; it prints each
//! face's pseudo-albedo errors (|ρ / truth − 1|, median / p95 over the seen
//! cells and channels) from both.
//!
//! `cargo run -p campanile-sim --example outdoor_sliver_cells [-- N]`
//! (default 8; photographs 128 × 96 at 64 samples per pixel, the tower
//! flattened to its mean albedo, a 2 m grid, as `outdoor_from_scans`).

use campanile_process::outdoor::{ReflectanceSettings, recover_reflectance};
use campanile_process::render::{Scene, Triangle};
use campanile_sim::world::campanile_day::{CampanileDay, TOWER, illuminations, training_times};
use campanile_sim::world::scanned_scene::{cell_errors, projected_cell_truth};
use campanile_sim::world::tower_from_scans::{TRUTH_PER_SIDE, TowerSetup};

fn fail(message: String) -> ! {
    eprintln!("{message}");
    std::process::exit(1);
}

fn main() {
    let n: usize = match std::env::args().nth(1) {
        None => 8,
        Some(a) => a.parse().ok().filter(|&n| n > 0).unwrap_or_else(|| {
            eprintln!("slivers per triangle: {a:?} is not a positive whole number");
            std::process::exit(2)
        }),
    };
    let setup = TowerSetup::default();
    let mut day = CampanileDay::load(setup.samples_per_pixel, 2).unwrap_or_else(|e| fail(e.to_string()));
    day.flatten_tower().unwrap_or_else(|e| fail(e.to_string()));
    let scene = day.world.scene.scene.clone();
    let targets = day.targets().unwrap_or_else(|e| fail(e.to_string()));
    let mut triangles = Vec::new();
    for t in scene.triangles() {
        if !targets.contains(&(t.surface as usize)) {
            triangles.push(t.clone());
            continue;
        }
        let [a, b, c] = t.vertices;
        for k in 0..n {
            let p = b + (c - b) * (k as f64 / n as f64);
            let q = b + (c - b) * ((k + 1) as f64 / n as f64);
            triangles.extend(Triangle::new([a, p, q], t.material, t.surface));
        }
    }
    let slivers = Scene::new(triangles, scene.materials().to_vec(), scene.surfaces().to_vec())
        .unwrap_or_else(|e| fail(e.to_string()));
    let times = training_times();
    let photos = day
        .photographs(&times, setup.width, setup.width * 3 / 4)
        .unwrap_or_else(|e| fail(e.to_string()));
    let days = day.daylights(&times).unwrap_or_else(|e| fail(e.to_string()));
    let settings = ReflectanceSettings {
        spacing_m: setup.spacing_m,
        ..ReflectanceSettings::default()
    };
    println!("| geometry | surface | cells seen (area) | ρ_se median / p95 (%) | ρ_sun median / p95 (%) |");
    println!("|---|---|---|---|---|");
    for (what, s) in [
        ("as modelled".to_string(), &scene),
        (format!("{n} slivers a triangle"), &slivers),
    ] {
        let (refl, _) = recover_reflectance(s, &targets, &photos, &illuminations(&days), &settings)
            .unwrap_or_else(|e| fail(format!("{what}: {e}")));
        let truth = projected_cell_truth(&day.world, &refl.grid, s, TRUTH_PER_SIDE);
        let mut sets: Vec<(&str, Vec<usize>)> = TOWER.iter().zip(&targets).map(|(n, &t)| (*n, vec![t])).collect();
        sets.push(("tower", targets.clone()));
        for (name, ids) in sets {
            let e = cell_errors(&refl, &truth, &ids);
            println!("| {what} | {name} | {} |", e.table_cells());
        }
    }
}

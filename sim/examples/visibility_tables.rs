//! Tables 3.2–3.3 on the example scenes: the hybrid visibility algorithm
//! (thesis §3.5) against repeated Weiler–Atherton, polygons produced and
//! time at three size thresholds, with each fragmentation's misclassified
//! fraction against brute-force ray casting.
//!
//! ```text
//! cargo run --release -p campanile-sim --example visibility_tables -- [WIDTH HEIGHT]
//! ```

use std::time::Instant;

use campanile_process::visibility::{
    Fragmentation, Model, PinholeView, VisibilityError, check, hybrid, misclassified, weiler_atherton,
};
use campanile_sim::world::scene_file::{examples_dir, load_scene};
use nalgebra::Vector3;

/// A visibility algorithm.
type Algorithm = fn(&Model, &[PinholeView], f64) -> Result<Fragmentation, VisibilityError>;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<usize> = std::env::args().skip(1).map(|a| a.parse()).collect::<Result<_, _>>()?;
    let (w, h) = match args[..] {
        [w, h] => (w, h),
        [] => (320, 240),
        _ => return Err("usage: visibility_tables [WIDTH HEIGHT]".into()),
    };
    for (file, thresholds, ring) in [
        (
            "campanile-scene.ron",
            [0.01, 0.1, 1.0],
            Some((70.0, Vector3::new(0.0, 0.0, 35.0))),
        ),
        ("room-scene.ron", [1e-4, 1e-3, 1e-2], None),
    ] {
        let scene = load_scene(&examples_dir().join(file))?;
        let mut views = scene.pinhole_views(60f64.to_radians(), w, h)?;
        // Model I of Table 3.1 had 24 views: add a ring around the tower.
        if let Some((radius, target)) = ring {
            for k in 0..8 {
                let a = std::f64::consts::TAU * (k as f64 + 0.5) / 8.0;
                let position = Vector3::new(radius * a.cos(), radius * a.sin(), 1.5);
                views.push(PinholeView::look_at(
                    &format!("ring-{k}"),
                    position,
                    target - position,
                    Vector3::z(),
                    60f64.to_radians(),
                    w,
                    h,
                )?);
            }
        }
        let model = Model::new(scene.scene.triangles().to_vec())?;
        println!(
            "\n{file}: {} triangles, {} views of {w}×{h} px",
            model.triangles.len(),
            views.len()
        );
        println!("| algorithm | threshold (m²) | polygons | clips | small mixed | time (s) | misclassified |");
        println!("|---|---|---|---|---|---|---|");
        for th in thresholds {
            let algorithms: [(&str, Algorithm); 2] = [("Hybrid", hybrid), ("WA", weiler_atherton)];
            for (name, run) in algorithms {
                let start = Instant::now();
                let f = run(&model, &views, th)?;
                let secs = start.elapsed().as_secs_f64();
                let m = check::total(&misclassified(&model, &f.fragments, &views));
                println!(
                    "| {name} | {th} | {} | {} | {} | {secs:.3} | {:.4}% ({} of {} points; {} in small mixed) |",
                    f.fragments.len(),
                    f.clips,
                    f.small_mixed,
                    100.0 * m.fraction(),
                    m.wrong,
                    m.points,
                    m.wrong_in_mixed
                );
            }
        }
    }
    Ok(())
}

//! Meshing speed against error (issue 28, thesis §2.4): prints one
//! `key=value` line per figure.
//!
//! 1. The box room with its cabinet scanned from its centre at a fine
//!    angular step (default 0.25°: about a million returns, σ 2 mm), meshed
//!    by [`reconstruct`] (planar polygons) with the truth: time, triangles,
//!    distances.
//! 2. A 6 × 4 m wall at 3 m scanned every 0.1° (σ 3 mm) with planarity
//!    off, so that it is meshed from scan-order neighbours and simplified:
//!    the simplification target swept (0 = none), with the triangles left,
//!    the time and the Hausdorff distance to the true wall.
//!
//! 3. A sphere of radius 0.5 m, N points (default 100 000, a Fibonacci
//!    lattice), as six unorganised scans without normals (each point in the
//!    scan of the axis scanner it faces most): ball pivoting with estimated
//!    normals, then the default simplification.
//!
//! Usage: `cargo run -p campanile-scan --example mesh_bench [STEP_DEG]`
//! (the dev profile: dependencies at opt-level 3, the crate at 1).

use std::time::Instant;

use campanile_scan::mesh::{MeshOptions, Reference, TriangleMesh, hausdorff, mesh_groups, one_sided};
use campanile_scan::obj_file::write_obj;
use campanile_scan::reconstruction::reconstruct;
use campanile_scan::synthetic_scan::{Rect, cabinet, room, scan_of, sphere_scans, truth};
use nalgebra::Vector3;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let step: f64 = std::env::args().nth(1).map_or(Ok(0.25), |s| s.parse())?;
    let dir = std::env::temp_dir().join("campanile-mesh-bench");
    std::fs::create_dir_all(&dir)?;

    let rects: Vec<Rect> = room().into_iter().chain(cabinet()).collect();
    let (scan, seg) = scan_of(&rects, Vector3::new(2.0, 1.5, 1.25), step, 87.0, 0.002);
    let truth_obj = dir.join("truth.obj");
    write_obj(&truth_obj, &truth(&rects), "truth")?;
    let options = MeshOptions {
        truth: Some(truth_obj),
        hausdorff_spacing_m: 0.05,
        ..MeshOptions::default()
    };
    let t = Instant::now();
    let report = reconstruct(std::slice::from_ref(&scan), &seg, &options, &dir.join("room"))?;
    println!("room_step_deg={step}");
    println!("room_points={}", scan.len());
    println!("room_seconds={:.3}", t.elapsed().as_secs_f64());
    println!("room_planar_groups={}", report.planar);
    println!("room_triangles={}", report.triangles_after);
    let worst = report
        .groups
        .iter()
        .filter_map(|g| g.hausdorff.map(|h| h.mesh_to_reference_m))
        .fold(0.0, f64::max);
    println!("room_mesh_to_truth_max_m={worst:.5}");
    println!("room_verdict={:?}", report.verdict);

    let wall = Rect {
        name: "wall".into(),
        axis: 0,
        at: 3.0,
        lo: [-3.0, -2.0],
        hi: [3.0, 2.0],
    };
    let (noisy, seg) = scan_of(std::slice::from_ref(&wall), Vector3::zeros(), 0.1, 30.0, 0.003);
    let (exact, _) = scan_of(std::slice::from_ref(&wall), Vector3::zeros(), 0.1, 30.0, 0.0);
    let plane = TriangleMesh {
        positions: vec![
            Vector3::new(3.0, -4.0, -3.0),
            Vector3::new(3.0, 4.0, -3.0),
            Vector3::new(3.0, 4.0, 3.0),
            Vector3::new(3.0, -4.0, 3.0),
        ],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
    };
    println!("wall_points={}", noisy.len());
    for target in [0.0, 0.002, 0.005, 0.01, 0.02] {
        let options = MeshOptions {
            planar_rms_m: 0.0,
            simplify_error_m: target,
            ..MeshOptions::default()
        };
        let t = Instant::now();
        let m = mesh_groups(std::slice::from_ref(&noisy), &seg, &options)?.remove(0);
        let seconds = t.elapsed().as_secs_f64();
        let away = one_sided(&m.mesh, Reference::Mesh(&plane), 0.01).map_or(f64::NAN, |d| d.max_m);
        let back =
            hausdorff(&m.mesh, Reference::Points(&exact.positions), 0.01).map_or(f64::NAN, |h| h.reference_to_mesh_m);
        println!(
            "wall_target_m={target} triangles_before={} triangles_after={} seconds={seconds:.3} hausdorff_m={:.5}",
            m.triangles_before,
            m.mesh.triangles.len(),
            away.max(back)
        );
    }

    let n = 100_000;
    let (scans, seg) = sphere_scans(n, 0.5, Vector3::zeros());
    let t = Instant::now();
    let m = mesh_groups(&scans, &seg, &MeshOptions::default())?.remove(0);
    let sag = (0..m.mesh.triangles.len())
        .map(|k| {
            let [a, b, c] = m.mesh.corners(k);
            0.5 - ((a + b + c) / 3.0).norm()
        })
        .fold(0.0, f64::max);
    println!(
        "sphere_points={n} method={:?} seconds={:.3} triangles_before={} triangles_after={} inside_max_m={sag:.5}",
        m.method,
        t.elapsed().as_secs_f64(),
        m.triangles_before,
        m.mesh.triangles.len()
    );
    Ok(())
}

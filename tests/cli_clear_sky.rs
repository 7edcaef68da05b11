//! `campanile process` on a simulated session with no sky scan and no sun
//! shot (what hand-taken brackets give): the quick campanile day without
//! its `SkyScan` and `SunShot` steps, captured as `campanile demo --quick`
//! captures (4 paths per pixel, 3 bounces). The light is estimated from the
//! CIE clear-sky model, the views' sky pixels and the photographs'
//! sunlit/shadowed ratio; quality.json says the light was estimated.
//!
//! The simulator renders with the model's own atmosphere
//! (`Atmosphere::clear()`), so the sun/sky ratio must come out ≈ 1 of the
//! model's, and the pseudo-albedos near the measured-light figures of
//! tests/demo.rs (ρ_se/ρ_sun medians 2.5 %/2.1 %).
//!
//! Issue 31: captured with `capture`'s default `--sim-bounces 1` (direct
//! light only: no light from the ground or the neighbours in the
//! photographs), the shaded walls were lit by the open sky alone, 41–54 %
//! of the irradiance the model (rightly) gathers there, and the ratio came
//! out 2.94 (morning) and 1.79 (afternoon), the pseudo-albedos 70 % (ρ_se)
//! and 60 % (ρ_sun) off.

mod common;

/// Bounds on the median relative errors of ρ_se and ρ_sun (green) under the estimated light.
/// Measured here: 5.3 % and 4.4 % (1496 cells); before the fix 70.5 % and 60.0 %.
const BOUND_SE: f64 = 0.06;
const BOUND_SUN: f64 = 0.05;

use std::path::Path;

use campanile_process::outdoor::CellStatus;
use campanile_process::outdoor::atlas::read_materials;
use campanile_sim::world::load_scene;
use common::campanile;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn a_session_without_sky_frames_gets_pseudo_albedos_under_estimated_light() {
    let tmp = tempfile::tempdir().unwrap();
    let scene = root().join("examples/campanile-scene.ron");
    let plan_text = std::fs::read_to_string(root().join("examples/campanile-quick.ron"))
        .unwrap()
        .lines()
        .filter(|l| !l.contains("SkyScan(") && !l.contains("SunShot("))
        .collect::<Vec<_>>()
        .join("\n")
        .replace(
            "Some(\"campanile-scene.ron\")",
            &format!("Some({:?})", scene.display().to_string()),
        );
    assert!(!plan_text.contains("SkyScan") && !plan_text.contains("SunShot"));
    let plan = tmp.path().join("plan.ron");
    std::fs::write(&plan, plan_text).unwrap();
    let session = tmp.path().join("session");
    let station = root().join("examples/sim-station.ron");
    let s = |p: &Path| p.to_str().unwrap().to_owned();
    let out = campanile(&[
        "-q",
        "capture",
        &s(&plan),
        "--station",
        &s(&station),
        "--out",
        &s(&session),
        // As `campanile demo --quick` captures: the ground's and the
        // neighbours' light on the shaded walls needs the second and third
        // bounces (the default, one, is direct light only).
        "--sim-samples",
        "4",
        "--sim-bounces",
        "3",
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));

    // Before: "the light of morning@…: no sky was fitted", exit 1.
    let processed = tmp.path().join("processed");
    let out = campanile(&["process", &s(&session), "--out", &s(&processed)]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    println!("{stdout}");
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));

    let quality: serde_json::Value =
        serde_json::from_slice(&std::fs::read(processed.join("quality.json")).unwrap()).unwrap();
    let albedo = quality["products"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["product"] == "pseudo-albedos")
        .expect("a pseudo-albedo verdict");
    // Not `failed`: the estimate is near the truth; `ok` or `poor` by its
    // stated uncertainty against the 2 % gate (1.9 % here).
    assert_ne!(albedo["verdict"], "failed", "{albedo:#}");
    let check = &albedo["checks"][0];
    assert!(
        check["figure"].as_str().unwrap().contains("estimated light"),
        "{check:#}"
    );
    let notes: Vec<&str> = albedo["notes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n.as_str().unwrap())
        .collect();
    for occ in ["morning@2026-08-28", "afternoon@2026-08-28"] {
        let note = notes
            .iter()
            .find(|n| n.starts_with(&format!("light of {occ} estimated:")))
            .unwrap_or_else(|| panic!("no note for {occ}: {notes:#?}"));
        assert!(
            note.contains("CIE clear-sky model (type 12)")
                && note.contains("sunlit/shadowed pairs")
                && note.contains("sky pixels")
                && note.contains("not measured"),
            "{note}"
        );
        // "… pairs (K within a cell): X ± S of the model's (green)"
        let x: f64 = note
            .split("within a cell): ")
            .nth(1)
            .and_then(|t| t.split(' ').next())
            .and_then(|t| t.parse().ok())
            .unwrap_or_else(|| panic!("no sun/sky ratio in {note}"));
        println!("{occ}: sun/sky ratio {x:.3} of the model's");
        // The truth is the model's own atmosphere: x = 1 (measured 0.994
        // morning, 1.039 afternoon; before the fix 2.94 and 1.79).
        assert!(
            (x - 1.0).abs() < 0.06,
            "{occ}: sun/sky ratio {x}, expected 1 ± 0.06: {note}"
        );
    }

    // The pseudo-albedos against the simulator's truth (green, averaged
    // over 64 × 64 points per cell, as the demo measures them).
    let loaded = load_scene(&scene).unwrap();
    let refl = read_materials(&loaded.scene, &processed.join("albedo/materials.ron")).unwrap();
    let (mut se, mut sun) = (Vec::new(), Vec::new());
    for (k, cell) in refl.grid.cells.iter().enumerate() {
        if refl.cells[k].status == CellStatus::Unseen {
            continue;
        }
        let pts = refl.grid.cell_points(&loaded.scene, k, 64);
        if pts.is_empty() {
            continue;
        }
        let t = pts
            .iter()
            .map(|p| loaded.scene.albedo_at(cell.triangle, p)[1])
            .sum::<f64>()
            / pts.len() as f64;
        se.push((refl.cells[k].rho_se[1] / t - 1.0).abs());
        sun.push((refl.cells[k].rho_sun[1] / t - 1.0).abs());
    }
    let q = |v: &mut Vec<f64>, p: f64| {
        v.sort_by(f64::total_cmp);
        v[((v.len() - 1) as f64 * p).round() as usize]
    };
    let (se50, se95, sun50, sun95) = (q(&mut se, 0.5), q(&mut se, 0.95), q(&mut sun, 0.5), q(&mut sun, 0.95));
    println!(
        "pseudo-albedos under estimated light, {} cells: rho_se median {:.1}% p95 {:.1}%, rho_sun median {:.1}% p95 {:.1}%",
        se.len(),
        100.0 * se50,
        100.0 * se95,
        100.0 * sun50,
        100.0 * sun95
    );
    // Compared over the cells the training photographs saw (756 measured;
    // before the atlas recorded its unseen cells, the filled ones were
    // read back as estimates and counted too, over 1000).
    assert!(se.len() > 700, "{} cells", se.len());
    // Measured light (tests/demo.rs): medians 2.5 % / 2.1 %.
    assert!(
        se50 < BOUND_SE && sun50 < BOUND_SUN,
        "rho_se median {se50}, rho_sun median {sun50}"
    );
}

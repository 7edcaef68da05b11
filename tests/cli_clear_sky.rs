//! `campanile process` on a simulated session with no sky scan and no sun
//! shot (what hand-taken brackets give): the quick campanile day without
//! its `SkyScan` and `SunShot` steps. The light is estimated from the CIE
//! clear-sky model, the views' sky pixels and the photographs'
//! sunlit/shadowed ratio; the pseudo-albedos come out, `poor` with the
//! reason, and quality.json says the light was estimated. Their errors
//! against the simulator's truth are printed: measured ρ_se median 70.5%
//! (p95 100%), ρ_sun 60.0% (p95 100%) on 1496 cells. That is NOT a pass:
//! the pairs' sun/sky ratio comes out 1.8–2.9 times the model's on the
//! campanile although the simulator renders with the model's own
//! atmosphere (on the small site of process/tests/estimated_light.rs it is
//! within 4%); the cause is not found yet, so no bound is asserted on them.

mod common;

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
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));

    // Before: "the light of morning@…: no sky was fitted", exit 1.
    let processed = tmp.path().join("processed");
    let out = campanile(&["process", &s(&session), "--out", &s(&processed)]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    println!("{stdout}");
    // `poor` (exit 0): the light's stated uncertainty is above the 2% gate.
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(stdout.contains("poor: pseudo-albedos"), "{stdout}");

    let quality: serde_json::Value =
        serde_json::from_slice(&std::fs::read(processed.join("quality.json")).unwrap()).unwrap();
    let albedo = quality["products"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["product"] == "pseudo-albedos")
        .expect("a pseudo-albedo verdict");
    assert_eq!(albedo["verdict"], "poor", "{albedo:#}");
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
    assert!(!se.is_empty());
}

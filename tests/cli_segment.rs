//! `campanile segment` and `campanile edit` (issue 28, thesis ch. 2) on
//! the simulated range scanner's room: five scans written as PLY files, as a
//! scanner's software would, read, segmented, meshed and written as a scene
//! that `campanile config check` accepts; then an object copied and moved.

mod common;

use campanile_scan::obj_file::read_obj;
use campanile_sim::world::range_scanner::{
    ScanFileFormat, ScannerSettings, room_poses, room_scene, scan_scene, write_scans,
};
use common::campanile_exits;

#[test]
fn simulated_room_scans_become_a_scene_that_can_be_edited() {
    let dir = tempfile::tempdir().unwrap();
    let scans = scan_scene(&room_scene().unwrap(), &room_poses(), &ScannerSettings::new(90, 180)).unwrap();
    let files = write_scans(&dir.path().join("scans"), "room", &scans, ScanFileFormat::Ply).unwrap();
    let out = dir.path().join("scene");
    let mut args: Vec<&str> = vec!["segment"];
    args.extend(files.iter().map(|f| f.to_str().unwrap()));
    args.extend(["--out", out.to_str().unwrap()]);
    let text = campanile_exits(&args, 0);
    eprintln!("{text}");
    for f in [
        "scene.obj",
        "scene.ron",
        "segmentation.ply",
        "segment-report.json",
        "mesh-report.json",
        "report.html",
        "groups-0.png",
    ] {
        assert!(out.join(f).is_file(), "{f} missing:\n{text}");
    }
    // The room's six planes (floor, ceiling, four walls: 3 × 4 × 2.5 m
    // and so on) are the six largest groups, each a planar polygon.
    let meshes = read_obj(&out.join("scene.obj")).unwrap();
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("mesh-report.json")).unwrap()).unwrap();
    let groups = report["groups"].as_array().unwrap();
    assert!(groups.len() >= 6, "{text}");
    for g in &groups[..6] {
        assert_eq!(g["method"], "PlanarPolygon", "{g}");
        assert!(g["area_m2"].as_f64().unwrap() > 5.0, "{g}");
    }
    // The two posters, 1 cm proud of the north wall, are layers of it, and
    // the three spheres on the table are objects; the page lists them.
    let segment: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("segment-report.json")).unwrap()).unwrap();
    let layers = segment["layers"].as_array().unwrap();
    assert_eq!(layers.len(), 2, "{segment}");
    for l in layers {
        assert!((l["offset_m"].as_f64().unwrap() - 0.01).abs() < 0.002, "{l}");
    }
    assert_eq!(segment["objects"].as_array().unwrap().len(), 3, "{segment}");
    let page = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(page.contains("<h2>Layers and objects</h2>") && page.contains("layer of surface_"));
    let check = campanile_exits(&["config", "check", out.join("scene.ron").to_str().unwrap()], 0);
    assert!(check.contains("surface_0"), "{check}");

    // Copy the largest group as an object, 0.5 m east; every corner moves by exactly that.
    let edit = dir.path().join("edit.ron");
    std::fs::write(
        &edit,
        r#"SceneEdit(
            objects: [Object(name: "big", members: ["surface_0"])],
            operations: [Copy(object: "big", name: "big_2", offset_m: (0.5, 0.0, 0.0))],
        )"#,
    )
    .unwrap();
    let edited = dir.path().join("edited");
    let text = campanile_exits(
        &[
            "edit",
            out.join("scene.ron").to_str().unwrap(),
            edit.to_str().unwrap(),
            "--out",
            edited.to_str().unwrap(),
        ],
        0,
    );
    assert!(text.contains("big_2"), "{text}");
    let after = read_obj(&edited.join("scene.obj")).unwrap();
    let original = meshes.iter().find(|m| m.group == "surface_0").unwrap();
    let copy = after
        .iter()
        .find(|m| m.group.starts_with("surface_0") && m.group != "surface_0")
        .unwrap();
    assert_eq!(original.mesh.positions.len(), copy.mesh.positions.len());
    for (a, b) in original.mesh.positions.iter().zip(&copy.mesh.positions) {
        assert!(
            (b - a - nalgebra::Vector3::new(0.5, 0.0, 0.0)).norm() < 2e-6, // OBJ text (6 decimals) read back as f32
            "{a} → {b}"
        );
    }
    campanile_exits(&["config", "check", edited.join("scene.ron").to_str().unwrap()], 0);

    // Bad input: an object that does not exist, a file that is not a scan.
    std::fs::write(
        &edit,
        r#"SceneEdit(objects: [], operations: [Delete(object: "piano")])"#,
    )
    .unwrap();
    let text = campanile_exits(
        &[
            "edit",
            out.join("scene.ron").to_str().unwrap(),
            edit.to_str().unwrap(),
            "--out",
            edited.to_str().unwrap(),
        ],
        2,
    );
    assert!(text.contains("piano"), "{text}");
    let text = campanile_exits(&["segment", edit.to_str().unwrap(), "--out", out.to_str().unwrap()], 2);
    assert!(text.contains("edit.ron"), "{text}");
}

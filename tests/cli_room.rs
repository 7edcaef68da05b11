//! `campanile process` on a room session too thin to triangulate its lamp:
//! the session is captured on the simulated station (one lamp, one wide
//! pose, a calibration bracket, one view up at the bulb) and processing
//! stops with a diagnostic that names the lamp, the views that held its
//! bulb and what is needed, after writing the response and the rectified
//! views. (The full path, from capture to relit room, is `tests/demo.rs`.)

mod common;

use common::campanile;

#[test]
fn a_lamp_seen_in_one_view_is_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let examples = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples");
    let plan = dir.path().join("thin-room.ron");
    std::fs::write(
        &plan,
        format!(
            r#"Plan(
    name: "one lamp, one view of its bulb",
    start_date: "2026-08-29",
    scene: Some("{}"),
    sessions: [(
        name: "room",
        trigger: Clock(time: "05:00:00"),
        steps: [
            LightSequence(lights: ["lamp-1"], all_on: true, poses: ["wide-sw"]),
            Bracket(aim: Pose("wide-sw"),
                    exposures_s: [0.001, 0.002, 0.004, 0.008, 0.016, 0.032, 0.064, 0.128, 0.256, 0.512, 1.024, 2.048]),
            AutoBracket(aim: Pose("bulb-1-sw"), max_frames: 9),
        ],
    )],
)
"#,
            examples.join("room-igi-scene.ron").display()
        ),
    )
    .unwrap();
    let session = dir.path().join("session");
    let o = campanile(&[
        "-q",
        "capture",
        plan.to_str().unwrap(),
        "--station",
        "examples/sim-station.ron",
        "--out",
        session.to_str().unwrap(),
        "--sim-samples",
        "1",
        "--sim-bounces",
        "1",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = dir.path().join("processed");
    let o = campanile(&[
        "-q",
        "process",
        session.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains(
            "lamp \"lamp-1\": its bulb is seen unclipped in 1 view(s) (bulb-1-sw), at least 2 are needed to triangulate it"
        ),
        "{stderr}"
    );
    // Only lamp-1 was switched: the others are not asked for.
    assert!(!stderr.contains("lamp-2"), "{stderr}");
    // What could be done was written: the response and the rectified views
    // (the wide view with its mask), none of it lost to the refusal.
    assert!(out.join("response.csv").is_file());
    for f in ["wide-sw.exr", "wide-sw-mask.png", "bulb-1-sw.exr"] {
        assert!(out.join("room/images").join(f).is_file(), "{f}");
    }
    let img = campanile_process::exr_io::read_rgb_exr(&out.join("room/images/wide-sw.exr")).unwrap();
    let (w, h, rgb) = (img.width, img.height, img.data);
    // Half the 256×192 frame (the default --room-scale), lit by lamp 1.
    assert_eq!((w, h), (128, 96));
    let lit = rgb.iter().filter(|v| **v > 0.0).count();
    assert!(lit > w * h * 3 / 2, "{lit} of {} channel values lit", w * h * 3);
}

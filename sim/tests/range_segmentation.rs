//! Thesis §2.3 on the simulated range scanner (issue 28): the example room
//! and the tower, scanned from five poses each (range noise, intensity
//! noise, dropouts, mixed pixels at depth edges), segmented by normalized
//! cuts with the parameters derived from the scans, and compared with every
//! point's true surface (`scan::segment::metrics`).

use campanile_scan::segment::metrics::compare;
use campanile_scan::segment::params::Overrides;
use campanile_scan::segment::segment;
use campanile_scan::segment::{SegmentReport, Verdict};
use campanile_sim::world::range_scanner::{
    ScannerSettings, building_poses, building_scene, room_poses, room_scene, scan_scene,
};

fn run(
    name: &str,
    scene: &campanile_process::render::Scene,
    poses: &[(String, campanile_scan::cloud::ScannerPose)],
) -> (campanile_scan::segment::metrics::Metrics, SegmentReport) {
    let scans = scan_scene(scene, poses, &ScannerSettings::new(90, 180)).unwrap();
    let (found, report) = segment(&scans.scans, &Overrides::default(), &|_| {}).unwrap();
    let m = compare(&scans.scans, &found, &scans.truth).unwrap();
    eprintln!(
        "{name}: {} points, {} groups ({} true surfaces), {:.2} % on the right surface, merged {:?}, split {:?}, true boundary found within 2 cm {:?}, found boundary within 2 cm of a true one {:?}, boundary mean {:?} m, median {:?} m, layers {:?}, objects {:?}, verdict {:?} ({})",
        m.points,
        m.found_groups,
        m.true_surfaces,
        100.0 * m.right_fraction,
        m.merged,
        m.split,
        m.true_boundary_found,
        m.boundary_within,
        m.boundary_mean_m,
        m.boundary_median_m,
        report.layers,
        report.objects,
        report.verdict,
        report.verdict_reason
    );
    (m, report)
}

/// Measured 99.22 % on the right surface (issue 28's goal: 98 %; 95.89 %
/// before the layers and objects passes, 92.68 % before the intensities
/// were divided by the incidence cosine), and 92.3 % of the points next to
/// a true boundary within 2 cm of a found one. The planes, the table, both
/// boards, both posters (1 cm proud of the wall, found as layers by
/// `scan::segment::relief`) and the three spheres (made groups from their
/// unassigned points by `scan::segment::objects`) are found; 33 of the
/// diffuse sphere's 131 points went to the table it stands on.
#[test]
fn the_simulated_room_segments_into_its_planes() {
    let (m, report) = run("room", &room_scene().unwrap(), &room_poses());
    assert!(m.right_fraction >= 0.985, "{:.4}", m.right_fraction);
    assert!(m.true_boundary_found.unwrap() >= 0.9, "{:?}", m.true_boundary_found);
    assert_eq!(report.verdict, Verdict::Ok);
    assert_eq!(report.layers.len(), 2, "{:?}", report.layers);
    for layer in &report.layers {
        assert!((layer.offset_m - 0.01).abs() < 0.002, "{layer:?}");
    }
    for surface in [
        "floor",
        "ceiling",
        "table",
        "board-1",
        "board-2",
        "posters",
        "sphere-plastic",
        "sphere-metal",
    ] {
        assert!(
            !m.merged.iter().any(|s| s == surface),
            "{surface} merged: {:?}",
            m.merged
        );
    }
    let corrected = report
        .parameters
        .iter()
        .find(|c| c.name == "correct_incidence")
        .unwrap();
    assert_eq!(corrected.value, 1.0, "{}", corrected.reason);
}

/// The tower from five poses on the ground, 30–40 m off: 99.04 % on the
/// right surface, every face its own group. Before clusters grew with the
/// points' spacing (`scan::segment::graph::scale_level`), the faces, a
/// metre between points against a few centimetres on the ground nearby,
/// fell apart into single points: 87.3 %, 12.8 % unassigned, failed. The
/// verdict follows what is left unassigned.
#[test]
fn the_simulated_tower_is_judged_by_what_it_leaves_unassigned() {
    let (m, report) = run("tower", &building_scene().unwrap(), &building_poses());
    assert!(m.right_fraction >= 0.985, "{:.4}", m.right_fraction);
    for face in ["south-face", "east-face", "north-face", "west-face"] {
        assert!(!m.merged.iter().any(|s| s == face), "{face} merged: {:?}", m.merged);
    }
    let unassigned = report.unassigned as f64 / report.points as f64;
    let expected = if unassigned > 0.10 {
        Verdict::Failed
    } else if unassigned > 0.02 {
        Verdict::Poor
    } else {
        Verdict::Ok
    };
    assert_eq!(report.verdict, expected, "{unassigned}: {}", report.verdict_reason);
}

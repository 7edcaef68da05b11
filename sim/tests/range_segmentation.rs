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
        "{name}: {} points, {} groups ({} true surfaces), {:.2} % on the right surface, merged {:?}, split {:?}, boundary mean {:?} m, median {:?} m, verdict {:?} ({})",
        m.points,
        m.found_groups,
        m.true_surfaces,
        100.0 * m.right_fraction,
        m.merged,
        m.split,
        m.boundary_mean_m,
        m.boundary_median_m,
        report.verdict,
        report.verdict_reason
    );
    (m, report)
}

/// Measured 92.68 % on the right surface (issue 28's goal: 98 %, not met).
/// The six planes are found; the posters and boards, coplanar with the
/// walls and differing only in reflectance, and the three spheres merge
/// into larger groups (the intensity pass does not split them: the
/// intensity's cos-incidence falloff across a wall sets σ_w high).
#[test]
fn the_simulated_room_segments_into_its_planes() {
    let (m, report) = run("room", &room_scene().unwrap(), &room_poses());
    assert!(m.right_fraction >= 0.92, "{:.4}", m.right_fraction);
    assert_eq!(report.verdict, Verdict::Ok);
    for plane in ["floor", "ceiling"] {
        assert!(!m.merged.iter().any(|s| s == plane), "{plane} merged: {:?}", m.merged);
    }
}

/// The tower from five poses on the ground: 87.3 % on the right surface,
/// but 12.8 % of the points (the far, sparse ground) in no group, which the
/// verdict must say rather than hand the scene on as ok.
#[test]
fn the_simulated_tower_is_judged_by_what_it_leaves_unassigned() {
    let (m, report) = run("tower", &building_scene().unwrap(), &building_poses());
    assert!(m.right_fraction >= 0.87, "{:.4}", m.right_fraction);
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

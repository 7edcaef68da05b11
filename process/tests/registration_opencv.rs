//! `process::registration` against OpenCV's solvePnP on the same
//! correspondences (validation/registration: cases of OpenCV's own
//! projection with the same k1/k2 lens, seeded pixel noise, no outliers).
//! Both minimize the same reprojection error, so the poses must agree far
//! inside the goals (5 mm at 10 m, 0.05°): to 0.05 mm and 0.0005°.

use campanile_process::pose::Pinhole;
use campanile_process::registration::{CameraPose, Correspondence, RegistrationSettings, Verdict, register};
use nalgebra::{Matrix3, Rotation3, Vector3};
use serde::Deserialize;

#[derive(Deserialize)]
struct Point {
    target: u32,
    pixel: [f64; 2],
    world: [f64; 3],
}

#[derive(Deserialize)]
struct Case {
    name: String,
    focal_px: f64,
    principal_px: [f64; 2],
    k1: f64,
    k2: f64,
    points: Vec<Point>,
    true_centre_m: [f64; 3],
    opencv_centre_m: [f64; 3],
    opencv_rotation: [[f64; 3]; 3],
    opencv_rms_px: f64,
}

#[derive(Deserialize)]
struct Fixture {
    cases: Vec<Case>,
}

#[test]
fn poses_agree_with_opencv_solvepnp_on_the_same_correspondences() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../validation/registration/fixtures/pnp-cases.json"
    );
    let fixture: Fixture = serde_json::from_str(&std::fs::read_to_string(path).expect("fixture")).expect("json");
    assert_eq!(fixture.cases.len(), 3);
    for case in &fixture.cases {
        let pinhole = Pinhole {
            focal_px: case.focal_px,
            principal_px: (case.principal_px[0], case.principal_px[1]),
            k1: case.k1,
            k2: case.k2,
            projection: campanile_config::camera::Projection::Pinhole,
        };
        let points: Vec<Correspondence> = case
            .points
            .iter()
            .map(|p| Correspondence {
                target: p.target,
                pixel: (p.pixel[0], p.pixel[1]),
                world: p.world,
            })
            .collect();
        let r = register(&pinhole, &points, &RegistrationSettings::default());
        let pose = r
            .pose
            .unwrap_or_else(|| panic!("{}: {:?}", case.name, r.quality.reasons));
        let cv = CameraPose {
            rotation: Rotation3::from_matrix_unchecked(Matrix3::from_fn(|i, j| case.opencv_rotation[i][j])),
            centre: Vector3::from(case.opencv_centre_m),
        };
        let dc = (pose.centre - cv.centre).norm();
        let da = pose.angle_to_deg(&cv);
        let truth = (pose.centre - Vector3::from(case.true_centre_m)).norm();
        eprintln!(
            "{}: {} — {:.4} mm and {:.6}° from OpenCV; {:.2} mm from the truth; rms {:.4} px (OpenCV {:.4})",
            case.name,
            r.quality.verdict,
            dc * 1e3,
            da,
            truth * 1e3,
            r.quality.rms_px.unwrap_or(f64::NAN),
            case.opencv_rms_px
        );
        assert!(dc < 5e-5, "{}: centre {dc} m from OpenCV's", case.name);
        assert!(da < 5e-4, "{}: {da}° from OpenCV's", case.name);
        assert!(r.quality.rejected_targets.is_empty(), "{}", case.name);
        assert_ne!(r.quality.verdict, Verdict::Failed);
    }
}

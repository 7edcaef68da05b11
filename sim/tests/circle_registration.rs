//! Camera pose from the thesis's own targets on the simulator (§3.3.1–
//! §3.3.4, issue 27): dark plates with a white circle and no identity,
//! hung on the example building and room, photographed through the path
//! tracer with the sensor's noise and a lens blur, found by the template
//! sweep and the ellipse fit, paired with the survey by search, and
//! registered. Each photo also holds a false target (a plate with a white
//! circle that the survey does not list).
//!
//! Against the thesis (62 photos with 4 or more targets): 90% of the
//! visible targets found, 4 false matches, 58 of 62 poses right. Goals
//! here: at least 90% found, no false match, every pose from at least 4
//! targets within 5 mm at 10 m and 0.05°; hard cases a right pose or a
//! clear verdict, never a silent wrong pose.

use campanile_config::targets::Target;
use campanile_process::pose::Pinhole;
use campanile_process::registration::circle_detect::{CircleDetection, CircleDetectorSettings, detect_circles};
use campanile_process::registration::circle_search::{
    CircleRegistration, CircleSearchSettings, SurveyedCircle, register_circles,
};
use campanile_process::registration::{CameraPose, RegistrationSettings, Verdict};
use campanile_sim::world::target_photos::{
    PhotoSettings, TargetPhoto, photograph, pose_looking, with_circle_targets, with_round_window, with_targets,
};
use campanile_sim::world::{World, examples_dir, load_scene};
use chrono::{DateTime, Utc};
use nalgebra::Vector3;

fn station() -> campanile_config::Station {
    campanile_config::load_station(&examples_dir().join("sim-station.ron"))
        .expect("the example station")
        .value
}

/// The survey and the circles' radius.
fn survey(file: &str) -> (Vec<Target>, f64) {
    let t = campanile_config::load_targets(&examples_dir().join(file))
        .expect("the example survey")
        .value;
    let r = t.kind.circle_radius_m().expect("circle targets");
    (t.targets, r)
}

fn circles(targets: &[Target], radius_m: f64) -> Vec<SurveyedCircle> {
    targets
        .iter()
        .map(|t| SurveyedCircle {
            id: t.id,
            centre: Vector3::new(t.centre_m.0, t.centre_m.1, t.centre_m.2),
            normal: Vector3::new(t.normal.0, t.normal.1, t.normal.2).normalize(),
            radius_m,
        })
        .collect()
}

/// Photos' size, 1600 × 1200 as for the coded targets, rendered with 1
/// path a pixel rather than 2 to keep the tests within CI's time. At
/// 1200 × 900 the poses are as right (1–4.5 mm at 10–16 m) but some
/// photos' σ passes the verdict's limit (poor).
const WIDTH: usize = 1600;
/// See [`WIDTH`].
const HEIGHT: usize = 1200;

/// The station camera (60° across, k1 −0.05, k2 0.01) at [`WIDTH`] × [`HEIGHT`].
fn lens() -> Pinhole {
    let s = station();
    let c = &s.camera;
    Pinhole::of_camera(c).rescaled(
        (c.resolution.width as usize, c.resolution.height as usize),
        WIDTH,
        HEIGHT,
    )
}

fn noon() -> DateTime<Utc> {
    "2026-06-21T19:30:00Z".parse().expect("a time")
}

fn world(scene: &str, hung: &[Target], radius_m: f64, tags: &[Target]) -> World {
    world_with_windows(scene, hung, radius_m, tags, &[])
}

/// [`world`] with round white windows (radius [`WINDOW_RADIUS_M`], in a
/// square of brick) at `windows`.
fn world_with_windows(scene: &str, hung: &[Target], radius_m: f64, tags: &[Target], windows: &[Target]) -> World {
    let loaded = load_scene(&examples_dir().join(scene)).expect("the example scene");
    let mut with = with_circle_targets(&loaded, hung, radius_m).expect("targets hung");
    for window in windows {
        with = with_round_window(&with, window, WINDOW_RADIUS_M, BRICK).expect("window");
    }
    let with = with_targets(&with, tags).expect("boards hung");
    let mut w = World::new(&station(), with);
    w.quality.samples_per_pixel = 1;
    w.quality.max_bounces = 1;
    w
}

fn settings(seed: u64) -> PhotoSettings {
    PhotoSettings {
        pinhole: lens(),
        width: WIDTH,
        height: HEIGHT,
        time: noon(),
        light_levels: [1.0, 1.0, 1.0, 0.0],
        blur_px: 0.7,
        exposure_scale: 1.0,
        seed,
    }
}

/// A handheld pose: at `centre`, looking at `at`, rolled `roll_deg`.
fn held(centre: [f64; 3], at: [f64; 3], roll_deg: f64) -> CameraPose {
    let look = [0, 1, 2].map(|i| at[i] - centre[i]);
    let level = pose_looking(centre, look, [0.0, 0.0, 1.0]).expect("a pose");
    let m = level.rotation.matrix();
    let (right, down, forward) = (m.row(0).transpose(), m.row(1).transpose(), m.row(2).transpose());
    let r = roll_deg.to_radians();
    let right2 = right * r.cos() + down * r.sin();
    CameraPose::from_axes(right2, forward.cross(&right2), forward, level.centre)
}

/// What one photo gave, against its truth.
struct Outcome {
    registration: CircleRegistration,
    detections: Vec<CircleDetection>,
    /// Surveyed targets visible in the photo (facing, in frame, centre unoccluded).
    visible: Vec<u32>,
    /// Those a detection lies on (within 1.5 px of the true image of the centre).
    found: Vec<u32>,
    /// Detections on no hung target at all.
    spurious: usize,
    /// Matches whose detection is not on the target it was matched to.
    false_matches: usize,
    position_error_m: f64,
    angle_error_deg: f64,
    distance_m: f64,
}

/// Most degrees off its normal that a target is counted visible from.
/// The detector finds every target seen up to 77° off (its image's axes
/// in a ratio of 0.22 or more) and none beyond 77.7° in these views: at
/// 78–88° the white circle is a sliver 0.4–2 px wide.
const MAX_VIEW_DEG: f64 = 75.0;

/// The true image of each hung target's circle centre that the camera
/// sees: facing it within [`MAX_VIEW_DEG`], in frame, centre unoccluded.
fn visible_targets(w: &World, photo: &TargetPhoto, hung: &[Target]) -> Vec<(u32, (f64, f64))> {
    hung.iter()
        .filter_map(|t| {
            let c = Vector3::new(t.centre_m.0, t.centre_m.1, t.centre_m.2);
            let n = Vector3::new(t.normal.0, t.normal.1, t.normal.2).normalize();
            let to_camera = photo.pose.centre - c;
            if n.dot(&to_camera) <= to_camera.norm() * MAX_VIEW_DEG.to_radians().cos()
                || !w.scene.scene.segment_clear(&photo.pose.centre, &c)
            {
                return None;
            }
            let (u, v) = photo.pose.project(&lens(), &c)?;
            let margin = 20.0;
            ((margin..photo.width as f64 - margin).contains(&u) && (margin..photo.height as f64 - margin).contains(&v))
                .then_some((t.id, (u, v)))
        })
        .collect()
}

fn register_photo(w: &World, photo: &TargetPhoto, surveyed: &[Target], radius_m: f64, hung: &[Target]) -> Outcome {
    if let Ok(dir) = std::env::var("CAMPANILE_DEBUG_PHOTOS") {
        let n = std::fs::read_dir(&dir).map(|d| d.count()).unwrap_or(0);
        let _ = image::save_buffer(
            format!("{dir}/circles-{n}.png"),
            &photo.gray(),
            photo.width as u32,
            photo.height as u32,
            image::ExtendedColorType::L8,
        );
    }
    let detections = detect_circles(
        &photo.gray(),
        photo.width,
        photo.height,
        &CircleDetectorSettings::default(),
    );
    let registration = register_circles(
        &lens(),
        &detections,
        &circles(surveyed, radius_m),
        &RegistrationSettings::default(),
        &CircleSearchSettings::default(),
    );
    let truth_images = visible_targets(w, photo, hung);
    let surveyed_ids: Vec<u32> = surveyed.iter().map(|t| t.id).collect();
    let on = |d: &CircleDetection, p: (f64, f64)| (d.ellipse.centre.0 - p.0).hypot(d.ellipse.centre.1 - p.1) < 1.5;
    let visible: Vec<u32> = truth_images
        .iter()
        .filter(|(id, _)| surveyed_ids.contains(id))
        .map(|(id, _)| *id)
        .collect();
    let found: Vec<u32> = truth_images
        .iter()
        .filter(|(id, p)| surveyed_ids.contains(id) && detections.iter().any(|d| on(d, *p)))
        .map(|(id, _)| *id)
        .collect();
    // A detection on no hung target: project every hung target (seen or not).
    let spurious = detections
        .iter()
        .filter(|d| {
            !hung.iter().any(|t| {
                photo
                    .pose
                    .project(&lens(), &Vector3::new(t.centre_m.0, t.centre_m.1, t.centre_m.2))
                    .is_some_and(|p| on(d, p))
            })
        })
        .count();
    let false_matches = registration
        .matches
        .iter()
        .filter(|(det, id)| {
            let t = hung.iter().find(|t| t.id == *id);
            !t.and_then(|t| {
                photo
                    .pose
                    .project(&lens(), &Vector3::new(t.centre_m.0, t.centre_m.1, t.centre_m.2))
            })
            .is_some_and(|p| on(&detections[*det], p))
        })
        .count();
    let reg = &registration.registration;
    let (position_error_m, angle_error_deg) = reg.pose.map_or((f64::NAN, f64::NAN), |p| {
        ((p.centre - photo.pose.centre).norm(), p.angle_to_deg(&photo.pose))
    });
    Outcome {
        distance_m: reg.quality.mean_distance_m.unwrap_or(f64::NAN),
        registration,
        detections,
        visible,
        found,
        spurious,
        false_matches,
        position_error_m,
        angle_error_deg,
    }
}

fn describe(name: &str, o: &Outcome) -> String {
    let r = &o.registration;
    let q = &r.registration.quality;
    format!(
        "{name}: {} — {} detections ({} spurious), {} of {} visible surveyed found, {} matched ({} false), {} hypotheses; {} used, rejected {:?}, at {:.1} m: position {:.2} mm, angle {:.4}°, rms {:.3} px, σ {:?} m; {:?}",
        q.verdict,
        o.detections.len(),
        o.spurious,
        o.found.len(),
        o.visible.len(),
        r.matches.len(),
        o.false_matches,
        r.hypotheses,
        q.targets_used,
        q.rejected_targets,
        o.distance_m,
        o.position_error_m * 1e3,
        o.angle_error_deg,
        q.rms_px.unwrap_or(f64::NAN),
        q.sigma_position_m,
        q.reasons
    )
}

/// Right: within 5 mm per 10 m of distance and 0.05°.
fn right(o: &Outcome) -> bool {
    o.position_error_m <= 0.005 * (o.distance_m / 10.0).max(1.0) && o.angle_error_deg <= 0.05
}

/// Each hard case: a right pose, or a verdict that says why not; never `ok` and wrong.
fn assert_right_or_clear(name: &str, o: &Outcome) {
    eprintln!("{}", describe(name, o));
    let q = &o.registration.registration.quality;
    if q.verdict == Verdict::Ok {
        assert!(right(o), "{name}: ok but wrong: {}", describe(name, o));
    }
    if !right(o) {
        assert_ne!(q.verdict, Verdict::Ok, "{}", describe(name, o));
        assert!(!q.reasons.is_empty(), "{}", describe(name, o));
    }
}

/// A round window's radius: larger than a target's circle (0.1 m).
const WINDOW_RADIUS_M: f64 = 0.15;
/// The wall around a round window: a brick red.
const BRICK: [f64; 3] = [0.45, 0.30, 0.24];

/// A round white window in the tower's south face, 1.4 m from the nearest
/// surveyed target (the false target: a white disc no survey lists
/// and no dark plate surrounds).
fn tower_round_window() -> Target {
    Target {
        id: 98,
        centre_m: (1.0, -5.502, 2.7),
        normal: (0.0, -1.0, 0.0),
        up: None,
        size_m: 0.5,
    }
}

/// A false target on the south face of the tower: a plate with a white
/// circle, the survey's size, 1.3 m from the nearest surveyed one.
fn tower_false_target() -> Target {
    Target {
        id: 99,
        centre_m: (0.6, -5.502, 4.2),
        normal: (0.0, -1.0, 0.0),
        up: None,
        size_m: 0.4,
    }
}

/// Totals over the photos of one test.
#[derive(Default)]
struct Tally {
    visible: usize,
    found: usize,
    false_matches: usize,
    spurious: usize,
    poses: usize,
    right: usize,
}

impl Tally {
    fn add(&mut self, o: &Outcome) {
        self.visible += o.visible.len();
        self.found += o.found.len();
        self.false_matches += o.false_matches;
        self.spurious += o.spurious;
        self.poses += 1;
        self.right += usize::from(right(o));
    }
}

fn check_views(scene: &str, survey_file: &str, false_target: Target, views: &[(&str, CameraPose)], seed: u64) -> Tally {
    let (targets, radius) = survey(survey_file);
    let mut hung = targets.clone();
    hung.push(false_target);
    let w = world(scene, &hung, radius, &[]);
    let mut tally = Tally::default();
    for (k, (name, pose)) in views.iter().enumerate() {
        let photo = photograph(&w, pose, &settings(seed + k as u64)).expect("rendered");
        let o = register_photo(&w, &photo, &targets, radius, &hung);
        eprintln!("{}", describe(name, &o));
        assert!(o.visible.len() >= 4, "{}", describe(name, &o));
        tally.add(&o);
        assert_eq!(o.false_matches, 0, "{}", describe(name, &o));
        assert!(right(&o), "{}", describe(name, &o));
        assert_eq!(
            o.registration.registration.quality.verdict,
            Verdict::Ok,
            "{}",
            describe(name, &o)
        );
    }
    eprintln!(
        "{scene}: {} of {} visible targets found ({:.0}%), {} spurious detections, {} false matches, {} of {} poses right",
        tally.found,
        tally.visible,
        100.0 * tally.found as f64 / tally.visible as f64,
        tally.spurious,
        tally.false_matches,
        tally.right,
        tally.poses
    );
    assert!(
        tally.found as f64 >= 0.9 * tally.visible as f64,
        "found {} of {}",
        tally.found,
        tally.visible
    );
    tally
}

/// Handheld (free positions, rolled) and a tripod moved between two
/// places (level), 10–16 m from the tower's south-east corner.
fn tower_views() -> [(&'static str, CameraPose); 5] {
    [
        ("handheld-1", held([13.0, -15.0, 1.6], [3.0, -3.0, 3.0], 4.0)),
        ("handheld-2", held([9.0, -16.0, 1.8], [2.0, -4.0, 3.0], -6.0)),
        ("handheld-3", held([16.0, -9.0, 1.5], [4.0, -2.0, 3.0], 2.5)),
        ("tripod-1", held([11.0, -12.0, 1.4], [4.0, -4.0, 3.0], 0.0)),
        ("tripod-2", held([6.0, -15.0, 1.4], [3.0, -4.0, 3.5], 0.0)),
    ]
}

/// The tower's five views (measured figures in docs/status.md).
#[test]
fn photos_of_the_tower_find_the_circles_and_register_within_the_goals() {
    check_views(
        "campanile-scene.ron",
        "campanile-circles.ron",
        tower_false_target(),
        &tower_views(),
        300,
    );
}

#[test]
fn photos_of_the_room_find_the_circles_and_register_within_the_goals() {
    let views = [
        ("room-se", held([4.3, 0.6, 1.5], [1.0, 3.5, 1.5], 3.0)),
        ("room-s", held([2.8, 0.4, 1.3], [1.2, 3.9, 1.6], -4.0)),
        ("room-e", held([4.6, 2.2, 1.7], [0.5, 3.0, 1.4], 0.0)),
    ];
    let fake = Target {
        id: 99,
        centre_m: (2.0, 3.998, 2.2),
        normal: (0.0, -1.0, 0.0),
        up: None,
        size_m: 0.15,
    };
    check_views("room-scene.ron", "room-circles.ron", fake, &views, 400);
}

#[test]
fn hard_cases_give_a_right_pose_or_a_clear_verdict() {
    let (targets, radius) = survey("campanile-circles.ron");
    let (_, near_corner) = tower_views()[0];
    let (_, tripod_south) = tower_views()[4];

    // A moved target (3 hangs 1.2 m above where the survey says), the
    // false target, a round white window, and a board 0.3 m in front of
    // target 2 hiding half of it.
    let mut hung = targets.clone();
    hung.iter_mut().filter(|t| t.id == 3).for_each(|t| t.centre_m.2 += 1.2);
    hung.push(tower_false_target());
    let board = Target {
        id: 100,
        centre_m: (-1.5 + 0.42, -5.8, 1.0),
        normal: (0.0, -1.0, 0.0),
        up: None,
        size_m: 0.6,
    };
    let window = tower_round_window();
    let w = world_with_windows(
        "campanile-scene.ron",
        &hung,
        radius,
        &[board],
        std::slice::from_ref(&window),
    );
    let photo = photograph(&w, &tripod_south, &settings(501)).expect("rendered");
    let o = register_photo(&w, &photo, &targets, radius, &hung);
    assert_right_or_clear("moved, false and half-hidden targets and a round window", &o);
    // The window is in view; whether it is detected (a white disc, but in
    // brick rather than on a dark plate) is said, and it is matched to
    // nothing either way (a detection matched to a target lies on that
    // target's image, checked by `false_matches` below).
    let (u, v) = tripod_south
        .project(
            &lens(),
            &Vector3::new(window.centre_m.0, window.centre_m.1, window.centre_m.2),
        )
        .expect("the window is in front of the camera");
    assert!(
        (0.0..WIDTH as f64).contains(&u) && (0.0..HEIGHT as f64).contains(&v),
        "the window is out of frame at ({u:.0}, {v:.0})"
    );
    let on_window: Vec<usize> = (0..o.detections.len())
        .filter(|&i| {
            let c = o.detections[i].ellipse.centre;
            (c.0 - u).hypot(c.1 - v) < 3.0
        })
        .collect();
    eprintln!("round window at ({u:.1}, {v:.1}) px: detections on it {on_window:?}");
    assert!(
        o.registration.matches.iter().all(|(i, _)| !on_window.contains(i)),
        "the round window was matched to a target: {}",
        describe("window", &o)
    );
    let ids: Vec<u32> = o.registration.matches.iter().map(|(_, id)| *id).collect();
    assert!(
        !ids.contains(&3) || o.registration.registration.quality.rejected_targets.contains(&3),
        "the moved target must not be used: {}",
        describe("moved", &o)
    );
    assert_eq!(o.false_matches, 0, "{}", describe("moved", &o));

    let mut hung = targets.clone();
    hung.push(tower_false_target());
    let w = world("campanile-scene.ron", &hung, radius, &[]);
    let photo = photograph(&w, &near_corner, &settings(502)).expect("rendered");
    let all = register_photo(&w, &photo, &targets, radius, &hung);
    // Three targets only: the survey lists three of those found, spread
    // over both faces.
    let f = &all.found;
    assert!(f.len() >= 6, "{}", describe("all", &all));
    let pick = [f[0], f[f.len() / 2], f[f.len() - 1]];
    let three: Vec<Target> = targets.iter().filter(|t| pick.contains(&t.id)).cloned().collect();
    let o = register_photo(&w, &photo, &three, radius, &hung);
    assert_right_or_clear("three targets", &o);

    // Nearly collinear: only the bottom row of the south face (1–4, 1.0–1.4 m
    // up over 8 m) is surveyed.
    let row: Vec<Target> = targets.iter().filter(|t| t.id <= 4).cloned().collect();
    let o = register_photo(&w, &photo, &row, radius, &hung);
    assert_right_or_clear("nearly collinear targets", &o);
    assert_ne!(o.registration.registration.quality.verdict, Verdict::Ok);

    // Strong perspective: 4 m from the south face, 64° off its normal.
    let oblique = held([-1.0, -7.5, 1.6], [3.0, -5.5, 2.5], 3.0);
    let o = register_photo(
        &w,
        &photograph(&w, &oblique, &settings(503)).expect("rendered"),
        &targets,
        radius,
        &hung,
    );
    assert_right_or_clear("strong perspective", &o);

    // Low light: a hundredth of the exposure.
    let dark = PhotoSettings {
        exposure_scale: 0.01,
        ..settings(504)
    };
    let o = register_photo(
        &w,
        &photograph(&w, &near_corner, &dark).expect("rendered"),
        &targets,
        radius,
        &hung,
    );
    assert_right_or_clear("low light", &o);
}

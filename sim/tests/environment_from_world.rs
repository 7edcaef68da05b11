//! The environment region model (thesis §5.5.2, eq. 5.13–5.15) against the
//! simulator: a patch of the landscape ring observed at the campanile
//! day's times, fitted, and compared with the patch's true normal and
//! albedo; and the planar sun track of an equinox flagged.

// Channel loops index several arrays at once; they read better with an index.
#![allow(clippy::needless_range_loop)]

use campanile_process::environment::{EnvironmentObservation, RegionModelKind, fit_region};
use campanile_process::irradiance::{SkySubdivision, sky_irradiance};
use campanile_sim::world::{World, examples_dir, load_scene};
use chrono::{DateTime, Utc};
use nalgebra::Vector3;

fn world() -> World {
    let station = campanile_config::document::load_station(&examples_dir().join("sim-station.ron"))
        .unwrap()
        .value;
    let mut w = World::new(
        &station,
        load_scene(&examples_dir().join("campanile-scene.ron")).unwrap(),
    );
    w.quality.max_bounces = 2;
    w
}

/// A point near the middle of the landscape triangle facing most nearly
/// `toward` (a horizontal direction), its normal (toward the tower) and true albedo.
fn landscape_patch(w: &World, toward: Vector3<f64>) -> (Vector3<f64>, Vector3<f64>, [f64; 3]) {
    let surface = w.scene.scene.surface_index("landscape").unwrap() as u32;
    let (i, tri) = w
        .scene
        .scene
        .triangles()
        .iter()
        .enumerate()
        .filter(|(_, t)| t.surface == surface)
        .max_by(|a, b| {
            let facing = |t: &campanile_process::render::Triangle| {
                let n = if t.normal.dot(&-t.vertices[0]) > 0.0 {
                    t.normal
                } else {
                    -t.normal
                };
                n.dot(&toward)
            };
            facing(a.1).total_cmp(&facing(b.1))
        })
        .unwrap();
    let n = if tri.normal.dot(&-tri.vertices[0]) > 0.0 {
        tri.normal
    } else {
        -tri.normal
    };
    let p = (tri.vertices[0] + tri.vertices[1] + tri.vertices[2]) / 3.0 + n * 0.01;
    (p, n, w.scene.scene.albedo_at(i, &p))
}

/// What the station would measure of the patch at `time`: its true
/// radiance ρ E / π (E the true irradiance, sky, sun and one bounce), the
/// sky's flux on a horizontal plane (App. B vector flux), and the sun's
/// normal irradiance.
fn observe(
    w: &World,
    p: Vector3<f64>,
    n: Vector3<f64>,
    albedo: [f64; 3],
    time: DateTime<Utc>,
) -> EnvironmentObservation {
    let day = w.daylight(time).unwrap().unwrap();
    let e = w
        .irradiance(time, [p.x, p.y, p.z], [n.x, n.y, n.z], &[], 20_000, 1)
        .unwrap();
    let sky = sky_irradiance(
        &Vector3::zeros(),
        &Vector3::z(),
        &|d| day.sky_radiance(d),
        None,
        &SkySubdivision::default(),
    )
    .unwrap();
    EnvironmentObservation {
        radiance: [0, 1, 2].map(|c| albedo[c] * e[c] / std::f64::consts::PI),
        sky_irradiance: sky.rgb,
        sun_irradiance: day.sun_irradiance(),
        sun: day.sun_direction,
    }
}

/// A patch of the landscape ring west of the tower, facing east into the
/// morning sun, observed at six times of the campanile day: the fitted
/// normal and sun pseudo-albedo against the truth (ρ_sun = albedo / π,
/// radiance per unit of sun irradiance on the patch), and the radiance
/// predicted at the held-out time.
///
/// The tolerances are the model's, not the fit's: eq. 5.13 takes the sky's
/// light on the patch as a fixed fraction of the sky's horizontal flux, but
/// the bright circumsolar sky moves with the sun, and that part is taken up
/// by the sun term; it shows most in blue, where the sky is bright and the
/// sun weak. Measured: normal 9.6° off, ρ_sun +3%, +8%, +22% (r, g, b);
/// at the held-out time, when the patch is barely sunlit, the predicted
/// radiance is 12%, 12% and 9.5% low (the fit's own RMS residual is 7.7%).
#[test]
fn a_landscape_patch_gives_back_its_normal_and_sun_albedo() {
    let w = world();
    // The patch west of the tower faces east, into the morning sun.
    let (p, n, albedo) = landscape_patch(&w, Vector3::new(1.0, 0.0, 0.0));
    // The campanile day's four training times, and two more mornings.
    let times = [
        "2026-08-28T14:30:00Z",
        "2026-08-28T15:47:00Z",
        "2026-08-28T17:30:00Z",
        "2026-08-28T20:10:00Z",
        "2026-08-28T22:41:00Z",
        "2026-08-29T01:38:00Z",
    ];
    let obs: Vec<EnvironmentObservation> = times
        .iter()
        .map(|t| observe(&w, p, n, albedo, t.parse().unwrap()))
        .collect();
    let fit = fit_region(&obs).unwrap();
    assert_eq!(fit.kind, RegionModelKind::SkyAndSun, "{}", fit.reason);
    let normal = Vector3::from(fit.normal.unwrap());
    let off = normal.dot(&n).clamp(-1.0, 1.0).acos().to_degrees();
    assert!(off < 12.0, "normal {off}° from the truth");
    for c in 0..3 {
        let truth = albedo[c] / std::f64::consts::PI;
        assert!(
            (fit.rho_sun[c] / truth - 1.0).abs() < 0.25,
            "channel {c}: ρ_sun {} vs {truth}",
            fit.rho_sun[c]
        );
    }
    // The held-out time (20:30 UTC): the model's radiance against the truth.
    let held_out = observe(&w, p, n, albedo, "2026-08-28T20:30:00Z".parse().unwrap());
    let predicted = fit.radiance(held_out.sky_irradiance, held_out.sun_irradiance, held_out.sun);
    for c in 0..3 {
        let e = predicted[c] / held_out.radiance[c] - 1.0;
        assert!(
            e.abs() < 0.15,
            "channel {c}: predicted {} vs true {}",
            predicted[c],
            held_out.radiance[c]
        );
    }
}

/// At the March equinox the sun's path is a great circle through the
/// station: the sun directions span a plane, and the fit says so instead of
/// returning a normal it cannot know.
#[test]
fn an_equinox_sun_track_is_flagged() {
    let w = world();
    let (p, n, albedo) = landscape_patch(&w, Vector3::new(1.0, 0.0, 0.0));
    let times = [
        "2026-03-20T15:00:00Z",
        "2026-03-20T17:00:00Z",
        "2026-03-20T19:00:00Z",
        "2026-03-20T21:00:00Z",
    ];
    let obs: Vec<EnvironmentObservation> = times
        .iter()
        .map(|t| observe(&w, p, n, albedo, t.parse().unwrap()))
        .collect();
    let fit = fit_region(&obs).unwrap();
    assert!(
        fit.sun_track_condition < campanile_process::environment::SUN_TRACK_MIN_CONDITION,
        "condition {}",
        fit.sun_track_condition
    );
    assert_eq!(fit.kind, RegionModelKind::SkyOnly, "{}", fit.reason);
}

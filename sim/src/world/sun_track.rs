//! One clear day's sun shots of a fixed sky camera: each rendered through
//! the world's true camera (the simulation's `true_camera` where given),
//! with the head held at one pose and an ND filter over the lens, and the
//! disc's centroid measured as a station would
//! ([`campanile_process::sun::measure_sun`]). These are what
//! [`campanile_process::sky_camera_calibration`] fits.

use campanile_process::pose::HeadPose;
use campanile_process::sky_camera_calibration::SunSighting;
use campanile_process::sun::{Ephemeris, SunFrame, measure_sun, sun_solid_angle_sr};
use chrono::{DateTime, Utc};

use super::{World, WorldError};

/// A simulated sun shot.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimSunShot {
    /// The time and the measured centroid.
    pub sighting: SunSighting,
    /// Where the true camera images the sun's centre, pixels (the
    /// measurement's ground truth).
    pub true_pixel: (f64, f64),
}

/// Why a time gave no sun shot (the sun down, off the image, or not
/// measurable), for the caller to report.
#[derive(Debug, Clone, PartialEq)]
pub struct MissedShot {
    /// When.
    pub time: DateTime<Utc>,
    /// Why.
    pub reason: String,
}

/// Renders a sun shot at each of `times` with the head at `head` (the
/// camera at its full resolution), through a filter of transmittance
/// `transmittance` (green channel), and measures each disc. Shots whose
/// sun is below the horizon or off the image, or whose disc cannot be
/// measured, are returned as missed with the reason.
pub fn sun_shots(
    world: &World,
    head: HeadPose,
    times: &[DateTime<Utc>],
    transmittance: f64,
    seed: u64,
) -> Result<(Vec<SimSunShot>, Vec<MissedShot>), WorldError> {
    let (w, h) = (
        world.camera.resolution.width as usize,
        world.camera.resolution.height as usize,
    );
    let rig = world.rig(head, [0.0, 0.0, 2.0], w, h);
    let (mut shots, mut missed) = (Vec::new(), Vec::new());
    for (k, &time) in times.iter().enumerate() {
        let sun = world.sun(time)?;
        if sun.elevation_rad() <= 0.0 {
            missed.push(MissedShot {
                time,
                reason: format!("the sun is down ({:.2}°)", sun.elevation_rad().to_degrees()),
            });
            continue;
        }
        let c = rig.mount.to_camera(rig.head, sun.direction());
        let Some(true_pixel) = rig
            .pinhole
            .project(c)
            .filter(|(u, v)| (0.0..w as f64).contains(u) && (0.0..h as f64).contains(v))
        else {
            missed.push(MissedShot {
                time,
                reason: "the sun is off the image".into(),
            });
            continue;
        };
        let image = world.render(time, &rig, &[], seed.wrapping_add(k as u64))?;
        let green: Vec<f32> = image
            .data
            .chunks_exact(3)
            .map(|p| p[1] * transmittance as f32)
            .collect();
        let frame = SunFrame {
            width: w,
            height: h,
            radiance: &green,
            clipped: None,
            focal_px: rig.pinhole.focal_px,
            principal_px: rig.pinhole.principal_px,
            transmittance,
        };
        let distance = Ephemeris::at(time, world.delta_t_s)
            .map(|e| e.earth_sun_distance_au())
            .unwrap_or(1.0);
        match measure_sun(&frame, sun_solid_angle_sr(distance)) {
            Ok(disc) => shots.push(SimSunShot {
                sighting: SunSighting {
                    time,
                    centroid_px: disc.centroid_px,
                },
                true_pixel,
            }),
            Err(e) => missed.push(MissedShot {
                time,
                reason: e.to_string(),
            }),
        }
    }
    Ok((shots, missed))
}

//! The simulated world against its own ground truth: what the camera sees
//! must be what the sun, sky, materials and lamps say, through the
//! station's camera geometry.

// Channel loops index several arrays at once; they read better with an index.
#![allow(clippy::needless_range_loop)]

use campanile_process::brdf::ShadingFrame;
use campanile_process::camera::image::RadianceImage;
use campanile_process::pose::HeadPose;
use campanile_process::render::{self, Lighting};
use campanile_sim::world::cube_room::CubeRoom;
use campanile_sim::world::{World, examples_dir, load_scene};
use chrono::{DateTime, Utc};
use nalgebra::Vector3;

fn station() -> campanile_config::Station {
    campanile_config::document::load_station(&examples_dir().join("sim-station.ron"))
        .unwrap()
        .value
}

fn world(scene: &str) -> World {
    World::new(&station(), load_scene(&examples_dir().join(scene)).unwrap())
}

fn head_toward(azimuth_deg: f64, elevation_deg: f64) -> HeadPose {
    let (pan, tilt) = station().head.reach(azimuth_deg, elevation_deg).unwrap();
    HeadPose {
        pan_rad: pan.to_radians(),
        tilt_rad: tilt.to_radians(),
    }
}

fn pixel(image: &RadianceImage, u: usize, v: usize) -> [f64; 3] {
    let i = (v * image.width + u) * 3;
    [0, 1, 2].map(|c| f64::from(image.data[i + c]))
}

fn afternoon() -> DateTime<Utc> {
    "2026-08-29T22:00:00Z".parse().unwrap()
}

/// Sky pixels are the daylight model's radiance along each pixel's ray,
/// through the mount calibration and the lens distortion of the station.
#[test]
fn sky_pixels_are_the_daylight_model_along_each_ray() {
    let mut w = world("campanile-scene.ron");
    w.quality.samples_per_pixel = 16;
    // Looking south-east at 50°: sky only, away from the afternoon sun in the south-west.
    let rig = w.rig(head_toward(120.0, 50.0), [0.0, -60.0, 1.5], 64, 48);
    let image = w.render(afternoon(), &rig, &[], 3).unwrap();
    let day = w.daylight(afternoon()).unwrap().unwrap();
    let mut worst: f64 = 0.0;
    for v in (2..46).step_by(7) {
        for u in (2..62).step_by(7) {
            let ray = rig.ray(u as f64 + 0.5, v as f64 + 0.5).unwrap();
            let d = ray.direction;
            let expected = day.sky_radiance([d.x, d.y, d.z]);
            let got = pixel(&image, u, v);
            for c in 0..3 {
                worst = worst.max((got[c] / expected[c] - 1.0).abs());
            }
        }
    }
    // The pixel averages the sky over its footprint (about 1°); the model
    // changes by well under 1% across that away from the sun.
    assert!(worst < 0.01, "worst relative difference {worst}");
}

/// A sunlit wall's pixel is its true albedo times its true irradiance over π.
#[test]
fn sunlit_wall_is_albedo_times_irradiance_over_pi() {
    let w = world("campanile-scene.ron");
    let rig = w.rig(head_toward(0.0, 20.0), [0.0, -60.0, 1.5], 256, 192);
    // The centre of a stone block on the south face (blocks 1.2 × 0.6 m,
    // rows start at z = 0 and odd rows such as row 37 shift by half a
    // block); a pixel covers 0.25 m there, inside the block.
    let point = Vector3::new(0.0, -5.5, 22.5);
    let (u, v) = rig.project(&point).unwrap();
    let (u, v) = (u.floor() as usize, v.floor() as usize);
    let triangle = w
        .scene
        .scene
        .intersect(&rig.ray(u as f64 + 0.5, v as f64 + 0.5).unwrap(), f64::INFINITY)
        .unwrap();
    let p = [triangle.point.x, triangle.point.y, triangle.point.z];
    let truth = w.pseudo_albedos(triangle.triangle, p);
    assert_eq!(
        truth.sun, truth.sky_environment,
        "Lambertian: one albedo for both spectra"
    );
    let albedo = truth.sun;
    let e = w
        .irradiance(
            afternoon(),
            [triangle.point.x, triangle.point.y, triangle.point.z],
            [0.0, -1.0, 0.0],
            &[],
            20_000,
            7,
        )
        .unwrap();
    let got = w.pixel_radiance(afternoon(), &rig, (u, v), &[], 20_000, 5).unwrap();
    for c in 0..3 {
        let expected = albedo[c] * e[c] / std::f64::consts::PI;
        assert!(
            (got[c] / expected - 1.0).abs() < 0.03,
            "channel {c}: pixel {} vs ρE/π {expected}",
            got[c]
        );
    }
}

/// The camera aimed at the ephemeris sun sees the disc at the image centre
/// (through the mount's level error), carrying the sun's irradiance.
#[test]
fn the_disc_is_where_the_ephemeris_puts_it_and_carries_its_irradiance() {
    let mut w = world("campanile-scene.ron");
    w.quality.samples_per_pixel = 64;
    let sun = w.sun(afternoon()).unwrap();
    let (az, el) = (sun.azimuth_rad.to_degrees(), sun.elevation_rad().to_degrees());
    let rig = w.rig(head_toward(az, el), [0.0, -60.0, 1.5], 256, 192);
    let image = w.render(afternoon(), &rig, &[], 9).unwrap();
    let day = w.daylight(afternoon()).unwrap().unwrap();
    // Integrate the excess over the sky within 2° of the brightest pixel.
    let (mut best, mut at) = (0.0, (0, 0));
    for v in 0..192 {
        for u in 0..256 {
            let g = pixel(&image, u, v)[1];
            if g > best {
                best = g;
                at = (u, v);
            }
        }
    }
    let mut sum = [0.0; 3];
    let mut centroid = Vector3::zeros();
    for v in at.1 - 8..=at.1 + 8 {
        for u in at.0 - 8..=at.0 + 8 {
            let c = |du: f64, dv: f64| rig.ray(u as f64 + du, v as f64 + dv).unwrap().direction;
            let d = c(0.5, 0.5);
            // Pixel solid angle from the corners' directions.
            let omega = (c(1.0, 0.5) - c(0.0, 0.5)).cross(&(c(0.5, 1.0) - c(0.5, 0.0))).norm();
            let sky = day.sky_radiance([d.x, d.y, d.z]);
            let l = pixel(&image, u, v);
            for k in 0..3 {
                sum[k] += (l[k] - sky[k]).max(0.0) * omega;
            }
            centroid += d * (l[1] - sky[1]).max(0.0) * omega;
        }
    }
    let e = day.sun_irradiance();
    for k in 0..3 {
        assert!(
            (sum[k] / e[k] - 1.0).abs() < 0.02,
            "channel {k}: disc carries {} vs {}",
            sum[k],
            e[k]
        );
    }
    let towards = Vector3::from(sun.direction());
    let off = centroid.normalize().dot(&towards).clamp(-1.0, 1.0).acos().to_degrees();
    assert!(off < 0.02, "disc centroid {off}° from the ephemeris sun");
    // And it is at the image centre, within the mount's 0.15° level error.
    let centre = rig.ray(128.0, 96.0).unwrap().direction;
    let from_centre = centre.dot(&towards).acos().to_degrees();
    assert!(from_centre < 0.3, "sun {from_centre}° from the optical axis");
}

/// Hard cases: a whole day of frames, from night through sunrise (sun on
/// the horizon) to noon (the highest sun) and back, are finite and
/// non-negative everywhere, and black at night.
#[test]
fn a_day_of_frames_is_finite_from_night_to_noon() {
    let mut w = world("campanile-scene.ron");
    w.quality.samples_per_pixel = 1;
    let sunrise: DateTime<Utc> = "2026-08-29T13:37:00Z".parse().unwrap();
    for hours in [-3.0, -0.25, 0.0, 0.1, 6.5, 12.0, 13.3] {
        let time = sunrise + chrono::Duration::seconds((hours * 3600.0) as i64);
        let rig = w.rig(head_toward(90.0, 2.0), [0.0, -60.0, 1.5], 32, 24);
        let image = w.render(time, &rig, &[], 1).unwrap();
        assert!(
            image.data.iter().all(|v| v.is_finite() && *v >= 0.0),
            "{time}: non-finite or negative radiance"
        );
        if hours == -3.0 {
            assert!(image.data.iter().all(|v| *v == 0.0), "night is black");
        }
    }
}

/// The room's lamps: a bulb's pixel has radiance I / (π r²), and the
/// direct irradiance under a lamp is Σ I cos θ / d² over the lamps.
#[test]
fn lamps_have_their_configured_intensity() {
    let mut w = world("room-scene.ron");
    w.quality.max_bounces = 1;
    let st = station();
    let lamps = &st.lights.as_ref().unwrap().channels;
    let point = Vector3::new(1.0, 1.0, 0.0); // the floor under lamp 1 (the table is elsewhere)
    let e = w
        .irradiance(
            afternoon(),
            [point.x, point.y, point.z],
            [0.0, 0.0, 1.0],
            &[1.0, 1.0, 1.0],
            4000,
            3,
        )
        .unwrap();
    let mut expected = [0.0; 3];
    for lamp in lamps {
        let (x, y, z) = lamp.position_m;
        let to = Vector3::new(x, y, z) - point;
        let cos = to.z / to.norm();
        let (r, g, b) = lamp.intensity.radiant_intensity_w_sr;
        for (c, i) in [r, g, b].into_iter().enumerate() {
            expected[c] += i * cos / to.norm_squared();
        }
    }
    for c in 0..3 {
        assert!(
            (e[c] / expected[c] - 1.0).abs() < 0.01,
            "channel {c}: {} vs {}",
            e[c],
            expected[c]
        );
    }
    // Only lamp 2 on: the bulb seen from below has radiance I / (π r²).
    let (x, y, z) = lamps[1].position_m;
    let rig = w.rig(head_toward(0.0, 90.0), [x, y, 1.0], 256, 192);
    let image = w.render(afternoon(), &rig, &[0.0, 1.0, 0.0], 1).unwrap();
    let l = pixel(&image, 128, 96);
    let (r, g, b) = lamps[1].intensity.radiant_intensity_w_sr;
    let area = std::f64::consts::PI * lamps[1].radius_m.powi(2);
    for (c, i) in [r, g, b].into_iter().enumerate() {
        assert!(
            (l[c] / (i / area) - 1.0).abs() < 1e-5,
            "channel {c}: {} vs {}",
            l[c],
            i / area
        );
    }
    assert!(z > 1.0, "the lamp hangs above the camera");
}

/// The cube of §4.7.1 rendered with direct light only equals the sum over
/// the six point lights of `f_r(wi, wo) I cos θi / d²`, computed here from
/// the Table 4.1 BRDFs on an analytic ray–wall intersection: an
/// independent check of the Ward shading, its frame and anisotropy.
#[test]
fn cube_room_direct_light_matches_the_table_4_1_brdfs() {
    let cube = CubeRoom::new(1.0);
    let centre = Vector3::repeat(0.5);
    let lighting = Lighting {
        points: &cube.lights,
        ..Default::default()
    };
    let mut rng_dirs = 0u64;
    let mut checked = 0;
    for wall in 0..6 {
        for k in 0..20 {
            rng_dirs = rng_dirs
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let a = (rng_dirs >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            let b = (((rng_dirs >> 7) % 1000) as f64 / 1000.0 - 0.5) * 0.9;
            // A ray from the centre toward wall `wall`.
            let axis = wall / 2;
            let sign = if wall % 2 == 0 { -1.0 } else { 1.0 };
            let mut d = Vector3::zeros();
            d[axis] = sign * 0.5;
            d[(axis + 1) % 3] = a * 0.9;
            d[(axis + 2) % 3] = b;
            let d = d.normalize();
            let ray = render::Ray {
                origin: centre,
                direction: d,
            };
            let mut rng = rand_chacha_seed(k);
            let got = render::trace(&cube.scene, &lighting, ray, 1, &mut rng);
            // The analytic hit and the BRDF at it (albedo noise only on walls 5 and 6).
            let t = 0.5 / d[axis].abs();
            let p = centre + d * t;
            let mut normal = Vector3::zeros();
            normal[axis] = -sign;
            let hit = cube.scene.intersect(&ray, f64::INFINITY).unwrap();
            let tri = &cube.scene.triangles()[hit.triangle];
            let mut material = cube.materials[wall];
            material.rho_d = cube.scene.albedo_at(hit.triangle, &p);
            let frame = ShadingFrame::new(normal, tri.texture_axes[0]).unwrap();
            let wo = frame.to_local(&(-d));
            let mut expected = [0.0; 3];
            for light in &cube.lights {
                let to = light.position - p;
                let wi = to.normalize();
                let f = material.eval(&frame.to_local(&wi), &wo);
                for c in 0..3 {
                    expected[c] += f[c] * light.intensity[c] * wi.dot(&normal).max(0.0) / to.norm_squared();
                }
            }
            for c in 0..3 {
                assert!(
                    (got[c] - expected[c]).abs() <= 1e-5 * expected[c].max(1e-3),
                    "wall {wall}, ray {k}, channel {c}: traced {} vs analytic {}",
                    got[c],
                    expected[c]
                );
            }
            checked += 1;
        }
    }
    assert_eq!(checked, 120);
}

fn rand_chacha_seed(k: u64) -> impl rand::Rng {
    use rand::SeedableRng;
    rand_chacha::ChaCha8Rng::seed_from_u64(k)
}

/// The environment panorama: its top rows are the daylight sky and its
/// bottom row, every ray of which lands just below the station, is the
/// ground's true albedo times its irradiance over π.
#[test]
fn environment_panorama_shows_the_sky_above_and_the_ground_below() {
    let mut w = world("campanile-scene.ron");
    w.quality.samples_per_pixel = 64;
    // Over the centre of a 1 m ground-texture cell: the bottom row's rays
    // land within 0.16 m of the point below.
    let position = [30.5, -60.5, 1.5];
    let map = w.environment_map(afternoon(), position, &[], 64, 4).unwrap();
    assert_eq!((map.width, map.height), (64, 32));
    let day = w.daylight(afternoon()).unwrap().unwrap();
    // Row 2 (zenith angles 11.25°–16.9°), away from the sun: the sky model, averaged over each pixel.
    for x in [8usize, 24, 56] {
        let az = (x as f64 + 0.5) / 64.0 * std::f64::consts::TAU;
        let zen = 2.5 / 32.0 * std::f64::consts::PI;
        let d = campanile_process::sky::direction(zen, az);
        let expected = day.sky_radiance(d);
        let got = pixel(&map, x, 2);
        for c in 0..3 {
            assert!(
                (got[c] / expected[c] - 1.0).abs() < 0.02,
                "x {x}, channel {c}: {} vs {}",
                got[c],
                expected[c]
            );
        }
    }
    // The bottom row: the ground under the station.
    let below = Vector3::new(position[0], position[1], 0.0);
    let tri = w
        .scene
        .scene
        .intersect(
            &render::Ray {
                origin: Vector3::from(position),
                direction: -Vector3::z(),
            },
            f64::INFINITY,
        )
        .unwrap();
    let albedo = w.scene.scene.albedo_at(tri.triangle, &below);
    let e = w
        .irradiance(afternoon(), [below.x, below.y, 0.0], [0.0, 0.0, 1.0], &[], 20_000, 8)
        .unwrap();
    let mut mean = [0.0; 3];
    for x in 0..64 {
        let p = pixel(&map, x, 31);
        (0..3).for_each(|c| mean[c] += p[c] / 64.0);
    }
    for c in 0..3 {
        let expected = albedo[c] * e[c] / std::f64::consts::PI;
        assert!(
            (mean[c] / expected - 1.0).abs() < 0.03,
            "channel {c}: nadir {} vs ρE/π {expected}",
            mean[c]
        );
    }
}

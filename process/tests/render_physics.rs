//! Independent checks of the renderer's light transport against analytic
//! answers, so that the simulator is not wrong in the same way as the
//! solvers it feeds.

// Channel loops index several arrays at once; they read better with an index.
#![allow(clippy::needless_range_loop)]

use campanile_process::pose::{HeadPose, Mount, Pinhole};
use campanile_process::render::{
    CameraRig, Lighting, Material, PointLight, RenderSettings, Scene, Sky, SolarDisc, Texture, UniformSky, irradiance,
    render, shapes,
};
use nalgebra::Vector3;
use std::f64::consts::{FRAC_PI_2, PI};

fn camera_at(position: Vector3<f64>, tilt_rad: f64, size: usize) -> CameraRig {
    CameraRig {
        pinhole: Pinhole {
            focal_px: size as f64,
            principal_px: (size as f64 / 2.0, size as f64 / 2.0),
            k1: 0.0,
            k2: 0.0,
            projection: campanile_process::pose::Projection::Pinhole,
        },
        mount: Mount::default(),
        head: HeadPose { pan_rad: 0.0, tilt_rad },
        position,
        width: size,
        height: size,
    }
}

fn mean(image: &campanile_process::camera::image::RadianceImage, c: usize) -> f64 {
    let v: Vec<f64> = image.data.iter().skip(c).step_by(3).map(|&x| f64::from(x)).collect();
    v.iter().sum::<f64>() / v.len() as f64
}

fn ground(half_size: f64, albedo: Texture) -> Scene {
    let h = half_size;
    let tris = shapes::quad(
        [
            Vector3::new(-h, -h, 0.0),
            Vector3::new(h, -h, 0.0),
            Vector3::new(h, h, 0.0),
            Vector3::new(-h, h, 0.0),
        ],
        0,
        0,
    );
    let material = Material {
        name: "ground".into(),
        albedo,
        specular: None,
        emission: [0.0; 3],
    };
    Scene::new(tris, vec![material], vec!["ground".into()]).unwrap()
}

/// Furnace test: inside a closed diffuse enclosure of albedo ρ whose walls
/// emit E, every point sees L = E / (1 − ρ). With 80 bounces the truncation
/// error is ρ⁸¹ < 1e-7 for ρ ≤ 0.8.
#[test]
fn furnace_closed_box_and_sphere_give_e_over_one_minus_rho() {
    for rho in [0.5, 0.8] {
        let emission = [1.0, 2.0, 0.5];
        let material = Material {
            name: "furnace".into(),
            albedo: Texture::Constant([rho; 3]),
            specular: None,
            emission,
        };
        let boxed = shapes::cuboid(Vector3::repeat(-1.0), Vector3::repeat(1.0), true, [0; 6], [0; 6]);
        let ball = shapes::sphere(Vector3::zeros(), 1.0, 12, 24, 0, 0);
        for tris in [boxed, ball] {
            let scene = Scene::new(tris, vec![material.clone()], vec!["walls".into()]).unwrap();
            let camera = camera_at(Vector3::new(0.1, -0.2, 0.05), 0.3, 8);
            let settings = RenderSettings {
                samples_per_pixel: 16,
                max_bounces: 80,
                seed: 1,
                ..RenderSettings::default()
            };
            let image = render(&scene, &camera, &Lighting::default(), &settings);
            for c in 0..3 {
                let expected = emission[c] / (1.0 - rho);
                let worst = image
                    .data
                    .iter()
                    .skip(c)
                    .step_by(3)
                    .map(|&l| (f64::from(l) / expected - 1.0).abs())
                    .fold(0.0, f64::max);
                assert!(worst < 1e-5, "ρ = {rho}, channel {c}: worst relative error {worst}");
            }
        }
    }
}

/// A sky of radiance `L0 (1 + k cos θ)` above the horizon.
struct GradedSky {
    l0: [f64; 3],
    k: f64,
    sun: Option<SolarDisc>,
}

impl Sky for GradedSky {
    fn radiance(&self, d: &Vector3<f64>) -> [f64; 3] {
        if d.z <= 0.0 {
            return [0.0; 3];
        }
        self.l0.map(|l| l * (1.0 + self.k * d.z))
    }
    fn sun(&self) -> Option<SolarDisc> {
        self.sun
    }
}

/// A Lambertian plane under a uniform sky has radiance ρ·L_sky; under
/// `L0 (1 + k cos θ)` its irradiance is `L0 π (1 + 2k/3)`, so its radiance is
/// `ρ L0 (1 + 2k/3)`. The uniform case is exact for every path; the graded
/// one is Monte Carlo, checked to 4 standard errors.
#[test]
fn lambertian_plane_under_uniform_and_graded_sky() {
    let rho = 0.4;
    let scene = ground(1e4, Texture::Constant([rho; 3]));
    let camera = camera_at(Vector3::new(0.0, 0.0, 1.0), -FRAC_PI_2, 16);
    let settings = RenderSettings {
        samples_per_pixel: 64,
        max_bounces: 2,
        seed: 3,
        ..RenderSettings::default()
    };
    let sky = UniformSky {
        radiance: [10.0, 20.0, 40.0],
    };
    let image = render(
        &scene,
        &camera,
        &Lighting {
            sky: Some(&sky),
            ..Default::default()
        },
        &settings,
    );
    for c in 0..3 {
        let expected = rho * sky.radiance[c];
        assert!(
            (mean(&image, c) / expected - 1.0).abs() < 1e-6,
            "uniform sky, channel {c}: {}",
            mean(&image, c)
        );
    }

    let graded = GradedSky {
        l0: [10.0, 20.0, 40.0],
        k: 2.0,
        sun: None,
    };
    let image = render(
        &scene,
        &camera,
        &Lighting {
            sky: Some(&graded),
            ..Default::default()
        },
        &settings,
    );
    let n = (16 * 16 * 64) as f64;
    for c in 0..3 {
        let expected = rho * graded.l0[c] * (1.0 + 2.0 * 2.0 / 3.0);
        // One path's radiance is ρ L0 (1 + k cos θ) with cos θ = √u: its
        // standard deviation is ρ L0 k √(1/2 − 4/9).
        let sigma = rho * graded.l0[c] * 2.0 * (0.5_f64 - 4.0 / 9.0).sqrt() / n.sqrt();
        let err = (mean(&image, c) - expected).abs();
        assert!(
            err < 4.0 * sigma,
            "graded sky, channel {c}: {} vs {expected} (σ {sigma})",
            mean(&image, c)
        );
    }
}

/// Direct sun on a Lambertian plane: `L = ρ/π · E_n cos θs`, and a block
/// casts a shadow where the geometry says. One sample of the disc has a
/// relative spread of `tan θs · r / 2` = 0.28% (r = 0.27°), so the image
/// mean of 8 × 8 × 256 samples is within 1e-4 at 4.5 standard errors.
#[test]
fn sunlit_plane_and_a_sharp_shadow() {
    let rho = 0.3;
    let zenith = 50f64.to_radians();
    let sun = SolarDisc {
        direction: Vector3::new(0.0, -zenith.sin(), zenith.cos()),
        angular_radius_rad: 0.2666f64.to_radians(),
        radiance: [1.0e7, 0.9e7, 0.8e7],
    };
    let sky = GradedSky {
        l0: [0.0; 3],
        k: 0.0,
        sun: Some(sun),
    };
    let lighting = Lighting {
        sky: Some(&sky),
        ..Default::default()
    };
    let scene = ground(1e3, Texture::Constant([rho; 3]));
    let camera = camera_at(Vector3::new(0.0, 0.0, 2.0), -FRAC_PI_2, 8);
    let settings = RenderSettings {
        samples_per_pixel: 256,
        max_bounces: 1,
        seed: 9,
        ..RenderSettings::default()
    };
    let image = render(&scene, &camera, &lighting, &settings);
    for c in 0..3 {
        let expected = rho / PI * sun.normal_irradiance()[c] * zenith.cos();
        assert!(
            (mean(&image, c) / expected - 1.0).abs() < 1e-4,
            "channel {c}: {} vs {expected}",
            mean(&image, c)
        );
    }

    // A block 1 m tall whose north face stands on y = 0: with the sun to
    // the south at 50° from the zenith, its shadow falls to the north, out to
    // y = tan 50° = 1.19 m (the disc's penumbra there is 1 cm wide).
    let mut tris = ground(1e3, Texture::Constant([rho; 3])).triangles().to_vec();
    tris.extend(shapes::cuboid(
        Vector3::new(-0.5, -1.0, 0.0),
        Vector3::new(0.5, 0.0, 1.0),
        false,
        [0; 6],
        [0; 6],
    ));
    let material = Material::diffuse("ground", [rho; 3]);
    let scene = Scene::new(tris, vec![material], vec!["ground".into()]).unwrap();
    let e = irradiance(&scene, &lighting, &Vector3::new(0.0, 0.5, 0.0), &Vector3::z(), 1, 64, 1);
    assert!(
        e.iter().all(|v| *v == 0.0),
        "0.5 m north of the block is in shadow: {e:?}"
    );
    let e = irradiance(&scene, &lighting, &Vector3::new(0.0, 1.1, 0.0), &Vector3::z(), 1, 64, 1);
    assert!(
        e.iter().all(|v| *v == 0.0),
        "1.1 m north of the block is in shadow: {e:?}"
    );
    let e = irradiance(&scene, &lighting, &Vector3::new(0.0, 1.3, 0.0), &Vector3::z(), 1, 64, 1);
    let lit = sun.normal_irradiance()[0] * zenith.cos();
    assert!((e[0] / lit - 1.0).abs() < 1e-4, "1.3 m north is lit: {} vs {lit}", e[0]);
}

/// Inverse-square law and cosine: a point light of intensity I at height h
/// gives `E = I cos³ θ / h²` on the floor.
#[test]
fn point_light_irradiance_follows_inverse_square_and_cosine() {
    let scene = ground(100.0, Texture::Constant([0.0; 3]));
    let light = PointLight {
        position: Vector3::new(0.0, 0.0, 2.0),
        intensity: [3.0, 2.0, 1.0],
    };
    let lighting = Lighting {
        points: std::slice::from_ref(&light),
        ..Default::default()
    };
    for x in [0.0, 1.0, 3.0] {
        let e = irradiance(&scene, &lighting, &Vector3::new(x, 0.0, 0.0), &Vector3::z(), 1, 1, 0);
        let d2: f64 = x * x + 4.0;
        let cos = 2.0 / d2.sqrt();
        for c in 0..3 {
            let expected = light.intensity[c] * cos / d2;
            // Shadow rays leave 1 µm off the surface: a 1e-6 relative shift.
            assert!(
                (e[c] / expected - 1.0).abs() < 1e-5,
                "x = {x}, channel {c}: {} vs {expected}",
                e[c]
            );
        }
    }
}

/// One interreflection: a vertical surface standing on an infinite ground
/// of albedo ρg under a uniform sky L receives `π L / 2` from the sky and
/// `π ρg L / 2` from the sunless ground, `E = π L (1 + ρg) / 2`; with
/// direct light only it receives `π L / 2`.
#[test]
fn vertical_surface_gets_sky_plus_ground_bounce() {
    let rho_g = 0.6;
    let scene = ground(1e5, Texture::Constant([rho_g; 3]));
    let sky = UniformSky { radiance: [5.0; 3] };
    let lighting = Lighting {
        sky: Some(&sky),
        ..Default::default()
    };
    let p = Vector3::new(0.0, 0.0, 1.0);
    let n = 40_000;
    let direct = irradiance(&scene, &lighting, &p, &Vector3::x(), 1, n, 2);
    let bounced = irradiance(&scene, &lighting, &p, &Vector3::x(), 2, n, 2);
    // Per sample the estimate is π L or 0 (direct), π L or π ρg L (bounced),
    // each half the time: σ = π L / 2 · (1 or 1 − ρg) / √n.
    let l = 5.0;
    let sigma = PI * l / 2.0 / f64::from(n).sqrt();
    assert!((direct[1] - PI * l / 2.0).abs() < 4.0 * sigma, "direct {}", direct[1]);
    let expected = PI * l * (1.0 + rho_g) / 2.0;
    assert!(
        (bounced[1] - expected).abs() < 4.0 * sigma,
        "bounced {} vs {expected}",
        bounced[1]
    );
}

/// The same seed gives the same image on any number of threads; another seed
/// changes the Monte Carlo noise.
#[test]
fn rendering_is_deterministic_per_seed() {
    let scene = ground(1e3, Texture::Constant([0.5; 3]));
    let sky = GradedSky {
        l0: [1.0; 3],
        k: 3.0,
        sun: None,
    };
    let lighting = Lighting {
        sky: Some(&sky),
        ..Default::default()
    };
    let camera = camera_at(Vector3::new(0.0, 0.0, 1.0), -1.0, 12);
    let settings = |seed| RenderSettings {
        samples_per_pixel: 4,
        max_bounces: 2,
        seed,
        ..RenderSettings::default()
    };
    let a = render(&scene, &camera, &lighting, &settings(5));
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    let b = pool.install(|| render(&scene, &camera, &lighting, &settings(5)));
    let c = render(&scene, &camera, &lighting, &settings(6));
    assert_eq!(a, b);
    let differing = a.data.iter().zip(&c.data).filter(|(x, y)| x != y).count();
    assert!(
        differing > a.data.len() / 2,
        "only {differing} of {} samples changed",
        a.data.len()
    );
}

/// A photograph of the sun by a wide camera whose pixels are ten times the
/// disc (64 px over 80°, distorted): the image summed over its pixels'
/// solid angles is the disc's irradiance, within 0.3 %, wherever the disc
/// falls on the pixel grid (five positions a fifth of a pixel apart), and
/// half the disc hidden behind an edge halves it. Sampled by paths (about a
/// hundred of a near-sun pixel's 1024 hit the disc) the positions would
/// differ by several percent.
#[test]
fn a_sun_smaller_than_a_pixel_is_integrated_exactly() {
    let pinhole = Pinhole {
        focal_px: 32.0 / 40f64.to_radians().tan(),
        principal_px: (32.0, 24.0),
        k1: -0.05,
        k2: 0.01,
        projection: campanile_process::pose::Projection::Pinhole,
    };
    let empty = Scene::new(Vec::new(), Vec::new(), Vec::new()).unwrap();
    let irradiance_seen = |scene: &Scene, direction: Vector3<f64>| {
        let sun = SolarDisc {
            direction: direction.normalize(),
            angular_radius_rad: 0.2666f64.to_radians(),
            radiance: [1.0e7, 0.9e7, 0.8e7],
        };
        let sky = GradedSky {
            l0: [0.0; 3],
            k: 0.0,
            sun: Some(sun),
        };
        let lighting = Lighting {
            sky: Some(&sky),
            ..Default::default()
        };
        // Looking north and 30° up; the sun near the image centre.
        let camera = CameraRig {
            pinhole,
            mount: Mount::default(),
            head: HeadPose {
                pan_rad: 0.0,
                tilt_rad: 30f64.to_radians(),
            },
            position: Vector3::zeros(),
            width: 64,
            height: 48,
        };
        let image = render(
            scene,
            &camera,
            &lighting,
            &RenderSettings {
                samples_per_pixel: 1,
                max_bounces: 1,
                seed: 3,
                ..RenderSettings::default()
            },
        );
        let caster = camera.rays();
        let mut e = [0.0; 3];
        for y in 0..48 {
            for x in 0..64 {
                // The pixel's solid angle from its corners' rays (small pixels: planar).
                let r = |u: f64, v: f64| caster.ray(u, v).unwrap().direction;
                let (a, b, c) = (
                    r(x as f64, y as f64),
                    r(x as f64 + 1.0, y as f64),
                    r(x as f64, y as f64 + 1.0),
                );
                let omega = (b - a).cross(&(c - a)).norm();
                for ch in 0..3 {
                    e[ch] += f64::from(image.data[(y * 64 + x) * 3 + ch]) * omega;
                }
            }
        }
        (e, sun.normal_irradiance())
    };
    let pixel = 1.0 / pinhole.focal_px;
    for k in 0..5 {
        let shift = 0.2 * f64::from(k) * pixel;
        let el = 30f64.to_radians() + 0.37 * pixel + shift;
        let az = 0.41 * pixel + shift;
        let d = Vector3::new(az.sin() * el.cos(), az.cos() * el.cos(), el.sin());
        let (e, truth) = irradiance_seen(&empty, d);
        for ch in 0..3 {
            assert!(
                (e[ch] / truth[ch] - 1.0).abs() < 3e-3,
                "position {k}, channel {ch}: {} vs {}",
                e[ch],
                truth[ch]
            );
        }
    }
    // A vertical wall whose edge (x = 0) splits the disc: half is hidden.
    let wall = {
        let tris = shapes::quad(
            [
                Vector3::new(0.0, 100.0, -100.0),
                Vector3::new(100.0, 100.0, -100.0),
                Vector3::new(100.0, 100.0, 200.0),
                Vector3::new(0.0, 100.0, 200.0),
            ],
            0,
            0,
        );
        let m = Material {
            name: "wall".into(),
            albedo: Texture::Constant([0.0; 3]),
            specular: None,
            emission: [0.0; 3],
        };
        Scene::new(tris, vec![m], vec!["wall".into()]).unwrap()
    };
    let el = 30f64.to_radians();
    let (e, truth) = irradiance_seen(&wall, Vector3::new(0.0, el.cos(), el.sin()));
    for ch in 0..3 {
        assert!(
            (e[ch] / truth[ch] - 0.5).abs() < 5e-3,
            "half hidden, channel {ch}: {}",
            e[ch] / truth[ch]
        );
    }
}

/// Path splitting at the first surface (`RenderSettings::split_rays`)
/// against the analytic answer. A 1 cm vertical patch of albedo ρw, 10 m
/// above an unbounded ground of albedo ρg, under the sky `L0 (1 + k cos θ)`:
/// the upper half of its hemisphere brings `L0 (π/2 + 2k/3)` (∫ z·(n·ω) dω
/// over that quarter sphere is 2/3), the lower half the ground's radiance
/// `ρg L0 (1 + 2k/3)` times π/2, so it shows `ρw/π` times their sum. With
/// two scattering events the ground's light is its sky, found by the
/// branches' occlusion rays (split) or by the continuation (no split). The
/// image mean must hit the sum within 4 standard errors (the pixels are
/// independent and see the same radiance) plus 0.1% for the ground's
/// finite extent, without splitting and with 1 to 16 branches.
#[test]
fn path_splitting_matches_the_analytic_patch_on_a_ground() {
    let (rho_w, rho_g, l0, k) = (0.5, 0.6, 10.0, 2.0);
    let h = 0.005;
    let mut tris = ground(1e5, Texture::Constant([rho_g; 3])).triangles().to_vec();
    // Facing south (−y), toward the camera.
    tris.extend(shapes::quad(
        [
            Vector3::new(-h, 0.0, 10.0 - h),
            Vector3::new(h, 0.0, 10.0 - h),
            Vector3::new(h, 0.0, 10.0 + h),
            Vector3::new(-h, 0.0, 10.0 + h),
        ],
        1,
        1,
    ));
    let scene = Scene::new(
        tris,
        vec![
            Material::diffuse("ground", [rho_g; 3]),
            Material::diffuse("patch", [rho_w; 3]),
        ],
        vec!["ground".into(), "patch".into()],
    )
    .unwrap();
    let sky = GradedSky {
        l0: [l0, 2.0 * l0, 4.0 * l0],
        k,
        sun: None,
    };
    let lighting = Lighting {
        sky: Some(&sky),
        ..Default::default()
    };
    // A narrow camera 10 cm south of the patch, looking north: the 32 px
    // span 5 mm, all on the patch.
    let mut camera = camera_at(Vector3::new(0.0, -0.1, 10.0), 0.0, 32);
    camera.pinhole.focal_px = 32.0 * 20.0;
    for split_rays in [0, 1, 4, 16] {
        let settings = RenderSettings {
            samples_per_pixel: 16,
            max_bounces: 2,
            seed: 11,
            split_rays,
        };
        let image = render(&scene, &camera, &lighting, &settings);
        for c in 0..3 {
            let l = sky.l0[c];
            let expected =
                rho_w / PI * (l * (FRAC_PI_2 + 2.0 * k / 3.0) + FRAC_PI_2 * rho_g * l * (1.0 + 2.0 * k / 3.0));
            let v: Vec<f64> = image.data.iter().skip(c).step_by(3).map(|&x| f64::from(x)).collect();
            let n = v.len() as f64;
            let m = v.iter().sum::<f64>() / n;
            let sd = (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
            let tolerance = 4.0 * sd / n.sqrt() + 1e-3 * expected;
            assert!(
                (m - expected).abs() < tolerance,
                "{split_rays} branches, channel {c}: {m} vs {expected} (tolerance {tolerance})"
            );
        }
    }
}

/// A wall in its own shadow: 10 m tall and 200 m wide, facing south, the
/// sun to the north 40° up (its irradiance 8× the sky's), on a ground of
/// albedo 0.3 that is sunlit beyond the wall's 12 m shadow, under a graded
/// sky; seen from 20 m at 2 scattering events. Per wall pixel and channel,
/// one frame's relative noise is `|a − b| / √2` over two seeds, relative
/// to their mean. At equal samples per pixel (16), 4 branches at the wall
/// must cut its RMS at least 2-fold from one continuation (measured 0.174
/// → 0.070, ×2.5; a path costs about twice as much, BENCHMARKS.md, "Path
/// splitting at the first surface"), and both estimators must agree on the
/// wall's mean radiance within 4 standard errors (from the seed
/// differences).
#[test]
fn path_splitting_cuts_the_noise_of_a_shadowed_wall() {
    let mut tris = ground(1e3, Texture::Constant([0.3; 3])).triangles().to_vec();
    tris.extend(shapes::quad(
        [
            Vector3::new(-100.0, 0.0, 0.0),
            Vector3::new(100.0, 0.0, 0.0),
            Vector3::new(100.0, 0.0, 10.0),
            Vector3::new(-100.0, 0.0, 10.0),
        ],
        1,
        1,
    ));
    let scene = Scene::new(
        tris,
        vec![
            Material::diffuse("ground", [0.3; 3]),
            Material::diffuse("wall", [0.5; 3]),
        ],
        vec!["ground".into(), "wall".into()],
    )
    .unwrap();
    let (l0, k) = (100.0, 1.0);
    let elevation = 40f64.to_radians();
    let mut sun = SolarDisc {
        direction: Vector3::new(0.0, elevation.cos(), elevation.sin()),
        angular_radius_rad: 0.2666f64.to_radians(),
        radiance: [1.0; 3],
    };
    let e_sky = PI * l0 * (1.0 + 2.0 * k / 3.0);
    sun.radiance = [8.0 * e_sky / sun.solid_angle(); 3];
    let sky = GradedSky {
        l0: [l0; 3],
        k,
        sun: Some(sun),
    };
    let lighting = Lighting {
        sky: Some(&sky),
        ..Default::default()
    };
    let camera = camera_at(Vector3::new(0.0, -20.0, 4.0), 0.0, 48);
    let caster = camera.rays();
    let wall: Vec<usize> = (0..48 * 48)
        .filter(|p| {
            let ray = caster.ray((p % 48) as f64 + 0.5, (p / 48) as f64 + 0.5).unwrap();
            scene
                .intersect(&ray, f64::INFINITY)
                .is_some_and(|hit| scene.triangles()[hit.triangle].surface == 1)
        })
        .collect();
    assert!(wall.len() > 500, "{} wall pixels", wall.len());
    // (RMS relative noise of one frame, mean radiance, its variance).
    let measure = |split_rays: u32| {
        let settings = |seed| RenderSettings {
            samples_per_pixel: 16,
            max_bounces: 2,
            seed,
            split_rays,
        };
        let a = render(&scene, &camera, &lighting, &settings(1));
        let b = render(&scene, &camera, &lighting, &settings(2));
        let (mut rel2, mut sum, mut var) = (0.0, 0.0, 0.0);
        let n = (wall.len() * 3) as f64;
        for &p in &wall {
            for c in 0..3 {
                let (x, y) = (f64::from(a.data[p * 3 + c]), f64::from(b.data[p * 3 + c]));
                let d2 = (x - y) * (x - y) / 2.0;
                rel2 += d2 / (0.5 * (x + y)).powi(2);
                sum += 0.5 * (x + y);
                // The pair's mean has half one frame's variance.
                var += d2 / 2.0;
            }
        }
        ((rel2 / n).sqrt(), sum / n, var / (n * n))
    };
    let (old_noise, old_mean, old_var) = measure(0);
    let (new_noise, new_mean, new_var) = measure(4);
    eprintln!("shadowed wall: noise {old_noise:.4} → {new_noise:.4}; mean {old_mean:.3} vs {new_mean:.3}");
    assert!(
        old_noise >= 2.0 * new_noise,
        "noise {old_noise} without splitting, {new_noise} with 4 branches"
    );
    let sigma = (old_var + new_var).sqrt();
    assert!(
        (old_mean - new_mean).abs() < 4.0 * sigma,
        "mean wall radiance {old_mean} without splitting, {new_mean} with it (σ {sigma})"
    );
}

/// A segment through the 20 m ground square (z = 0) is blocked; one above
/// it, one ending on it, and one from it upward are clear; a point is not a
/// segment.
#[test]
fn segments_are_clear_only_when_nothing_lies_between_their_ends() {
    let scene = ground(10.0, Texture::Constant([0.5; 3]));
    let (above, below) = (Vector3::new(0.0, 0.0, 1.0), Vector3::new(0.0, 0.0, -1.0));
    assert!(!scene.segment_clear(&above, &below));
    assert!(scene.segment_clear(&above, &Vector3::new(5.0, 5.0, 2.0)));
    assert!(scene.segment_clear(&above, &Vector3::new(3.0, 0.0, 0.0)));
    assert!(scene.segment_clear(&Vector3::new(3.0, 0.0, 1e-4), &above));
    assert!(!scene.segment_clear(&above, &above));
    // Beyond the square's edge the segment passes under nothing.
    assert!(scene.segment_clear(&Vector3::new(11.0, 0.0, 1.0), &Vector3::new(11.0, 0.0, -1.0)));
}

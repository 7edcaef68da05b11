//! Camera pose from targets, speed against the thesis (§3.3: 5.8 s for 50
//! targets, 21 s for 100; goal: 100 targets under 0.1 s): AprilTag
//! detection and registration on a synthetic 2048 × 1536 photograph of a
//! wall of N tags (4 × 4 supersampled, seeded noise), median of repeated
//! runs. Prints a Markdown table; with a directory argument, also writes
//! each photo (PNG) and its correspondences (JSON) there, for
//! `bench/registration/opencv.py` to time OpenCV on the same input.
//!
//! Then the thesis's own targets (§3.3.1–§3.3.3): a wall of N white
//! circles on dark plates, placed off a regular grid (a grid's symmetry
//! would let shifted assignments confirm each other), found by the
//! template sweep and ellipse fit, paired with the N surveyed circles by
//! the search, and registered.
//!
//! `cargo bench -p campanile-process --bench registration -- [DIR]`, or
//! `-- circles` for the circle targets' table alone.

use std::hint::black_box;
use std::time::Instant;

use campanile_config::targets::Target;
use campanile_process::pose::Pinhole;
use campanile_process::registration::apriltag::{TAG36H11_BORDER_CELLS, TagDetector, correspondences, tag36h11_cells};
use campanile_process::registration::circle_detect::{CircleDetectorSettings, detect_circles};
use campanile_process::registration::circle_search::{CircleSearchSettings, SurveyedCircle, register_circles};
use campanile_process::registration::{CameraPose, RegistrationSettings, register};
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};

const W: usize = 2048;
const H: usize = 1536;

fn lens() -> Pinhole {
    Pinhole {
        focal_px: 1600.0,
        principal_px: (1024.0, 768.0),
        k1: -0.05,
        k2: 0.01,
        projection: campanile_config::camera::Projection::Pinhole,
    }
}

/// `n` tags of 0.3 m on a wall (y = 0, facing south), 10 to a row, 0.5 m apart.
fn wall(n: usize) -> Vec<Target> {
    (0..n)
        .map(|i| Target {
            id: i as u32,
            centre_m: (-2.25 + 0.5 * (i % 10) as f64, 0.0, 1.0 + 0.5 * (i / 10) as f64),
            normal: (0.0, -1.0, 0.0),
            up: None,
            size_m: 0.3,
        })
        .collect()
}

fn camera(n: usize) -> CameraPose {
    let rows = n.div_ceil(10) as f64;
    let at = Vector3::new(0.0, 0.0, 1.0 + 0.25 * (rows - 1.0));
    let centre = Vector3::new(1.5, -5.5, 1.6);
    let forward = (at - centre).normalize();
    let level_right = forward.cross(&Vector3::z()).normalize();
    let level_down = forward.cross(&level_right);
    let r = 3f64.to_radians();
    let right = level_right * r.cos() + level_down * r.sin();
    CameraPose::from_axes(right, forward.cross(&right), forward, centre)
}

/// The wall of tags seen from `pose`: white 220 / black 25 cells on a grey
/// (120) wall, 4 × 4 samples a pixel, Gaussian noise σ 2 codes.
fn photo(targets: &[Target], pose: &CameraPose) -> Vec<u8> {
    let cells: Vec<(usize, Vec<bool>)> = targets.iter().map(|t| tag36h11_cells(t.id).expect("an id")).collect();
    let r_inv = pose.rotation.inverse();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    let mut out = vec![0u8; W * H];
    for y in 0..H {
        for x in 0..W {
            let mut sum = 0.0f64;
            for s in 0..16 {
                let (u, v) = (
                    x as f64 + (f64::from(s % 4) + 0.5) / 4.0,
                    y as f64 + (f64::from(s / 4) + 0.5) / 4.0,
                );
                let Some(d) = lens().unproject(u, v) else { continue };
                let dir = r_inv * Vector3::new(d[0], d[1], d[2]);
                // The wall y = 0.
                let k = -pose.centre.y / dir.y;
                let p = pose.centre + dir * k;
                let mut value = 120.0;
                if k > 0.0 {
                    let col = ((p.x + 2.5) / 0.5).floor();
                    let row = ((p.z - 0.75) / 0.5).floor();
                    let i = row * 10.0 + col;
                    if (0.0..10.0).contains(&col) && row >= 0.0 && (i as usize) < targets.len() {
                        let t = &targets[i as usize];
                        let (w, c) = &cells[i as usize];
                        let cell = t.size_m / TAG36H11_BORDER_CELLS as f64;
                        let a = (p.x - t.centre_m.0) / cell + *w as f64 / 2.0;
                        let b = (t.centre_m.2 - p.z) / cell + *w as f64 / 2.0;
                        if a >= -1.0 && b >= -1.0 && a < *w as f64 + 1.0 && b < *w as f64 + 1.0 {
                            let inside = a >= 0.0 && b >= 0.0 && a < *w as f64 && b < *w as f64;
                            value = if !inside || c[b as usize * w + a as usize] {
                                220.0
                            } else {
                                25.0
                            };
                        }
                    }
                }
                sum += value;
            }
            let noise: f64 = (0..4).map(|_| rng.random::<f64>() - 0.5).sum::<f64>() * 2.0 * 3f64.sqrt();
            out[y * W + x] = (sum / 16.0 + noise).round().clamp(0.0, 255.0) as u8;
        }
    }
    out
}

/// Circle radius and plate side of the circle wall, metres.
const CIRCLE_R: f64 = 0.09;
const PLATE: f64 = 0.3;

/// `n` circle targets on the wall y = 0, 10 to a row, 0.5 m apart, each
/// moved up to ±8 cm along and up the wall (a fixed pseudo-random pattern).
fn circle_wall(n: usize) -> Vec<SurveyedCircle> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(17);
    (0..n)
        .map(|i| SurveyedCircle {
            id: i as u32,
            centre: Vector3::new(
                -2.25 + 0.5 * (i % 10) as f64 + rng.random_range(-0.08..0.08),
                0.0,
                1.0 + 0.5 * (i / 10) as f64 + rng.random_range(-0.08..0.08),
            ),
            normal: -Vector3::y(),
            radius_m: CIRCLE_R,
        })
        .collect()
}

/// The circle wall seen from `pose`: white (220) circles on dark (25)
/// plates on a grey (120) wall, 4 × 4 samples a pixel, noise σ 2 codes.
fn circle_photo(targets: &[SurveyedCircle], pose: &CameraPose) -> Vec<u8> {
    let r_inv = pose.rotation.inverse();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(12);
    let mut out = vec![0u8; W * H];
    for y in 0..H {
        for x in 0..W {
            let mut sum = 0.0f64;
            for s in 0..16 {
                let (u, v) = (
                    x as f64 + (f64::from(s % 4) + 0.5) / 4.0,
                    y as f64 + (f64::from(s / 4) + 0.5) / 4.0,
                );
                let Some(d) = lens().unproject(u, v) else { continue };
                let dir = r_inv * Vector3::new(d[0], d[1], d[2]);
                let k = -pose.centre.y / dir.y;
                let p = pose.centre + dir * k;
                let mut value = 120.0;
                if k > 0.0 {
                    let col = ((p.x + 2.5) / 0.5).floor();
                    let row = ((p.z - 0.75) / 0.5).floor();
                    // The plate may have moved into a neighbouring cell.
                    for (dc, dr) in [(0.0, 0.0), (-1.0, 0.0), (1.0, 0.0), (0.0, -1.0), (0.0, 1.0)] {
                        let (c, r) = (col + dc, row + dr);
                        let i = r * 10.0 + c;
                        if !((0.0..10.0).contains(&c) && r >= 0.0 && (i as usize) < targets.len()) {
                            continue;
                        }
                        let t = &targets[i as usize];
                        let (dx, dz) = (p.x - t.centre.x, p.z - t.centre.z);
                        if dx.abs() <= PLATE / 2.0 && dz.abs() <= PLATE / 2.0 {
                            value = if dx.hypot(dz) <= CIRCLE_R { 220.0 } else { 25.0 };
                            break;
                        }
                    }
                }
                sum += value;
            }
            let noise: f64 = (0..4).map(|_| rng.random::<f64>() - 0.5).sum::<f64>() * 2.0 * 3f64.sqrt();
            out[y * W + x] = (sum / 16.0 + noise).round().clamp(0.0, 255.0) as u8;
        }
    }
    out
}

fn circles_table() {
    println!();
    println!(
        "| circle targets | found | matched | hypotheses (surveyed pairs considered) | detection (median) | search + registration (median) | total | position error | angle error | thesis |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for (n, thesis) in [(50, "5.8 s"), (100, "21 s")] {
        let targets = circle_wall(n);
        let pose = camera(n);
        let gray = circle_photo(&targets, &pose);
        let ds = CircleDetectorSettings::default();
        let (rs, ss) = (RegistrationSettings::default(), CircleSearchSettings::default());
        let found = detect_circles(&gray, W, H, &ds);
        let r = register_circles(&lens(), &found, &targets, &rs, &ss);
        let (error, angle) = r.registration.pose.map_or((f64::NAN, f64::NAN), |p| {
            ((p.centre - pose.centre).norm(), p.angle_to_deg(&pose))
        });
        let runs = 5;
        let det: Vec<f64> = (0..runs)
            .map(|_| {
                let t = Instant::now();
                black_box(detect_circles(black_box(&gray), W, H, &ds));
                t.elapsed().as_secs_f64()
            })
            .collect();
        let reg: Vec<f64> = (0..runs)
            .map(|_| {
                let t = Instant::now();
                black_box(register_circles(&lens(), black_box(&found), &targets, &rs, &ss));
                t.elapsed().as_secs_f64()
            })
            .collect();
        let (d, g) = (median(det), median(reg));
        println!(
            "| {n} | {} | {} | {} ({}) | {:.1} ms | {:.2} ms | {:.1} ms | {:.2} mm | {:.4}° | {thesis} |",
            found.len(),
            r.matches.len(),
            r.hypotheses,
            r.pairs_considered,
            d * 1e3,
            g * 1e3,
            (d + g) * 1e3,
            error * 1e3,
            angle
        );
    }
}

fn median(mut xs: Vec<f64>) -> f64 {
    xs.sort_by(f64::total_cmp);
    xs[xs.len() / 2]
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).filter(|a| !a.starts_with('-')).collect();
    // `circles` alone: only the circle targets' table.
    if args.iter().any(|a| a == "circles") {
        circles_table();
        return;
    }
    let dir = args.first();
    println!("| targets | found | detection (median) | registration (median) | total | position error | thesis |");
    println!("|---|---|---|---|---|---|---|");
    for (n, thesis) in [(50, "5.8 s"), (100, "21 s")] {
        let targets = wall(n);
        let pose = camera(n);
        let gray = photo(&targets, &pose);
        let mut detector = TagDetector::new(W, H).expect("detector");
        let found = detector.detect(&gray).expect("detects");
        let (points, _) = correspondences(&found, &targets);
        let settings = RegistrationSettings::default();
        let r = register(&lens(), &points, &settings);
        let error = r.pose.map_or(f64::NAN, |p| (p.centre - pose.centre).norm());
        let runs = 15;
        let det: Vec<f64> = (0..runs)
            .map(|_| {
                let t = Instant::now();
                black_box(detector.detect(black_box(&gray)).expect("detects"));
                t.elapsed().as_secs_f64()
            })
            .collect();
        let reg: Vec<f64> = (0..runs)
            .map(|_| {
                let t = Instant::now();
                black_box(register(&lens(), black_box(&points), &settings));
                t.elapsed().as_secs_f64()
            })
            .collect();
        let (d, g) = (median(det), median(reg));
        println!(
            "| {n} | {} | {:.1} ms | {:.2} ms | {:.1} ms | {:.2} mm | {thesis} |",
            found.len(),
            d * 1e3,
            g * 1e3,
            (d + g) * 1e3,
            error * 1e3
        );
        if let Some(dir) = &dir {
            std::fs::create_dir_all(dir).expect("output directory");
            image::save_buffer(
                format!("{dir}/wall-{n}.png"),
                &gray,
                W as u32,
                H as u32,
                image::ExtendedColorType::L8,
            )
            .expect("png");
            let l = lens();
            let json = serde_json::json!({
                "focal_px": l.focal_px, "principal_px": [l.principal_px.0, l.principal_px.1],
                "k1": l.k1, "k2": l.k2,
                "campanile_detection_ms": d * 1e3, "campanile_registration_ms": g * 1e3,
                "points": points.iter().map(|c| serde_json::json!({
                    "target": c.target, "pixel": [c.pixel.0, c.pixel.1], "world": c.world})).collect::<Vec<_>>(),
            });
            std::fs::write(format!("{dir}/wall-{n}.json"), json.to_string()).expect("json");
        }
    }
    circles_table();
}

//! Outdoor reflectance recovery and re-rendering (thesis §5.4–§5.6) against
//! the simulated campanile day: pseudo-albedos recovered from the four
//! training times against the world's true ones, and re-renders at the
//! held-out time against the world's own render.

// Channel loops index several arrays at once; they read better with an index.
#![allow(clippy::needless_range_loop)]

use campanile_process::error_figures::{block_relative_rmse, quantile};
use campanile_process::outdoor::rerender::{relative_rmse, target_mask};
use campanile_process::outdoor::{
    CellStatus, Illumination, Photo, Reflectance, ReflectanceSettings, RerenderSettings, recover_reflectance, rerender,
};
use campanile_process::pose::HeadPose;
use campanile_process::render::CameraRig;
use campanile_process::sky::Daylight;
use campanile_sim::world::{World, examples_dir, load_scene};
use chrono::{DateTime, Utc};

const WIDTH: usize = 128;
const HEIGHT: usize = 96;

fn station() -> campanile_config::Station {
    campanile_config::document::load_station(&examples_dir().join("sim-station.ron"))
        .unwrap()
        .value
}

fn world() -> World {
    let mut w = World::new(
        &station(),
        load_scene(&examples_dir().join("campanile-scene.ron")).unwrap(),
    );
    w.quality.samples_per_pixel = 16;
    w.quality.max_bounces = 2;
    w
}

/// The training triggers' times, from `campanile plan check examples/campanile-day.ron`.
const TRAINING: [&str; 4] = [
    "2026-08-29T15:48:00Z",
    "2026-08-29T20:10:00Z",
    "2026-08-29T22:42:00Z",
    "2026-08-30T01:38:00Z",
];
const HELD_OUT: &str = "2026-08-29T20:30:00Z";

fn time(s: &str) -> DateTime<Utc> {
    s.parse().unwrap()
}

/// The camera at the scene's pose `name`.
fn rig(w: &World, name: &str) -> CameraRig {
    let station = station();
    let pose = w.scene.description.pose(name).unwrap();
    let (pan, tilt) = station.head.reach(pose.azimuth_deg, pose.elevation_deg).unwrap();
    let head = HeadPose {
        pan_rad: pan.to_radians(),
        tilt_rad: tilt.to_radians(),
    };
    let (x, y, z) = pose.position_m;
    w.rig(head, [x, y, z], WIDTH, HEIGHT)
}

/// Grid spacing of the tests, metres (about three pixels of the 128-px photos).
const SPACING_M: f64 = 2.0;

const VIEWS: [&str; 4] = ["view-se", "view-sw", "view-nw", "view-ne"];

/// The tower's surfaces: the four faces, the pillars and the roof.
fn targets(w: &World) -> Vec<usize> {
    ["south-face", "east-face", "north-face", "west-face", "pillars", "roof"]
        .iter()
        .map(|s| w.scene.scene.surface_index(s).unwrap())
        .collect()
}

/// The world's photos of the tower from the four views at `times`.
fn photos(w: &World, times: &[&str]) -> Vec<Photo> {
    let mut out = Vec::new();
    for (i, t) in times.iter().enumerate() {
        for (j, v) in VIEWS.iter().enumerate() {
            let r = rig(w, v);
            let image = w.render(time(t), &r, &[], 100 + (i * 4 + j) as u64).unwrap();
            out.push(Photo {
                label: format!("{t} {v}"),
                image,
                rig: r,
                time: time(t),
                mask: None,
            });
        }
    }
    out
}

fn daylights(w: &World, times: &[&str]) -> Vec<(DateTime<Utc>, Daylight)> {
    times
        .iter()
        .map(|t| (time(t), w.daylight(time(t)).unwrap().unwrap()))
        .collect()
}

/// The true pseudo-albedo of each cell: the mean over the cell of the
/// world's per-point truth (ρ_sun = ρ_se in the simulator).
fn truth(w: &World, refl: &Reflectance) -> Vec<[f64; 3]> {
    (0..refl.grid.cells.len())
        .map(|c| {
            // 64 × 64 sub-samples: the 5 cm mortar joints alias with an
            // 8 × 8 grid (±3% in the truth itself, tests/outdoor_error_budget.rs).
            let pts = refl.grid.cell_points(&w.scene.scene, c, 64);
            let tri = refl.grid.cells[c].triangle;
            let mut s = [0.0; 3];
            for p in &pts {
                let a = w.pseudo_albedos(tri, [p.x, p.y, p.z]).sun;
                for ch in 0..3 {
                    s[ch] += a[ch] / pts.len() as f64;
                }
            }
            s
        })
        .collect()
}

/// Relative errors of ρ_sun and ρ_se per cell and channel (cells with `keep`).
fn errors(refl: &Reflectance, truth: &[[f64; 3]], keep: impl Fn(usize) -> bool) -> (Vec<f64>, Vec<f64>) {
    let (mut sun, mut se) = (Vec::new(), Vec::new());
    for (c, t) in truth.iter().enumerate() {
        if !keep(c) {
            continue;
        }
        for ch in 0..3 {
            sun.push((refl.cells[c].rho_sun[ch] / t[ch] - 1.0).abs());
            se.push((refl.cells[c].rho_se[ch] / t[ch] - 1.0).abs());
        }
    }
    (sun, se)
}

/// Correlation between recovered and true albedos over the cells of one
/// surface (green channel): the texture, not just the mean.
fn texture_correlation(refl: &Reflectance, truth: &[[f64; 3]], surface: usize) -> f64 {
    let ids: Vec<usize> = (0..truth.len())
        .filter(|&c| refl.grid.cells[c].surface == surface && refl.cells[c].status != CellStatus::Unseen)
        .collect();
    let a: Vec<f64> = ids.iter().map(|&c| refl.cells[c].rho_se[1]).collect();
    let b: Vec<f64> = ids.iter().map(|&c| truth[c][1]).collect();
    let n = a.len() as f64;
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    let cov: f64 = a.iter().zip(&b).map(|(x, y)| (x - ma) * (y - mb)).sum();
    let va: f64 = a.iter().map(|x| (x - ma).powi(2)).sum();
    let vb: f64 = b.iter().map(|y| (y - mb).powi(2)).sum();
    cov / (va * vb).sqrt()
}

/// The training day's photos, rendered once for all tests of this file.
fn training_photos(w: &World) -> &'static [Photo] {
    static PHOTOS: std::sync::OnceLock<Vec<Photo>> = std::sync::OnceLock::new();
    PHOTOS.get_or_init(|| photos(w, &TRAINING))
}

fn median_signed(refl: &Reflectance, truth: &[[f64; 3]], surface: usize, sun: bool) -> f64 {
    let mut v: Vec<f64> = (0..truth.len())
        .filter(|&c| refl.grid.cells[c].surface == surface && refl.cells[c].status != CellStatus::Unseen)
        .flat_map(|c| {
            let e = &refl.cells[c];
            (0..3).map(move |ch| if sun { e.rho_sun[ch] } else { e.rho_se[ch] } / truth[c][ch] - 1.0)
        })
        .collect();
    quantile(&mut v, 0.5)
}

fn recover(w: &World, photos: &[Photo], times: &[&str]) -> Reflectance {
    let days = daylights(w, times);
    let lights: Vec<Illumination> = days.iter().map(|(t, d)| Illumination { time: *t, sky: d }).collect();
    let settings = ReflectanceSettings {
        spacing_m: SPACING_M,
        ..ReflectanceSettings::default()
    };
    recover_reflectance(&w.scene.scene, &targets(w), photos, &lights, &settings)
        .unwrap()
        .0
}

/// Thesis §5.4 on the simulated day: pseudo-albedos from the four training
/// times (true sun and sky), and the re-render at the held-out time.
///
/// The simulator's 16-spp photographs carry Monte Carlo noise of several
/// percent per pixel where the sky and the ground light the walls, and its
/// brick texture is finer than the 128-px photos resolve, so a 2 m cell's
/// estimate scatters about its true mean (measured: median |error| ≈ 5.5%
/// for ρ_se, 6% for ρ_sun, p95 ≈ 27% / 90% over all solved cells, the
/// worst on the small pillars). The estimator is unbiased: the median
/// signed error per wall is within 2%. Re-rendered radiance at the
/// held-out time is compared with a 64-spp render at the grid's resolution
/// (4 × 4-pixel blocks ≈ one 2 m cell): the renderer's own noise floor
/// between two 64-spp seeds is 4–9% per pixel, 1–2% per block.
#[test]
fn pseudo_albedos_and_the_held_out_time_match_the_world() {
    let w = world();
    let photos = training_photos(&w);
    let refl = recover(&w, photos, &TRAINING);
    let tr = truth(&w, &refl);
    let solved = |c: usize| refl.cells[c].status == CellStatus::Solved;
    // 688 of 927 seen cells are solved alone since pixels straddling two
    // faces are dropped and grazing-sun cells are filled (973 before, many
    // of them wrong; see tests/outdoor_error_budget.rs).
    assert!(
        refl.count(CellStatus::Solved) > 600,
        "{} cells solved",
        refl.count(CellStatus::Solved)
    );
    let (mut sun, mut se) = errors(&refl, &tr, solved);
    let (ms, ps, me, pe) = (
        quantile(&mut sun, 0.5),
        quantile(&mut sun, 0.95),
        quantile(&mut se, 0.5),
        quantile(&mut se, 0.95),
    );
    eprintln!("ρ_sun |error| median {ms:.4} p95 {ps:.4}; ρ_se median {me:.4} p95 {pe:.4}");
    assert!(ms < 0.08 && me < 0.08, "median errors ρ_sun {ms}, ρ_se {me}");
    for name in ["south-face", "east-face", "north-face", "west-face"] {
        let s = w.scene.scene.surface_index(name).unwrap();
        let (a, b) = (median_signed(&refl, &tr, s, true), median_signed(&refl, &tr, s, false));
        eprintln!("{name}: median signed error ρ_sun {a:+.4} ρ_se {b:+.4}");
        assert!(a.abs() < 0.03 && b.abs() < 0.03, "{name}: bias ρ_sun {a}, ρ_se {b}");
    }
    assert!(refl.photos.iter().all(|p| !p.outlier), "{:?}", refl.photos);
    for name in ["south-face", "east-face", "west-face"] {
        let s = w.scene.scene.surface_index(name).unwrap();
        // Reported, not asserted: the brick texture averaged over 2 m cells
        // varies by a few percent, about as much as the estimates scatter.
        eprintln!("{name}: texture correlation {:.3}", texture_correlation(&refl, &tr, s));
    }

    // The held-out time, with the true sun and sky.
    let held = daylights(&w, &[HELD_OUT]);
    let light = Illumination {
        time: held[0].0,
        sky: &held[0].1,
    };
    let mut fine = w.clone();
    fine.quality.samples_per_pixel = 64;
    for v in ["view-se", "view-sw", "view-nw"] {
        let r = rig(&w, v);
        let reference = fine.render(time(HELD_OUT), &r, &[], 7).unwrap();
        let (image, _) = rerender(&w.scene.scene, &refl, &r, &light, &RerenderSettings::default());
        let mask = target_mask(&w.scene.scene, &refl, &r);
        let pixel = relative_rmse(&image, &reference, &mask).unwrap();
        let block = block_relative_rmse(&image, &reference, &mask, 4);
        eprintln!("{v}: relative RMSE per pixel {pixel:.4}, per 4×4 block {block:.4}");
        assert!(block <= 0.03, "{v}: block relative RMSE {block}");
        assert!(pixel <= 0.12, "{v}: pixel relative RMSE {pixel}");
    }
}

/// A face never sunlit (the north walls, photographed only at noon and in
/// the afternoon) is reported, and its ρ_sun filled from the ratio of its
/// neighbours: within 10% of the truth (median), ρ_se as good as elsewhere.
#[test]
fn a_face_never_sunlit_is_reported_and_filled() {
    let w = world();
    let photos: Vec<Photo> = training_photos(&w)[4..12].to_vec();
    let times = &TRAINING[1..3];
    let refl = recover(&w, &photos, times);
    let tr = truth(&w, &refl);
    let north = w.scene.scene.surface_index("north-face").unwrap();
    let shaft = refl
        .grid
        .faces
        .iter()
        .position(|f| f.surface == north && f.cells.len() > 100)
        .unwrap();
    let face = &refl.grid.faces[shaft];
    let seen: Vec<usize> = face
        .cells
        .iter()
        .copied()
        .filter(|&c| refl.cells[c].status != CellStatus::Unseen)
        .collect();
    assert!(seen.len() > 100);
    assert!(
        seen.iter().all(|&c| refl.cells[c].status == CellStatus::NeverSunlit),
        "statuses {:?}",
        seen.iter().map(|&c| refl.cells[c].status).collect::<Vec<_>>()
    );
    let said = refl
        .diagnostics
        .iter()
        .find(|d| d.contains("north-face") && d.contains("never seen sunlit"));
    assert!(said.is_some(), "diagnostics {:#?}", refl.diagnostics);
    let (mut sun, mut se) = errors(&refl, &tr, |c| seen.contains(&c));
    let (ms, me) = (quantile(&mut sun, 0.5), quantile(&mut se, 0.5));
    eprintln!(
        "north face filled: ρ_sun median |error| {ms:.4}, ρ_se {me:.4}; {}",
        said.unwrap()
    );
    assert!(ms < 0.10 && me < 0.08, "ρ_sun {ms}, ρ_se {me}");
    // The stated uncertainty of the filled ρ_sun is larger than of ρ_se.
    let c = seen[seen.len() / 2];
    assert!(refl.cells[c].sigma_sun[1] > refl.cells[c].sigma_se[1]);
}

/// A photo whose exposure metadata is wrong by a factor of two (its
/// radiance doubled) is caught as an outlier and left out; the others are
/// kept and the estimates stay as good as without it.
#[test]
fn a_photo_with_a_wrong_exposure_is_rejected() {
    let w = world();
    let mut photos: Vec<Photo> = training_photos(&w).to_vec();
    for v in photos[5].image.data.iter_mut() {
        *v *= 2.0;
    }
    let refl = recover(&w, &photos, &TRAINING);
    let flagged: Vec<usize> = (0..photos.len()).filter(|&k| refl.photos[k].outlier).collect();
    eprintln!(
        "flagged {flagged:?}; {:?}",
        refl.diagnostics.iter().find(|d| d.contains("outlier"))
    );
    assert_eq!(flagged, vec![5]);
    assert!(refl.photos[5].median_log_ratio > 0.4, "{:?}", refl.photos[5]);
    let tr = truth(&w, &refl);
    let (mut sun, mut se) = errors(&refl, &tr, |c| refl.cells[c].status == CellStatus::Solved);
    let (ms, me) = (quantile(&mut sun, 0.5), quantile(&mut se, 0.5));
    assert!(ms < 0.08 && me < 0.08, "ρ_sun {ms}, ρ_se {me}");
}

/// Without the evening, cells lose their sunlit or shadowed view and are
/// filled; the estimates degrade but their stated uncertainty says so:
/// at least 80% of the errors lie within three stated standard deviations.
#[test]
fn a_missing_time_degrades_with_stated_uncertainty() {
    let w = world();
    let photos: Vec<Photo> = training_photos(&w)[..12].to_vec();
    let refl = recover(&w, &photos, &TRAINING[..3]);
    let tr = truth(&w, &refl);
    let seen: Vec<usize> = (0..tr.len())
        .filter(|&c| refl.cells[c].status != CellStatus::Unseen)
        .collect();
    let (mut inside, mut total) = (0, 0);
    for &c in &seen {
        let e = &refl.cells[c];
        for ch in 0..3 {
            for (est, sigma) in [(e.rho_sun[ch], e.sigma_sun[ch]), (e.rho_se[ch], e.sigma_se[ch])] {
                total += 1;
                if (est - tr[c][ch]).abs() <= 3.0 * sigma {
                    inside += 1;
                }
            }
        }
    }
    let coverage = f64::from(inside) / f64::from(total);
    let filled = seen.len() - refl.count(CellStatus::Solved);
    let (mut sun, mut se) = errors(&refl, &tr, |c| seen.contains(&c));
    let (ms, me) = (quantile(&mut sun, 0.5), quantile(&mut se, 0.5));
    eprintln!(
        "3 times: {filled} of {} seen cells filled; coverage of 3σ {coverage:.3}; median |error| ρ_sun {ms:.4} ρ_se {me:.4}",
        seen.len()
    );
    assert!(coverage >= 0.8, "coverage {coverage}");
    assert!(ms < 0.12 && me < 0.10, "ρ_sun {ms}, ρ_se {me}");
}

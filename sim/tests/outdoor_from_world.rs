//! Outdoor reflectance recovery and re-rendering (thesis §5.4–§5.6) against
//! the simulated campanile day: pseudo-albedos recovered from the four
//! training times against the world's true ones, and re-renders at the
//! held-out time against the world's own render.

// Channel loops index several arrays at once; they read better with an index.
#![allow(clippy::needless_range_loop)]

use std::sync::OnceLock;

use campanile_process::error_figures::{block_relative_rmse, quantile};
use campanile_process::outdoor::rerender::{relative_rmse, target_mask};
use campanile_process::outdoor::{
    CellStatus, Illumination, Photo, Reflectance, ReflectanceSettings, RerenderSettings, recover_reflectance, rerender,
};
use campanile_sim::world::campanile_day::{
    CampanileDay, HELD_OUT_VIEWS, held_out_time, illuminations, texture_correlation, training_times,
};
use chrono::{DateTime, Utc};

const WIDTH: usize = 128;
const HEIGHT: usize = 96;

/// Grid spacing of the tests, metres (about three pixels of the 128-px photos).
const SPACING_M: f64 = 2.0;

/// The day at 16 samples per pixel, 2 bounces, set up once for all tests of this file.
fn day() -> &'static CampanileDay {
    static DAY: OnceLock<CampanileDay> = OnceLock::new();
    DAY.get_or_init(|| CampanileDay::load(16, 2).unwrap())
}

/// The true pseudo-albedo of each cell (64 × 64 points per cell).
fn truth(refl: &Reflectance) -> Vec<[f64; 3]> {
    day().cell_truth(&refl.grid, 64)
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

/// The training day's photos, rendered once for all tests of this file.
fn training_photos() -> &'static [Photo] {
    static PHOTOS: OnceLock<Vec<Photo>> = OnceLock::new();
    PHOTOS.get_or_init(|| day().photographs(&training_times(), WIDTH, HEIGHT).unwrap())
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

fn recover(photos: &[Photo], times: &[DateTime<Utc>]) -> Reflectance {
    let days = day().daylights(times).unwrap();
    let settings = ReflectanceSettings {
        spacing_m: SPACING_M,
        ..ReflectanceSettings::default()
    };
    let scene = &day().world.scene.scene;
    recover_reflectance(
        scene,
        &day().targets().unwrap(),
        photos,
        &illuminations(&days),
        &settings,
    )
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
    let w = &day().world;
    let photos = training_photos();
    let refl = recover(photos, &training_times());
    let tr = truth(&refl);
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
    let held = day().daylight(held_out_time()).unwrap();
    let light = Illumination {
        time: held_out_time(),
        sky: &held,
    };
    let mut fine = w.clone();
    fine.quality.samples_per_pixel = 64;
    for v in HELD_OUT_VIEWS {
        let r = day().view_rig(v, WIDTH, HEIGHT).unwrap();
        let reference = fine.render(held_out_time(), &r, &[], 7).unwrap();
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
    let w = &day().world;
    let photos: Vec<Photo> = training_photos()[4..12].to_vec();
    let refl = recover(&photos, &training_times()[1..3]);
    let tr = truth(&refl);
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
    let mut photos: Vec<Photo> = training_photos().to_vec();
    for v in photos[5].image.data.iter_mut() {
        *v *= 2.0;
    }
    let refl = recover(&photos, &training_times());
    let flagged: Vec<usize> = (0..photos.len()).filter(|&k| refl.photos[k].outlier).collect();
    eprintln!(
        "flagged {flagged:?}; {:?}",
        refl.diagnostics.iter().find(|d| d.contains("outlier"))
    );
    assert_eq!(flagged, vec![5]);
    assert!(refl.photos[5].median_log_ratio > 0.4, "{:?}", refl.photos[5]);
    let tr = truth(&refl);
    let (mut sun, mut se) = errors(&refl, &tr, |c| refl.cells[c].status == CellStatus::Solved);
    let (ms, me) = (quantile(&mut sun, 0.5), quantile(&mut se, 0.5));
    assert!(ms < 0.08 && me < 0.08, "ρ_sun {ms}, ρ_se {me}");
}

/// Without the evening, cells lose their sunlit or shadowed view and are
/// filled; the estimates degrade but their stated uncertainty says so:
/// at least 80% of the errors lie within three stated standard deviations.
#[test]
fn a_missing_time_degrades_with_stated_uncertainty() {
    let photos: Vec<Photo> = training_photos()[..12].to_vec();
    let refl = recover(&photos, &training_times()[..3]);
    let tr = truth(&refl);
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

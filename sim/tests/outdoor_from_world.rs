//! Outdoor reflectance recovery and re-rendering (thesis §5.4–§5.6) against
//! the simulated campanile day: pseudo-albedos recovered from the four
//! training times against the world's true ones, and re-renders at the
//! held-out time against the world's own render.

// Channel loops index several arrays at once; they read better with an index.
#![allow(clippy::needless_range_loop)]

use campanile_process::camera::image::RadianceImage;
use campanile_process::outdoor::rerender::{relative_rmse, target_mask};
use campanile_process::outdoor::{
    CellStatus, Illumination, Photo, Reflectance, ReflectanceSettings, RerenderSettings, recover_reflectance,
    rerender,
};
use campanile_process::pose::HeadPose;
use campanile_process::render::CameraRig;
use campanile_process::sky::Daylight;
use campanile_sim::world::{World, examples_dir, load_scene};
use chrono::{DateTime, Utc};

fn width() -> usize { std::env::var("W").map(|v| v.parse().unwrap()).unwrap_or(128) }
fn height() -> usize { width() * 3 / 4 }

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
    w.quality.samples_per_pixel = std::env::var("SPP").map(|v| v.parse().unwrap()).unwrap_or(16);
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
    w.rig(head, [x, y, z], width(), height())
}

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
            let pts = refl.grid.cell_points(&w.scene.scene, c, 8);
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

fn quantile(v: &[f64], q: f64) -> f64 {
    let mut v = v.to_vec();
    v.sort_by(|a, b| a.total_cmp(b));
    v[((v.len() - 1) as f64 * q).round() as usize]
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

fn recover(w: &World, photos: &[Photo], times: &[&str]) -> Reflectance {
    let days = daylights(w, times);
    let lights: Vec<Illumination> = days.iter().map(|(t, d)| Illumination { time: *t, sky: d }).collect();
    let mut settings = ReflectanceSettings {
        spacing_m: std::env::var("SPACING").map(|v| v.parse().unwrap()).unwrap_or(2.0),
        ..ReflectanceSettings::default()
    };
    settings.gather.bounce_rays_per_side = 20;
    recover_reflectance(&w.scene.scene, &targets(w), photos, &lights, &settings)
        .unwrap()
        .0
}

#[test]
fn explore() {
    let w = world();
    let t0 = std::time::Instant::now();
    let ph = photos(&w, &TRAINING);
    eprintln!("photos {:?}", t0.elapsed());
    let refl = recover(&w, &ph, &TRAINING);
    eprintln!("recover {:?}", t0.elapsed());
    let tr = truth(&w, &refl);
    for s in [CellStatus::Solved, CellStatus::NeverSunlit, CellStatus::NeverShadowed, CellStatus::IllConditioned, CellStatus::Unseen] {
        let (a, b) = errors(&refl, &tr, |c| refl.cells[c].status == s);
        if !a.is_empty() {
            eprintln!("{s:?}: {} cells; sun median {:.4} p95 {:.4}; se median {:.4} p95 {:.4}", a.len() / 3, quantile(&a, 0.5), quantile(&a, 0.95), quantile(&b, 0.5), quantile(&b, 0.95));
        }
    }
    let seen = |c: usize| refl.cells[c].status != CellStatus::Unseen;
    let (a, b) = errors(&refl, &tr, seen);
    eprintln!("seen: sun median {:.4} p95 {:.4}; se median {:.4} p95 {:.4}", quantile(&a, 0.5), quantile(&a, 0.95), quantile(&b, 0.5), quantile(&b, 0.95));
    for s in 0..6 {
        let surf = targets(&w)[s];
        eprintln!("surface {} texture corr {:.3}", w.scene.scene.surfaces()[surf], texture_correlation(&refl, &tr, surf));
    }
    for s in 0..5 {
        let surf = targets(&w)[s];
        let mut v: Vec<f64> = (0..tr.len()).filter(|&c| refl.grid.cells[c].surface == surf && refl.cells[c].status == CellStatus::Solved).map(|c| refl.cells[c].rho_se[1] / tr[c][1] - 1.0).collect();
        let mut u: Vec<f64> = (0..tr.len()).filter(|&c| refl.grid.cells[c].surface == surf && refl.cells[c].status == CellStatus::Solved).map(|c| refl.cells[c].rho_sun[1] / tr[c][1] - 1.0).collect();
        if v.is_empty() { continue; }
        v.sort_by(|a, b| a.total_cmp(b)); u.sort_by(|a, b| a.total_cmp(b));
        eprintln!("signed {}: se q25 {:.3} q50 {:.3} q75 {:.3} | sun q25 {:.3} q50 {:.3} q75 {:.3}", w.scene.scene.surfaces()[surf], v[v.len()/4], v[v.len()/2], v[3*v.len()/4], u[u.len()/4], u[u.len()/2], u[3*u.len()/4]);
    }
    let mut perfect = refl.clone();
    for c in 0..tr.len() { perfect.cells[c].rho_se = tr[c]; perfect.cells[c].rho_sun = tr[c]; }
    if std::env::var("DIAG").is_ok() { for d in &refl.diagnostics { eprintln!("{d}"); } }
    for p in &refl.photos { eprintln!("{:?} {:.4} {}", p.label, p.median_log_ratio, p.observations); }
    eprintln!("{:?}", refl.sampling);
    // Held-out.
    let held = daylights(&w, &[HELD_OUT]);
    let light = Illumination { time: held[0].0, sky: &held[0].1 };
    for v in ["view-se", "view-sw", "view-nw"] {
        let r = rig(&w, v);
        let mut wq = w.clone();
        wq.quality.samples_per_pixel = 64;
        let reference: RadianceImage = wq.render(time(HELD_OUT), &r, &[], 7).unwrap();
        for (bil, rf) in [(false, &refl), (true, &refl), (true, &perfect)] {
            let (img, _) = rerender(&w.scene.scene, rf, &r, &light, &RerenderSettings { bilinear: bil, ..Default::default() });
            let mask = target_mask(&w.scene.scene, &refl, &r);
            eprintln!("{v} bilinear {bil}: rel rmse {:.4}", relative_rmse(&img, &reference, &mask).unwrap());
        }
    }
    eprintln!("total {:?}", t0.elapsed());
}

#[test]
fn explore_irradiance() {
    let w = world();
    let ph = photos(&w, &TRAINING[..2]);
    let days = daylights(&w, &TRAINING[..2]);
    let lights: Vec<Illumination> = days.iter().map(|(t, d)| Illumination { time: *t, sky: d }).collect();
    let mut settings = ReflectanceSettings { spacing_m: 2.0, ..ReflectanceSettings::default() };
    let b: usize = std::env::var("BOUNCE").map(|v| v.parse().unwrap()).unwrap_or(16);
    let e: usize = std::env::var("ENVRAYS").map(|v| v.parse().unwrap()).unwrap_or(6);
    let ts: u32 = std::env::var("TRUTHS").map(|v| v.parse().unwrap()).unwrap_or(4000);
    settings.gather.bounce_rays_per_side = b;
    settings.gather.environment_rays_per_side = e;
    let t0 = std::time::Instant::now();
    let (refl, tls) = recover_reflectance(&w.scene.scene, &targets(&w), &ph, &lights, &settings).unwrap();
    eprintln!("recover {:?}", t0.elapsed());
    let tr = truth(&w, &refl);
    let mut ratios = Vec::new();
    for c in (0..refl.grid.cells.len()).step_by(37) {
        let cell = &refl.grid.cells[c];
        for (k, tl) in tls.iter().enumerate() {
            let se = tl.se_irradiance(c, &tr, &tr);
            let sun = tl.sun_irradiance(c);
            let vis = tl.sun.map_or(false, |s| campanile_process::outdoor::cell_irradiance::sun_visible(&w.scene.scene, &s, &cell.centre, &cell.normal));
            let mine: Vec<f64> = (0..3).map(|ch| se[ch] + if vis { sun[ch] } else { 0.0 }).collect();
            let p = cell.centre;
            let n = cell.normal;
            let truth_e = w.irradiance(lights[k].time, [p.x, p.y, p.z], [n.x, n.y, n.z], &[], ts, 3).unwrap();
            let sky_only = tl.cells[c].sky;
            eprintln!("cell {c} {} t{k} vis {vis}: mine {:.1} truth {:.1} ratio {:.3}  sky {:.1} env {:.1} refl {:.1}", w.scene.scene.surfaces()[cell.surface], mine[1], truth_e[1], mine[1] / truth_e[1], sky_only[1], tl.cells[c].environment[1], se[1] - sky_only[1] - tl.cells[c].environment[1]);
            ratios.push(mine[1] / truth_e[1]);
        }
    }
    eprintln!("median ratio {:.4}", quantile(&ratios, 0.5));
}

#[test]
fn explore_obs() {
    use campanile_process::outdoor::observation::observe;
    let w = world();
    let ph = photos(&w, &TRAINING);
    let days = daylights(&w, &TRAINING);
    let lights: Vec<Illumination> = days.iter().map(|(t, d)| Illumination { time: *t, sky: d }).collect();
    let mut settings = ReflectanceSettings { spacing_m: std::env::var("SPACING").map(|v| v.parse().unwrap()).unwrap_or(2.0), ..ReflectanceSettings::default() };
    settings.gather.bounce_rays_per_side = 20;
    let (refl, tls) = recover_reflectance(&w.scene.scene, &targets(&w), &ph, &lights, &settings).unwrap();
    let tr = truth(&w, &refl);
    let times: Vec<usize> = (0..ph.len()).map(|k| k / 4).collect();
    let (obs, _) = observe(&w.scene.scene, &refl.grid, &ph, &lights, &times).unwrap();
    let mut all = Vec::new();
    for o in &obs {
        let c = o.cell;
        let tl = &tls[o.time];
        let se = tl.se_irradiance(c, &tr, &tr);
        let sun = if o.sunlit { tl.sun_irradiance(c) } else { [0.0; 3] };
        let r = std::f64::consts::PI * o.radiance[1] / (tr[c][1] * (se[1] + sun[1]));
        all.push(r);
        if c % 97 == 0 {
            eprintln!("cell {c} {} photo {} t{} lit {} px {} ratio {:.3}  (E_se {:.1} E_sun {:.1}) est se {:.3} sun {:.3} truth {:.3}", w.scene.scene.surfaces()[refl.grid.cells[c].surface], o.photo, o.time, o.sunlit, o.pixels, r, se[1], sun[1], refl.cells[c].rho_se[1], refl.cells[c].rho_sun[1], tr[c][1]);
        }
    }
    let dev: Vec<f64> = all.iter().map(|r| (r - 1.0).abs()).collect();
    eprintln!("obs ratio: median {:.4} |dev| median {:.4} p90 {:.4}", quantile(&all, 0.5), quantile(&dev, 0.5), quantile(&dev, 0.9));
}

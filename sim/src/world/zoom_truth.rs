//! Ground truth for a zoom photograph of the world (thesis §5.6.4): the
//! station's camera at a longer focal length aimed at a surface point, the
//! world's true pseudo-albedos averaged over each grid cell (what a perfect
//! reflectance recovery would give, the `ρ̃` of eq. 5.16), and the true
//! pseudo-albedo seen by each pixel.

// Channel loops index several arrays at once; they read better with an index.
#![allow(clippy::needless_range_loop)]

use campanile_process::outdoor::estimate::{CellEstimate, CellStatus, Reflectance};
use campanile_process::outdoor::grid::Grid;
use campanile_process::outdoor::observation::SamplingReport;
use campanile_process::pose::HeadPose;
use campanile_process::render::CameraRig;
use nalgebra::Vector3;

use super::World;

/// The world's camera at `position_m`, its optical axis through
/// `look_at_m`, its focal length `zoom` times the station camera's, with a
/// `width` × `height` image (level head: the mount's level offsets are
/// ignored, as in plan checking).
pub fn zoom_rig(
    world: &World,
    position_m: [f64; 3],
    look_at_m: [f64; 3],
    zoom: f64,
    width: usize,
    height: usize,
) -> CameraRig {
    let d = Vector3::from(look_at_m) - Vector3::from(position_m);
    let azimuth = d.x.atan2(d.y);
    let elevation = d.z.atan2(d.x.hypot(d.y));
    let head = HeadPose {
        pan_rad: azimuth - world.mount.pan_zero_azimuth_rad,
        tilt_rad: elevation + world.mount.tilt_zero_rad,
    };
    let mut rig = world.rig(head, position_m, width, height);
    rig.pinhole.focal_px *= zoom;
    rig
}

/// The true pseudo-albedos averaged over each cell of `grid` from
/// `per_side`² sub-samples (64 keeps the 5 cm mortar joints from aliasing,
/// `tests/outdoor_error_budget.rs`), as a [`Reflectance`] whose cells are
/// all `Solved` with zero uncertainty.
pub fn cell_mean_reflectance(world: &World, grid: Grid, per_side: usize) -> Reflectance {
    let cells = (0..grid.cells.len())
        .map(|c| {
            let pts = grid.cell_points(&world.scene.scene, c, per_side);
            let tri = grid.cells[c].triangle;
            let mut sun = [0.0; 3];
            let mut se = [0.0; 3];
            for p in &pts {
                let a = world.pseudo_albedos(tri, [p.x, p.y, p.z]);
                for ch in 0..3 {
                    sun[ch] += a.sun[ch] / pts.len() as f64;
                    se[ch] += a.sky_environment[ch] / pts.len() as f64;
                }
            }
            CellEstimate {
                rho_sun: sun,
                rho_se: se,
                sigma_sun: [0.0; 3],
                sigma_se: [0.0; 3],
                status: CellStatus::Solved,
                condition: 1.0,
                amplification: 1.0,
                observations: 0,
                rms_relative: 0.0,
            }
        })
        .collect();
    let faces = grid.faces.len();
    Reflectance {
        grid,
        cells,
        photos: Vec::new(),
        sampling: SamplingReport::default(),
        face_ratio: vec![[1.0; 3]; faces],
        diagnostics: vec!["the world's true pseudo-albedos, averaged over each cell".into()],
    }
}

/// The true pseudo-albedo ρ^sun (= ρ^se in this world) seen by each pixel
/// of `rig`: the mean over `per_side`² rays spread over the pixel, of those
/// that meet the triangle's face of the centre ray; `None` where the centre
/// ray meets no target of `grid`.
pub fn pixel_albedo_truth(world: &World, grid: &Grid, rig: &CameraRig, per_side: usize) -> Vec<Option<[f64; 3]>> {
    let scene = &world.scene.scene;
    let rays = rig.rays();
    let n = per_side.max(1);
    (0..rig.width * rig.height)
        .map(|i| {
            let (x, y) = ((i % rig.width) as f64, (i / rig.width) as f64);
            let centre = scene.intersect(&rays.ray(x + 0.5, y + 0.5)?, f64::INFINITY)?;
            let face = grid.face_of(centre.triangle)?;
            let mut sum = [0.0; 3];
            let mut k = 0usize;
            for a in 0..n {
                for b in 0..n {
                    let u = x + (a as f64 + 0.5) / n as f64;
                    let v = y + (b as f64 + 0.5) / n as f64;
                    let Some(hit) = rays.ray(u, v).and_then(|r| scene.intersect(&r, f64::INFINITY)) else {
                        continue;
                    };
                    if grid.face_of(hit.triangle) != Some(face) {
                        continue;
                    }
                    let p = world.pseudo_albedos(hit.triangle, [hit.point.x, hit.point.y, hit.point.z]);
                    for ch in 0..3 {
                        sum[ch] += p.sun[ch];
                    }
                    k += 1;
                }
            }
            (k > 0).then(|| sum.map(|s| s / k as f64))
        })
        .collect()
}

//! The irradiance the outdoor solver gathers at chosen points (thesis §5.4):
//! sun (n·s E_sun), sky (App. B, occluded), environment bounce and the
//! target-to-target bounce with the true albedo, per time of a light file,
//! for comparison with another renderer's irradiance at the same points
//! (`validation/outdoor`: `rtrace -I`).
//!
//! `cargo run --release -p campanile-process --example outdoor_cell_light -- \
//!    SCENE.ron PHOTOS.ron LIGHT.ron ALBEDO x,y,z [x,y,z ...]` (ALBEDO: the
//!    targets' true albedo, green, for the target bounce).

use std::path::Path;

use campanile_process::outdoor::Illumination;
use campanile_process::outdoor::cell_irradiance::{GatherSettings, gather};
use campanile_process::outdoor::grid::Grid;
use campanile_process::outdoor::light_file::load_light;
use campanile_process::outdoor::photo_file::load_photos;
use campanile_process::outdoor::scene_file::load_scene;
use nalgebra::Vector3;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 5 {
        return Err("usage: outdoor_cell_light SCENE.ron PHOTOS.ron LIGHT.ron ALBEDO x,y,z ...".into());
    }
    let scene = load_scene(Path::new(&args[0]))?;
    let views = load_photos(Path::new(&args[1]))?;
    let lights = load_light(Path::new(&args[2]))?;
    let albedo: f64 = args[3].parse()?;
    let viewpoints: Vec<Vector3<f64>> = views.iter().map(|v| v.rig.position).collect();
    let grid = Grid::new(&scene.scene, &scene.targets, 1.0, &viewpoints)?;
    let points: Vec<Vector3<f64>> = args[4..]
        .iter()
        .map(|s| {
            let v: Vec<f64> = s.split(',').map(|x| x.parse().unwrap()).collect();
            Vector3::new(v[0], v[1], v[2])
        })
        .collect();
    let cells: Vec<usize> = points
        .iter()
        .map(|p| {
            (0..grid.cells.len())
                .min_by(|&a, &b| {
                    (grid.cells[a].centre - p)
                        .norm()
                        .total_cmp(&(grid.cells[b].centre - p).norm())
                })
                .unwrap()
        })
        .collect();
    println!("time,cell,x,y,z,nx,ny,nz,sun_cos,e_sun_g,e_sky_g,e_env_g,e_targets_g,e_se_g");
    for l in &lights {
        let illum = Illumination {
            time: l.time,
            sky: &l.sky,
        };
        let tl = gather(&scene.scene, &grid, &illum, &GatherSettings::default());
        let n = grid.cells.len();
        let rho = vec![[albedo; 3]; n];
        for &k in &cells {
            let c = &grid.cells[k];
            let cl = &tl.cells[k];
            let e_se = tl.se_irradiance(k, &rho, &rho);
            let targets = e_se[1] - cl.sky[1] - cl.environment[1];
            println!(
                "{},{k},{:.3},{:.3},{:.3},{:.3},{:.3},{:.3},{:.4},{:.3},{:.3},{:.3},{:.3},{:.3}",
                l.time.to_rfc3339(),
                c.centre.x,
                c.centre.y,
                c.centre.z,
                c.normal.x,
                c.normal.y,
                c.normal.z,
                cl.sun_cosine,
                tl.sun_irradiance(k)[1],
                cl.sky[1],
                cl.environment[1],
                targets,
                e_se[1]
            );
        }
    }
    Ok(())
}

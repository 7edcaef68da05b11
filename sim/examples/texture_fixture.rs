//! The inputs of the independent texture check (`validation/texture`):
//! the floodlit campanile (`campanile_sim::world::texture_truth`)
//! photographed from three of the example scene's poses through the
//! station's lens (HDR, 2% noise), the poses file `campanile texture`
//! takes, and a noise-free check view from another place through an
//! undistorted pinhole, with its camera as JSON for Mitsuba.
//!
//! ```text
//! cargo run -p campanile-sim --example texture_fixture -- OUT_DIR
//! ```

use std::path::PathBuf;

use campanile_process::camera::image::RadianceImage;
use campanile_process::exr_io::{ExrPrecision, write_rgb_exr};
use campanile_process::hdr::merge::RadianceMap;
use campanile_process::pose::Pinhole;
use campanile_process::render::CameraRig;
use campanile_process::texture::{TexturePhoto, pose_from_angles};
use campanile_sim::world::examples_dir;
use campanile_sim::world::texture_truth::TextureWorld;
use nalgebra::Vector3;

const W: usize = 640;
const H: usize = 480;

fn write(image: RadianceImage, path: &std::path::Path) -> Result<(), Box<dyn std::error::Error>> {
    let map = RadianceMap {
        width: image.width,
        height: image.height,
        rgb: image.data,
        variance: Vec::new(),
        mask: Vec::new(),
    };
    write_rgb_exr(&map, path, ExrPrecision::Float)?;
    Ok(())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = PathBuf::from(std::env::args().nth(1).ok_or("usage: texture_fixture OUT_DIR")?);
    std::fs::create_dir_all(out.join("photos"))?;
    let mut world = TextureWorld::campanile()?;
    let station = campanile_config::load_station(&examples_dir().join("sim-station.ron"))?.value;
    let c = &station.camera;
    let pinhole = Pinhole::of_camera(c).rescaled((c.resolution.width as usize, c.resolution.height as usize), W, H);
    let scene = campanile_config::document::load_scene(&examples_dir().join("campanile-scene.ron"))?.value;
    let mut poses = String::from("RegisteredPoses(\n    poses: [\n");
    for (k, name) in ["view-se", "view-sw", "view-ne"].iter().enumerate() {
        let p = scene.pose(name).ok_or("pose")?;
        let (x, y, z) = p.position_m;
        let pose = pose_from_angles(Vector3::new(x, y, z), p.azimuth_deg, p.elevation_deg, 0.0).ok_or("pose")?;
        let blank = RadianceImage {
            width: W,
            height: H,
            data: vec![0.0; W * H * 3],
        };
        let photo = TexturePhoto::new(name, blank, &pose, pinhole)?;
        write(
            world.photograph(&photo.rig, k as u64 + 1),
            &out.join("photos").join(format!("{name}.exr")),
        )?;
        poses += &format!(
            "        (name: \"{name}\", position_m: ({x}, {y}, {z}), azimuth_deg: {}, elevation_deg: {}),\n",
            p.azimuth_deg, p.elevation_deg
        );
    }
    poses += "    ],\n    photos: [],\n)\n";
    std::fs::write(out.join("poses.ron"), poses)?;
    // The check view: south-east of the tower, between the photos' places.
    let (position, target, vfov_deg, cw, ch) = ([25.0, -55.0, 1.8], [0.0, 0.0, 30.0], 40.0, 320usize, 240usize);
    let look = Vector3::from(target) - Vector3::from(position);
    let rig = CameraRig::look_at(
        Vector3::from(position),
        look,
        Vector3::z(),
        f64::to_radians(vfov_deg),
        cw,
        ch,
    )
    .ok_or("check camera")?;
    world.noise = 0.0;
    world.samples_per_side = 4;
    write(world.photograph(&rig, 99), &out.join("check.exr"))?;
    std::fs::write(
        out.join("check-camera.json"),
        format!(
            "{{\"position\": {position:?}, \"target\": {target:?}, \"up\": [0.0, 0.0, 1.0], \"vfov_deg\": {vfov_deg}, \
             \"width\": {cw}, \"height\": {ch}}}\n"
        ),
    )?;
    println!("fixture written to {}", out.display());
    Ok(())
}

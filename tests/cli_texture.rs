//! `campanile texture` as a user runs it: HDR photographs of the floodlit
//! tower with their registered poses in, a textured OBJ out that `tobj`
//! and `image` read back; and its errors and exit statuses.

mod common;

use campanile_process::camera::image::RadianceImage;
use campanile_process::exr_io::{ExrPrecision, write_rgb_exr};
use campanile_process::hdr::merge::RadianceMap;
use campanile_process::pose::Pinhole;
use campanile_process::texture::{TexturePhoto, pose_from_angles};
use campanile_sim::world::examples_dir;
use campanile_sim::world::texture_truth::TextureWorld;
use common::campanile;
use nalgebra::Vector3;

const W: usize = 320;
const H: usize = 240;

/// Renders the pose's photograph into `dir/NAME.exr`.
fn shoot(world: &TextureWorld, dir: &std::path::Path, name: &str, p: [f64; 3], az: f64, el: f64, roll: f64) {
    let s = campanile_config::load_station(&examples_dir().join("sim-station.ron"))
        .expect("station")
        .value;
    let c = &s.camera;
    let pinhole = Pinhole::of_camera(c).rescaled((c.resolution.width as usize, c.resolution.height as usize), W, H);
    let pose = pose_from_angles(Vector3::from(p), az, el, roll).expect("pose");
    let blank = RadianceImage {
        width: W,
        height: H,
        data: vec![0.0; W * H * 3],
    };
    let photo = TexturePhoto::new(name, blank, &pose, pinhole).expect("photo");
    let image = world.photograph(&photo.rig, 11);
    let map = RadianceMap {
        width: W,
        height: H,
        rgb: image.data,
        variance: Vec::new(),
        mask: Vec::new(),
    };
    write_rgb_exr(&map, &dir.join(format!("{name}.exr")), ExrPrecision::Float).expect("exr");
}

fn s(p: &std::path::Path) -> &str {
    p.to_str().expect("utf-8")
}

#[test]
fn registered_photos_make_a_textured_obj_that_reads_back() {
    let world = TextureWorld::campanile().expect("world");
    let dir = tempfile::tempdir().expect("tempdir");
    let photos = dir.path().join("photos");
    std::fs::create_dir_all(&photos).expect("dir");
    shoot(&world, &photos, "left", [-30.0, -45.0, 1.5], 33.0, 28.0, 0.0);
    shoot(&world, &photos, "right", [25.0, -50.0, 1.5], 333.0, 28.0, 4.0);
    let poses = dir.path().join("poses.ron");
    std::fs::write(
        &poses,
        "RegisteredPoses(\n  poses: [\n    (name: \"left\", position_m: (-30.0, -45.0, 1.5), azimuth_deg: 33.0, elevation_deg: 28.0),\n    \
         (name: \"right\", position_m: (25.0, -50.0, 1.5), azimuth_deg: 333.0, elevation_deg: 28.0),\n  ],\n  \
         photos: [],\n)\n",
    )
    .expect("poses");
    let out = dir.path().join("textured");
    let run = campanile(&[
        "texture",
        s(&examples_dir().join("campanile-scene.ron")),
        "--poses",
        s(&poses),
        "--station",
        s(&examples_dir().join("sim-station.ron")),
        "--photos",
        s(&photos),
        "--surface",
        "south-face",
        "--texel",
        "0.5",
        "--out",
        s(&out),
    ]);
    let stdout = String::from_utf8_lossy(&run.stdout);
    let stderr = String::from_utf8_lossy(&run.stderr);
    // The "right" photo's roll is 4° but the file says 0: still a texture, poorer.
    assert_eq!(run.status.code(), Some(0), "{stdout}\n{stderr}");
    assert!(
        stdout.contains("texture: ok") || stdout.contains("texture: poor"),
        "{stdout}"
    );
    let (models, materials) = tobj::load_obj(
        out.join("model.obj"),
        &tobj::LoadOptions {
            single_index: true,
            triangulate: true,
            ..Default::default()
        },
    )
    .expect("the OBJ parses");
    let materials = materials.expect("the MTL parses");
    assert_eq!(materials[0].diffuse_texture.as_deref(), Some("page_0.png"));
    assert_eq!(models.len(), 2, "shaft and belfry patches of the south face");
    assert!(models.iter().all(|m| m.name == "south-face"));
    let png = image::open(out.join("page_0.png")).expect("the preview reads");
    let exr = campanile_process::exr_io::read_rgb_exr(&out.join("page_0.exr")).expect("the EXR reads");
    assert_eq!((png.width() as usize, png.height() as usize), (exr.width, exr.height));
    let manifest = std::fs::read_to_string(out.join("texture.ron")).expect("manifest");
    assert!(
        manifest.contains("coverage") && manifest.contains("\"left\""),
        "{manifest}"
    );
}

#[test]
fn bad_input_is_named_and_exits_2() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scene = examples_dir().join("campanile-scene.ron");
    let station = examples_dir().join("sim-station.ron");
    let bad_texel = campanile(&[
        "texture",
        s(&scene),
        "--station",
        s(&station),
        "--texel",
        "0",
        "--out",
        s(dir.path()),
    ]);
    assert_eq!(bad_texel.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad_texel.stderr).contains("--texel 0"));
    // The scene's own poses, but no photographs where they are looked for.
    let missing = campanile(&[
        "texture",
        s(&scene),
        "--station",
        s(&station),
        "--photos",
        s(dir.path()),
        "--out",
        s(dir.path()),
    ]);
    assert_eq!(missing.status.code(), Some(2));
    let err = String::from_utf8_lossy(&missing.stderr);
    assert!(err.contains("view-se") && err.contains("view-se.exr"), "{err}");
    let albedo = campanile(&[
        "texture",
        s(&scene),
        "--station",
        s(&station),
        "--albedo",
        "--out",
        s(dir.path()),
    ]);
    assert_eq!(albedo.status.code(), Some(2));
}

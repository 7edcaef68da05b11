//! `campanile igi` reads the inputs other renderers and cameras give
//! (issue 24): images in RADIANCE RGBE and PFM beside OpenEXR, cameras as a
//! RADIANCE view string (given or from the picture's header) or a
//! horizontal field of view on a non-square picture, lights as RADIANCE
//! `light` spheres; each imported and checked against a known number, and
//! bad input refused with exit 2 naming the file, field and value.
//!
//! References made by RADIANCE and OpenCV are in
//! `validation/radiance-inputs/fixtures` (made by its `make_fixtures.sh`).

mod common;

use std::path::{Path, PathBuf};

use campanile_process::hdr::merge::RadianceMap;
use campanile_process::igi::scene_file::{load, load_lights};
use campanile_process::rgbe_file::write_rgbe;
use common::campanile;
use nalgebra::Vector3;

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("validation/radiance-inputs/fixtures")
}

/// A directory with a one-quad OBJ, the RADIANCE sphere render, a 48x30
/// RGBE image written by Campanile and a 48x30 PFM.
fn scene_dir() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(
        d.join("q.obj"),
        "v 0 3 0\nv 3 3 0\nv 3 3 2\nv 0 3 2\ng wall\nf 1 2 3 4\n",
    )
    .unwrap();
    std::fs::copy(fixtures().join("sphere-48x30.hdr"), d.join("sphere.hdr")).unwrap();
    let (w, h) = (48, 30);
    let rgb: Vec<f32> = (0..w * h * 3).map(|i| 0.5 + (i % 7) as f32 * 0.25).collect();
    let map = RadianceMap {
        width: w,
        height: h,
        rgb: rgb.clone(),
        variance: vec![0.0; w * h * 3],
        mask: vec![0; w * h],
    };
    write_rgbe(&map, &d.join("wall.pic")).unwrap();
    // PFM: little endian, bottom row first; pixel (x, y) = x + 100 y in R.
    let mut pfm = format!("PF\n{w} {h}\n-1.0\n").into_bytes();
    for row in 0..h {
        let y = h - 1 - row;
        for x in 0..w {
            for c in 0..3 {
                pfm.extend(((x + 100 * y) as f32 + c as f32 * 0.5).to_le_bytes());
            }
        }
    }
    std::fs::write(d.join("wall.pfm"), pfm).unwrap();
    dir
}

const SPHERE_VIEW: &str =
    "VIEW= -vtv -vp 0.2 0.3 0.8 -vd 0.4 1 -0.1 -vu 0 0 1 -vh 60 -vv 39.71 -vo 0 -va 0 -vs 0 -vl 0";

fn scene_text(cameras: &str, lights: &str) -> String {
    format!(
        "IgiScene(\n  geometry: \"q.obj\",\n  cameras: [\n{cameras}\n  ],\n  lights: [{lights}],\n  images: [\n    (camera: \"rad\", image: \"sphere.hdr\"),\n    (camera: \"header\", image: \"sphere.hdr\"),\n    (camera: \"wide\", image: \"wall.pic\"),\n    (camera: \"wide\", image: \"wall.pfm\"),\n  ],\n)\n"
    )
}

fn good_cameras() -> String {
    format!(
        "    (name: \"rad\", radiance_view: \"{SPHERE_VIEW}\", width: 48, height: 30),\n    (name: \"header\", radiance_view: \"from-image\", width: 48, height: 30),\n    (name: \"wide\", position_m: (1.5, 0.0, 1.0), look: (0.0, 1.0, 0.0), up: (0.0, 0.0, 1.0), hfov_deg: 70.0, width: 48, height: 30),"
    )
}

const RADIANCE_LIGHT: &str =
    "RadianceLight(name: \"lamp\", position_m: (1.5, 1.0, 1.8), radius_m: 0.05, radiance: (20.0, 10.0, 5.0))";

#[test]
fn a_scene_of_radiance_images_views_and_lights_loads_with_their_numbers() {
    let dir = scene_dir();
    let path = dir.path().join("s.ron");
    std::fs::write(&path, scene_text(&good_cameras(), RADIANCE_LIGHT)).unwrap();
    let s = load(&path).unwrap();
    let cam = |name: &str| s.cameras.iter().find(|(n, _)| n == name).unwrap().1;

    // hfov 70° on 48x30: tan(v/2) = tan(35°) · 30/48.
    let want = 2.0 * (35f64.to_radians().tan() * 30.0 / 48.0).atan();
    assert!(
        (cam("wide").vfov_rad - want).abs() < 1e-12,
        "{}",
        cam("wide").vfov_rad.to_degrees()
    );
    assert!((cam("wide").vfov_rad.to_degrees() - 47.2712).abs() < 1e-4);

    // The RADIANCE view projects the sphere's centre onto the centroid of
    // rpict's render of it (the image as the scene loaded it).
    let view = &s.input.views[0];
    let (px, py) = cam("rad").project(&Vector3::new(1.9, 2.9, 1.2)).unwrap();
    let (mut sx, mut sy, mut sum) = (0.0, 0.0, 0.0);
    for y in 0..30 {
        for x in 0..48 {
            let v = f64::from(view.image.radiance(x, y, 1));
            sx += v * (x as f64 + 0.5);
            sy += v * (y as f64 + 0.5);
            sum += v;
        }
    }
    eprintln!(
        "projected ({px:.3}, {py:.3}), rendered ({:.3}, {:.3})",
        sx / sum,
        sy / sum
    );
    assert!((px - sx / sum).abs() < 0.3 && (py - sy / sum).abs() < 0.3);
    // The view read from the picture's header is the same camera.
    assert_eq!(cam("header"), cam("rad"));

    // RGBE written by Campanile (.pic) and PFM: pixel values.
    let pic = &s.input.views[2].image;
    assert!((pic.radiance(5, 0, 0) - (0.5 + 15.0 % 7.0 * 0.25)).abs() < 0.01);
    let pfm = &s.input.views[3].image;
    assert_eq!(pfm.radiance(7, 0, 0), 7.0);
    assert_eq!(pfm.radiance(3, 29, 2), 2904.0);

    // The RADIANCE light: I = π r² L.
    let i = s.input.lights[0].intensity;
    let area = std::f64::consts::PI * 0.05 * 0.05;
    for (c, l) in [20.0, 10.0, 5.0].iter().enumerate() {
        assert!((i[c] - l * area).abs() < 1e-12, "{c}: {}", i[c]);
    }
    assert_eq!(s.input.lights[0].radius, 0.05);
}

#[test]
fn a_radiance_light_has_the_intensity_rtrace_measures() {
    // rtrace -I at d from a light sphere L = (20, 10, 5), r = 0.05
    // (validation/radiance-inputs/fixtures/light-irradiance.txt): E · d²
    // against Campanile's I = π r² L.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("lights.ron");
    std::fs::write(
        &path,
        "[RadianceLight(name: \"l\", position_m: (0.0, 0.0, 0.0), radius_m: 0.05, radiance: (20.0, 10.0, 5.0))]",
    )
    .unwrap();
    let lights = load_lights(&path).unwrap();
    let i = lights[0].1.intensity;
    let text = std::fs::read_to_string(fixtures().join("light-irradiance.txt")).unwrap();
    let mut worst = 0.0f64;
    for line in text.lines().filter(|l| !l.starts_with('#')) {
        let v: Vec<f64> = line.split_whitespace().map(|t| t.parse().unwrap()).collect();
        let d = v[0];
        for c in 0..3 {
            worst = worst.max((v[1 + c] * d * d / i[c] - 1.0).abs());
        }
    }
    // Measured 0.040 % (d = 10 r to 40 r).
    eprintln!("rtrace E·d² against π r² L: worst {:.3} %", 100.0 * worst);
    assert!(worst < 0.01, "{worst}");
}

/// Runs `campanile igi` on the scene text; returns (exit code, stderr).
fn igi(dir: &Path, text: &str) -> (Option<i32>, String) {
    let path = dir.join("s.ron");
    std::fs::write(&path, text).unwrap();
    let o = campanile(&[
        "igi",
        path.to_str().unwrap(),
        "--out",
        dir.join("out").to_str().unwrap(),
    ]);
    (o.status.code(), String::from_utf8_lossy(&o.stderr).into_owned())
}

#[test]
fn bad_views_images_and_sizes_are_refused_with_exit_2_by_name() {
    let dir = scene_dir();
    let d = dir.path();
    let with_rad = |view: &str| {
        good_cameras().replace(
            &format!("radiance_view: \"{SPHERE_VIEW}\""),
            &format!("radiance_view: \"{view}\""),
        )
    };

    let (code, e) = igi(d, &scene_text(&with_rad("-vth -vh 180 -vv 180"), RADIANCE_LIGHT));
    assert_eq!(code, Some(2), "{e}");
    assert!(
        e.contains("s.ron: cameras[0].radiance_view = \"-vth -vh 180 -vv 180\"")
            && e.contains("only perspective views (-vtv) are supported, not hemispherical fisheye"),
        "{e}"
    );

    let both = good_cameras().replace(
        "(name: \"rad\", radiance_view:",
        "(name: \"rad\", position_m: (0.0, 0.0, 1.0), radiance_view:",
    );
    let (code, e) = igi(d, &scene_text(&both, RADIANCE_LIGHT));
    assert_eq!(code, Some(2), "{e}");
    assert!(
        e.contains("cameras[0].position_m = given: expected absent when radiance_view is given"),
        "{e}"
    );

    let neither = good_cameras().replace("hfov_deg: 70.0, ", "");
    let (code, e) = igi(d, &scene_text(&neither, RADIANCE_LIGHT));
    assert_eq!(code, Some(2), "{e}");
    assert!(
        e.contains("cameras[2].vfov_deg = absent: expected vfov_deg or hfov_deg (degrees), or a radiance_view"),
        "{e}"
    );

    let square = with_rad("-vtv -vp 0.2 0.3 0.8 -vd 0.4 1 -0.1 -vh 60 -vv 60");
    let (code, e) = igi(d, &scene_text(&square, RADIANCE_LIGHT));
    assert_eq!(code, Some(2), "{e}");
    assert!(
        e.contains("cameras[0].radiance_view") && e.contains("rpict -x 48 -y 30 makes 30x30"),
        "{e}"
    );

    let (code, e) = igi(
        d,
        &scene_text(
            &good_cameras(),
            "RadianceLight(name: \"l\", position_m: (1.0, 1.0, 1.0), radius_m: 0.0, radiance: (1.0, 1.0, 1.0))",
        ),
    );
    assert_eq!(code, Some(2), "{e}");
    assert!(
        e.contains("lights[0].radius_m = 0: expected a finite sphere radius > 0 m"),
        "{e}"
    );

    // A truncated RGBE picture.
    let bytes = std::fs::read(d.join("sphere.hdr")).unwrap();
    std::fs::write(d.join("sphere.hdr"), &bytes[..bytes.len() - 100]).unwrap();
    let (code, e) = igi(d, &scene_text(&good_cameras(), RADIANCE_LIGHT));
    assert_eq!(code, Some(2), "{e}");
    assert!(
        e.contains("sphere.hdr: scan line") && e.contains("the file is truncated"),
        "{e}"
    );
    std::fs::write(d.join("sphere.hdr"), &bytes).unwrap();

    // A PFM whose pixels are one row short.
    let pfm = std::fs::read(d.join("wall.pfm")).unwrap();
    std::fs::write(d.join("wall.pfm"), &pfm[..pfm.len() - 48 * 12]).unwrap();
    let (code, e) = igi(d, &scene_text(&good_cameras(), RADIANCE_LIGHT));
    assert_eq!(code, Some(2), "{e}");
    assert!(
        e.contains("wall.pfm: 16704 bytes of pixels: expected 17280 for a 48x30 colour PFM"),
        "{e}"
    );
    // A PFM of the wrong size for its camera.
    std::fs::write(
        d.join("wall.pfm"),
        b"PF\n2 1\n-1.0\n\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0",
    )
    .unwrap();
    let (code, e) = igi(d, &scene_text(&good_cameras(), RADIANCE_LIGHT));
    assert_eq!(code, Some(2), "{e}");
    assert!(
        e.contains("images[3].image") && e.contains("(2x1): expected an image of the camera's size 48x30"),
        "{e}"
    );
}

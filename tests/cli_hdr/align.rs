//! `campanile hdr calibrate|merge --align [--deghost]` end to end: a
//! hand-held bracket simulated with known shifts (one frame also rotated 1°)
//! is written as PNGs; the printed transforms must be right to 0.25 px and
//! the aligned merge must match the merge of the same bracket shot without
//! motion.

use std::path::Path;

use crate::common::campanile;
use campanile_process::camera::sensor::CameraModel;
use campanile_process::camera::textured_scene::textured_scene;
use campanile_process::exr_io::read_radiance_exr;
use campanile_process::hdr::image_file::write_png;
use campanile_process::hdr::merge::RadianceMap;

const TIMES: [f64; 5] = [1.0 / 16.0, 0.25, 1.0, 4.0, 16.0];
/// (dx, dy, rotation in degrees) of each exposure; the middle one is the reference.
const MOTION: [(f64, f64, f64); 5] = [
    (3.25, -1.5, 0.0),
    (-7.75, 2.0, 0.0),
    (0.0, 0.0, 0.0),
    (1.5, 4.25, 1.0),
    (-2.4, -5.6, 0.0),
];

fn write_bracket(dir: &Path, name: &str, moved: bool) -> Vec<String> {
    let cam = CameraModel::typical(8);
    let (w, h) = (192, 144);
    TIMES
        .iter()
        .zip(MOTION)
        .enumerate()
        .map(|(k, (&t, (dx, dy, deg)))| {
            let scene = if moved {
                textured_scene(w, h, dx, dy, deg.to_radians())
            } else {
                textured_scene(w, h, 0.0, 0.0, 0.0)
            };
            let p = dir.join(format!("{name}{k}.png"));
            write_png(&cam.photograph(&scene, t, 70 + k as u64), &p).expect("png");
            p.to_str().expect("utf-8").to_owned()
        })
        .collect()
}

fn run(args: &[&str], paths: &[String]) -> String {
    let mut all = args.to_vec();
    all.extend(paths.iter().map(String::as_str));
    let out = campanile(&all);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{all:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("utf-8")
}

/// The (dx, dy, rotation) printed for each image, in the bracket's order.
fn printed_transforms(stdout: &str) -> Vec<(f64, f64, f64)> {
    let num = |s: &str, key: &str| -> f64 {
        let rest = &s[s.find(key).unwrap_or_else(|| panic!("'{key}' in '{s}'")) + key.len()..];
        let end = rest.find([' ', '°']).unwrap_or(rest.len());
        rest[..end]
            .parse()
            .unwrap_or_else(|_| panic!("number after '{key}' in '{s}'"))
    };
    stdout
        .lines()
        .filter(|l| l.starts_with("image ") && l.contains(": dx "))
        .map(|l| (num(l, ": dx "), num(l, ", dy "), num(l, "rotation ")))
        .collect()
}

fn median_rel_diff(a: &RadianceMap, b: &RadianceMap) -> f64 {
    let mut d: Vec<f64> = (0..a.width * a.height)
        .filter(|&p| a.is_valid(p) && b.is_valid(p))
        .flat_map(|p| (0..3).map(move |c| 3 * p + c))
        .map(|i| (f64::from(a.rgb[i]) / f64::from(b.rgb[i]) - 1.0).abs())
        .collect();
    let mid = d.len() / 2;
    *d.select_nth_unstable_by(mid, f64::total_cmp).1
}

#[test]
fn align_recovers_the_shifts_and_the_aligned_merge_matches_the_still_one() {
    let dir = tempfile::tempdir().expect("temp");
    let moved = write_bracket(dir.path(), "moved", true);
    let still = write_bracket(dir.path(), "still", false);
    let times = TIMES.iter().map(|t| t.to_string()).collect::<Vec<_>>().join(",");
    let s = |p: &Path| p.to_str().expect("utf-8").to_owned();
    let curve = s(&dir.path().join("curve.csv"));
    let out = run(
        &["hdr", "calibrate", "--align", "--times", &times, "--out", &curve],
        &moved,
    );
    let found = printed_transforms(&out);
    assert_eq!(found.len(), 5, "{out}");
    for (k, ((dx, dy, deg), (tx, ty, tdeg))) in found.iter().zip(MOTION).enumerate() {
        eprintln!(
            "image {k}: printed dx {dx:+.2} dy {dy:+.2} rotation {deg:+.2}° (true {tx:+.2} {ty:+.2} {tdeg:+.2}°)"
        );
        assert!(
            (dx - tx).abs() <= 0.25 && (dy - ty).abs() <= 0.25,
            "image {k}: printed ({dx}, {dy}), true ({tx}, {ty}) ± 0.25 px"
        );
        // Two decimals are printed: the angle to 0.05° plus rounding.
        assert!((deg - tdeg).abs() <= 0.055, "image {k}: printed {deg}°, true {tdeg}°");
    }

    let merge = |name: &str, paths: &[String], extra: &[&str]| -> (RadianceMap, String) {
        let exr = dir.path().join(name);
        let mut args = vec!["hdr", "merge", "--with-variance", "--times", &times, "--curve", &curve];
        let e = s(&exr);
        args.extend(["--out", &e]);
        args.extend(extra);
        let stdout = run(&args, paths);
        (read_radiance_exr(&exr).expect("readable EXR"), stdout)
    };
    let (reference, _) = merge("still.exr", &still, &[]);
    let (plain, _) = merge("plain.exr", &moved, &[]);
    let (aligned, out) = merge("aligned.exr", &moved, &["--align"]);
    assert_eq!(printed_transforms(&out).len(), 5, "{out}");
    let (deghosted, out) = merge("deghosted.exr", &moved, &["--align", "--deghost"]);
    assert!(out.contains("deghost: "), "{out}");
    let before = median_rel_diff(&plain, &reference);
    let after = median_rel_diff(&aligned, &reference);
    let after_dg = median_rel_diff(&deghosted, &reference);
    eprintln!(
        "median relative difference from the still merge: unaligned {before:.4}, aligned {after:.4}, \
         aligned and deghosted {after_dg:.4}"
    );
    assert!(before > 0.1, "the unaligned merge should differ: {before}");
    assert!(after < 0.02, "aligned merge: median relative difference {after} ≥ 0.02");
    assert!(
        after_dg < 0.02,
        "aligned, deghosted merge: median relative difference {after_dg} ≥ 0.02"
    );
}

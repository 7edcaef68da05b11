//! `read_raw` against LibRaw (through rawpy) on the committed DNG fixtures
//! of `validation/raw/` (written by `examples/write_dng_fixture.rs`, decoded
//! by `validation/raw/check_dng.py` into `NAME.rawpy.csv`): an independent,
//! widely used DNG reader must see the same file we wrote and read.
//!
//! - raw codes at 48 photosites, the CFA colour of each 2×2 position, the
//!   black level of each position and the white level: exact;
//! - white balance (R/G, B/G of LibRaw's camera multipliers): within 1e-4
//!   (the file stores AsShotNeutral as rationals);
//! - LibRaw's demosaiced output (AHD, raw colour, camera WB, linear,
//!   16-bit) at the centre of each 16×16 flat patch, against ours scaled the
//!   way LibRaw scales (`v · wb_c / min wb · 65535`): within 2 codes of
//!   65535 (0.003 %) plus, where the four black levels differ, the
//!   difference of conventions (LibRaw scales by `white − min black`, the
//!   DNG specification by `white − black` of each position: at most
//!   0.05 % of the value in these fixtures). On flat patches AHD and bilinear
//!   agree exactly; the 2 codes allow for LibRaw's integer rounding. Edges
//!   are not compared: demosaic algorithms differ there by design.
//! - the camera → sRGB matrix LibRaw derives from ColorMatrix1 (dcraw's
//!   method), against [`camera_to_srgb`]: within 1e-4.

use std::collections::HashMap;
use std::path::PathBuf;

use campanile_process::hdr::linear_merge::camera_to_srgb;
use campanile_process::hdr::raw_file::{demosaic, read_raw_mosaic};

const FIXTURES: [&str; 4] = ["sim_rggb_14bit", "sim_bggr_14bit", "sim_grbg_12bit", "sim_gbrg_12bit"];

fn dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../validation/raw/fixtures")
}

/// Rows of NAME.rawpy.csv by kind: (x, y, c, value).
fn rows(name: &str) -> HashMap<String, Vec<(usize, usize, usize, f64)>> {
    let path = dir().join(format!("{name}.rawpy.csv"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut out: HashMap<String, Vec<_>> = HashMap::new();
    for line in text.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let n = |i: usize| {
            f[i].parse::<f64>()
                .unwrap_or_else(|_| panic!("{}: '{line}'", path.display()))
        };
        out.entry(f[0].to_owned())
            .or_default()
            .push((n(1) as usize, n(2) as usize, n(3) as usize, n(4)));
    }
    out
}

#[test]
fn dng_fixtures_decode_as_libraw_decodes_them() {
    for name in FIXTURES {
        let r = rows(name);
        let mosaic = read_raw_mosaic(&dir().join(format!("{name}.dng"))).expect("reads");
        let frame = demosaic(&mosaic);
        let w = mosaic.width;

        for &(x, y, _, v) in &r["raw"] {
            assert_eq!(f64::from(mosaic.data[y * w + x]), v, "{name}: raw code at ({x}, {y})");
        }
        // LibRaw's colour indices: 0 R, 1 G, 2 B, 3 second G.
        let mut libraw_color = [0usize; 4];
        for &(x, y, _, v) in &r["raw_color"] {
            libraw_color[y * 2 + x] = v as usize;
            let ours = mosaic.pattern.color_at(x, y);
            assert_eq!(ours, [0, 1, 2, 1][v as usize], "{name}: CFA colour at ({x}, {y})");
        }
        let black: HashMap<usize, f64> = r["black"].iter().map(|&(_, _, c, v)| (c, v)).collect();
        for (i, &lc) in libraw_color.iter().enumerate() {
            assert_eq!(
                mosaic.meta.black_levels[i], black[&lc],
                "{name}: black level at 2×2 position {i}"
            );
        }
        assert_eq!(mosaic.meta.white_level, r["white"][0].3, "{name}: white level");

        let cam_wb: HashMap<usize, f64> = r["cam_wb"].iter().map(|&(_, _, c, v)| (c, v)).collect();
        let wb = mosaic.meta.wb_multipliers.expect("as-shot WB");
        for (c, ours) in [(0, wb[0]), (2, wb[2])] {
            let theirs = cam_wb[&c] / cam_wb[&1];
            assert!(
                (ours / theirs - 1.0).abs() < 1e-4,
                "{name}: WB channel {c}: {ours} vs LibRaw {theirs}"
            );
        }
        let (m, _) = mosaic.meta.xyz_to_camera.expect("colour matrix");
        let rgb_cam = camera_to_srgb(&m).expect("invertible");
        for &(i, j, _, v) in &r["rgb_cam"] {
            if j < 3 {
                let ours = rgb_cam[i][j];
                assert!(
                    (ours - v).abs() < 1e-4,
                    "{name}: camera→sRGB[{i}][{j}] {ours} vs LibRaw {v}"
                );
            }
        }

        let size = r["post_size"][0];
        assert_eq!((size.0, size.1), (frame.width, frame.height), "{name}: output size");
        let min_wb = wb.iter().copied().fold(f64::INFINITY, f64::min);
        // LibRaw divides every position by (white − smallest black); the DNG
        // specification, and we, by (white − that position's black). With
        // unequal blacks the two differ by up to this fraction of the value.
        let b = mosaic.meta.black_levels;
        let (b_min, b_max) = (
            b.iter().copied().fold(f64::MAX, f64::min),
            b.iter().copied().fold(0.0, f64::max),
        );
        let convention = (b_max - b_min) / (mosaic.meta.white_level - b_min);
        let mut compared = 0;
        let mut worst = 0.0f64;
        for &(x, y, c, v) in &r["post"] {
            let p = y * frame.width + x;
            let ours = f64::from(frame.rgb[p * 3 + c]) * wb[c] / min_wb * 65535.0;
            if frame.is_clipped(p, c) || ours >= 65535.0 {
                let floor = 65535.0 * (1.0 - convention) - 2.0;
                assert!(
                    v >= floor,
                    "{name}: ({x}, {y}) channel {c} clipped here, LibRaw {v} < {floor}"
                );
                continue;
            }
            // 2 codes of rounding, plus the black-level convention.
            worst = worst.max((ours - v).abs() - ours * convention);
            compared += 1;
        }
        println!("{name}: {compared} patch values compared, largest difference {worst:.2} of 65535");
        assert!(compared >= 60, "{name}: only {compared} unclipped patch values");
        assert!(worst <= 2.0, "{name}: largest difference {worst} codes of 65535");
    }
}

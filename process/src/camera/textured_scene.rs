//! A textured test scene with known radiance at any real position, so a
//! shifted or rotated view of it is exact (no resampling): for alignment
//! tests and benchmarks, where [`super::test_chart::hdr_chart`] has too little
//! texture at mid-tones for median threshold bitmaps.

use super::image::RadianceImage;

/// Deterministic lattice hash in [0, 1).
fn hash(i: i64, j: i64, seed: u64) -> f64 {
    let mut z = (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ (j as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F)
        ^ seed.wrapping_mul(0x1656_67B1_9E37_79F9);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64
}

/// Smooth (C¹) value noise in [0, 1) with feature size `scale` px.
fn value_noise(x: f64, y: f64, scale: f64, seed: u64) -> f64 {
    let (u, v) = (x / scale, y / scale);
    let (i, j) = (u.floor(), v.floor());
    let s = |t: f64| t * t * (3.0 - 2.0 * t);
    let (sx, sy) = (s(u - i), s(v - j));
    let (i, j) = (i as i64, j as i64);
    let a = hash(i, j, seed) * (1.0 - sx) + hash(i + 1, j, seed) * sx;
    let b = hash(i, j + 1, seed) * (1.0 - sx) + hash(i + 1, j + 1, seed) * sx;
    a * (1.0 - sy) + b * sy
}

/// Radiance (W·m⁻²·sr⁻¹, RGB) at scene point (`x`, `y`): log radiance from
/// three octaves of value noise (29, 11 and 4.5 px), about 0.0007–3.7
/// around 0.05, tinted `[1, 0.9, 0.8]`.
pub fn textured_radiance(x: f64, y: f64) -> [f64; 3] {
    let n = 2.0 * (value_noise(x, y, 29.0, 1) - 0.5) * 2.6
        + 2.0 * (value_noise(x, y, 11.0, 2) - 0.5) * 1.2
        + 2.0 * (value_noise(x, y, 4.5, 3) - 0.5) * 0.5;
    let l = 0.05 * n.exp();
    [l, 0.9 * l, 0.8 * l]
}

/// A `width`×`height` view of the scene moved by (`dx`, `dy`) px and rotated by
/// `angle_rad` about the image centre `c`: pixel `s` shows the scene point
/// `R(−angle)(s − c − d) + c`, so a point at `x` in the unmoved view appears
/// at `R(angle)(x − c) + c + d`.
pub fn textured_scene(width: usize, height: usize, dx: f64, dy: f64, angle_rad: f64) -> RadianceImage {
    let (cx, cy) = ((width as f64 - 1.0) / 2.0, (height as f64 - 1.0) / 2.0);
    let (s, c) = angle_rad.sin_cos();
    let mut data = Vec::with_capacity(width * height * 3);
    for y in 0..height {
        for x in 0..width {
            let (u, v) = (x as f64 - cx - dx, y as f64 - cy - dy);
            let (px, py) = (c * u + s * v + cx, -s * u + c * v + cy);
            data.extend(textured_radiance(px, py).map(|v| v as f32));
        }
    }
    RadianceImage { width, height, data }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_moved_view_shows_the_same_point_where_stated() {
        // The point at (10, 7) of the unmoved view appears at (13.0, 5.0) in a view moved by (+3, −2).
        let still = textured_scene(32, 24, 0.0, 0.0, 0.0);
        let moved = textured_scene(32, 24, 3.0, -2.0, 0.0);
        assert_eq!(still.radiance(10, 7, 1), moved.radiance(13, 5, 1));
        let (lo, hi) = still
            .data
            .iter()
            .fold((f32::MAX, 0.0f32), |(a, b), &v| (a.min(v), b.max(v)));
        assert!(lo > 5e-4 && hi < 4.0, "range {lo}..{hi}");
    }
}

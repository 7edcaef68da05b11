//! Procedural albedo textures, evaluated at a face's planar texture
//! coordinates in metres. They are the simulator's ground truth for
//! per-texel albedo (thesis §5.4: "every surface of the building has its
//! own surface texture"), so they are exact functions, not images.

/// An albedo (per channel, 0–1) as a function of position on a face.
#[derive(Debug, Clone, PartialEq)]
pub enum Texture {
    /// The same albedo everywhere.
    Constant([f64; 3]),
    /// Running-bond brickwork: bricks of `size_m` (along, up) separated by
    /// mortar joints `joint_m` wide; each brick's albedo is `brick` scaled by
    /// `1 + variation · u` with `u` uniform in [−1, 1], drawn per brick from `seed`.
    Bricks {
        /// Mean brick albedo.
        brick: [f64; 3],
        /// Mortar albedo.
        mortar: [f64; 3],
        /// Brick length and height (with the joint), metres.
        size_m: [f64; 2],
        /// Joint width, metres.
        joint_m: f64,
        /// Relative per-brick variation.
        variation: f64,
        /// Seed of the per-brick variation.
        seed: u64,
    },
    /// Alternating bands of two albedos, `period_m` apart, across the `t`
    /// axis (horizontal bands) or, with `vertical`, across `s`.
    Stripes {
        /// The two albedos.
        colours: [[f64; 3]; 2],
        /// Width of one pair of bands, metres.
        period_m: f64,
        /// Bands run up the face instead of along it.
        vertical: bool,
    },
    /// Square cells of `cell_m` whose albedo is `mean · (1 + amplitude · u)`,
    /// `u` uniform in [−1, 1] per cell: the thesis's "zero mean white noise
    /// added to the uniform diffuse albedo" (§4.7.1).
    Noise {
        /// Mean albedo.
        mean: [f64; 3],
        /// Relative amplitude (0.2 for ±20%).
        amplitude: f64,
        /// Cell size, metres.
        cell_m: f64,
        /// Seed of the cells.
        seed: u64,
    },
    /// A printed square pattern, such as a coded target (an AprilTag):
    /// `width` × `width` cells of side `cell_m`, row-major from the
    /// pattern's top-left, `true` for `white`, `false` for `black`; white
    /// beyond the pattern (the target's plate). The pattern's axes need not
    /// be the face's: `axes` gives the pattern's right and up directions
    /// in (s, t), so a tag can hang at any angle on a face.
    Pattern {
        /// The pattern's centre, texture coordinates (metres).
        centre_st: [f64; 2],
        /// The pattern's right and up unit directions in (s, t).
        axes: [[f64; 2]; 2],
        /// Cell side, metres.
        cell_m: f64,
        /// Cells per side.
        width: usize,
        /// The cells, `width²`, row-major from the top-left, `true` white.
        cells: Vec<bool>,
        /// Albedo of black cells.
        black: [f64; 3],
        /// Albedo of white cells and of the plate around the pattern.
        white: [f64; 3],
    },
    /// A disc on a square plate, such as the thesis's targets (§3.3: "flat
    /// square green patches with a white circular area in the middle"):
    /// `inside` within `radius_m` of `centre_st`, `outside` elsewhere.
    Disc {
        /// The disc's centre, texture coordinates (metres).
        centre_st: [f64; 2],
        /// The disc's radius, metres.
        radius_m: f64,
        /// Side of the square plate around it, metres (for the mean albedo).
        plate_m: f64,
        /// Albedo inside the disc.
        inside: [f64; 3],
        /// Albedo of the plate around it.
        outside: [f64; 3],
    },
    /// A measured albedo image on a plane: square texels of `texel_m`
    /// from the corner `origin_st`, row-major along s; `mean` beyond the
    /// image. Inverse global illumination puts a face's first albedo map
    /// here to gather the light its own texture sends back to it.
    Texels(TexelImage),
}

/// The image of [`Texture::Texels`].
#[derive(Debug, Clone, PartialEq)]
pub struct TexelImage {
    /// Texture coordinates of the image's corner, metres.
    pub origin_st: [f64; 2],
    /// Texel side, metres.
    pub texel_m: f64,
    /// Texels along s and t.
    pub size: [usize; 2],
    /// Albedo per texel, `size[0] × size[1]`, shared between clones.
    pub texels: std::sync::Arc<[[f32; 3]]>,
    /// The albedo beyond the image, and its mean.
    pub mean: [f64; 3],
}

impl TexelImage {
    fn at(&self, st: [f64; 2]) -> [f64; 3] {
        let i = ((st[0] - self.origin_st[0]) / self.texel_m).floor();
        let j = ((st[1] - self.origin_st[1]) / self.texel_m).floor();
        if !(i >= 0.0 && j >= 0.0 && i < self.size[0] as f64 && j < self.size[1] as f64) {
            return self.mean;
        }
        match self.texels.get(j as usize * self.size[0] + i as usize) {
            Some(v) => v.map(f64::from),
            None => self.mean,
        }
    }
}

/// A uniform number in [−1, 1] for integer cell `(i, j)` and `seed`
/// (SplitMix64 finalizer over the packed cell), so that textures need no state.
fn cell_noise(i: i64, j: i64, seed: u64) -> f64 {
    let mut z = seed
        .wrapping_add((i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15))
        .wrapping_add((j as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F));
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
}

fn scale(c: [f64; 3], k: f64) -> [f64; 3] {
    c.map(|v| (v * k).clamp(0.0, 1.0))
}

impl Texture {
    /// The albedo at texture coordinates `st` (metres).
    pub fn albedo(&self, st: [f64; 2]) -> [f64; 3] {
        match self {
            Texture::Constant(c) => *c,
            Texture::Bricks {
                brick,
                mortar,
                size_m,
                joint_m,
                variation,
                seed,
            } => {
                let row = (st[1] / size_m[1]).floor();
                // Running bond: odd rows shift by half a brick.
                let shift = if (row as i64).rem_euclid(2) == 1 {
                    0.5 * size_m[0]
                } else {
                    0.0
                };
                let col = ((st[0] + shift) / size_m[0]).floor();
                let fs = st[0] + shift - col * size_m[0];
                let ft = st[1] - row * size_m[1];
                if fs < *joint_m || ft < *joint_m {
                    *mortar
                } else {
                    scale(*brick, 1.0 + variation * cell_noise(col as i64, row as i64, *seed))
                }
            }
            Texture::Stripes {
                colours,
                period_m,
                vertical,
            } => {
                let x = if *vertical { st[0] } else { st[1] };
                let phase = (x / period_m).rem_euclid(1.0);
                if phase < 0.5 { colours[0] } else { colours[1] }
            }
            Texture::Noise {
                mean,
                amplitude,
                cell_m,
                seed,
            } => {
                let (i, j) = ((st[0] / cell_m).floor() as i64, (st[1] / cell_m).floor() as i64);
                scale(*mean, 1.0 + amplitude * cell_noise(i, j, *seed))
            }
            Texture::Pattern {
                centre_st,
                axes,
                cell_m,
                width,
                cells,
                black,
                white,
            } => {
                let (ds, dt) = (st[0] - centre_st[0], st[1] - centre_st[1]);
                let right = ds * axes[0][0] + dt * axes[0][1];
                let up = ds * axes[1][0] + dt * axes[1][1];
                let half = *width as f64 / 2.0;
                let (a, b) = (right / cell_m + half, half - up / cell_m);
                if a < 0.0 || b < 0.0 || a >= *width as f64 || b >= *width as f64 {
                    return *white;
                }
                match cells.get(b as usize * width + a as usize) {
                    Some(false) => *black,
                    _ => *white,
                }
            }
            Texture::Disc {
                centre_st,
                radius_m,
                inside,
                outside,
                ..
            } => {
                if (st[0] - centre_st[0]).hypot(st[1] - centre_st[1]) <= *radius_m {
                    *inside
                } else {
                    *outside
                }
            }
            Texture::Texels(image) => image.at(st),
        }
    }

    /// The texture's mean albedo over a large area (for reports and for
    /// the thesis's "compared to the true average values").
    pub fn mean_albedo(&self) -> [f64; 3] {
        match self {
            Texture::Constant(c) => *c,
            Texture::Bricks {
                brick,
                mortar,
                size_m,
                joint_m,
                ..
            } => {
                let brick_fraction =
                    (size_m[0] - joint_m).max(0.0) * (size_m[1] - joint_m).max(0.0) / (size_m[0] * size_m[1]);
                [0, 1, 2].map(|c| brick_fraction * brick[c] + (1.0 - brick_fraction) * mortar[c])
            }
            Texture::Stripes { colours, .. } => [0, 1, 2].map(|c| 0.5 * (colours[0][c] + colours[1][c])),
            Texture::Noise { mean, .. } => *mean,
            // Over the pattern itself; the plate around it is white.
            Texture::Pattern {
                cells, black, white, ..
            } => {
                let f = cells.iter().filter(|c| **c).count() as f64 / cells.len().max(1) as f64;
                [0, 1, 2].map(|c| f * white[c] + (1.0 - f) * black[c])
            }
            // Over the plate.
            Texture::Disc {
                radius_m,
                plate_m,
                inside,
                outside,
                ..
            } => {
                let f = (std::f64::consts::PI * radius_m * radius_m / (plate_m * plate_m).max(1e-300)).min(1.0);
                [0, 1, 2].map(|c| f * inside[c] + (1.0 - f) * outside[c])
            }
            Texture::Texels(image) => image.mean,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cell_noise_is_uniform_on_minus_one_one() {
        let n = 200_000;
        let xs: Vec<f64> = (0..n).map(|i| cell_noise(i, -3 * i, 9)).collect();
        let mean = xs.iter().sum::<f64>() / n as f64;
        let var = xs.iter().map(|x| x * x).sum::<f64>() / n as f64 - mean * mean;
        assert!(xs.iter().all(|x| (-1.0..=1.0).contains(x)));
        assert!(mean.abs() < 0.01, "mean {mean}");
        assert!((var - 1.0 / 3.0).abs() < 0.005, "variance {var} (uniform: 1/3)");
    }

    #[test]
    fn brick_area_average_matches_mean_albedo() {
        let t = Texture::Bricks {
            brick: [0.6, 0.35, 0.25],
            mortar: [0.8, 0.8, 0.75],
            size_m: [0.25, 0.08],
            joint_m: 0.01,
            variation: 0.15,
            seed: 3,
        };
        let n = 400;
        let mut sum = [0.0; 3];
        for i in 0..n {
            for j in 0..n {
                let a = t.albedo([i as f64 * 0.0173, j as f64 * 0.0071]);
                (0..3).for_each(|c| sum[c] += a[c]);
            }
        }
        let mean = t.mean_albedo();
        for c in 0..3 {
            let m = sum[c] / (n * n) as f64;
            assert!(
                (m / mean[c] - 1.0).abs() < 0.01,
                "channel {c}: sampled {m} vs {}",
                mean[c]
            );
        }
    }

    #[test]
    fn a_pattern_turned_a_quarter_turn_reads_its_cells_in_place() {
        // 2 × 2 cells: only the top-left is white.
        let t = Texture::Pattern {
            centre_st: [10.0, 5.0],
            axes: [[0.0, 1.0], [-1.0, 0.0]],
            cell_m: 0.5,
            width: 2,
            cells: vec![true, false, false, false],
            black: [0.05; 3],
            white: [0.9; 3],
        };
        // The pattern's right is +t and its up is −s: its top-left cell
        // lies towards −s (up) and −t (left).
        assert_eq!(t.albedo([9.75, 4.75]), [0.9; 3]);
        assert_eq!(t.albedo([10.25, 4.75]), [0.05; 3]);
        assert_eq!(t.albedo([9.75, 5.25]), [0.05; 3]);
        // Beyond the pattern: the white plate.
        assert_eq!(t.albedo([12.0, 5.0]), [0.9; 3]);
        assert_eq!(t.mean_albedo(), [0.25 * 0.9 + 0.75 * 0.05; 3]);
    }

    #[test]
    fn a_disc_is_inside_within_its_radius_and_its_mean_is_over_the_plate() {
        let t = Texture::Disc {
            centre_st: [2.0, 1.0],
            radius_m: 0.1,
            plate_m: 0.4,
            inside: [0.9; 3],
            outside: [0.05; 3],
        };
        assert_eq!(t.albedo([2.09, 1.0]), [0.9; 3]);
        assert_eq!(t.albedo([2.08, 1.08]), [0.05; 3]);
        let f = std::f64::consts::PI * 0.01 / 0.16;
        assert!((t.mean_albedo()[0] - (f * 0.9 + (1.0 - f) * 0.05)).abs() < 1e-12);
    }

    #[test]
    fn a_texel_image_is_read_texel_by_texel_and_its_mean_beyond_it() {
        // 3 × 2 texels of 10 cm from (1.0, -0.5): texel (i, j) holds i + 10 j.
        let texels: Vec<[f32; 3]> = (0..6).map(|k| [(k % 3 + 10 * (k / 3)) as f32; 3]).collect();
        let t = Texture::Texels(TexelImage {
            origin_st: [1.0, -0.5],
            texel_m: 0.1,
            size: [3, 2],
            texels: texels.into(),
            mean: [0.25; 3],
        });
        assert_eq!(t.albedo([1.05, -0.45]), [0.0; 3]);
        assert_eq!(t.albedo([1.25, -0.45]), [2.0; 3]);
        assert_eq!(t.albedo([1.15, -0.35]), [11.0; 3]);
        assert_eq!(t.albedo([1.299, -0.301]), [12.0; 3]);
        for outside in [
            [0.99, -0.45],
            [1.31, -0.45],
            [1.05, -0.51],
            [1.05, -0.29],
            [f64::NAN, 0.0],
        ] {
            assert_eq!(t.albedo(outside), [0.25; 3], "{outside:?}");
        }
        assert_eq!(t.mean_albedo(), [0.25; 3]);
    }

    #[test]
    fn stripes_alternate() {
        let t = Texture::Stripes {
            colours: [[0.1; 3], [0.9; 3]],
            period_m: 2.0,
            vertical: false,
        };
        assert_eq!(t.albedo([5.0, 0.5]), [0.1; 3]);
        assert_eq!(t.albedo([5.0, 1.5]), [0.9; 3]);
        assert_eq!(t.albedo([5.0, -0.5]), [0.9; 3]);
    }
}

//! A coarse latitude-longitude environment map (§5.3.3): the sphere cut
//! into rectangular regions along elevation and azimuth, each holding the
//! mean radiance of the samples that fell in it, with their count and
//! variance (Welford's running update, stable in one pass).

use crate::sky::{FrameSampleError, SkyFrame};

/// Running statistics of one region, per channel.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct RegionStats {
    /// Samples.
    pub count: u64,
    /// Mean radiance per channel.
    pub mean: [f64; 3],
    m2: [f64; 3],
}

impl RegionStats {
    /// Adds one sample.
    pub fn add(&mut self, rgb: [f64; 3]) {
        self.count += 1;
        let n = self.count as f64;
        for ((x, mean), m2) in rgb.iter().zip(&mut self.mean).zip(&mut self.m2) {
            let delta = x - *mean;
            *mean += delta / n;
            *m2 += delta * (x - *mean);
        }
    }

    /// Sample variance per channel (zero below two samples).
    pub fn variance(&self) -> [f64; 3] {
        if self.count < 2 {
            return [0.0; 3];
        }
        let d = (self.count - 1) as f64;
        [self.m2[0] / d, self.m2[1] / d, self.m2[2] / d]
    }
}

/// The map: `rows` elevation bands from −90° to 90°, `cols` azimuth
/// sectors from north through east.
#[derive(Debug, Clone, PartialEq)]
pub struct EnvironmentMap {
    /// Elevation bands.
    pub rows: usize,
    /// Azimuth sectors.
    pub cols: usize,
    /// Row-major regions, row 0 the lowest band.
    pub regions: Vec<RegionStats>,
}

impl EnvironmentMap {
    /// An empty map; at least one row and column.
    pub fn new(rows: usize, cols: usize) -> EnvironmentMap {
        let (rows, cols) = (rows.max(1), cols.max(1));
        EnvironmentMap {
            rows,
            cols,
            regions: vec![RegionStats::default(); rows * cols],
        }
    }

    /// The region index of a unit direction (world frame, z up).
    pub fn region_of(&self, dir: [f64; 3]) -> usize {
        let elevation = dir[2].clamp(-1.0, 1.0).asin();
        let azimuth = dir[0].atan2(dir[1]).rem_euclid(std::f64::consts::TAU);
        let row = (((elevation + std::f64::consts::FRAC_PI_2) / std::f64::consts::PI) * self.rows as f64) as usize;
        let col = ((azimuth / std::f64::consts::TAU) * self.cols as f64) as usize;
        row.min(self.rows - 1) * self.cols + col.min(self.cols - 1)
    }

    /// The unit direction of a region's centre.
    pub fn region_centre(&self, index: usize) -> [f64; 3] {
        let (row, col) = (index / self.cols, index % self.cols);
        let el = -std::f64::consts::FRAC_PI_2 + (row as f64 + 0.5) * std::f64::consts::PI / self.rows as f64;
        let az = (col as f64 + 0.5) * std::f64::consts::TAU / self.cols as f64;
        [el.cos() * az.sin(), el.cos() * az.cos(), el.sin()]
    }

    /// Bins every `stride`-th pixel of an HDR frame (through its head pose
    /// and intrinsics) into the regions; pixels the merge marked invalid and
    /// non-finite values are skipped. Returns the pixels binned.
    pub fn add_frame(&mut self, frame: &SkyFrame<'_>, stride: usize) -> Result<usize, FrameSampleError> {
        if stride == 0 {
            return Err(FrameSampleError::Stride);
        }
        let pixels = frame.width * frame.height;
        let mask = frame.valid.map_or(pixels, <[bool]>::len);
        if frame.rgb.len() != 3 * pixels || mask != pixels {
            return Err(FrameSampleError::Size {
                index: 0,
                width: frame.width,
                height: frame.height,
                needed: 3 * pixels,
                pixels,
                rgb: frame.rgb.len(),
                mask,
            });
        }
        let mut added = 0;
        for y in (0..frame.height).step_by(stride) {
            for x in (0..frame.width).step_by(stride) {
                let p = y * frame.width + x;
                if frame.valid.is_some_and(|v| !v[p]) {
                    continue;
                }
                let Some(d) = frame.camera.unproject(x as f64 + 0.5, y as f64 + 0.5) else {
                    continue;
                };
                let rgb = [0, 1, 2].map(|c| f64::from(frame.rgb[3 * p + c]));
                if rgb.iter().all(|v| v.is_finite()) {
                    self.add(frame.mount.to_world(frame.pose, d), rgb);
                    added += 1;
                }
            }
        }
        Ok(added)
    }

    /// Adds one radiance sample seen toward `dir`; non-finite samples are skipped.
    pub fn add(&mut self, dir: [f64; 3], rgb: [f64; 3]) {
        if dir.iter().chain(rgb.iter()).all(|v| v.is_finite()) {
            let i = self.region_of(dir);
            self.regions[i].add(rgb);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn welford_matches_two_pass_statistics() {
        let xs = [3.0, 4.5, 1e9 + 1.0, 1e9 + 2.0, -2.0];
        let mut s = RegionStats::default();
        for &x in &xs {
            s.add([x, 2.0 * x, 0.0]);
        }
        let mean = xs.iter().sum::<f64>() / 5.0;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / 4.0;
        assert!((s.mean[0] - mean).abs() < 1e-6 && (s.variance()[0] / var - 1.0).abs() < 1e-12);
        assert!((s.variance()[1] / (4.0 * var) - 1.0).abs() < 1e-12 && s.variance()[2] == 0.0);
    }

    #[test]
    fn a_frame_bins_into_the_regions_it_sees() {
        use crate::pose::{HeadPose, Mount, Pinhole};
        // A camera looking due east at the horizon, seeing radiance that
        // equals the elevation in degrees: regions average what they saw.
        let cam = Pinhole {
            focal_px: 40.0,
            principal_px: (32.0, 24.0),
            k1: 0.0,
            k2: 0.0,
            projection: crate::pose::Projection::Pinhole,
        };
        let (mount, pose) = (
            Mount::default(),
            HeadPose {
                pan_rad: std::f64::consts::FRAC_PI_2,
                tilt_rad: 0.0,
            },
        );
        let (w, h) = (64usize, 48usize);
        let mut rgb = vec![0f32; 3 * w * h];
        for y in 0..h {
            for x in 0..w {
                let d = mount.to_world(pose, cam.unproject(x as f64 + 0.5, y as f64 + 0.5).expect("ray"));
                let el = d[2].asin().to_degrees() as f32;
                rgb[3 * (y * w + x)..3 * (y * w + x) + 3].copy_from_slice(&[el, el, el]);
            }
        }
        let mut valid = vec![true; w * h];
        valid[0] = false;
        let frame = SkyFrame {
            width: w,
            height: h,
            rgb: &rgb,
            valid: Some(&valid),
            camera: cam,
            mount,
            pose,
        };
        let mut m = EnvironmentMap::new(18, 36);
        assert_eq!(m.add_frame(&frame, 1), Ok(w * h - 1));
        let short = SkyFrame {
            rgb: &rgb[..10],
            ..frame
        };
        assert!(matches!(m.add_frame(&short, 1), Err(FrameSampleError::Size { .. })));
        // Only eastern sectors (azimuth 45°–135°) received samples.
        for (i, r) in m.regions.iter().enumerate() {
            let az = ((i % 36) as f64 + 0.5) * 10.0;
            if r.count > 0 {
                assert!((40.0..140.0).contains(&az), "sector {az}° got {} samples", r.count);
                // Row i/18 spans elevations [-90 + 10 row, -80 + 10 row): its mean is inside.
                let lo = -90.0 + 10.0 * (i / 36) as f64;
                assert!(
                    (lo - 1e-9..lo + 10.0 + 1e-9).contains(&r.mean[0]),
                    "{} not in [{lo}, {}]",
                    r.mean[0],
                    lo + 10.0
                );
            }
        }
    }

    #[test]
    fn directions_land_in_the_right_region_and_centres_round_trip() {
        let m = EnvironmentMap::new(6, 12);
        for i in 0..m.regions.len() {
            assert_eq!(m.region_of(m.region_centre(i)), i);
        }
        // Due east, slightly below the horizon: row 2 (−30°..0°), column 3 (90°..120°).
        let d = [(-0.1f64).cos(), 0.0, (-0.1f64).sin()];
        assert_eq!(m.region_of(d), 2 * 12 + 3);
    }
}

//! The sky of one scan by region, for the sky-condition index
//! ([`super::condition`]): the mean measured radiance per channel in each
//! of [`REGION_COUNT`] regions of the dome (zenith bands × azimuth
//! sectors, the sun's neighbourhood left out) and in the sun's
//! neighbourhood itself (an annulus from the disc's margin out to
//! [`NEAR_SUN_DEG`]).
//!
//! The regions are fixed in the sky (sectors from north through east), so
//! that a region is the same patch of dome in every scan; the sun's
//! neighbourhood moves with the sun and is taken out of every region.

use serde::{Deserialize, Serialize};

use super::sky_pixels::for_each_sky_pixel;
use crate::pipeline::{MergedGroup, SUN_MARGIN_RAD, StationOptics};
use crate::sky::{angle_between, direction};

/// Edges of the zenith bands, degrees. Below 80° of zenith angle the
/// horizon's occluders and the ground's glow dominate, so the last band
/// stops there.
pub const BAND_EDGES_DEG: [f64; 4] = [0.0, 30.0, 60.0, 80.0];
/// Azimuth sectors per band (45° each, the first from north to north-east).
pub const SECTORS: usize = 8;
/// Regions of the dome: bands × sectors.
pub const REGION_COUNT: usize = (BAND_EDGES_DEG.len() - 1) * SECTORS;
/// Outer radius of the sun's neighbourhood, degrees from the sun's centre
/// (the inner one is the sky fit's margin around the disc, 3°).
pub const NEAR_SUN_DEG: f64 = 15.0;
/// Fewest valid pixels a region needs to have a measured mean.
pub const MIN_REGION_PIXELS: usize = 8;

/// The region of a direction (unit vector, z up) with the sun at unit
/// vector `sun`: `Some(index)` in a band × sector region, `None` below the
/// last band or within [`NEAR_SUN_DEG`] of the sun.
pub fn region_of(d: [f64; 3], sun: [f64; 3]) -> Option<usize> {
    if d[2] <= 0.0 || angle_between(d, sun) < NEAR_SUN_DEG.to_radians() {
        return None;
    }
    let xi = d[2].min(1.0).acos().to_degrees();
    let band = BAND_EDGES_DEG.windows(2).position(|w| xi >= w[0] && xi < w[1])?;
    let azimuth = d[0].atan2(d[1]).to_degrees().rem_euclid(360.0);
    let sector = ((azimuth / (360.0 / SECTORS as f64)) as usize).min(SECTORS - 1);
    Some(band * SECTORS + sector)
}

/// Whether a direction lies in the sun's neighbourhood: above the
/// horizon, between the disc's margin ([`SUN_MARGIN_RAD`]) and [`NEAR_SUN_DEG`].
pub fn in_sun_neighbourhood(d: [f64; 3], sun: [f64; 3]) -> bool {
    let g = angle_between(d, sun);
    d[2] > 0.0 && (SUN_MARGIN_RAD..NEAR_SUN_DEG.to_radians()).contains(&g)
}

/// Solid angle of a whole band × sector region, steradians.
pub fn region_solid_angle(region: usize) -> f64 {
    let band = region / SECTORS;
    let (lo, hi) = (BAND_EDGES_DEG[band].to_radians(), BAND_EDGES_DEG[band + 1].to_radians());
    std::f64::consts::TAU * (lo.cos() - hi.cos()) / SECTORS as f64
}

/// Directions spread evenly in solid angle over `region` (`n` × `n`, in
/// cos ξ and azimuth), those in the sun's exclusion left out.
pub fn region_grid(region: usize, sun: [f64; 3], n: usize) -> Vec<[f64; 3]> {
    let band = region / SECTORS;
    let sector = region % SECTORS;
    let (c0, c1) = (
        BAND_EDGES_DEG[band].to_radians().cos(),
        BAND_EDGES_DEG[band + 1].to_radians().cos(),
    );
    let width = std::f64::consts::TAU / SECTORS as f64;
    let mut out = Vec::with_capacity(n * n);
    for i in 0..n {
        let cos_xi = c0 + (c1 - c0) * (i as f64 + 0.5) / n as f64;
        for j in 0..n {
            let az = width * (sector as f64 + (j as f64 + 0.5) / n as f64);
            let d = direction(cos_xi.clamp(-1.0, 1.0).acos(), az);
            if region_of(d, sun) == Some(region) {
                out.push(d);
            }
        }
    }
    out
}

/// Directions spread evenly over the sun's neighbourhood (`n` rings × `2n`
/// around), those below the horizon left out.
pub fn sun_neighbourhood_grid(sun: [f64; 3], n: usize) -> Vec<[f64; 3]> {
    // An orthonormal frame around the sun.
    let helper = if sun[2].abs() < 0.9 {
        [0.0, 0.0, 1.0]
    } else {
        [1.0, 0.0, 0.0]
    };
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let norm = |v: [f64; 3]| {
        let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        v.map(|x| x / l)
    };
    let u = norm(cross(sun, helper));
    let v = cross(sun, u);
    let (c0, c1) = (SUN_MARGIN_RAD.cos(), NEAR_SUN_DEG.to_radians().cos());
    let mut out = Vec::new();
    for i in 0..n {
        let g = (c0 + (c1 - c0) * (i as f64 + 0.5) / n as f64).acos();
        for j in 0..2 * n {
            let phi = std::f64::consts::TAU * (j as f64 + 0.5) / (2 * n) as f64;
            let (s, c) = (g.sin(), g.cos());
            let d = [0, 1, 2].map(|k| c * sun[k] + s * (phi.cos() * u[k] + phi.sin() * v[k]));
            if d[2] > 0.0 {
                out.push(d);
            }
        }
    }
    out
}

/// One scan's measured sky by region.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct SkyRegions {
    /// Mean measured radiance per channel in each band × sector region,
    /// W·m⁻²·sr⁻¹ (`None`: fewer than [`MIN_REGION_PIXELS`] valid pixels).
    /// Empty in products written before regions were kept.
    pub measured: Vec<Option<[f64; 3]>>,
    /// Valid pixels per region.
    pub pixels: Vec<usize>,
    /// Mean measured radiance in the sun's neighbourhood (`None`: too few pixels).
    pub near_sun: Option<[f64; 3]>,
    /// Valid pixels in the sun's neighbourhood.
    pub near_sun_pixels: usize,
}

/// Accumulates radiance samples by region.
#[derive(Debug, Clone)]
pub struct RegionSums {
    sun: [f64; 3],
    sum: Vec<[f64; 3]>,
    count: Vec<usize>,
    near_sum: [f64; 3],
    near_count: usize,
}

impl RegionSums {
    /// Empty sums for the sun at unit vector `sun`.
    pub fn new(sun: [f64; 3]) -> RegionSums {
        RegionSums {
            sun,
            sum: vec![[0.0; 3]; REGION_COUNT],
            count: vec![0; REGION_COUNT],
            near_sum: [0.0; 3],
            near_count: 0,
        }
    }

    /// Adds the radiance `rgb` seen in direction `d` (non-finite or negative values are skipped).
    pub fn add(&mut self, d: [f64; 3], rgb: [f64; 3]) {
        if !rgb.iter().all(|v| v.is_finite() && *v >= 0.0) {
            return;
        }
        if let Some(r) = region_of(d, self.sun) {
            (0..3).for_each(|c| self.sum[r][c] += rgb[c]);
            self.count[r] += 1;
        } else if in_sun_neighbourhood(d, self.sun) {
            (0..3).for_each(|c| self.near_sum[c] += rgb[c]);
            self.near_count += 1;
        }
    }

    /// The means.
    pub fn finish(self) -> SkyRegions {
        let mean = |s: [f64; 3], k: usize| (k >= MIN_REGION_PIXELS).then(|| s.map(|v| v / k as f64));
        SkyRegions {
            measured: self.sum.iter().zip(&self.count).map(|(s, &k)| mean(*s, k)).collect(),
            pixels: self.count,
            near_sun: mean(self.near_sum, self.near_count),
            near_sun_pixels: self.near_count,
        }
    }
}

/// The sky of `occurrence`'s sky groups in `merged` by region (every
/// `stride`-th pixel in each direction; masked pixels left out).
pub fn sky_regions(
    merged: &[MergedGroup],
    optics: &StationOptics,
    occurrence: &str,
    sun: [f64; 3],
    stride: usize,
) -> SkyRegions {
    let mut sums = RegionSums::new(sun);
    for_each_sky_pixel(merged, optics, occurrence, stride, |d, rgb| sums.add(d, rgb));
    sums.finish()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regions_tile_the_dome_and_leave_the_sun_out() {
        let total: f64 = (0..REGION_COUNT).map(region_solid_angle).sum();
        // The cap down to 80°: 2π (1 − cos 80°).
        assert!((total - std::f64::consts::TAU * (1.0 - 80f64.to_radians().cos())).abs() < 1e-12);
        let sun = direction(40f64.to_radians(), 90f64.to_radians());
        // North at 10° is band 0 sector 0; east at 70° is band 2 sector 2.
        assert_eq!(region_of(direction(0.17, 0.01), sun), Some(0));
        assert_eq!(
            region_of(direction(70f64.to_radians(), 91f64.to_radians()), sun),
            Some(2 * SECTORS + 2)
        );
        // Within 15° of the sun: the neighbourhood, no region.
        let near = direction(48f64.to_radians(), 92f64.to_radians());
        assert_eq!(region_of(near, sun), None);
        assert!(in_sun_neighbourhood(near, sun));
        assert!(!in_sun_neighbourhood(sun, sun));
        // Below 80°: nothing.
        assert_eq!(region_of(direction(85f64.to_radians(), 0.0), sun), None);
        // Grids stay in their region, and an even grid over a region away
        // from the sun is as large as asked.
        for r in 0..REGION_COUNT {
            assert!(region_grid(r, sun, 6).iter().all(|&d| region_of(d, sun) == Some(r)));
        }
        assert_eq!(region_grid(SECTORS + 5, sun, 6).len(), 36);
        let ring = sun_neighbourhood_grid(sun, 4);
        assert_eq!(ring.len(), 32);
        assert!(ring.iter().all(|&d| in_sun_neighbourhood(d, sun)));
    }

    #[test]
    fn sums_give_means_of_enough_pixels() {
        let sun = direction(30f64.to_radians(), 180f64.to_radians());
        let mut s = RegionSums::new(sun);
        let d = direction(10f64.to_radians(), 10f64.to_radians());
        for k in 0..MIN_REGION_PIXELS {
            s.add(d, [1.0 + k as f64, 2.0, 3.0]);
        }
        s.add(d, [f64::NAN, 1.0, 1.0]);
        let near = direction(25f64.to_radians(), 180f64.to_radians());
        s.add(near, [5.0, 5.0, 5.0]);
        let r = s.finish();
        assert_eq!(r.pixels[0], MIN_REGION_PIXELS);
        assert_eq!(r.measured[0], Some([4.5, 2.0, 3.0]));
        assert_eq!(r.measured[1], None);
        assert_eq!(r.near_sun_pixels, 1);
        assert_eq!(r.near_sun, None);
    }
}

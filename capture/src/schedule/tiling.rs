//! Tilings of the sphere of directions by camera frames: rows of tiles
//! over an elevation band (sky scans and environment tiles, thesis §5.3.2
//! and §5.3.3), a zenith or nadir cap, and rings of tiles around the sun
//! for the aureole (§5.3.2).
//!
//! A tile is the direction of the optical axis, with the image's horizontal
//! axis level (as a pan-tilt head holds it). Coverage is computed with the
//! field of view shrunk by the step's overlap ([`FieldOfView::shrunk`]), so
//! neighbouring tiles overlap by at least that fraction:
//!
//! - Rows: from the band's bottom up, each row `0.9 × 2 × v'` tall (`v'`
//!   the shrunk vertical half-angle; the 10% leaves room for the curvature
//!   of a frame's top and bottom edges away from its centre), shrunk further
//!   by 10% at a time if no number of tiles covers it. Each row gets the
//!   fewest tiles, evenly spaced in azimuth from 0°, such that every
//!   direction of the row lies inside the shrunk frame of its nearest tile.
//!   This is exact on the pinhole's tangent-space rectangle, checked on 33
//!   azimuth offsets between tiles with a 0.01° margin.
//! - Caps: when the band reaches within `min(h', v')` of the zenith (nadir)
//!   a single tile points straight up (down), and the rows stop there.
//! - Rings: `k` tiles centred on a circle of angular radius `r` around a
//!   direction, the fewest for which the inscribed cone (`min(h', v')`) of
//!   each covers its arc of the circle; the first tile on the side toward
//!   the zenith, then clockwise as seen facing the centre.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use serde::{Deserialize, Serialize};

use super::error::ScheduleError;
use super::field_of_view::FieldOfView;

/// Fraction of a row's nominal height actually given to it.
const ROW_FILL: f64 = 0.9;
/// Azimuth offsets checked between two tiles of a row.
const OFFSET_SAMPLES: usize = 32;
/// Margin at the band edges when checking a row, radians (0.01°).
const EDGE_MARGIN_RAD: f64 = 0.01 * PI / 180.0;
/// The most tiles in one row.
const MAX_TILES_PER_ROW: usize = 1440;

/// Where one frame of a tiling points: its optical axis, degrees.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Tile {
    /// Azimuth from north through east, in [0, 360).
    pub azimuth_deg: f64,
    /// Elevation above the horizon, in [−90, 90].
    pub elevation_deg: f64,
}

/// A tiling in rows, bottom to top; a cap is a row of one tile.
pub type Rows = Vec<Vec<Tile>>;

/// The elevation interval `[lo, hi]` (radians) covered on the meridian at
/// azimuth offset `delta` from the centre of a level frame at elevation
/// `ec` with tangent half-extents `tx`, `ty`; `None` if the frame misses it.
///
/// With `d = (cos e cos δ, cos e sin δ, sin e)` in (ahead, right, up), each
/// of `tx z ∓ x ≥ 0`, `ty z ∓ y ≥ 0` reads `a cos e + b sin e ≥ 0`, i.e.
/// `e ∈ [φ − π/2, φ + π/2]` with `φ = atan2(b, a)`.
fn meridian_interval(ec: f64, delta: f64, tx: f64, ty: f64) -> Option<(f64, f64)> {
    let (se, ce) = ec.sin_cos();
    let (sd, cd) = delta.sin_cos();
    let constraints = [
        (tx * cd * ce - sd, tx * se),
        (tx * cd * ce + sd, tx * se),
        (ty * cd * ce + cd * se, ty * se - ce),
        (ty * cd * ce - cd * se, ty * se + ce),
    ];
    let (mut lo, mut hi) = (-FRAC_PI_2, FRAC_PI_2);
    for (a, b) in constraints {
        let phi = b.atan2(a);
        lo = lo.max(phi - FRAC_PI_2);
        hi = hi.min(phi + FRAC_PI_2);
    }
    (lo <= hi).then_some((lo, hi))
}

/// Whether `n` level frames centred at elevation `ec`, spaced evenly in
/// azimuth, cover every direction with elevation in `[a, b]`.
fn row_covers(ec: f64, n: usize, a: f64, b: f64, tx: f64, ty: f64) -> bool {
    let half_gap = PI / n as f64;
    (0..=OFFSET_SAMPLES).all(|k| {
        let delta = half_gap * k as f64 / OFFSET_SAMPLES as f64;
        meridian_interval(ec, delta, tx, ty).is_some_and(|(lo, hi)| {
            lo <= a - EDGE_MARGIN_RAD && hi >= b.min(FRAC_PI_2 - EDGE_MARGIN_RAD) + EDGE_MARGIN_RAD
        })
    })
}

/// Rows of tiles covering elevations `[min, max]` (degrees) with at least
/// `overlap` between neighbours; see the module documentation.
pub fn band_rows(fov: &FieldOfView, overlap: f64, min_deg: f64, max_deg: f64) -> Result<Rows, ScheduleError> {
    let shrunk = fov.shrunk(overlap);
    let (tx, ty) = (shrunk.half_horizontal_rad.tan(), shrunk.half_vertical_rad.tan());
    let cap = shrunk.half_horizontal_rad.min(shrunk.half_vertical_rad);
    let (mut bottom, mut top) = (
        min_deg.to_radians().max(-FRAC_PI_2),
        max_deg.to_radians().min(FRAC_PI_2),
    );
    let nadir = bottom <= -FRAC_PI_2 + cap;
    let zenith = top >= FRAC_PI_2 - cap;
    if nadir {
        bottom = -FRAC_PI_2 + cap;
    }
    if zenith {
        top = FRAC_PI_2 - cap;
    }
    let mut rows = Vec::new();
    if nadir {
        rows.push(vec![Tile {
            azimuth_deg: 0.0,
            elevation_deg: -90.0,
        }]);
    }
    let nominal = ROW_FILL * 2.0 * shrunk.half_vertical_rad;
    let mut a = bottom;
    while a < top - 1e-9 {
        let mut height = nominal;
        let (b, n) = loop {
            if height < 1e-4 {
                return Err(ScheduleError::Tiling {
                    reason: format!(
                        "no row of frames covers elevation {:.2}°: the field of view ({:.3}° × {:.3}°) is too small",
                        a.to_degrees(),
                        2.0 * fov.half_horizontal_rad.to_degrees(),
                        2.0 * fov.half_vertical_rad.to_degrees()
                    ),
                });
            }
            let b = (a + height).min(top);
            let ec = 0.5 * (a + b);
            if let Some(n) = (1..=MAX_TILES_PER_ROW).find(|&n| row_covers(ec, n, a, b, tx, ty)) {
                break (b, n);
            }
            height *= 0.9;
        };
        let ec = (0.5 * (a + b)).to_degrees();
        rows.push(
            (0..n)
                .map(|j| Tile {
                    azimuth_deg: 360.0 * j as f64 / n as f64,
                    elevation_deg: ec,
                })
                .collect(),
        );
        a = b;
    }
    if zenith {
        rows.push(vec![Tile {
            azimuth_deg: 0.0,
            elevation_deg: 90.0,
        }]);
    }
    Ok(rows)
}

/// The sky scan: rows from `min_elevation_deg` up, and the zenith tile.
pub fn sky_rows(fov: &FieldOfView, overlap: f64, min_elevation_deg: f64) -> Result<Rows, ScheduleError> {
    band_rows(fov, overlap, min_elevation_deg, 90.0)
}

/// Unit world direction (x east, y north, z up) of azimuth and elevation in radians.
pub fn direction(azimuth_rad: f64, elevation_rad: f64) -> [f64; 3] {
    let (sa, ca) = azimuth_rad.sin_cos();
    let (se, ce) = elevation_rad.sin_cos();
    [ce * sa, ce * ca, se]
}

/// Azimuth in [0°, 360°) and elevation of a unit world direction, degrees.
pub fn azimuth_elevation_deg(d: [f64; 3]) -> (f64, f64) {
    let az = d[0].atan2(d[1]).to_degrees().rem_euclid(360.0);
    (
        if az >= 360.0 { 0.0 } else { az },
        d[2].clamp(-1.0, 1.0).asin().to_degrees(),
    )
}

/// Tiles on a ring of angular radius `radius_deg` around the direction
/// (`azimuth_deg`, `elevation_deg`); see the module documentation.
pub fn ring_tiles(fov: &FieldOfView, overlap: f64, azimuth_deg: f64, elevation_deg: f64, radius_deg: f64) -> Vec<Tile> {
    let shrunk = fov.shrunk(overlap);
    let c = shrunk.half_horizontal_rad.min(shrunk.half_vertical_rad);
    let r = radius_deg.to_radians();
    // A tile centred on the ring covers the ring points within angle c of
    // its centre: cos c ≤ cos² r + sin² r cos ψ.
    let cos_psi = (c.cos() - r.cos() * r.cos()) / (r.sin() * r.sin()).max(1e-300);
    let k = if cos_psi <= -1.0 {
        1
    } else {
        (PI / cos_psi.clamp(-1.0, 1.0).acos()).ceil().max(1.0) as usize
    };
    let s = direction(azimuth_deg.to_radians(), elevation_deg.to_radians());
    (0..k)
        .map(|j| {
            let (azimuth_deg, elevation_deg) = azimuth_elevation_deg(ring_point(s, r, TAU * j as f64 / k as f64));
            Tile {
                azimuth_deg,
                elevation_deg,
            }
        })
        .collect()
}

/// The direction at angle `r` from unit direction `s`, at position angle
/// `psi` measured from the side toward the zenith (toward north when `s`
/// is vertical), clockwise as seen facing `s`.
pub fn ring_point(s: [f64; 3], r: f64, psi: f64) -> [f64; 3] {
    let up = [-s[2] * s[0], -s[2] * s[1], 1.0 - s[2] * s[2]];
    let len = (up[0] * up[0] + up[1] * up[1] + up[2] * up[2]).sqrt();
    let up = if len < 1e-9 {
        [0.0, 1.0, 0.0]
    } else {
        up.map(|x| x / len)
    };
    // side = up × s: to the right when facing s with up on top.
    let side = [
        up[1] * s[2] - up[2] * s[1],
        up[2] * s[0] - up[0] * s[2],
        up[0] * s[1] - up[1] * s[0],
    ];
    let (sp, cp) = psi.sin_cos();
    [0, 1, 2].map(|i| r.cos() * s[i] + r.sin() * (cp * up[i] + sp * side[i]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::schedule::field_of_view::tests::camera;
    use crate::schedule::field_of_view::{FieldOfView, pinhole};
    use campanile_config::camera::Camera;
    use campanile_process::pose::{HeadPose, Mount};

    /// `n` directions spread evenly over the sphere (Fibonacci lattice).
    fn fibonacci(n: usize) -> impl Iterator<Item = [f64; 3]> {
        let golden = PI * (3.0 - 5f64.sqrt());
        (0..n).map(move |i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let r = (1.0 - z * z).sqrt();
            let phi = golden * i as f64;
            [r * phi.cos(), r * phi.sin(), z]
        })
    }

    /// Whether the world direction `d` lands inside the image of a frame
    /// taken at `tile` (level head, the camera's own distortion).
    fn sees(camera: &Camera, tile: &Tile, d: [f64; 3]) -> bool {
        let pose = HeadPose {
            pan_rad: tile.azimuth_deg.to_radians(),
            tilt_rad: tile.elevation_deg.to_radians(),
        };
        let c = Mount::default().to_camera(pose, d);
        let (w, h) = (f64::from(camera.resolution.width), f64::from(camera.resolution.height));
        pinhole(camera)
            .project(c)
            .is_some_and(|(u, v)| (0.0..=w).contains(&u) && (0.0..=h).contains(&v))
    }

    /// Returns how many of 20 000 (or more) sampled directions with
    /// elevation in `[min, max]` no tile sees.
    fn misses(camera: &Camera, rows: &Rows, min_deg: f64, max_deg: f64) -> (usize, usize) {
        let (lo, hi) = (min_deg.to_radians().sin(), max_deg.to_radians().sin());
        let total = (20_000.0 * 2.0 / (hi - lo)).ceil() as usize;
        let inside: Vec<[f64; 3]> = fibonacci(total).filter(|d| (lo..=hi).contains(&d[2])).collect();
        let missed = inside
            .iter()
            .filter(|d| !rows.iter().flatten().any(|t| sees(camera, t, **d)))
            .count();
        (missed, inside.len())
    }

    /// Every one of ≥ 20 000 directions above the horizon falls inside at
    /// least one sky tile's image, for the example station's camera
    /// (60° × 47°, barrel distortion) with 20% and with no overlap, and for
    /// a narrow 20° 4:3 camera.
    #[test]
    fn sky_tiles_cover_every_direction_above_the_minimum_elevation() {
        for (cam, overlap, min_el) in [
            (camera(60.0, 256, 192, (-0.05, 0.01)), 0.2, 0.0),
            (camera(60.0, 256, 192, (-0.05, 0.01)), 0.0, 0.0),
            (camera(20.0, 640, 480, (0.02, 0.0)), 0.1, -5.0),
        ] {
            let fov = FieldOfView::of_camera(&cam);
            let rows = sky_rows(&fov, overlap, min_el).expect("tiles");
            assert_eq!(rows.last().map(|r| r[0].elevation_deg), Some(90.0), "zenith tile last");
            let (missed, of) = misses(&cam, &rows, min_el, 90.0);
            assert!(of >= 20_000);
            assert_eq!(missed, 0, "{missed} of {of} directions unseen; rows {rows:?}");
        }
    }

    /// Environment tiles from −30° to 10° cover their band the same way.
    #[test]
    fn environment_tiles_cover_their_band() {
        let cam = camera(60.0, 256, 192, (-0.05, 0.01));
        let rows = band_rows(&FieldOfView::of_camera(&cam), 0.2, -30.0, 10.0).expect("tiles");
        assert!(
            rows.iter().all(|r| r.len() > 1),
            "no caps in a band away from the poles"
        );
        assert_eq!(misses(&cam, &rows, -30.0, 10.0).0, 0);
    }

    /// The tile counts for the example camera: rows of 34.0°-wide
    /// (shrunk) frames need at least 360 × cos e / 48° tiles (48° = the
    /// shrunk horizontal field), so the horizon row has at least 8.
    #[test]
    fn the_horizon_row_has_at_least_the_nominal_count() {
        let cam = camera(60.0, 256, 192, (-0.05, 0.01));
        let fov = FieldOfView::of_camera(&cam);
        let rows = sky_rows(&fov, 0.2, 0.0).expect("tiles");
        let nominal = (360.0 / (2.0 * fov.shrunk(0.2).half_horizontal_rad.to_degrees())).ceil() as usize;
        assert!(rows[0].len() >= nominal, "{} < {nominal}", rows[0].len());
    }

    /// Every point of an aureole ring (sampled every 0.5°) is seen by one
    /// of its tiles, for small and large radii and a sun near the zenith.
    #[test]
    fn ring_tiles_cover_their_ring() {
        let cam = camera(60.0, 256, 192, (-0.05, 0.01));
        let fov = FieldOfView::of_camera(&cam);
        for (az, el, r) in [
            (120.0, 25.0, 5.0),
            (200.0, 60.0, 10.0),
            (240.0, 12.0, 40.0),
            (0.0, 89.0, 20.0),
        ] {
            let tiles = ring_tiles(&fov, 0.2, az, el, r);
            let s = direction(f64::to_radians(az), f64::to_radians(el));
            let r_rad = f64::to_radians(r);
            for k in 0..720 {
                let d = ring_point(s, r_rad, TAU * k as f64 / 720.0);
                let angle = (d[0] * s[0] + d[1] * s[1] + d[2] * s[2]).clamp(-1.0, 1.0).acos();
                assert!(
                    (angle - r_rad).abs() < 1e-12,
                    "ring point {k} at {angle} rad from the centre"
                );
                assert!(
                    tiles.iter().any(|t| sees(&cam, t, d)),
                    "ring ({az}, {el}, {r}) point {k} unseen"
                );
            }
        }
    }

    #[test]
    fn directions_round_trip() {
        let (az, el) = azimuth_elevation_deg(direction(1.0, 0.3));
        assert!((az.to_radians() - 1.0).abs() < 1e-12 && (el.to_radians() - 0.3).abs() < 1e-12);
    }
}

//! An analytic range scan of a box room, with the true surface of every
//! point: for the segmentation's tests and bench until the simulated
//! scanner (issue 28) is there, and as a reference independent of it.
//!
//! The room is 4 × 3 × 2.5 m (x, y, z), with optionally a table (a slab
//! 1.0 × 0.8 m, 3 cm thick, its top at 0.75 m), a curtain (a sinusoidal
//! sheet in front of the wall y = 3, amplitude 5 cm, wavelength 0.4 m) and a
//! calibration target (a bright disc of 0.1 m radius on a dark 0.4 m square
//! on the wall x = 0). The scanner sweeps `cols` azimuths over 360° and
//! `rows` elevations from −60° to +60°; every ray is intersected with the
//! surfaces exactly, and the range gets Gaussian noise.

use nalgebra::{Rotation3, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

use crate::cloud::{NO_RETURN, RangeGrid, Scan, ScannerPose};
use crate::segmentation::Segmentation;

/// The room's size, m.
pub const ROOM: [f64; 3] = [4.0, 3.0, 2.5];

/// What to put in the room and how to scan it.
#[derive(Debug, Clone, PartialEq)]
pub struct RoomScan {
    /// Scanner centre.
    pub scanner: Vector3<f64>,
    /// Elevation steps.
    pub rows: usize,
    /// Azimuth steps.
    pub cols: usize,
    /// Range noise (σ), m.
    pub noise_m: f64,
    /// Intensity noise (σ).
    pub intensity_noise: f64,
    /// The table.
    pub table: bool,
    /// The curtain.
    pub curtain: bool,
    /// The target.
    pub target: bool,
    /// Keep the pose in the scan.
    pub pose: bool,
    /// Noise seed.
    pub seed: u64,
}

impl Default for RoomScan {
    fn default() -> RoomScan {
        RoomScan {
            scanner: Vector3::new(2.6, 1.2, 1.5),
            rows: 90,
            cols: 240,
            noise_m: 0.005,
            intensity_noise: 0.01,
            table: true,
            curtain: false,
            target: false,
            pose: true,
            seed: 1,
        }
    }
}

/// The true surfaces, in label order.
pub const SURFACES: [&str; 12] = [
    "floor",
    "ceiling",
    "wall_x0",
    "wall_x4",
    "wall_y0",
    "wall_y3",
    "table_top",
    "table_bottom",
    "table_edge",
    "curtain",
    "target_disc",
    "target_patch",
];

const TABLE_MIN: [f64; 3] = [1.5, 1.0, 0.72];
const TABLE_MAX: [f64; 3] = [2.5, 1.8, 0.75];
const CURTAIN_Y: f64 = 2.9;
const CURTAIN_AMPLITUDE: f64 = 0.05;
const CURTAIN_WAVELENGTH: f64 = 0.4;
const CURTAIN_X: [f64; 2] = [0.4, 1.6];
const CURTAIN_Z: [f64; 2] = [0.2, 2.3];
/// The target's centre on the wall x = 0 (y, z), disc radius, patch half-width.
const TARGET: [f64; 4] = [1.5, 1.4, 0.1, 0.2];

/// The surface label and intensity where the ray o + t d first hits, and t.
fn trace(o: &Vector3<f64>, d: &Vector3<f64>, spec: &RoomScan) -> Option<(f64, u32, f32)> {
    // The room from inside: the nearest wall plane ahead.
    let mut best: Option<(f64, u32)> = None;
    for axis in 0..3 {
        if d[axis].abs() < 1e-12 {
            continue;
        }
        let (plane, label) = if d[axis] > 0.0 {
            (ROOM[axis], [3, 5, 1][axis])
        } else {
            (0.0, [2, 4, 0][axis])
        };
        let t = (plane - o[axis]) / d[axis];
        if t > 0.0 && best.is_none_or(|(b, _)| t < b) {
            best = Some((t, label));
        }
    }
    let (mut t, mut label) = best?;
    if spec.table {
        // Ray–box slab test.
        let (mut t0, mut t1, mut entry) = (0.0_f64, f64::INFINITY, None);
        let mut hit = true;
        for axis in 0..3 {
            if d[axis].abs() < 1e-12 {
                if o[axis] < TABLE_MIN[axis] || o[axis] > TABLE_MAX[axis] {
                    hit = false;
                }
                continue;
            }
            let a = (TABLE_MIN[axis] - o[axis]) / d[axis];
            let b = (TABLE_MAX[axis] - o[axis]) / d[axis];
            let (near, far) = if a < b { (a, b) } else { (b, a) };
            if near > t0 {
                t0 = near;
                entry = Some((axis, d[axis] > 0.0));
            }
            t1 = t1.min(far);
        }
        if hit && t0 <= t1 && t0 > 0.0 && t0 < t {
            t = t0;
            label = match entry {
                Some((2, false)) => 6,
                Some((2, true)) => 7,
                _ => 8,
            };
        }
    }
    if spec.curtain && d.y > 0.0 {
        let y_lo = CURTAIN_Y - CURTAIN_AMPLITUDE - 1e-3;
        let y_hi = CURTAIN_Y + CURTAIN_AMPLITUDE + 1e-3;
        let (ta, tb) = ((y_lo - o.y) / d.y, (y_hi - o.y) / d.y);
        if ta > 0.0 && ta < t {
            let f = |t: f64| {
                let p = o + d * t;
                p.y - (CURTAIN_Y + CURTAIN_AMPLITUDE * (std::f64::consts::TAU * p.x / CURTAIN_WAVELENGTH).sin())
            };
            let steps = 64;
            let mut prev = ta;
            for s in 1..=steps {
                let cur = ta + (tb - ta) * f64::from(s) / f64::from(steps);
                if f(prev) < 0.0 && f(cur) >= 0.0 {
                    let (mut lo, mut hi) = (prev, cur);
                    for _ in 0..50 {
                        let mid = 0.5 * (lo + hi);
                        if f(mid) < 0.0 { lo = mid } else { hi = mid }
                    }
                    let p = o + d * hi;
                    if (CURTAIN_X[0]..=CURTAIN_X[1]).contains(&p.x)
                        && (CURTAIN_Z[0]..=CURTAIN_Z[1]).contains(&p.z)
                        && hi < t
                    {
                        t = hi;
                        label = 9;
                    }
                    break;
                }
                prev = cur;
            }
        }
    }
    let p = o + d * t;
    if spec.target && label == 2 {
        let (dy, dz) = (p.y - TARGET[0], p.z - TARGET[1]);
        if dy.hypot(dz) <= TARGET[2] {
            label = 10;
        } else if dy.abs() <= TARGET[3] && dz.abs() <= TARGET[3] {
            label = 11;
        }
    }
    let intensity = match label {
        0 => 0.3,
        6..=8 => 0.45,
        9 => 0.6,
        10 => 0.95,
        11 => 0.1,
        _ => 0.5,
    };
    Some((t, label, intensity))
}

/// The scan and its truth.
pub fn scan_room(spec: &RoomScan) -> (Scan, Segmentation) {
    let mut rng = ChaCha8Rng::seed_from_u64(spec.seed);
    let range_noise = Normal::new(0.0, spec.noise_m.max(0.0)).unwrap_or(Normal::new(0.0, 0.0).expect("σ = 0 is valid"));
    let intensity_noise =
        Normal::new(0.0, spec.intensity_noise.max(0.0)).unwrap_or(Normal::new(0.0, 0.0).expect("σ = 0 is valid"));
    let mut positions = Vec::new();
    let mut intensity = Vec::new();
    let mut labels = Vec::new();
    let mut cells = vec![NO_RETURN; spec.rows * spec.cols];
    for r in 0..spec.rows {
        let elevation = (-60.0 + 120.0 * (r as f64 + 0.5) / spec.rows as f64).to_radians();
        for c in 0..spec.cols {
            let azimuth = std::f64::consts::TAU * (c as f64 + 0.5) / spec.cols as f64;
            let d = Vector3::new(
                elevation.cos() * azimuth.cos(),
                elevation.cos() * azimuth.sin(),
                elevation.sin(),
            );
            if let Some((t, label, i)) = trace(&spec.scanner, &d, spec) {
                cells[r * spec.cols + c] = positions.len() as u32;
                positions.push(spec.scanner + d * (t + range_noise.sample(&mut rng)));
                intensity.push((i + intensity_noise.sample(&mut rng) as f32).clamp(0.0, 1.0));
                labels.push(label);
            }
        }
    }
    let mut scan = Scan::from_positions("box room", positions);
    scan.intensity = Some(intensity);
    scan.grid = Some(RangeGrid {
        rows: spec.rows,
        cols: spec.cols,
        cells,
    });
    if spec.pose {
        scan.pose = Some(ScannerPose {
            origin: spec.scanner,
            rotation: Rotation3::identity(),
        });
    }
    let truth = Segmentation {
        labels: vec![labels],
        names: SURFACES.iter().map(|s| (*s).to_string()).collect(),
    };
    (scan, truth)
}

/// The target's true centre and normal.
pub fn target_truth() -> (Vector3<f64>, Vector3<f64>, f64) {
    (Vector3::new(0.0, TARGET[0], TARGET[1]), Vector3::x(), TARGET[2])
}

//! Scenes built for tests and benchmarks: axis-aligned rectangles (a box
//! room, a cabinet in it) scanned from a point by an ideal organised
//! scanner, with uniform range noise and every return labelled with the
//! rectangle it hit; and a sphere seen from six sides as unorganised
//! clouds. No mixed pixels, dropouts or intensity: the simulated
//! range scanner (`campanile-sim`) is the realistic one.

use nalgebra::{Rotation3, Vector3};

use crate::cloud::{NO_RETURN, RangeGrid, Scan, ScannerPose};
use crate::mesh::TriangleMesh;
use crate::obj_file::NamedMesh;
use crate::segmentation::Segmentation;

/// An axis-aligned rectangle: coordinate `axis` is `at`, the other two
/// (in x, y, z order) span `lo..hi`.
#[derive(Debug, Clone)]
pub struct Rect {
    /// The surface's name (the segmentation's and the truth's).
    pub name: String,
    /// The axis the rectangle is normal to: 0 x, 1 y, 2 z.
    pub axis: usize,
    /// Its coordinate along that axis, metres.
    pub at: f64,
    /// The low corner along the other two axes (in x, y, z order).
    pub lo: [f64; 2],
    /// The high corner.
    pub hi: [f64; 2],
}

impl Rect {
    fn others(&self) -> [usize; 2] {
        match self.axis {
            0 => [1, 2],
            1 => [0, 2],
            _ => [0, 1],
        }
    }

    fn hit(&self, origin: &Vector3<f64>, dir: &Vector3<f64>) -> Option<f64> {
        let t = (self.at - origin[self.axis]) / dir[self.axis];
        if !(t > 1e-9 && t.is_finite()) {
            return None;
        }
        let p = origin + t * dir;
        let [a, b] = self.others();
        (p[a] >= self.lo[0] && p[a] <= self.hi[0] && p[b] >= self.lo[1] && p[b] <= self.hi[1]).then_some(t)
    }

    /// The rectangle as two triangles.
    pub fn mesh(&self) -> TriangleMesh {
        let [a, b] = self.others();
        let corner = |u: f64, v: f64| {
            let mut p = Vector3::zeros();
            p[self.axis] = self.at;
            p[a] = u;
            p[b] = v;
            p
        };
        TriangleMesh {
            positions: vec![
                corner(self.lo[0], self.lo[1]),
                corner(self.hi[0], self.lo[1]),
                corner(self.hi[0], self.hi[1]),
                corner(self.lo[0], self.hi[1]),
            ],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
        }
    }
}

fn rect(name: &str, axis: usize, at: f64, lo: [f64; 2], hi: [f64; 2]) -> Rect {
    Rect {
        name: name.into(),
        axis,
        at,
        lo,
        hi,
    }
}

/// A 4 × 3 × 2.5 m room (x 0–4, y 0–3, z 0–2.5): floor, ceiling and four
/// walls.
pub fn room() -> Vec<Rect> {
    vec![
        rect("floor", 2, 0.0, [0.0, 0.0], [4.0, 3.0]),
        rect("ceiling", 2, 2.5, [0.0, 0.0], [4.0, 3.0]),
        rect("wall_west", 0, 0.0, [0.0, 0.0], [3.0, 2.5]),
        rect("wall_east", 0, 4.0, [0.0, 0.0], [3.0, 2.5]),
        rect("wall_south", 1, 0.0, [0.0, 0.0], [4.0, 2.5]),
        rect("wall_north", 1, 3.0, [0.0, 0.0], [4.0, 2.5]),
    ]
}

/// A 0.8 × 0.5 × 0.9 m cabinet standing on the floor with its west face
/// at x = 2.8, y 0.4–0.9: its top and its west and north faces (those a
/// scanner at the room's centre sees).
pub fn cabinet() -> Vec<Rect> {
    vec![
        rect("cabinet_top", 2, 0.9, [2.8, 0.4], [3.6, 0.9]),
        rect("cabinet_west", 0, 2.8, [0.4, 0.0], [0.9, 0.9]),
        rect("cabinet_north", 1, 0.9, [2.8, 0.0], [3.6, 0.9]),
    ]
}

/// A uniform deviate in [−1, 1) from `seed` and `i` (splitmix64).
fn uniform(seed: u64, i: u64) -> f64 {
    let mut z = seed.wrapping_add(i.wrapping_mul(0x9E37_79B9_7F4A_7C15));
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 52) as f64 - 1.0
}

/// An organised scan of `rects` from `origin`: azimuth 0–360° and
/// elevation ±`max_elevation_deg` every `step_deg`, the range perturbed by
/// uniform noise of standard deviation `sigma_m` (half-width √3 σ), and
/// the true segmentation (groups named as the rectangles, in their order).
pub fn scan_of(
    rects: &[Rect],
    origin: Vector3<f64>,
    step_deg: f64,
    max_elevation_deg: f64,
    sigma_m: f64,
) -> (Scan, Segmentation) {
    let rows = (2.0 * max_elevation_deg / step_deg).round() as usize + 1;
    let cols = (360.0 / step_deg).round() as usize;
    let mut positions = Vec::new();
    let mut labels = Vec::new();
    let mut cells = Vec::with_capacity(rows * cols);
    for r in 0..rows {
        let el = (-max_elevation_deg + r as f64 * step_deg).to_radians();
        for c in 0..cols {
            let az = (c as f64 * step_deg).to_radians();
            let dir = Vector3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin());
            let hit = rects
                .iter()
                .enumerate()
                .filter_map(|(k, rc)| rc.hit(&origin, &dir).map(|t| (t, k)))
                .min_by(|a, b| a.0.total_cmp(&b.0));
            match hit {
                Some((t, k)) => {
                    let i = positions.len() as u64;
                    let noisy = t + 3f64.sqrt() * sigma_m * uniform(7, i);
                    cells.push(positions.len() as u32);
                    positions.push(origin + noisy * dir);
                    labels.push(k as u32);
                }
                None => cells.push(NO_RETURN),
            }
        }
    }
    let mut scan = Scan::from_positions("test scan", positions);
    scan.pose = Some(ScannerPose {
        origin,
        rotation: Rotation3::identity(),
    });
    scan.grid = Some(RangeGrid { rows, cols, cells });
    (
        scan,
        Segmentation {
            labels: vec![labels],
            names: rects.iter().map(|r| r.name.clone()).collect(),
        },
    )
}

/// The rectangles as an OBJ's named meshes (the truth).
pub fn truth(rects: &[Rect]) -> Vec<NamedMesh> {
    rects
        .iter()
        .map(|r| NamedMesh {
            group: r.name.clone(),
            mesh: r.mesh(),
        })
        .collect()
}

/// `n` points on a sphere of radius `r` about the origin (a Fibonacci
/// lattice: near-uniform).
pub fn fibonacci_sphere(n: usize, r: f64) -> Vec<Vector3<f64>> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let s = (1.0 - z * z).sqrt();
            let a = golden * i as f64;
            r * Vector3::new(s * a.cos(), s * a.sin(), z)
        })
        .collect()
}

/// A sphere of `n` points and radius `r` about `centre` seen by six
/// scanners 3 m from it along ±x, ±y, ±z: each point in the unorganised
/// scan (no normals) of the scanner it faces most, all in one group
/// "sphere".
pub fn sphere_scans(n: usize, r: f64, centre: Vector3<f64>) -> (Vec<Scan>, Segmentation) {
    let axes = [
        Vector3::x(),
        -Vector3::x(),
        Vector3::y(),
        -Vector3::y(),
        Vector3::z(),
        -Vector3::z(),
    ];
    let mut scans: Vec<Scan> = axes
        .iter()
        .enumerate()
        .map(|(k, axis)| {
            let mut scan = Scan::from_positions(format!("sphere scan {k}"), Vec::new());
            scan.pose = Some(ScannerPose {
                origin: centre + 3.0 * axis,
                rotation: Rotation3::identity(),
            });
            scan
        })
        .collect();
    for p in fibonacci_sphere(n, r) {
        let k = (0..6)
            .max_by(|&a, &b| p.dot(&axes[a]).total_cmp(&p.dot(&axes[b])))
            .unwrap_or(0);
        scans[k].positions.push(p + centre);
    }
    let segmentation = Segmentation {
        labels: scans.iter().map(|s| vec![0; s.len()]).collect(),
        names: vec!["sphere".into()],
    };
    (scans, segmentation)
}

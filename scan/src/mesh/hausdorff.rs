//! How far a mesh is from the true geometry: the Hausdorff distance,
//! symmetric, and the mean distance, between a mesh and a reference mesh
//! or point set, both sampled.
//!
//! A mesh is sampled on a barycentric lattice of each triangle, fine
//! enough that no sample is more than `spacing` from the next (its corners
//! and edges included); a point set is its points. Each sample's distance
//! to the other side is exact (to the nearest triangle, or the nearest
//! point), found through a uniform grid of cells. The Hausdorff distance
//! is the larger of the two one-sided maxima; the mean is over the samples
//! of both sides together.

use nalgebra::Vector3;

use super::triangle_mesh::TriangleMesh;

/// Distances between a mesh and a reference, metres.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Hausdorff {
    /// The largest distance from a mesh sample to the reference.
    pub mesh_to_reference_m: f64,
    /// The largest distance from a reference sample to the mesh.
    pub reference_to_mesh_m: f64,
    /// The symmetric Hausdorff distance: the larger of the two.
    pub symmetric_m: f64,
    /// The mean distance over both sides' samples.
    pub mean_m: f64,
    /// Samples taken, both sides.
    pub samples: usize,
}

/// The geometry to measure against.
#[derive(Debug, Clone, Copy)]
pub enum Reference<'a> {
    /// True surfaces.
    Mesh(&'a TriangleMesh),
    /// True points (e.g. noiseless samples).
    Points(&'a [Vector3<f64>]),
}

/// The largest and the mean distance from a mesh's samples to a reference.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct OneSided {
    /// The largest distance, metres.
    pub max_m: f64,
    /// The mean distance, metres.
    pub mean_m: f64,
    /// Samples of the mesh.
    pub samples: usize,
}

/// The distances from `mesh`, sampled every `spacing_m`, to `reference`
/// (one way: how far the mesh strays from it, not how much of it the mesh
/// covers); `None` when either is empty or the spacing is not positive.
pub fn one_sided(mesh: &TriangleMesh, reference: Reference<'_>, spacing_m: f64) -> Option<OneSided> {
    if spacing_m.is_nan() || spacing_m <= 0.0 || mesh.is_empty() {
        return None;
    }
    let index = Nearest::of(reference)?;
    let d: Vec<f64> = samples(mesh, spacing_m).iter().map(|p| index.distance(p)).collect();
    Some(OneSided {
        max_m: d.iter().copied().fold(0.0, f64::max),
        mean_m: d.iter().sum::<f64>() / d.len() as f64,
        samples: d.len(),
    })
}

/// The distances between `mesh` and `reference`, meshes sampled every
/// `spacing_m`; `None` when either side is empty or the spacing is not
/// positive.
pub fn hausdorff(mesh: &TriangleMesh, reference: Reference<'_>, spacing_m: f64) -> Option<Hausdorff> {
    let forward = one_sided(mesh, reference, spacing_m)?;
    let mesh_index = Nearest::triangles(mesh)?;
    let backward: Vec<f64> = match reference {
        Reference::Mesh(m) => samples(m, spacing_m),
        Reference::Points(p) => p.to_vec(),
    }
    .iter()
    .map(|p| mesh_index.distance(p))
    .collect();
    let b = backward.iter().copied().fold(0.0, f64::max);
    let samples = forward.samples + backward.len();
    Some(Hausdorff {
        mesh_to_reference_m: forward.max_m,
        reference_to_mesh_m: b,
        symmetric_m: forward.max_m.max(b),
        mean_m: (forward.mean_m * forward.samples as f64 + backward.iter().sum::<f64>()) / samples as f64,
        samples,
    })
}

/// Points on every triangle of `mesh`, no two neighbours more than
/// `spacing` apart.
fn samples(mesh: &TriangleMesh, spacing: f64) -> Vec<Vector3<f64>> {
    let mut out = Vec::new();
    for t in 0..mesh.triangles.len() {
        let [a, b, c] = mesh.corners(t);
        let longest = (b - a).norm().max((c - b).norm()).max((a - c).norm());
        let n = ((longest / spacing).ceil() as usize).clamp(1, 10_000);
        for i in 0..=n {
            for j in 0..=n - i {
                let (s, t) = (i as f64 / n as f64, j as f64 / n as f64);
                out.push(a + s * (b - a) + t * (c - a));
            }
        }
    }
    out
}

/// The closest point to `p` of triangle `a b c` (Ericson, *Real-Time
/// Collision Detection*, §5.1.5).
pub fn closest_on_triangle(p: &Vector3<f64>, a: &Vector3<f64>, b: &Vector3<f64>, c: &Vector3<f64>) -> Vector3<f64> {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(&ap), ac.dot(&ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return *a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(&bp), ac.dot(&bp));
    if d3 >= 0.0 && d4 <= d3 {
        return *b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(&cp), ac.dot(&cp));
    if d6 >= 0.0 && d5 <= d6 {
        return *c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    a + ab * (vb * denom) + ac * (vc * denom)
}

/// Nearest-item queries over triangles or points, through a uniform grid:
/// each item is listed in every cell its bounding box overlaps, and a query
/// looks at shells of cells around its own until the next shell is farther
/// than the nearest item found.
struct Nearest<'a> {
    triangles: Option<&'a TriangleMesh>,
    points: &'a [Vector3<f64>],
    lo: Vector3<f64>,
    cell: f64,
    dims: [usize; 3],
    cells: Vec<Vec<u32>>,
}

impl<'a> Nearest<'a> {
    fn of(reference: Reference<'a>) -> Option<Nearest<'a>> {
        match reference {
            Reference::Mesh(m) => Nearest::triangles(m),
            Reference::Points(p) => Nearest::points(p),
        }
    }

    fn triangles(mesh: &'a TriangleMesh) -> Option<Nearest<'a>> {
        let boxes: Vec<_> = (0..mesh.triangles.len())
            .map(|t| {
                let [a, b, c] = mesh.corners(t);
                (a.inf(&b).inf(&c), a.sup(&b).sup(&c))
            })
            .collect();
        Nearest::build(Some(mesh), &mesh.positions, &boxes)
    }

    fn points(points: &'a [Vector3<f64>]) -> Option<Nearest<'a>> {
        let boxes: Vec<_> = points.iter().map(|p| (*p, *p)).collect();
        Nearest::build(None, points, &boxes)
    }

    fn build(
        triangles: Option<&'a TriangleMesh>,
        points: &'a [Vector3<f64>],
        boxes: &[(Vector3<f64>, Vector3<f64>)],
    ) -> Option<Nearest<'a>> {
        let (first, _) = *boxes.first()?;
        let (lo, hi) = boxes
            .iter()
            .fold((first, first), |(lo, hi), (a, b)| (lo.inf(a), hi.sup(b)));
        let extent = hi - lo;
        // About as many cells as items, over the box's occupied dimensions.
        let volume_side = (extent.iter().map(|e| e.max(extent.max() * 1e-3)).product::<f64>() / boxes.len() as f64)
            .cbrt()
            .max(extent.max() * 1e-4);
        let cell = if volume_side > 0.0 { volume_side } else { 1.0 };
        let dims = [0, 1, 2].map(|k| ((extent[k] / cell).floor() as usize + 1).min(1024));
        let mut cells = vec![Vec::new(); dims[0] * dims[1] * dims[2]];
        let mut me = Nearest {
            triangles,
            points,
            lo,
            cell,
            dims,
            cells: Vec::new(),
        };
        for (i, (a, b)) in boxes.iter().enumerate() {
            let (ca, cb) = (me.cell_of(a), me.cell_of(b));
            for x in ca[0]..=cb[0] {
                for y in ca[1]..=cb[1] {
                    for z in ca[2]..=cb[2] {
                        cells[(x * dims[1] + y) * dims[2] + z].push(i as u32);
                    }
                }
            }
        }
        me.cells = cells;
        Some(me)
    }

    fn cell_of(&self, p: &Vector3<f64>) -> [usize; 3] {
        [0, 1, 2].map(|k| (((p[k] - self.lo[k]) / self.cell).floor().max(0.0) as usize).min(self.dims[k] - 1))
    }

    fn item_distance(&self, i: u32, p: &Vector3<f64>) -> f64 {
        match self.triangles {
            Some(mesh) => {
                let [a, b, c] = mesh.corners(i as usize);
                (closest_on_triangle(p, &a, &b, &c) - p).norm()
            }
            None => (self.points[i as usize] - p).norm(),
        }
    }

    fn distance(&self, p: &Vector3<f64>) -> f64 {
        let c = self.cell_of(p);
        // How far p lies outside the grid's box: shells start from there.
        let outside = (0..3)
            .map(|k| {
                (self.lo[k] - p[k])
                    .max(p[k] - (self.lo[k] + self.dims[k] as f64 * self.cell))
                    .max(0.0)
            })
            .fold(0.0f64, |s, d| s + d * d)
            .sqrt();
        let mut best = f64::INFINITY;
        let max_shell = self.dims.iter().copied().max().unwrap_or(1);
        for shell in 0..=max_shell {
            // Every cell of this shell is at least (shell − 1) cells from p.
            if best <= outside.hypot((shell as f64 - 1.0).max(0.0) * self.cell) {
                break;
            }
            let range = |k: usize| {
                let lo = c[k].saturating_sub(shell);
                let hi = (c[k] + shell).min(self.dims[k] - 1);
                lo..=hi
            };
            for x in range(0) {
                for y in range(1) {
                    // Inside the shell's x-y square only its two z faces
                    // belong to it: O(shell²) cells a shell, not O(shell³).
                    let side = x.abs_diff(c[0]).max(y.abs_diff(c[1])) == shell;
                    let zs = range(2);
                    let (z0, z1) = (*zs.start(), *zs.end());
                    let faces = [c[2].checked_sub(shell), Some(c[2] + shell)];
                    let mut visit = |z: usize| {
                        for &i in &self.cells[(x * self.dims[1] + y) * self.dims[2] + z] {
                            best = best.min(self.item_distance(i, p));
                        }
                    };
                    if side {
                        (z0..=z1).for_each(&mut visit);
                    } else {
                        faces
                            .into_iter()
                            .flatten()
                            .filter(|z| (z0..=z1).contains(z))
                            .for_each(visit);
                    }
                }
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::super::simplification::fine_square;
    use super::*;

    #[test]
    fn a_lifted_square_is_its_lift_away_and_a_missing_half_counts_one_way() {
        let truth = fine_square(4);
        let mut lifted = fine_square(10);
        for p in &mut lifted.positions {
            p.z = 0.003;
        }
        let h = hausdorff(&lifted, Reference::Mesh(&truth), 0.05).unwrap();
        assert!((h.symmetric_m - 0.003).abs() < 1e-12, "{h:?}");
        assert!((h.mean_m - 0.003).abs() < 1e-12, "{h:?}");

        // Half the square: its samples are on the truth; the truth's far
        // corner (1, 1) is 0.5 m from it.
        let half = TriangleMesh {
            positions: vec![
                Vector3::new(0.0, 0.0, 0.0),
                Vector3::new(0.5, 0.0, 0.0),
                Vector3::new(0.5, 1.0, 0.0),
                Vector3::new(0.0, 1.0, 0.0),
            ],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
        };
        let h = hausdorff(&half, Reference::Mesh(&truth), 0.02).unwrap();
        assert!(h.mesh_to_reference_m < 1e-12, "{h:?}");
        assert!((h.reference_to_mesh_m - 0.5).abs() < 1e-12, "{h:?}");

        // Against points: a point 0.2 m above the middle of the square.
        let points = [Vector3::new(0.5, 0.5, 0.2), Vector3::new(0.0, 0.0, 0.0)];
        let h = hausdorff(&truth, Reference::Points(&points), 0.1).unwrap();
        assert!((h.reference_to_mesh_m - 0.2).abs() < 1e-12, "{h:?}");
        // The square's corners (1, 0), (1, 1), (0, 1) are farthest from both points.
        let far = (0.5f64 * 0.5 + 0.5 * 0.5 + 0.2 * 0.2).sqrt();
        assert!((h.mesh_to_reference_m - far).abs() < 1e-12, "{h:?}");
    }

    #[test]
    fn the_grid_search_finds_the_nearest_of_many_points_as_brute_force_does() {
        // 2000 points spread through a box, queried from inside and outside it.
        let points: Vec<Vector3<f64>> = (0..2000u32)
            .map(|i| {
                let f = |k: u32| f64::from((i * k + 17) % 1000) / 1000.0;
                Vector3::new(f(389), 0.3 * f(631), 2.0 * f(757))
            })
            .collect();
        let index = Nearest::points(&points).unwrap();
        for q in 0..200u32 {
            let f = |k: u32| f64::from((q * k + 3) % 97) / 97.0;
            let p = Vector3::new(3.0 * f(13) - 1.0, 2.0 * f(29) - 0.8, 4.0 * f(41) - 1.0);
            let brute = points.iter().map(|x| (x - p).norm()).fold(f64::INFINITY, f64::min);
            assert_eq!(index.distance(&p), brute, "query {q} at {p:?}");
        }
    }

    #[test]
    fn the_closest_point_of_a_triangle_is_found_in_each_region() {
        let (a, b, c) = (Vector3::zeros(), Vector3::x(), Vector3::y());
        let cases = [
            (Vector3::new(0.2, 0.2, 1.0), Vector3::new(0.2, 0.2, 0.0)),
            (Vector3::new(-1.0, -1.0, 0.0), a),
            (Vector3::new(2.0, -0.5, 0.0), b),
            (Vector3::new(0.5, -1.0, 0.0), Vector3::new(0.5, 0.0, 0.0)),
            (Vector3::new(1.0, 1.0, 0.0), Vector3::new(0.5, 0.5, 0.0)),
            (Vector3::new(-1.0, 0.5, 0.0), Vector3::new(0.0, 0.5, 0.0)),
        ];
        for (p, want) in cases {
            assert!((closest_on_triangle(&p, &a, &b, &c) - want).norm() < 1e-12, "{p:?}");
        }
    }
}

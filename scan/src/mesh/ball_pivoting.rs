//! Ball pivoting (Bernardini, Mittleman, Rushmeier, Silva and Taubin,
//! 1999): a surface through unorganised points with normals. A ball of
//! radius ρ rests on three points (a seed triangle, its centre on the
//! normals' side and no other point inside); it pivots about each edge of
//! the growing mesh's front until it touches a further point, which makes
//! the next triangle. Where no point is within reach the front stays open
//! (a hole or the mesh's border).
//!
//! One radius (`ρ = radius_factor × spacing`, the spacing the median
//! nearest-neighbour distance); an edge is used by at most two triangles,
//! and a triangle is accepted only when its normal agrees with the normal
//! of the point it adds, so that thin objects do not join front and back.
//! The mesh for curved unorganised groups that are not height fields
//! ([`super::height_field`]); the thesis used the crust algorithm for these.

use std::collections::{HashMap, HashSet, VecDeque};

use nalgebra::{Matrix3, SymmetricEigen, Vector3};

use super::triangle_mesh::TriangleMesh;

/// Points bucketed in cubes of a given side, for neighbours within a radius.
struct PointGrid<'a> {
    points: &'a [Vector3<f64>],
    side: f64,
    cells: HashMap<[i64; 3], Vec<u32>>,
}

impl<'a> PointGrid<'a> {
    fn new(points: &'a [Vector3<f64>], side: f64) -> PointGrid<'a> {
        let mut cells: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
        for (i, p) in points.iter().enumerate() {
            cells.entry(Self::key(p, side)).or_default().push(i as u32);
        }
        PointGrid { points, side, cells }
    }

    fn key(p: &Vector3<f64>, side: f64) -> [i64; 3] {
        [0, 1, 2].map(|k| (p[k] / side).floor() as i64)
    }

    /// Indices of the points within `radius` (at most the side) of `p`.
    fn within(&self, p: &Vector3<f64>, radius: f64) -> Vec<u32> {
        let k = Self::key(p, self.side);
        let mut out = Vec::new();
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    if let Some(cell) = self.cells.get(&[k[0] + dx, k[1] + dy, k[2] + dz]) {
                        out.extend(cell.iter().filter(|&&i| (self.points[i as usize] - p).norm() <= radius));
                    }
                }
            }
        }
        out
    }
}

/// The median, over points, of the distance to the nearest other point
/// (0 for fewer than two points).
pub fn nearest_spacing(points: &[Vector3<f64>]) -> f64 {
    if points.len() < 2 {
        return 0.0;
    }
    // A first cell size from the bounding box, as if the points covered
    // a surface; doubled until most points find a neighbour.
    let (lo, hi) = points
        .iter()
        .fold((points[0], points[0]), |(lo, hi), p| (lo.inf(p), hi.sup(p)));
    let e = hi - lo;
    let mut side = ((e.x * e.y + e.y * e.z + e.z * e.x).max(e.max() * e.max() * 1e-6) / points.len() as f64)
        .sqrt()
        .max(1e-9);
    loop {
        let grid = PointGrid::new(points, side);
        let mut nearest: Vec<f64> = points
            .iter()
            .enumerate()
            .filter_map(|(i, p)| {
                grid.within(p, side)
                    .into_iter()
                    .filter(|&j| j as usize != i)
                    .map(|j| (points[j as usize] - p).norm())
                    .min_by(f64::total_cmp)
            })
            .collect();
        if nearest.len() * 4 >= points.len() * 3 || side > e.max() {
            if nearest.is_empty() {
                return 0.0;
            }
            let middle = nearest.len() / 2;
            return *nearest.select_nth_unstable_by(middle, f64::total_cmp).1;
        }
        side *= 2.0;
    }
}

/// Unit normals of `points` by principal components of their neighbours
/// within `radius`, each turned towards its `viewpoints` entry.
pub fn estimate_normals(points: &[Vector3<f64>], viewpoints: &[Vector3<f64>], radius: f64) -> Vec<Vector3<f64>> {
    let grid = PointGrid::new(points, radius);
    points
        .iter()
        .zip(viewpoints)
        .map(|(p, view)| {
            let near = grid.within(p, radius);
            let n = near.len().max(1) as f64;
            let centre = near.iter().map(|&i| points[i as usize]).sum::<Vector3<f64>>() / n;
            let cov = near.iter().fold(Matrix3::zeros(), |m, &i| {
                let d = points[i as usize] - centre;
                m + d * d.transpose()
            });
            let eigen = SymmetricEigen::new(cov);
            let smallest = (0..3)
                .min_by(|&a, &b| eigen.eigenvalues[a].total_cmp(&eigen.eigenvalues[b]))
                .unwrap_or(0);
            let normal: Vector3<f64> = eigen.eigenvectors.column(smallest).into_owned();
            let normal = normal.try_normalize(1e-300).unwrap_or_else(Vector3::z);
            if normal.dot(&(view - p)) < 0.0 { -normal } else { normal }
        })
        .collect()
}

/// The centre of the ball of radius `rho` through `a b c` on the side of
/// the triangle's normal (right-hand rule), if the triangle is small enough.
fn ball_centre(a: &Vector3<f64>, b: &Vector3<f64>, c: &Vector3<f64>, rho: f64) -> Option<Vector3<f64>> {
    let (ab, ac) = (b - a, c - a);
    let n = ab.cross(&ac);
    let n2 = n.norm_squared();
    if n2 <= 1e-24 * ab.norm_squared() * ac.norm_squared() {
        return None;
    }
    let centre = a + (n.cross(&ab) * ac.norm_squared() + ac.cross(&n) * ab.norm_squared()) / (2.0 * n2);
    let r2 = (a - centre).norm_squared();
    let h2 = rho * rho - r2;
    (h2 >= 0.0).then(|| centre + n / n2.sqrt() * h2.sqrt())
}

/// An edge of the front: the triangle `(from, to, opposite)` lies behind it
/// and the ball rests at `centre`.
#[derive(Debug, Clone, Copy)]
struct FrontEdge {
    from: u32,
    to: u32,
    opposite: u32,
    centre: Vector3<f64>,
}

struct Pivoter<'a> {
    points: &'a [Vector3<f64>],
    normals: &'a [Vector3<f64>],
    rho: f64,
    grid: PointGrid<'a>,
    /// Triangles on each undirected edge.
    edges: HashMap<(u32, u32), u8>,
    used: Vec<bool>,
    triangles: Vec<[u32; 3]>,
    /// The triangles made, corners sorted: none is made twice.
    made: HashSet<[u32; 3]>,
    front: VecDeque<FrontEdge>,
}

fn undirected(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

impl Pivoter<'_> {
    fn empty_ball(&self, centre: &Vector3<f64>, corners: [u32; 3]) -> bool {
        self.grid
            .within(centre, self.rho * (1.0 - 1e-9))
            .iter()
            .all(|i| corners.contains(i))
    }

    fn edge_count(&self, a: u32, b: u32) -> u8 {
        self.edges.get(&undirected(a, b)).copied().unwrap_or(0)
    }

    /// Adds triangle `t` (counter-clockwise seen from its normal's side),
    /// ball at `centre`, and puts its edges that have only it on the front.
    fn add(&mut self, t: [u32; 3], centre: Vector3<f64>) {
        self.triangles.push(t);
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *self.edges.entry(undirected(a, b)).or_default() += 1;
            self.used[a as usize] = true;
        }
        for k in 0..3 {
            let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
            if self.edge_count(a, b) == 1 {
                self.front.push_back(FrontEdge {
                    from: a,
                    to: b,
                    opposite: c,
                    centre,
                });
            }
        }
    }

    fn seed(&mut self, start: &mut usize) -> bool {
        while *start < self.points.len() {
            let s = *start as u32;
            *start += 1;
            if self.used[s as usize] {
                continue;
            }
            let p = self.points[s as usize];
            let mut near = self.grid.within(&p, 2.0 * self.rho);
            near.retain(|&i| i != s && !self.used[i as usize]);
            near.sort_by(|&a, &b| {
                (self.points[a as usize] - p)
                    .norm_squared()
                    .total_cmp(&(self.points[b as usize] - p).norm_squared())
            });
            near.truncate(12);
            for (x, &a) in near.iter().enumerate() {
                for &b in &near[x + 1..] {
                    let [pa, pb] = [a, b].map(|i| self.points[i as usize]);
                    let n = (pa - p).cross(&(pb - p));
                    let t = if n.dot(&self.normals[s as usize]) >= 0.0 {
                        [s, a, b]
                    } else {
                        [s, b, a]
                    };
                    let [q0, q1, q2] = t.map(|i| self.points[i as usize]);
                    let tn = (q1 - q0).cross(&(q2 - q0));
                    if t.iter().any(|&i| tn.dot(&self.normals[i as usize]) <= 0.0) {
                        continue;
                    }
                    if let Some(c) = ball_centre(&q0, &q1, &q2, self.rho)
                        && self.empty_ball(&c, t)
                    {
                        let mut key = t;
                        key.sort_unstable();
                        self.made.insert(key);
                        self.add(t, c);
                        return true;
                    }
                }
            }
        }
        false
    }

    /// Pivots the ball about `e`; the point it meets first, with its centre.
    fn pivot(&self, e: &FrontEdge) -> Option<(u32, Vector3<f64>)> {
        let (pi, pj) = (self.points[e.from as usize], self.points[e.to as usize]);
        let m = 0.5 * (pi + pj);
        let axis = (pj - pi).normalize();
        let flat = |v: Vector3<f64>| v - axis * axis.dot(&v);
        let v0 = flat(e.centre - m);
        let mut best: Option<(f64, u32, Vector3<f64>)> = None;
        for x in self.grid.within(&m, 2.0 * self.rho) {
            if x == e.from || x == e.to || x == e.opposite {
                continue;
            }
            let px = self.points[x as usize];
            // The new triangle (to, from, x) shares the edge the other way round.
            let Some(c) = ball_centre(&pj, &pi, &px, self.rho) else {
                continue;
            };
            let v1 = flat(c - m);
            let mut angle = v0.cross(&v1).dot(&axis).atan2(v0.dot(&v1));
            if angle < 0.0 {
                angle += std::f64::consts::TAU;
            }
            if best.is_none_or(|(a, _, _)| angle < a) {
                best = Some((angle, x, c));
            }
        }
        let (_, x, c) = best?;
        self.empty_ball(&c, [e.from, e.to, x]).then_some((x, c))
    }

    fn grow(&mut self) {
        while let Some(e) = self.front.pop_front() {
            if self.edge_count(e.from, e.to) != 1 {
                continue;
            }
            let Some((x, c)) = self.pivot(&e) else {
                continue;
            };
            let t = [e.to, e.from, x];
            let [q0, q1, q2] = t.map(|i| self.points[i as usize]);
            let tn = (q1 - q0).cross(&(q2 - q0));
            let fits = tn.dot(&self.normals[x as usize]) > 0.0
                && self.edge_count(e.to, x) < 2
                && self.edge_count(x, e.from) < 2;
            let mut key = t;
            key.sort_unstable();
            if fits && self.made.insert(key) {
                self.add(t, c);
            }
        }
    }
}

/// A mesh through `points` with unit `normals` by ball pivoting with a ball
/// of radius `rho`, triangles facing the normals.
pub fn ball_pivoting(points: &[Vector3<f64>], normals: &[Vector3<f64>], rho: f64) -> TriangleMesh {
    if points.len() < 3 || normals.len() != points.len() || rho.is_nan() || rho <= 0.0 {
        return TriangleMesh::default();
    }
    let mut p = Pivoter {
        points,
        normals,
        rho,
        grid: PointGrid::new(points, 2.0 * rho),
        edges: HashMap::new(),
        used: vec![false; points.len()],
        triangles: Vec::new(),
        made: HashSet::new(),
        front: VecDeque::new(),
    };
    let mut start = 0;
    while p.seed(&mut start) {
        p.grow();
    }
    TriangleMesh::gathered(points, &p.triangles)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sphere_closes_with_its_normals_outward() {
        let n = 1500;
        let points = crate::synthetic_scan::fibonacci_sphere(n, 0.5);
        // Viewpoints outside each point: the normals turn outward.
        let views: Vec<_> = points.iter().map(|p| 3.0 * p).collect();
        let spacing = (4.0 * std::f64::consts::PI * 0.25 / n as f64).sqrt();
        let normals = estimate_normals(&points, &views, 2.5 * spacing);
        for (p, n) in points.iter().zip(&normals) {
            assert!(n.dot(&p.normalize()) > 0.99, "{n:?} at {p:?}");
        }
        let mesh = ball_pivoting(&points, &normals, 1.5 * spacing);
        let t = mesh.triangles.len();
        // Closed: a triangulation of n points on a sphere has 2n − 4
        // triangles, and every edge two of them.
        assert_eq!(t, 2 * n - 4);
        let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
        for tri in &mesh.triangles {
            for k in 0..3 {
                *edges.entry(undirected(tri[k], tri[(k + 1) % 3])).or_default() += 1;
            }
        }
        assert!(edges.values().all(|&c| c == 2));
        assert!((0..t).all(|k| {
            let [a, b, c] = mesh.corners(k);
            mesh.area_normal(k).dot(&(a + b + c)) > 0.0
        }));
        // Area within 1 % of the sphere's (flat triangles cut inside it:
        // measured 0.2 % short).
        let area = 4.0 * std::f64::consts::PI * 0.25;
        assert!((mesh.area() / area - 1.0).abs() < 0.01, "{}", mesh.area());
    }
}

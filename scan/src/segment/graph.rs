//! The graph of §2.3.2: points clustered into nodes, nodes joined by local
//! and random long-range edges weighted w = S·P.
//!
//! **Clustering** is incremental, one scan at a time, as the thesis does:
//! a point joins the nearest cluster whose centroid is within the radius and
//! whose mean normal and intensity are within the limits, or starts a new
//! one. Only the clusters' sums are kept, so memory grows with the nodes, not
//! the points. Nearby clusters are found through a hash grid of cubes one
//! radius wide (the thesis projects onto a 2D grid on a plane normal to the
//! average normal, which suits one facade but not a room's six faces).
//!
//! A cluster may carry a tag (the fine stage's coarse group) and then only
//! takes points with the same tag and only links to clusters with the same
//! tag, so the fine stage segments each coarse group on its own.

use std::collections::HashMap;

use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use super::params::Parameters;

/// Eq. (2.3): S(u, v) = exp(−diff²(u, v) / 2σ_w²).
pub fn similarity(diff: f64, sigma_w: f64) -> f64 {
    (-diff * diff / (2.0 * sigma_w * sigma_w)).exp()
}

/// Eq. (2.4): P(u, v) = exp(−dist²(u, v) / 2σ_c²).
pub fn proximity(dist: f64, sigma_c: f64) -> f64 {
    (-dist * dist / (2.0 * sigma_c * sigma_c)).exp()
}

/// Eq. (2.5): the anisotropic distance, max(dist_u, dist_v) with
/// dist_u = √(E‖u_n‖² + ‖u_p‖²/E), u_n and u_p the projections of the
/// vector uv onto u's normal and tangent plane.
pub fn anisotropic_distance(pu: &Vector3<f64>, nu: &Vector3<f64>, pv: &Vector3<f64>, nv: &Vector3<f64>, e: f64) -> f64 {
    let d = pv - pu;
    let d2 = d.norm_squared();
    let one = |n: &Vector3<f64>| {
        let along = d.dot(n);
        let across = (d2 - along * along).max(0.0);
        (e * along * along + across / e).sqrt()
    };
    one(nu).max(one(nv))
}

/// The angle between two unit normals' lines, radians (0 to π/2): a scan
/// without a pose can only orient its normals by propagation, which may
/// flip a patch, so the sign is not trusted.
pub fn normal_angle(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    a.dot(b).abs().min(1.0).acos()
}

/// One cluster: its sums (the node's attributes are their means).
#[derive(Debug, Clone, Copy)]
pub struct Node {
    /// Σ positions.
    pub sum_position: Vector3<f64>,
    /// Σ normals.
    pub sum_normal: Vector3<f64>,
    /// Σ intensities.
    pub sum_intensity: f64,
    /// Points in the cluster.
    pub points: u32,
    /// The coarse group the cluster belongs to (fine stage), or `u32::MAX`.
    pub tag: u32,
}

impl Node {
    /// The mean position.
    pub fn position(&self) -> Vector3<f64> {
        self.sum_position / f64::from(self.points)
    }

    /// The mean normal, renormalised (zero when the normals cancel).
    pub fn normal(&self) -> Vector3<f64> {
        self.sum_normal.try_normalize(1e-12).unwrap_or_else(Vector3::zeros)
    }

    /// The mean intensity.
    pub fn intensity(&self) -> f64 {
        self.sum_intensity / f64::from(self.points)
    }
}

/// A hash grid of cubes `cell` wide.
#[derive(Debug, Clone)]
pub struct CellGrid {
    cell: f64,
    cells: HashMap<(i64, i64, i64), Vec<u32>>,
}

impl CellGrid {
    /// An empty grid of cubes `cell` wide.
    pub fn new(cell: f64) -> CellGrid {
        CellGrid {
            cell,
            cells: HashMap::new(),
        }
    }

    fn key(&self, p: &Vector3<f64>) -> (i64, i64, i64) {
        let k = |v: f64| (v / self.cell).floor() as i64;
        (k(p.x), k(p.y), k(p.z))
    }

    /// Files `item` at `p`.
    pub fn insert(&mut self, p: &Vector3<f64>, item: u32) {
        let key = self.key(p);
        self.cells.entry(key).or_default().push(item);
    }

    /// The items filed in the 27 cubes around `p`.
    pub fn around<'a>(&'a self, p: &Vector3<f64>) -> impl Iterator<Item = u32> + 'a {
        let (x, y, z) = self.key(p);
        (-1..=1)
            .flat_map(move |dx| (-1..=1).flat_map(move |dy| (-1..=1).map(move |dz| (x + dx, y + dy, z + dz))))
            .filter_map(|k| self.cells.get(&k))
            .flatten()
            .copied()
    }
}

/// Incremental clustering (§2.3.2).
#[derive(Debug, Clone)]
pub struct Clusterer {
    radius: f64,
    cos_normal: f64,
    intensity: f64,
    nodes: Vec<Node>,
    grid: CellGrid,
}

impl Clusterer {
    /// Clusters of `radius` m whose points' normals are within `normal_deg`
    /// and intensities within `intensity` of the cluster's mean.
    pub fn new(radius: f64, normal_deg: f64, intensity: f64) -> Clusterer {
        Clusterer {
            radius,
            cos_normal: normal_deg.to_radians().cos(),
            intensity,
            nodes: Vec::new(),
            grid: CellGrid::new(radius),
        }
    }

    /// Adds one point; returns its node.
    pub fn add(&mut self, p: &Vector3<f64>, n: &Vector3<f64>, intensity: f64, tag: u32) -> u32 {
        let r2 = self.radius * self.radius;
        let mut best: Option<(f64, u32)> = None;
        for k in self.grid.around(p) {
            let node = &self.nodes[k as usize];
            if node.tag != tag {
                continue;
            }
            let d2 = (node.position() - p).norm_squared();
            if d2 > r2 || best.is_some_and(|(b, _)| b <= d2) {
                continue;
            }
            if node.normal().dot(n).abs() < self.cos_normal || (node.intensity() - intensity).abs() > self.intensity {
                continue;
            }
            best = Some((d2, k));
        }
        match best {
            Some((_, k)) => {
                let node = &mut self.nodes[k as usize];
                node.sum_position += p;
                // Normals of either sign (see `normal_angle`) add aligned.
                if node.sum_normal.dot(n) < 0.0 {
                    node.sum_normal -= n;
                } else {
                    node.sum_normal += n;
                }
                node.sum_intensity += intensity;
                node.points += 1;
                k
            }
            None => {
                let k = self.nodes.len() as u32;
                self.nodes.push(Node {
                    sum_position: *p,
                    sum_normal: *n,
                    sum_intensity: intensity,
                    points: 1,
                    tag,
                });
                self.grid.insert(p, k);
                k
            }
        }
    }

    /// The clusters so far.
    pub fn into_nodes(self) -> Vec<Node> {
        self.nodes
    }
}

/// A node's attributes, as the graph uses them.
#[derive(Debug, Clone, Copy)]
pub struct NodeAttributes {
    /// Mean position.
    pub position: Vector3<f64>,
    /// Mean unit normal.
    pub normal: Vector3<f64>,
    /// Mean intensity.
    pub intensity: f64,
    /// Points in the node.
    pub points: u32,
    /// Coarse group (fine stage) or `u32::MAX`.
    pub tag: u32,
}

/// Which similarity a pass uses (§2.3.4: normal continuity, then intensity).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Pass {
    /// S on the angle between normals.
    Normal,
    /// S on the intensity difference.
    Intensity,
}

/// The node graph: symmetric sparse adjacency (CSR) with each edge's P and
/// its S for both passes.
#[derive(Debug, Clone)]
pub struct Graph {
    /// The nodes.
    pub nodes: Vec<NodeAttributes>,
    /// CSR offsets: node i's edges are `offsets[i]..offsets[i + 1]`.
    pub offsets: Vec<usize>,
    /// Edge targets.
    pub targets: Vec<u32>,
    /// P (eq. 2.4) per edge.
    pub proximity: Vec<f64>,
    /// The angle between the ends' normals per edge, radians.
    pub normal_diff: Vec<f32>,
    /// The ends' intensity difference per edge.
    pub intensity_diff: Vec<f32>,
    /// σ_w for normals, radians; σ_w for intensity; σ_c, m; E.
    sigmas: (f64, f64, f64, f64),
}

impl Graph {
    /// Builds the graph over `nodes`: an edge between nodes of the same tag
    /// whose centroids are within `edge_radius_m`, plus `random_edges` a
    /// node to a random node of the same tag within twice that.
    pub fn build(nodes: &[Node], params: &Parameters) -> Graph {
        let attributes: Vec<NodeAttributes> = nodes
            .iter()
            .map(|n| NodeAttributes {
                position: n.position(),
                normal: n.normal(),
                intensity: n.intensity(),
                points: n.points,
                tag: n.tag,
            })
            .collect();
        let reach = 2.0 * params.edge_radius_m;
        let mut grid = CellGrid::new(reach);
        for (k, a) in attributes.iter().enumerate() {
            grid.insert(&a.position, k as u32);
        }
        let r2 = params.edge_radius_m * params.edge_radius_m;
        let reach2 = reach * reach;
        let mut pairs: Vec<(u32, u32)> = attributes
            .par_iter()
            .enumerate()
            .flat_map_iter(|(i, a)| {
                let mut local = Vec::new();
                let mut far = Vec::new();
                for j in grid.around(&a.position) {
                    let b = &attributes[j as usize];
                    if j as usize == i || b.tag != a.tag {
                        continue;
                    }
                    let d2 = (b.position - a.position).norm_squared();
                    if d2 <= r2 {
                        if (j as usize) > i {
                            local.push((i as u32, j));
                        }
                    } else if d2 <= reach2 {
                        far.push(j);
                    }
                }
                if !far.is_empty() {
                    let mut rng =
                        ChaCha8Rng::seed_from_u64(params.seed ^ (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
                    for _ in 0..params.random_edges {
                        let j = far[rng.random_range(0..far.len())];
                        local.push((i.min(j as usize) as u32, i.max(j as usize) as u32));
                    }
                }
                local
            })
            .collect();
        pairs.par_sort_unstable();
        pairs.dedup();
        let n = attributes.len();
        let mut degree = vec![0usize; n + 1];
        for &(a, b) in &pairs {
            degree[a as usize + 1] += 1;
            degree[b as usize + 1] += 1;
        }
        for i in 0..n {
            degree[i + 1] += degree[i];
        }
        let offsets = degree;
        let mut fill = offsets.clone();
        let mut targets = vec![0u32; pairs.len() * 2];
        for &(a, b) in &pairs {
            targets[fill[a as usize]] = b;
            fill[a as usize] += 1;
            targets[fill[b as usize]] = a;
            fill[b as usize] += 1;
        }
        let sigmas = (
            params.sigma_w_normal_deg.to_radians(),
            params.sigma_w_intensity,
            params.sigma_c_m,
            params.anisotropy,
        );
        let mut graph = Graph {
            nodes: attributes,
            offsets,
            targets,
            proximity: Vec::new(),
            normal_diff: Vec::new(),
            intensity_diff: Vec::new(),
            sigmas,
        };
        let terms: Vec<(f64, f32, f32)> = (0..n)
            .into_par_iter()
            .flat_map_iter(|i| {
                let g = &graph;
                g.edges(i).map(move |(j, _)| {
                    let (a, b) = (&g.nodes[i], &g.nodes[j]);
                    (
                        g.proximity_of(i, j),
                        normal_angle(&a.normal, &b.normal) as f32,
                        (a.intensity - b.intensity).abs() as f32,
                    )
                })
            })
            .collect();
        graph.proximity = terms.iter().map(|t| t.0).collect();
        graph.normal_diff = terms.iter().map(|t| t.1).collect();
        graph.intensity_diff = terms.iter().map(|t| t.2).collect();
        graph
    }

    /// Node `i`'s neighbours and their edge indices.
    pub fn edges(&self, i: usize) -> impl Iterator<Item = (usize, usize)> + '_ {
        (self.offsets[i]..self.offsets[i + 1]).map(|e| (self.targets[e] as usize, e))
    }

    /// P (eq. 2.4) between any two nodes, with eq. 2.5's distance.
    pub fn proximity_of(&self, i: usize, j: usize) -> f64 {
        let (a, b) = (&self.nodes[i], &self.nodes[j]);
        let (_, _, sigma_c, e) = self.sigmas;
        proximity(
            anisotropic_distance(&a.position, &a.normal, &b.position, &b.normal, e),
            sigma_c,
        )
    }

    /// S (eq. 2.3) between any two nodes for `pass`.
    pub fn similarity_of(&self, i: usize, j: usize, pass: Pass) -> f64 {
        let (a, b) = (&self.nodes[i], &self.nodes[j]);
        let (sigma_normal, sigma_intensity, _, _) = self.sigmas;
        match pass {
            Pass::Normal => similarity(normal_angle(&a.normal, &b.normal), sigma_normal),
            Pass::Intensity => similarity(a.intensity - b.intensity, sigma_intensity),
        }
    }

    /// S for `pass` on edge `e`.
    pub fn edge_similarity(&self, e: usize, pass: Pass) -> f64 {
        let (sigma_normal, sigma_intensity, _, _) = self.sigmas;
        match pass {
            Pass::Normal => similarity(f64::from(self.normal_diff[e]), sigma_normal),
            Pass::Intensity => similarity(f64::from(self.intensity_diff[e]), sigma_intensity),
        }
    }

    /// The `q`-quantile of the edges' normal differences (radians) and
    /// intensity differences, over the local edges (P above 0.1): the
    /// clusters' own noise, since most edges lie within a surface.
    pub fn difference_quantiles(&self, q: f64) -> (f64, f64) {
        let pick = |values: &[f32]| {
            let mut v: Vec<f32> = values
                .iter()
                .zip(&self.proximity)
                .filter(|(_, p)| **p > 0.1)
                .map(|(d, _)| *d)
                .collect();
            if v.is_empty() {
                return 0.0;
            }
            let k = ((v.len() - 1) as f64 * q).round() as usize;
            let (_, x, _) = v.select_nth_unstable_by(k, f32::total_cmp);
            f64::from(*x)
        };
        (pick(&self.normal_diff), pick(&self.intensity_diff))
    }

    /// Sets σ_w for normals (radians) and intensity.
    pub fn set_sigma_w(&mut self, normal: f64, intensity: f64) {
        self.sigmas.0 = normal;
        self.sigmas.1 = intensity;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_anisotropic_distance_magnifies_depth_and_shrinks_the_tangent() {
        let z = Vector3::z();
        let o = Vector3::zeros();
        // Along the surface: √(d²/E).
        let along = anisotropic_distance(&o, &z, &Vector3::new(0.4, 0.0, 0.0), &z, 4.0);
        assert!((along - 0.2).abs() < 1e-12, "{along}");
        // Across (a depth step): √(E d²).
        let across = anisotropic_distance(&o, &z, &Vector3::new(0.0, 0.0, 0.1), &z, 4.0);
        assert!((across - 0.2).abs() < 1e-12, "{across}");
        // Eq. 2.5 takes the larger of the two ends' distances: at u (normal z)
        // the step (0.3, 0, 0.4) is 0.3 along and 0.4 across, at v (normal x)
        // the reverse.
        let d = anisotropic_distance(&o, &z, &Vector3::new(0.3, 0.0, 0.4), &Vector3::x(), 4.0);
        let at_u = (4.0 * 0.16 + 0.09 / 4.0_f64).sqrt();
        let at_v = (4.0 * 0.09 + 0.16 / 4.0_f64).sqrt();
        assert!((d - at_u.max(at_v)).abs() < 1e-12, "{d}");
        assert!((similarity(0.1, 0.1) - (-0.5_f64).exp()).abs() < 1e-12);
        assert!((proximity(0.2, 0.1) - (-2.0_f64).exp()).abs() < 1e-12);
    }

    #[test]
    fn clusters_stay_within_radius_and_do_not_cross_a_crease() {
        let mut c = Clusterer::new(0.1, 20.0, 0.1);
        // A 1 m strip of floor (normal z) along x, then a wall (normal x) at x = 1.
        let mut labels = Vec::new();
        for i in 0..50 {
            labels.push(c.add(&Vector3::new(i as f64 * 0.02, 0.0, 0.0), &Vector3::z(), 0.5, u32::MAX));
        }
        for i in 0..10 {
            labels.push(c.add(&Vector3::new(1.0, 0.0, i as f64 * 0.02), &-Vector3::x(), 0.5, u32::MAX));
        }
        let nodes = c.into_nodes();
        for (k, &l) in labels.iter().enumerate() {
            let p = if k < 50 {
                Vector3::new(k as f64 * 0.02, 0.0, 0.0)
            } else {
                Vector3::new(1.0, 0.0, (k - 50) as f64 * 0.02)
            };
            assert!((nodes[l as usize].position() - p).norm() < 0.2);
        }
        // No node holds both floor and wall points.
        for &l in &labels[50..] {
            assert!(!labels[..50].contains(&l));
        }
        // The floor's 1 m, in clusters of radius 0.1 m: 5 to 10 of them.
        let floor: std::collections::BTreeSet<u32> = labels[..50].iter().copied().collect();
        assert!((5..=10).contains(&floor.len()), "{}", floor.len());
    }
}

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

/// Eq. (2.3) on an intensity difference; 1 when it is NaN (an end without
/// intensity: nothing to tell them apart by).
pub fn intensity_similarity(diff: f64, sigma_w: f64) -> f64 {
    if diff.is_nan() { 1.0 } else { similarity(diff, sigma_w) }
}

/// The variance of the difference of two means of `a` and `b` samples
/// each of noise σ = `noise`: σ²(1/a + 1/b), a mean of no sample adding
/// nothing (its intensity is NaN, which [`intensity_similarity`] takes as
/// no evidence).
pub fn mean_difference_variance(noise: f64, a: u32, b: u32) -> f64 {
    let inverse = |n: u32| if n == 0 { 0.0 } else { 1.0 / f64::from(n) };
    noise.powi(2) * (inverse(a) + inverse(b))
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
    /// Σ intensities (of the points that carry one).
    pub sum_intensity: f64,
    /// Points that carry an intensity (not NaN: see
    /// [`crate::segment::normals::corrected_intensity`]).
    pub intensity_points: u32,
    /// Points in the cluster.
    pub points: u32,
    /// The coarse group the cluster belongs to (fine stage), or `u32::MAX`.
    pub tag: u32,
    /// Its scale level: the cluster's radius is the base radius × 2^level
    /// ([`scale_level`]).
    pub level: u8,
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

    /// The mean intensity, NaN when no point carries one.
    pub fn intensity(&self) -> f64 {
        if self.intensity_points == 0 {
            f64::NAN
        } else {
            self.sum_intensity / f64::from(self.intensity_points)
        }
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

/// The most scale levels: a cluster is at most 2^(LEVELS − 1) times the
/// base radius.
pub const LEVELS: usize = 7;

/// The scale level of a point whose local spacing is `spacing` m, for
/// clusters of `radius` m: 0 while the spacing is at most the radius (a
/// cluster then holds π (radius / spacing)² ≥ 3 points), then one more for
/// each doubling of the spacing, up to `LEVELS − 1`. (Levels from half the
/// radius on were tried first: on the simulated room's coarse scans they
/// split the table off and the floor in three, 94.7 % against 95.8 %.)
///
/// A scanner's points thin out with range (their spacing is the range
/// times the beam step) and at grazing incidence. With one radius for all
/// (§2.3.2), a tower 30 m away from scans whose median spacing is a few
/// centimetres on the ground nearby gets one point per cluster, no edge
/// within the edge radius, and falls apart into single points. With its
/// level, a cluster keeps at least a few points wherever it is.
pub fn scale_level(spacing: f64, radius: f64) -> u8 {
    if !(spacing.is_finite() && radius > 0.0) || spacing <= radius {
        return 0;
    }
    ((spacing / radius).log2().ceil().max(0.0) as usize).min(LEVELS - 1) as u8
}

/// 2^level.
pub fn level_scale(level: u8) -> f64 {
    f64::from(1u32 << level)
}

/// Incremental clustering (§2.3.2), with one hash grid per scale level.
#[derive(Debug, Clone)]
pub struct Clusterer {
    radius: f64,
    cos_normal: f64,
    intensity: f64,
    nodes: Vec<Node>,
    grids: Vec<CellGrid>,
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
            grids: (0..LEVELS)
                .map(|l| CellGrid::new(radius * level_scale(l as u8)))
                .collect(),
        }
    }

    /// Adds one point at scale `level` ([`scale_level`]); it joins a cluster
    /// of its level; returns its node.
    pub fn add(&mut self, p: &Vector3<f64>, n: &Vector3<f64>, intensity: f64, tag: u32, level: u8) -> u32 {
        let level = level.min(LEVELS as u8 - 1);
        let radius = self.radius * level_scale(level);
        let r2 = radius * radius;
        let mut best: Option<(f64, u32)> = None;
        for k in self.grids[usize::from(level)].around(p) {
            let node = &self.nodes[k as usize];
            if node.tag != tag {
                continue;
            }
            let d2 = (node.position() - p).norm_squared();
            if d2 > r2 || best.is_some_and(|(b, _)| b <= d2) {
                continue;
            }
            // NaN (no intensity on either side) never refuses.
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
                if intensity.is_finite() {
                    node.sum_intensity += intensity;
                    node.intensity_points += 1;
                }
                node.points += 1;
                k
            }
            None => {
                let k = self.nodes.len() as u32;
                self.nodes.push(Node {
                    sum_position: *p,
                    sum_normal: *n,
                    sum_intensity: if intensity.is_finite() { intensity } else { 0.0 },
                    intensity_points: u32::from(intensity.is_finite()),
                    points: 1,
                    tag,
                    level,
                });
                self.grids[usize::from(level)].insert(p, k);
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
    /// Mean intensity (NaN when none of its points carries one).
    pub intensity: f64,
    /// Points in the node.
    pub points: u32,
    /// Coarse group (fine stage) or `u32::MAX`.
    pub tag: u32,
    /// 2^level ([`scale_level`]): the node's radius, edge radius and σ_c
    /// are the parameters' times this.
    pub scale: f64,
    /// Points that carry an intensity.
    pub intensity_points: u32,
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
    /// The variance of that difference from the ends' own noise,
    /// σ²(1/n_u + 1/n_v) (σ one point's intensity noise).
    pub intensity_var: Vec<f32>,
    /// One point's intensity noise σ.
    intensity_noise: f64,
    /// σ_w for normals, radians; σ_w for intensity; σ_c, m; E.
    sigmas: (f64, f64, f64, f64),
}

impl Graph {
    /// Builds the graph over `nodes`: an edge between nodes of the same tag
    /// whose centroids are within `edge_radius_m` (times the coarser node's
    /// scale), plus `random_edges` a node to a random node of the same tag
    /// within twice that.
    pub fn build(nodes: &[Node], params: &Parameters) -> Graph {
        let attributes: Vec<NodeAttributes> = nodes
            .iter()
            .map(|n| NodeAttributes {
                position: n.position(),
                normal: n.normal(),
                intensity: n.intensity(),
                points: n.points,
                tag: n.tag,
                scale: level_scale(n.level),
                intensity_points: n.intensity_points,
            })
            .collect();
        // One grid per level, of cubes twice that level's edge radius; a
        // pair's reach is set by the larger of its two levels, so each node
        // looks in its own level's grid and the coarser ones.
        let mut grids: Vec<CellGrid> = (0..LEVELS)
            .map(|l| CellGrid::new(2.0 * params.edge_radius_m * level_scale(l as u8)))
            .collect();
        for (k, n) in nodes.iter().enumerate() {
            grids[usize::from(n.level.min(LEVELS as u8 - 1))].insert(&n.position(), k as u32);
        }
        let mut pairs: Vec<(u32, u32)> = attributes
            .par_iter()
            .enumerate()
            .flat_map_iter(|(i, a)| {
                let mut local = Vec::new();
                let mut far = Vec::new();
                let own = usize::from(nodes[i].level.min(LEVELS as u8 - 1));
                for (l, grid) in grids.iter().enumerate().skip(own) {
                    let r = params.edge_radius_m * level_scale(l as u8);
                    let (r2, reach2) = (r * r, 4.0 * r * r);
                    for j in grid.around(&a.position) {
                        let b = &attributes[j as usize];
                        if j as usize == i || b.tag != a.tag {
                            continue;
                        }
                        let d2 = (b.position - a.position).norm_squared();
                        if d2 <= r2 {
                            if l > own || (j as usize) > i {
                                local.push((i.min(j as usize) as u32, i.max(j as usize) as u32));
                            }
                        } else if d2 <= reach2 {
                            far.push(j);
                        }
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
            intensity_var: Vec::new(),
            intensity_noise: params.intensity_noise,
            sigmas,
        };
        let terms: Vec<(f64, f32, f32, f32)> = (0..n)
            .into_par_iter()
            .flat_map_iter(|i| {
                let g = &graph;
                g.edges(i).map(move |(j, _)| {
                    let (a, b) = (&g.nodes[i], &g.nodes[j]);
                    (
                        g.proximity_of(i, j),
                        normal_angle(&a.normal, &b.normal) as f32,
                        (a.intensity - b.intensity).abs() as f32,
                        g.intensity_variance(i, j) as f32,
                    )
                })
            })
            .collect();
        graph.proximity = terms.iter().map(|t| t.0).collect();
        graph.normal_diff = terms.iter().map(|t| t.1).collect();
        graph.intensity_diff = terms.iter().map(|t| t.2).collect();
        graph.intensity_var = terms.iter().map(|t| t.3).collect();
        graph
    }

    /// Node `i`'s neighbours and their edge indices.
    pub fn edges(&self, i: usize) -> impl Iterator<Item = (usize, usize)> + '_ {
        (self.offsets[i]..self.offsets[i + 1]).map(|e| (self.targets[e] as usize, e))
    }

    /// P (eq. 2.4) between any two nodes, with eq. 2.5's distance; σ_c is
    /// scaled by the coarser node's level.
    pub fn proximity_of(&self, i: usize, j: usize) -> f64 {
        let (a, b) = (&self.nodes[i], &self.nodes[j]);
        let (_, _, sigma_c, e) = self.sigmas;
        proximity(
            anisotropic_distance(&a.position, &a.normal, &b.position, &b.normal, e),
            sigma_c * a.scale.max(b.scale),
        )
    }

    /// The variance of nodes `i` and `j`'s intensity difference from their
    /// own noise, σ²(1/n_i + 1/n_j).
    pub fn intensity_variance(&self, i: usize, j: usize) -> f64 {
        mean_difference_variance(
            self.intensity_noise,
            self.nodes[i].intensity_points,
            self.nodes[j].intensity_points,
        )
    }

    /// S (eq. 2.3) between any two nodes for `pass`. For intensity, σ_w is
    /// widened by the two means' own noise: σ² = σ_w² + σ²(1/n_i + 1/n_j),
    /// so that a cluster of three grazing points is not cut off a wall for
    /// reading 2σ_w off its mean.
    pub fn similarity_of(&self, i: usize, j: usize, pass: Pass) -> f64 {
        let (a, b) = (&self.nodes[i], &self.nodes[j]);
        let (sigma_normal, sigma_intensity, _, _) = self.sigmas;
        match pass {
            Pass::Normal => similarity(normal_angle(&a.normal, &b.normal), sigma_normal),
            Pass::Intensity => intensity_similarity(
                a.intensity - b.intensity,
                (sigma_intensity.powi(2) + self.intensity_variance(i, j)).sqrt(),
            ),
        }
    }

    /// S for `pass` on edge `e`.
    pub fn edge_similarity(&self, e: usize, pass: Pass) -> f64 {
        let (sigma_normal, sigma_intensity, _, _) = self.sigmas;
        match pass {
            Pass::Normal => similarity(f64::from(self.normal_diff[e]), sigma_normal),
            Pass::Intensity => intensity_similarity(
                f64::from(self.intensity_diff[e]),
                (sigma_intensity.powi(2) + f64::from(self.intensity_var[e])).sqrt(),
            ),
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
                .filter(|(d, p)| **p > 0.1 && d.is_finite())
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
    fn scale_levels_double_with_the_spacing() {
        // Clusters of 0.125 m: level 0 up to 0.125 m spacing, then one
        // level per doubling.
        assert_eq!(scale_level(0.03, 0.125), 0);
        assert_eq!(scale_level(0.125, 0.125), 0);
        assert_eq!(scale_level(0.2, 0.125), 1);
        assert_eq!(scale_level(0.25, 0.125), 1);
        assert_eq!(scale_level(0.26, 0.125), 2);
        assert_eq!(scale_level(1.0, 0.125), 3);
        assert_eq!(scale_level(1e6, 0.125), (LEVELS - 1) as u8);
        assert_eq!(scale_level(f64::NAN, 0.125), 0);
        assert_eq!(scale_level(f64::INFINITY, 0.125), 0);
        assert_eq!(level_scale(3), 8.0);
    }

    #[test]
    fn sparse_points_cluster_at_their_own_level_apart_from_the_dense_ones() {
        // A line of points 0.02 m apart, then one 0.3 m apart: with one
        // radius (0.1 m) every far point would be a node of its own.
        let mut c = Clusterer::new(0.1, 20.0, 0.1);
        let mut nodes = Vec::new();
        for i in 0..50 {
            nodes.push(c.add(
                &Vector3::new(i as f64 * 0.02, 0.0, 0.0),
                &Vector3::z(),
                0.5,
                u32::MAX,
                0,
            ));
        }
        let level = scale_level(0.3, 0.1);
        assert_eq!(level, 2);
        for i in 0..20 {
            nodes.push(c.add(
                &Vector3::new(1.0 + i as f64 * 0.3, 0.0, 0.0),
                &Vector3::z(),
                f64::NAN,
                u32::MAX,
                level,
            ));
        }
        let dense: std::collections::BTreeSet<u32> = nodes[..50].iter().copied().collect();
        let sparse: std::collections::BTreeSet<u32> = nodes[50..].iter().copied().collect();
        // Radius 0.4 m at level 2: two points a node, not one.
        assert_eq!(sparse.len(), 10, "{sparse:?}");
        assert!(dense.is_disjoint(&sparse));
        let all = c.into_nodes();
        // A node of points without intensity has none, not 0 or NaN mixed in.
        assert!(all[*sparse.first().unwrap() as usize].intensity().is_nan());
        assert!((all[0].intensity() - 0.5).abs() < 1e-12);
    }

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
            labels.push(c.add(
                &Vector3::new(i as f64 * 0.02, 0.0, 0.0),
                &Vector3::z(),
                0.5,
                u32::MAX,
                0,
            ));
        }
        for i in 0..10 {
            labels.push(c.add(
                &Vector3::new(1.0, 0.0, i as f64 * 0.02),
                &-Vector3::x(),
                0.5,
                u32::MAX,
                0,
            ));
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

//! Nearest-hit and any-hit queries over a scene's triangles, accelerated by
//! a bounding volume hierarchy. The `bvh` crate builds the tree (surface
//! area heuristic); it is then flattened into boxes this module traverses
//! nearest child first, skipping every box beyond the nearest hit so far
//! (the crate's own iterator visits every box the infinite ray crosses).

use bvh::aabb::{Aabb, Bounded};
use bvh::bounding_hierarchy::BHShape;
use bvh::bvh::{Bvh, BvhNode};
use nalgebra::{Point3, Vector3};

use super::mesh::{EdgeForm, Ray, Triangle};

/// A triangle's box while the tree is built.
#[derive(Debug, Clone)]
struct Leaf {
    bounds: Aabb<f64, 3>,
    node: usize,
}

impl Bounded<f64, 3> for Leaf {
    fn aabb(&self) -> Aabb<f64, 3> {
        self.bounds
    }
}

impl BHShape<f64, 3> for Leaf {
    fn set_bh_node_index(&mut self, index: usize) {
        self.node = index;
    }
    fn bh_node_index(&self) -> usize {
        self.node
    }
}

/// One node of the flattened tree: its box, and either two children or a triangle.
#[derive(Debug, Clone, Copy)]
struct Node {
    min: [f64; 3],
    max: [f64; 3],
    /// Inner node: `(left, right)`; leaf: `(triangle, usize::MAX)`.
    a: usize,
    b: usize,
}

impl Node {
    fn is_leaf(&self) -> bool {
        self.b == usize::MAX
    }

    /// Entry distance of the ray into the box within `(t_min, t_max)`, if any.
    fn entry(&self, origin: &Vector3<f64>, inverse: &Vector3<f64>, t_min: f64, t_max: f64) -> Option<f64> {
        let (mut lo, mut hi) = (t_min, t_max);
        for i in 0..3 {
            let a = (self.min[i] - origin[i]) * inverse[i];
            let b = (self.max[i] - origin[i]) * inverse[i];
            // NaN (0 × ∞ on a slab edge) compares false and leaves the bounds alone.
            let (near, far) = if a <= b { (a, b) } else { (b, a) };
            if near > lo {
                lo = near;
            }
            if far < hi {
                hi = far;
            }
            if lo > hi {
                return None;
            }
        }
        Some(lo)
    }
}

/// The hierarchy over a fixed list of triangles.
#[derive(Debug, Clone, Default)]
pub struct Accel {
    nodes: Vec<Node>,
    /// Per triangle, its corner and edges for the ray tests.
    forms: Vec<EdgeForm>,
}

/// The nearest hit along a ray.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriangleHit {
    /// Index of the triangle.
    pub triangle: usize,
    /// Distance along the ray.
    pub t: f64,
}

fn corners(b: &Aabb<f64, 3>) -> ([f64; 3], [f64; 3]) {
    ([b.min.x, b.min.y, b.min.z], [b.max.x, b.max.y, b.max.z])
}

impl Accel {
    /// Builds the hierarchy over `triangles`.
    pub fn build(triangles: &[Triangle]) -> Accel {
        if triangles.is_empty() {
            return Accel::default();
        }
        let mut leaves: Vec<Leaf> = triangles
            .iter()
            .map(|tri| {
                let mut bounds = Aabb::empty();
                for v in &tri.vertices {
                    bounds.grow_mut(&Point3::from(*v));
                }
                // Pad flat boxes so that slab tests stay robust on axis-aligned faces.
                let pad = Vector3::repeat(1e-9 * (1.0 + bounds.max.coords.norm()));
                Leaf {
                    bounds: Aabb::with_bounds(bounds.min - pad, bounds.max + pad),
                    node: 0,
                }
            })
            .collect();
        let tree = Bvh::build(&mut leaves);
        // Flatten: the crate keeps each child's box in its parent.
        let mut root = Aabb::empty();
        for l in &leaves {
            root.join_mut(&l.bounds);
        }
        let mut nodes = Vec::with_capacity(tree.nodes.len());
        let mut stack = vec![(0usize, root)];
        let mut index_of = vec![usize::MAX; tree.nodes.len()];
        let mut pending: Vec<(usize, usize, usize)> = Vec::new();
        while let Some((i, bounds)) = stack.pop() {
            let (min, max) = corners(&bounds);
            index_of[i] = nodes.len();
            match tree.nodes[i] {
                BvhNode::Leaf { shape_index, .. } => nodes.push(Node {
                    min,
                    max,
                    a: shape_index,
                    b: usize::MAX,
                }),
                BvhNode::Node {
                    child_l_index,
                    child_l_aabb,
                    child_r_index,
                    child_r_aabb,
                    ..
                } => {
                    pending.push((nodes.len(), child_l_index, child_r_index));
                    nodes.push(Node { min, max, a: 0, b: 0 });
                    stack.push((child_r_index, child_r_aabb));
                    stack.push((child_l_index, child_l_aabb));
                }
            }
        }
        for (at, l, r) in pending {
            nodes[at].a = index_of[l];
            nodes[at].b = index_of[r];
        }
        Accel {
            nodes,
            forms: triangles.iter().map(EdgeForm::new).collect(),
        }
    }

    /// Visits triangles whose boxes the ray enters within `(t_min, t_max)`,
    /// nearest box first; `visit` returns a new `t_max` (a nearer hit) or
    /// `None` to stop at once.
    fn traverse(&self, ray: &Ray, t_min: f64, t_max: f64, mut visit: impl FnMut(usize, f64) -> Option<f64>) {
        if self.nodes.is_empty() {
            return;
        }
        let inverse = ray.direction.map(|d| 1.0 / d);
        let mut t_max = t_max;
        let mut stack: [(usize, f64); 64] = [(0, 0.0); 64];
        let Some(entry) = self.nodes[0].entry(&ray.origin, &inverse, t_min, t_max) else {
            return;
        };
        stack[0] = (0, entry);
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let (i, entry) = stack[top];
            if entry > t_max {
                continue;
            }
            let node = &self.nodes[i];
            if node.is_leaf() {
                match visit(node.a, t_max) {
                    Some(t) => t_max = t,
                    None => return,
                }
                continue;
            }
            let l = self.nodes[node.a].entry(&ray.origin, &inverse, t_min, t_max);
            let r = self.nodes[node.b].entry(&ray.origin, &inverse, t_min, t_max);
            // Push the farther child first so that the nearer is visited next.
            let mut push = |n: usize, e: f64| {
                if top < stack.len() {
                    stack[top] = (n, e);
                    top += 1;
                }
            };
            match (l, r) {
                (Some(a), Some(b)) if a <= b => {
                    push(node.b, b);
                    push(node.a, a);
                }
                (Some(a), Some(b)) => {
                    push(node.a, a);
                    push(node.b, b);
                }
                (Some(a), None) => push(node.a, a),
                (None, Some(b)) => push(node.b, b),
                (None, None) => {}
            }
        }
    }

    /// The nearest triangle hit in `(t_min, t_max)`; `triangles` are those
    /// the hierarchy was built over (their edges are kept from the build).
    pub fn nearest(&self, triangles: &[Triangle], ray: &Ray, t_min: f64, t_max: f64) -> Option<TriangleHit> {
        debug_assert_eq!(triangles.len(), self.forms.len());
        let mut best: Option<TriangleHit> = None;
        self.traverse(ray, t_min, t_max, |i, limit| {
            if let Some(t) = self.forms[i].intersect(ray, t_min, limit) {
                best = Some(TriangleHit { triangle: i, t });
                Some(t)
            } else {
                Some(limit)
            }
        });
        best
    }

    /// Whether any triangle lies on `ray` within `(t_min, t_max)` (shadow rays).
    pub fn occluded(&self, triangles: &[Triangle], ray: &Ray, t_min: f64, t_max: f64) -> bool {
        debug_assert_eq!(triangles.len(), self.forms.len());
        let mut hit = false;
        self.traverse(ray, t_min, t_max, |i, limit| {
            if self.forms[i].intersect(ray, t_min, limit).is_some() {
                hit = true;
                None
            } else {
                Some(limit)
            }
        });
        hit
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Brute force agrees with the hierarchy on random rays through a random soup.
    #[test]
    fn nearest_matches_brute_force() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let mut v = || Vector3::new(rng.random::<f64>(), rng.random::<f64>(), rng.random::<f64>()) * 10.0;
        let tris: Vec<Triangle> = (0..300).filter_map(|i| Triangle::new([v(), v(), v()], 0, i)).collect();
        let accel = Accel::build(&tris);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(6);
        let mut agree = 0;
        for _ in 0..2000 {
            let origin = Vector3::new(rng.random(), rng.random(), rng.random()) * 10.0;
            let direction = Vector3::new(
                rng.random::<f64>() - 0.5,
                rng.random::<f64>() - 0.5,
                rng.random::<f64>() - 0.5,
            )
            .normalize();
            let ray = Ray { origin, direction };
            let brute = tris
                .iter()
                .enumerate()
                .filter_map(|(i, t)| t.intersect(&ray, 1e-9, f64::INFINITY).map(|d| (i, d)))
                .min_by(|a, b| a.1.total_cmp(&b.1));
            let fast = accel.nearest(&tris, &ray, 1e-9, f64::INFINITY);
            assert_eq!(brute.map(|b| b.0), fast.map(|f| f.triangle));
            assert_eq!(brute.is_some(), accel.occluded(&tris, &ray, 1e-9, f64::INFINITY));
            // A segment that stops short of the nearest hit is not occluded.
            if let Some((_, d)) = brute {
                assert!(!accel.occluded(&tris, &ray, 1e-9, d * 0.999));
            }
            agree += usize::from(brute.is_some());
        }
        assert!(agree > 500, "the test must exercise hits: {agree}");
    }

    #[test]
    fn axis_parallel_rays_hit_axis_aligned_faces() {
        let tris = super::super::shapes::cuboid(Vector3::zeros(), Vector3::repeat(1.0), false, [0; 6], [0; 6]);
        let accel = Accel::build(&tris);
        let ray = Ray {
            origin: Vector3::new(0.5, 0.5, 5.0),
            direction: -Vector3::z(),
        };
        let hit = accel.nearest(&tris, &ray, 1e-9, f64::INFINITY).unwrap();
        assert!((hit.t - 4.0).abs() < 1e-12);
    }
}

//! Nearest-hit and any-hit queries over a scene's triangles, accelerated by
//! a bounding volume hierarchy.
//!
//! The `bvh` crate builds a binary tree (surface area heuristic). It is
//! collapsed into a **4-wide** tree whose boxes are stored in `f32`, one
//! array per bound so that the four slab tests of a node run as one SIMD
//! operation. The triangles are still tested in `f64`
//! ([`EdgeForm`], Möller–Trumbore), so a hit's distance is the same number
//! to the last bit as with an `f64` tree: the `f32` boxes are rounded
//! outward and padded by the rounding of the ray's origin, and the far
//! bound of a slab test is widened by a few ulp, so a box test can only
//! admit more triangles, never miss one (Ize, "Robust BVH ray traversal",
//! JCGT 2013, gives the ulp bound). Traversal visits the nearest child
//! first (next, without a trip through the stack) and skips every box
//! beyond the nearest hit so far; any-hit queries take the children in
//! their stored order, since any hit ends them.

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

/// A child slot with nothing in it.
const EMPTY: u32 = u32::MAX;
/// Set on a child slot that holds a triangle rather than a node.
const TRIANGLE: u32 = 1 << 31;
/// The traversal stack's depth on the stack: three slots net per 4-wide
/// level, so 10 levels (a tree over about a million triangles) without
/// touching the heap; 32 measured a little faster than 96 on the example
/// scenes (less to initialise per ray). A deeper tree is still traversed
/// completely: what does not fit spills to a vector (see
/// `Accel::traverse`).
const STACK: usize = 32;

/// One node of the 4-wide tree: its children's boxes, bound by bound
/// (`bounds[0..3]` the minima in x, y, z, `bounds[3..6]` the maxima), and
/// what each child is.
#[derive(Debug, Clone, Copy)]
#[repr(C, align(32))]
struct Node4 {
    bounds: [[f32; 4]; 6],
    /// A node index, `TRIANGLE | triangle`, or [`EMPTY`].
    child: [u32; 4],
}

/// The binary tree as the `bvh` crate leaves it, flattened.
#[derive(Debug, Clone, Copy)]
enum Binary {
    Inner { left: usize, right: usize },
    Leaf { triangle: usize },
}

/// The hierarchy over a fixed list of triangles.
#[derive(Debug, Clone, Default)]
pub struct Accel {
    nodes: Vec<Node4>,
    /// The root's box test is the root node's; `root` says whether the
    /// tree is a single triangle (the root is then that triangle).
    root: u32,
    /// Per triangle, its corner and edges for the ray tests.
    forms: Vec<EdgeForm>,
    /// Added to every box, in metres: covers the rounding of a ray's
    /// origin to `f32` anywhere in the scene.
    pad: f64,
}

/// The nearest hit along a ray.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriangleHit {
    /// Index of the triangle.
    pub triangle: usize,
    /// Distance along the ray.
    pub t: f64,
}

/// The ray as the `f32` box tests take it.
struct BoxRay {
    origin: [f32; 3],
    inverse: [f32; 3],
    /// Per axis, the bound index (0..6) of the near slab plane.
    near: [usize; 3],
    /// Per axis, the bound index of the far slab plane.
    far: [usize; 3],
}

impl BoxRay {
    fn new(ray: &Ray) -> BoxRay {
        let mut b = BoxRay {
            origin: [0.0; 3],
            inverse: [0.0; 3],
            near: [0; 3],
            far: [0; 3],
        };
        for i in 0..3 {
            b.origin[i] = ray.origin[i] as f32;
            let inverse = 1.0 / ray.direction[i];
            // A component too small for f32 becomes ±∞, as 1/±0 does.
            b.inverse[i] = inverse as f32;
            let positive = inverse.is_sign_positive();
            b.near[i] = if positive { i } else { i + 3 };
            b.far[i] = if positive { i + 3 } else { i };
        }
        b
    }

    /// Entry distances of the ray into the node's four boxes within
    /// `(t_min, t_max)`, NaN where it misses (so that every comparison with
    /// a distance fails, `t_max` = ∞ included). Written lane by
    /// lane over arrays so that the compiler issues 4-wide SIMD.
    #[inline(always)]
    fn entries(&self, node: &Node4, t_min: f32, t_max: f32) -> [f32; 4] {
        let mut out = [f32::NAN; 4];
        let b = &node.bounds;
        let (nx, ny, nz) = (&b[self.near[0]], &b[self.near[1]], &b[self.near[2]]);
        let (fx, fy, fz) = (&b[self.far[0]], &b[self.far[1]], &b[self.far[2]]);
        let [ox, oy, oz] = self.origin;
        let [ix, iy, iz] = self.inverse;
        for k in 0..4 {
            // A slab distance is NaN when the origin lies on the slab's
            // plane and the ray runs along it (0 × ∞); that axis then
            // leaves the ray unconstrained. `more`/`less` keep the bound
            // so far when the new distance is NaN, as `f32::max`/`min`
            // ignore a NaN, but compile to one `maxps`/`minps` each.
            let near = more(
                more(more(t_min, (nx[k] - ox) * ix), (ny[k] - oy) * iy),
                (nz[k] - oz) * iz,
            );
            let far = less(
                less(less(t_max, (fx[k] - ox) * ix), (fy[k] - oy) * iy),
                (fz[k] - oz) * iz,
            );
            // Widen the far bound by a few ulp: the slab distances are
            // rounded (Ize 2013: 1 + 2γ₃).
            // A box beside a ray parallel to its slabs is "entered" at ∞.
            out[k] = if near <= far * (1.0 + 4.0 * f32::EPSILON) && near < f32::INFINITY {
                near
            } else {
                f32::NAN
            };
        }
        out
    }
}

/// The larger of `bound` and `d`; `bound` when `d` is NaN (`bound` never is).
#[inline(always)]
fn more(bound: f32, d: f32) -> f32 {
    if d > bound { d } else { bound }
}

/// The smaller of `bound` and `d`; `bound` when `d` is NaN (`bound` never is).
#[inline(always)]
fn less(bound: f32, d: f32) -> f32 {
    if d < bound { d } else { bound }
}

fn corners(b: &Aabb<f64, 3>) -> ([f64; 3], [f64; 3]) {
    ([b.min.x, b.min.y, b.min.z], [b.max.x, b.max.y, b.max.z])
}

/// `x` in `f32`, rounded toward −∞ (`down`) or +∞.
fn round_f32(x: f64, down: bool) -> f32 {
    let y = x as f32;
    match (down, f64::from(y)) {
        (true, v) if v > x => y.next_down(),
        (false, v) if v < x => y.next_up(),
        _ => y,
    }
}

/// Surface area of a box (the collapse opens the largest child first).
fn area(min: &[f64; 3], max: &[f64; 3]) -> f64 {
    let d = [max[0] - min[0], max[1] - min[1], max[2] - min[2]];
    d[0] * d[1] + d[1] * d[2] + d[2] * d[0]
}

impl Accel {
    /// Builds the hierarchy over `triangles`.
    pub fn build(triangles: &[Triangle]) -> Accel {
        if triangles.is_empty() {
            return Accel::default();
        }
        let mut extent = 0.0f64;
        let mut leaves: Vec<Leaf> = triangles
            .iter()
            .map(|tri| {
                let mut bounds = Aabb::empty();
                for v in &tri.vertices {
                    bounds.grow_mut(&Point3::from(*v));
                    extent = extent.max(v.amax());
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
        let mut binary = vec![Binary::Leaf { triangle: 0 }; tree.nodes.len()];
        let mut boxes = vec![([0.0; 3], [0.0; 3]); tree.nodes.len()];
        let mut stack = vec![(0usize, root)];
        while let Some((i, bounds)) = stack.pop() {
            boxes[i] = corners(&bounds);
            binary[i] = match tree.nodes[i] {
                BvhNode::Leaf { shape_index, .. } => Binary::Leaf { triangle: shape_index },
                BvhNode::Node {
                    child_l_index,
                    child_l_aabb,
                    child_r_index,
                    child_r_aabb,
                    ..
                } => {
                    stack.push((child_r_index, child_r_aabb));
                    stack.push((child_l_index, child_l_aabb));
                    Binary::Inner {
                        left: child_l_index,
                        right: child_r_index,
                    }
                }
            };
        }
        // An f32 origin is within |o|·2⁻²⁴ of the true one: pad every box by
        // more than that anywhere in the scene (and by ray origins a little
        // outside it).
        let pad = 1e-6 * (1.0 + extent);
        let mut accel = Accel {
            nodes: Vec::with_capacity(tree.nodes.len() / 2 + 1),
            root: 0,
            forms: triangles.iter().map(EdgeForm::new).collect(),
            pad,
        };
        accel.root = match binary[0] {
            Binary::Leaf { triangle } => TRIANGLE | triangle as u32,
            Binary::Inner { .. } => accel.collapse(&binary, &boxes, 0),
        };
        accel
    }

    /// Collapses the binary subtree at `i` (an inner node) into 4-wide
    /// nodes: its two children are opened, largest box first, until there
    /// are four or only leaves. Returns the new node's index.
    fn collapse(&mut self, binary: &[Binary], boxes: &[([f64; 3], [f64; 3])], i: usize) -> u32 {
        let Binary::Inner { left, right } = binary[i] else {
            unreachable!("collapse starts at an inner node");
        };
        let mut children = vec![left, right];
        while children.len() < 4 {
            let open = children
                .iter()
                .enumerate()
                .filter(|(_, c)| matches!(binary[**c], Binary::Inner { .. }))
                .max_by(|a, b| area(&boxes[*a.1].0, &boxes[*a.1].1).total_cmp(&area(&boxes[*b.1].0, &boxes[*b.1].1)))
                .map(|(k, _)| k);
            let Some(k) = open else { break };
            let Binary::Inner { left, right } = binary[children[k]] else {
                unreachable!("only inner nodes are opened");
            };
            children[k] = left;
            children.push(right);
        }
        let at = self.nodes.len();
        self.nodes.push(Node4 {
            bounds: [
                [f32::INFINITY; 4],
                [f32::INFINITY; 4],
                [f32::INFINITY; 4],
                [f32::NEG_INFINITY; 4],
                [f32::NEG_INFINITY; 4],
                [f32::NEG_INFINITY; 4],
            ],
            child: [EMPTY; 4],
        });
        for (k, &c) in children.iter().enumerate() {
            let (min, max) = boxes[c];
            for axis in 0..3 {
                self.nodes[at].bounds[axis][k] = round_f32(min[axis] - self.pad, true);
                self.nodes[at].bounds[axis + 3][k] = round_f32(max[axis] + self.pad, false);
            }
            self.nodes[at].child[k] = match binary[c] {
                Binary::Leaf { triangle } => TRIANGLE | triangle as u32,
                Binary::Inner { .. } => self.collapse(binary, boxes, c),
            };
        }
        at as u32
    }

    /// Visits triangles whose boxes the ray enters within `(t_min, t_max)`,
    /// nearest box first when `ORDERED` (nearest-hit queries; any-hit
    /// queries gain nothing from the order, measured 3–6 % faster without
    /// it); `visit` returns a new `t_max` (a nearer hit) or `None` to stop
    /// at once.
    #[inline(always)]
    fn traverse<const ORDERED: bool>(
        &self,
        ray: &Ray,
        t_min: f64,
        t_max: f64,
        mut visit: impl FnMut(usize, f64) -> Option<f64>,
    ) {
        if self.forms.is_empty() {
            return;
        }
        if self.root & TRIANGLE != 0 {
            visit((self.root & !TRIANGLE) as usize, t_max);
            return;
        }
        let b = BoxRay::new(ray);
        let lo = round_f32(t_min, true).max(0.0);
        let mut t_max = t_max;
        let mut hi = round_f32(t_max, false);
        let mut stack = [(0u32, 0f32); STACK];
        let mut top = 0;
        // Entries pushed once the array is full (the most recent, so popped
        // first); empty, and never allocated, on any tree of sane depth.
        let mut spill: Vec<(u32, f32)> = Vec::new();
        let mut n = self.root;
        loop {
            let node = &self.nodes[n as usize];
            let entries = b.entries(node, lo, hi);
            // Triangles first (they may shorten the ray), then the nearest
            // node next and the others on the stack, farthest deepest.
            let mut inner = [(0u32, f32::INFINITY); 4];
            let mut count = 0;
            for (&e, &c) in entries.iter().zip(&node.child) {
                // A miss is NaN, so it fails this test whatever `hi` is.
                let entered = e <= hi;
                if !entered {
                    continue;
                }
                if c & TRIANGLE != 0 && c != EMPTY {
                    match visit((c & !TRIANGLE) as usize, t_max) {
                        Some(t) => {
                            if t < t_max {
                                t_max = t;
                                hi = round_f32(t, false);
                            }
                        }
                        None => return,
                    }
                } else if c != EMPTY {
                    inner[count] = (c, e);
                    count += 1;
                }
            }
            // Farthest first: a sort of at most four, by hand (the
            // library's sort costs a call and its general cases, 1.5 % of
            // a demo's time in `perf`).
            for i in (1..count).filter(|_| ORDERED) {
                let mut j = i;
                while j > 0 && inner[j - 1].1 < inner[j].1 {
                    inner.swap(j - 1, j);
                    j -= 1;
                }
            }
            if count > 0 {
                count -= 1;
                for &(c, e) in &inner[..count] {
                    if top < STACK && spill.is_empty() {
                        stack[top] = (c, e);
                        top += 1;
                    } else {
                        spill.push((c, e));
                    }
                }
                // The nearest child goes next without a trip through the
                // stack, unless a triangle tested after it already lies
                // nearer than its box.
                let (c, e) = inner[count];
                if e <= hi {
                    n = c;
                    continue;
                }
            }
            loop {
                let (c, e) = match spill.pop() {
                    Some(p) => p,
                    None if top > 0 => {
                        top -= 1;
                        stack[top]
                    }
                    None => return,
                };
                if e <= hi {
                    n = c;
                    break;
                }
            }
        }
    }

    /// Levels of 4-wide nodes on the longest path from the root.
    #[cfg(test)]
    fn depth(&self, node: u32) -> usize {
        if node & TRIANGLE != 0 {
            return 0;
        }
        1 + self.nodes[node as usize]
            .child
            .iter()
            .filter(|&&c| c != EMPTY)
            .map(|&c| self.depth(c))
            .max()
            .unwrap_or(0)
    }

    /// The nearest triangle hit in `(t_min, t_max)`; `triangles` are those
    /// the hierarchy was built over (their edges are kept from the build).
    pub fn nearest(&self, triangles: &[Triangle], ray: &Ray, t_min: f64, t_max: f64) -> Option<TriangleHit> {
        debug_assert_eq!(triangles.len(), self.forms.len());
        let mut best: Option<TriangleHit> = None;
        self.traverse::<true>(ray, t_min, t_max, |i, limit| {
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
        self.traverse::<false>(ray, t_min, t_max, |i, limit| {
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

    /// The slab test's `more`/`less` are `f32::max`/`min` whenever the
    /// bound is a number (a NaN distance leaves the bound), so the faster
    /// test admits exactly the boxes the old one did.
    #[test]
    fn more_and_less_are_max_and_min_ignoring_a_nan_distance() {
        let values = [
            f32::NEG_INFINITY,
            -3.5,
            -0.0,
            0.0,
            1e-30,
            2.25,
            f32::MAX,
            f32::INFINITY,
            f32::NAN,
        ];
        for &bound in values.iter().filter(|v| !v.is_nan()) {
            for &d in &values {
                assert_eq!(more(bound, d), bound.max(d), "more({bound}, {d})");
                assert_eq!(less(bound, d), bound.min(d), "less({bound}, {d})");
            }
        }
    }

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

    /// The f32 boxes never lose a hit, far from the origin (where f32
    /// spacing is 0.5 mm), along axis-parallel rays and rays that start on
    /// a triangle; and the distances are the f64 test's, bit for bit.
    #[test]
    fn f32_boxes_keep_every_hit_far_from_the_origin() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let offset = Vector3::new(5000.0, -3000.0, 200.0);
        // Small triangles (5–25 cm) in a 2 m cube 5 km out, some axis-aligned.
        let tris: Vec<Triangle> = (0..2000)
            .filter_map(|i| {
                let c = offset + Vector3::new(rng.random(), rng.random(), rng.random()) * 2.0;
                let s = 0.05 + 0.2 * rng.random::<f64>();
                let mut e = || {
                    Vector3::new(
                        rng.random::<f64>() - 0.5,
                        rng.random::<f64>() - 0.5,
                        rng.random::<f64>() - 0.5,
                    ) * s
                };
                let (a, mut b, mut d) = (e(), e(), e());
                if i % 3 == 0 {
                    b.z = a.z;
                    d.z = a.z;
                }
                Triangle::new([c + a, c + b, c + d], 0, i)
            })
            .collect();
        let accel = Accel::build(&tris);
        let mut hits = 0;
        for k in 0..4000 {
            let ray = if k % 4 == 0 {
                // Along an axis, from outside the cube.
                let axis = k / 4 % 3;
                let mut origin = offset + Vector3::new(rng.random(), rng.random(), rng.random()) * 2.0;
                origin[axis] = offset[axis] - 1.0;
                let mut direction = Vector3::zeros();
                direction[axis] = 1.0;
                Ray { origin, direction }
            } else {
                // From a point on a triangle, as a bounce or a shadow ray.
                let t = &tris[rng.random_range(0..tris.len())];
                let d = Vector3::new(
                    rng.random::<f64>() - 0.5,
                    rng.random::<f64>() - 0.5,
                    rng.random::<f64>() - 0.5,
                )
                .normalize();
                Ray {
                    origin: t.point(0.3, 0.3),
                    direction: d,
                }
            };
            let brute = tris
                .iter()
                .enumerate()
                .filter_map(|(i, t)| t.intersect(&ray, 1e-7, f64::INFINITY).map(|d| (i, d)))
                .min_by(|a, b| a.1.total_cmp(&b.1));
            let fast = accel.nearest(&tris, &ray, 1e-7, f64::INFINITY);
            assert_eq!(brute.map(|b| b.1), fast.map(|f| f.t), "ray {k}: {ray:?}");
            assert_eq!(
                brute.is_some(),
                accel.occluded(&tris, &ray, 1e-7, f64::INFINITY),
                "ray {k}"
            );
            hits += usize::from(brute.is_some());
        }
        assert!(hits > 800, "the test must exercise hits: {hits}");
    }

    /// Thousands of coincident triangles: the build cannot separate them,
    /// and every query must still find one (and the any-hit test too).
    #[test]
    fn coincident_triangles_are_still_found() {
        let corners = [Vector3::zeros(), Vector3::x(), Vector3::y()];
        let tris: Vec<Triangle> = (0..3000).filter_map(|i| Triangle::new(corners, 0, i)).collect();
        let accel = Accel::build(&tris);
        // Deeper than the stack holds: the spill is exercised.
        assert!(accel.depth(accel.root) > STACK / 3, "depth {}", accel.depth(accel.root));
        for (x, y) in [(0.1, 0.1), (0.5, 0.2), (0.01, 0.9)] {
            let ray = Ray {
                origin: Vector3::new(x, y, 2.0),
                direction: -Vector3::z(),
            };
            assert_eq!(accel.nearest(&tris, &ray, 1e-9, f64::INFINITY).map(|h| h.t), Some(2.0));
            assert!(accel.occluded(&tris, &ray, 1e-9, 3.0));
            assert!(!accel.occluded(&tris, &ray, 1e-9, 1.5));
        }
    }

    #[test]
    fn a_single_triangle_and_an_empty_scene() {
        let tri = Triangle::new([Vector3::zeros(), Vector3::x(), Vector3::y()], 0, 0).unwrap();
        let accel = Accel::build(std::slice::from_ref(&tri));
        let down = Ray {
            origin: Vector3::new(0.2, 0.2, 1.0),
            direction: -Vector3::z(),
        };
        assert_eq!(
            accel
                .nearest(std::slice::from_ref(&tri), &down, 1e-9, f64::INFINITY)
                .map(|h| h.t),
            Some(1.0)
        );
        assert!(!accel.occluded(std::slice::from_ref(&tri), &down, 1e-9, 0.5));
        let empty = Accel::build(&[]);
        assert_eq!(empty.nearest(&[], &down, 1e-9, f64::INFINITY), None);
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

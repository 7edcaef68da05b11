//! Nearest-hit and any-hit queries over a scene's triangles, accelerated by
//! a bounding volume hierarchy (the `bvh` crate, SAH build).

use std::cell::Cell;

use bvh::aabb::{Aabb, Bounded, IntersectsAabb};
use bvh::bounding_hierarchy::BHShape;
use bvh::bvh::Bvh;
use nalgebra::{Point3, Vector3};

use super::mesh::{Ray, Triangle};

/// A triangle's box in the hierarchy.
#[derive(Debug, Clone)]
struct Leaf {
    index: usize,
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

/// A ray segment `(t_min, t_max)` as a hierarchy query. `t_max` shrinks as
/// nearer hits are found, so boxes beyond the nearest hit so far are
/// skipped (the crate's own ray query tests the whole infinite ray).
struct Segment {
    origin: Vector3<f64>,
    inverse: Vector3<f64>,
    t_min: f64,
    t_max: Cell<f64>,
}

impl Segment {
    fn new(ray: &Ray, t_min: f64, t_max: f64) -> Segment {
        Segment {
            origin: ray.origin,
            inverse: ray.direction.map(|d| 1.0 / d),
            t_min,
            t_max: Cell::new(t_max),
        }
    }
}

impl IntersectsAabb<f64, 3> for Segment {
    fn intersects_aabb(&self, aabb: &Aabb<f64, 3>) -> bool {
        let (mut lo, mut hi) = (self.t_min, self.t_max.get());
        for i in 0..3 {
            let a = (aabb.min[i] - self.origin[i]) * self.inverse[i];
            let b = (aabb.max[i] - self.origin[i]) * self.inverse[i];
            // NaN (0 × ∞ on a slab edge) compares false and leaves the bounds alone.
            let (near, far) = if a <= b { (a, b) } else { (b, a) };
            if near > lo {
                lo = near;
            }
            if far < hi {
                hi = far;
            }
            if lo > hi {
                return false;
            }
        }
        true
    }
}

/// The hierarchy over a fixed list of triangles.
#[derive(Debug, Clone)]
pub struct Accel {
    bvh: Option<Bvh<f64, 3>>,
    leaves: Vec<Leaf>,
}

/// The nearest hit along a ray.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriangleHit {
    /// Index of the triangle.
    pub triangle: usize,
    /// Distance along the ray.
    pub t: f64,
}

impl Accel {
    /// Builds the hierarchy over `triangles`.
    pub fn build(triangles: &[Triangle]) -> Accel {
        let mut leaves: Vec<Leaf> = triangles
            .iter()
            .enumerate()
            .map(|(index, tri)| {
                let p = |v: &Vector3<f64>| Point3::from(*v);
                let mut bounds = Aabb::empty();
                for v in &tri.vertices {
                    bounds.grow_mut(&p(v));
                }
                // Pad flat boxes so that slab tests stay robust on axis-aligned faces.
                let pad = Vector3::repeat(1e-9);
                bounds = Aabb::with_bounds(bounds.min - pad, bounds.max + pad);
                Leaf { index, bounds, node: 0 }
            })
            .collect();
        let bvh = (!leaves.is_empty()).then(|| Bvh::build(&mut leaves));
        Accel { bvh, leaves }
    }

    /// The nearest triangle hit in `(t_min, t_max)`.
    pub fn nearest(&self, triangles: &[Triangle], ray: &Ray, t_min: f64, t_max: f64) -> Option<TriangleHit> {
        let bvh = self.bvh.as_ref()?;
        let query = Segment::new(ray, t_min, t_max);
        let mut best: Option<TriangleHit> = None;
        for leaf in bvh.traverse_iterator(&query, &self.leaves) {
            if let Some(t) = triangles[leaf.index].intersect(ray, t_min, query.t_max.get()) {
                best = Some(TriangleHit {
                    triangle: leaf.index,
                    t,
                });
                query.t_max.set(t);
            }
        }
        best
    }

    /// Whether any triangle lies on `ray` within `(t_min, t_max)` (shadow rays).
    pub fn occluded(&self, triangles: &[Triangle], ray: &Ray, t_min: f64, t_max: f64) -> bool {
        let Some(bvh) = self.bvh.as_ref() else {
            return false;
        };
        let query = Segment::new(ray, t_min, t_max);
        bvh.traverse_iterator(&query, &self.leaves)
            .any(|leaf| triangles[leaf.index].intersect(ray, t_min, t_max).is_some())
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
        for _ in 0..500 {
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
            agree += usize::from(brute.is_some());
        }
        assert!(agree > 100, "the test must exercise hits: {agree}");
    }
}

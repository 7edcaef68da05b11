//! Small objects that no cluster holds: points left unassigned that lie
//! together make a group of their own.
//!
//! Clusters are a few point spacings across (§2.3.2), so an object smaller
//! than a cluster or two, such as a 15 cm ball on a table, gives nodes too
//! small to survive as groups, and its points end unassigned (the points
//! stage finds no group near enough). They are still a surface a user
//! wants: the scene's lamps, ornaments, and the ball whose highlight the
//! reflectance solver needs. This pass, ours and not the thesis's, joins
//! unassigned points closer than [`LINK_SPACINGS`] times their spacing
//! (here the distance to the nearest other unassigned point) and
//! makes each set of at least `min_group_points` points a group
//! ([`Object`] in the report). Mixed pixels at depth edges, scattered
//! along the beam between two surfaces, seldom lie that close together and
//! stay unassigned.

use serde::{Deserialize, Serialize};

use super::normals::{nearest, point_tree};
use crate::cloud::Scan;
use crate::segmentation::UNASSIGNED;

/// Two unassigned points are joined when each is within this many times
/// its distance to its nearest other unassigned point of the other.
pub const LINK_SPACINGS: f64 = 2.0;

/// A group made of unassigned points; its group is `G`: a raw number as
/// the pass finds it, a name in the report.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Object<G = String> {
    /// Its group.
    pub group: G,
    /// Its points.
    pub points: usize,
    /// Its bounding box's longest side, m.
    pub extent_m: f64,
}

impl Object<u32> {
    /// The same object with its group named by `name`.
    pub fn named(&self, name: impl Fn(u32) -> String) -> Object {
        Object {
            group: name(self.group),
            points: self.points,
            extent_m: self.extent_m,
        }
    }
}

/// The root of `i`'s set, halving the path on the way.
fn root(parent: &mut [u32], mut i: u32) -> u32 {
    while parent[i as usize] != i {
        let up = parent[parent[i as usize] as usize];
        parent[i as usize] = up;
        i = up;
    }
    i
}

/// Makes each set of at least `min_points` unassigned points of `labels`
/// that lie together a group, numbered from `groups` on; returns them in
/// that order (the caller names them: [`Object::named`]).
pub fn group_leftovers(scans: &[Scan], labels: &mut [Vec<u32>], groups: usize, min_points: usize) -> Vec<Object<u32>> {
    let left: Vec<(u32, u32)> = labels
        .iter()
        .enumerate()
        .flat_map(|(s, l)| {
            l.iter()
                .enumerate()
                .filter(|(_, g)| **g == UNASSIGNED)
                .map(move |(i, _)| (s as u32, i as u32))
        })
        .collect();
    if left.len() < min_points.max(1) {
        return Vec::new();
    }
    let positions: Vec<_> = left
        .iter()
        .map(|&(s, i)| scans[s as usize].positions[i as usize])
        .collect();
    let tree = point_tree(&positions);
    // Each point's reach: a multiple of its distance to the nearest other
    // leftover point (the local spacing measured over a scan window is
    // inflated at silhouettes, where leftovers are).
    let reach: Vec<f64> = positions
        .iter()
        .map(|p| LINK_SPACINGS * nearest(&tree, p, 2).get(1).map_or(0.0, |n| n.0))
        .collect();
    let mut parent: Vec<u32> = (0..left.len() as u32).collect();
    for (k, p) in positions.iter().enumerate() {
        if !(reach[k].is_finite() && reach[k] > 0.0) {
            continue;
        }
        for n in tree.within_unsorted::<kiddo::SquaredEuclidean>(&[p.x, p.y, p.z], reach[k] * reach[k]) {
            let j = n.item as usize;
            if n.distance.sqrt() > reach[j] {
                continue;
            }
            let (a, b) = (root(&mut parent, k as u32), root(&mut parent, j as u32));
            if a != b {
                parent[a.max(b) as usize] = a.min(b);
            }
        }
    }
    let mut members: std::collections::BTreeMap<u32, Vec<usize>> = std::collections::BTreeMap::new();
    for k in 0..left.len() {
        let r = root(&mut parent, k as u32);
        members.entry(r).or_default().push(k);
    }
    let mut objects = Vec::new();
    for set in members.into_values().filter(|m| m.len() >= min_points) {
        let group = (groups + objects.len()) as u32;
        let (mut lo, mut hi) = (positions[set[0]], positions[set[0]]);
        for &k in &set {
            let (s, i) = left[k];
            labels[s as usize][i as usize] = group;
            lo = lo.inf(&positions[k]);
            hi = hi.sup(&positions[k]);
        }
        objects.push(Object {
            group,
            points: set.len(),
            extent_m: (hi - lo).max(),
        });
    }
    objects
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn two_balls_become_two_groups_and_scattered_points_stay_unassigned() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mut positions = Vec::new();
        // Two balls of 20 cm radius, 13 cm apart at their nearest (as the
        // simulated room's spheres), 120 points each on their near halves,
        // about 3 cm apart.
        for centre in [Vector3::new(0.0, 0.0, 1.0), Vector3::new(0.53, 0.0, 1.0)] {
            for i in 0..12 {
                for k in 0..10 {
                    let (a, b) = (i as f64 / 12.0 * std::f64::consts::PI, k as f64 / 10.0 * 1.4 - 0.7);
                    positions.push(centre + 0.2 * Vector3::new(a.cos() * b.cos(), -a.sin() * b.cos(), b.sin()));
                }
            }
        }
        // 25 mixed pixels scattered in a 3 m box, and a wall point group
        // already labelled.
        for _ in 0..25 {
            positions.push(Vector3::new(
                rng.random_range(-1.0..2.0),
                rng.random_range(0.5..3.5),
                rng.random_range(0.0..3.0),
            ));
        }
        let scan = Scan::from_positions("balls", positions);
        let mut labels = vec![vec![UNASSIGNED; scan.len()]];
        labels[0][0] = 0;
        let objects = group_leftovers(std::slice::from_ref(&scan), &mut labels, 1, 30);
        assert_eq!(objects.len(), 2, "{objects:?}");
        // The first ball (less the point already in group 0) and the second.
        assert_eq!(objects[0].points, 119);
        assert_eq!(objects[1].points, 120);
        for o in &objects {
            assert!((o.extent_m - 0.4).abs() < 0.03, "{o:?}");
        }
        assert!(labels[0][1..120].iter().all(|&l| l == 1));
        assert!(labels[0][120..240].iter().all(|&l| l == 2));
        assert!(labels[0][240..].iter().all(|&l| l == UNASSIGNED));
    }
}

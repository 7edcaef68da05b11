//! Boundary improvement by local voting (§2.3.4).
//!
//! After a split, the boundary between the two sides may be off the true
//! surface boundary by a node or two. At every node on the boundary (one
//! with an edge to the other side), the thesis solves a local problem: the
//! node and its neighbours, ordered by the eigenvector of eq. 2.2, on a
//! complete graph of their weights w = S·P; the cut of that order with the
//! least Ncut assigns each of them a side. A node takes part in several
//! local problems; the majority of their votes decides its side (a tie keeps
//! the side it had).
//!
//! A local cut votes only when it passes the split's own test (Ncut and
//! NWAcut under T_cut, §2.3.3): a neighbourhood that lies all on one
//! surface has no boundary to place, and the least-Ncut cut of its order
//! (the region's eigenvector, meaningless inside one surface) would hand
//! good nodes to the other side. Taking every least-Ncut cut, a split that
//! peeled four grazing corner nodes off the ceiling grew, vote by vote,
//! into ceiling pieces of 200–600 points: 9 extra groups on the simulated
//! room.

use super::criterion::scan_cuts;
use super::graph::{Graph, Pass};

/// Re-decides the sides of the nodes near the boundary. `members` are the
/// region's graph nodes, `edges` its local adjacency ((j, w, P) per node),
/// `y` the eigenvector, `side_a` each member's side (updated), `t_cut`
/// the split's threshold.
pub fn improve(
    graph: &Graph,
    members: &[u32],
    edges: &[Vec<(u32, f64, f64)>],
    y: &[f64],
    side_a: &mut [bool],
    pass: Pass,
    t_cut: f64,
) {
    let n = members.len();
    // Votes for A and for B.
    let mut votes = vec![(0u32, 0u32); n];
    for c in 0..n {
        if !edges[c].iter().any(|&(j, _, _)| side_a[j as usize] != side_a[c]) {
            continue;
        }
        let mut hood: Vec<usize> = std::iter::once(c)
            .chain(edges[c].iter().map(|&(j, _, _)| j as usize))
            .collect();
        hood.sort_unstable();
        hood.dedup();
        if hood.len() < 3 {
            continue;
        }
        let m = hood.len();
        // The complete graph on the neighbourhood.
        let local: Vec<Vec<(u32, f64, f64)>> = (0..m)
            .map(|a| {
                (0..m)
                    .filter(|&b| b != a)
                    .map(|b| {
                        let (u, v) = (members[hood[a]] as usize, members[hood[b]] as usize);
                        let p = graph.proximity_of(u, v);
                        (b as u32, graph.similarity_of(u, v, pass) * p, p)
                    })
                    .collect()
            })
            .collect();
        let mut order: Vec<usize> = (0..m).collect();
        order.sort_by(|&a, &b| y[hood[a]].total_cmp(&y[hood[b]]));
        // The least-Ncut cut of the order among those that pass.
        let (passing, _) = scan_cuts(&order, &local, t_cut);
        let Some(cut) = passing else { continue };
        // The side of the order's low end is the side most of those nodes had.
        let low_in_a = order[..cut.k].iter().filter(|&&i| side_a[hood[i]]).count() * 2 >= cut.k;
        for (rank, &i) in order.iter().enumerate() {
            let in_a = (rank < cut.k) == low_in_a;
            let v = &mut votes[hood[i]];
            if in_a { v.0 += 1 } else { v.1 += 1 }
        }
    }
    for (side, (a, b)) in side_a.iter_mut().zip(votes) {
        if a > b {
            *side = true;
        } else if b > a {
            *side = false;
        }
    }
}

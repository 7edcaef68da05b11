//! The partition criterion (§2.3.3): recursive bipartition by the
//! second-smallest generalized eigenvector of (D − W)y = λDy (eq. 2.2),
//! accepted only when both Ncut (eq. 2.1) and the normalized weighted-average
//! cut NWAcut (eq. 2.6) are below T_cut.
//!
//! **The eigenvector.** With z = D^½ y, eq. 2.2 is the symmetric problem
//! (I − D^-½ W D^-½) z = λ z. Its smallest eigenvector is D^½ 1 (λ = 0); the
//! Fiedler vector is the largest eigenvector of
//! M = I + D^-½ W D^-½ − 2 u uᵀ (u = D^½ 1 / ‖D^½ 1‖), whose spectrum is
//! 2 − λ ∈ [0, 2] with the trivial one deflated to 0. `faer`'s matrix-free
//! Krylov–Schur solver (the restarted Lanczos the thesis uses, [18]) finds it
//! from sparse products; regions of 300 nodes or fewer use a dense
//! symmetric eigensolver (nalgebra).
//!
//! **The threshold.** The thesis searches "a certain number of discrete
//! values" along the eigenvector for the best Ncut. Here every one of the
//! n − 1 cuts of the eigenvector's order is evaluated (Ncut and NWAcut are
//! updated incrementally, O(edges) in all), and the split taken is the one of
//! least Ncut **among those whose NWAcut is below T_cut**; when none is, the
//! least-Ncut split is recorded as refused. Taking the least Ncut regardless
//! would, on Fig. 2.2's regions, stop at a refused split in the middle of A
//! where a split at the A–B border passes both tests.
//!
//! Disconnected regions are split into their components first (edges
//! under [`NO_EDGE`] left out; recorded with Ncut = NWAcut = 0): on a
//! 0.96 M-point room, peeling such weakly held pieces off 50 000-node
//! regions one eigensolve at a time took most of the time.

use std::sync::Mutex;

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::matrix_free::LinOp;
use faer::matrix_free::eigen::{PartialEigenParams, partial_self_adjoint_eigen, partial_self_adjoint_eigen_scratch};
use faer::{Col, Mat, MatMut, MatRef, Par};
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use super::boundary;
use super::graph::{Graph, Pass};

/// Edges lighter than this count as absent when finding components: a node
/// or piece held only by such edges (w = S·P under a thousandth, against
/// 0.3–1 within a surface) is split off at once, without an eigensolve.
const NO_EDGE: f64 = 1e-3;

/// Regions from this size multiply in parallel.
const PARALLEL_FROM: usize = 16_384;

/// The eigensolver's residual tolerance (the operator's norm is at most 2):
/// the split needs the eigenvector's order, not its last digits.
const TOLERANCE: f64 = 1e-6;

/// Regions up to this size use the dense eigensolver.
const DENSE_UP_TO: usize = 300;

/// One split considered.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SplitRecord {
    /// The pass (normal continuity or intensity).
    pub pass: Pass,
    /// Nodes in the region.
    pub nodes: usize,
    /// Nodes on the smaller side.
    pub smaller_side: usize,
    /// Ncut (eq. 2.1).
    pub ncut: f64,
    /// NWAcut (eq. 2.6).
    pub nwacut: f64,
    /// Whether it was made.
    pub accepted: bool,
    /// Why: "disconnected", "below T_cut", "Ncut above T_cut",
    /// "NWAcut above T_cut", "eigensolver did not converge".
    pub reason: String,
}

/// A region's local graph: members (graph node ids) and, per member, its
/// edges inside the region as (local index, w = S·P, P).
struct Region {
    members: Vec<u32>,
    edges: Vec<Vec<(u32, f64, f64)>>,
}

impl Region {
    fn new(graph: &Graph, members: Vec<u32>, pass: Pass, local: &mut [u32]) -> Region {
        for (k, &m) in members.iter().enumerate() {
            local[m as usize] = k as u32;
        }
        let edges = members
            .iter()
            .map(|&m| {
                graph
                    .edges(m as usize)
                    .filter_map(|(j, e)| {
                        let l = local[j];
                        (l != u32::MAX).then(|| {
                            let p = graph.proximity[e];
                            (l, graph.edge_similarity(e, pass) * p, p)
                        })
                    })
                    .collect()
            })
            .collect();
        for &m in &members {
            local[m as usize] = u32::MAX;
        }
        Region { members, edges }
    }

    fn len(&self) -> usize {
        self.members.len()
    }

    fn degree(&self, i: usize) -> f64 {
        self.edges[i].iter().map(|e| e.1).sum()
    }

    /// Connected components over edges heavier than [`NO_EDGE`].
    fn components(&self) -> Vec<Vec<u32>> {
        let n = self.len();
        let mut component = vec![u32::MAX; n];
        let mut out = Vec::new();
        for seed in 0..n {
            if component[seed] != u32::MAX {
                continue;
            }
            let id = out.len() as u32;
            let mut stack = vec![seed];
            component[seed] = id;
            let mut members = Vec::new();
            while let Some(i) = stack.pop() {
                members.push(self.members[i]);
                for &(j, w, _) in &self.edges[i] {
                    if w > NO_EDGE && component[j as usize] == u32::MAX {
                        component[j as usize] = id;
                        stack.push(j as usize);
                    }
                }
            }
            out.push(members);
        }
        out
    }
}

/// The operator I + D^-½ W D^-½ − 2uuᵀ (see the module's doc).
#[derive(Debug)]
struct DeflatedOperator<'a> {
    offsets: &'a [usize],
    targets: &'a [u32],
    weights: &'a [f64],
    inv_sqrt_degree: &'a [f64],
    trivial: &'a [f64],
}

impl LinOp<f64> for DeflatedOperator<'_> {
    fn apply_scratch(&self, _rhs_ncols: usize, _par: Par) -> faer::dyn_stack::StackReq {
        faer::dyn_stack::StackReq::EMPTY
    }

    fn nrows(&self) -> usize {
        self.inv_sqrt_degree.len()
    }

    fn ncols(&self) -> usize {
        self.inv_sqrt_degree.len()
    }

    fn apply(&self, mut out: MatMut<'_, f64>, rhs: MatRef<'_, f64>, _par: Par, _stack: &mut MemStack) {
        use rayon::prelude::*;
        let n = self.nrows();
        for k in 0..rhs.ncols() {
            let x: Vec<f64> = (0..n).map(|i| rhs[(i, k)]).collect();
            let ux: f64 = self.trivial.iter().zip(&x).map(|(u, x)| u * x).sum();
            let row = |i: usize| {
                let s: f64 = (self.offsets[i]..self.offsets[i + 1])
                    .map(|e| {
                        let j = self.targets[e] as usize;
                        self.weights[e] * self.inv_sqrt_degree[j] * x[j]
                    })
                    .sum();
                x[i] + self.inv_sqrt_degree[i] * s - 2.0 * self.trivial[i] * ux
            };
            // Large regions' products in parallel (they are the sequential
            // top of the recursion).
            let y: Vec<f64> = if n >= PARALLEL_FROM {
                (0..n).into_par_iter().with_min_len(4096).map(row).collect()
            } else {
                (0..n).map(row).collect()
            };
            for (i, v) in y.into_iter().enumerate() {
                out[(i, k)] = v;
            }
        }
    }

    fn conj_apply(&self, out: MatMut<'_, f64>, rhs: MatRef<'_, f64>, par: Par, stack: &mut MemStack) {
        self.apply(out, rhs, par, stack);
    }
}

/// The Fiedler vector y of eq. 2.2 for a connected region with positive
/// degrees, or `None` when the solver does not converge.
fn fiedler(region: &Region) -> Option<Vec<f64>> {
    let n = region.len();
    let degree: Vec<f64> = (0..n).map(|i| region.degree(i)).collect();
    let inv_sqrt_degree: Vec<f64> = degree.iter().map(|d| 1.0 / d.sqrt()).collect();
    let volume: f64 = degree.iter().sum();
    let trivial: Vec<f64> = degree.iter().map(|d| (d / volume).sqrt()).collect();
    let z: Vec<f64> = if n <= DENSE_UP_TO {
        let mut m = DMatrix::<f64>::zeros(n, n);
        for i in 0..n {
            for &(j, w, _) in &region.edges[i] {
                m[(i, j as usize)] += inv_sqrt_degree[i] * w * inv_sqrt_degree[j as usize];
            }
        }
        let eigen = m.symmetric_eigen();
        // The second-largest eigenvalue of D^-½ W D^-½.
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by(|&a, &b| eigen.eigenvalues[b].total_cmp(&eigen.eigenvalues[a]));
        eigen.eigenvectors.column(*order.get(1)?).iter().copied().collect()
    } else {
        let mut offsets = Vec::with_capacity(n + 1);
        let mut targets = Vec::new();
        let mut weights = Vec::new();
        offsets.push(0);
        for edges in &region.edges {
            for &(j, w, _) in edges {
                targets.push(j);
                weights.push(w);
            }
            offsets.push(targets.len());
        }
        let op = DeflatedOperator {
            offsets: &offsets,
            targets: &targets,
            weights: &weights,
            inv_sqrt_degree: &inv_sqrt_degree,
            trivial: &trivial,
        };
        let params = PartialEigenParams {
            max_restarts: 400,
            ..Default::default()
        };
        let mut memory = MemBuffer::new(partial_self_adjoint_eigen_scratch(&op, 1, Par::Seq, params));
        let mut vectors = Mat::<f64>::zeros(n, 1);
        let mut values = [0.0];
        // A fixed, deterministic start (a hash of the index).
        let mut v0 = Col::<f64>::from_fn(n, |i| ((i as f64 * 12.9898).sin() * 43_758.545_3).fract() - 0.5);
        let norm = v0.norm_l2();
        v0 /= norm;
        let info = partial_self_adjoint_eigen(
            vectors.as_mut(),
            &mut values,
            &op,
            v0.as_ref(),
            TOLERANCE,
            Par::Seq,
            MemStack::new(&mut memory),
            params,
        );
        if info.n_converged_eigen < 1 {
            return None;
        }
        (0..n).map(|i| vectors[(i, 0)]).collect()
    };
    let y: Vec<f64> = z.iter().zip(&inv_sqrt_degree).map(|(z, s)| z * s).collect();
    y.iter().all(|v| v.is_finite()).then_some(y)
}

/// A candidate split of a region along an order of its nodes: the first
/// `k` nodes form A.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Cut {
    pub k: usize,
    pub ncut: f64,
    pub nwacut: f64,
}

/// Ncut and NWAcut of every cut of `order` (eqs. 2.1, 2.6); returns the
/// least-Ncut cut among those with NWAcut below `t_cut`, and the least-Ncut
/// cut overall. `edges[i]` lists (j, w, P) for local indices.
pub(crate) fn scan_cuts(order: &[usize], edges: &[Vec<(u32, f64, f64)>], t_cut: f64) -> (Option<Cut>, Option<Cut>) {
    let n = order.len();
    let mut in_a = vec![false; n];
    let degree: Vec<f64> = edges.iter().map(|e| e.iter().map(|x| x.1).sum()).collect();
    let volume: f64 = degree.iter().sum();
    // Internal sums of S·P and P, over ordered pairs (both directions).
    let (mut b_sp, mut b_p) = (0.0, 0.0);
    for e in edges {
        for &(_, w, p) in e {
            b_sp += w;
            b_p += p;
        }
    }
    let (mut a_sp, mut a_p) = (0.0, 0.0);
    let (mut cut_sp, mut cut_p) = (0.0, 0.0);
    let mut vol_a = 0.0;
    let mut best_passing: Option<Cut> = None;
    let mut best_any: Option<Cut> = None;
    for (k, &i) in order.iter().enumerate().take(n.saturating_sub(1)) {
        let (mut to_a_sp, mut to_a_p, mut to_b_sp, mut to_b_p) = (0.0, 0.0, 0.0, 0.0);
        for &(j, w, p) in &edges[i] {
            if in_a[j as usize] {
                to_a_sp += w;
                to_a_p += p;
            } else {
                to_b_sp += w;
                to_b_p += p;
            }
        }
        in_a[i] = true;
        vol_a += degree[i];
        a_sp += 2.0 * to_a_sp;
        a_p += 2.0 * to_a_p;
        b_sp -= 2.0 * to_b_sp;
        b_p -= 2.0 * to_b_p;
        cut_sp += to_b_sp - to_a_sp;
        cut_p += to_b_p - to_a_p;
        let vol_b = volume - vol_a;
        if vol_a <= 0.0 || vol_b <= 0.0 {
            continue;
        }
        let cut = cut_sp.max(0.0);
        let ncut = cut / vol_a + cut / vol_b;
        let wa_cut = if cut_p > 0.0 { cut / cut_p } else { 0.0 };
        let wa_asso = |sp: f64, p: f64| if p > 0.0 { sp / p } else { 1.0 };
        let nwacut = (wa_cut / wa_asso(a_sp, a_p)).min(wa_cut / wa_asso(b_sp, b_p));
        let candidate = Cut { k: k + 1, ncut, nwacut };
        if best_any.is_none_or(|b| ncut < b.ncut) {
            best_any = Some(candidate);
        }
        if nwacut < t_cut && ncut < t_cut && best_passing.is_none_or(|b| ncut < b.ncut) {
            best_passing = Some(candidate);
        }
    }
    (best_passing, best_any)
}

/// Settings for one recursive segmentation.
#[derive(Debug, Clone, Copy)]
pub struct Recursion {
    /// Normal continuity or intensity.
    pub pass: Pass,
    /// T_cut.
    pub t_cut: f64,
    /// Regions with fewer nodes are not split.
    pub min_region_nodes: usize,
    /// Run boundary improvement after each accepted split.
    pub boundary_voting: bool,
}

/// Recursively bipartitions `members` (§2.3.3); returns the groups (node
/// ids) and appends every split considered to `records`.
pub fn segment_region(
    graph: &Graph,
    members: Vec<u32>,
    settings: Recursion,
    records: &Mutex<Vec<SplitRecord>>,
) -> Vec<Vec<u32>> {
    let mut local = vec![u32::MAX; graph.nodes.len()];
    let region = Region::new(graph, members, settings.pass, &mut local);
    drop(local);
    let record = |r: SplitRecord| {
        if let Ok(mut v) = records.lock() {
            v.push(r);
        }
    };
    let mut components = region.components();
    if components.len() > 1 {
        components.sort_by_key(Vec::len);
        record(SplitRecord {
            pass: settings.pass,
            nodes: region.len(),
            smaller_side: components[0].len(),
            ncut: 0.0,
            nwacut: 0.0,
            accepted: true,
            reason: format!("disconnected ({} components)", components.len()),
        });
        drop(region);
        return recurse_all(graph, components, settings, records);
    }
    if region.len() < settings.min_region_nodes.max(2) {
        return vec![region.members];
    }
    let Some(y) = fiedler(&region) else {
        record(SplitRecord {
            pass: settings.pass,
            nodes: region.len(),
            smaller_side: 0,
            ncut: f64::NAN,
            nwacut: f64::NAN,
            accepted: false,
            reason: "eigensolver did not converge".into(),
        });
        return vec![region.members];
    };
    let mut order: Vec<usize> = (0..region.len()).collect();
    order.sort_by(|&a, &b| y[a].total_cmp(&y[b]).then(a.cmp(&b)));
    let (passing, any) = scan_cuts(&order, &region.edges, settings.t_cut);
    let Some(cut) = passing else {
        if let Some(c) = any {
            record(SplitRecord {
                pass: settings.pass,
                nodes: region.len(),
                smaller_side: c.k.min(region.len() - c.k),
                ncut: c.ncut,
                nwacut: c.nwacut,
                accepted: false,
                reason: if c.ncut >= settings.t_cut {
                    "Ncut above T_cut"
                } else {
                    "NWAcut above T_cut"
                }
                .into(),
            });
        }
        return vec![region.members];
    };
    record(SplitRecord {
        pass: settings.pass,
        nodes: region.len(),
        smaller_side: cut.k.min(region.len() - cut.k),
        ncut: cut.ncut,
        nwacut: cut.nwacut,
        accepted: true,
        reason: "below T_cut".into(),
    });
    let mut side_a = vec![false; region.len()];
    for &i in &order[..cut.k] {
        side_a[i] = true;
    }
    if settings.boundary_voting {
        boundary::improve(
            graph,
            &region.members,
            &region.edges,
            &y,
            &mut side_a,
            settings.pass,
            settings.t_cut,
        );
    }
    let (a, b): (Vec<u32>, Vec<u32>) = {
        let mut a = Vec::new();
        let mut b = Vec::new();
        for (i, &m) in region.members.iter().enumerate() {
            if side_a[i] { a.push(m) } else { b.push(m) }
        }
        (a, b)
    };
    drop(region);
    if a.is_empty() || b.is_empty() {
        return vec![a, b].into_iter().filter(|v| !v.is_empty()).collect();
    }
    recurse_all(graph, vec![a, b], settings, records)
}

fn recurse_all(
    graph: &Graph,
    parts: Vec<Vec<u32>>,
    settings: Recursion,
    records: &Mutex<Vec<SplitRecord>>,
) -> Vec<Vec<u32>> {
    use rayon::prelude::*;
    parts
        .into_par_iter()
        .flat_map_iter(|part| segment_region(graph, part, settings, records))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two cliques of `m` nodes (weight 1 inside) joined by one edge of
    /// weight `bridge`; P = 1 everywhere.
    fn two_cliques(m: usize, bridge: f64) -> Vec<Vec<(u32, f64, f64)>> {
        let n = 2 * m;
        let mut edges: Vec<Vec<(u32, f64, f64)>> = (0..n)
            .map(|i| {
                (0..n)
                    .filter(|&j| i != j && (i < m) == (j < m))
                    .map(|j| (j as u32, 1.0, 1.0))
                    .collect()
            })
            .collect();
        edges[m - 1].push((m as u32, bridge, 1.0));
        edges[m].push(((m - 1) as u32, bridge, 1.0));
        edges
    }

    #[test]
    fn ncut_and_nwacut_of_two_cliques_match_the_formulas() {
        let m = 5;
        let edges = two_cliques(m, 0.1);
        let order: Vec<usize> = (0..2 * m).collect();
        let (passing, any) = scan_cuts(&order, &edges, 0.2);
        let cut = passing.expect("the bridge passes");
        assert_eq!(cut.k, m);
        // asso(A, V) = 5·4 + 0.1 = 20.1; Ncut = 2 × 0.1 / 20.1.
        assert!((cut.ncut - 0.2 / 20.1).abs() < 1e-12, "{}", cut.ncut);
        // WAcut = 0.1 / 1; WAasso = 1: NWAcut = 0.1.
        assert!((cut.nwacut - 0.1).abs() < 1e-12, "{}", cut.nwacut);
        assert_eq!(any.unwrap().k, m);
        // A strong bridge (S = 0.5) makes NWAcut 0.5: refused at T_cut 0.2.
        let edges = two_cliques(m, 0.5);
        let (passing, _) = scan_cuts(&order, &edges, 0.2);
        assert!(passing.is_none());
    }

    #[test]
    fn the_fiedler_vector_separates_two_cliques_dense_and_sparse() {
        for m in [20, 200] {
            let edges = two_cliques(m, 0.01);
            let region = Region {
                members: (0..2 * m as u32).collect(),
                edges,
            };
            let y = fiedler(&region).expect("converges");
            // Constant sign on each clique, opposite between them.
            let a = y[0].signum();
            assert!(y[..m].iter().all(|v| v.signum() == a), "m = {m}");
            assert!(y[m..].iter().all(|v| v.signum() == -a), "m = {m}");
        }
    }
}

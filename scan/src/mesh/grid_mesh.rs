//! A group's mesh from an organised scan's rows and columns: thesis §2.4's
//! second method, "nearest neighbor connections" between direct neighbours
//! of the range image that both belong to the group.
//!
//! Each grid quad whose four corners are returns of the group gives two
//! triangles (split along the shorter diagonal); a quad with three gives
//! one. An edge across a depth jump is refused: an edge between returns
//! `a` and `b` is kept when `|a − b| ≤ k · min(r_a, r_b) · Δφ`, where `r`
//! is the range from the scanner, `Δφ` the grid's angular step (the median
//! angle between neighbouring beams) and `k` the depth-jump factor. A
//! surface seen at incidence θ spaces neighbours `r Δφ / cos θ` apart, so
//! `k = 8` keeps surfaces up to about 83° from face-on and cuts the edges
//! that jump from a foreground object to the wall behind it. Without a
//! scanner pose, `min(r_a, r_b) · Δφ` is replaced by the median distance
//! between neighbouring returns.

use nalgebra::Vector3;

use crate::cloud::{RangeGrid, Scan};

use super::triangle_mesh::TriangleMesh;

/// What an edge between neighbouring returns may span, for one scan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridStep {
    /// The scanner's centre, when the scan has a pose.
    pub origin: Option<Vector3<f64>>,
    /// With an origin: the median angle between neighbouring beams,
    /// radians. Without: the median distance between neighbouring
    /// returns, metres.
    pub step: f64,
}

impl GridStep {
    /// The step of `scan`'s grid (over its horizontal and vertical
    /// neighbours), or `None` for an unorganised scan or one with no two
    /// neighbouring returns.
    pub fn of(scan: &Scan) -> Option<GridStep> {
        let grid = scan.grid.as_ref()?;
        let origin = scan.pose.map(|p| p.origin);
        let mut steps = Vec::new();
        for (a, b) in neighbour_pairs(grid) {
            let (pa, pb) = (scan.positions[a], scan.positions[b]);
            steps.push(match origin {
                Some(o) => (pa - o).angle(&(pb - o)),
                None => (pa - pb).norm(),
            });
        }
        steps.retain(|s| s.is_finite() && *s > 0.0);
        if steps.is_empty() {
            return None;
        }
        let middle = steps.len() / 2;
        let step = *steps.select_nth_unstable_by(middle, f64::total_cmp).1;
        Some(GridStep { origin, step })
    }

    /// The longest edge allowed between returns at `a` and `b`.
    fn limit(&self, a: &Vector3<f64>, b: &Vector3<f64>, factor: f64) -> f64 {
        match self.origin {
            Some(o) => factor * (a - o).norm().min((b - o).norm()) * self.step,
            None => factor * self.step,
        }
    }
}

/// The rows and columns (inclusive) a group's returns span in one grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GridWindow {
    /// First and last row.
    pub rows: (usize, usize),
    /// First and last column.
    pub cols: (usize, usize),
}

impl GridWindow {
    /// The whole grid.
    pub fn whole(grid: &RangeGrid) -> GridWindow {
        GridWindow {
            rows: (0, grid.rows.saturating_sub(1)),
            cols: (0, grid.cols.saturating_sub(1)),
        }
    }

    /// Each of `groups` groups' window in `grid` (`None` for a group with
    /// no return there), in one pass over the grid.
    pub fn of_groups(grid: &RangeGrid, labels: &[u32], groups: usize) -> Vec<Option<GridWindow>> {
        let mut windows: Vec<Option<GridWindow>> = vec![None; groups];
        for r in 0..grid.rows {
            for c in 0..grid.cols {
                let Some(g) = grid.point_at(r, c).and_then(|p| labels.get(p)) else {
                    continue;
                };
                if let Some(w) = windows.get_mut(*g as usize) {
                    let n = w.get_or_insert(GridWindow {
                        rows: (r, r),
                        cols: (c, c),
                    });
                    n.rows = (n.rows.0.min(r), n.rows.1.max(r));
                    n.cols = (n.cols.0.min(c), n.cols.1.max(c));
                }
            }
        }
        windows
    }
}

/// Horizontal and vertical neighbour pairs of returns.
fn neighbour_pairs(grid: &RangeGrid) -> impl Iterator<Item = (usize, usize)> + '_ {
    (0..grid.rows).flat_map(move |r| {
        (0..grid.cols).flat_map(move |c| {
            let here = grid.point_at(r, c);
            [grid.point_at(r, c + 1), grid.point_at(r + 1, c)]
                .into_iter()
                .filter_map(move |n| Some((here?, n?)))
        })
    })
}

/// The mesh of `group`'s returns in `scan` (`labels[point]` is a point's
/// group) within `window`, facing `viewpoint`; empty for an unorganised
/// scan.
pub fn grid_mesh(
    scan: &Scan,
    labels: &[u32],
    group: u32,
    window: &GridWindow,
    step: &GridStep,
    depth_jump_factor: f64,
    viewpoint: &Vector3<f64>,
) -> TriangleMesh {
    let Some(grid) = &scan.grid else {
        return TriangleMesh::default();
    };
    let member = |r: usize, c: usize| grid.point_at(r, c).filter(|&p| labels.get(p) == Some(&group));
    let p = |i: usize| scan.positions[i];
    let joined = |a: usize, b: usize| (p(a) - p(b)).norm() <= step.limit(&p(a), &p(b), depth_jump_factor);
    let mut triangles = Vec::new();
    let mut add = |t: [usize; 3]| {
        if joined(t[0], t[1]) && joined(t[1], t[2]) && joined(t[2], t[0]) {
            triangles.push(t.map(|i| i as u32));
        }
    };
    for r in window.rows.0..window.rows.1.min(grid.rows.saturating_sub(1)) {
        for c in window.cols.0..window.cols.1.min(grid.cols.saturating_sub(1)) {
            let corners = [member(r, c), member(r, c + 1), member(r + 1, c), member(r + 1, c + 1)];
            match corners {
                [Some(a), Some(b), Some(d), Some(e)] => {
                    if (p(a) - p(e)).norm() <= (p(b) - p(d)).norm() {
                        add([a, d, e]);
                        add([a, e, b]);
                    } else {
                        add([a, d, b]);
                        add([b, d, e]);
                    }
                }
                _ => {
                    let present: Vec<usize> = corners.into_iter().flatten().collect();
                    if let [a, b, d] = present[..] {
                        add([a, b, d]);
                    }
                }
            }
        }
    }
    let mut mesh = TriangleMesh::gathered(&scan.positions, &triangles);
    mesh.face_towards(viewpoint);
    mesh
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cloud::{NO_RETURN, ScannerPose};
    use nalgebra::Rotation3;

    /// A scanner at the origin looking along +x: beams every 1° in azimuth
    /// and elevation over ±10°, hitting the wall x = 3 where `near` is
    /// false and a board at x = 1 where it is true.
    fn wall_and_board(near: impl Fn(i32, i32) -> bool) -> Scan {
        let step = 1f64.to_radians();
        let mut positions = Vec::new();
        let mut cells = Vec::new();
        for row in -10..=10 {
            for col in -10..=10 {
                let (el, az) = (row as f64 * step, col as f64 * step);
                let dir = Vector3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin());
                let depth = if near(row, col) { 1.0 } else { 3.0 };
                if row == 10 && col == 10 {
                    cells.push(NO_RETURN);
                    continue;
                }
                cells.push(positions.len() as u32);
                positions.push(dir * (depth / dir.x));
            }
        }
        let mut scan = Scan::from_positions("wall", positions);
        scan.pose = Some(ScannerPose {
            origin: Vector3::zeros(),
            rotation: Rotation3::identity(),
        });
        scan.grid = Some(RangeGrid {
            rows: 21,
            cols: 21,
            cells,
        });
        scan
    }

    #[test]
    fn a_grid_meshes_to_two_triangles_a_quad_and_refuses_depth_jumps() {
        let scan = wall_and_board(|_, _| false);
        let step = GridStep::of(&scan).unwrap();
        assert!(
            (step.step - 1f64.to_radians()).abs() < 1e-3 * step.step,
            "{}",
            step.step
        );
        let labels = vec![0; scan.len()];
        let whole = GridWindow::whole(scan.grid.as_ref().unwrap());
        let mesh = grid_mesh(&scan, &labels, 0, &whole, &step, 8.0, &Vector3::zeros());
        // 20 × 20 quads, less one triangle at the missing corner.
        assert_eq!(mesh.triangles.len(), 799);
        assert!((0..mesh.triangles.len()).all(|t| mesh.area_normal(t).x < 0.0));

        // The board in front, labelled with the wall (a segmentation that
        // missed it): no triangle joins board and wall across the 2 m jump.
        let scan = wall_and_board(|r, c| (-3..=3).contains(&r) && (-3..=3).contains(&c));
        let mesh = grid_mesh(&scan, &labels, 0, &whole, &step, 8.0, &Vector3::zeros());
        for t in 0..mesh.triangles.len() {
            let xs = mesh.corners(t).map(|p| p.x);
            assert!(xs.iter().all(|&x| (x - 1.0).abs() < 1e-9) || xs.iter().all(|&x| (x - 3.0).abs() < 1e-9));
        }
        // The board's 6 × 6 quads (72 triangles); the wall's 20 × 20 quads
        // less the 8 × 8 that touch the board, less one triangle at the
        // missing corner; and in each of the 4 quads with one board corner,
        // the wall's triangle (the short diagonal runs between wall returns).
        assert_eq!(mesh.triangles.len(), 72 + 2 * (400 - 64) - 1 + 4);
        // Only the wall's group: the board's returns labelled 1 are left out.
        let labels: Vec<u32> = (0..scan.len())
            .map(|i| u32::from((scan.positions[i].x - 1.0).abs() < 1e-9))
            .collect();
        let windows = GridWindow::of_groups(scan.grid.as_ref().unwrap(), &labels, 2);
        // The board's returns: rows and columns −3..=3 of −10..=10.
        let board = GridWindow {
            rows: (7, 13),
            cols: (7, 13),
        };
        assert_eq!(windows, vec![Some(whole), Some(board)]);
        let wall = grid_mesh(&scan, &labels, 0, &whole, &step, 8.0, &Vector3::zeros());
        let board_mesh = grid_mesh(&scan, &labels, 1, &board, &step, 8.0, &Vector3::zeros());
        assert_eq!(board_mesh.triangles.len(), 72);
        assert_eq!(wall.triangles.len(), 2 * (400 - 64) - 1 + 4);
    }
}

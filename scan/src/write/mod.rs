//! Writing scans: the PLY and E57 files that the simulator hands out and
//! that the readers' round-trip tests read back.
//!
//! - [`ply`]: one scan as PLY (binary by default), with normals,
//!   intensity, colour, the grid as `row`/`col` properties, and the pose.
//! - [`e57`]: several scans in one E57 file, each with its pose, intensity,
//!   colour and grid.

pub mod e57;
pub mod ply;

use std::path::PathBuf;

/// Why a scan could not be written.
#[derive(Debug, thiserror::Error)]
pub enum WriteError {
    /// The file could not be created or written.
    #[error("{path}: {message}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The system's or library's message.
        message: String,
    },
    /// The scan cannot be written as asked.
    #[error("{path}: scan {scan:?}: {problem}")]
    Scan {
        /// The file.
        path: PathBuf,
        /// The scan's name.
        scan: String,
        /// What is wrong.
        problem: String,
    },
}

/// Checks `scan` for writing to `path`, and gives each point's (row,
/// column) in its grid when it has one. Every point of an organised scan
/// must be in a cell (both formats store a cell per point).
pub(crate) fn checked_cells(
    path: &std::path::Path,
    scan: &crate::cloud::Scan,
) -> Result<Option<Vec<(u32, u32)>>, WriteError> {
    let problem = |problem: String| WriteError::Scan {
        path: path.to_path_buf(),
        scan: scan.name.clone(),
        problem,
    };
    scan.check().map_err(|e| problem(e.to_string()))?;
    let Some(grid) = scan.grid.as_ref() else {
        return Ok(None);
    };
    let mut cells = vec![(u32::MAX, u32::MAX); scan.len()];
    for (cell, &p) in grid.cells.iter().enumerate() {
        if let Some(c) = cells.get_mut(p as usize) {
            *c = ((cell / grid.cols) as u32, (cell % grid.cols) as u32);
        }
    }
    match cells.iter().position(|&(r, _)| r == u32::MAX) {
        Some(p) => Err(problem(format!(
            "point {p} is in no grid cell (the file keeps a cell for every point)"
        ))),
        None => Ok(Some(cells)),
    }
}

/// An organised 3 × 4 scan with every attribute, a posed scanner and one
/// cell without a return: the writers' round trips.
#[cfg(test)]
pub(crate) fn test_scan() -> crate::cloud::Scan {
    use crate::cloud::{NO_RETURN, RangeGrid, Scan, ScannerPose};
    use nalgebra::{Rotation3, Vector3};
    let mut positions = Vec::new();
    let mut cells = Vec::new();
    for r in 0..3 {
        for c in 0..4 {
            if (r, c) == (1, 2) {
                cells.push(NO_RETURN);
                continue;
            }
            cells.push(positions.len() as u32);
            positions.push(Vector3::new(
                1.0 + 0.25 * c as f64,
                -2.0 + 0.5 * r as f64,
                3.0 + 0.125 * (r * c) as f64,
            ));
        }
    }
    let n = positions.len();
    let mut scan = Scan::from_positions("test-scan", positions);
    scan.normals = Some(
        (0..n)
            .map(|i| Vector3::new(0.6, 0.0, 0.8 * if i % 2 == 0 { 1.0 } else { -1.0 }))
            .collect(),
    );
    scan.intensity = Some((0..n).map(|i| i as f32 / 16.0).collect());
    scan.colour = Some((0..n).map(|i| [i as f32 / 255.0, 0.5, 1.0]).collect());
    scan.grid = Some(RangeGrid {
        rows: 3,
        cols: 4,
        cells,
    });
    scan.pose = Some(ScannerPose {
        origin: Vector3::new(0.5, -1.5, 1.25),
        rotation: Rotation3::from_euler_angles(0.1, -0.2, 0.7),
    });
    scan
}

/// `a` and `b` agree: positions within `tol` m, attributes within `tol`
/// (colour within half a step of 1/255), the same grid and pose.
#[cfg(test)]
pub(crate) fn assert_same_scan(a: &crate::cloud::Scan, b: &crate::cloud::Scan, tol: f64) {
    assert_eq!(a.len(), b.len());
    for (p, q) in a.positions.iter().zip(&b.positions) {
        assert!((p - q).norm() < tol, "{p} vs {q}");
    }
    match (&a.normals, &b.normals) {
        (Some(x), Some(y)) => x
            .iter()
            .zip(y)
            .for_each(|(p, q)| assert!((p - q).norm() < 1e-6, "{p} vs {q}")),
        (None, None) => {}
        _ => panic!("normals differ in presence"),
    }
    match (&a.intensity, &b.intensity) {
        (Some(x), Some(y)) => x
            .iter()
            .zip(y)
            .for_each(|(p, q)| assert!((p - q).abs() < 1e-6, "{p} vs {q}")),
        (None, None) => {}
        _ => panic!("intensity differs in presence"),
    }
    match (&a.colour, &b.colour) {
        (Some(x), Some(y)) => x.iter().zip(y).for_each(|(p, q)| {
            (0..3).for_each(|k| assert!((p[k] - q[k]).abs() <= 0.5 / 255.0 + 1e-6, "{p:?} vs {q:?}"))
        }),
        (None, None) => {}
        _ => panic!("colour differs in presence"),
    }
    assert_eq!(a.grid, b.grid);
    match (&a.pose, &b.pose) {
        (Some(p), Some(q)) => {
            assert!((p.origin - q.origin).norm() < 1e-12);
            assert!(p.rotation.angle_to(&q.rotation) < 1e-9);
        }
        (None, None) => {}
        _ => panic!("pose differs in presence"),
    }
}

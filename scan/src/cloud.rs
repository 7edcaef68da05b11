//! One scan as data: points in the scene frame, and what the scanner knew
//! about them.
//!
//! A scan is either **organised** (a range image: the scanner's rows and
//! columns, which give every point its neighbours for free, thesis §2.4's
//! second meshing method) or **unorganised** (a cloud with no order). Both are
//! a [`Scan`]; an organised scan also has a [`RangeGrid`].

use nalgebra::{Rotation3, Vector3};

/// A grid cell with no return (the beam hit nothing, or the return was
/// dropped).
pub const NO_RETURN: u32 = u32::MAX;

/// What is wrong with a scan's data.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ScanError {
    /// A per-point attribute has a different length from the positions.
    #[error("scan {scan:?}: {attribute} has {found} values but the scan has {points} points")]
    AttributeLength {
        /// The scan's name.
        scan: String,
        /// Which attribute (`normals`, `intensity`, `colour`).
        attribute: &'static str,
        /// Its length.
        found: usize,
        /// The number of points.
        points: usize,
    },
    /// A coordinate, normal, intensity or colour is NaN or infinite.
    #[error("scan {scan:?}: point {point}'s {attribute} is {value} (expected a finite number)")]
    NotFinite {
        /// The scan's name.
        scan: String,
        /// The point's index.
        point: usize,
        /// Which attribute.
        attribute: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A normal is not of unit length (within 1e-3).
    #[error("scan {scan:?}: point {point}'s normal has length {length} (expected 1 within 1e-3)")]
    NormalLength {
        /// The scan's name.
        scan: String,
        /// The point's index.
        point: usize,
        /// Its length.
        length: f64,
    },
    /// The grid's size does not match its cells.
    #[error("scan {scan:?}: a {rows}×{cols} grid needs {expected} cells, found {found}")]
    GridSize {
        /// The scan's name.
        scan: String,
        /// Rows.
        rows: usize,
        /// Columns.
        cols: usize,
        /// rows × cols.
        expected: usize,
        /// The number of cells given.
        found: usize,
    },
    /// A grid cell points past the points, or two cells point at one point.
    #[error("scan {scan:?}: grid cell (row {row}, column {col}) holds point {point}: {problem}")]
    GridCell {
        /// The scan's name.
        scan: String,
        /// The cell's row.
        row: usize,
        /// The cell's column.
        col: usize,
        /// The point index it holds.
        point: u32,
        /// What is wrong.
        problem: &'static str,
    },
}

/// Where the scanner stood: its centre in the scene frame and the rotation
/// from the scanner's own frame to the scene's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScannerPose {
    /// The scanner's optical centre, scene frame, metres.
    pub origin: Vector3<f64>,
    /// Scanner frame → scene frame.
    pub rotation: Rotation3<f64>,
}

/// An organised scan's rows and columns: `cells[row * cols + col]` is the
/// index of the point that cell measured, or [`NO_RETURN`].
#[derive(Debug, Clone, PartialEq)]
pub struct RangeGrid {
    /// Rows (elevation steps of the beam).
    pub rows: usize,
    /// Columns (azimuth steps).
    pub cols: usize,
    /// Row-major point indices, [`NO_RETURN`] where there is none.
    pub cells: Vec<u32>,
}

impl RangeGrid {
    /// The point measured at (`row`, `col`), if any.
    pub fn point_at(&self, row: usize, col: usize) -> Option<usize> {
        if row >= self.rows || col >= self.cols {
            return None;
        }
        let p = self.cells[row * self.cols + col];
        (p != NO_RETURN).then_some(p as usize)
    }
}

/// One scan: points in the scene frame (already registered), with the
/// attributes the source had.
#[derive(Debug, Clone, PartialEq)]
pub struct Scan {
    /// A name for messages (the file name, or the E57 scan's name).
    pub name: String,
    /// Where the scanner stood, when known (E57 and the simulator give it;
    /// PLY and LAS do not).
    pub pose: Option<ScannerPose>,
    /// Positions, scene frame, metres.
    pub positions: Vec<Vector3<f64>>,
    /// Unit normals, when the source had them.
    pub normals: Option<Vec<Vector3<f64>>>,
    /// Return intensity, scaled to [0, 1] where the source's range is known.
    pub intensity: Option<Vec<f32>>,
    /// Linear RGB in [0, 1], when the source had colour.
    pub colour: Option<Vec<[f32; 3]>>,
    /// The scanner's rows and columns, for an organised scan.
    pub grid: Option<RangeGrid>,
}

impl Scan {
    /// An unorganised scan of `positions` with no attributes.
    pub fn from_positions(name: impl Into<String>, positions: Vec<Vector3<f64>>) -> Scan {
        Scan {
            name: name.into(),
            pose: None,
            positions,
            normals: None,
            intensity: None,
            colour: None,
            grid: None,
        }
    }

    /// The number of points.
    pub fn len(&self) -> usize {
        self.positions.len()
    }

    /// Whether the scan has no points.
    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    /// Checks the scan's invariants: attribute lengths, finite values, unit
    /// normals, and a grid whose cells each hold a distinct point or none.
    /// Readers and the simulator call it before handing a scan out.
    pub fn check(&self) -> Result<(), ScanError> {
        let n = self.positions.len();
        let scan = || self.name.clone();
        let length = |attribute: &'static str, found: usize| {
            if found == n {
                Ok(())
            } else {
                Err(ScanError::AttributeLength {
                    scan: scan(),
                    attribute,
                    found,
                    points: n,
                })
            }
        };
        if let Some(v) = &self.normals {
            length("normals", v.len())?;
        }
        if let Some(v) = &self.intensity {
            length("intensity", v.len())?;
        }
        if let Some(v) = &self.colour {
            length("colour", v.len())?;
        }
        let finite =
            |point: usize, attribute: &'static str, values: &[f64]| match values.iter().find(|v| !v.is_finite()) {
                Some(&value) => Err(ScanError::NotFinite {
                    scan: scan(),
                    point,
                    attribute,
                    value,
                }),
                None => Ok(()),
            };
        for (i, p) in self.positions.iter().enumerate() {
            finite(i, "position", p.as_slice())?;
        }
        if let Some(normals) = &self.normals {
            for (i, v) in normals.iter().enumerate() {
                finite(i, "normal", v.as_slice())?;
                let length = v.norm();
                if (length - 1.0).abs() > 1e-3 {
                    return Err(ScanError::NormalLength {
                        scan: scan(),
                        point: i,
                        length,
                    });
                }
            }
        }
        if let Some(intensity) = &self.intensity {
            for (i, &v) in intensity.iter().enumerate() {
                finite(i, "intensity", &[f64::from(v)])?;
            }
        }
        if let Some(colour) = &self.colour {
            for (i, c) in colour.iter().enumerate() {
                finite(i, "colour", &c.map(f64::from))?;
            }
        }
        if let Some(grid) = &self.grid {
            let expected = grid.rows * grid.cols;
            if grid.cells.len() != expected {
                return Err(ScanError::GridSize {
                    scan: scan(),
                    rows: grid.rows,
                    cols: grid.cols,
                    expected,
                    found: grid.cells.len(),
                });
            }
            let mut seen = vec![false; n];
            for (cell, &point) in grid.cells.iter().enumerate() {
                if point == NO_RETURN {
                    continue;
                }
                let problem = match seen.get_mut(point as usize) {
                    None => Some("past the scan's last point"),
                    Some(true) => Some("already held by another cell"),
                    Some(s) => {
                        *s = true;
                        None
                    }
                };
                if let Some(problem) = problem {
                    return Err(ScanError::GridCell {
                        scan: scan(),
                        row: cell / grid.cols,
                        col: cell % grid.cols,
                        point,
                        problem,
                    });
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> Scan {
        let positions = vec![
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(0.0, 1.0, 0.0),
        ];
        let mut scan = Scan::from_positions("square", positions);
        scan.grid = Some(RangeGrid {
            rows: 2,
            cols: 2,
            cells: vec![0, 1, 2, NO_RETURN],
        });
        scan
    }

    #[test]
    fn a_well_formed_organised_scan_passes_and_finds_its_neighbours() {
        let scan = square();
        assert_eq!(scan.check(), Ok(()));
        let grid = scan.grid.as_ref().unwrap();
        assert_eq!(grid.point_at(1, 0), Some(2));
        assert_eq!(grid.point_at(1, 1), None);
        assert_eq!(grid.point_at(2, 0), None);
    }

    #[test]
    fn bad_scans_are_refused_naming_the_point() {
        let mut scan = square();
        scan.positions[1].y = f64::NAN;
        assert!(matches!(
            scan.check(),
            Err(ScanError::NotFinite {
                point: 1,
                attribute: "position",
                ..
            })
        ));

        let mut scan = square();
        scan.intensity = Some(vec![0.5; 2]);
        assert!(matches!(
            scan.check(),
            Err(ScanError::AttributeLength {
                found: 2,
                points: 3,
                ..
            })
        ));

        let mut scan = square();
        scan.normals = Some(vec![Vector3::z(), Vector3::z(), Vector3::new(0.0, 0.0, 2.0)]);
        assert!(matches!(scan.check(), Err(ScanError::NormalLength { point: 2, .. })));

        let mut scan = square();
        scan.grid.as_mut().unwrap().cells[3] = 1;
        let error = scan.check().unwrap_err();
        assert!(
            matches!(
                error,
                ScanError::GridCell {
                    row: 1,
                    col: 1,
                    point: 1,
                    ..
                }
            ),
            "{error}"
        );

        let mut scan = square();
        scan.grid.as_mut().unwrap().cells[3] = 7;
        assert!(matches!(
            scan.check(),
            Err(ScanError::GridCell {
                problem: "past the scan's last point",
                ..
            })
        ));
    }
}

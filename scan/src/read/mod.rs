//! Reading scans from files: PLY, E57 and LAS/LAZ, one module per format,
//! and [`read_scan`], which picks the format by the file's extension.
//!
//! Every reader hands out [`Scan`]s that passed [`Scan::check`]: positions
//! in the scene frame (E57 poses applied; PLY and LAS are taken as already
//! registered), unit normals, intensity and colour scaled to [0, 1] where
//! the file says how, and the scanner's grid when the file keeps one. A bad
//! or truncated file is a [`ReadError`] naming the file, the element or
//! field, the value found and what was expected; never a panic.
//!
//! - [`ply`]: ascii and binary (both byte orders) PLY.
//! - [`e57`]: every scan of an E57 file, posed, with its grid.
//! - [`las`]: LAS and LAZ.
//! - [`stream`]: several registered scans, one at a time, so that memory
//!   stays bounded (§2.3.2's incremental merge).

pub mod e57;
pub mod las;
pub mod ply;
pub mod stream;

use std::path::{Path, PathBuf};

use crate::cloud::{Scan, ScanError};

/// Why a scan file could not be read.
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    /// The file could not be opened or read.
    #[error("{path}: {message}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The system's message.
        message: String,
    },
    /// The extension names no format we read.
    #[error("{path}: unknown scan format {extension:?} (expected .ply, .e57, .las or .laz)")]
    Extension {
        /// The file.
        path: PathBuf,
        /// Its extension (empty when it has none).
        extension: String,
    },
    /// The file is not what its format requires.
    #[error("{path}: {element} {field}: found {found}, expected {expected}")]
    Malformed {
        /// The file.
        path: PathBuf,
        /// The element, point cloud or section (`header`, `element vertex`,
        /// `point cloud 0`, `point 12`).
        element: String,
        /// The field or property.
        field: String,
        /// What the file holds.
        found: String,
        /// What was expected.
        expected: String,
    },
    /// The format's library refused the file.
    #[error("{path}: not a readable {format} file: {message}")]
    Format {
        /// The file.
        path: PathBuf,
        /// `PLY`, `E57` or `LAS`.
        format: &'static str,
        /// The library's message.
        message: String,
    },
    /// The points read break a scan's invariants (a NaN coordinate, a
    /// normal of the wrong length, two points in one grid cell).
    #[error("{path}: {source}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        source: ScanError,
    },
}

impl ReadError {
    pub(crate) fn io(path: &Path, e: &std::io::Error) -> ReadError {
        ReadError::Io {
            path: path.to_path_buf(),
            message: e.to_string(),
        }
    }

    pub(crate) fn malformed(
        path: &Path,
        element: impl Into<String>,
        field: impl Into<String>,
        found: impl Into<String>,
        expected: impl Into<String>,
    ) -> ReadError {
        ReadError::Malformed {
            path: path.to_path_buf(),
            element: element.into(),
            field: field.into(),
            found: found.into(),
            expected: expected.into(),
        }
    }
}

/// A file's scan format, from its extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Stanford PLY.
    Ply,
    /// ASTM E57.
    E57,
    /// ASPRS LAS, or LAZ (LASzip-compressed LAS).
    Las,
}

impl Format {
    /// The format of `path` by its extension (case-insensitive).
    pub fn of(path: &Path) -> Result<Format, ReadError> {
        let extension = path
            .extension()
            .and_then(|e| e.to_str())
            .unwrap_or("")
            .to_ascii_lowercase();
        match extension.as_str() {
            "ply" => Ok(Format::Ply),
            "e57" => Ok(Format::E57),
            "las" | "laz" => Ok(Format::Las),
            _ => Err(ReadError::Extension {
                path: path.to_path_buf(),
                extension,
            }),
        }
    }
}

/// Every scan in the file at `path`, the format chosen by its extension
/// (`.ply`, `.e57`, `.las`, `.laz`). PLY and LAS files hold one scan; E57
/// files any number. An empty file is an error; a file with a header and
/// no points is an empty scan.
pub fn read_scan(path: &Path) -> Result<Vec<Scan>, ReadError> {
    let format = Format::of(path)?;
    let len = std::fs::metadata(path).map_err(|e| ReadError::io(path, &e))?.len();
    if len == 0 {
        return Err(ReadError::malformed(
            path,
            "file",
            "length",
            "0 bytes",
            "a scan file's header",
        ));
    }
    match format {
        Format::Ply => ply::read(path).map(|s| vec![s]),
        Format::E57 => e57::read(path),
        Format::Las => las::read(path).map(|s| vec![s]),
    }
}

/// `scan` after [`Scan::check`], or the check's error with the file's name.
pub(crate) fn checked(path: &Path, scan: Scan) -> Result<Scan, ReadError> {
    scan.check().map_err(|source| ReadError::Invalid {
        path: path.to_path_buf(),
        source,
    })?;
    Ok(scan)
}

/// The file's stem, for a scan's name.
pub(crate) fn stem(path: &Path) -> String {
    path.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| path.display().to_string())
}

/// The grid of an organised scan from each point's (row, column): rows and
/// columns from 0 to the largest given (at least `min_rows` × `min_cols`).
/// `None` for an empty list.
pub(crate) fn grid_from_indices(
    path: &Path,
    element: &str,
    indices: &[(u32, u32)],
    min_rows: usize,
    min_cols: usize,
) -> Result<crate::cloud::RangeGrid, ReadError> {
    let rows = indices
        .iter()
        .map(|&(r, _)| r as usize + 1)
        .max()
        .unwrap_or(0)
        .max(min_rows);
    let cols = indices
        .iter()
        .map(|&(_, c)| c as usize + 1)
        .max()
        .unwrap_or(0)
        .max(min_cols);
    // A grid far larger than its points is a corrupt index, not a scan:
    // at most 64 cells a point (a scan of mostly sky), plus 2²⁰.
    let max_cells = indices.len().saturating_mul(64).saturating_add(1 << 20).min(1 << 31);
    let cells = rows.checked_mul(cols).filter(|&c| c <= max_cells).ok_or_else(|| {
        ReadError::malformed(
            path,
            element,
            "row/column",
            format!("a {rows}×{cols} grid for {} points", indices.len()),
            format!("at most {max_cells} cells (64 a point, plus 2^20)"),
        )
    })?;
    let mut grid = crate::cloud::RangeGrid {
        rows,
        cols,
        cells: vec![crate::cloud::NO_RETURN; cells],
    };
    for (point, &(r, c)) in indices.iter().enumerate() {
        let cell = &mut grid.cells[r as usize * cols + c as usize];
        if *cell != crate::cloud::NO_RETURN {
            return Err(ReadError::malformed(
                path,
                format!("point {point}"),
                "row/column",
                format!("({r}, {c}), already held by point {cell}"),
                "one point per grid cell",
            ));
        }
        *cell = point as u32;
    }
    Ok(grid)
}

/// A file of `validation/scans/` (real files made by other software).
#[cfg(test)]
pub(crate) fn validation_file(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../validation/scans")
        .join(name)
}

/// The smallest and largest coordinates of `scan`'s points.
#[cfg(test)]
pub(crate) fn bounds(scan: &Scan) -> (nalgebra::Vector3<f64>, nalgebra::Vector3<f64>) {
    use nalgebra::Vector3;
    let lo = scan
        .positions
        .iter()
        .fold(Vector3::repeat(f64::INFINITY), |a, p| a.inf(p));
    let hi = scan
        .positions
        .iter()
        .fold(Vector3::repeat(f64::NEG_INFINITY), |a, p| a.sup(p));
    (lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_format_follows_the_extension_and_an_empty_or_unknown_file_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let empty = dir.path().join("empty.ply");
        std::fs::write(&empty, b"").unwrap();
        let e = read_scan(&empty).unwrap_err();
        assert!(
            matches!(&e, ReadError::Malformed { found, .. } if found == "0 bytes"),
            "{e}"
        );
        assert!(e.to_string().contains("empty.ply"), "{e}");

        let e = read_scan(&dir.path().join("cloud.xyz")).unwrap_err();
        assert!(
            matches!(&e, ReadError::Extension { extension, .. } if extension == "xyz"),
            "{e}"
        );
        assert_eq!(Format::of(Path::new("A.LAZ")).unwrap(), Format::Las);
        assert_eq!(Format::of(Path::new("a.E57")).unwrap(), Format::E57);

        let e = read_scan(&dir.path().join("missing.e57")).unwrap_err();
        assert!(matches!(e, ReadError::Io { .. }), "{e}");
    }

    #[test]
    fn truncations_of_a_binary_ply_and_an_e57_are_errors() {
        // Every 7th length of the PLY (header and payload), every 509th of
        // the E57 (its pages), then the whole file.
        let dir = tempfile::tempdir().unwrap();
        let whole = dir.path().join("whole.ply");
        crate::write::ply::write(&whole, &crate::write::test_scan()).unwrap();
        let e57 = std::fs::read(validation_file("tiny_spherical.e57")).unwrap();
        for (bytes, name, step) in [(std::fs::read(&whole).unwrap(), "cut.ply", 7), (e57, "cut.e57", 509)] {
            let cut = dir.path().join(name);
            for len in (0..bytes.len()).step_by(step) {
                std::fs::write(&cut, &bytes[..len]).unwrap();
                assert!(read_scan(&cut).is_err(), "{name}: {len} of {} bytes read", bytes.len());
            }
            std::fs::write(&cut, &bytes).unwrap();
            assert!(read_scan(&cut).is_ok());
        }
    }
}

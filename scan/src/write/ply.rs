//! One scan as a PLY file through `ply-rs-bw`: positions as `double`,
//! normals `nx ny nz` and `intensity` as `float`, colour as `uchar`
//! `red green blue` (rounded to 1/255), the grid as `int` `row`/`col`,
//! and two comments: `campanile scanner_pose ox oy oz qw qx qy qz` and
//! `campanile grid rows cols`, which [`crate::read::ply`] reads back.

use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

use nalgebra::UnitQuaternion;
use ply_rs_bw::ply::{Addable, ElementDef, Encoding, Ply, PropertyDef, PropertyType, ScalarType};
use ply_rs_bw::writer::Writer;

use super::{WriteError, checked_cells};
use crate::cloud::Scan;
use crate::read::ply::{GRID_COMMENT, POSE_COMMENT, PlyVertex};

/// How the payload is encoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlyEncoding {
    /// Text, one vertex a line.
    Ascii,
    /// Binary, little-endian (the default).
    BinaryLittleEndian,
    /// Binary, big-endian.
    BinaryBigEndian,
}

/// Writes `scan` to `path` as binary little-endian PLY.
pub fn write(path: &Path, scan: &Scan) -> Result<(), WriteError> {
    write_encoded(path, scan, PlyEncoding::BinaryLittleEndian)
}

/// Writes `scan` to `path` as PLY with `encoding`.
pub fn write_encoded(path: &Path, scan: &Scan, encoding: PlyEncoding) -> Result<(), WriteError> {
    let problem = |problem: String| WriteError::Scan {
        path: path.to_path_buf(),
        scan: scan.name.clone(),
        problem,
    };
    let cells = checked_cells(path, scan)?;
    if let Some(g) = &scan.grid
        && (g.rows > i32::MAX as usize || g.cols > i32::MAX as usize)
    {
        return Err(problem(format!(
            "a {}×{} grid does not fit PLY int indices",
            g.rows, g.cols
        )));
    }
    let mut ply = Ply::<PlyVertex>::new();
    ply.header.encoding = match encoding {
        PlyEncoding::Ascii => Encoding::Ascii,
        PlyEncoding::BinaryLittleEndian => Encoding::BinaryLittleEndian,
        PlyEncoding::BinaryBigEndian => Encoding::BinaryBigEndian,
    };
    ply.header.comments.push(format!("scan {}", scan.name));
    if let Some(pose) = &scan.pose {
        let q = UnitQuaternion::from_rotation_matrix(&pose.rotation);
        let o = pose.origin;
        ply.header.comments.push(format!(
            "{POSE_COMMENT} {} {} {} {} {} {} {}",
            o.x, o.y, o.z, q.w, q.i, q.j, q.k
        ));
    }
    if let Some(g) = &scan.grid {
        ply.header
            .comments
            .push(format!("{GRID_COMMENT} {} {}", g.rows, g.cols));
    }
    let mut vertex = ElementDef::new("vertex".into());
    let mut property = |name: &str, t: ScalarType| {
        vertex
            .properties
            .add(PropertyDef::new(name.into(), PropertyType::Scalar(t)))
    };
    for n in ["x", "y", "z"] {
        property(n, ScalarType::Double);
    }
    if scan.normals.is_some() {
        for n in ["nx", "ny", "nz"] {
            property(n, ScalarType::Float);
        }
    }
    if scan.intensity.is_some() {
        property("intensity", ScalarType::Float);
    }
    if scan.colour.is_some() {
        for n in ["red", "green", "blue"] {
            property(n, ScalarType::UChar);
        }
    }
    if cells.is_some() {
        property("row", ScalarType::Int);
        property("col", ScalarType::Int);
    }
    vertex.count = scan.len();
    ply.header.elements.add(vertex);
    let vertices = (0..scan.len())
        .map(|i| {
            let mut v = PlyVertex {
                position: scan.positions[i].into(),
                ..PlyVertex::default()
            };
            if let Some(n) = &scan.normals {
                v.normal = n[i].into();
            }
            if let Some(t) = &scan.intensity {
                v.intensity = t[i];
            }
            if let Some(c) = &scan.colour {
                v.colour_u8 = c[i].map(|x| (x.clamp(0.0, 1.0) * 255.0).round() as u8);
            }
            if let Some(cells) = &cells {
                (v.row, v.col) = (i64::from(cells[i].0), i64::from(cells[i].1));
            }
            v
        })
        .collect();
    ply.payload.insert("vertex".into(), vertices);
    let io = |e: &dyn std::fmt::Display| WriteError::Io {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    let mut out = BufWriter::new(File::create(path).map_err(|e| io(&e))?);
    Writer::new().write_ply(&mut out, &mut ply).map_err(|e| io(&e))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::read::{ReadError, read_scan};
    use crate::write::{assert_same_scan, test_scan};

    #[test]
    fn every_encoding_reads_back_with_its_attributes_grid_and_pose() {
        let dir = tempfile::tempdir().unwrap();
        let scan = test_scan();
        for (encoding, name) in [
            (PlyEncoding::BinaryLittleEndian, "le.ply"),
            (PlyEncoding::BinaryBigEndian, "be.ply"),
            (PlyEncoding::Ascii, "ascii.ply"),
        ] {
            let path = dir.path().join(name);
            write_encoded(&path, &scan, encoding).unwrap();
            let back = read_scan(&path).unwrap();
            assert_eq!(back.len(), 1);
            // Doubles round-trip exactly in binary and through Rust's
            // shortest float printing in ascii.
            assert_same_scan(&scan, &back[0], 1e-12);
            assert_eq!(back[0].grid.as_ref().unwrap().point_at(1, 2), None);
        }
    }

    #[test]
    fn a_truncated_binary_file_is_an_error_naming_the_element() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("cut.ply");
        write(&path, &test_scan()).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        std::fs::write(&path, &bytes[..bytes.len() - 10]).unwrap();
        let e = read_scan(&path).unwrap_err();
        // 10 bytes short: the last vertex (51 bytes) is cut.
        assert!(
            matches!(&e, ReadError::Malformed { field, found, .. } if field == "entry 10 of 11" && found == "the end of the file"),
            "{e}"
        );
        assert!(e.to_string().contains("cut.ply"), "{e}");
    }
}

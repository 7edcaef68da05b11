//! LAS and LAZ scans through the `las` crate (LAZ by its pure-Rust `laz`
//! feature): positions with the header's scale and offset applied,
//! intensity over 65535, colour over 65535 when the point format has it
//! (formats 2, 3, 5, 7, 8, 10). A file with no points is an empty scan.
//! LAS keeps no scanner pose and no grid.

use std::path::Path;

use nalgebra::Vector3;

use super::{ReadError, checked, stem};
use crate::cloud::Scan;

/// Points decoded per batch (bounds the decoder's buffer).
const BATCH: u64 = 1 << 16;

/// The scan in the LAS or LAZ file at `path`.
pub fn read(path: &Path) -> Result<Scan, ReadError> {
    let format_error = |e: &dyn std::fmt::Display| ReadError::Format {
        path: path.to_path_buf(),
        format: "LAS",
        message: e.to_string(),
    };
    let mut reader = ::las::Reader::from_path(path).map_err(|e| format_error(&e))?;
    let header = reader.header();
    let count = header.number_of_points();
    let has_colour = header.point_format().has_color;
    let capacity = usize::try_from(count).unwrap_or(0).min(1 << 24);
    let mut positions = Vec::with_capacity(capacity);
    let mut intensity = Vec::with_capacity(capacity);
    let mut colour = Vec::with_capacity(if has_colour { capacity } else { 0 });
    let mut data = ::las::PointDataBuilder::new().for_header(header).build();
    let mut read = 0;
    while read < count {
        let n = reader
            .fill_points(BATCH.min(count - read), &mut data)
            .map_err(|e| format_error(&e))?;
        if n == 0 {
            return Err(ReadError::malformed(
                path,
                "point data",
                "points",
                read.to_string(),
                format!("{count} (the header's count)"),
            ));
        }
        for p in data.points() {
            let p = p.map_err(|e| format_error(&e))?;
            positions.push(Vector3::new(p.x, p.y, p.z));
            intensity.push(f32::from(p.intensity) / 65535.0);
            if has_colour {
                let c = p.color.unwrap_or_default();
                colour.push([c.red, c.green, c.blue].map(|v| f32::from(v) / 65535.0));
            }
        }
        read += n;
    }
    let mut scan = Scan::from_positions(stem(path), positions);
    scan.intensity = Some(intensity);
    if has_colour {
        scan.colour = Some(colour);
    }
    checked(path, scan)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::read::{bounds, validation_file};

    // laspy's simple.las and simple.laz (validation/scans/README.md): the
    // public header block says 1065 points, point format 3 (with colour),
    // scale 0.01, and the bounds below.
    #[test]
    fn laspy_simple_las_and_laz_read_the_same_points_within_the_header_bounds() {
        let las = read(&validation_file("simple.las")).unwrap();
        let laz = read(&validation_file("simple.laz")).unwrap();
        assert_eq!(las.len(), 1065);
        assert_eq!(laz.len(), 1065);
        let (lo, hi) = bounds(&las);
        // Header min/max: x 635619.85..638982.55, y 848899.70..853535.43,
        // z 406.59..586.38 (to the 0.01 m scale).
        assert!((lo - Vector3::new(635619.85, 848899.70, 406.59)).norm() < 0.006, "{lo}");
        assert!((hi - Vector3::new(638982.55, 853535.43, 586.38)).norm() < 0.006, "{hi}");
        // The LAZ decompresses to the same points and attributes.
        assert_eq!(las.positions, laz.positions);
        assert_eq!(las.intensity, laz.intensity);
        assert_eq!(las.colour, laz.colour);
        assert!(
            las.colour
                .as_ref()
                .unwrap()
                .iter()
                .flatten()
                .all(|c| (0.0..=1.0).contains(c))
        );
        assert!(las.intensity.as_ref().unwrap().iter().all(|t| (0.0..=1.0).contains(t)));
    }

    #[test]
    fn a_las_with_zero_points_is_an_empty_scan_and_a_truncated_one_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("empty.las");
        let writer = ::las::Writer::from_path(&path, ::las::Header::default()).unwrap();
        drop(writer);
        let scan = read(&path).unwrap();
        assert!(scan.is_empty());

        let bytes = std::fs::read(validation_file("simple.las")).unwrap();
        let cut = dir.path().join("cut.las");
        std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
        let e = read(&cut).unwrap_err();
        assert!(e.to_string().contains("cut.las"), "{e}");
    }
}

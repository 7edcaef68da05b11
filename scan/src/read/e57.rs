//! E57 scans through the `e57` crate: every point cloud of the file, each
//! a [`Scan`].
//!
//! - Points go to the file's frame through the scan's pose (the E57
//!   `pose`, scanner frame → file frame), which becomes [`Scan::pose`]. A
//!   scan with no pose but spherical coordinates stands at the origin; a
//!   Cartesian scan with no pose has none.
//! - Spherical and Cartesian coordinates are both read (spherical turned
//!   Cartesian by the crate).
//! - Points whose coordinates are invalid (invalid state 1, a direction
//!   with no range, or 2, no return) are dropped, and their grid cells stay
//!   [`crate::cloud::NO_RETURN`].
//! - Intensity is scaled to [0, 1] by the scan's `intensityLimits` (by the
//!   record type's range when the file gives none); colour likewise by
//!   `colorLimits`. A point whose intensity or colour is flagged invalid
//!   gets 0.
//! - The grid comes from `rowIndex`/`columnIndex`: rows and columns from
//!   `indexBounds`' minimum (or the smallest index present, negative ones
//!   too) to the largest; the grid's row 0 is that minimum.
//! - E57 has no standard normals; none are read.

use std::path::Path;

use ::e57::{CartesianCoordinate, E57Reader, PointCloud};
use nalgebra::{Quaternion, Rotation3, UnitQuaternion, Vector3};

use super::{ReadError, checked, grid_from_indices, stem};
use crate::cloud::{Scan, ScannerPose};

fn format_error(path: &Path, e: &::e57::Error) -> ReadError {
    ReadError::Format {
        path: path.to_path_buf(),
        format: "E57",
        message: e.to_string(),
    }
}

fn open(path: &Path) -> Result<E57Reader<std::io::BufReader<std::fs::File>>, ReadError> {
    E57Reader::from_file(path).map_err(|e| format_error(path, &e))
}

/// Every scan of the E57 file at `path`, in the file's order.
pub fn read(path: &Path) -> Result<Vec<Scan>, ReadError> {
    let mut reader = open(path)?;
    let clouds = reader.pointclouds();
    clouds
        .iter()
        .enumerate()
        .map(|(i, pc)| read_cloud(path, &mut reader, i, pc))
        .collect()
}

/// The number of scans in the E57 file at `path` (reads only its XML).
pub fn scan_count(path: &Path) -> Result<usize, ReadError> {
    Ok(open(path)?.pointclouds().len())
}

/// Scan `index` of the E57 file at `path`, reading no other scan's points.
pub fn read_one(path: &Path, index: usize) -> Result<Scan, ReadError> {
    let mut reader = open(path)?;
    let clouds = reader.pointclouds();
    let pc = clouds.get(index).ok_or_else(|| {
        ReadError::malformed(
            path,
            "data3D",
            "scans",
            clouds.len().to_string(),
            format!("a scan with index {index}"),
        )
    })?;
    read_cloud(path, &mut reader, index, pc)
}

fn pose_of(pc: &PointCloud) -> Option<ScannerPose> {
    match &pc.transform {
        Some(t) => {
            let q = Quaternion::new(t.rotation.w, t.rotation.x, t.rotation.y, t.rotation.z);
            Some(ScannerPose {
                origin: Vector3::new(t.translation.x, t.translation.y, t.translation.z),
                rotation: UnitQuaternion::from_quaternion(q).to_rotation_matrix(),
            })
        }
        None if pc.has_spherical() => Some(ScannerPose {
            origin: Vector3::zeros(),
            rotation: Rotation3::identity(),
        }),
        None => None,
    }
}

fn read_cloud<R: std::io::Read + std::io::Seek>(
    path: &Path,
    reader: &mut E57Reader<R>,
    index: usize,
    pc: &PointCloud,
) -> Result<Scan, ReadError> {
    let element = format!("point cloud {index}");
    if let Some(t) = &pc.transform {
        let q = &t.rotation;
        let v = [q.w, q.x, q.y, q.z, t.translation.x, t.translation.y, t.translation.z];
        if v.iter().any(|c| !c.is_finite()) || Quaternion::new(q.w, q.x, q.y, q.z).norm() < 1e-9 {
            return Err(ReadError::malformed(
                path,
                element,
                "pose",
                format!("{v:?}"),
                "a finite translation and a non-zero rotation quaternion",
            ));
        }
    }
    let name = pc.name.clone().unwrap_or_else(|| format!("{}#{index}", stem(path)));
    let has_intensity = pc.has_intensity();
    let has_colour = pc.has_color();
    let has_grid = pc.has_row_column();
    let mut points = reader.pointcloud_simple(pc).map_err(|e| format_error(path, &e))?;
    points.intensity_to_color(false);
    points.spherical_to_cartesian(true);
    points.apply_pose(true);
    let capacity = usize::try_from(pc.records).unwrap_or(0).min(1 << 24);
    let mut positions = Vec::with_capacity(capacity);
    let mut intensity = Vec::new();
    let mut colour = Vec::new();
    let mut raw_indices = Vec::new();
    for p in points {
        let p = p.map_err(|e| format_error(path, &e))?;
        let CartesianCoordinate::Valid { x, y, z } = p.cartesian else {
            continue;
        };
        positions.push(Vector3::new(x, y, z));
        if has_intensity {
            intensity.push(p.intensity.unwrap_or(0.0));
        }
        if has_colour {
            colour.push(p.color.map_or([0.0; 3], |c| [c.red, c.green, c.blue]));
        }
        if has_grid {
            raw_indices.push((p.row, p.column));
        }
    }
    let mut scan = Scan::from_positions(name, positions);
    scan.pose = pose_of(pc);
    if has_intensity {
        scan.intensity = Some(intensity);
    }
    if has_colour {
        scan.colour = Some(colour);
    }
    if has_grid {
        let bounds = pc.index_bounds.as_ref();
        let row_min = bounds
            .and_then(|b| b.row_min)
            .unwrap_or(i64::MAX)
            .min(raw_indices.iter().map(|&(r, _)| r).min().unwrap_or(0));
        let col_min = bounds
            .and_then(|b| b.column_min)
            .unwrap_or(i64::MAX)
            .min(raw_indices.iter().map(|&(_, c)| c).min().unwrap_or(0));
        let offset = |v: i64, min: i64| v.checked_sub(min).and_then(|d| u32::try_from(d).ok());
        let span = |max: Option<i64>, min: i64| max.and_then(|m| offset(m, min)).map_or(0, |d| d as usize + 1);
        let rows = span(bounds.and_then(|b| b.row_max), row_min);
        let cols = span(bounds.and_then(|b| b.column_max), col_min);
        let mut indices = Vec::with_capacity(raw_indices.len());
        for (i, &(r, c)) in raw_indices.iter().enumerate() {
            let (Some(r), Some(c)) = (offset(r, row_min), offset(c, col_min)) else {
                return Err(ReadError::malformed(
                    path,
                    format!("{element} point {i}"),
                    "rowIndex/columnIndex",
                    format!("({r}, {c}) from the smallest ({row_min}, {col_min})"),
                    "a span that fits 32 bits",
                ));
            };
            indices.push((r, c));
        }
        scan.grid = Some(grid_from_indices(path, &element, &indices, rows, cols)?);
    }
    checked(path, scan)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::read::{bounds, validation_file};

    // The files' own XML (validation/scans/README.md) gives the record
    // counts and bounds asserted here.
    #[test]
    fn cloudcompare_e57_reads_its_points_bounds_and_colour() {
        let scans = read(&validation_file("tinyCartesianFloatRgb.e57")).unwrap();
        assert_eq!(scans.len(), 1);
        let scan = &scans[0];
        // <name>exp2.fls.subsampled</name>, recordCount="2090".
        assert_eq!(scan.name, "exp2.fls.subsampled");
        assert_eq!(scan.len(), 2090);
        // cartesianBounds (single precision in the file).
        let (lo, hi) = bounds(scan);
        let expected_lo = Vector3::new(-9.779_529_571_533_203, 4.513_879_299_163_818, 295.524_688_720_703_1);
        let expected_hi = Vector3::new(-6.774_238_109_588_623, 7.515_460_491_180_42, 298.532_165_527_343_75);
        assert!(
            (lo - expected_lo).norm() < 1e-5 && (hi - expected_hi).norm() < 1e-5,
            "{lo} {hi}"
        );
        // colorLimits 0..255: every channel in [0, 1], and not all black.
        let colour = scan.colour.as_ref().unwrap();
        assert!(colour.iter().flatten().all(|c| (0.0..=1.0).contains(c)));
        assert!(colour.iter().flatten().any(|&c| c > 0.1));
        // No pose in the file and Cartesian points: no scanner pose.
        assert!(scan.pose.is_none() && scan.grid.is_none() && scan.intensity.is_none());
    }

    #[test]
    fn libe57_bunny_reads_its_30571_points() {
        let scans = read(&validation_file("bunnyInt19.e57")).unwrap();
        // <name>bunny</name>, recordCount="30571", 19-bit scaled integers
        // of scale 1e-6.
        assert_eq!(scans[0].name, "bunny");
        assert_eq!(scans[0].len(), 30571);
        let (lo, hi) = bounds(&scans[0]);
        let expected_lo = Vector3::new(-0.094689, 0.040011, -0.061873);
        let expected_hi = Vector3::new(0.061009, 0.187321, 0.058799);
        assert!(
            (lo - expected_lo).norm() < 2e-6 && (hi - expected_hi).norm() < 2e-6,
            "{lo} {hi}"
        );
    }

    #[test]
    fn spherical_points_become_cartesian_and_direction_only_points_are_dropped() {
        // libE57Format's generator (the e57 crate's cpp_generator): 360
        // points, range 1, azimuth = elevation = i·3.14/360, odd ones
        // direction-only (invalid state 1).
        let scans = read(&validation_file("tiny_spherical.e57")).unwrap();
        let scan = &scans[0];
        assert_eq!(scan.len(), 180);
        let pose = scan.pose.unwrap();
        assert_eq!(pose.origin, Vector3::zeros());
        for (k, p) in scan.positions.iter().enumerate() {
            // The generator's 3.14, not π.
            #[allow(clippy::approx_constant)]
            let a = (2 * k) as f64 * (3.14 / 360.0);
            let expected = Vector3::new(a.cos() * a.cos(), a.cos() * a.sin(), a.sin());
            assert!((p - expected).norm() < 1e-12, "point {k}: {p} vs {expected}");
        }
    }

    #[test]
    fn libe57formats_zero_point_files_are_an_empty_scan_and_a_clear_refusal() {
        // recordCount="0", Cartesian single floats: one empty scan.
        let scans = read(&validation_file("ZeroPoints.e57")).unwrap();
        assert_eq!(scans.len(), 1);
        assert!(scans[0].is_empty());
        // recordCount="0" at fileOffset="0" (no section there): refused,
        // naming the file.
        let e = read(&validation_file("ZeroPointsInvalid.e57")).unwrap_err();
        assert!(matches!(e, ReadError::Format { format: "E57", .. }), "{e}");
        assert!(e.to_string().contains("ZeroPointsInvalid.e57"), "{e}");
    }

    #[test]
    fn a_grid_with_negative_indices_starts_at_its_smallest_and_invalid_points_leave_holes() {
        use ::e57::{E57Writer, Record, RecordDataType, RecordName, RecordValue};
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("grid.e57");
        let mut writer = E57Writer::from_file(&path, "grid-test").unwrap();
        let index = |name| Record {
            name,
            data_type: RecordDataType::Integer { min: -2, max: 1 },
        };
        let prototype = vec![
            Record::CARTESIAN_X_F64,
            Record::CARTESIAN_Y_F64,
            Record::CARTESIAN_Z_F64,
            Record::CARTESIAN_INVALID_STATE,
            index(RecordName::RowIndex),
            index(RecordName::ColumnIndex),
        ];
        let mut cloud = writer.add_pointcloud("grid-cloud", prototype).unwrap();
        // A 4 × 4 grid from (−2, −2); the cell (0, 0) has no return.
        for r in -2..2i64 {
            for c in -2..2i64 {
                let invalid = i64::from((r, c) == (0, 0)) * 2;
                cloud
                    .add_point(vec![
                        RecordValue::Double(r as f64),
                        RecordValue::Double(c as f64),
                        RecordValue::Double(1.0),
                        RecordValue::Integer(invalid),
                        RecordValue::Integer(r),
                        RecordValue::Integer(c),
                    ])
                    .unwrap();
            }
        }
        cloud.finalize().unwrap();
        writer.finalize().unwrap();
        let scan = read(&path).unwrap().remove(0);
        assert_eq!(scan.len(), 15);
        let grid = scan.grid.as_ref().unwrap();
        assert_eq!((grid.rows, grid.cols), (4, 4));
        // File cell (−2, −2) is grid cell (0, 0); file (0, 0) is (2, 2).
        assert_eq!(
            scan.positions[grid.point_at(0, 0).unwrap()],
            Vector3::new(-2.0, -2.0, 1.0)
        );
        assert_eq!(grid.point_at(2, 2), None);
        assert_eq!(
            scan.positions[grid.point_at(3, 1).unwrap()],
            Vector3::new(1.0, -1.0, 1.0)
        );
    }

    #[test]
    fn a_file_that_is_not_e57_is_a_format_error() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("fake.e57");
        std::fs::write(&path, b"ply\nformat ascii 1.0\n").unwrap();
        let e = read(&path).unwrap_err();
        assert!(matches!(e, ReadError::Format { format: "E57", .. }), "{e}");
        // Truncated: the bunny's first 20 kB.
        let bytes = std::fs::read(validation_file("bunnyInt19.e57")).unwrap();
        std::fs::write(&path, &bytes[..20_000]).unwrap();
        assert!(read(&path).is_err());
    }
}

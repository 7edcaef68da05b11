//! Scans as one E57 file through the `e57` crate: each scan a point cloud
//! with its pose (points stored in the scanner's frame, as E57 wants, and
//! the pose as the cloud's transform), intensity (single precision, limits
//! 0 and 1, values clamped to them), colour (single precision in [0, 1])
//! and the grid (`rowIndex`, `columnIndex`, `indexBounds`). Cells with no
//! return are not written; [`crate::read::e57`] leaves them empty again.
//! A scan with no pose is written in the file's frame.

use std::path::Path;

use ::e57::{
    ColorLimits, E57Writer, IndexBounds, IntensityLimits, Quaternion, Record, RecordDataType, RecordName, RecordValue,
    Transform, Translation,
};
use nalgebra::{UnitQuaternion, Vector3};

use super::{WriteError, checked_cells};
use crate::cloud::Scan;

/// Writes `scans` to `path` as one E57 file.
pub fn write(path: &Path, scans: &[Scan]) -> Result<(), WriteError> {
    let io = |e: &dyn std::fmt::Display| WriteError::Io {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    let mut writer = E57Writer::from_file(path, &format!("campanile-scan:{}", path.display())).map_err(|e| io(&e))?;
    for (index, scan) in scans.iter().enumerate() {
        let cells = checked_cells(path, scan)?;
        let mut prototype = vec![
            Record::CARTESIAN_X_F64,
            Record::CARTESIAN_Y_F64,
            Record::CARTESIAN_Z_F64,
        ];
        if scan.intensity.is_some() {
            prototype.push(Record::INTENSITY_UNIT_F32);
        }
        if scan.colour.is_some() {
            prototype.extend([
                Record::COLOR_RED_UNIT_F32,
                Record::COLOR_GREEN_UNIT_F32,
                Record::COLOR_BLUE_UNIT_F32,
            ]);
        }
        if let Some(grid) = &scan.grid {
            let index = |name, n: usize| Record {
                name,
                data_type: RecordDataType::Integer {
                    min: 0,
                    max: n.saturating_sub(1) as i64,
                },
            };
            prototype.push(index(RecordName::RowIndex, grid.rows));
            prototype.push(index(RecordName::ColumnIndex, grid.cols));
        }
        let mut cloud = writer
            .add_pointcloud(&format!("campanile-scan:{}:{index}", scan.name), prototype)
            .map_err(|e| io(&e))?;
        cloud.set_name(Some(scan.name.clone()));
        if scan.intensity.is_some() {
            cloud.set_intensity_limits(Some(IntensityLimits {
                intensity_min: Some(RecordValue::Single(0.0)),
                intensity_max: Some(RecordValue::Single(1.0)),
            }));
        }
        if scan.colour.is_some() {
            let (lo, hi) = (Some(RecordValue::Single(0.0)), Some(RecordValue::Single(1.0)));
            cloud.set_color_limits(Some(ColorLimits {
                red_min: lo.clone(),
                red_max: hi.clone(),
                green_min: lo.clone(),
                green_max: hi.clone(),
                blue_min: lo,
                blue_max: hi,
            }));
        }
        if let Some(grid) = &scan.grid {
            cloud.set_index_bounds(Some(IndexBounds {
                row_min: Some(0),
                row_max: Some(grid.rows.saturating_sub(1) as i64),
                column_min: Some(0),
                column_max: Some(grid.cols.saturating_sub(1) as i64),
                return_min: None,
                return_max: None,
            }));
        }
        // Scene frame → scanner frame: p_local = Rᵀ (p − o).
        let to_local = |p: &Vector3<f64>| match &scan.pose {
            Some(pose) => pose.rotation.inverse() * (p - pose.origin),
            None => *p,
        };
        if let Some(pose) = &scan.pose {
            let q = UnitQuaternion::from_rotation_matrix(&pose.rotation);
            cloud.set_transform(Some(Transform {
                rotation: Quaternion {
                    w: q.w,
                    x: q.i,
                    y: q.j,
                    z: q.k,
                },
                translation: Translation {
                    x: pose.origin.x,
                    y: pose.origin.y,
                    z: pose.origin.z,
                },
            }));
        }
        for (i, p) in scan.positions.iter().enumerate() {
            let local = to_local(p);
            let mut values = vec![
                RecordValue::Double(local.x),
                RecordValue::Double(local.y),
                RecordValue::Double(local.z),
            ];
            if let Some(t) = &scan.intensity {
                values.push(RecordValue::Single(t[i].clamp(0.0, 1.0)));
            }
            if let Some(c) = &scan.colour {
                values.extend(c[i].map(|v| RecordValue::Single(v.clamp(0.0, 1.0))));
            }
            if let Some(cells) = &cells {
                values.push(RecordValue::Integer(i64::from(cells[i].0)));
                values.push(RecordValue::Integer(i64::from(cells[i].1)));
            }
            cloud.add_point(values).map_err(|e| io(&e))?;
        }
        cloud.finalize().map_err(|e| io(&e))?;
    }
    writer.finalize().map_err(|e| io(&e))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::read::stream::ScanStream;
    use crate::write::{assert_same_scan, test_scan};

    #[test]
    fn scans_read_back_posed_with_their_grids_and_stream_one_at_a_time() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("two.e57");
        let first = test_scan();
        let mut second = test_scan();
        second.name = "unposed".into();
        second.pose = None;
        second.grid = None;
        second.normals = None;
        second.positions.iter_mut().for_each(|p| p.x += 10.0);
        write(&path, &[first.clone(), second.clone()]).unwrap();
        let back = crate::read::read_scan(&path).unwrap();
        assert_eq!(back.len(), 2);
        // E57 has no normals; the rest round-trips (the posed scan through
        // its scanner frame and back: 1e-12 m).
        let mut expected = first.clone();
        expected.normals = None;
        assert_same_scan(&expected, &back[0], 1e-12);
        assert_eq!(back[0].name, "test-scan");
        second.normals = None;
        assert_same_scan(&second, &back[1], 1e-12);

        // The stream gives the same scans, one at a time, then the PLY.
        let ply = dir.path().join("one.ply");
        crate::write::ply::write(&ply, &first).unwrap();
        let streamed: Vec<Scan> = ScanStream::new(vec![path.clone(), ply]).map(Result::unwrap).collect();
        assert_eq!(streamed.len(), 3);
        assert_eq!(streamed[0], back[0]);
        assert_eq!(streamed[1], back[1]);
        assert_same_scan(&first, &streamed[2], 1e-12);
        // A bad file in the stream is an error, and the stream goes on.
        let results: Vec<_> = ScanStream::new(vec![dir.path().join("x.txt"), path]).collect();
        assert_eq!(results.len(), 3);
        assert!(results[0].is_err() && results[1].is_ok() && results[2].is_ok());
    }
}

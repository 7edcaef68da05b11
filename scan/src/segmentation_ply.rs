//! The segmentation as a point cloud to look at: every point of every scan,
//! coloured by its group, in a binary PLY (positions as doubles, 8-bit RGB,
//! and the group as an int, −1 for unassigned) that MeshLab, CloudCompare
//! and Open3D open.
//!
//! The vertices are the scans' points in their order (scan by scan, in the
//! order given, each scan's points as read), so the `group` property is
//! also every point's label for a program that scores the segmentation
//! against per-point truth (`bench/segment/campanile_segment.py`).
//!
//! Colours are deterministic: group `g` takes the hue `g × 0.618…` turns
//! (the golden ratio's fraction, which keeps neighbouring numbers far
//! apart) at full saturation and value 0.9; unassigned points are grey.

use std::io::Write;
use std::path::{Path, PathBuf};

use crate::cloud::Scan;
use crate::segmentation::{Segmentation, UNASSIGNED};

/// The grey of unassigned points.
pub const UNASSIGNED_COLOUR: [u8; 3] = [128, 128, 128];

/// Group `group`'s colour.
pub fn group_colour(group: u32) -> [u8; 3] {
    if group == UNASSIGNED {
        return UNASSIGNED_COLOUR;
    }
    let hue = (f64::from(group) * 0.618_033_988_749_895).fract() * 6.0;
    let (value, saturation) = (0.9, 1.0);
    let c = value * saturation;
    let x = c * (1.0 - (hue % 2.0 - 1.0).abs());
    let (r, g, b) = match hue as u32 {
        0 => (c, x, 0.0),
        1 => (x, c, 0.0),
        2 => (0.0, c, x),
        3 => (0.0, x, c),
        4 => (x, 0.0, c),
        _ => (c, 0.0, x),
    };
    let m = value - c;
    [r, g, b].map(|v| ((v + m) * 255.0).round() as u8)
}

/// Writes every point of `scans` coloured by its group in `segmentation`
/// (whose labels must match the scans, as [`crate::mesh::mesh_groups`]
/// checks) to `path`.
pub fn write_segmentation_ply(path: &Path, scans: &[Scan], segmentation: &Segmentation) -> Result<(), PlyError> {
    let io = |source| PlyError {
        path: path.to_path_buf(),
        source,
    };
    let points: usize = scans.iter().map(Scan::len).sum();
    let header = format!(
        "ply\nformat binary_little_endian 1.0\ncomment campanile segmentation: {} groups\n\
         element vertex {points}\nproperty double x\nproperty double y\nproperty double z\n\
         property uchar red\nproperty uchar green\nproperty uchar blue\nproperty int group\nend_header\n",
        segmentation.groups()
    );
    let file = std::fs::File::create(path).map_err(io)?;
    let mut out = std::io::BufWriter::new(file);
    out.write_all(header.as_bytes()).map_err(io)?;
    let mut record = [0u8; 31];
    for (scan, labels) in scans.iter().zip(&segmentation.labels) {
        for (p, &label) in scan.positions.iter().zip(labels) {
            for (k, v) in [p.x, p.y, p.z].into_iter().enumerate() {
                record[8 * k..8 * k + 8].copy_from_slice(&v.to_le_bytes());
            }
            record[24..27].copy_from_slice(&group_colour(label));
            let group = if label == UNASSIGNED { -1 } else { label as i32 };
            record[27..31].copy_from_slice(&group.to_le_bytes());
            out.write_all(&record).map_err(io)?;
        }
    }
    let file = out.into_inner().map_err(|e| io(e.into_error()))?;
    file.sync_all().map_err(io)
}

/// The PLY file could not be written.
#[derive(Debug, thiserror::Error)]
#[error("{}: {source}", path.display())]
pub struct PlyError {
    /// The file.
    pub path: PathBuf,
    /// What went wrong.
    pub source: std::io::Error,
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    #[test]
    fn colours_are_fixed_and_the_file_holds_every_point() {
        assert_eq!(group_colour(0), [230, 0, 0]);
        assert_eq!(group_colour(UNASSIGNED), UNASSIGNED_COLOUR);
        let colours: Vec<_> = (0..8).map(group_colour).collect();
        for i in 0..8 {
            for j in 0..i {
                assert_ne!(colours[i], colours[j], "groups {i} and {j}");
            }
        }
        let scans = [
            Scan::from_positions("s", vec![Vector3::new(1.0, 2.0, 3.0), Vector3::zeros()]),
            Scan::from_positions("t", vec![Vector3::new(-4.0, 5.0, 6.5)]),
        ];
        let seg = Segmentation {
            labels: vec![vec![1, UNASSIGNED], vec![0]],
            names: vec!["a".into(), "b".into()],
        };
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("seg.ply");
        write_segmentation_ply(&path, &scans, &seg).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let header_end = bytes.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
        assert_eq!(bytes.len() - header_end, 3 * 31);
        // The vertices in scan order: (x, y, z, group) of each.
        let vertex = |i: usize| {
            let r = &bytes[header_end + 31 * i..header_end + 31 * (i + 1)];
            let f = |k: usize| f64::from_le_bytes(r[8 * k..8 * k + 8].try_into().unwrap());
            (f(0), f(1), f(2), i32::from_le_bytes(r[27..31].try_into().unwrap()))
        };
        assert_eq!(vertex(0), (1.0, 2.0, 3.0, 1));
        assert_eq!(vertex(1), (0.0, 0.0, 0.0, -1));
        assert_eq!(vertex(2), (-4.0, 5.0, 6.5, 0));
        assert_eq!(&bytes[header_end + 24..header_end + 27], &group_colour(1));
    }
}

//! Calibration targets: flat patches with a high-intensity disc (thesis
//! §3, pose registration from targets).
//!
//! In each scan with intensity, points at or above [`BRIGHT`] are joined
//! into pieces (neighbours within 2.5× the point spacing). A piece is a
//! target when it has at least [`MIN_POINTS`] points, is flat (RMS distance
//! to its plane at most 3× the scan's noise plus 1 mm), round (the two
//! in-plane second moments within a factor 1.6, the farthest point within
//! 1.4× the disc radius), and lies on a flat patch: the points in the ring
//! from 1.2 to 1.8 disc radii are within 3× the noise plus 2 mm of the
//! disc's plane and darker. Its centre is the points' centroid, its radius
//! √(2 ⟨r²⟩) (a uniformly sampled disc), its normal the plane's, toward the
//! scanner when the pose is known.

use nalgebra::{Matrix3, SymmetricEigen, Vector3};
use serde::{Deserialize, Serialize};

use super::normals::{LocalSurface, ScanFigures, point_tree};
use crate::cloud::Scan;

/// Intensity at or above which a point may belong to a target's disc.
pub const BRIGHT: f32 = 0.8;
/// Fewest points in a disc.
pub const MIN_POINTS: usize = 12;

/// One target found.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Target {
    /// The scan it is in.
    pub scan: usize,
    /// The disc's centre, scene frame, m.
    pub centre: [f64; 3],
    /// Its unit normal.
    pub normal: [f64; 3],
    /// Its radius, m.
    pub radius_m: f64,
    /// Points on the disc.
    pub points: usize,
    /// RMS distance of the disc's points to its plane, m.
    pub flatness_m: f64,
}

/// The targets in `scans` (`surfaces` from [`super::normals::local_surface`]).
pub fn find(scans: &[Scan], surfaces: &[LocalSurface], figures: &ScanFigures) -> Vec<Target> {
    let mut out = Vec::new();
    for (k, (scan, surface)) in scans.iter().zip(surfaces).enumerate() {
        let Some(intensity) = &scan.intensity else { continue };
        let bright: Vec<usize> = (0..scan.len()).filter(|&i| intensity[i] >= BRIGHT).collect();
        if bright.len() < MIN_POINTS {
            continue;
        }
        let spacing = surface.figures.spacing_m.max(figures.spacing_m * 0.25);
        let noise = surface.figures.noise_m;
        let positions: Vec<Vector3<f64>> = bright.iter().map(|&i| scan.positions[i]).collect();
        let tree = point_tree(&positions);
        let reach = (2.5 * spacing) * (2.5 * spacing);
        // Pieces by flood fill over the bright points.
        let mut piece = vec![u32::MAX; bright.len()];
        let mut pieces: Vec<Vec<usize>> = Vec::new();
        for seed in 0..bright.len() {
            if piece[seed] != u32::MAX {
                continue;
            }
            let id = pieces.len() as u32;
            piece[seed] = id;
            let mut stack = vec![seed];
            let mut members = Vec::new();
            while let Some(i) = stack.pop() {
                members.push(i);
                let p = positions[i];
                for n in tree.within_unsorted::<kiddo::SquaredEuclidean>(&[p.x, p.y, p.z], reach) {
                    let j = n.item as usize;
                    if piece[j] == u32::MAX {
                        piece[j] = id;
                        stack.push(j);
                    }
                }
            }
            pieces.push(members);
        }
        let all_tree = point_tree(&scan.positions);
        for members in pieces.into_iter().filter(|m| m.len() >= MIN_POINTS) {
            let pts: Vec<Vector3<f64>> = members.iter().map(|&i| positions[i]).collect();
            let n = pts.len() as f64;
            let centre = pts.iter().sum::<Vector3<f64>>() / n;
            let mut cov = Matrix3::zeros();
            for p in &pts {
                let d = p - centre;
                cov += d * d.transpose();
            }
            let eigen = SymmetricEigen::new(cov / n);
            let mut idx = [0usize, 1, 2];
            idx.sort_by(|&a, &b| eigen.eigenvalues[a].total_cmp(&eigen.eigenvalues[b]));
            let flatness = eigen.eigenvalues[idx[0]].max(0.0).sqrt();
            let (l1, l2) = (eigen.eigenvalues[idx[1]], eigen.eigenvalues[idx[2]]);
            let mut normal: Vector3<f64> = eigen.eigenvectors.column(idx[0]).into_owned();
            if flatness > 3.0 * noise + 1e-3 || l1 <= 0.0 || l2 / l1 > 1.6 {
                continue;
            }
            let in_plane = |p: &Vector3<f64>| {
                let d = p - centre;
                (d - normal * d.dot(&normal)).norm()
            };
            let mean_r2 = pts.iter().map(|p| in_plane(p).powi(2)).sum::<f64>() / n;
            let radius = (2.0 * mean_r2).sqrt();
            if pts.iter().map(in_plane).fold(0.0, f64::max) > 1.4 * radius + spacing {
                continue;
            }
            // The patch around: flat and darker.
            let ring: Vec<usize> = all_tree
                .within_unsorted::<kiddo::SquaredEuclidean>(&[centre.x, centre.y, centre.z], (1.8 * radius).powi(2))
                .into_iter()
                .map(|n| n.item as usize)
                .filter(|&i| in_plane(&scan.positions[i]) >= 1.2 * radius)
                .collect();
            if ring.len() < MIN_POINTS {
                continue;
            }
            let off_plane = ring
                .iter()
                .filter(|&&i| (scan.positions[i] - centre).dot(&normal).abs() > 3.0 * noise + 2e-3)
                .count();
            let darker = ring.iter().filter(|&&i| intensity[i] < BRIGHT).count();
            if off_plane * 10 > ring.len() || darker * 10 < ring.len() * 9 {
                continue;
            }
            let facing = match &scan.pose {
                Some(pose) => pose.origin - centre,
                None => members.iter().map(|&i| surface.normals[bright[i]]).sum(),
            };
            if normal.dot(&facing) < 0.0 {
                normal = -normal;
            }
            out.push(Target {
                scan: k,
                centre: [centre.x, centre.y, centre.z],
                normal: [normal.x, normal.y, normal.z],
                radius_m: radius,
                points: members.len(),
                flatness_m: flatness,
            });
        }
    }
    out
}

//! Normals and local noise, measured from the points themselves.
//!
//! The thesis (§2.3) takes each point's normal "estimated from neighboring
//! pixels in the scan image". A scan without normals gets them here:
//!
//! - **organised scans**: a plane fitted to the point's 5×5 grid window, its
//!   neighbours gated by distance so that a window does not reach across a
//!   depth jump;
//! - **unorganised clouds**: a plane fitted to the point's 10 nearest
//!   neighbours (a kd-tree, `kiddo`).
//!
//! (3×3 windows were tried first: with noise at a fifth of the spacing,
//! their normals scatter by 4° and more, and the clusters fragment.)
//!
//! Each point takes, among the windows that contain it, the one that fits a
//! plane best (the smallest RMS residual): near a crease or a depth jump the
//! window centred on the point straddles both surfaces, a shifted one does
//! not, so normals stay sharp up to the edge. Normals face the scanner when
//! its pose is known; otherwise they are made consistent by propagation over
//! the neighbour graph, each connected piece seeded to face its centroid
//! (inward, for a room scanned from inside).
//!
//! The same fits give the scan's figures ([`ScanFigures`]): point spacing,
//! noise across the surface, normal noise and intensity noise, from which
//! [`crate::segment::params`] derives the segmentation's parameters.

use std::num::NonZero;

use kiddo::SquaredEuclidean;
use kiddo::immutable::float::kdtree::ImmutableKdTree;
use nalgebra::{Matrix3, SymmetricEigen, Vector3};
use rayon::prelude::*;

use crate::cloud::Scan;

/// Neighbours for an unorganised cloud's plane fits.
const NEAREST: usize = 16;
/// The grid window's half-width, cells.
const HALF_WINDOW: isize = 2;

/// A kd-tree over points (index = the point's position in the slice).
pub(crate) type PointTree = ImmutableKdTree<f64, u64, 3, 32>;

/// A kd-tree over `points`.
pub(crate) fn point_tree(points: &[Vector3<f64>]) -> PointTree {
    let coords: Vec<[f64; 3]> = points.iter().map(|p| [p.x, p.y, p.z]).collect();
    PointTree::new_from_slice(&coords)
}

/// The `k` nearest points to `p` (itself included when it is in the tree).
pub(crate) fn nearest(tree: &PointTree, p: &Vector3<f64>, k: usize) -> Vec<(f64, usize)> {
    let k = NonZero::new(k.max(1)).unwrap_or(NonZero::<usize>::MIN);
    tree.nearest_n::<SquaredEuclidean>(&[p.x, p.y, p.z], k)
        .into_iter()
        .map(|n| (n.distance.sqrt(), n.item as usize))
        .collect()
}

/// A scan's figures, measured from its points.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ScanFigures {
    /// Median distance from a point to its nearest neighbour, m.
    pub spacing_m: f64,
    /// Median noise across the surface (RMS distance to the local plane,
    /// corrected for the plane's three fitted parameters), m.
    pub noise_m: f64,
    /// A normal's angular error (σ in each direction), from the median
    /// angle between normals of non-overlapping windows nearby, degrees.
    pub normal_noise_deg: f64,
    /// Median absolute intensity difference between neighbours, scaled to a
    /// standard deviation; `None` without intensity.
    pub intensity_noise: Option<f64>,
    /// The same for the intensity divided by the incidence cosine
    /// ([`corrected_intensity`]); `None` without intensity or pose.
    #[serde(default)]
    pub corrected_intensity_noise: Option<f64>,
    /// How the returns follow the beam's incidence: the least-squares slope
    /// of ln intensity on ln cos incidence between points five cells apart
    /// on one plane ([`incidence_slope`]). About 1 for a scanner that
    /// reports raw returns from matte surfaces, about 0 for one that
    /// corrects them already. `None` without intensity, pose or pairs.
    #[serde(default)]
    pub incidence_slope: Option<f64>,
    /// The points measured.
    pub points: usize,
}

/// Every point's normal and how well a plane fits around it.
#[derive(Debug, Clone)]
pub struct LocalSurface {
    /// Unit normals (the scan's own when it has them).
    pub normals: Vec<Vector3<f64>>,
    /// Per point, the RMS distance of the best window to its plane, m: the
    /// point's planarity and noise figure (large at edges and on clutter).
    pub residual_m: Vec<f32>,
    /// Per point, the local spacing, m: the median over its neighbourhood of
    /// each neighbour's distance to its closest neighbour (what sets its
    /// scale level, [`crate::segment::graph::scale_level`]).
    pub spacing_m: Vec<f32>,
    /// Per point, the cosine of the beam's incidence (from the scan's pose
    /// and the point's normal); `None` without a pose.
    pub incidence_cos: Option<Vec<f32>>,
    /// The scan's figures.
    pub figures: ScanFigures,
}

/// A plane fit: unit normal, RMS residual, number of points.
#[derive(Debug, Clone, Copy)]
struct PlaneFit {
    normal: Vector3<f64>,
    rms: f64,
    count: usize,
}

/// The least-squares plane through `points` (the smallest eigenvector of
/// their covariance); `None` under three points.
fn fit_plane(points: &[Vector3<f64>]) -> Option<PlaneFit> {
    if points.len() < 3 {
        return None;
    }
    let n = points.len() as f64;
    let mean = points.iter().sum::<Vector3<f64>>() / n;
    let mut cov = Matrix3::zeros();
    for p in points {
        let d = p - mean;
        cov += d * d.transpose();
    }
    let eigen = SymmetricEigen::new(cov / n);
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| eigen.eigenvalues[a].total_cmp(&eigen.eigenvalues[b]));
    let [k, middle, largest] = order;
    let smallest = eigen.eigenvalues[k];
    // Nearly collinear points fix no plane.
    if eigen.eigenvalues[middle] < 0.01 * eigen.eigenvalues[largest] {
        return None;
    }
    let normal = eigen.eigenvectors.column(k).into_owned();
    let norm = normal.norm();
    (norm > 0.0 && norm.is_finite()).then(|| PlaneFit {
        normal: normal / norm,
        rms: smallest.max(0.0).sqrt(),
        count: points.len(),
    })
}

/// Each point's neighbour lists: for a grid, the 5×5 window gated at 3.5×
/// the larger of the distances to the closest neighbour along the row and
/// along the column; otherwise its [`NEAREST`] nearest neighbours. The point
/// itself comes first. With each list, partners whose windows do not
/// overlap the point's (5 cells along the row and 5 along the column; for
/// a cloud, the farthest of the nearest): the first gives the normal noise,
/// both the incidence slope.
fn neighbourhoods(scan: &Scan) -> (Vec<Vec<u32>>, Vec<[Option<u32>; 2]>) {
    let positions = &scan.positions;
    match &scan.grid {
        Some(grid) => {
            let mut lists = vec![Vec::new(); positions.len()];
            let mut partners = vec![[None; 2]; positions.len()];
            let cells: Vec<(usize, usize, usize)> = (0..grid.rows)
                .flat_map(|r| (0..grid.cols).map(move |c| (r, c)))
                .filter_map(|(r, c)| grid.point_at(r, c).map(|p| (r, c, p)))
                .collect();
            let computed: Vec<(usize, Vec<u32>, [Option<u32>; 2])> = cells
                .par_iter()
                .map(|&(r, c, p)| {
                    let at = |dr: isize, dc: isize| {
                        let (rr, cc) = (r as isize + dr, c as isize + dc);
                        if rr < 0 || cc < 0 {
                            None
                        } else {
                            grid.point_at(rr as usize, cc as usize)
                        }
                    };
                    // The closest neighbour along the row and along the
                    // column; the gate is 2.5× the larger (the grid's
                    // spacing differs between its two directions).
                    let closest = |steps: [(isize, isize); 2]| {
                        steps
                            .iter()
                            .filter_map(|&(dr, dc)| at(dr, dc))
                            .map(|q| (positions[q] - positions[p]).norm())
                            .fold(f64::INFINITY, f64::min)
                    };
                    let (along_row, along_col) = (closest([(0, -1), (0, 1)]), closest([(-1, 0), (1, 0)]));
                    let gate = (HALF_WINDOW as f64 + 1.5)
                        * match (along_row.is_finite(), along_col.is_finite()) {
                            (true, true) => along_row.max(along_col),
                            (true, false) => along_row,
                            (false, true) => along_col,
                            (false, false) => 0.0,
                        };
                    let mut list = vec![p as u32];
                    for dr in -HALF_WINDOW..=HALF_WINDOW {
                        for dc in -HALF_WINDOW..=HALF_WINDOW {
                            if let Some(q) = at(dr, dc).filter(|&q| q != p)
                                && (positions[q] - positions[p]).norm() <= gate
                            {
                                list.push(q as u32);
                            }
                        }
                    }
                    let far = 2 * HALF_WINDOW + 1;
                    (p, list, [at(0, far).map(|q| q as u32), at(far, 0).map(|q| q as u32)])
                })
                .collect();
            for (p, list, partner) in computed {
                lists[p] = list;
                partners[p] = partner;
            }
            (lists, partners)
        }
        None => {
            let tree = point_tree(positions);
            let lists: Vec<Vec<u32>> = positions
                .par_iter()
                .enumerate()
                .map(|(i, p)| {
                    let mut list = vec![i as u32];
                    list.extend(
                        nearest(&tree, p, NEAREST + 1)
                            .into_iter()
                            .filter(|&(_, q)| q != i)
                            .map(|(_, q)| q as u32),
                    );
                    list
                })
                .collect();
            let partners = lists
                .iter()
                .map(|l| [l.last().copied().filter(|_| l.len() > 1), None])
                .collect();
            (lists, partners)
        }
    }
}

/// The median of `values` (0 when empty).
pub(crate) fn median(mut values: Vec<f64>) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    let mid = values.len() / 2;
    let (_, m, _) = values.select_nth_unstable_by(mid, f64::total_cmp);
    *m
}

/// 1.4826 × the median absolute deviation of `values` from `centre`: a
/// normal variable's σ, unmoved by outliers under half of them.
pub(crate) fn robust_spread(values: impl Iterator<Item = f64>, centre: f64) -> f64 {
    1.4826 * median(values.map(|v| (v - centre).abs()).collect())
}

/// For a normal random variable X, median |X − X'| = 0.954 σ (X' an
/// independent copy): turns a median neighbour difference into a σ.
const MEDIAN_DIFF_TO_SIGMA: f64 = 0.953_872;

/// The angle between two normals, each off by σ in each of two directions,
/// has the median 1.177 √2 σ (a Rayleigh distribution).
const MEDIAN_ANGLE_TO_SIGMA: f64 = 1.664_9;

/// Normals, residuals and figures for `scan`.
pub fn local_surface(scan: &Scan) -> LocalSurface {
    let positions = &scan.positions;
    let (lists, partners) = neighbourhoods(scan);
    let fits: Vec<Option<PlaneFit>> = lists
        .par_iter()
        .map(|list| {
            let pts: Vec<Vector3<f64>> = list.iter().map(|&q| positions[q as usize]).collect();
            fit_plane(&pts)
        })
        .collect();
    // Shifted windows: the best-fitting window among those containing the point.
    let best: Vec<Option<PlaneFit>> = lists
        .par_iter()
        .enumerate()
        .map(|(i, list)| {
            let mut best = fits[i].filter(|f| f.count >= 4);
            for &q in &list[1..] {
                let Some(f) = fits[q as usize].filter(|f| f.count >= 4) else {
                    continue;
                };
                if !lists[q as usize].contains(&(i as u32)) {
                    continue;
                }
                if best.is_none_or(|b| f.rms < b.rms) {
                    best = Some(f);
                }
            }
            best.or(fits[i])
        })
        .collect();
    let mut normals: Vec<Vector3<f64>> = best.iter().map(|f| f.map_or(Vector3::zeros(), |f| f.normal)).collect();
    let residual_m: Vec<f32> = best.iter().map(|f| f.map_or(f32::INFINITY, |f| f.rms as f32)).collect();
    orient(scan, &lists, &mut normals);
    if let Some(given) = &scan.normals {
        normals.clone_from(given);
    }

    let closest_distance: Vec<Option<f64>> = lists
        .par_iter()
        .enumerate()
        .map(|(i, l)| {
            l[1..]
                .iter()
                .map(|&q| (positions[q as usize] - positions[i]).norm())
                .reduce(f64::min)
        })
        .collect();
    let spacing_m = median(closest_distance.iter().flatten().copied().collect());
    let local_spacing: Vec<f32> = lists
        .par_iter()
        .map(|l| median(l.iter().filter_map(|&q| closest_distance[q as usize]).collect()) as f32)
        .collect();
    let noise_m = median(
        fits.iter()
            .flatten()
            .filter(|f| f.count > 4)
            .map(|f| f.rms * (f.count as f64 / (f.count as f64 - 3.0)).sqrt())
            .collect(),
    );
    let closest = |i: usize| {
        lists[i][1..].iter().map(|&q| q as usize).min_by(|&a, &b| {
            (positions[a] - positions[i])
                .norm()
                .total_cmp(&(positions[b] - positions[i]).norm())
        })
    };
    let normal_noise_deg = median(
        (0..positions.len())
            .filter_map(|i| partners[i][0].map(|q| normals[i].dot(&normals[q as usize]).abs().clamp(-1.0, 1.0).acos()))
            .collect(),
    )
    .to_degrees()
        / MEDIAN_ANGLE_TO_SIGMA;
    let incidence_cos = incidence_cosines(scan, &normals);
    let noise_of = |intensity: &[f32]| {
        median(
            (0..positions.len())
                .filter_map(|i| closest(i).map(|q| f64::from((intensity[i] - intensity[q]).abs())))
                .filter(|d| d.is_finite())
                .collect(),
        ) / MEDIAN_DIFF_TO_SIGMA
    };
    let intensity_noise = scan.intensity.as_deref().map(noise_of);
    let corrected = corrected_intensity(scan, incidence_cos.as_deref(), true);
    let corrected_intensity_noise = incidence_cos.as_ref().and(corrected.as_deref()).map(noise_of);
    let incidence_slope = match (&scan.intensity, &incidence_cos) {
        (Some(intensity), Some(cos)) => incidence_slope(intensity, cos, &normals, &partners),
        _ => None,
    };
    LocalSurface {
        normals,
        residual_m,
        spacing_m: local_spacing,
        incidence_cos,
        figures: ScanFigures {
            spacing_m,
            noise_m,
            normal_noise_deg,
            intensity_noise,
            corrected_intensity_noise,
            incidence_slope,
            points: positions.len(),
        },
    }
}

/// The least incidence cosine an intensity is divided by (75°): past it a
/// return is mostly noise and the correction would magnify it.
pub const MIN_INCIDENCE_COS: f64 = 0.258_819;

/// Each point's incidence cosine, `|n · b|` for the unit beam `b` from the
/// scanner's origin to the point (1 for a point with no normal); `None`
/// without a pose.
fn incidence_cosines(scan: &Scan, normals: &[Vector3<f64>]) -> Option<Vec<f32>> {
    let pose = scan.pose.as_ref()?;
    Some(
        scan.positions
            .par_iter()
            .zip(normals)
            .map(|(p, n)| {
                let beam = pose.origin - p;
                let length = beam.norm();
                if length <= 0.0 || n.norm_squared() == 0.0 {
                    return 1.0;
                }
                (n.dot(&beam) / length).abs() as f32
            })
            .collect(),
    )
}

/// The intensity the segmentation compares. A scanner's raw return from a
/// matte surface is its reflectance at the laser's wavelength times the
/// cosine of the beam's incidence (the Lambertian model that radiometric
/// corrections of terrestrial-scanner intensity start from, and the
/// simulated scanner's). Divided by the cosine (`correct`, and a pose),
/// what is left is the reflectance, which is what tells a board from its
/// wall: uncorrected, one wall read from five scans spreads over 0.1–0.5
/// and the intensity pass's σ_w, set from neighbouring clusters'
/// differences, grows to 0.5. Past [`MIN_INCIDENCE_COS`] the division
/// would magnify the noise and the normal's error, and dividing by the
/// limit instead would make a grazing strip read darker than its surface
/// (the intensity pass then cut it off): such points carry no intensity
/// (NaN), and the intensity neither joins nor separates them. Without
/// `correct` or a pose, the return as it is. `None` without intensity.
pub fn corrected_intensity(scan: &Scan, incidence_cos: Option<&[f32]>, correct: bool) -> Option<Vec<f32>> {
    let intensity = scan.intensity.as_ref()?;
    match incidence_cos {
        Some(cos) if correct => Some(
            intensity
                .iter()
                .zip(cos)
                .map(|(&i, &c)| {
                    if f64::from(c) >= MIN_INCIDENCE_COS {
                        i / c
                    } else {
                        f32::NAN
                    }
                })
                .collect(),
        ),
        _ => Some(intensity.clone()),
    }
}

/// The least-squares slope, through the origin, of Δ ln I on Δ ln cos over
/// pairs of points five cells apart along the row and along the column
/// ([`neighbourhoods`]' partners; for a cloud, the farthest of the
/// nearest) whose normals agree within 5°, whose intensities are both
/// above 0.02 and whose cosines are both above [`MIN_INCIDENCE_COS`] and
/// differ by at least 2 %: one surface's reflectance cancels in each pair,
/// so what is left is how the scanner's returns follow the incidence.
/// `None` under 100 pairs. Noisy normals attenuate it (errors in the
/// variable): on 4 mm-spaced scans with 2 mm noise it reads 0.2–0.4 where
/// coarser scans of the same scene read 0.9–1.0.
fn incidence_slope(
    intensity: &[f32],
    cos: &[f32],
    normals: &[Vector3<f64>],
    partners: &[[Option<u32>; 2]],
) -> Option<f64> {
    let same_plane = 5f64.to_radians().cos();
    let (mut sxy, mut sxx, mut pairs) = (0.0, 0.0, 0usize);
    for (i, q) in partners
        .iter()
        .enumerate()
        .flat_map(|(i, pair)| pair.iter().flatten().map(move |&q| (i, q as usize)))
    {
        if normals[i].dot(&normals[q]).abs() < same_plane
            || intensity[i] <= 0.02
            || intensity[q] <= 0.02
            || f64::from(cos[i].min(cos[q])) < MIN_INCIDENCE_COS
        {
            continue;
        }
        let dx = f64::from(cos[i].ln() - cos[q].ln());
        if dx.abs() < 0.02 {
            continue;
        }
        let dy = f64::from(intensity[i].ln() - intensity[q].ln());
        sxy += dx * dy;
        sxx += dx * dx;
        pairs += 1;
    }
    (pairs >= 100 && sxx > 0.0).then(|| sxy / sxx)
}

/// Faces every normal toward the scanner, or, without a pose, makes them
/// consistent by breadth-first propagation over the neighbour lists.
fn orient(scan: &Scan, lists: &[Vec<u32>], normals: &mut [Vector3<f64>]) {
    if let Some(pose) = &scan.pose {
        for (n, p) in normals.iter_mut().zip(&scan.positions) {
            if n.dot(&(pose.origin - p)) < 0.0 {
                *n = -*n;
            }
        }
        return;
    }
    let count = normals.len();
    if count == 0 {
        return;
    }
    let centroid = scan.positions.iter().sum::<Vector3<f64>>() / count as f64;
    // Symmetric neighbour lists (k-nearest lists are not symmetric).
    let mut adjacency = vec![Vec::new(); count];
    for (i, list) in lists.iter().enumerate() {
        for &q in &list[1..] {
            adjacency[i].push(q);
            adjacency[q as usize].push(i as u32);
        }
    }
    let mut seen = vec![false; count];
    let mut queue = std::collections::VecDeque::new();
    for seed in 0..count {
        if seen[seed] {
            continue;
        }
        if normals[seed].dot(&(centroid - scan.positions[seed])) < 0.0 {
            normals[seed] = -normals[seed];
        }
        seen[seed] = true;
        queue.push_back(seed);
        while let Some(i) = queue.pop_front() {
            for &q in &adjacency[i] {
                let q = q as usize;
                if !seen[q] {
                    seen[q] = true;
                    if normals[q].dot(&normals[i]) < 0.0 {
                        normals[q] = -normals[q];
                    }
                    queue.push_back(q);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::segment::room_fixture::{RoomScan, SURFACES, scan_room};

    /// The fixture's true normal for its six room faces (`None` for the
    /// table and the rest).
    fn face_normal(label: u32) -> Option<Vector3<f64>> {
        match SURFACES.get(label as usize).copied()? {
            "floor" | "ceiling" => Some(Vector3::z()),
            "wall_x0" | "wall_x4" => Some(Vector3::x()),
            "wall_y0" | "wall_y3" => Some(Vector3::y()),
            _ => None,
        }
    }

    fn room() -> (Scan, Vec<u32>) {
        let (scan, truth) = scan_room(&RoomScan {
            cols: 160,
            rows: 64,
            table: false,
            ..RoomScan::default()
        });
        (scan, truth.labels[0].clone())
    }

    #[test]
    fn a_scanner_reporting_raw_returns_is_found_and_its_returns_corrected() {
        let (mut scan, labels) = room();
        let origin = scan.pose.as_ref().unwrap().origin;
        // Returns as a raw scanner gives them: the fixture's reflectance
        // times the true incidence cosine.
        let reflectance = scan.intensity.clone().unwrap();
        let intensity: Vec<f32> = scan
            .positions
            .iter()
            .zip(&labels)
            .zip(&reflectance)
            .map(|((p, &l), &r)| {
                let n = face_normal(l).unwrap_or_else(Vector3::z);
                r * (n.dot(&(origin - p).normalize()).abs() as f32)
            })
            .collect();
        scan.intensity = Some(intensity);
        let surface = local_surface(&scan);
        let slope = surface.figures.incidence_slope.unwrap();
        // Measured: 0.996.
        assert!((slope - 1.0).abs() < 0.1, "{slope}");
        let corrected = corrected_intensity(&scan, surface.incidence_cos.as_deref(), true).unwrap();
        let errors: Vec<f64> = corrected
            .iter()
            .zip(&reflectance)
            .zip(&labels)
            .filter(|((c, _), l)| c.is_finite() && face_normal(**l).is_some())
            .map(|((c, r), _)| f64::from((c - r).abs()))
            .collect();
        let grazing = corrected.iter().filter(|c| c.is_nan()).count();
        assert!(grazing < corrected.len() / 10, "{grazing} of {}", corrected.len());
        // Back to the reflectance within the intensity noise (0.01) at the
        // median (measured 0.0018), where the raw returns are off by up to
        // half.
        let m = median(errors);
        assert!(m < 0.02, "{m}");
    }

    #[test]
    fn a_scanner_reporting_corrected_returns_is_left_alone() {
        // The fixture's intensity is the reflectance itself.
        let (scan, _) = room();
        let surface = local_surface(&scan);
        let slope = surface.figures.incidence_slope.unwrap();
        // Measured: −0.002.
        assert!(slope.abs() < 0.2, "{slope}");
        // Without a pose there is no incidence to measure.
        let mut posed_off = scan.clone();
        posed_off.pose = None;
        let surface = local_surface(&posed_off);
        assert_eq!(surface.figures.incidence_slope, None);
        assert!(surface.incidence_cos.is_none());
        assert_eq!(corrected_intensity(&posed_off, None, true), posed_off.intensity.clone());
    }
}

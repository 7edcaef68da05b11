//! Correspondences of identity-less circle targets by search, and the
//! pose they give (thesis §3.3.2–§3.3.3).
//!
//! **Each detected ellipse** is refitted in a virtual camera turned to look
//! straight at it (the thesis: "for targets not located at the center of
//! the image, we reproject them onto such a plane"): its edge points are
//! undistorted through the lens model, turned into that frame and fitted
//! there, where the image of a circle is exactly a conic. This gives the
//! thesis's `a_i, b_i, γ_i` (semi-axes in pixels, the major axis's angle
//! to the plane's up) and, since the targets' radius is known, the
//! circle's two possible poses in the camera frame: centre and normal
//! from the eigen-decomposition of the cone through the ellipse (the
//! closed form of the ellipse–circle pair the thesis cites, [42]).
//!
//! **A pair of detections** matched to a pair of surveyed targets then
//! fixes the pose: the rotation that takes the two surveyed normals and
//! the baseline between the two centres onto their camera-frame
//! counterparts (weighted Kabsch), the centre of projection from the
//! anchored centres. That is 10 constraints for 6 unknowns, and the
//! thesis's function
//! `Σ_t (a_ti − a_tg)² + (b_ti − b_tg)² + ((γ_ti − γ_tg)·((a_ti − b_ti) + (a_tg − b_tg))/2)²`
//! with its `a_g = r f / ‖Q‖`, `b_g = a_g (Q̂ · T_n)`, `γ_g` the angle of
//! `T_n × Q` to the plane's up, "weed[s] out most bad correspondences
//! immediately". The thesis minimizes that function from several starts;
//! here the four closed-form poses (two normals per ellipse) are those
//! starts and the function judges them. The pair's baseline (the two
//! distances from the ellipses' sizes) and the normals' angles prune
//! the pairs before any pose is computed.
//!
//! **The remaining targets confirm or reject it**, as in the thesis: from the
//! pair's pose each other detection gets its few (at most 3) candidate
//! targets, those projected near it with a size that agrees; each is tried
//! in turn, the pose solved from the three (Levenberg–Marquardt), and the
//! detections counted whose nearest projected target is within the inlier
//! threshold. The search stops when a hypothesis explains 80% of the
//! detections (at least 4), or at a cap; the number of hypotheses tried
//! is reported. If an assignment that conflicts with the best explains as
//! many detections, the pose is not to be trusted: the verdict says so.
//!
//! **Refinement** (§3.3.3) is [`super::solve::register`] on the matched
//! centres: RANSAC, Levenberg–Marquardt on all six parameters through the
//! lens model, covariance and verdict. The centre of an ellipse is not the
//! image of the circle's centre under perspective: it is the image of the
//! pole, with respect to the circle, of the line where the target's plane
//! meets the camera's principal plane, the point
//! `c − (r²/d)(f − (f·n) n)` (c the circle's centre, n its normal, f the
//! image plane's normal, d the depth of c; the ellipse being fitted in
//! the virtual camera that looks at the target, f is the direction to it
//! and d its distance). The shift is r²/d · sin θ (θ the angle between
//! the line of sight and the normal): 0.7 mm for a 0.1 m circle at 10 m
//! seen 45° off its normal. The refinement pairs each ellipse
//! centre with that point, recomputed at the refined pose (two rounds).

use nalgebra::{Matrix3, Rotation3, Vector3};

use super::camera_pose::CameraPose;
use super::circle_detect::CircleDetection;
use super::correspondence::Correspondence;
use super::ellipse::{Ellipse, fit_ellipse_robust};
use super::refine::refine;
use super::solve::{Registration, RegistrationSettings, register};
use super::verdict::Verdict;
use crate::pose::Pinhole;

/// One surveyed circle target.
#[derive(Debug, Clone, PartialEq)]
pub struct SurveyedCircle {
    /// The survey's label (not seen in the image).
    pub id: u32,
    /// Centre of the white circle, world frame, metres.
    pub centre: Vector3<f64>,
    /// Unit normal out of the target's face.
    pub normal: Vector3<f64>,
    /// Radius of the white circle, metres.
    pub radius_m: f64,
}

impl SurveyedCircle {
    /// The circles of a targets file of kind `Circle(radius)`, or `None` for coded targets.
    pub fn from_targets(targets: &campanile_config::targets::Targets) -> Option<Vec<SurveyedCircle>> {
        let radius_m = targets.kind.circle_radius_m()?;
        Some(
            targets
                .targets
                .iter()
                .map(|t| SurveyedCircle {
                    id: t.id,
                    centre: Vector3::new(t.centre_m.0, t.centre_m.1, t.centre_m.2),
                    normal: Vector3::new(t.normal.0, t.normal.1, t.normal.2).normalize(),
                    radius_m,
                })
                .collect(),
        )
    }
}

/// How the correspondence search is bounded.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CircleSearchSettings {
    /// Most hypotheses (pair poses and three-target poses) tried.
    pub max_hypotheses: usize,
    /// The pair's baseline from the ellipses' sizes may differ from the
    /// survey's by this fraction of the mean distance, plus `baseline_relative` of the baseline.
    pub baseline_of_distance: f64,
    /// See `baseline_of_distance`.
    pub baseline_relative: f64,
    /// Largest angle between a surveyed normal or baseline turned by the
    /// pair's rotation and the one seen, degrees.
    pub max_normal_deg: f64,
    /// Largest per-target value of the thesis's function, square-rooted,
    /// relative to the semi-major axis.
    pub max_shape_error: f64,
    /// A detection's size and a target's projected size agree within this
    /// factor (either way).
    pub size_factor: f64,
    /// The search stops once a hypothesis explains this fraction of the
    /// detections, or `enough_targets` of them (and at least 4).
    pub enough_fraction: f64,
    /// See `enough_fraction`.
    pub enough_targets: usize,
}

impl Default for CircleSearchSettings {
    fn default() -> Self {
        CircleSearchSettings {
            max_hypotheses: 200_000,
            baseline_of_distance: 0.04,
            baseline_relative: 0.1,
            max_normal_deg: 20.0,
            max_shape_error: 0.15,
            size_factor: 1.5,
            enough_fraction: 0.8,
            enough_targets: 12,
        }
    }
}

/// A detection as the search sees it (module doc).
#[derive(Debug, Clone)]
pub struct ImageCircle {
    /// Index in the detections given.
    pub detection: usize,
    /// The ellipse's centre, distorted pixels.
    pub centre_px: (f64, f64),
    /// The thesis's `a_i`, `b_i` (pixels) and `γ_i` (radians, in [0, π)).
    pub shape: (f64, f64, f64),
    /// The circle's two possible centres and normals in the camera frame
    /// (normals toward the camera), for the survey's radius.
    pub poses: Vec<(Vector3<f64>, Vector3<f64>)>,
    /// The ellipse's quality, the search's order: its semi-major axis
    /// (pixels) times the fraction of its perimeter with an edge, over
    /// 1 + its fit's RMS in pixels.
    pub quality: f64,
}

/// The virtual camera looking along unit `z` (camera frame), its up the
/// camera's up made orthogonal: rows x, y, z.
fn virtual_frame(z: &Vector3<f64>) -> Option<Matrix3<f64>> {
    let y = (Vector3::y() - z * z.y).try_normalize(1e-9)?;
    let x = y.cross(z);
    Some(Matrix3::from_rows(&[x.transpose(), y.transpose(), z.transpose()]))
}

/// Angle of a line of direction `(x, y)` (virtual frame) to the up (−y), in [0, π).
fn line_angle(x: f64, y: f64) -> f64 {
    (y.atan2(x) + std::f64::consts::FRAC_PI_2).rem_euclid(std::f64::consts::PI)
}

/// The difference of two line angles, folded to [−π/2, π/2].
fn angle_difference(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(std::f64::consts::PI);
    if d > std::f64::consts::FRAC_PI_2 {
        d - std::f64::consts::PI
    } else {
        d
    }
}

/// The circles of radius `r` whose image is the cone `q` (camera frame:
/// `Xᵀ q X = 0`): up to two (centre, normal toward the camera) pairs.
pub fn circle_poses_from_cone(q: &Matrix3<f64>, r: f64) -> Vec<(Vector3<f64>, Vector3<f64>)> {
    let sym = (q + q.transpose()) * 0.5;
    let eig = sym.symmetric_eigen();
    let mut pairs: Vec<(f64, Vector3<f64>)> = (0..3)
        .map(|i| (eig.eigenvalues[i], eig.eigenvectors.column(i).into_owned()))
        .collect();
    if pairs.iter().filter(|(l, _)| *l > 0.0).count() < 2 {
        pairs.iter_mut().for_each(|(l, _)| *l = -*l);
    }
    pairs.sort_by(|a, b| b.0.total_cmp(&a.0));
    let [(l1, e1), (l2, e2), (l3, e3)] = [pairs[0], pairs[1], pairs[2]];
    if !(l2 > 0.0 && l3 < 0.0) {
        return Vec::new();
    }
    let _ = e2;
    let s1 = ((l1 - l2) / (l1 - l3)).max(0.0).sqrt();
    let s3 = ((l2 - l3) / (l1 - l3)).max(0.0).sqrt();
    let mut out: Vec<(Vector3<f64>, Vector3<f64>)> = Vec::new();
    for sign in [1.0, -1.0] {
        let n = (e1 * (sign * s1) + e3 * s3).normalize();
        // The section n·X = 1: its centre and radius, then scaled to r.
        let ea = n
            .cross(&if n.x.abs() < 0.9 { Vector3::x() } else { Vector3::y() })
            .normalize();
        let eb = n.cross(&ea);
        let b = Matrix3::from_columns(&[ea, eb, n]);
        let m = b.transpose() * sym * b;
        let a2 = m.fixed_view::<2, 2>(0, 0).into_owned();
        let b2 = m.fixed_view::<2, 1>(0, 2).into_owned();
        let Some(inv) = a2.try_inverse() else { continue };
        let uv = -(inv * b2);
        let k = m[(2, 2)] + (b2.transpose() * uv)[(0, 0)];
        let alpha = 0.5 * a2.trace();
        let rho2 = -k / alpha;
        if rho2.is_nan() || rho2 <= 0.0 {
            continue;
        }
        let mut centre = n + ea * uv[0] + eb * uv[1];
        if centre.z < 0.0 {
            centre = -centre;
        }
        let centre = centre * (r / rho2.sqrt());
        let normal = if n.dot(&centre) > 0.0 { -n } else { n };
        if centre.iter().chain(normal.iter()).all(|v| v.is_finite()) {
            out.push((centre, normal));
        }
        if s1 < 1e-12 {
            break; // a frontal circle: one pose
        }
    }
    out
}

/// A detection refitted in the virtual camera that looks at it (module doc).
pub fn image_circle(pinhole: &Pinhole, index: usize, d: &CircleDetection, radius_m: f64) -> Option<ImageCircle> {
    let (cx, cy) = d.ellipse.centre;
    let z = Vector3::from(pinhole.unproject(cx, cy)?);
    let rv = virtual_frame(&z)?;
    let f = pinhole.focal_px;
    let pts: Vec<(f64, f64)> = d
        .edge_points
        .iter()
        .filter_map(|(u, v)| {
            let b = rv * Vector3::from(pinhole.unproject(*u, *v)?);
            (b.z > 0.0).then(|| (f * b.x / b.z, f * b.y / b.z))
        })
        .collect();
    let fit = fit_ellipse_robust(&pts, 0.35)?;
    let e: Ellipse = fit.ellipse;
    // The fitted centre, back to distorted pixels.
    let centre_v = Vector3::new(e.centre.0 / f, e.centre.1 / f, 1.0);
    let centre_cam = rv.transpose() * centre_v;
    let centre_px = pinhole.project([centre_cam.x, centre_cam.y, centre_cam.z])?;
    // The cone: (f x, f y, z) on the conic, turned back to the camera frame.
    let scale = Matrix3::from_diagonal(&Vector3::new(f, f, 1.0));
    let q_virtual = scale * fit.conic * scale;
    let q = rv.transpose() * q_virtual * rv;
    let poses = circle_poses_from_cone(&q, radius_m);
    if poses.is_empty() {
        return None;
    }
    let (s, c) = e.angle.sin_cos();
    Some(ImageCircle {
        detection: index,
        centre_px,
        shape: (e.a, e.b, line_angle(c, s)),
        poses,
        quality: e.a * d.perimeter_edges / (1.0 + d.fit_rms_px),
    })
}

/// The thesis's `a_g, b_g, γ_g` of `target` seen from `pose` (module doc).
fn predicted_shape(pinhole: &Pinhole, pose: &CameraPose, target: &SurveyedCircle) -> Option<(f64, f64, f64)> {
    let t = pose.to_camera(&target.centre);
    let q = -t; // target to camera, camera frame
    let dist = q.norm();
    let rv = virtual_frame(&t.try_normalize(1e-12)?)?;
    let n = pose.rotation * target.normal;
    let a = target.radius_m / dist * pinhole.focal_px;
    let b = a * (q / dist).dot(&n).abs();
    let axis = rv * n.cross(&q);
    Some((a, b, line_angle(axis.x, axis.y)))
}

/// The thesis's function for one target, square-rooted, over `a`.
fn shape_error(seen: (f64, f64, f64), predicted: (f64, f64, f64)) -> f64 {
    let (ai, bi, gi) = seen;
    let (ag, bg, gg) = predicted;
    let weight = 0.5 * ((ai - bi) + (ag - bg));
    ((ai - ag).powi(2) + (bi - bg).powi(2) + (angle_difference(gi, gg) * weight).powi(2)).sqrt() / ai.max(1e-9)
}

/// The rotation R minimizing `Σ w ‖R x − y‖²` (weighted Kabsch).
fn kabsch(pairs: &[(Vector3<f64>, Vector3<f64>, f64)]) -> Option<Rotation3<f64>> {
    let h: Matrix3<f64> = pairs.iter().map(|(x, y, w)| y * x.transpose() * *w).sum();
    let svd = h.svd(true, true);
    let (u, vt) = (svd.u?, svd.v_t?);
    let d = (u * vt).determinant().signum();
    let r = u * Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, d)) * vt;
    r.iter()
        .all(|v| v.is_finite())
        .then(|| Rotation3::from_matrix_unchecked(r))
}

/// A surveyed target faces the camera at `pose` and is in front of it.
fn faces(pose: &CameraPose, t: &SurveyedCircle) -> bool {
    t.normal.dot(&(pose.centre - t.centre)) > 0.0 && pose.to_camera(&t.centre).z > 0.0
}

/// Detections matched to targets at `pose`: each detection's nearest
/// projected facing target within `threshold_px` whose size agrees; a
/// target claimed twice goes to the nearer. (detection, target, pixels).
fn matches_at(
    pinhole: &Pinhole,
    pose: &CameraPose,
    circles: &[ImageCircle],
    targets: &[SurveyedCircle],
    threshold_px: f64,
    size_factor: f64,
) -> Vec<(usize, usize, f64)> {
    let projected: Vec<Option<((f64, f64), f64)>> = targets
        .iter()
        .map(|t| {
            if !faces(pose, t) {
                return None;
            }
            let p = pose.project(pinhole, &t.centre)?;
            let a = t.radius_m / (t.centre - pose.centre).norm() * pinhole.focal_px;
            Some((p, a))
        })
        .collect();
    let mut out: Vec<(usize, usize, f64)> = Vec::new();
    for (m, c) in circles.iter().enumerate() {
        let best = projected
            .iter()
            .enumerate()
            .filter_map(|(k, p)| {
                let ((u, v), a) = (*p)?;
                let e = (u - c.centre_px.0).hypot(v - c.centre_px.1);
                let ratio = a / c.shape.0;
                (e <= threshold_px && ratio <= size_factor && ratio >= 1.0 / size_factor).then_some((k, e))
            })
            .min_by(|a, b| a.1.total_cmp(&b.1));
        if let Some((k, e)) = best {
            match out.iter().position(|(_, kk, _)| *kk == k) {
                Some(i) if out[i].2 <= e => {}
                Some(i) => out[i] = (m, k, e),
                None => out.push((m, k, e)),
            }
        }
    }
    out
}

/// The point on a target's plane whose image is the ellipse centre at
/// `pose` (module doc). The ellipse is fitted in the virtual camera that
/// looks at the target, so the image plane's normal `f` is the direction
/// to the target, and `d` its distance.
pub fn ellipse_centre_point(pose: &CameraPose, t: &SurveyedCircle) -> Vector3<f64> {
    let to = t.centre - pose.centre;
    let depth = to.norm();
    if depth <= 0.0 {
        return t.centre;
    }
    let f = to / depth;
    let in_plane = f - t.normal * f.dot(&t.normal);
    t.centre - in_plane * (t.radius_m * t.radius_m / depth)
}

/// A hypothesis's assignment: (detection, target) pairs, sorted.
type Assignment = Vec<(usize, usize)>;

/// Two assignments conflict when a detection or a target is given two partners.
fn conflict(a: &Assignment, b: &Assignment) -> bool {
    a.iter().any(|(m, k)| b.iter().any(|(mm, kk)| (m == mm) != (k == kk)))
}

/// The outcome of the search and the refinement.
#[derive(Debug, Clone, PartialEq)]
pub struct CircleRegistration {
    /// The pose, its covariance and verdict (target ids are the survey's).
    pub registration: Registration,
    /// (detection index, target id) of the matched detections.
    pub matches: Vec<(usize, u32)>,
    /// Detections matched to no surveyed target (false or unsurveyed targets).
    pub unmatched: Vec<usize>,
    /// Detections the search could use (a circle pose from their ellipse).
    pub usable: usize,
    /// Hypotheses tried: pair poses judged by the thesis's function, and three-target poses.
    pub hypotheses: usize,
    /// Pairs of (detection pair, target pair) considered before pruning.
    pub pairs_considered: usize,
    /// Detections explained by the best assignment that conflicts with the
    /// chosen one (0 if none was found).
    pub runner_up: usize,
}

/// Finds the correspondences of `detections` to `targets` and registers
/// the photograph (module doc).
pub fn register_circles(
    pinhole: &Pinhole,
    detections: &[CircleDetection],
    targets: &[SurveyedCircle],
    settings: &RegistrationSettings,
    search: &CircleSearchSettings,
) -> CircleRegistration {
    let radius = targets.first().map_or(0.0, |t| t.radius_m);
    let mut circles: Vec<ImageCircle> = detections
        .iter()
        .enumerate()
        .filter_map(|(i, d)| image_circle(pinhole, i, d, radius))
        .collect();
    // Best first: the largest, cleanest ellipses' shapes and distances are the most precise.
    circles.sort_by(|a, b| b.quality.total_cmp(&a.quality));
    let n = circles.len();
    let threshold = settings.inlier_threshold_px;
    let enough = ((search.enough_fraction * n as f64).ceil() as usize)
        .min(search.enough_targets)
        .max(4);
    // The surveyed pairs by baseline, for a range search per detection pair.
    let mut by_baseline: Vec<(f64, usize, usize)> = Vec::with_capacity(targets.len() * targets.len());
    for (g, tg) in targets.iter().enumerate() {
        for (h, th) in targets.iter().enumerate() {
            let baseline = (th.centre - tg.centre).norm();
            if g != h && baseline > 1e-9 {
                by_baseline.push((baseline, g, h));
            }
        }
    }
    by_baseline.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut hypotheses = 0usize;
    let mut pairs_considered = 0usize;
    // (count, error sum, pose, assignment)
    let mut found: Vec<(usize, f64, CameraPose, Assignment)> = Vec::new();
    let mut best_count = 0usize;
    let mut tried_pairs: Vec<(usize, usize)> = Vec::new();
    for span in 1..n {
        for i in 0..n - span {
            tried_pairs.push((i, i + span));
        }
    }
    tried_pairs.sort_by_key(|(i, j)| i + j);
    'search: for (i, j) in tried_pairs {
        let (ci, cj) = (&circles[i], &circles[j]);
        let (pi0, pj0) = (ci.poses[0].0, cj.poses[0].0);
        let seen_baseline = (pj0 - pi0).norm();
        let mean_distance = 0.5 * (pi0.norm() + pj0.norm());
        // |seen − b| ≤ k·d + ρ·b bounds b to [(seen − k·d)/(1 + ρ), (seen + k·d)/(1 − ρ)].
        let slack = search.baseline_of_distance * mean_distance;
        let low = (seen_baseline - slack) / (1.0 + search.baseline_relative);
        let high = (seen_baseline + slack) / (1.0 - search.baseline_relative).max(1e-9);
        let first = by_baseline.partition_point(|(b, _, _)| *b < low);
        let last = by_baseline.partition_point(|(b, _, _)| *b <= high);
        // The angle between the two normals, seen (either pose of each) and surveyed.
        let seen_normal_angles: Vec<f64> = ci
            .poses
            .iter()
            .flat_map(|(_, ni)| cj.poses.iter().map(move |(_, nj)| ni.angle(nj)))
            .collect();
        // Most consistent baselines first.
        let mut candidates: Vec<(f64, usize, usize)> = by_baseline[first..last].to_vec();
        candidates.sort_by(|a, b| (a.0 - seen_baseline).abs().total_cmp(&(b.0 - seen_baseline).abs()));
        for (baseline, g, h) in candidates {
            let (tg, th) = (&targets[g], &targets[h]);
            {
                pairs_considered += 1;
                let tol = slack + search.baseline_relative * baseline;
                if (seen_baseline - baseline).abs() > tol {
                    continue;
                }
                let surveyed_angle = tg.normal.angle(&th.normal);
                if seen_normal_angles
                    .iter()
                    .all(|a| (a - surveyed_angle).abs() > 2.0 * search.max_normal_deg.to_radians())
                {
                    continue;
                }
                for (pi, ni) in &ci.poses {
                    for (pj, nj) in &cj.poses {
                        let seen = pj - pi;
                        let Some(seen_dir) = seen.try_normalize(1e-12) else {
                            continue;
                        };
                        let world_dir = (th.centre - tg.centre) / baseline;
                        let Some(rot) =
                            kabsch(&[(world_dir, seen_dir, 2.0), (tg.normal, *ni, 1.0), (th.normal, *nj, 1.0)])
                        else {
                            continue;
                        };
                        let limit = search.max_normal_deg.to_radians();
                        if (rot * world_dir).angle(&seen_dir) > limit
                            || (rot * tg.normal).angle(ni) > limit
                            || (rot * th.normal).angle(nj) > limit
                        {
                            continue;
                        }
                        let inv = rot.inverse();
                        let centre = 0.5 * ((tg.centre - inv * pi) + (th.centre - inv * pj));
                        let pose = CameraPose { rotation: rot, centre };
                        if !(faces(&pose, tg) && faces(&pose, th)) {
                            continue;
                        }
                        hypotheses += 1;
                        let shapes_agree = [(ci, tg), (cj, th)].iter().all(|(c, t)| {
                            predicted_shape(pinhole, &pose, t)
                                .is_some_and(|p| shape_error(c.shape, p) <= search.max_shape_error)
                        });
                        if !shapes_agree {
                            continue;
                        }
                        // Candidates for the other detections, nearest anchors first.
                        let anchors = [ci.centre_px, cj.centre_px];
                        let mut thirds: Vec<(f64, usize, usize)> = Vec::new();
                        for (m, cm) in circles.iter().enumerate() {
                            if m == i || m == j {
                                continue;
                            }
                            let reach = anchors
                                .iter()
                                .map(|a| (a.0 - cm.centre_px.0).hypot(a.1 - cm.centre_px.1))
                                .fold(f64::INFINITY, f64::min);
                            let radius_px = 3.0 + cm.shape.0 + 0.25 * reach;
                            let mut near: Vec<(f64, usize)> = targets
                                .iter()
                                .enumerate()
                                .filter(|(k, t)| *k != g && *k != h && faces(&pose, t))
                                .filter_map(|(k, t)| {
                                    let (u, v) = pose.project(pinhole, &t.centre)?;
                                    let e = (u - cm.centre_px.0).hypot(v - cm.centre_px.1);
                                    let a = t.radius_m / (t.centre - pose.centre).norm() * pinhole.focal_px;
                                    let ratio = a / cm.shape.0;
                                    // Size, axis ratio and orientation agree with the target's
                                    // radius and normal at the pair's pose (the thesis's function,
                                    // with twice the pair's tolerance: that pose is rough).
                                    let shape_ok = predicted_shape(pinhole, &pose, t)
                                        .is_some_and(|p| shape_error(cm.shape, p) <= 2.0 * search.max_shape_error);
                                    (e <= radius_px
                                        && ratio <= search.size_factor
                                        && ratio >= 1.0 / search.size_factor
                                        && shape_ok)
                                        .then_some((e, k))
                                })
                                .collect();
                            near.sort_by(|a, b| a.0.total_cmp(&b.0));
                            thirds.extend(near.into_iter().take(3).map(|(e, k)| (e + 0.1 * reach, m, k)));
                        }
                        thirds.sort_by(|a, b| a.0.total_cmp(&b.0));
                        let mut detections_tried: Vec<usize> = Vec::new();
                        for (_, m, k) in thirds {
                            if !detections_tried.contains(&m) {
                                if detections_tried.len() == 3 {
                                    continue;
                                }
                                detections_tried.push(m);
                            }
                            hypotheses += 1;
                            let three: Vec<Correspondence> = [(i, g), (j, h), (m, k)]
                                .iter()
                                .map(|(d, t)| Correspondence {
                                    target: *t as u32,
                                    pixel: circles[*d].centre_px,
                                    world: targets[*t].centre.into(),
                                })
                                .collect();
                            let Ok(r) = refine(pinhole, &three, pose, settings.sigma_floor_px) else {
                                continue;
                            };
                            if r.rms_px > threshold {
                                continue;
                            }
                            let matched =
                                matches_at(pinhole, &r.pose, &circles, targets, threshold, search.size_factor);
                            let count = matched.len();
                            if count < 3 {
                                continue;
                            }
                            let mut assignment: Assignment = matched.iter().map(|(m, k, _)| (*m, *k)).collect();
                            assignment.sort_unstable();
                            let error: f64 = matched.iter().map(|(_, _, e)| e).sum();
                            if !found.iter().any(|(_, _, _, a)| *a == assignment) {
                                found.push((count, error, r.pose, assignment));
                            }
                            best_count = best_count.max(count);
                            if best_count >= enough || hypotheses >= search.max_hypotheses {
                                break 'search;
                            }
                        }
                        if hypotheses >= search.max_hypotheses {
                            break 'search;
                        }
                    }
                }
            }
        }
    }
    let seen = n;
    let failed = |reason: String| Registration {
        pose: None,
        covariance: None,
        quality: super::verdict::Quality::failed(reason, seen),
    };
    found.sort_by(|a, b| b.0.cmp(&a.0).then(a.1.total_cmp(&b.1)));
    let Some((_, _, start, assignment)) = found.first().cloned() else {
        return CircleRegistration {
            registration: failed(format!(
                "no assignment of the {} surveyed circles explains three of the {n} circles found ({hypotheses} hypotheses tried)",
                targets.len()
            )),
            matches: Vec::new(),
            unmatched: circles.iter().map(|c| c.detection).collect(),
            usable: n,
            hypotheses,
            pairs_considered,
            runner_up: 0,
        };
    };
    let runner_up = found
        .iter()
        .skip(1)
        .filter(|(_, _, _, a)| conflict(a, &assignment))
        .map(|(c, _, _, _)| *c)
        .max()
        .unwrap_or(0);
    // Refinement with the ellipse-centre points, recomputed at the refined pose.
    let mut pose = start;
    let mut registration = failed("not refined".into());
    for _ in 0..2 {
        let points: Vec<Correspondence> = assignment
            .iter()
            .map(|(m, k)| Correspondence {
                target: targets[*k].id,
                pixel: circles[*m].centre_px,
                world: ellipse_centre_point(&pose, &targets[*k]).into(),
            })
            .collect();
        registration = register(pinhole, &points, settings);
        match registration.pose {
            Some(p) => pose = p,
            None => break,
        }
    }
    registration.quality.targets_seen = n;
    if runner_up >= assignment.len() && registration.quality.verdict != Verdict::Failed {
        registration.quality.verdict = Verdict::Poor;
        registration.quality.reasons.push(format!(
            "ambiguous correspondence: another assignment of surveyed circles explains {runner_up} of the circles found, as many as this pose's {}",
            assignment.len()
        ));
    }
    let matches: Vec<(usize, u32)> = assignment
        .iter()
        .map(|(m, k)| (circles[*m].detection, targets[*k].id))
        .collect();
    let unmatched = circles
        .iter()
        .map(|c| c.detection)
        .filter(|d| !matches.iter().any(|(m, _)| m == d))
        .collect();
    CircleRegistration {
        registration,
        matches,
        unmatched,
        usable: n,
        hypotheses,
        pairs_considered,
        runner_up,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Pinhole {
        Pinhole {
            focal_px: 1400.0,
            principal_px: (800.0, 600.0),
            k1: -0.05,
            k2: 0.01,
            projection: campanile_config::camera::Projection::Pinhole,
        }
    }

    fn pose() -> CameraPose {
        let centre = Vector3::new(3.0, -10.0, 1.6);
        let forward = (Vector3::new(0.0, 0.0, 2.5) - centre).normalize();
        let right = forward.cross(&Vector3::z()).normalize();
        CameraPose::from_axes(right, forward.cross(&right), forward, centre)
    }

    fn wall(n: usize) -> Vec<SurveyedCircle> {
        // A pseudo-random layout on a wall (y = 0) and a side wall (x = −4).
        (0..n)
            .map(|i| {
                let t = i as f64;
                let (x, z) = ((t * 2.371).rem_euclid(7.0) - 3.5, 0.5 + (t * 1.618).rem_euclid(4.0));
                if i % 4 == 3 {
                    SurveyedCircle {
                        id: 100 + i as u32,
                        centre: Vector3::new(-4.0, -1.0 - (t * 0.77).rem_euclid(3.0), z),
                        normal: Vector3::x(),
                        radius_m: 0.1,
                    }
                } else {
                    SurveyedCircle {
                        id: 100 + i as u32,
                        centre: Vector3::new(x, 0.0, z),
                        normal: -Vector3::y(),
                        radius_m: 0.1,
                    }
                }
            })
            .collect()
    }

    /// Exact edge points of a target's image: the circle's rim projected.
    fn detection(p: &CameraPose, t: &SurveyedCircle) -> CircleDetection {
        let e1 = t
            .normal
            .cross(&Vector3::z())
            .try_normalize(1e-9)
            .unwrap_or(Vector3::x());
        let e2 = t.normal.cross(&e1);
        let edge: Vec<(f64, f64)> = (0..64)
            .filter_map(|k| {
                let a = std::f64::consts::TAU * f64::from(k) / 64.0;
                p.project(&camera(), &(t.centre + (e1 * a.cos() + e2 * a.sin()) * t.radius_m))
            })
            .collect();
        let fit = fit_ellipse_robust(&edge, 0.3).expect("an ellipse");
        CircleDetection {
            ellipse: fit.ellipse,
            edge_points: edge,
            fit_rms_px: fit.rms,
            template_residual: 0.0,
            contrast: 100.0,
            contrast_ratio: 8.0,
            inside_spread: 0.0,
            ring_spread: 0.0,
            perimeter_edges: 1.0,
            ncc: 1.0,
        }
    }

    #[test]
    fn the_cone_of_a_projected_circle_gives_back_its_centre_and_normal() {
        let p = pose();
        let t = SurveyedCircle {
            id: 0,
            centre: Vector3::new(1.0, 0.0, 2.0),
            normal: Vector3::new(0.3, -1.0, 0.1).normalize(),
            radius_m: 0.15,
        };
        let c = image_circle(&camera(), 0, &detection(&p, &t), 0.15).expect("a circle");
        let truth_centre = p.to_camera(&t.centre);
        let truth_normal = p.rotation * t.normal;
        let best = c
            .poses
            .iter()
            .map(|(centre, normal)| ((centre - truth_centre).norm(), normal.angle(&truth_normal)))
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .expect("poses");
        assert!(best.0 < 1e-6, "centre off by {} m", best.0);
        assert!(best.1 < 1e-6, "normal off by {} rad", best.1);
        // The thesis's a, b, γ agree with the prediction from the true pose.
        let predicted = predicted_shape(&camera(), &p, &t).expect("in view");
        assert!(shape_error(c.shape, predicted) < 0.02, "{:?} vs {predicted:?}", c.shape);
    }

    #[test]
    fn the_ellipse_centre_is_the_image_of_the_pole_point_not_of_the_centre() {
        let p = pose();
        let t = SurveyedCircle {
            id: 0,
            centre: Vector3::new(-2.0, 0.0, 0.6),
            normal: -Vector3::y(),
            radius_m: 0.4,
        };
        let d = detection(&p, &t);
        let c = image_circle(&camera(), 0, &d, 0.4).expect("a circle");
        let centre_image = p.project(&camera(), &t.centre).expect("in view");
        let pole_image = p.project(&camera(), &ellipse_centre_point(&p, &t)).expect("in view");
        let off = |q: (f64, f64)| (q.0 - c.centre_px.0).hypot(q.1 - c.centre_px.1);
        assert!(
            off(centre_image) > 0.05,
            "the bias is measurable: {}",
            off(centre_image)
        );
        assert!(off(pole_image) < 1e-3, "corrected: {}", off(pole_image));
    }

    #[test]
    fn twenty_of_sixty_targets_seen_register_with_the_right_assignment() {
        let p = pose();
        let targets = wall(60);
        let mut detections: Vec<CircleDetection> = targets
            .iter()
            .filter(|t| faces(&p, t))
            .filter_map(|t| {
                let (u, v) = p.project(&camera(), &t.centre)?;
                ((0.0..1600.0).contains(&u) && (0.0..1200.0).contains(&v)).then(|| detection(&p, t))
            })
            .collect();
        let visible = detections.len();
        assert!(visible >= 10, "{visible} visible");
        // A false target: a disc of the same size not in the survey.
        let fake = SurveyedCircle {
            id: 999,
            centre: Vector3::new(0.2, 0.0, 3.3),
            normal: -Vector3::y(),
            radius_m: 0.1,
        };
        detections.push(detection(&p, &fake));
        let r = register_circles(
            &camera(),
            &detections,
            &targets,
            &RegistrationSettings::default(),
            &CircleSearchSettings::default(),
        );
        let reg = &r.registration;
        let got = reg.pose.expect("a pose");
        assert!((got.centre - p.centre).norm() < 1e-4, "{:?}", got.centre - p.centre);
        assert!(got.angle_to_deg(&p) < 1e-3);
        assert_eq!(reg.quality.verdict, Verdict::Ok, "{:?}", reg.quality.reasons);
        assert_eq!(r.matches.len(), visible);
        assert_eq!(r.unmatched, [visible]);
        assert!(r.hypotheses > 0 && r.hypotheses < 1000, "{} hypotheses", r.hypotheses);
    }
}

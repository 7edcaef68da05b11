//! Groups that are spheres: a least-squares sphere and a tessellated mesh
//! of it.
//!
//! A ball on a table, a lamp's globe, a dome: a few hundred points of a
//! curved surface meshed in scan order give one partial, noisy shell per
//! scan, overlapping and spiked by the mixed pixels at the silhouette; a
//! renderer then sees the wrong normals and the wrong outline. When a
//! curved group's points lie on a sphere within the planar tolerance
//! ([`super::MeshOptions::planar_rms_m`]: the same noise figure), the
//! sphere is the better model, and the one the scene needs. The fit is
//! started from the sphere through four of the points with the least median
//! distance to all (300 seeded draws), refined by Gauss–Newton on the
//! geometric distance |p − c| − r (a four-point sphere is Kåsa's algebraic
//! |p|² + D·p + E = 0, linear), refitted
//! three times on the 80 % of the points nearest it (stray points pull the
//! first fit off) and three times on the points within 3 σ of it (σ from
//! the median absolute residual). It is kept when at least [`INLIER_SHARE`] of the
//! points are within, their RMS is within the tolerance, and the points
//! span at least a radius across (a cap of 60° or more, so that the radius
//! is measured rather than guessed).

use nalgebra::{Matrix4, Vector3, Vector4};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::TriangleMesh;
use crate::segment::normals::robust_spread;

/// The share of a group's points that must lie on its sphere.
pub const INLIER_SHARE: f64 = 0.8;
/// Refits on the nearest [`INLIER_SHARE`] of the points, then as many
/// without the points beyond 3 σ.
const REFITS: usize = 3;
/// Gauss–Newton steps per fit.
const STEPS: usize = 10;
/// Four-point spheres tried for the start.
const TRIALS: usize = 300;

/// A sphere fitted to points.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SphereFit {
    /// Centre, metres.
    pub centre: Vector3<f64>,
    /// Radius, metres.
    pub radius: f64,
    /// RMS geometric residual of the points kept, metres.
    pub rms_m: f64,
    /// The share of the points kept.
    pub inliers: f64,
}

/// The algebraic sphere through `points`; `None` when degenerate.
fn algebraic(points: &[Vector3<f64>]) -> Option<(Vector3<f64>, f64)> {
    // Centred for conditioning.
    let mean = points.iter().sum::<Vector3<f64>>() / points.len() as f64;
    let mut ata = Matrix4::zeros();
    let mut atb = Vector4::zeros();
    for p in points {
        let q = p - mean;
        let row = Vector4::new(q.x, q.y, q.z, 1.0);
        ata += row * row.transpose();
        atb -= row * q.norm_squared();
    }
    let x = ata.lu().solve(&atb)?;
    let centre = Vector3::new(-x[0] / 2.0, -x[1] / 2.0, -x[2] / 2.0);
    let r2 = centre.norm_squared() - x[3];
    (r2 > 0.0 && r2.is_finite()).then(|| (centre + mean, r2.sqrt()))
}

/// The sphere through four of `points` whose median distance to all of
/// them is least, over [`TRIALS`] seeded draws (least median of squares:
/// stray points, under half of them, do not move it).
fn least_median(points: &[Vector3<f64>]) -> Option<(Vector3<f64>, f64)> {
    let mut rng = ChaCha8Rng::seed_from_u64(points.len() as u64);
    let mut best: Option<(f64, (Vector3<f64>, f64))> = None;
    let mut deviations = vec![0.0; points.len()];
    for _ in 0..TRIALS {
        let four: Vec<Vector3<f64>> = (0..4).map(|_| points[rng.random_range(0..points.len())]).collect();
        let Some((c, r)) = algebraic(&four) else { continue };
        for (d, p) in deviations.iter_mut().zip(points) {
            *d = ((p - c).norm() - r).abs();
        }
        let mid = deviations.len() / 2;
        let median = *deviations.select_nth_unstable_by(mid, f64::total_cmp).1;
        if median.is_finite() && best.is_none_or(|(m, _)| median < m) {
            best = Some((median, (c, r)));
        }
    }
    best.map(|(_, sphere)| sphere)
}

/// Gauss–Newton on |p − c| − r from `start`.
fn refine(points: &[Vector3<f64>], (mut c, mut r): (Vector3<f64>, f64)) -> (Vector3<f64>, f64) {
    for _ in 0..STEPS {
        let mut jtj = Matrix4::zeros();
        let mut jtr = Vector4::zeros();
        for p in points {
            let d = p - c;
            let n = d.norm();
            if n <= 0.0 {
                continue;
            }
            let j = Vector4::new(-d.x / n, -d.y / n, -d.z / n, -1.0);
            let res = n - r;
            jtj += j * j.transpose();
            jtr += j * res;
        }
        let Some(step) = jtj.lu().solve(&-jtr) else { break };
        c += Vector3::new(step[0], step[1], step[2]);
        r += step[3];
        if step.norm() < 1e-9 {
            break;
        }
    }
    (c, r)
}

/// The sphere through `points` within `tolerance_m` RMS, or `None` when
/// they are not a sphere (see the module's criteria).
pub fn fit_sphere(points: &[Vector3<f64>], tolerance_m: f64) -> Option<SphereFit> {
    if points.len() < 10 {
        return None;
    }
    let (mut c, mut r) = least_median(points)?;
    let mut kept: Vec<Vector3<f64>> = Vec::new();
    // First the nearest share of the points (stray points can pull the
    // first fit far off, and a far-off fit's σ is large), then those
    // within 3 σ.
    for round in 0..2 * REFITS {
        let mut deviations: Vec<f64> = points.iter().map(|p| ((p - c).norm() - r).abs()).collect();
        let cut = if round < REFITS {
            let k = ((INLIER_SHARE * points.len() as f64) as usize).min(points.len() - 1);
            *deviations.select_nth_unstable_by(k, f64::total_cmp).1
        } else {
            3.0 * robust_spread(deviations.into_iter(), 0.0).max(1e-6)
        };
        kept = points
            .iter()
            .copied()
            .filter(|p| ((p - c).norm() - r).abs() <= cut)
            .collect();
        if kept.len() < 10 {
            return None;
        }
        (c, r) = refine(&kept, (c, r));
    }
    let rms = (kept.iter().map(|p| ((p - c).norm() - r).powi(2)).sum::<f64>() / kept.len() as f64).sqrt();
    let inliers = kept.len() as f64 / points.len() as f64;
    let (lo, hi) = kept
        .iter()
        .fold((kept[0], kept[0]), |(lo, hi), p| (lo.inf(p), hi.sup(p)));
    let ok = r.is_finite() && r > 0.0 && rms <= tolerance_m && inliers >= INLIER_SHARE && (hi - lo).max() >= r;
    ok.then_some(SphereFit {
        centre: c,
        radius: r,
        rms_m: rms,
        inliers,
    })
}

/// A UV sphere of `rings` × `2 rings` quads (triangles at the poles),
/// normals outward.
pub fn sphere_mesh(sphere: &SphereFit, rings: usize) -> TriangleMesh {
    let rings = rings.max(2);
    let segments = 2 * rings;
    let mut mesh = TriangleMesh::default();
    let point = |i: usize, j: usize| {
        let theta = std::f64::consts::PI * i as f64 / rings as f64;
        let phi = 2.0 * std::f64::consts::PI * j as f64 / segments as f64;
        sphere.centre + sphere.radius * Vector3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos())
    };
    // Poles once, rings between.
    mesh.positions.push(point(0, 0));
    for i in 1..rings {
        for j in 0..segments {
            mesh.positions.push(point(i, j));
        }
    }
    mesh.positions.push(point(rings, 0));
    let south = (mesh.positions.len() - 1) as u32;
    let at = |i: usize, j: usize| (1 + (i - 1) * segments + j % segments) as u32;
    for j in 0..segments {
        mesh.triangles.push([0, at(1, j), at(1, j + 1)]);
        mesh.triangles.push([at(rings - 1, j), south, at(rings - 1, j + 1)]);
    }
    for i in 1..rings - 1 {
        for j in 0..segments {
            mesh.triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            mesh.triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    mesh
}

/// The share of a group's mesh vertices within the tolerance of a sphere
/// for the sphere to cover it (the rest: mixed pixels along its outline).
pub const COVERED_SHARE: f64 = 0.9;

/// The cover's tolerance is at most this share of the ball's radius: a
/// 2 cm band around a 5.3 cm ball (the Stanford bunny's body, fitted as
/// one) took in its flat base (`validation/scans/bunnyInt19.e57`).
pub const COVER_RADIUS_SHARE: f64 = 0.1;

/// Marks the groups of `meshes` that are pieces of another group's
/// fitted sphere as covered by it ([`super::GroupMesh::covered_by`]) and
/// empties their meshes. A ball the segmentation split in pieces (denser
/// scans: the room's spheres came in two or three groups at 180 × 360)
/// would otherwise be meshed as overlapping whole spheres, or as a sphere
/// and a shell inside it. A sphere covers another sphere with a centre and
/// radius within the tolerance of its own, and any smaller group all of
/// whose mesh vertices but a tenth ([`COVERED_SHARE`]) lie within the
/// tolerance of its surface, the tolerance being `tolerance_m` or
/// [`COVER_RADIUS_SHARE`] of the radius, whichever is less; the groups
/// with the most points cover first.
pub fn cover_pieces(meshes: &mut [super::GroupMesh], tolerance_m: f64) {
    let mut balls: Vec<(usize, SphereFit)> = meshes
        .iter()
        .enumerate()
        .filter_map(|(k, m)| Some((k, m.sphere?)))
        .collect();
    balls.sort_by_key(|&(k, _)| (std::cmp::Reverse(meshes[k].points), k));
    for (i, &(k, ball)) in balls.iter().enumerate() {
        if meshes[k].covered_by.is_some() {
            continue;
        }
        let cover = meshes[k].group;
        let tolerance_m = tolerance_m.min(COVER_RADIUS_SHARE * ball.radius);
        for j in 0..meshes.len() {
            let m = &meshes[j];
            if j == k || m.covered_by.is_some() || m.mesh.is_empty() || m.points > meshes[k].points {
                continue;
            }
            let on = match m.sphere {
                Some(other) => {
                    // Only spheres after this one in the order are covered.
                    balls[i + 1..].iter().any(|&(b, _)| b == j)
                        && (other.centre - ball.centre).norm() <= tolerance_m
                        && (other.radius - ball.radius).abs() <= tolerance_m
                }
                None => {
                    let near = m
                        .mesh
                        .positions
                        .iter()
                        .filter(|p| ((*p - ball.centre).norm() - ball.radius).abs() <= tolerance_m)
                        .count();
                    near as f64 >= COVERED_SHARE * m.mesh.positions.len() as f64
                }
            };
            if on {
                meshes[j].covered_by = Some(cover);
                meshes[j].mesh = super::TriangleMesh::default();
                meshes[j].outer.clear();
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand_distr::{Distribution, Normal};

    /// Points on the near half of a 20 cm ball, 3 mm noise, and `mixed`
    /// stray points between it and a wall 2 m behind.
    fn ball(mixed: usize) -> Vec<Vector3<f64>> {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let noise = Normal::new(0.0, 0.003).unwrap();
        let centre = Vector3::new(2.0, 1.8, 0.95);
        let mut points = Vec::new();
        for _ in 0..200 {
            let (u, v): (f64, f64) = (rng.random_range(0.0..1.0), rng.random_range(0.0..1.0));
            let z = v * 2.0 - 1.0;
            let phi = std::f64::consts::PI * (1.0 + u);
            let d = Vector3::new((1.0 - z * z).sqrt() * phi.cos(), (1.0 - z * z).sqrt() * phi.sin(), z);
            points.push(centre + (0.2 + noise.sample(&mut rng)) * d);
        }
        for _ in 0..mixed {
            points.push(centre + Vector3::new(rng.random_range(-0.2..0.2), rng.random_range(0.3..2.0), 0.0));
        }
        points
    }

    #[test]
    fn a_noisy_half_ball_with_stray_points_is_its_sphere() {
        let fit = fit_sphere(&ball(15), 0.01).unwrap();
        assert!((fit.centre - Vector3::new(2.0, 1.8, 0.95)).norm() < 0.002, "{fit:?}");
        assert!((fit.radius - 0.2).abs() < 0.002, "{fit:?}");
        assert!(fit.rms_m < 0.0035, "{fit:?}");
        // The 15 stray points of 215 are left out.
        assert!((fit.inliers - 200.0 / 215.0).abs() < 0.01, "{fit:?}");
        let mesh = sphere_mesh(&fit, 12);
        assert_eq!(mesh.triangles.len(), 2 * 24 + 2 * 24 * 10);
        // Area within 2 % of 4πr² (the facets' sagitta), normals outward.
        let area = mesh.area();
        assert!(
            (area / (4.0 * std::f64::consts::PI * fit.radius.powi(2)) - 1.0).abs() < 0.02,
            "{area}"
        );
        for t in 0..mesh.triangles.len() {
            let [a, b, c] = mesh.corners(t);
            assert!(
                mesh.area_normal(t).dot(&((a + b + c) / 3.0 - fit.centre)) > 0.0,
                "triangle {t}"
            );
        }
    }

    #[test]
    fn a_plane_a_cylinder_and_a_small_cap_are_not_spheres() {
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let noise = Normal::new(0.0, 0.003).unwrap();
        let plane: Vec<Vector3<f64>> = (0..200)
            .map(|_| {
                Vector3::new(
                    rng.random_range(0.0..1.0),
                    rng.random_range(0.0..1.0),
                    noise.sample(&mut rng),
                )
            })
            .collect();
        assert!(fit_sphere(&plane, 0.01).is_none());
        // A cylinder of 20 cm radius, 1 m long, its near half.
        let cylinder: Vec<Vector3<f64>> = (0..300)
            .map(|_| {
                let a = rng.random_range(0.0..std::f64::consts::PI);
                Vector3::new(0.2 * a.cos(), 0.2 * a.sin(), rng.random_range(0.0..1.0))
            })
            .collect();
        assert!(fit_sphere(&cylinder, 0.01).is_none());
        // A 20° cap of a 1 m sphere: 35 cm across, under a radius.
        let cap: Vec<Vector3<f64>> = (0..200)
            .map(|_| {
                let (t, p) = (
                    rng.random_range(0.0..0.17f64),
                    rng.random_range(0.0..std::f64::consts::TAU),
                );
                (1.0 + noise.sample(&mut rng)) * Vector3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
            })
            .collect();
        assert!(fit_sphere(&cap, 0.01).is_none());
    }

    /// A group of `points` points with `mesh`, a sphere's when `ball`.
    fn group(group: u32, points: usize, ball: Option<SphereFit>, mesh: TriangleMesh) -> crate::mesh::GroupMesh {
        crate::mesh::GroupMesh {
            group,
            name: format!("surface_{group}"),
            points,
            method: if ball.is_some() {
                crate::mesh::MeshMethod::Sphere
            } else {
                crate::mesh::MeshMethod::ScanGrid
            },
            plane_rms_m: None,
            folded: 0,
            triangles_before: mesh.triangles.len(),
            simplify_error_m: 0.0,
            pieces: 0,
            unmeshed_points: 0,
            spacing_m: None,
            corners_moved: 0,
            sphere: ball,
            covered_by: None,
            slabs: Vec::new(),
            outer: Vec::new(),
            mesh,
        }
    }

    #[test]
    fn pieces_of_one_ball_are_covered_by_its_sphere() {
        let ball = |x: f64, r: f64| SphereFit {
            centre: Vector3::new(x, 0.0, 1.0),
            radius: r,
            rms_m: 0.003,
            inliers: 1.0,
        };
        // The ball's main piece, a second piece fitted 4 mm off, a shell
        // of its scan-order triangles 3 mm proud, a second ball 0.5 m
        // away, and a wall patch through the ball's middle.
        let main = ball(0.0, 0.2);
        let second = ball(0.004, 0.195);
        let shell = {
            let mut m = sphere_mesh(&ball(0.0, 0.203), 6);
            m.triangles.truncate(20);
            m
        };
        let other = ball(0.5, 0.2);
        let wall = TriangleMesh {
            positions: vec![
                Vector3::new(-0.3, 0.0, 0.7),
                Vector3::new(0.3, 0.0, 0.7),
                Vector3::new(0.3, 0.0, 1.3),
            ],
            triangles: vec![[0, 1, 2]],
        };
        // A 5 cm ball (0.5 cm tolerance) and a 6 × 6 cm square touching
        // its bottom: the square's corners 1.6 cm off the ball.
        let small = ball(2.0, 0.05);
        let base = TriangleMesh {
            positions: [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0), (0.0, 0.0)]
                .map(|(x, y)| Vector3::new(2.0 + 0.03 * x, 0.03 * y, 0.95))
                .to_vec(),
            triangles: vec![[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]],
        };
        let mut meshes = vec![
            group(5, 500, Some(small), sphere_mesh(&small, 12)),
            group(6, 100, None, base),
            group(0, 90, Some(second), sphere_mesh(&second, 12)),
            group(1, 300, Some(main), sphere_mesh(&main, 12)),
            group(2, 60, None, shell),
            group(3, 280, Some(other), sphere_mesh(&other, 12)),
            group(4, 50, None, wall),
        ];
        cover_pieces(&mut meshes, 0.02);
        let covered: Vec<Option<u32>> = meshes.iter().map(|m| m.covered_by).collect();
        assert_eq!(covered, [None, None, Some(1), None, Some(1), None, None]);
        assert!(meshes[2].mesh.is_empty() && meshes[4].mesh.is_empty());
        assert_eq!(meshes[3].mesh.triangles.len(), 528);
        assert_eq!(meshes[6].mesh.triangles.len(), 1);
        assert_eq!(meshes[1].mesh.triangles.len(), 4);
    }
}

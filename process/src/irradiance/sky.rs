//! Irradiance from the sky by adaptive subdivision of spherical polygons,
//! Appendix B.
//!
//! 1. The sky hemisphere (z ≥ 0) starts as the four upper faces of the
//!    octahedron: spherical triangles with 90° edges.
//! 2. Each is clipped by the receiver's tangent plane (keep `n · ω ≥ 0`,
//!    [`clip_to_hemisphere`]) and fanned back into spherical triangles.
//! 3. Each triangle is split at its edge midpoints into four, recursively,
//!    until the radiance sampled at its three vertices and its centroid is
//!    linear within the relative tolerance in every channel (the centroid's
//!    radiance and the vertices' mean agree; see [`SkySubdivision`]), or the
//!    depth limit is reached. Children tile their parent exactly, so the flux
//!    sums are exact at every depth.
//! 4. A leaf's radiance `L̄` is the cosine-weighted mean of its samples with
//!    the degree-2 triangle rule's weights (3/4 at the centroid, 1/12 at each
//!    vertex), `L̄ = Σ wₖ cₖ Lₖ / Σ wₖ cₖ`, `cₖ = max(0, ωₖ · n)`; its
//!    irradiance is `L̄ · (F · n)` with `F` its vector flux, eq. (B.1). A
//!    uniform sky is therefore integrated exactly.
//!
//! Occluders, two ways ([`Occlusion`]):
//!
//! - **Projected** (the thesis's): each leaf's open part is the patch minus
//!   the scene's triangles projected onto the sphere, exact at any depth
//!   ([`super::occluder_projection`]); patches split only for radiance. A
//!   leaf partly cut away takes the radiance at its open part's mean
//!   direction (the normalized flux), not the patch's mean.
//! - **Shadow rays**: each sample's radiance is the sky's times its visibility, a shadow ray
//!   from the point toward the sample; occluders are black (light they
//!   reflect is gathered elsewhere, §5.4). Where visibility differs among a
//!   patch's vertices, edge midpoints and centroid, the patch is split, so
//!   occluder silhouettes are refined to the depth limit. A silhouette that
//!   cuts a patch between all seven samples is missed at that depth.

use nalgebra::Vector3;

use super::IrradianceError;
use super::clip::{SLIVER_SR, clip_to_hemisphere};
use super::occluder_projection::ProjectedOccluders;
use super::spherical_polygon::{SphericalPolygon, triangle_flux, triangle_solid_angle};
use crate::render::{Ray, Scene};

/// Offset of shadow-ray origins off the receiving surface, metres (scaled
/// up with the distance from the origin).
pub const SHADOW_RAY_OFFSET: f64 = 1e-6;

/// Sample directions on the horizon (z = 0) are evaluated at this height,
/// so that a sky function returning zero for `z ≤ 0` sees the sky's limit.
pub const HORIZON_LIFT: f64 = 1e-12;

/// How finely the sky is subdivided.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SkySubdivision {
    /// Relative tolerance on the radiance's departure from linear over a
    /// patch: a patch is split while `|L(centroid) − mean of L(vertices)| >
    /// tolerance · mean` in some channel. (Asking the samples themselves to
    /// agree, as the thesis's "almost uniform" reads, costs O(1/tolerance)
    /// depth for an error the leaf rule already cancels to first order.)
    pub tolerance: f64,
    /// Depth below the octant faces at which patches are always split.
    pub min_depth: u32,
    /// Depth below the octant faces at which patches are never split.
    pub max_depth: u32,
}

impl Default for SkySubdivision {
    fn default() -> Self {
        SkySubdivision {
            tolerance: 1e-3,
            min_depth: 2,
            max_depth: 12,
        }
    }
}

/// Irradiance from the sky and how it was gathered.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SkyIrradiance {
    /// Irradiance per channel, W·m⁻².
    pub rgb: [f64; 3],
    /// Leaf patches summed.
    pub patches: usize,
    /// Deepest subdivision reached.
    pub max_depth: u32,
    /// Solid angle of the sky above the tangent plane, sr (occluded parts included).
    pub solid_angle: f64,
    /// Radiance evaluations of the sky function.
    pub evaluations: usize,
}

/// A sample: direction and the radiance seen along it (visibility applied).
#[derive(Clone, Copy)]
struct Sample {
    dir: Vector3<f64>,
    radiance: [f64; 3],
    visible: bool,
}

struct Gather<'a, F> {
    sky: &'a F,
    normal: Vector3<f64>,
    origin: Vector3<f64>,
    occluders: Option<&'a Scene>,
    projected: Option<ProjectedOccluders>,
    subdivision: SkySubdivision,
    result: SkyIrradiance,
}

impl<F: Fn([f64; 3]) -> [f64; 3]> Gather<'_, F> {
    fn sample(&mut self, dir: Vector3<f64>) -> Sample {
        self.result.evaluations += 1;
        let visible = self.occluders.is_none_or(|scene| {
            !scene.occluded(
                &Ray {
                    origin: self.origin,
                    direction: dir,
                },
                f64::INFINITY,
            )
        });
        let radiance = if visible {
            // Sky functions commonly give zero at and below the horizon (the
            // ground's side): samples on it are taken just above it.
            let l = (self.sky)([dir.x, dir.y, dir.z.max(HORIZON_LIFT)]);
            l.map(|x| if x.is_finite() { x } else { 0.0 })
        } else {
            [0.0; 3]
        };
        Sample { dir, radiance, visible }
    }

    fn triangle(&mut self, t: [Sample; 3], depth: u32) {
        let [a, b, c] = t;
        let omega = triangle_solid_angle(&a.dir, &b.dir, &c.dir);
        if omega < SLIVER_SR {
            return;
        }
        let centroid = self.sample((a.dir + b.dir + c.dir).normalize());
        let samples = [a, b, c, centroid];
        let s = self.subdivision;
        // With occluders the edge midpoints join the visibility test (they
        // are the children's vertices, so they cost nothing when it splits).
        let mids = (self.occluders.is_some() && depth < s.max_depth).then(|| {
            [
                self.sample((a.dir + b.dir).normalize()),
                self.sample((b.dir + c.dir).normalize()),
                self.sample((c.dir + a.dir).normalize()),
            ]
        });
        let same_visibility = mids.is_none_or(|m| samples.iter().chain(&m).all(|x| x.visible == a.visible));
        let split = depth < s.max_depth && (depth < s.min_depth || !same_visibility || !uniform(&samples, s.tolerance));
        if split {
            let [mab, mbc, mca] = match mids {
                Some(m) => m,
                None => [
                    self.sample((a.dir + b.dir).normalize()),
                    self.sample((b.dir + c.dir).normalize()),
                    self.sample((c.dir + a.dir).normalize()),
                ],
            };
            self.triangle([a, mab, mca], depth + 1);
            self.triangle([mab, b, mbc], depth + 1);
            self.triangle([mca, mbc, c], depth + 1);
            self.triangle([mab, mbc, mca], depth + 1);
            return;
        }
        let (flux, partial) = match &self.projected {
            Some(p) => p.open_flux(&a.dir, &b.dir, &c.dir),
            None => (triangle_flux(&a.dir, &b.dir, &c.dir), false),
        };
        let cos_flux = flux.dot(&self.normal);
        // A patch partly cut away: the radiance at its open part's mean
        // direction (normalized flux), which a radiance linear over the
        // patch gives to second order; the patch's mean would be off to
        // first order in its size.
        let mean = match flux.try_normalize(1e-300) {
            Some(d) if partial => self.sample(d).radiance,
            Some(_) | None if partial => [0.0; 3],
            _ => leaf_radiance(&samples, &self.normal),
        };
        for (e, l) in self.result.rgb.iter_mut().zip(mean) {
            *e += l * cos_flux;
        }
        self.result.patches += 1;
        self.result.max_depth = self.result.max_depth.max(depth);
        self.result.solid_angle += omega;
    }
}

/// Quadrature weights of the samples `[a, b, c, centroid]`: the degree-2
/// rule for triangles.
const WEIGHTS: [f64; 4] = [1.0 / 12.0, 1.0 / 12.0, 1.0 / 12.0, 0.75];

/// Whether the patch's radiance is linear to within `tolerance`: in every
/// channel the centroid's radiance and the mean of the vertices' agree
/// within `tolerance` times the patch's mean. The leaf rule is exact for
/// linear radiance, so this second difference, not the raw spread, is what
/// its error follows; a visibility change among the samples always fails it.
fn uniform(samples: &[Sample; 4], tolerance: f64) -> bool {
    (0..3).all(|ch| {
        let vertices = (samples[0].radiance[ch] + samples[1].radiance[ch] + samples[2].radiance[ch]) / 3.0;
        let centroid = samples[3].radiance[ch];
        let mean = 0.25 * (3.0 * vertices + centroid);
        (vertices - centroid).abs() <= tolerance * mean.abs()
    })
}

/// The cosine-weighted mean radiance of a leaf (module documentation, 4).
fn leaf_radiance(samples: &[Sample; 4], normal: &Vector3<f64>) -> [f64; 3] {
    let weights: Vec<f64> = samples
        .iter()
        .zip(WEIGHTS)
        .map(|(s, w)| w * s.dir.dot(normal).max(0.0))
        .collect();
    let total: f64 = weights.iter().sum();
    let (weights, total) = if total > 0.0 {
        (weights, total)
    } else {
        (WEIGHTS.to_vec(), 1.0)
    };
    [0, 1, 2].map(|ch| {
        samples
            .iter()
            .zip(&weights)
            .map(|(s, w)| w * s.radiance[ch])
            .sum::<f64>()
            / total
    })
}

/// Irradiance from the sky at `point` on the side `normal` of a surface,
/// Appendix B: the sky hemisphere clipped by the tangent plane, subdivided
/// adaptively, each patch's vector flux (eq. B.1) dotted with the normal
/// and weighted by its radiance.
///
/// `sky` gives the radiance per channel from a unit direction (world frame,
/// z up); it is only asked about directions with z ≥ 0, and non-finite
/// values count as zero. `occluders`, if any, block the sky, found by
/// shadow rays (module documentation; [`sky_irradiance_with`] chooses).
pub fn sky_irradiance<F: Fn([f64; 3]) -> [f64; 3]>(
    point: &Vector3<f64>,
    normal: &Vector3<f64>,
    sky: &F,
    occluders: Option<&Scene>,
    subdivision: &SkySubdivision,
) -> Result<SkyIrradiance, IrradianceError> {
    let occlusion = occluders.map_or(Occlusion::None, Occlusion::ShadowRays);
    sky_irradiance_with(point, normal, sky, occlusion, subdivision)
}

/// How a scene blocks the sky.
#[derive(Debug, Clone, Copy)]
pub enum Occlusion<'a> {
    /// Nothing does.
    None,
    /// Shadow rays at the subdivision's samples.
    ShadowRays(&'a Scene),
    /// The scene's triangles projected onto the sphere and cut out of each
    /// patch (Appendix B; [`super::occluder_projection`]).
    Projected(&'a Scene),
}

/// [`sky_irradiance`] with the occlusion method chosen.
pub fn sky_irradiance_with<F: Fn([f64; 3]) -> [f64; 3]>(
    point: &Vector3<f64>,
    normal: &Vector3<f64>,
    sky: &F,
    occlusion: Occlusion<'_>,
    subdivision: &SkySubdivision,
) -> Result<SkyIrradiance, IrradianceError> {
    let n = super::unit_normal(normal)?;
    if !point.iter().all(|x| x.is_finite()) {
        return Err(IrradianceError::BadPoint {
            point: [point.x, point.y, point.z],
        });
    }
    if !(subdivision.tolerance.is_finite() && subdivision.tolerance >= 0.0) {
        return Err(IrradianceError::BadTolerance {
            tolerance: subdivision.tolerance,
        });
    }
    if subdivision.max_depth > MAX_DEPTH_LIMIT {
        return Err(IrradianceError::DepthTooLarge {
            depth: subdivision.max_depth,
            limit: MAX_DEPTH_LIMIT,
        });
    }
    let origin = point + n * SHADOW_RAY_OFFSET * (1.0 + point.norm() * 1e-3);
    let (occluders, projected) = match occlusion {
        Occlusion::None => (None, None),
        Occlusion::ShadowRays(scene) => (Some(scene), None),
        Occlusion::Projected(scene) => (None, Some(ProjectedOccluders::new(scene, &origin, &n))),
    };
    let mut gather = Gather {
        sky,
        normal: n,
        origin,
        occluders,
        projected,
        subdivision: *subdivision,
        result: SkyIrradiance {
            rgb: [0.0; 3],
            patches: 0,
            max_depth: 0,
            solid_angle: 0.0,
            evaluations: 0,
        },
    };
    for face in upper_octahedron() {
        let Some(piece) = clip_to_hemisphere(&face, &n)? else {
            continue;
        };
        let vs = piece.vertices();
        let samples: Vec<Sample> = vs.iter().map(|v| gather.sample(*v)).collect();
        for k in 1..samples.len() - 1 {
            gather.triangle([samples[0], samples[k], samples[k + 1]], 0);
        }
    }
    Ok(gather.result)
}

/// The deepest subdivision allowed: 4²⁰ patches per face would not fit in memory or time.
pub const MAX_DEPTH_LIMIT: u32 = 20;

/// The four upper faces of the octahedron, counter-clockwise seen from outside.
fn upper_octahedron() -> [SphericalPolygon; 4] {
    let z = Vector3::z();
    let ring = [Vector3::x(), Vector3::y(), -Vector3::x(), -Vector3::y()];
    [0, 1, 2, 3].map(|i| SphericalPolygon::from_unit_unchecked(vec![ring[i], ring[(i + 1) % 4], z]))
}

#[cfg(test)]
mod tests {
    use std::f64::consts::PI;

    use super::*;
    use crate::irradiance::reference::{ReferenceGrid, reference_sky_irradiance};
    use crate::render::{Material, Triangle};
    use crate::sky::{Atmosphere, COS_XI_FLOOR, Daylight, direction};

    /// Clear daylight (CIE type 12) with the sun at `elevation_deg`, `azimuth_deg`.
    fn daylight(elevation_deg: f64, azimuth_deg: f64) -> Daylight {
        let sun = direction((90.0 - elevation_deg).to_radians(), azimuth_deg.to_radians());
        Daylight::clear(sun, &Atmosphere::clear())
    }

    /// A plane facing azimuth 170° (just east of south), tilted by `tilt_deg`.
    fn tilted(tilt_deg: f64) -> Vector3<f64> {
        let d = direction(tilt_deg.to_radians(), 170f64.to_radians());
        Vector3::new(d[0], d[1], d[2])
    }

    fn reference(day: &Daylight, n: &Vector3<f64>, scale: usize) -> [f64; 3] {
        let s = day.sun_direction;
        let grid = ReferenceGrid {
            azimuth_panels: 48 * scale,
            zenith_panels: 24 * scale,
            features: vec![Vector3::new(s[0], s[1], s[2])],
            zenith_breaks: vec![COS_XI_FLOOR.acos()],
        };
        reference_sky_irradiance(n, &|d| day.sky_radiance(d), &grid)
    }

    fn relative_error(e: &[f64; 3], r: &[f64; 3]) -> f64 {
        (0..3).map(|c| ((e[c] - r[c]) / r[c]).abs()).fold(0.0, f64::max)
    }

    #[test]
    fn the_reference_quadrature_is_converged() {
        let day = daylight(20.0, 200.0);
        for tilt in [45.0, 135.0] {
            let n = tilted(tilt);
            let (a, b) = (reference(&day, &n, 1), reference(&day, &n, 2));
            assert!(relative_error(&a, &b) < 1e-8, "tilt {tilt}: {a:?} vs {b:?}");
        }
    }

    #[test]
    fn clear_sky_on_tilted_planes_is_within_1e_4_of_the_reference() {
        let s = SkySubdivision {
            tolerance: 1e-3,
            ..SkySubdivision::default()
        };
        for (elevation, azimuth) in [(60.0, 30.0), (20.0, 200.0)] {
            let day = daylight(elevation, azimuth);
            for tilt in [0.0, 45.0, 90.0, 135.0] {
                let n = tilted(tilt);
                let r = reference(&day, &n, 1);
                let e = sky_irradiance(&Vector3::zeros(), &n, &|d| day.sky_radiance(d), None, &s).unwrap();
                let err = relative_error(&e.rgb, &r);
                eprintln!(
                    "sun {elevation}°/{azimuth}° tilt {tilt}°: E {:?} ref {:?} rel err {err:.2e}, {} patches",
                    e.rgb, r, e.patches
                );
                assert!(e.rgb.iter().all(|x| x.is_finite()));
                assert!(err < 1e-4, "sun {elevation}/{azimuth} tilt {tilt}: {err:e}");
            }
        }
    }

    #[test]
    fn uniform_sky_on_tilted_planes_is_exact() {
        // E = π L (1 + cos β) / 2 through the clipping, at any tolerance.
        let l = [1.0, 2.0, 0.5];
        let sky = |_d: [f64; 3]| l;
        for beta_deg in [0.0_f64, 30.0, 45.0, 90.0, 120.0, 135.0, 180.0] {
            let beta = beta_deg.to_radians();
            let n = Vector3::new(beta.sin() * 0.6, beta.sin() * 0.8, beta.cos());
            let e = sky_irradiance(&Vector3::zeros(), &n, &sky, None, &SkySubdivision::default()).unwrap();
            for (ch, lc) in l.iter().enumerate() {
                let exact = PI * lc * (1.0 + beta.cos()) / 2.0;
                assert!(
                    (e.rgb[ch] - exact).abs() <= 1e-9 * exact.max(1e-300),
                    "β {beta_deg}: {:?}",
                    e.rgb
                );
            }
        }
    }

    fn scene(triangles: Vec<Triangle>) -> Scene {
        Scene::new(
            triangles,
            vec![Material::diffuse("wall", [0.5; 3])],
            vec!["wall".into()],
        )
        .unwrap()
    }

    /// A wall 10 m wide and 3 m high, 2 m south of the origin, as two triangles.
    fn wall_corners() -> [Vector3<f64>; 4] {
        [
            Vector3::new(-5.0, -2.0, 0.0),
            Vector3::new(5.0, -2.0, 0.0),
            Vector3::new(5.0, -2.0, 3.0),
            Vector3::new(-5.0, -2.0, 3.0),
        ]
    }

    fn wall() -> Scene {
        let [a, b, c, d] = wall_corners();
        scene(vec![
            Triangle::new([a, b, c], 0, 0).unwrap(),
            Triangle::new([a, c, d], 0, 0).unwrap(),
        ])
    }

    /// Irradiance on the plane tilted 45° at the origin under a uniform unit
    /// sky with the wall in front, exactly: the sky's view factor minus the
    /// wall's spherical quad, eq. (B.1).
    fn exact_wall_irradiance() -> f64 {
        let n = tilted(45.0);
        let mut quad = SphericalPolygon::new(wall_corners().to_vec()).unwrap();
        if quad.vector_flux().dot(&Vector3::new(0.0, -1.0, 0.3)) < 0.0 {
            quad = SphericalPolygon::new(wall_corners().iter().rev().copied().collect()).unwrap();
        }
        let blocked = clip_to_hemisphere(&quad, &n)
            .unwrap()
            .map_or(0.0, |q| q.vector_flux().dot(&n));
        PI * (1.0 + 45f64.to_radians().cos()) / 2.0 - blocked
    }

    #[test]
    fn a_wall_under_a_uniform_sky_converges_with_depth_to_the_exact_flux() {
        let n = tilted(45.0);
        let exact = exact_wall_irradiance();
        let scene = wall();
        let mut last = f64::INFINITY;
        for depth in [4, 6, 8, 10, 12] {
            let s = SkySubdivision {
                tolerance: 1e-3,
                min_depth: 2,
                max_depth: depth,
            };
            let e = sky_irradiance(&Vector3::zeros(), &n, &|_d| [1.0; 3], Some(&scene), &s).unwrap();
            let err = (e.rgb[0] - exact).abs() / exact;
            eprintln!(
                "wall, uniform sky: depth {depth}: rel err {err:.2e}, {} patches",
                e.patches
            );
            assert!(e.rgb.iter().all(|x| x.is_finite()));
            last = err;
        }
        assert!(last < 1e-4, "{last:e}");
    }

    #[test]
    fn projected_occluders_give_the_exact_flux_at_any_depth() {
        // The same exact answer as above, but the wall's silhouette is cut
        // out of each patch, so depth 2 is already exact to rounding.
        let n = tilted(45.0);
        let exact = exact_wall_irradiance();
        let scene = wall();
        for depth in [2, 3, 5] {
            let s = SkySubdivision {
                tolerance: 1e-3,
                min_depth: 2,
                max_depth: depth,
            };
            let e =
                sky_irradiance_with(&Vector3::zeros(), &n, &|_d| [1.0; 3], Occlusion::Projected(&scene), &s).unwrap();
            let err = (e.rgb[0] - exact).abs() / exact;
            eprintln!(
                "wall, uniform sky, projected: depth {depth}: rel err {err:.2e}, {} patches",
                e.patches
            );
            // 1e-7: the polygon Boolean operations' integer snapping.
            assert!(err < 1e-7, "depth {depth}: {err:e}");
        }
    }

    #[test]
    fn projected_and_shadow_ray_occlusion_agree_under_a_clear_sky() {
        let day = daylight(20.0, 200.0);
        let scene = wall();
        let sky = |d| day.sky_radiance(d);
        let run = |n: &Vector3<f64>, occlusion: Occlusion<'_>, tolerance: f64, max_depth: u32| {
            let s = SkySubdivision {
                tolerance,
                min_depth: 2,
                max_depth,
            };
            sky_irradiance_with(&Vector3::zeros(), n, &sky, occlusion, &s)
                .unwrap()
                .rgb
        };
        for tilt in [45.0, 90.0] {
            let n = tilted(tilt);
            let p = run(&n, Occlusion::Projected(&scene), 1e-4, 12);
            let r = run(&n, Occlusion::ShadowRays(&scene), 1e-4, 12);
            let err = relative_error(&p, &r);
            eprintln!("tilt {tilt}: projected {p:?}, rays {r:?}: {err:.2e}");
            assert!(err < 1e-4, "tilt {tilt}: {err:e}");
        }
        // Facing down at 160°, the plane sees a sliver of sky above the
        // southern horizon, mostly behind the wall: the projection has
        // converged (tolerance 1e-3 against 1e-4), while shadow rays close
        // in on it only as the depth limit grows (measured: 1.6e-2, 4.0e-3,
        // 8.4e-4 at depths 10, 12, 14).
        let n = tilted(160.0);
        let p = run(&n, Occlusion::Projected(&scene), 1e-4, 12);
        assert!(relative_error(&p, &run(&n, Occlusion::Projected(&scene), 1e-3, 12)) < 1e-3);
        let errs: Vec<f64> = [10, 12, 14]
            .map(|d| relative_error(&run(&n, Occlusion::ShadowRays(&scene), 1e-4, d), &p))
            .to_vec();
        eprintln!("tilt 160: shadow-ray error against the projection by depth 10, 12, 14: {errs:?}");
        assert!(errs[0] > errs[1] && errs[1] > errs[2] && errs[2] < 2e-3, "{errs:?}");
    }

    #[test]
    fn projected_occlusion_hard_cases() {
        // A wall standing on the receiver's plane with its base edge through
        // the point: its plane contains the point, so it is skipped, and the
        // result is finite (half the sky is behind it: check against rays).
        let stand = scene(vec![
            Triangle::new(
                [
                    Vector3::new(-5.0, 0.0, 0.0),
                    Vector3::new(5.0, 0.0, 0.0),
                    Vector3::new(5.0, 0.0, 3.0),
                ],
                0,
                0,
            )
            .unwrap(),
            Triangle::new(
                [
                    Vector3::new(-5.0, 0.0, 0.0),
                    Vector3::new(5.0, 0.0, 3.0),
                    Vector3::new(-5.0, 0.0, 3.0),
                ],
                0,
                0,
            )
            .unwrap(),
        ]);
        let s = SkySubdivision::default();
        let up = Vector3::z();
        let e = sky_irradiance_with(&Vector3::zeros(), &up, &|_d| [1.0; 3], Occlusion::Projected(&stand), &s).unwrap();
        assert!(
            e.rgb.iter().all(|x| x.is_finite()) && (e.rgb[0] - PI).abs() < 1e-9,
            "{:?}",
            e.rgb
        );
        // The same wall 1 mm behind the point: the wall hides its own
        // spherical quad, exactly (compare with a fine shadow-ray run).
        let p = Vector3::new(0.0, -1e-3, 0.0);
        let e = sky_irradiance_with(&p, &up, &|_d| [1.0; 3], Occlusion::Projected(&stand), &s).unwrap();
        let quad = SphericalPolygon::new(vec![
            Vector3::new(5.0, 1e-3, 3.0).normalize(),
            Vector3::new(5.0, 1e-3, 0.0).normalize(),
            Vector3::new(-5.0, 1e-3, 0.0).normalize(),
            Vector3::new(-5.0, 1e-3, 3.0).normalize(),
        ])
        .unwrap();
        let blocked = quad.vector_flux().dot(&up).abs();
        assert!(
            (e.rgb[0] - (PI - blocked)).abs() < 1e-6,
            "{} against {}",
            e.rgb[0],
            PI - blocked
        );
        // Facing the ground, under a closed octahedron: zero, not NaN.
        let axes = [Vector3::x(), Vector3::y(), -Vector3::x(), -Vector3::y()];
        let mut tris = Vec::new();
        for i in 0..4 {
            for pole in [Vector3::z(), -Vector3::z()] {
                tris.push(Triangle::new([axes[i] * 10.0, axes[(i + 1) % 4] * 10.0, pole * 10.0], 0, 0).unwrap());
            }
        }
        let closed = scene(tris);
        for n in [Vector3::z(), -Vector3::z(), tilted(135.0)] {
            let e =
                sky_irradiance_with(&Vector3::zeros(), &n, &|_d| [1.0; 3], Occlusion::Projected(&closed), &s).unwrap();
            assert!(
                e.rgb.iter().all(|x| x.is_finite() && x.abs() < 1e-9),
                "{n:?}: {:?}",
                e.rgb
            );
        }
    }

    /// The daylight's sky without its disc, for the Monte Carlo reference.
    struct SkyOnly(Daylight);

    impl crate::render::Sky for SkyOnly {
        fn radiance(&self, d: &Vector3<f64>) -> [f64; 3] {
            self.0.sky_radiance([d.x, d.y, d.z])
        }
        fn sun(&self) -> Option<crate::render::SolarDisc> {
            None
        }
    }

    #[test]
    fn a_wall_under_a_clear_sky_agrees_with_monte_carlo() {
        // render::irradiance, direct light only, 400 000 cosine-distributed rays:
        // its standard error here is about 0.1%, so the bound is 0.5%.
        let day = daylight(20.0, 200.0);
        let n = tilted(45.0);
        let scene = wall();
        let s = SkySubdivision {
            tolerance: 1e-4,
            min_depth: 2,
            max_depth: 12,
        };
        let e = sky_irradiance(&Vector3::zeros(), &n, &|d| day.sky_radiance(d), Some(&scene), &s).unwrap();
        let sky = SkyOnly(day);
        let lighting = crate::render::Lighting {
            sky: Some(&sky),
            points: &[],
            spheres: &[],
        };
        let mc = crate::render::irradiance(&scene, &lighting, &Vector3::zeros(), &n, 1, 400_000, 7);
        let err = relative_error(&e.rgb, &mc);
        eprintln!("wall, clear sky: E {:?} MC {mc:?} rel diff {err:.2e}", e.rgb);
        assert!(err < 5e-3, "{err:e}");
    }

    #[test]
    fn an_occluder_covering_the_whole_sky_gives_zero() {
        // An octahedron of radius 10 m around the point.
        let axes = [Vector3::x(), Vector3::y(), -Vector3::x(), -Vector3::y()];
        let mut tris = Vec::new();
        for i in 0..4 {
            for pole in [Vector3::z(), -Vector3::z()] {
                tris.push(Triangle::new([axes[i] * 10.0, axes[(i + 1) % 4] * 10.0, pole * 10.0], 0, 0).unwrap());
            }
        }
        let scene = scene(tris);
        let day = daylight(60.0, 30.0);
        for tilt in [0.0, 90.0, 135.0] {
            let e = sky_irradiance(
                &Vector3::zeros(),
                &tilted(tilt),
                &|d| day.sky_radiance(d),
                Some(&scene),
                &SkySubdivision::default(),
            )
            .unwrap();
            assert_eq!(e.rgb, [0.0; 3], "tilt {tilt}");
        }
    }

    #[test]
    fn a_surface_facing_the_ground_sees_no_sky() {
        let sky = |_d: [f64; 3]| [1.0; 3];
        let e = sky_irradiance(
            &Vector3::zeros(),
            &-Vector3::z(),
            &sky,
            None,
            &SkySubdivision::default(),
        )
        .unwrap();
        assert_eq!(e.rgb, [0.0; 3]);
        assert_eq!(e.patches, 0);
    }

    #[test]
    fn bad_inputs_are_refused() {
        let sky = |_d: [f64; 3]| [1.0; 3];
        let s = SkySubdivision::default();
        assert!(sky_irradiance(&Vector3::zeros(), &Vector3::zeros(), &sky, None, &s).is_err());
        assert!(sky_irradiance(&Vector3::new(f64::NAN, 0.0, 0.0), &Vector3::z(), &sky, None, &s).is_err());
        let bad = SkySubdivision {
            tolerance: f64::NAN,
            ..s
        };
        assert!(sky_irradiance(&Vector3::zeros(), &Vector3::z(), &sky, None, &bad).is_err());
        let deep = SkySubdivision { max_depth: 40, ..s };
        assert!(sky_irradiance(&Vector3::zeros(), &Vector3::z(), &sky, None, &deep).is_err());
    }
}

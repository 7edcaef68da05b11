//! Point-to-patch form factors with hierarchical links, for the indoor
//! solver's interreflection (thesis §4.5).
//!
//! The form factor from a receiving point `P` (unit normal `n`) to a planar
//! polygon is Lambert's polygon formula, which is eq. (B.1) under unit
//! radiance divided by π: `F = n · Φ / π`, with `Φ` the vector flux of the
//! polygon as seen from `P` after cutting it to the half-space in front of
//! the receiver (in 3-D, so each edge stays a straight segment whose image
//! is a great arc). Only a patch's front side emits.
//!
//! Links (hierarchical radiosity's, "under a solid-angle threshold"): each
//! source triangle is split at its edge midpoints while a piece subtends
//! more than the threshold, so near patches are linked finely and far ones
//! coarsely; the children tile their parent, so without occlusion the
//! links' form factors sum to the triangle's exactly (to 1e-12 measured). A
//! link's visibility is the fraction of unblocked shadow rays from `P` to
//! seven points of the piece (corners, edge midpoints, centroid); a partly
//! hidden link is split further, to the depth limit, so its error is
//! confined to pieces at the depth limit along the occluders' silhouettes
//! (a box with a screen: the links sum to 1 within 5e-5).

use nalgebra::Vector3;

use super::IrradianceError;
use super::occluder_projection::clip;
use super::spherical_polygon::edge_flux;
use crate::render::{Ray, Scene};

/// The form factor from the point `point` with unit normal `normal` to the
/// triangle `corners` (emitting on the side its counter-clockwise order
/// faces), unoccluded.
pub fn point_to_triangle(
    point: &Vector3<f64>,
    normal: &Vector3<f64>,
    corners: &[Vector3<f64>; 3],
) -> Result<f64, IrradianceError> {
    let n = super::unit_normal(normal)?;
    if !point.iter().all(|x| x.is_finite()) {
        return Err(IrradianceError::BadPoint {
            point: [point.x, point.y, point.z],
        });
    }
    Ok(form_factor(point, &n, corners))
}

fn form_factor(p: &Vector3<f64>, n: &Vector3<f64>, corners: &[Vector3<f64>; 3]) -> f64 {
    let face = (corners[1] - corners[0]).cross(&(corners[2] - corners[0]));
    if face.dot(&(p - corners[0])) <= 0.0 {
        return 0.0;
    }
    let rel = clip(&corners.map(|c| c - p), n);
    let dirs: Vec<Vector3<f64>> = rel.iter().filter_map(|d| d.try_normalize(1e-300)).collect();
    if dirs.len() < 3 {
        return 0.0;
    }
    let flux: Vector3<f64> = (0..dirs.len())
        .map(|i| edge_flux(&dirs[i], &dirs[(i + 1) % dirs.len()]))
        .sum();
    (flux.dot(n) / std::f64::consts::PI).abs()
}

/// Solid angle of the triangle `corners` seen from `p` (Van Oosterom–Strackee).
fn solid_angle(p: &Vector3<f64>, corners: &[Vector3<f64>; 3]) -> f64 {
    let [a, b, c] = corners.map(|v| v - p);
    let (la, lb, lc) = (a.norm(), b.norm(), c.norm());
    let triple = a.dot(&b.cross(&c));
    let den = la * lb * lc + a.dot(&b) * lc + b.dot(&c) * la + c.dot(&a) * lb;
    (2.0 * triple.atan2(den)).abs()
}

/// One link from the receiving point to a piece of a source triangle.
#[derive(Debug, Clone, PartialEq)]
pub struct Link {
    /// The scene triangle the piece belongs to.
    pub triangle: usize,
    /// The piece's corners.
    pub corners: [Vector3<f64>; 3],
    /// Its unoccluded form factor.
    pub form_factor: f64,
    /// Fraction of the shadow rays to its seven points that arrive.
    pub visibility: f64,
}

/// How links are refined.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinkOptions {
    /// A piece subtending more than this (sr) is split.
    pub max_solid_angle_sr: f64,
    /// Splits below the whole triangle never go deeper than this.
    pub max_depth: u32,
}

impl Default for LinkOptions {
    fn default() -> Self {
        LinkOptions {
            max_solid_angle_sr: 0.05,
            max_depth: 8,
        }
    }
}

/// The links from `point` (unit normal `normal`) to every triangle of
/// `scene` that faces it; occluders are the scene itself.
pub fn links(
    scene: &Scene,
    point: &Vector3<f64>,
    normal: &Vector3<f64>,
    options: &LinkOptions,
) -> Result<Vec<Link>, IrradianceError> {
    let n = super::unit_normal(normal)?;
    if !point.iter().all(|x| x.is_finite()) {
        return Err(IrradianceError::BadPoint {
            point: [point.x, point.y, point.z],
        });
    }
    if !(options.max_solid_angle_sr.is_finite() && options.max_solid_angle_sr > 0.0) {
        return Err(IrradianceError::BadTolerance {
            tolerance: options.max_solid_angle_sr,
        });
    }
    if options.max_depth > super::sky::MAX_DEPTH_LIMIT {
        return Err(IrradianceError::DepthTooLarge {
            depth: options.max_depth,
            limit: super::sky::MAX_DEPTH_LIMIT,
        });
    }
    let origin = point + n * super::sky::SHADOW_RAY_OFFSET * (1.0 + point.norm() * 1e-3);
    let mut out = Vec::new();
    for (i, t) in scene.triangles().iter().enumerate() {
        let at = Receiver {
            point,
            origin: &origin,
            normal: &n,
        };
        link(scene, &at, i, t.vertices, 0, options, &mut out);
    }
    Ok(out)
}

/// The receiving point, the origin of its shadow rays (lifted off the
/// surface), and its normal.
struct Receiver<'a> {
    point: &'a Vector3<f64>,
    origin: &'a Vector3<f64>,
    normal: &'a Vector3<f64>,
}

fn link(
    scene: &Scene,
    at: &Receiver<'_>,
    triangle: usize,
    c: [Vector3<f64>; 3],
    depth: u32,
    options: &LinkOptions,
    out: &mut Vec<Link>,
) {
    let (p, o) = (at.point, at.origin);
    let f = form_factor(p, at.normal, &c);
    if f <= 0.0 {
        return;
    }
    let mids = [(c[0] + c[1]) / 2.0, (c[1] + c[2]) / 2.0, (c[2] + c[0]) / 2.0];
    let centroid = (c[0] + c[1] + c[2]) / 3.0;
    let visible = |q: &Vector3<f64>| {
        let d = q - o;
        let dist = d.norm();
        dist > 0.0
            && !scene.occluded(
                &Ray {
                    origin: *o,
                    direction: d / dist,
                },
                dist * (1.0 - 1e-9),
            )
    };
    let seen = c
        .iter()
        .chain(&mids)
        .chain(std::iter::once(&centroid))
        .filter(|q| visible(q))
        .count();
    let partial = seen != 0 && seen != 7;
    if depth < options.max_depth && (solid_angle(p, &c) > options.max_solid_angle_sr || partial) {
        for child in [
            [c[0], mids[0], mids[2]],
            [mids[0], c[1], mids[1]],
            [mids[2], mids[1], c[2]],
            [mids[0], mids[1], mids[2]],
        ] {
            link(scene, at, triangle, child, depth + 1, options, out);
        }
        return;
    }
    out.push(Link {
        triangle,
        corners: c,
        form_factor: f,
        visibility: seen as f64 / 7.0,
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::shapes::quad;
    use crate::render::{Material, Triangle};

    fn scene(t: Vec<Triangle>) -> Scene {
        Scene::new(t, vec![Material::diffuse("m", [0.5; 3])], vec!["s".into()]).unwrap()
    }

    /// Differential area to a parallel w × h rectangle at distance d with
    /// one corner above the point (the standard closed form).
    fn corner_rectangle(w: f64, h: f64, d: f64) -> f64 {
        let (x, y) = (w / d, h / d);
        let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
        (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / (2.0 * std::f64::consts::PI)
    }

    #[test]
    fn a_parallel_rectangle_matches_the_closed_form_and_links_sum_to_it() {
        // A 2 × 3 m ceiling 1.5 m above, one corner over the point, facing down.
        let ceiling = quad(
            [
                Vector3::new(0.0, 0.0, 1.5),
                Vector3::new(0.0, 3.0, 1.5),
                Vector3::new(2.0, 3.0, 1.5),
                Vector3::new(2.0, 0.0, 1.5),
            ],
            0,
            0,
        );
        let exact = corner_rectangle(2.0, 3.0, 1.5);
        let p = Vector3::zeros();
        let whole: f64 = ceiling
            .iter()
            .map(|t| point_to_triangle(&p, &Vector3::z(), &t.vertices).unwrap())
            .sum();
        assert!((whole - exact).abs() < 1e-12, "{whole} against {exact}");
        let s = scene(ceiling);
        let ls = links(
            &s,
            &p,
            &Vector3::z(),
            &LinkOptions {
                max_solid_angle_sr: 0.01,
                max_depth: 10,
            },
        )
        .unwrap();
        let sum: f64 = ls.iter().map(|l| l.form_factor * l.visibility).sum();
        assert!((sum - exact).abs() < 1e-12, "links {sum} against {exact}");
        assert!(
            ls.len() > 16 && ls.iter().all(|l| solid_angle(&p, &l.corners) <= 0.01),
            "{} links",
            ls.len()
        );
        // Seen from above (its back), it gives nothing.
        assert_eq!(
            point_to_triangle(&Vector3::new(1.0, 1.0, 3.0), &-Vector3::z(), &s.triangles()[0].vertices).unwrap(),
            0.0
        );
    }

    #[test]
    fn a_closed_box_sums_to_one_and_a_screen_hides_its_share() {
        // The inside of a 4 m cube around a point on its floor, facing up.
        let (a, b) = (-2.0, 2.0);
        let v = |x: f64, y: f64, z: f64| Vector3::new(x, y, z);
        let mut tris = Vec::new();
        // Faces turned inward below.
        tris.extend(quad([v(a, a, b), v(b, a, b), v(b, b, b), v(a, b, b)], 0, 0)); // ceiling
        tris.extend(quad(
            [v(a, a, 0.0), v(a, b, 0.0), v(a, b, b), v(a, a, b)].map(|q| q),
            0,
            0,
        )); // x = a, facing +x
        tris.extend(quad([v(b, a, 0.0), v(b, a, b), v(b, b, b), v(b, b, 0.0)], 0, 0)); // x = b
        tris.extend(quad([v(a, a, 0.0), v(a, a, b), v(b, a, b), v(b, a, 0.0)], 0, 0)); // y = a
        tris.extend(quad([v(a, b, 0.0), v(b, b, 0.0), v(b, b, b), v(a, b, b)], 0, 0)); // y = b
        let centre = v(0.0, 0.0, 1.0);
        let tris: Vec<Triangle> = tris
            .into_iter()
            .map(|t| {
                let [x, y, z] = t.vertices;
                if t.normal.dot(&(centre - x)) < 0.0 {
                    Triangle::new([x, z, y], 0, 0).unwrap()
                } else {
                    t
                }
            })
            .collect();
        let p = Vector3::new(0.3, -0.4, 0.0);
        let total: f64 = tris
            .iter()
            .map(|t| point_to_triangle(&p, &Vector3::z(), &t.vertices).unwrap())
            .sum();
        assert!((total - 1.0).abs() < 1e-12, "enclosure: {total}");
        // A 1 m screen 1 m above the point hides part of the ceiling: the
        // visible links plus the screen's own form factor still sum to one
        // (to the shadow-ray sampling of the partly hidden links).
        let screen = quad(
            [
                v(-0.2, -0.9, 1.0),
                v(0.8, -0.9, 1.0),
                v(0.8, 0.1, 1.0),
                v(-0.2, 0.1, 1.0),
            ],
            0,
            0,
        );
        let screen_down: Vec<Triangle> = screen
            .iter()
            .map(|t| Triangle::new([t.vertices[0], t.vertices[2], t.vertices[1]], 0, 0).unwrap())
            .collect();
        let f_screen: f64 = screen_down
            .iter()
            .map(|t| point_to_triangle(&p, &Vector3::z(), &t.vertices).unwrap())
            .sum();
        let mut all = tris.clone();
        all.extend(screen_down);
        let s = scene(all);
        let ls = links(
            &s,
            &p,
            &Vector3::z(),
            &LinkOptions {
                max_solid_angle_sr: 0.02,
                max_depth: 9,
            },
        )
        .unwrap();
        let seen: f64 = ls.iter().map(|l| l.form_factor * l.visibility).sum();
        eprintln!("screen {f_screen:.6}, everything seen {seen:.6}, {} links", ls.len());
        assert!(f_screen > 0.2, "{f_screen}");
        assert!((seen - 1.0).abs() < 2e-3, "{seen}");
        assert!(
            ls.iter()
                .all(|l| l.form_factor.is_finite() && (0.0..=1.0).contains(&l.visibility))
        );
    }

    #[test]
    fn bad_inputs_are_refused() {
        let s = scene(quad(
            [
                Vector3::zeros(),
                Vector3::x(),
                Vector3::new(1.0, 1.0, 0.0),
                Vector3::y(),
            ],
            0,
            0,
        ));
        let p = Vector3::new(0.5, 0.5, 1.0);
        assert!(links(&s, &p, &Vector3::zeros(), &LinkOptions::default()).is_err());
        assert!(
            links(
                &s,
                &p,
                &-Vector3::z(),
                &LinkOptions {
                    max_solid_angle_sr: f64::NAN,
                    max_depth: 4
                }
            )
            .is_err()
        );
        assert!(
            point_to_triangle(
                &Vector3::new(f64::NAN, 0.0, 0.0),
                &Vector3::z(),
                &s.triangles()[0].vertices
            )
            .is_err()
        );
    }
}

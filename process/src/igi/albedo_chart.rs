//! The albedo maps (thesis §4.6) as files: one image per planar OBJ group
//! (a *chart*), and the layout that places each of its texels on the
//! scene's geometry, with how each texel got its value.
//!
//! [`super::albedo_map::AlbedoMap`] holds a grid of square texels per
//! triangle over the triangle's planar texture coordinates `(s, t)`
//! (metres; [`crate::render::Triangle::texture_coordinates`]): texel
//! `(i, j)` covers `s ∈ [s_g + iΔ, s_g + (i+1)Δ)`, `t ∈ [t_g + jΔ, …)`, with
//! `(s_g, t_g)` the triangle's lower corner. A chart resamples the grids of
//! a group's coplanar triangles onto one image over their shared axes:
//! pixel `(x, y)` (row 0 at the top) has its centre at
//!
//! s = s0 + (x + ½) Δ,  t = t0 − (y + ½) Δ,
//!
//! world point `s·a_s + t·a_t + d·n` (`a_s`, `a_t` the texture axes, `n` the
//! plane's unit normal, `d = n·p` for its points), and takes the value of
//! the grid texel of the triangle that point lies in. A pixel whose centre
//! lies in no triangle of the group is outside (0 in the image).
//!
//! Each pixel's origin ([`TexelOrigin`]) is written beside the image as an
//! 8-bit grey PNG ([`origin_code`]): seen by a view, filled from seen texels
//! within [`super::albedo_map::FILL_RADIUS`], or its surface's recovered ρd;
//! and [`AlbedoMapIndex`] (`albedo/layout.json`) records every chart's
//! layout, the triangles it covers (their corners, to check the geometry
//! against), and the groups that have no chart, with the reason.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use super::albedo_map::{AlbedoMap, TexelOrigin};
use crate::camera::image::RadianceImage;
use crate::render::Triangle;

/// The index's file name in the albedo directory.
pub const LAYOUT_FILE: &str = "layout.json";

/// The index's format name ([`AlbedoMapIndex::format`]).
pub const LAYOUT_FORMAT: &str = "campanile-igi-albedo-maps";

/// The index's format version.
pub const LAYOUT_VERSION: u32 = 1;

/// Largest chart side, texels.
pub const MAX_CHART_SIDE: usize = 4096;

/// The PNG grey level of a pixel's origin: 255 seen, 128 filled from
/// neighbours, 64 the surface's recovered ρd, 0 outside the group.
pub fn origin_code(origin: Option<TexelOrigin>) -> u8 {
    match origin {
        Some(TexelOrigin::Seen) => 255,
        Some(TexelOrigin::Filled) => 128,
        Some(TexelOrigin::SurfaceMean) => 64,
        None => 0,
    }
}

/// The origin of PNG grey level `code` ([`origin_code`]); `Err` for any
/// other level.
pub fn origin_of_code(code: u8) -> Result<Option<TexelOrigin>, u8> {
    match code {
        255 => Ok(Some(TexelOrigin::Seen)),
        128 => Ok(Some(TexelOrigin::Filled)),
        64 => Ok(Some(TexelOrigin::SurfaceMean)),
        0 => Ok(None),
        other => Err(other),
    }
}

/// One triangle of a chart.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChartTriangle {
    /// Its index among the scene's triangles (the OBJ's faces in file
    /// order, degenerate faces skipped).
    pub index: usize,
    /// Its corners, world frame, metres.
    pub vertices: [[f64; 3]; 3],
    /// Its own texel grid: the lower corner `(s_g, t_g)`, metres, on the
    /// chart's axes (a triangle's axes follow from its normal alone, so
    /// coplanar triangles share them).
    pub grid_origin_m: [f64; 2],
    /// Its grid's texels along `s` (columns) and `t` (rows).
    pub grid_size: [usize; 2],
    /// The block of image pixels whose centres lie in it: x, y, width,
    /// height (all 0 when no pixel centre does).
    pub rect: [usize; 4],
}

/// Where a chart's pixels lie (module doc).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChartLayout {
    /// Texel (pixel) side Δ, metres.
    pub texel_m: f64,
    /// Image width, pixels (along `s`).
    pub width: usize,
    /// Image height, pixels (along −`t`).
    pub height: usize,
    /// The plane's unit normal `n` (its first triangle's).
    pub normal: [f64; 3],
    /// `d = n·p` for points `p` of the plane, metres.
    pub offset_m: f64,
    /// Texture axes `a_s`, `a_t` (unit, in the plane).
    pub axes: [[f64; 3]; 2],
    /// `s` of the image's left edge, metres.
    pub s0_m: f64,
    /// `t` of the image's top edge, metres (row 0 at the largest `t`).
    pub t0_m: f64,
    /// The group's triangles.
    pub triangles: Vec<ChartTriangle>,
}

impl ChartLayout {
    /// The world point at the centre of pixel `(x, y)`.
    pub fn pixel_centre(&self, x: usize, y: usize) -> Vector3<f64> {
        let s = self.s0_m + (x as f64 + 0.5) * self.texel_m;
        let t = self.t0_m - (y as f64 + 0.5) * self.texel_m;
        Vector3::from(self.axes[0]) * s + Vector3::from(self.axes[1]) * t + Vector3::from(self.normal) * self.offset_m
    }

    /// The pixel `(x, y)` whose square holds world point `p` (projected on
    /// the plane), clamped to the image.
    pub fn pixel_of(&self, p: &Vector3<f64>) -> (usize, usize) {
        let s = p.dot(&Vector3::from(self.axes[0]));
        let t = p.dot(&Vector3::from(self.axes[1]));
        let x = ((s - self.s0_m) / self.texel_m).floor();
        let y = ((self.t0_m - t) / self.texel_m).floor();
        let clamp = |v: f64, n: usize| {
            if v.is_finite() {
                v.clamp(0.0, (n - 1) as f64) as usize
            } else {
                0
            }
        };
        (clamp(x, self.width), clamp(y, self.height))
    }
}

/// A chart: the image, each pixel's origin (`None`: outside the group) and
/// the layout.
#[derive(Debug, Clone, PartialEq)]
pub struct Chart {
    /// Albedo, linear RGB.
    pub image: RadianceImage,
    /// Per pixel, row-major.
    pub origin: Vec<Option<TexelOrigin>>,
    /// Where the pixels lie.
    pub layout: ChartLayout,
}

impl Chart {
    /// Pixels on the group, and of them seen, filled, and the surface's ρd.
    pub fn counts(&self) -> [usize; 4] {
        let mut c = [0usize; 4];
        for o in self.origin.iter().flatten() {
            c[0] += 1;
            match o {
                TexelOrigin::Seen => c[1] += 1,
                TexelOrigin::Filled => c[2] += 1,
                TexelOrigin::SurfaceMean => c[3] += 1,
            }
        }
        c
    }
}

/// Whether `p` (on the plane of `t`) is inside triangle `t`, edges included.
fn inside(t: &Triangle, p: &Vector3<f64>) -> bool {
    let (a, b, c) = (t.vertices[0], t.vertices[1], t.vertices[2]);
    let s1 = (b - a).cross(&(p - a)).dot(&t.normal);
    let s2 = (c - b).cross(&(p - b)).dot(&t.normal);
    let s3 = (a - c).cross(&(p - c)).dot(&t.normal);
    s1 >= -1e-9 && s2 >= -1e-9 && s3 >= -1e-9
}

/// The chart of triangles `members` of `triangles` (the solver's input) in
/// `map` (module doc); refused, with the reason, when they are empty, not
/// coplanar, or the image would exceed [`MAX_CHART_SIDE`] texels a side.
pub fn chart(map: &AlbedoMap, triangles: &[Triangle], members: &[usize]) -> Result<Chart, String> {
    let Some(first) = members.first().and_then(|&i| triangles.get(i)) else {
        return Err("no triangles".into());
    };
    let (n, d) = (first.normal, first.normal.dot(&first.vertices[0]));
    let coplanar = members.iter().all(|&i| {
        triangles
            .get(i)
            .is_some_and(|t| t.normal.dot(&n) > 1.0 - 1e-9 && t.vertices.iter().all(|v| (v.dot(&n) - d).abs() < 1e-6))
    });
    if !coplanar {
        return Err("its triangles are not coplanar (a chart is one plane's image)".into());
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for &i in members {
        let t = &triangles[i];
        for v in &t.vertices {
            let st = t.texture_coordinates(v);
            for k in 0..2 {
                lo[k] = lo[k].min(st[k]);
                hi[k] = hi[k].max(st[k]);
            }
        }
    }
    let w = ((hi[0] - lo[0]) / map.texel_m).ceil() as usize;
    let h = ((hi[1] - lo[1]) / map.texel_m).ceil() as usize;
    if w == 0 || h == 0 || w > MAX_CHART_SIDE || h > MAX_CHART_SIDE {
        return Err(format!(
            "its chart would be {w} × {h} texels of {} m (expected 1 to {MAX_CHART_SIDE} a side)",
            map.texel_m
        ));
    }
    let t0 = &triangles[members[0]];
    let mut data = vec![0f32; w * h * 3];
    let mut origin = vec![None; w * h];
    // Per member: min x, min y, max x, max y of its pixels.
    let mut rects: Vec<Option<[usize; 4]>> = vec![None; members.len()];
    for y in 0..h {
        for x in 0..w {
            let st = [
                lo[0] + (x as f64 + 0.5) * map.texel_m,
                hi[1] - (y as f64 + 0.5) * map.texel_m,
            ];
            // The point in the plane with these coordinates: s and t
            // axes are orthonormal in the face.
            let p = t0.texture_axes[0] * st[0] + t0.texture_axes[1] * st[1] + n * d;
            let Some(k) = members.iter().position(|&i| inside(&triangles[i], &p)) else {
                continue;
            };
            let i = members[k];
            let (a, o) = map.albedo_and_origin_at(i, triangles[i].surface as usize, &triangles[i], &p);
            for c in 0..3 {
                data[(y * w + x) * 3 + c] = a[c] as f32;
            }
            origin[y * w + x] = Some(o);
            let r = rects[k].get_or_insert([x, y, x, y]);
            *r = [r[0].min(x), r[1].min(y), r[2].max(x), r[3].max(y)];
        }
    }
    let v3 = |v: &Vector3<f64>| [v.x, v.y, v.z];
    let layout = ChartLayout {
        texel_m: map.texel_m,
        width: w,
        height: h,
        normal: v3(&n),
        offset_m: d,
        axes: [v3(&t0.texture_axes[0]), v3(&t0.texture_axes[1])],
        s0_m: lo[0],
        t0_m: hi[1],
        triangles: members
            .iter()
            .zip(&rects)
            .map(|(&i, r)| {
                let grid = map.triangles.get(i);
                ChartTriangle {
                    index: i,
                    vertices: triangles[i].vertices.each_ref().map(v3),
                    grid_origin_m: grid.map_or([0.0; 2], |g| g.origin),
                    grid_size: grid.map_or([0; 2], |g| g.size),
                    rect: r.map_or([0; 4], |[x0, y0, x1, y1]| [x0, y0, x1 - x0 + 1, y1 - y0 + 1]),
                }
            })
            .collect(),
    };
    Ok(Chart {
        image: RadianceImage {
            width: w,
            height: h,
            data,
        },
        origin,
        layout,
    })
}

/// One chart on disk.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MapRecord {
    /// The OBJ group.
    pub group: String,
    /// The surface (BRDF) the group belongs to.
    pub surface: String,
    /// The albedo image (OpenEXR, linear RGB), relative to the index.
    pub exr: String,
    /// Each pixel's origin (8-bit grey PNG, [`origin_code`]), relative to the index.
    pub seen: String,
    /// Pixels on the group's triangles.
    pub texels: usize,
    /// Of those, seen by a view.
    pub seen_texels: usize,
    /// Of those, filled from seen texels within [`super::albedo_map::FILL_RADIUS`].
    pub filled_texels: usize,
    /// Of those, the surface's recovered ρd.
    pub surface_mean_texels: usize,
    /// Where the pixels lie.
    pub layout: ChartLayout,
}

impl MapRecord {
    /// The record of `chart` of `group` (surface `surface`), written as `GROUP.exr` and `GROUP.seen.png`.
    pub fn new(group: &str, surface: &str, chart: &Chart) -> MapRecord {
        let [texels, seen_texels, filled_texels, surface_mean_texels] = chart.counts();
        MapRecord {
            group: group.to_string(),
            surface: surface.to_string(),
            exr: format!("{group}.exr"),
            seen: format!("{group}.seen.png"),
            texels,
            seen_texels,
            filled_texels,
            surface_mean_texels,
            layout: chart.layout.clone(),
        }
    }
}

/// A group that has no chart.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SkippedGroup {
    /// The OBJ group.
    pub group: String,
    /// The surface it belongs to.
    pub surface: String,
    /// Why it has no chart.
    pub reason: String,
}

/// `albedo/layout.json`: every chart written, and every group without one.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AlbedoMapIndex {
    /// [`LAYOUT_FORMAT`].
    pub format: String,
    /// [`LAYOUT_VERSION`].
    pub version: u32,
    /// The maps' texel side, metres.
    pub texel_m: f64,
    /// What the seen PNGs' grey levels mean.
    pub seen_codes: String,
    /// The charts, in OBJ group order.
    pub maps: Vec<MapRecord>,
    /// The groups without a chart.
    pub skipped: Vec<SkippedGroup>,
}

impl AlbedoMapIndex {
    /// An empty index for maps of `texel_m`.
    pub fn new(texel_m: f64) -> AlbedoMapIndex {
        AlbedoMapIndex {
            format: LAYOUT_FORMAT.into(),
            version: LAYOUT_VERSION,
            texel_m,
            seen_codes: "255 seen by a view, 128 filled from seen texels within 3 texels, 64 the surface's \
                         recovered rho_d, 0 outside the group's triangles"
                .into(),
            maps: Vec::new(),
            skipped: Vec::new(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::igi::albedo_map::TriangleTexels;

    /// A 0.4 m × 0.2 m wall in the plane y = 0 (two triangles) on 0.1 m
    /// texels, every texel of its grids seen with albedo 0.1·(i + 1)
    /// except triangle 1's texel (0, 1): a 4 × 2 chart whose pixels
    /// map back to their centres, with the unseen texel filled.
    #[test]
    fn a_chart_places_each_pixel_and_says_how_it_was_obtained() {
        let v = |x: f64, z: f64| Vector3::new(x, 0.0, z);
        let tris = vec![
            Triangle::new([v(0.0, 0.0), v(0.4, 0.0), v(0.4, 0.2)], 0, 0).unwrap(),
            Triangle::new([v(0.0, 0.0), v(0.4, 0.2), v(0.0, 0.2)], 0, 0).unwrap(),
        ];
        let grid = |t: &Triangle| {
            let st: Vec<[f64; 2]> = t.vertices.iter().map(|p| t.texture_coordinates(p)).collect();
            let lo = [0, 1].map(|k| st.iter().map(|p| p[k]).fold(f64::INFINITY, f64::min));
            let mut g = TriangleTexels {
                origin: lo,
                size: [4, 2],
                albedo: (0..8).map(|k| [0.1 * ((k % 4) as f32 + 1.0); 3]).collect(),
                weight: vec![1.0; 8],
            };
            if t.vertices[2].x == 0.0 {
                g.weight[4] = 0.0;
            }
            g
        };
        let map = AlbedoMap {
            texel_m: 0.1,
            triangles: tris.iter().map(grid).collect(),
            fallback: vec![[0.5; 3]],
            samples: (0, 0),
        };
        let c = chart(&map, &tris, &[0, 1]).unwrap();
        let l = &c.layout;
        assert_eq!((l.width, l.height), (4, 2));
        // The wall's s axis: horizontal in the plane; t up (+z).
        assert!((Vector3::from(l.axes[1]) - Vector3::z()).norm() < 1e-12, "{:?}", l.axes);
        for y in 0..2 {
            for x in 0..4 {
                let p = l.pixel_centre(x, y);
                assert!(
                    p.y.abs() < 1e-12 && (p.z - (0.2 - 0.1 * (y as f64 + 0.5))).abs() < 1e-12,
                    "{p:?}"
                );
                assert_eq!(l.pixel_of(&p), (x, y));
            }
        }
        // Every pixel centre lies in a triangle (none on the diagonal); s
        // is +x, so pixel (x, y) is texel (x, 1 − y) of its triangle's grid,
        // albedo 0.1 (x + 1); pixel (0, 0) lies in triangle 1, on its
        // unseen texel (0, 1): the mean of its seen ring (0.2, 0.1, 0.2).
        assert_eq!(c.counts(), [8, 7, 1, 0]);
        for y in 0..2 {
            for x in 0..4 {
                let (got, o) = (c.image.data[(y * 4 + x) * 3], c.origin[y * 4 + x]);
                let (want, origin) = if (x, y) == (0, 0) {
                    (0.5 / 3.0, TexelOrigin::Filled)
                } else {
                    (0.1 * (x as f64 + 1.0), TexelOrigin::Seen)
                };
                assert!((f64::from(got) - want).abs() < 1e-6, "({x}, {y}): {got}");
                assert_eq!(o, Some(origin), "({x}, {y})");
            }
        }
        assert_eq!(l.triangles.len(), 2);
        let area: usize = l.triangles.iter().map(|t| t.rect[2] * t.rect[3]).sum();
        assert!(area >= 8, "{:?}", l.triangles);
        for code in [0u8, 64, 128, 255] {
            assert_eq!(origin_of_code(code).map(origin_code), Ok(code));
        }
        assert_eq!(origin_of_code(7), Err(7));
        // Not coplanar: refused with the reason.
        let tilted = Triangle::new([v(0.0, 0.0), v(0.4, 0.0), Vector3::new(0.0, 0.3, 0.2)], 0, 0).unwrap();
        let err = chart(&map, &[tris[0].clone(), tilted], &[0, 1]).unwrap_err();
        assert!(err.contains("not coplanar"), "{err}");
    }
}

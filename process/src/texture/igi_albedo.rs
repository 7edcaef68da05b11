//! Albedo textures from the diffuse albedo maps of inverse global
//! illumination (thesis §4.6; `campanile igi` and `campanile process` on a room session write
//! them as one chart per planar OBJ group, [`crate::igi::albedo_chart`]),
//! laid out as the radiance textures are (§3.4): one patch per face, packed
//! into atlas pages, exported as OBJ + MTL + EXR/PNG.
//!
//! Each texel of a patch is resampled from the charts at `n × n` points
//! spread over it (`n = ⌈2 Δ / δ⌉` within [2, 8], `Δ` the texel side, `δ`
//! the maps' texel side, as [`super::albedo`] does with the outdoor grid):
//! each point lies in one triangle of the face, whose chart's pixel holds
//! it. The texel is the mean of the points that fall on pixels a view saw.
//! Pixels no view saw hold the map's own fill (its seen neighbours within
//! three texels, else the surface's recovered ρd), not a measurement: a
//! texel none of whose points fall on a seen pixel is counted unseen and
//! filled from its neighbours ([`super::fill`]), as radiance texels no
//! photograph sees are. A face no view saw at all keeps the maps' own fill
//! (its texels all counted unseen), where a radiance patch would stay black:
//! the surface's recovered ρd is the solver's estimate from every view of
//! the surface.

use super::TextureError;
use super::albedo::{SubSample, resample, subsamples};
use super::patch::Patch;
use super::synthesis::Synthesis;
use crate::camera::image::RadianceImage;
use crate::igi::albedo_chart::ChartLayout;
use crate::igi::albedo_map::TexelOrigin;
use crate::render::Scene;

/// One albedo map as read: its layout, image and each pixel's origin.
#[derive(Debug, Clone)]
pub struct ChartData {
    /// Where the pixels lie.
    pub layout: ChartLayout,
    /// Albedo, `layout.width × layout.height`.
    pub image: RadianceImage,
    /// Per pixel (`None`: outside the group).
    pub origin: Vec<Option<TexelOrigin>>,
}

/// The albedo texture of each of `patches` from `charts` (module doc);
/// `chart_of` gives each triangle of `scene` its chart. Refused, naming
/// the surface, when a patch has a triangle without a chart, or a chart's
/// image or origins do not match its layout's size. `step` is called
/// after each patch.
pub fn igi_albedo_synthesis(
    scene: &Scene,
    patches: &[Patch],
    charts: &[ChartData],
    chart_of: &[Option<usize>],
    step: &dyn Fn(),
) -> Result<Synthesis, TextureError> {
    for (k, c) in charts.iter().enumerate() {
        let n = c.layout.width * c.layout.height;
        if c.image.width != c.layout.width || c.image.height != c.layout.height || c.image.data.len() != 3 * n {
            return Err(TextureError::BadSetting {
                field: "charts",
                value: format!("chart {k}: image {} × {}", c.image.width, c.image.height),
                expected: format!("its layout's {} × {}", c.layout.width, c.layout.height),
            });
        }
        if c.origin.len() != n {
            return Err(TextureError::BadSetting {
                field: "charts",
                value: format!("chart {k}: {} origins", c.origin.len()),
                expected: format!("one per pixel ({n})"),
            });
        }
    }
    for p in patches {
        if let Some(&t) = p
            .triangles
            .iter()
            .find(|&&t| chart_of.get(t).copied().flatten().is_none_or(|c| c >= charts.len()))
        {
            return Err(TextureError::BadSetting {
                field: "charts",
                value: format!(
                    "no albedo map for triangle {t} of surface {:?}",
                    scene.surfaces()[p.surface]
                ),
                expected: "a map for every triangle of the surfaces textured".into(),
            });
        }
    }
    Ok(resample(
        scene,
        patches,
        |patch| patch_subsamples(patch, charts, chart_of),
        |tri, p| {
            let c = &charts[chart_of[tri]?];
            let (x, y) = c.layout.pixel_of(p);
            let k = y * c.layout.width + x;
            let origin = c.origin[k]?;
            let v = [0, 1, 2].map(|ch| f64::from(c.image.data[3 * k + ch]));
            if !v.iter().all(|x| x.is_finite()) {
                return None;
            }
            Some(if origin == TexelOrigin::Seen {
                SubSample::Seen(v)
            } else {
                SubSample::Unseen(v)
            })
        },
        step,
    ))
}

/// Sub-samples per side for `patch` over its charts (their texel side;
/// the finest when they differ).
fn patch_subsamples(patch: &Patch, charts: &[ChartData], chart_of: &[Option<usize>]) -> usize {
    let map_texel = patch
        .triangles
        .iter()
        .filter_map(|&t| chart_of.get(t).copied().flatten())
        .filter_map(|c| charts.get(c))
        .map(|c| c.layout.texel_m)
        .fold(f64::INFINITY, f64::min);
    if map_texel.is_finite() && map_texel > 0.0 {
        subsamples(patch.texel_m, map_texel)
    } else {
        2
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::Vector3;

    use super::*;
    use crate::igi::albedo_chart::chart;
    use crate::igi::albedo_map::{AlbedoMap, TriangleTexels};
    use crate::render::{Material, Triangle};
    use crate::texture::patch::patches;
    use crate::texture::synthesis::TexelStatus;

    /// A 0.4 m × 0.2 m wall (y = 0, s = x, t = z; two triangles) whose map
    /// on 0.05 m texels holds albedo 0.2 left of x = 0.2 and 0.6 right of
    /// it, seen everywhere but the texels with x > 0.3 (the map fills
    /// those from their seen ring); and a floor square of another surface
    /// with a map nobody saw (its surface's ρd 0.35).
    fn scene_and_charts() -> (Scene, Vec<ChartData>, Vec<Option<usize>>) {
        let v = |x: f64, y: f64, z: f64| Vector3::new(x, y, z);
        let tris = vec![
            Triangle::new([v(0.0, 0.0, 0.0), v(0.4, 0.0, 0.0), v(0.4, 0.0, 0.2)], 0, 0).unwrap(),
            Triangle::new([v(0.0, 0.0, 0.0), v(0.4, 0.0, 0.2), v(0.0, 0.0, 0.2)], 0, 0).unwrap(),
            Triangle::new([v(1.0, 0.0, 0.0), v(1.2, 0.0, 0.0), v(1.2, 0.2, 0.0)], 1, 1).unwrap(),
        ];
        let texel = 0.05;
        let grids: Vec<TriangleTexels> = tris
            .iter()
            .enumerate()
            .map(|(k, t)| {
                let st: Vec<[f64; 2]> = t.vertices.iter().map(|p| t.texture_coordinates(p)).collect();
                let lo = [0, 1].map(|c| st.iter().map(|p| p[c]).fold(f64::INFINITY, f64::min));
                let hi = [0, 1].map(|c| st.iter().map(|p| p[c]).fold(f64::NEG_INFINITY, f64::max));
                let size = [0, 1].map(|c| ((hi[c] - lo[c]) / texel).ceil() as usize);
                let n = size[0] * size[1];
                let mut albedo = vec![[0.0f32; 3]; n];
                let mut weight = vec![0.0f32; n];
                if k < 2 {
                    for j in 0..size[1] {
                        for i in 0..size[0] {
                            let x = lo[0] + (i as f64 + 0.5) * texel;
                            albedo[j * size[0] + i] = [if x < 0.2 { 0.2 } else { 0.6 }; 3];
                            weight[j * size[0] + i] = if x > 0.3 { 0.0 } else { 1.0 };
                        }
                    }
                }
                TriangleTexels {
                    origin: lo,
                    size,
                    albedo,
                    weight,
                }
            })
            .collect();
        let map = AlbedoMap {
            texel_m: texel,
            triangles: grids,
            fallback: vec![[0.5; 3], [0.35; 3]],
            samples: (0, 0),
        };
        let charts: Vec<ChartData> = [vec![0, 1], vec![2]]
            .iter()
            .map(|m| {
                let c = chart(&map, &tris, m).unwrap();
                ChartData {
                    layout: c.layout,
                    image: c.image,
                    origin: c.origin,
                }
            })
            .collect();
        let scene = Scene::new(
            tris,
            vec![Material::diffuse("a", [0.5; 3]), Material::diffuse("b", [0.5; 3])],
            vec!["wall".into(), "floor".into()],
        )
        .unwrap();
        (scene, charts, vec![Some(0), Some(0), Some(1)])
    }

    /// At 0.1 m texels (2 × 2 map texels each): the wall's four columns
    /// are 0.2, 0.2, 0.6 (seen) and unseen (x 0.3–0.4: filled from the
    /// seen 0.6 column); the floor's texels are all unseen and keep the
    /// map's ρd 0.35 rather than black.
    #[test]
    fn texels_take_the_seen_pixels_and_unseen_ones_are_counted() {
        let (scene, charts, chart_of) = scene_and_charts();
        let ps = patches(&scene, None, 0.1, 10_000).unwrap();
        assert_eq!(ps.len(), 2);
        assert_eq!((ps[0].cols, ps[0].rows), (4, 2));
        let syn = igi_albedo_synthesis(&scene, &ps, &charts, &chart_of, &|| {}).unwrap();
        let wall = &syn.textures[0];
        for j in 0..2 {
            for (i, want) in [0.2, 0.2, 0.6, 0.6].iter().enumerate() {
                let k = j * 4 + i;
                let status = if i == 3 { TexelStatus::Filled } else { TexelStatus::Seen };
                assert_eq!(wall.status[k], status, "({i}, {j})");
                assert!(
                    (f64::from(wall.rgb[k][0]) - want).abs() < 1e-6,
                    "({i}, {j}): {:?}",
                    wall.rgb[k]
                );
            }
        }
        let floor = &syn.textures[1];
        let on_floor = ps[1].texels_on_face();
        assert!(on_floor > 0);
        for (k, s) in floor.status.iter().enumerate() {
            assert!(
                (f64::from(floor.rgb[k][1]) - 0.35).abs() < 1e-6,
                "{k}: {:?}",
                floor.rgb[k]
            );
            assert_ne!(*s, TexelStatus::Seen);
        }
        assert_eq!(syn.report.texels_on_faces, 8 + on_floor);
        assert_eq!(syn.report.unseen, 2 + on_floor);
        assert_eq!(syn.report.per_patch, vec![(8, 2), (on_floor, on_floor)]);
        // A triangle without a chart is refused by surface.
        let err = igi_albedo_synthesis(&scene, &ps, &charts, &[Some(0), Some(0), None], &|| {})
            .unwrap_err()
            .to_string();
        assert!(err.contains("\"floor\"") && err.contains("triangle 2"), "{err}");
        // A chart whose image does not match its layout is refused.
        let mut bad = charts.clone();
        bad[1].layout.width += 1;
        assert!(igi_albedo_synthesis(&scene, &ps, &bad, &chart_of, &|| {}).is_err());
    }
}

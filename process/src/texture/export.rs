//! The textured model on disk, as Blender and other OBJ readers import it:
//!
//! - `model.obj`: every textured triangle with its own three corners
//!   (`v`), their texture coordinates in their patch's page (`vt`), the
//!   face normal (`vn`), grouped by surface (`g`), each page a material
//!   (`usemtl page_N`);
//! - `model.mtl`: one material per page, `Kd 1 1 1` and `map_Kd
//!   page_N.png` (the form Blender's importer reads: the option-free map
//!   statement with a path relative to the MTL file);
//! - `page_N.exr`: the linear radiance (or albedo) atlas, 32-bit float RGB;
//! - `page_N.png`: an 8-bit sRGB preview through a tone map: scaled so that
//!   the 99th percentile of the texels' largest channel is white, then the
//!   sRGB transfer curve (the scale is returned for the record).
//!
//! The MTL names the PNG because every OBJ reader opens PNG; the EXR beside
//! it holds the values (a comment in the MTL names it).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::TextureError;
use super::atlas::Atlas;
use super::patch::Patch;
use crate::exr_io::{ExrPrecision, write_rgb_exr};
use crate::hdr::merge::RadianceMap;
use crate::render::Scene;

/// The files written.
#[derive(Debug, Clone, PartialEq)]
pub struct Exported {
    /// The OBJ.
    pub obj: PathBuf,
    /// The MTL.
    pub mtl: PathBuf,
    /// Per page: the EXR and the PNG.
    pub pages: Vec<(PathBuf, PathBuf)>,
    /// The preview's tone-map scale (linear value × scale = display 1).
    pub preview_scale: f64,
}

fn file_error(path: &Path, e: impl ToString) -> TextureError {
    TextureError::File {
        path: path.to_path_buf(),
        message: e.to_string(),
    }
}

/// sRGB encoding of a linear value in [0, 1].
fn srgb(x: f64) -> u8 {
    let x = x.clamp(0.0, 1.0);
    let e = if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    };
    (e * 255.0).round() as u8
}

/// The preview scale: 1 / the 99th percentile of the texels' largest
/// channel (texels above 0 only; 1 when there are none).
pub fn preview_scale(atlas: &Atlas) -> f64 {
    let mut peaks: Vec<f32> = atlas
        .pages
        .iter()
        .flat_map(|p| p.rgb.chunks_exact(3).map(|c| c[0].max(c[1]).max(c[2])))
        .filter(|v| v.is_finite() && *v > 0.0)
        .collect();
    if peaks.is_empty() {
        return 1.0;
    }
    let k = ((peaks.len() - 1) as f64 * 0.99).round() as usize;
    let (_, p99, _) = peaks.select_nth_unstable_by(k, f32::total_cmp);
    1.0 / f64::from(*p99)
}

/// Writes each page of `atlas` as `dir/{prefix}page_N.exr` (32-bit float
/// RGB): a second layer in the first's layout (ρ^sun beside ρ^se), which
/// the same texture coordinates address.
pub fn write_page_exrs(atlas: &Atlas, dir: &Path, prefix: &str) -> Result<Vec<PathBuf>, TextureError> {
    std::fs::create_dir_all(dir).map_err(|e| file_error(dir, e))?;
    let mut out = Vec::new();
    for (n, page) in atlas.pages.iter().enumerate() {
        let exr = dir.join(format!("{prefix}page_{n}.exr"));
        let map = RadianceMap {
            width: page.width,
            height: page.height,
            rgb: page.rgb.clone(),
            variance: Vec::new(),
            mask: Vec::new(),
        };
        write_rgb_exr(&map, &exr, ExrPrecision::Float).map_err(|e| file_error(&exr, e))?;
        out.push(exr);
    }
    Ok(out)
}

/// Writes `model.obj`, `model.mtl` and the pages into `dir` (made if
/// missing), the previews tone-mapped by [`preview_scale`].
pub fn export(scene: &Scene, patches: &[Patch], atlas: &Atlas, dir: &Path) -> Result<Exported, TextureError> {
    export_scaled(scene, patches, atlas, dir, None)
}

/// [`export`] with the previews' scale given (`Some(1.0)` for albedo: the
/// PNG is then the diffuse colour itself, sRGB-encoded, clipped at 1), or
/// from [`preview_scale`] when `None`.
pub fn export_scaled(
    scene: &Scene,
    patches: &[Patch],
    atlas: &Atlas,
    dir: &Path,
    scale: Option<f64>,
) -> Result<Exported, TextureError> {
    let scale = scale.unwrap_or_else(|| preview_scale(atlas));
    let exrs = write_page_exrs(atlas, dir, "")?;
    let mut pages = Vec::new();
    for ((n, page), exr) in atlas.pages.iter().enumerate().zip(exrs) {
        let png = dir.join(format!("page_{n}.png"));
        let bytes: Vec<u8> = page.rgb.iter().map(|&v| srgb(f64::from(v) * scale)).collect();
        image::RgbImage::from_raw(page.width as u32, page.height as u32, bytes)
            .ok_or_else(|| file_error(&png, "page buffer does not match its size"))?
            .save(&png)
            .map_err(|e| file_error(&png, e))?;
        pages.push((exr, png));
    }
    let mut mtl = String::from("# Campanile texture atlas (thesis §3.4): one material per page.\n");
    for n in 0..atlas.pages.len() {
        let _ = write!(
            mtl,
            "\nnewmtl page_{n}\nKa 0 0 0\nKd 1 1 1\nKs 0 0 0\nillum 1\n# linear values: page_{n}.exr\nmap_Kd page_{n}.png\n"
        );
    }
    let mtl_path = dir.join("model.mtl");
    std::fs::write(&mtl_path, mtl).map_err(|e| file_error(&mtl_path, e))?;
    let mut obj = String::from("# Campanile textured model (thesis §3.4)\nmtllib model.mtl\n");
    let mut vertex = 0usize;
    for (k, patch) in patches.iter().enumerate() {
        let _ = write!(
            obj,
            "g {}\nusemtl page_{}\n",
            scene.surfaces()[patch.surface].replace(char::is_whitespace, "_"),
            atlas.placements[k].page
        );
        for &t in &patch.triangles {
            let tri = &scene.triangles()[t];
            for v in &tri.vertices {
                let _ = writeln!(obj, "v {} {} {}", v.x, v.y, v.z);
            }
            for v in &tri.vertices {
                let [u, w] = atlas.uv(patch, k, v);
                let _ = writeln!(obj, "vt {u} {w}");
            }
            let n = tri.normal;
            let _ = writeln!(obj, "vn {} {} {}", n.x, n.y, n.z);
            vertex += 3;
            let normal = vertex / 3;
            let _ = writeln!(
                obj,
                "f {a}/{a}/{normal} {b}/{b}/{normal} {c}/{c}/{normal}",
                a = vertex - 2,
                b = vertex - 1,
                c = vertex
            );
        }
    }
    let obj_path = dir.join("model.obj");
    std::fs::write(&obj_path, obj).map_err(|e| file_error(&obj_path, e))?;
    Ok(Exported {
        obj: obj_path,
        mtl: mtl_path,
        pages,
        preview_scale: scale,
    })
}

#[cfg(test)]
mod tests {
    use nalgebra::Vector3;

    use super::*;
    use crate::exr_io::read_rgb_exr;
    use crate::render::{Material, Triangle};
    use crate::texture::atlas::{AtlasSettings, pack};
    use crate::texture::patch::patches;
    use crate::texture::synthesis::{PatchTexture, TexelStatus};

    /// The OBJ and MTL parse back with `tobj`; the material's `map_Kd` is
    /// the page's PNG; each vertex's texture coordinates, looked up in the
    /// EXR read back, give the value the texel at that corner holds.
    #[test]
    fn obj_and_mtl_parse_back_and_uvs_land_on_the_texels() {
        let v = |x: f64, y: f64, z: f64| Vector3::new(x, y, z);
        let tris = vec![
            Triangle::new([v(0.0, 0.0, 0.0), v(3.0, 0.0, 0.0), v(3.0, 0.0, 2.0)], 0, 0).unwrap(),
            Triangle::new([v(0.0, 0.0, 0.0), v(3.0, 0.0, 2.0), v(0.0, 0.0, 2.0)], 0, 0).unwrap(),
            Triangle::new([v(5.0, 1.0, 0.0), v(5.0, 3.0, 0.0), v(5.0, 3.0, 1.0)], 0, 1).unwrap(),
        ];
        let scene = Scene::new(
            tris,
            vec![Material::diffuse("m", [0.5; 3])],
            vec!["front wall".into(), "side".into()],
        )
        .unwrap();
        let ps = patches(&scene, None, 0.25, 100_000).unwrap();
        // Radiance = x + 2 z + 10 · patch: a value each corner's texel can be checked against.
        let textures: Vec<PatchTexture> = ps
            .iter()
            .enumerate()
            .map(|(k, p)| PatchTexture {
                rgb: (0..p.rows)
                    .flat_map(|j| (0..p.cols).map(move |i| (i, j)))
                    .map(|(i, j)| {
                        let c = p.texel_centre(i, j);
                        [(c.x + 2.0 * c.z + 10.0 * k as f64) as f32, 1.0, 2.0]
                    })
                    .collect(),
                weight: vec![1.0; p.cols * p.rows],
                status: vec![TexelStatus::Seen; p.cols * p.rows],
                photos: vec![1; p.cols * p.rows],
                spread: vec![0.0; p.cols * p.rows],
            })
            .collect();
        let atlas = pack(&scene, &ps, &textures, &AtlasSettings::default()).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let out = export(&scene, &ps, &atlas, dir.path()).unwrap();
        let (models, materials) = tobj::load_obj(
            &out.obj,
            &tobj::LoadOptions {
                single_index: true,
                triangulate: true,
                ..Default::default()
            },
        )
        .unwrap();
        let materials = materials.unwrap();
        assert_eq!(materials.len(), 1);
        assert_eq!(materials[0].diffuse_texture.as_deref(), Some("page_0.png"));
        assert_eq!(models.len(), 2);
        assert_eq!(models[0].name, "front_wall");
        let page = read_rgb_exr(&out.pages[0].0).unwrap();
        assert_eq!((page.width, page.height), (atlas.pages[0].width, atlas.pages[0].height));
        let png = image::open(&out.pages[0].1).unwrap();
        assert_eq!(png.width() as usize, page.width);
        for (k, m) in models.iter().enumerate() {
            let mesh = &m.mesh;
            assert_eq!(mesh.texcoords.len() / 2, mesh.positions.len() / 3);
            for (q, uv) in mesh.texcoords.chunks_exact(2).enumerate() {
                let p = &mesh.positions[q * 3..q * 3 + 3];
                // The texel at the corner: the lookup a small step inside
                // the patch must be within one texel's change of the corner's value.
                let x = f64::from(uv[0]) * page.width as f64;
                let y = (1.0 - f64::from(uv[1])) * page.height as f64;
                let got = atlas.lookup(0, x, y)[0];
                let want = f64::from(p[0]) + 2.0 * f64::from(p[2]) + 10.0 * k as f64;
                // Corners lie at texel edges, half a texel from a centre:
                // at most 0.125 m in x and z, 0.375 in value.
                assert!(
                    (got - want).abs() <= 0.375 + 1e-4,
                    "patch {k} vertex {p:?}: {got} vs {want}"
                );
                let texel = (y as usize * page.width + x.min(page.width as f64 - 1.0) as usize) * 3;
                assert_eq!(page.data[texel + 1], 1.0);
            }
        }
        assert!(out.preview_scale > 0.0);
    }
}

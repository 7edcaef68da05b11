//! `campanile texture` on files (thesis §3.4): a scene description and its
//! OBJ, registered camera poses (`campanile register`'s `RegisteredPoses`
//! file, or the scene file's own `poses`), the station whose camera took
//! the photographs, and the HDR photographs themselves; out come the
//! textured model ([`campanile_process::texture::export`]) and
//! `texture.ron`, which records the figures and the verdict.
//!
//! Photographs are found by pose name: `DIR/NAME.exr` (or `.hdr`, `.pfm`)
//! when a photo directory is given; else, for a registered pose, the
//! registered photograph's path with the extension `.exr` (an HDR merge
//! beside the 8-bit picture registration read), or the registered file
//! itself when it is HDR. Relative paths are taken from the poses file's
//! directory. Every photograph must be a radiance image: 8-bit pictures
//! carry a tone curve, not radiance, and are refused.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use campanile_process::pose::Pinhole;
use campanile_process::radiance_file::read_radiance_image;
use campanile_process::render::{Material, Scene};
use campanile_process::scene_geometry::load_obj;
use campanile_process::texture::export::{Exported, export};
use campanile_process::texture::{
    Atlas, AtlasSettings, Patch, Quality, QualityLimits, SynthesisReport, SynthesisSettings, TexturePhoto, judge, pack,
    patches, pose_from_angles, seam_figures, synthesize_with_progress,
};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use crate::error::bad_input;
use crate::register_files::RegisteredPoses;

/// Most texels `texture` makes (four 4096² pages).
pub const MAX_TEXELS: usize = 64 << 20;

/// What `texture` was asked.
#[derive(Debug, Clone)]
pub struct TextureRequest {
    /// The scene description.
    pub scene: PathBuf,
    /// The registered poses (`None`: the scene file's `poses`).
    pub poses: Option<PathBuf>,
    /// The station whose camera took the photographs.
    pub station: PathBuf,
    /// Where the photographs are, by pose name.
    pub photos: Option<PathBuf>,
    /// The output directory.
    pub out: PathBuf,
    /// Texel side, metres.
    pub texel_m: f64,
    /// The surfaces to texture (`None`: all).
    pub surfaces: Option<Vec<String>>,
    /// Verdict thresholds.
    pub limits: QualityLimits,
}

/// One photograph as used.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PhotoUse {
    /// The pose's name.
    pub name: String,
    /// The radiance file read.
    pub file: PathBuf,
    /// Texels it contributed to.
    pub texels: usize,
    /// Texels in its frame hidden by another surface.
    pub occluded: usize,
    /// Texels in its frame seen too obliquely.
    pub grazing: usize,
    /// The image shift, pixels, at which it agrees best with the other
    /// photographs (`None`: too few shared texels).
    #[serde(default)]
    pub shift_px: Option<[f64; 2]>,
}

/// One patch as written.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PatchRecord {
    /// The surface.
    pub surface: String,
    /// Atlas page.
    pub page: usize,
    /// Rectangle in the page, gutter included: x, y, width, height.
    pub rect: (usize, usize, usize, usize),
    /// Texels on the face.
    pub texels: usize,
    /// Of those, seen by no photograph (filled from neighbours).
    pub unseen: usize,
}

/// `texture.ron`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename = "TextureMaps")]
pub struct TextureManifest {
    /// Texel side, metres.
    pub texel_m: f64,
    /// The OBJ, relative to the manifest.
    pub obj: String,
    /// Pages: (EXR, PNG) file names.
    pub pages: Vec<(String, String)>,
    /// The PNG previews' scale: linear value × scale = white.
    pub preview_scale: f64,
    /// The photographs.
    pub photos: Vec<PhotoUse>,
    /// The patches.
    pub patches: Vec<PatchRecord>,
    /// The verdict and its figures.
    pub quality: Quality,
    /// Wall time of synthesis, packing and export, seconds.
    pub seconds: f64,
}

/// What `texture` did.
#[derive(Debug, Clone)]
pub struct TextureRun {
    /// The manifest written.
    pub manifest: TextureManifest,
    /// Where it was written.
    pub manifest_path: PathBuf,
    /// The files written.
    pub exported: Exported,
    /// The synthesis report.
    pub report: SynthesisReport,
}

/// The scene's triangles (materials are not needed: every surface is
/// textured from photographs).
fn load_geometry(path: &Path) -> anyhow::Result<(campanile_config::Scene, Scene)> {
    let loaded = campanile_config::document::load_scene(path)?;
    let description = loaded.value;
    let obj = loaded.source.base_dir().join(&description.geometry);
    let geometry = load_obj(&description, &obj).map_err(|e| bad_input(e.to_string()))?;
    let materials = geometry
        .material_names
        .iter()
        .map(|n| Material::diffuse(n, [0.5; 3]))
        .collect();
    let scene = Scene::new(geometry.triangles, materials, geometry.surface_names)
        .map_err(|e| bad_input(format!("{}: {e}", obj.display())))?;
    Ok((description, scene))
}

/// A pose to texture from: its name, pose and the file it points at.
struct PoseEntry {
    name: String,
    position: (f64, f64, f64),
    azimuth_deg: f64,
    elevation_deg: f64,
    roll_deg: f64,
    registered_file: Option<PathBuf>,
}

fn poses_of(request: &TextureRequest, description: &campanile_config::Scene) -> anyhow::Result<Vec<PoseEntry>> {
    let Some(path) = &request.poses else {
        if description.poses.is_empty() {
            return Err(bad_input(format!(
                "{}: poses: the scene file lists no camera poses; give --poses POSES.ron from `campanile register`",
                request.scene.display()
            )));
        }
        return Ok(description
            .poses
            .iter()
            .map(|p| PoseEntry {
                name: p.name.clone(),
                position: p.position_m,
                azimuth_deg: p.azimuth_deg,
                elevation_deg: p.elevation_deg,
                roll_deg: 0.0,
                registered_file: None,
            })
            .collect());
    };
    let text = std::fs::read_to_string(path).map_err(|e| bad_input(format!("{}: {e}", path.display())))?;
    let file: RegisteredPoses = ron::from_str(&text).map_err(|e| {
        bad_input(format!(
            "{}: {e}: expected a RegisteredPoses(poses: [...], photos: [...]) file from `campanile register`",
            path.display()
        ))
    })?;
    let base = path.parent().unwrap_or(Path::new("."));
    let mut out = Vec::new();
    for p in &file.poses {
        let reg = file.photos.iter().find(|r| r.name == p.name);
        let roll_deg = reg.and_then(|r| r.roll_deg).unwrap_or(0.0);
        out.push(PoseEntry {
            name: p.name.clone(),
            position: p.position_m,
            azimuth_deg: p.azimuth_deg,
            elevation_deg: p.elevation_deg,
            roll_deg,
            registered_file: reg.map(|r| {
                if r.file.is_absolute() || r.file.exists() {
                    r.file.clone()
                } else {
                    base.join(&r.file)
                }
            }),
        });
    }
    if out.is_empty() {
        return Err(bad_input(format!(
            "{}: poses: no registered pose (every photograph failed registration)",
            path.display()
        )));
    }
    Ok(out)
}

/// The radiance file of pose `entry` (module doc).
fn photo_file(request: &TextureRequest, entry: &PoseEntry) -> anyhow::Result<PathBuf> {
    let mut tried = Vec::new();
    if let Some(dir) = &request.photos {
        for ext in ["exr", "hdr", "pfm"] {
            let p = dir.join(format!("{}.{ext}", entry.name));
            if p.is_file() {
                return Ok(p);
            }
            tried.push(p);
        }
    } else if let Some(file) = &entry.registered_file {
        let exr = file.with_extension("exr");
        if exr.is_file() {
            return Ok(exr);
        }
        tried.push(exr);
        if file.is_file() {
            return Ok(file.clone());
        }
        tried.push(file.clone());
    }
    Err(bad_input(format!(
        "pose {:?}: no radiance photograph found (tried {}); expected an HDR image (OpenEXR, RGBE or PFM) named \
         after the pose{}",
        entry.name,
        if tried.is_empty() {
            "nothing".to_string()
        } else {
            tried
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        },
        if request.photos.is_none() {
            ": give --photos DIR"
        } else {
            ""
        }
    )))
}

/// `--texel` must be a positive length.
fn check_texel(t: f64) -> anyhow::Result<()> {
    if t.is_finite() && t > 0.0 {
        Ok(())
    } else {
        Err(bad_input(format!("--texel {t}: expected a positive length in metres")))
    }
}

/// A written file's name, as the manifest records it (relative to it).
fn file_name(p: &Path) -> String {
    p.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// The atlas pages' file names (EXR, PNG preview) as a manifest lists them.
fn page_names(exported: &Exported) -> Vec<(String, String)> {
    exported
        .pages
        .iter()
        .map(|(e, p)| (file_name(e), file_name(p)))
        .collect()
}

/// Each patch's record: its surface, atlas rectangle (gutter included)
/// and texel counts.
fn patch_records(scene: &Scene, ps: &[Patch], atlas: &Atlas, per_patch: &[(usize, usize)]) -> Vec<PatchRecord> {
    ps.iter()
        .zip(&atlas.placements)
        .zip(per_patch)
        .map(|((p, pl), &(texels, unseen))| PatchRecord {
            surface: scene.surfaces()[p.surface].clone(),
            page: pl.page,
            rect: (pl.x, pl.y, p.cols + 2 * atlas.gutter, p.rows + 2 * atlas.gutter),
            texels,
            unseen,
        })
        .collect()
}

/// Writes `manifest` as `out/texture.ron`; returns its path.
fn write_manifest(out: &Path, manifest: &impl Serialize) -> anyhow::Result<PathBuf> {
    let path = out.join("texture.ron");
    let text =
        ron::ser::to_string_pretty(manifest, ron::ser::PrettyConfig::default()).context("serializing texture.ron")?;
    std::fs::write(&path, text + "\n").with_context(|| format!("writing {}", path.display()))?;
    Ok(path)
}

/// Runs `texture` (module doc); `bar` gets the steps' count, then one tick per step.
pub fn texture_files(request: &TextureRequest, bar: &indicatif::ProgressBar) -> anyhow::Result<TextureRun> {
    check_texel(request.texel_m)?;
    let (description, scene) = load_geometry(&request.scene)?;
    let station = campanile_config::load_station(&request.station)?.value;
    let configured = Pinhole::of_camera(&station.camera);
    let size = (
        station.camera.resolution.width as usize,
        station.camera.resolution.height as usize,
    );
    let mut photos = Vec::new();
    let mut files = Vec::new();
    for entry in poses_of(request, &description)? {
        let file = photo_file(request, &entry)?;
        let image = read_radiance_image(&file).map_err(|e| bad_input(e.to_string()))?.image;
        let (w, h) = (image.width, image.height);
        if (w as f64 / h as f64 - size.0 as f64 / size.1 as f64).abs() > 0.01 {
            return Err(bad_input(format!(
                "{}: {w} × {h} pixels, but the station's camera is {} × {}: expected the same aspect ratio",
                file.display(),
                size.0,
                size.1
            )));
        }
        let (x, y, z) = entry.position;
        let pose = pose_from_angles(
            Vector3::new(x, y, z),
            entry.azimuth_deg,
            entry.elevation_deg,
            entry.roll_deg,
        )
        .ok_or_else(|| {
            bad_input(format!(
                "pose {:?}: elevation_deg {} with roll_deg {}: expected an optical axis that is not vertical",
                entry.name, entry.elevation_deg, entry.roll_deg
            ))
        })?;
        let photo = TexturePhoto::new(&entry.name, image, &pose, configured.rescaled(size, w, h))
            .map_err(|e| bad_input(format!("{}: {e}", file.display())))?;
        photos.push(photo);
        files.push(file);
    }
    let start = Instant::now();
    let ps = patches(&scene, request.surfaces.as_deref(), request.texel_m, MAX_TEXELS)
        .map_err(|e| bad_input(format!("{}: {e}", request.scene.display())))?;
    bar.set_length((photos.len() + ps.len()) as u64);
    let synthesis = synthesize_with_progress(&scene, &ps, &photos, &SynthesisSettings::default(), &|| bar.inc(1))?;
    let atlas =
        pack(&scene, &ps, &synthesis.textures, &AtlasSettings::default()).map_err(|e| bad_input(e.to_string()))?;
    let exported = export(&scene, &ps, &atlas, &request.out)?;
    let seconds = start.elapsed().as_secs_f64();
    let seams = seam_figures(&ps, &synthesis.textures);
    let quality = judge(&synthesis.report, &seams, &request.limits);
    let r = &synthesis.report;
    let manifest = TextureManifest {
        texel_m: request.texel_m,
        obj: file_name(&exported.obj),
        pages: page_names(&exported),
        preview_scale: exported.preview_scale,
        photos: photos
            .iter()
            .zip(&files)
            .enumerate()
            .map(|(k, (p, f))| PhotoUse {
                name: p.label.clone(),
                file: f.clone(),
                texels: r.used[k],
                occluded: r.occluded[k],
                grazing: r.grazing[k],
                shift_px: r.offsets.get(k).copied().flatten().map(|o| o.shift_px),
            })
            .collect(),
        patches: patch_records(&scene, &ps, &atlas, &r.per_patch),
        quality,
        seconds,
    };
    let manifest_path = write_manifest(&request.out, &manifest)?;
    Ok(TextureRun {
        manifest,
        manifest_path,
        exported,
        report: synthesis.report,
    })
}

/// What `texture --albedo` was asked.
#[derive(Debug, Clone)]
pub struct AlbedoTextureRequest {
    /// The scene description.
    pub scene: PathBuf,
    /// The albedo products: `materials.ron`, or the directory holding it
    /// (`albedo/`, or the `process` output directory above it).
    pub albedo: PathBuf,
    /// The output directory.
    pub out: PathBuf,
    /// Texel side, metres (`None`: the products' grid spacing).
    pub texel_m: Option<f64>,
    /// The surfaces to texture (`None`: every surface the products cover).
    pub surfaces: Option<Vec<String>>,
    /// Verdict thresholds.
    pub limits: QualityLimits,
}

/// One surface's cells in the products, by how their pseudo-albedos were
/// obtained (the materials file's counts; thesis §5.4).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ProductCells {
    /// The surface.
    pub surface: String,
    /// Solved from their own sunlit and shadowed views.
    pub solved: usize,
    /// Never seen sunlit (ρ^sun from the face's ratio).
    pub never_sunlit: usize,
    /// Never seen shadowed (one unknown through the face's ratio).
    pub never_shadowed: usize,
    /// Sunlit and shadowed views too alike to separate.
    pub ill_conditioned: usize,
    /// Seen by no photograph (filled in the products; unseen here).
    pub unseen: usize,
}

/// `texture.ron` of an albedo texture.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename = "AlbedoTextureMaps")]
pub struct AlbedoTextureManifest {
    /// The materials file read.
    pub materials: PathBuf,
    /// The products' grid spacing, metres.
    pub spacing_m: f64,
    /// Texel side, metres.
    pub texel_m: f64,
    /// The OBJ, relative to the manifest.
    pub obj: String,
    /// ρ^se pages: (EXR, PNG) file names; the MTL's `map_Kd` is the PNG.
    pub pages: Vec<(String, String)>,
    /// ρ^sun pages (EXR), in the same layout.
    pub sun_pages: Vec<String>,
    /// The patches.
    pub patches: Vec<PatchRecord>,
    /// The products' cells per surface.
    pub products: Vec<ProductCells>,
    /// The recovery's findings, from the materials file.
    pub diagnostics: Vec<String>,
    /// The verdict and its figures (coverage: texels on cells a photograph saw).
    pub quality: Quality,
    /// Wall time of sampling, packing and export, seconds.
    pub seconds: f64,
}

/// What `texture --albedo` did.
#[derive(Debug, Clone)]
pub struct AlbedoTextureRun {
    /// The manifest written.
    pub manifest: AlbedoTextureManifest,
    /// Where it was written.
    pub manifest_path: PathBuf,
    /// The files written (ρ^se).
    pub exported: Exported,
    /// The sampling report.
    pub report: SynthesisReport,
}

/// The materials file `path` names (module doc of [`AlbedoTextureRequest::albedo`]).
fn materials_file(path: &Path) -> anyhow::Result<PathBuf> {
    if path.is_file() {
        return Ok(path.to_path_buf());
    }
    if !path.is_dir() {
        return Err(bad_input(format!(
            "--albedo {}: no such file or directory; expected the albedo/ directory `campanile process` or \
             `campanile outdoor recover` writes (with materials.ron), or that materials.ron",
            path.display()
        )));
    }
    for candidate in [path.join("materials.ron"), path.join("albedo").join("materials.ron")] {
        if candidate.is_file() {
            return Ok(candidate);
        }
    }
    let igi_maps = std::fs::read_dir(path)
        .map(|d| {
            d.filter_map(Result::ok)
                .any(|e| e.path().extension().is_some_and(|x| x == "exr"))
        })
        .unwrap_or(false);
    Err(bad_input(format!(
        "--albedo {}: no materials.ron here or in albedo/ and no layout.json; expected the pseudo-albedo products of \
         `campanile process` or `campanile outdoor recover`, or the albedo maps of `campanile igi`{}",
        path.display(),
        if igi_maps {
            " (the EXR files here look like `campanile igi`'s per-group albedo maps, but their layout.json is \
             missing: run `campanile igi` again to write it)"
        } else {
            ""
        }
    )))
}

/// Runs `texture --albedo`: albedo textures from the recovered
/// pseudo-albedos ([`campanile_process::texture::albedo`]). `bar` gets the
/// patches' count, then one tick per patch and layer.
pub fn albedo_texture_files(
    request: &AlbedoTextureRequest,
    bar: &indicatif::ProgressBar,
) -> anyhow::Result<AlbedoTextureRun> {
    use campanile_process::outdoor::atlas::{MaterialsFile, read_materials};
    use campanile_process::texture::export::{export_scaled, write_page_exrs};
    use campanile_process::texture::{PseudoAlbedo, albedo_synthesis, judge_albedo, patches_on_lattice};

    if let Some(t) = request.texel_m {
        check_texel(t)?;
    }
    let materials = materials_file(&request.albedo)?;
    let (_, scene) = load_geometry(&request.scene)?;
    let text = std::fs::read_to_string(&materials).map_err(|e| bad_input(format!("{}: {e}", materials.display())))?;
    let file: MaterialsFile = ron::from_str(&text).map_err(|e| {
        bad_input(format!(
            "{}: {e}: expected a materials file (MaterialsFile(spacing_m: …, faces: […])) as `campanile process` \
             writes it",
            materials.display()
        ))
    })?;
    let refl = read_materials(&scene, &materials).map_err(|e| bad_input(e.to_string()))?;
    let texel_m = request.texel_m.unwrap_or(refl.grid.spacing_m);
    let covered: Vec<String> = refl.grid.targets.iter().map(|&s| scene.surfaces()[s].clone()).collect();
    let surfaces = request.surfaces.clone().unwrap_or_else(|| covered.clone());
    let start = Instant::now();
    let ps = patches_on_lattice(&scene, Some(&surfaces), texel_m, MAX_TEXELS)
        .map_err(|e| bad_input(format!("{}: {e}", request.scene.display())))?;
    bar.set_length(2 * ps.len() as u64);
    let se = albedo_synthesis(&scene, &ps, &refl, PseudoAlbedo::SkyEnvironment, &|| bar.inc(1))
        .map_err(|e| bad_input(format!("{}: {e}", materials.display())))?;
    let sun = albedo_synthesis(&scene, &ps, &refl, PseudoAlbedo::Sun, &|| bar.inc(1))
        .map_err(|e| bad_input(format!("{}: {e}", materials.display())))?;
    let settings = AtlasSettings::default();
    let atlas = pack(&scene, &ps, &se.textures, &settings).map_err(|e| bad_input(e.to_string()))?;
    let sun_atlas = pack(&scene, &ps, &sun.textures, &settings).map_err(|e| bad_input(e.to_string()))?;
    if sun_atlas.placements != atlas.placements {
        anyhow::bail!("the ρ^sun patches packed differently from the ρ^se patches (the packer is not deterministic)");
    }
    let exported = export_scaled(&scene, &ps, &atlas, &request.out, Some(1.0))?;
    let sun_pages = write_page_exrs(&sun_atlas, &request.out, "sun_")?;
    let seconds = start.elapsed().as_secs_f64();
    let quality = judge_albedo(&se.report, &request.limits);
    let mut products: Vec<ProductCells> = Vec::new();
    for f in &file.faces {
        let entry = match products.iter_mut().find(|p| p.surface == f.surface) {
            Some(e) => e,
            None => {
                products.push(ProductCells {
                    surface: f.surface.clone(),
                    solved: 0,
                    never_sunlit: 0,
                    never_shadowed: 0,
                    ill_conditioned: 0,
                    unseen: 0,
                });
                products.last_mut().expect("just pushed")
            }
        };
        let [a, b, c, d, e] = f.statuses;
        entry.solved += a;
        entry.never_sunlit += b;
        entry.never_shadowed += c;
        entry.ill_conditioned += d;
        entry.unseen += e;
    }
    let r = &se.report;
    let manifest = AlbedoTextureManifest {
        materials: materials.clone(),
        spacing_m: refl.grid.spacing_m,
        texel_m,
        obj: file_name(&exported.obj),
        pages: page_names(&exported),
        sun_pages: sun_pages.iter().map(|p| file_name(p)).collect(),
        patches: patch_records(&scene, &ps, &atlas, &r.per_patch),
        products,
        diagnostics: file.diagnostics,
        quality,
        seconds,
    };
    let manifest_path = write_manifest(&request.out, &manifest)?;
    Ok(AlbedoTextureRun {
        manifest,
        manifest_path,
        exported,
        report: se.report,
    })
}

/// The `layout.json` of `campanile igi`'s albedo maps that `path` names:
/// that file, or in `path` (the albedo directory), `path/albedo` (the
/// `igi` output directory) or `path/room/igi/albedo` (a session's output
/// directory after `campanile process` on a room session); `None` when
/// there is none.
pub fn igi_layout_file(path: &Path) -> Option<PathBuf> {
    use campanile_process::igi::albedo_chart::LAYOUT_FILE;
    if path.is_file() {
        return (path.file_name().is_some_and(|n| n == LAYOUT_FILE)).then(|| path.to_path_buf());
    }
    [
        path.join(LAYOUT_FILE),
        path.join("albedo").join(LAYOUT_FILE),
        path.join("room").join("igi").join("albedo").join(LAYOUT_FILE),
    ]
    .into_iter()
    .find(|p| p.is_file())
}

/// One albedo map as used.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MapUse {
    /// The OBJ group.
    pub group: String,
    /// Its surface.
    pub surface: String,
    /// The map's texels on the group, and of them seen by a view, filled
    /// from neighbours, and the surface's recovered ρd (the index's counts).
    pub texels: usize,
    /// Seen by a view.
    pub seen: usize,
    /// Filled from seen texels within 3 texels.
    pub filled: usize,
    /// The surface's recovered ρd.
    pub surface_mean: usize,
}

/// `texture.ron` of an albedo texture from `campanile igi`'s albedo maps.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename = "IgiAlbedoTextureMaps")]
pub struct IgiAlbedoTextureManifest {
    /// The maps' index read.
    pub layout: PathBuf,
    /// The maps' texel side, metres.
    pub maps_texel_m: f64,
    /// Texel side, metres.
    pub texel_m: f64,
    /// The OBJ, relative to the manifest.
    pub obj: String,
    /// ρd pages: (EXR, PNG) file names; the MTL's `map_Kd` is the PNG.
    pub pages: Vec<(String, String)>,
    /// The patches.
    pub patches: Vec<PatchRecord>,
    /// The maps of the surfaces textured.
    pub maps: Vec<MapUse>,
    /// Faces not textured (a triangle of theirs has no map), with the reason.
    pub not_textured: Vec<String>,
    /// The verdict and its figures (coverage: texels on map texels a view saw).
    pub quality: Quality,
    /// Wall time of reading, resampling, packing and export, seconds.
    pub seconds: f64,
}

/// What `texture --albedo` did with `campanile igi`'s maps.
#[derive(Debug, Clone)]
pub struct IgiAlbedoTextureRun {
    /// The manifest written.
    pub manifest: IgiAlbedoTextureManifest,
    /// Where it was written.
    pub manifest_path: PathBuf,
    /// The files written.
    pub exported: Exported,
    /// The resampling report.
    pub report: SynthesisReport,
}

/// The maps of `index` (read from `layout`) checked against `geometry`
/// (errors name the file, the field, the value and what was expected);
/// per triangle of `geometry`, its map.
fn igi_chart_of(
    layout: &Path,
    index: &campanile_process::igi::albedo_chart::AlbedoMapIndex,
    geometry: &campanile_process::igi::scene_file::IgiGeometry,
) -> anyhow::Result<Vec<Option<usize>>> {
    use campanile_process::igi::albedo_chart::{LAYOUT_FORMAT, LAYOUT_VERSION};
    let err = |field: String, value: String, expected: String| {
        bad_input(format!("{}: {field} = {value}: expected {expected}", layout.display()))
    };
    if index.format != LAYOUT_FORMAT || index.version != LAYOUT_VERSION {
        return Err(err(
            "format, version".into(),
            format!("{:?}, {}", index.format, index.version),
            format!("{LAYOUT_FORMAT:?}, {LAYOUT_VERSION}"),
        ));
    }
    if !(index.texel_m.is_finite() && index.texel_m > 0.0) {
        return Err(err(
            "texel_m".into(),
            index.texel_m.to_string(),
            "a length > 0 m".into(),
        ));
    }
    let obj = geometry.obj.display();
    let mut chart_of = vec![None; geometry.triangles.len()];
    for (m, rec) in index.maps.iter().enumerate() {
        let Some(g) = geometry.groups.iter().position(|n| n == &rec.group) else {
            return Err(err(
                format!("maps[{m}].group"),
                format!("{:?}", rec.group),
                format!(
                    "an OBJ group of {obj} (it has: {}); the maps were recovered on another geometry",
                    geometry.groups.join(", ")
                ),
            ));
        };
        let members: Vec<usize> = (0..geometry.triangles.len())
            .filter(|&i| geometry.triangle_group[i] == g)
            .collect();
        let l = &rec.layout;
        if l.triangles.len() != members.len() {
            return Err(err(
                format!("maps[{m}].layout.triangles"),
                format!("{} triangles", l.triangles.len()),
                format!(
                    "the {} triangles of group {:?} in {obj}; the maps were recovered on another geometry",
                    members.len(),
                    rec.group
                ),
            ));
        }
        if !(l.texel_m.is_finite() && l.texel_m > 0.0 && l.width > 0 && l.height > 0) {
            return Err(err(
                format!("maps[{m}].layout"),
                format!("texel_m {}, {} × {} texels", l.texel_m, l.width, l.height),
                "a texel > 0 m and at least one texel".into(),
            ));
        }
        for (k, (t, &i)) in l.triangles.iter().zip(&members).enumerate() {
            let have = &geometry.triangles[i].vertices;
            let off = (0..3)
                .map(|v| (have[v] - nalgebra::Vector3::from(t.vertices[v])).norm())
                .fold(0.0, f64::max);
            if t.index != i || off.is_nan() || off > 1e-6 {
                return Err(err(
                    format!("maps[{m}].layout.triangles[{k}]"),
                    format!("triangle {} at {:?}", t.index, t.vertices),
                    format!(
                        "triangle {i} of group {:?} in {obj}, at {:?} (within 1 µm); the maps were recovered on another \
                         geometry",
                        rec.group,
                        have.each_ref().map(|v| [v.x, v.y, v.z])
                    ),
                ));
            }
            chart_of[i] = Some(m);
        }
    }
    for (g, name) in geometry.groups.iter().enumerate() {
        let has_triangles = geometry.triangle_group.contains(&g);
        if has_triangles
            && !index.maps.iter().any(|r| &r.group == name)
            && !index.skipped.iter().any(|s| &s.group == name)
        {
            return Err(err(
                "maps, skipped".into(),
                format!("no entry for group {name:?}"),
                format!("one entry per OBJ group of {obj}; the maps were recovered on another geometry"),
            ));
        }
    }
    Ok(chart_of)
}

/// Reads map `rec`'s image and origins beside `layout`.
fn read_chart(
    layout: &Path,
    m: usize,
    rec: &campanile_process::igi::albedo_chart::MapRecord,
) -> anyhow::Result<campanile_process::texture::ChartData> {
    use campanile_process::exr_io::read_rgb_exr;
    use campanile_process::igi::albedo_chart::origin_of_code;
    let dir = layout.parent().unwrap_or(Path::new("."));
    let (w, h) = (rec.layout.width, rec.layout.height);
    let exr = dir.join(&rec.exr);
    let image = read_rgb_exr(&exr).map_err(|e| bad_input(format!("{}: {e}", exr.display())))?;
    if (image.width, image.height) != (w, h) {
        return Err(bad_input(format!(
            "{}: {} × {} texels, but {} maps[{m}].layout says {w} × {h}: expected the map the index describes",
            exr.display(),
            image.width,
            image.height,
            layout.display()
        )));
    }
    let png = dir.join(&rec.seen);
    let mask = image::open(&png)
        .map_err(|e| {
            bad_input(format!(
                "{}: {e}: expected the map's 8-bit grey origin mask",
                png.display()
            ))
        })?
        .into_luma8();
    if (mask.width() as usize, mask.height() as usize) != (w, h) {
        return Err(bad_input(format!(
            "{}: {} × {} pixels, but {} maps[{m}].layout says {w} × {h}: expected the map's origin mask",
            png.display(),
            mask.width(),
            mask.height(),
            layout.display()
        )));
    }
    let origin = mask
        .as_raw()
        .iter()
        .enumerate()
        .map(|(k, &c)| {
            origin_of_code(c).map_err(|c| {
                bad_input(format!(
                    "{}: pixel ({}, {}) = {c}: expected 255 (seen), 128 (filled), 64 (surface ρd) or 0 (outside)",
                    png.display(),
                    k % w,
                    k / w
                ))
            })
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    Ok(campanile_process::texture::ChartData {
        layout: rec.layout.clone(),
        image,
        origin,
    })
}

/// Runs `texture --albedo` on `campanile igi`'s albedo maps (`layout`, from
/// [`igi_layout_file`]): `request.scene` is the IGI scene file the maps were
/// recovered from ([`campanile_process::texture::igi_albedo`]). `bar` gets
/// the patches' count, then one tick per patch.
pub fn igi_albedo_texture_files(
    request: &AlbedoTextureRequest,
    layout: &Path,
    bar: &indicatif::ProgressBar,
) -> anyhow::Result<IgiAlbedoTextureRun> {
    use campanile_process::igi::albedo_chart::AlbedoMapIndex;
    use campanile_process::igi::scene_file::load_geometry;
    use campanile_process::texture::export::export_scaled;
    use campanile_process::texture::{AlbedoSource, igi_albedo_synthesis, judge_albedo_from};

    if let Some(t) = request.texel_m {
        check_texel(t)?;
    }
    let start = Instant::now();
    let text = std::fs::read_to_string(layout).map_err(|e| bad_input(format!("{}: {e}", layout.display())))?;
    let index: AlbedoMapIndex = serde_json::from_str(&text).map_err(|e| {
        bad_input(format!(
            "{}: {e}: expected the albedo maps' index that `campanile igi` writes (format {:?})",
            layout.display(),
            campanile_process::igi::albedo_chart::LAYOUT_FORMAT
        ))
    })?;
    let geometry = load_geometry(&request.scene).map_err(|e| {
        bad_input(format!(
            "{e} (with `campanile igi`'s albedo maps, SCENE is the IGI scene file they were recovered from)"
        ))
    })?;
    let chart_of = igi_chart_of(layout, &index, &geometry)?;
    let materials = geometry
        .surfaces
        .iter()
        .map(|n| Material::diffuse(n, [0.5; 3]))
        .collect();
    let scene = Scene::new(geometry.triangles.clone(), materials, geometry.surfaces.clone())
        .map_err(|e| bad_input(format!("{}: {e}", geometry.obj.display())))?;
    // The faces with a map on every triangle; the others, by surface and
    // group, and why.
    let wanted: Vec<String> = request.surfaces.clone().unwrap_or_else(|| scene.surfaces().to_vec());
    let texel_m = request.texel_m.unwrap_or(index.texel_m);
    let all = patches(&scene, Some(&wanted), texel_m, MAX_TEXELS)
        .map_err(|e| bad_input(format!("{}: {e}", request.scene.display())))?;
    let mut ps = Vec::with_capacity(all.len());
    // (surface, group, faces, triangles)
    let mut lacking: Vec<(usize, usize, usize, usize)> = Vec::new();
    for p in all {
        let Some(&i) = p.triangles.iter().find(|&&i| chart_of[i].is_none()) else {
            ps.push(p);
            continue;
        };
        let g = geometry.triangle_group[i];
        match lacking.iter_mut().find(|l| (l.0, l.1) == (p.surface, g)) {
            Some(l) => {
                l.2 += 1;
                l.3 += p.triangles.len();
            }
            None => lacking.push((p.surface, g, 1, p.triangles.len())),
        }
    }
    let not_textured: Vec<String> = lacking
        .iter()
        .map(|&(s, g, faces, triangles)| {
            let group = &geometry.groups[g];
            let why = index
                .skipped
                .iter()
                .find(|k| &k.group == group)
                .map_or("no map".to_string(), |k| k.reason.clone());
            format!(
                "{}: {faces} face(s), {triangles} triangle(s): group {group:?} has no albedo map ({why})",
                scene.surfaces()[s]
            )
        })
        .collect();
    if request.surfaces.is_some() && !not_textured.is_empty() {
        return Err(bad_input(format!(
            "--surface: {}: expected surfaces whose faces all have albedo maps in {}",
            not_textured.join("; "),
            layout.display()
        )));
    }
    if ps.is_empty() {
        return Err(bad_input(format!(
            "{}: no face has an albedo map on every triangle{}",
            layout.display(),
            if not_textured.is_empty() {
                String::new()
            } else {
                format!(": {}", not_textured.join("; "))
            }
        )));
    }
    let used: Vec<usize> = (0..index.maps.len())
        .filter(|&m| ps.iter().any(|p| p.triangles.iter().any(|&t| chart_of[t] == Some(m))))
        .collect();
    let mut charts = Vec::with_capacity(index.maps.len());
    for (m, rec) in index.maps.iter().enumerate() {
        charts.push(if used.contains(&m) {
            read_chart(layout, m, rec)?
        } else {
            // Not needed: an empty stand-in that no patch reads.
            campanile_process::texture::ChartData {
                layout: campanile_process::igi::albedo_chart::ChartLayout {
                    width: 0,
                    height: 0,
                    ..rec.layout.clone()
                },
                image: campanile_process::camera::image::RadianceImage {
                    width: 0,
                    height: 0,
                    data: Vec::new(),
                },
                origin: Vec::new(),
            }
        });
    }
    bar.set_length(ps.len() as u64);
    let syn = igi_albedo_synthesis(&scene, &ps, &charts, &chart_of, &|| bar.inc(1))
        .map_err(|e| bad_input(format!("{}: {e}", layout.display())))?;
    let atlas = pack(&scene, &ps, &syn.textures, &AtlasSettings::default()).map_err(|e| bad_input(e.to_string()))?;
    let exported = export_scaled(&scene, &ps, &atlas, &request.out, Some(1.0))?;
    let seconds = start.elapsed().as_secs_f64();
    let quality = judge_albedo_from(&syn.report, &request.limits, AlbedoSource::IgiMapTexels);
    let r = &syn.report;
    let manifest = IgiAlbedoTextureManifest {
        layout: layout.to_path_buf(),
        maps_texel_m: index.texel_m,
        texel_m,
        obj: file_name(&exported.obj),
        pages: page_names(&exported),
        patches: patch_records(&scene, &ps, &atlas, &r.per_patch),
        maps: used
            .iter()
            .map(|&m| {
                let rec = &index.maps[m];
                MapUse {
                    group: rec.group.clone(),
                    surface: rec.surface.clone(),
                    texels: rec.texels,
                    seen: rec.seen_texels,
                    filled: rec.filled_texels,
                    surface_mean: rec.surface_mean_texels,
                }
            })
            .collect(),
        not_textured,
        quality,
        seconds,
    };
    let manifest_path = write_manifest(&request.out, &manifest)?;
    Ok(IgiAlbedoTextureRun {
        manifest,
        manifest_path,
        exported,
        report: syn.report,
    })
}

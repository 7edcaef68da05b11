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
    AtlasSettings, Quality, QualityLimits, SynthesisReport, SynthesisSettings, TexturePhoto, judge, pack, patches,
    pose_from_angles, seam_figures, synthesize_with_progress,
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

/// Runs `texture` (module doc); `bar` gets the steps' count, then one tick per step.
pub fn texture_files(request: &TextureRequest, bar: &indicatif::ProgressBar) -> anyhow::Result<TextureRun> {
    if !(request.texel_m.is_finite() && request.texel_m > 0.0) {
        return Err(bad_input(format!(
            "--texel {}: expected a positive length in metres",
            request.texel_m
        )));
    }
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
    let name_of = |p: &Path| {
        p.file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default()
    };
    let manifest = TextureManifest {
        texel_m: request.texel_m,
        obj: name_of(&exported.obj),
        pages: exported.pages.iter().map(|(e, p)| (name_of(e), name_of(p))).collect(),
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
        patches: ps
            .iter()
            .zip(&atlas.placements)
            .zip(&r.per_patch)
            .map(|((p, pl), &(texels, unseen))| PatchRecord {
                surface: scene.surfaces()[p.surface].clone(),
                page: pl.page,
                rect: (pl.x, pl.y, p.cols + 2 * atlas.gutter, p.rows + 2 * atlas.gutter),
                texels,
                unseen,
            })
            .collect(),
        quality,
        seconds,
    };
    let manifest_path = request.out.join("texture.ron");
    let text =
        ron::ser::to_string_pretty(&manifest, ron::ser::PrettyConfig::default()).context("serializing texture.ron")?;
    std::fs::write(&manifest_path, text + "\n").with_context(|| format!("writing {}", manifest_path.display()))?;
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
        "--albedo {}: no materials.ron here or in albedo/; expected the pseudo-albedo products of `campanile process` \
         or `campanile outdoor recover`{}",
        path.display(),
        if igi_maps {
            " (the EXR files here look like `campanile igi`'s per-group albedo maps, which record no layout and \
             are not textured yet)"
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

    if let Some(t) = request.texel_m
        && !(t.is_finite() && t > 0.0)
    {
        return Err(bad_input(format!("--texel {t}: expected a positive length in metres")));
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
    let name_of = |p: &Path| {
        p.file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default()
    };
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
        obj: name_of(&exported.obj),
        pages: exported.pages.iter().map(|(e, p)| (name_of(e), name_of(p))).collect(),
        sun_pages: sun_pages.iter().map(|p| name_of(p)).collect(),
        patches: ps
            .iter()
            .zip(&atlas.placements)
            .zip(&r.per_patch)
            .map(|((p, pl), &(texels, unseen))| PatchRecord {
                surface: scene.surfaces()[p.surface].clone(),
                page: pl.page,
                rect: (pl.x, pl.y, p.cols + 2 * atlas.gutter, p.rows + 2 * atlas.gutter),
                texels,
                unseen,
            })
            .collect(),
        products,
        diagnostics: file.diagnostics,
        quality,
        seconds,
    };
    let manifest_path = request.out.join("texture.ron");
    let text =
        ron::ser::to_string_pretty(&manifest, ron::ser::PrettyConfig::default()).context("serializing texture.ron")?;
    std::fs::write(&manifest_path, text + "\n").with_context(|| format!("writing {}", manifest_path.display()))?;
    Ok(AlbedoTextureRun {
        manifest,
        manifest_path,
        exported,
        report: se.report,
    })
}

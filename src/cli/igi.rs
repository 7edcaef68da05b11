//! `campanile igi SCENE.ron`: inverse global illumination on plain files
//! (thesis ch. 4): the materials table (Table 4.1's layout), each
//! surface's model and why, albedo maps as EXR, a summary JSON, and
//! optionally the scene relit under new lights.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, anyhow};
use campanile_process::camera::image::RadianceImage;
use campanile_process::exr_io::write_radiance_exr;
use campanile_process::hdr::merge::RadianceMap;
use campanile_process::igi::albedo_map::{AlbedoMap, AlbedoMapOptions};
use campanile_process::igi::relight::{RelightSettings, relight};
use campanile_process::igi::relit_scene::recovered_scene;
use campanile_process::igi::scene_file::{LoadedIgiScene, load, load_lights};
use campanile_process::igi::{IgiLight, IgiOptions, IgiResult, format_table, recover};
use campanile_process::quality::{QualityReport, gates};
use clap::Args;

/// Recover every surface's Ward BRDF and albedo map from a scene file.
///
/// SCENE.ron lists OBJ geometry (groups gathered into surfaces that share
/// specular parameters), calibrated cameras (or RADIANCE views), lights
/// (known, RADIANCE light spheres, or HDR images of their bulbs to
/// triangulate) and radiance images (OpenEXR, RADIANCE RGBE .hdr/.pic or
/// PFM) with optional masks; the README documents the format. Writes to --out:
/// materials.txt (Table 4.1's layout, with each surface's model and why),
/// materials.rad (RADIANCE plastic/plastic2/metal/metal2) and materials.xml
/// (Mitsuba 3; see the README for the conversions),
/// summary.json, albedo/GROUP.exr for each planar OBJ group, and with
/// --relight LIGHTS.ron, relit-CAMERA.exr for every camera with an image.
///
/// Example: campanile igi room/scene.ron --out room/igi
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct IgiArgs {
    /// The scene file (RON).
    scene: PathBuf,
    /// Output directory.
    #[arg(long)]
    out: PathBuf,
    /// Lights file (a RON list of Known(...) lights) to relight the scene under.
    #[arg(long)]
    relight: Option<PathBuf>,
    /// A faster, coarser run (fewer radiosity cells, rays and iterations).
    #[arg(long)]
    quick: bool,
    /// Quality thresholds (a `Quality(...)` RON file, any subset of the
    /// gates). Each surface's verdict (its fit's residual, the energy
    /// bound) goes to OUT/quality.json; a failed surface exits 3.
    #[arg(long, value_name = "FILE.ron")]
    thresholds: Option<PathBuf>,
}

/// The solver's and the albedo map's settings: `quick` for the tests and `demo --quick`.
pub fn settings(quick: bool) -> (IgiOptions, AlbedoMapOptions, RelightSettings) {
    let igi = IgiOptions {
        cells_per_edge: if quick { 4 } else { 6 },
        gather_rays: if quick { 32 } else { 64 },
        iterations: if quick { 3 } else { 4 },
        ..IgiOptions::default()
    };
    // Stratified rays and paths (igi::lamp_paths): the maps' irradiance and
    // the relit image's noise well below the relit error (BENCHMARKS.md,
    // the room's noise budget).
    let map = AlbedoMapOptions {
        irradiance_rays: if quick { 64 } else { 128 },
        irradiance_cell_m: 0.125,
        ..AlbedoMapOptions::default()
    };
    let relight = RelightSettings {
        indirect_samples: if quick { 64 } else { 256 },
        ..RelightSettings::default()
    };
    (igi, map, relight)
}

/// What a run recovered.
pub struct Recovered {
    /// The scene file, loaded.
    pub loaded: LoadedIgiScene,
    /// The materials.
    pub result: IgiResult,
    /// The albedo maps.
    pub map: AlbedoMap,
}

/// Loads `scene` and recovers its materials and albedo maps.
pub fn recover_scene(scene: &Path, quick: bool) -> Result<Recovered> {
    let loaded = load(scene)?;
    for w in &loaded.warnings {
        eprintln!("warning: {w}");
    }
    let (opts, map_opts, _) = settings(quick);
    let result = recover(&loaded.input, &opts).map_err(|e| anyhow!("inverse global illumination: {e}"))?;
    let map = AlbedoMap::build(&loaded.input, &result, &map_opts).map_err(|e| anyhow!("albedo maps: {e}"))?;
    Ok(Recovered { loaded, result, map })
}

impl Recovered {
    /// The scene under `lights` from camera `camera` of the scene file.
    pub fn relight(&self, lights: &[IgiLight], camera: &str, quick: bool) -> Result<RadianceImage> {
        let (_, cam) = self
            .loaded
            .cameras
            .iter()
            .find(|(n, _)| n == camera)
            .ok_or_else(|| anyhow!("no camera {camera:?} in the scene file"))?;
        let scene = recovered_scene(&self.loaded.input, &self.result).map_err(|e| anyhow!("{e}"))?;
        Ok(relight(&scene, Some(&self.map), lights, cam, &settings(quick).2))
    }

    /// Names of the cameras that took the solver's images.
    pub fn image_cameras(&self) -> Vec<String> {
        let mut names: Vec<String> = Vec::new();
        for v in &self.loaded.input.views {
            let n = v.name.rsplit_once('#').map_or(v.name.as_str(), |(a, _)| a).to_string();
            if !names.contains(&n) {
                names.push(n);
            }
        }
        names
    }
}

/// Writes `image` as OpenEXR radiance.
pub fn write_exr(image: &RadianceImage, path: &Path) -> Result<()> {
    let n = image.width * image.height;
    let map = RadianceMap {
        width: image.width,
        height: image.height,
        rgb: image.data.clone(),
        variance: vec![0.0; n * 3],
        mask: vec![0; n],
    };
    write_radiance_exr(&map, path).with_context(|| format!("writing {}", path.display()))
}

/// Writes the albedo map of every planar OBJ group to `dir/GROUP.exr`;
/// returns the groups written.
pub fn write_albedo_maps(r: &Recovered, dir: &Path) -> Result<Vec<String>> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let mut written = Vec::new();
    for (g, name) in r.loaded.groups.iter().enumerate() {
        let members: Vec<usize> = (0..r.loaded.triangle_group.len())
            .filter(|&i| r.loaded.triangle_group[i] == g)
            .collect();
        if let Some(img) = r.map.chart(&r.loaded.input.triangles, &members) {
            write_exr(&img, &dir.join(format!("{name}.exr")))?;
            written.push(name.clone());
        }
    }
    Ok(written)
}

/// The summary JSON.
fn summary(r: &Recovered, albedo: &[String]) -> serde_json::Value {
    let surfaces: Vec<serde_json::Value> = r
        .result
        .surfaces
        .iter()
        .map(|s| {
            let m = s.material;
            serde_json::json!({
                "name": s.name,
                "model": format!("{:?}", s.model),
                "kind": format!("{:?}", s.kind),
                "reason": s.reason,
                "rho_d": m.map(|m| m.rho_d),
                "rho_s": m.and_then(|m| m.lobe).map(|l| l.rho_s),
                "alpha_x": m.and_then(|m| m.lobe).map(|l| l.alpha_x),
                "alpha_y": m.and_then(|m| m.lobe).map(|l| l.alpha_y),
                "gamma_deg": m.and_then(|m| m.lobe).map(|l| l.gamma_rad.to_degrees()),
                "samples": s.samples,
                "energy_ok": s.energy_ok,
                "rms_relative": s.rms_relative,
            })
        })
        .collect();
    let lights: Vec<serde_json::Value> = r
        .loaded
        .light_names
        .iter()
        .zip(&r.loaded.input.lights)
        .map(|(n, l)| {
            let t = r.loaded.triangulated.iter().find(|(m, _)| m == n);
            serde_json::json!({
                "name": n,
                "position_m": [l.position.x, l.position.y, l.position.z],
                "radius_m": l.radius,
                "intensity_w_sr": l.intensity,
                "triangulated": t.is_some(),
                "ray_rms_m": t.map(|(_, t)| t.ray_rms_m),
            })
        })
        .collect();
    serde_json::json!({
        "ward_normalization": r.result.variant.to_string(),
        "seconds": r.result.seconds,
        "iterations": r.result.iterations.iter().map(|i| i.max_relative_change).collect::<Vec<_>>(),
        "surfaces": surfaces,
        "lights": lights,
        "albedo_maps": albedo.iter().map(|g| format!("albedo/{g}.exr")).collect::<Vec<_>>(),
        "albedo_samples": {"used": r.map.samples.0, "dropped_brightest": r.map.samples.1},
    })
}

/// Runs `campanile igi`.
/// Writes the recovered materials of `result` as RADIANCE (`STEM.rad`) and
/// Mitsuba 3 (`STEM.xml`) files in `dir`. Each surface's shading frame (for
/// an anisotropic lobe's γ) is its first triangle's, with the normal turned
/// toward `inside` (a point the photographs were taken from) and the
/// texture `s` axis as tangent.
pub fn write_material_files(
    triangles: &[campanile_process::render::Triangle],
    inside: &nalgebra::Vector3<f64>,
    result: &IgiResult,
    dir: &Path,
    stem: &str,
) -> Result<()> {
    use campanile_process::brdf::ShadingFrame;
    use campanile_process::material_export::{ExportMaterial, write_mitsuba, write_radiance};
    let mut list = Vec::new();
    for (s, surface) in result.surfaces.iter().enumerate() {
        let Some(material) = &surface.material else {
            continue;
        };
        let mut m = ExportMaterial::new(&surface.name, material);
        if let Some(t) = triangles.iter().find(|t| t.surface as usize == s) {
            let n = if t.normal.dot(&(inside - t.vertices[0])) >= 0.0 {
                t.normal
            } else {
                -t.normal
            };
            if let Ok(frame) = ShadingFrame::new(n, t.texture_axes[0]) {
                m = m.with_frame(frame);
            }
        }
        list.push(m);
    }
    for (ext, radiance) in [("rad", true), ("xml", false)] {
        let path = dir.join(format!("{stem}.{ext}"));
        let mut out = std::io::BufWriter::new(
            std::fs::File::create(&path).with_context(|| format!("{}: cannot create", path.display()))?,
        );
        if radiance {
            write_radiance(&list, &mut out)
        } else {
            write_mitsuba(&list, &mut out)
        }
        .with_context(|| format!("{}: writing the recovered materials", path.display()))?;
    }
    Ok(())
}

/// Prints the materials table and the triangulated lights, and writes
/// `out/materials.txt`, `materials.rad`, `materials.xml`, `summary.json` and
/// `albedo/GROUP.exr`.
pub fn write_products(r: &Recovered, out: &Path) -> Result<()> {
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let table = format_table(&r.result, &[], None);
    out!("{table}")?;
    for (n, t) in &r.loaded.triangulated {
        outln!(
            "light {n:?} triangulated from {} images: position ({:.4}, {:.4}, {:.4}) m, radius {:.4} m, intensity {:.3?} W/sr, ray rms {:.2} mm",
            t.sightings.len(),
            t.light.position.x,
            t.light.position.y,
            t.light.position.z,
            t.light.radius,
            t.light.intensity,
            t.ray_rms_m * 1e3
        )?;
    }
    let materials = out.join("materials.txt");
    std::fs::write(&materials, &table).with_context(|| format!("writing {}", materials.display()))?;
    let albedo = write_albedo_maps(r, &out.join("albedo"))?;
    let cameras = &r.loaded.cameras;
    let inside = cameras.iter().map(|(_, c)| c.position).sum::<nalgebra::Vector3<f64>>() / cameras.len().max(1) as f64;
    write_material_files(&r.loaded.input.triangles, &inside, &r.result, out, "materials")?;
    let json = out.join("summary.json");
    std::fs::write(&json, serde_json::to_string_pretty(&summary(r, &albedo))?)
        .with_context(|| format!("writing {}", json.display()))?;
    outln!(
        "wrote {}, materials.rad (RADIANCE), materials.xml (Mitsuba 3), {}, {} albedo maps under {}",
        materials.display(),
        json.display(),
        albedo.len(),
        out.join("albedo").display()
    )?;
    Ok(())
}

/// Runs `campanile igi`.
pub fn run(args: IgiArgs) -> Result<()> {
    let q = super::verdicts::thresholds(args.thresholds.as_deref(), None)?;
    let r = recover_scene(&args.scene, args.quick).with_context(|| format!("reading {}", args.scene.display()))?;
    write_products(&r, &args.out)?;
    let quality = QualityReport::new(r.result.surfaces.iter().map(|s| gates::brdf(s, &q)).collect(), &q);
    if let Some(lights) = &args.relight {
        let lights: Vec<IgiLight> = load_lights(lights)
            .map_err(|e| anyhow!("{e}"))?
            .into_iter()
            .map(|(_, l)| l)
            .collect();
        for cam in r.image_cameras() {
            let img = r.relight(&lights, &cam, args.quick)?;
            let path = args.out.join(format!("relit-{cam}.exr"));
            write_exr(&img, &path)?;
            outln!("relit {}", path.display())?;
        }
    }
    super::verdicts::finish(&quality, &args.out.join("quality.json"))
}

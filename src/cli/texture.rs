//! `campanile texture`: texture maps from registered photographs, or from
//! the recovered pseudo-albedos.

use std::path::PathBuf;

use anyhow::Result;
use campanile_process::texture::QualityLimits;
use campanile_session::progress::bar;
use campanile_session::texture_files::{
    AlbedoTextureRequest, TextureRequest, albedo_texture_files, igi_albedo_texture_files, igi_layout_file,
    texture_files,
};
use clap::Args;

use super::exit::{EXIT_OK, EXIT_QUALITY};

/// Texture maps from registered HDR photographs (thesis §3.4), or albedo
/// textures from the recovered pseudo-albedos or IGI albedo maps (--albedo).
///
/// Every face of the scene (coplanar triangles of one named surface) gets a
/// patch of square texels of --texel metres; each texel is the weighted
/// mean of every photograph that sees it (a clear line of sight), weighted
/// down at grazing views, where the photograph resolves the texel poorly,
/// and near the photograph's edge. Texels no photograph sees are counted
/// and filled from their neighbours. The patches are packed into atlas
/// pages.
///
/// Poses: --poses takes `campanile register`'s RegisteredPoses file
/// (positions, azimuths, elevations and rolls); without it, the scene
/// file's own `poses`. The station file gives the camera's intrinsics and
/// lens distortion. Photographs are HDR radiance images (OpenEXR, RGBE or
/// PFM) named after their pose: DIR/NAME.exr with --photos DIR, else the
/// registered photograph's path with the extension .exr.
///
/// --out gets model.obj, model.mtl (map_Kd page_N.png, as Blender imports
/// it), page_N.exr (linear radiance, 32-bit float), page_N.png (tone-mapped
/// preview) and texture.ron (patches, photographs, coverage, seam figures,
/// verdict).
///
/// Only pixels whose neighbours show the same face are used (no mixed
/// pixels along outlines). Each photograph's image is compared with the
/// others' on the texels they share, shifted over ±6 px: the shift that
/// agrees best is printed, and over 0.3 px means its pose (or its
/// neighbours') is off.
///
/// Verdict: failed below 50% of the texels seen, poor below 95%, when the
/// photographs disagree over twice as much along face borders as inside,
/// or when a photograph agrees best with the others moved over 0.3 px.
/// Exit status: 0 ok or poor, 3 failed (the files are still written),
/// 2 bad input, 1 failure while working.
///
/// Albedo textures: --albedo DIR takes the pseudo-albedos (ρ^se, ρ^sun per
/// surface-grid cell, thesis §5.4) that `campanile process` (scene
/// sessions) and `campanile outdoor recover` write to OUT/albedo/
/// (materials.ron with its atlases; DIR may be that directory, the output
/// directory above it, or materials.ron). No photographs, poses or station
/// are read. Default --texel: the products' grid spacing (each texel is
/// then one grid cell); default surfaces: those the products cover. Out:
/// model.obj, model.mtl (map_Kd page_N.png: the ρ^se colour, sRGB, not
/// tone-mapped), page_N.exr (ρ^se), sun_page_N.exr (ρ^sun, same layout)
/// and texture.ron. Texels on cells no photograph saw are counted as
/// unseen and filled from their neighbours; the verdict follows the same
/// coverage thresholds.
///
/// IGI albedo maps: --albedo DIR also takes the diffuse albedo maps (ρd,
/// thesis §4.6) that `campanile igi` writes to OUT/albedo/ (one EXR per
/// planar OBJ group, GROUP.seen.png saying which texels a view saw, and
/// layout.json placing every texel on the geometry), and `campanile
/// process` on a room session to OUT/room/igi/albedo/; DIR may be that
/// directory, the directory above it, layout.json, or a room session's
/// process OUT. SCENE is then the IGI scene file the maps were recovered
/// from (for a room session, OUT/room/scene.ron); its OBJ
/// must be the one the maps were made on (every group, triangle and
/// corner is checked). Default --texel: the maps' (1 cm). Every face
/// with a map on each of its triangles is textured; faces of groups that
/// have no map (not planar) are listed with the reason (a --surface
/// holding one is refused). Each texel is the mean of the map texels under it
/// that a view saw; a texel on none is counted unseen and filled from its
/// neighbours (a surface no view saw keeps the maps' own fill: its
/// recovered ρd). Out: model.obj, model.mtl (map_Kd page_N.png: ρd, sRGB),
/// page_N.exr (ρd, linear) and texture.ron; the same verdict and exit
/// status.
///
/// Example:
///   campanile register shots/*.png --targets examples/campanile-targets.ron \
///       --station examples/sim-station.ron --out poses.ron
///   campanile texture examples/campanile-scene.ron --poses poses.ron \
///       --station examples/sim-station.ron --texel 0.1 --out textured/
///   campanile texture examples/campanile-scene.ron --albedo processed/albedo \
///       --out albedo-textured/
///   campanile igi room/scene.ron --out room/igi
///   campanile texture room/scene.ron --albedo room/igi --texel 0.05 --out room/textured/
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct TextureArgs {
    /// The scene description (its OBJ beside it).
    #[arg(value_name = "SCENE.ron")]
    scene: PathBuf,
    /// Registered poses from `campanile register` (default: the scene file's poses).
    #[arg(long, value_name = "POSES.ron")]
    poses: Option<PathBuf>,
    /// The station file whose camera took the photographs (radiance textures).
    #[arg(long, value_name = "STATION.ron", required_unless_present = "albedo")]
    station: Option<PathBuf>,
    /// Directory of the HDR photographs, one per pose, named after it.
    #[arg(long, value_name = "DIR")]
    photos: Option<PathBuf>,
    /// Output directory.
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
    /// Texel side, metres (default 0.1; with --albedo the products' grid spacing or the IGI maps' texel).
    #[arg(long, value_name = "M")]
    texel: Option<f64>,
    /// Texture only this surface (repeat for several; default: all).
    #[arg(long = "surface", value_name = "NAME")]
    surfaces: Vec<String>,
    /// Albedo textures from the pseudo-albedo products in DIR (`process`'s albedo/), or from the IGI albedo
    /// maps in DIR (`igi`'s albedo/), instead of radiance.
    #[arg(long, value_name = "DIR", conflicts_with_all = ["poses", "photos"])]
    albedo: Option<PathBuf>,
}

pub fn run(args: TextureArgs) -> Result<u8> {
    if let Some(albedo) = args.albedo {
        return run_albedo(AlbedoTextureRequest {
            scene: args.scene,
            albedo,
            out: args.out,
            texel_m: args.texel,
            surfaces: (!args.surfaces.is_empty()).then_some(args.surfaces),
            limits: QualityLimits::default(),
        });
    }
    let Some(station) = args.station else {
        return Err(super::exit::bad_input(
            "--station STATION.ron: needed for radiance textures",
        ));
    };
    let request = TextureRequest {
        scene: args.scene,
        poses: args.poses,
        station,
        photos: args.photos,
        out: args.out,
        texel_m: args.texel.unwrap_or(0.1),
        surfaces: (!args.surfaces.is_empty()).then_some(args.surfaces),
        limits: QualityLimits::default(),
    };
    let progress = bar(0, "texture");
    let run = texture_files(&request, &progress);
    progress.finish_and_clear();
    let run = run?;
    let m = &run.manifest;
    for p in &m.photos {
        println!(
            "{}: {} texels ({} hidden, {} too oblique){}",
            p.name,
            p.texels,
            p.occluded,
            p.grazing,
            p.shift_px.map_or(String::new(), |[u, v]| format!(
                "; agrees best with the others moved ({u:.2}, {v:.2}) px"
            ))
        );
    }
    let q = &m.quality;
    println!(
        "texture: {} (coverage {:.1}% of {} texels, {} filled from neighbours; seam spread {:.3} at borders, {:.3} inside; {} page(s), {:.1} s){}",
        q.verdict,
        100.0 * q.coverage,
        q.texels_on_faces,
        q.unseen,
        q.seams.border_spread,
        q.seams.interior_spread,
        m.pages.len(),
        m.seconds,
        reasons(q)
    );
    println!("written to {}", run.manifest_path.display());
    Ok(if q.verdict == "failed" { EXIT_QUALITY } else { EXIT_OK })
}

fn run_albedo(request: AlbedoTextureRequest) -> Result<u8> {
    if let Some(layout) = igi_layout_file(&request.albedo) {
        return run_igi_albedo(request, &layout);
    }
    let progress = bar(0, "albedo texture");
    let run = albedo_texture_files(&request, &progress);
    progress.finish_and_clear();
    let run = run?;
    let m = &run.manifest;
    for p in &m.products {
        println!(
            "{}: cells {} solved, {} never sunlit, {} never shadowed, {} ill-conditioned, {} unseen",
            p.surface, p.solved, p.never_sunlit, p.never_shadowed, p.ill_conditioned, p.unseen
        );
    }
    let q = &m.quality;
    println!(
        "albedo texture: {} (coverage {:.1}% of {} texels, {} on unseen cells filled from neighbours; {} m texels on {} m cells; {} page(s), {:.1} s){}",
        q.verdict,
        100.0 * q.coverage,
        q.texels_on_faces,
        q.unseen,
        m.texel_m,
        m.spacing_m,
        m.pages.len(),
        m.seconds,
        reasons(q)
    );
    println!("written to {}", run.manifest_path.display());
    Ok(if q.verdict == "failed" { EXIT_QUALITY } else { EXIT_OK })
}

fn run_igi_albedo(request: AlbedoTextureRequest, layout: &std::path::Path) -> Result<u8> {
    let progress = bar(0, "albedo texture");
    let run = igi_albedo_texture_files(&request, layout, &progress);
    progress.finish_and_clear();
    let run = run?;
    let m = &run.manifest;
    for u in &m.maps {
        println!(
            "{} (surface {}): map texels {} seen, {} filled from neighbours, {} the surface's rho_d, of {}",
            u.group, u.surface, u.seen, u.filled, u.surface_mean, u.texels
        );
    }
    for n in &m.not_textured {
        println!("not textured: {n}");
    }
    let q = &m.quality;
    println!(
        "albedo texture: {} (coverage {:.1}% of {} texels, {} on map texels no view saw filled from neighbours; {} m texels on {} m map texels; {} page(s), {:.1} s){}",
        q.verdict,
        100.0 * q.coverage,
        q.texels_on_faces,
        q.unseen,
        m.texel_m,
        m.maps_texel_m,
        m.pages.len(),
        m.seconds,
        reasons(q)
    );
    println!("written to {}", run.manifest_path.display());
    Ok(if q.verdict == "failed" { EXIT_QUALITY } else { EXIT_OK })
}

/// A verdict's reasons as the line's tail (`: a; b`), or nothing.
fn reasons(q: &campanile_process::texture::Quality) -> String {
    if q.reasons.is_empty() {
        String::new()
    } else {
        format!(": {}", q.reasons.join("; "))
    }
}

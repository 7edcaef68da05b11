//! `campanile outdoor recover|render`: outdoor reflectance (thesis ch. 5)
//! on plain files: pseudo-albedos from posed HDR photographs under a known
//! sun and sky, and views at new times rendered from them (the work is
//! `campanile_session::outdoor_files`').

use std::path::PathBuf;

use anyhow::Result;
use campanile_process::outdoor::{CellStatus, ReflectanceSettings};
use campanile_session::outdoor_files::{self, RecoverOptions, RenderOptions};
use clap::{Args, Subcommand};

/// `campanile outdoor`.
#[derive(Debug, Subcommand)]
pub enum OutdoorCommand {
    Recover(RecoverArgs),
    Render(RenderArgs),
}

/// Recover pseudo-albedos (ρ_sun, ρ_se; thesis §5.2–5.4) from posed HDR photographs.
///
/// SCENE.ron is the scene description (as the station's: OBJ geometry,
/// materials, surfaces): surfaces whose material has `model: PseudoBrdf`
/// are recovered; every other material is environment and must give its
/// known diffuse `albedo: (r, g, b)`. PHOTOS.ron lists cameras (position,
/// look, up and a field of view, or a RADIANCE view string) and photos
/// (camera, UTC time, HDR radiance image: OpenEXR, RGBE .hdr, PFM; an
/// optional PNG mask). LIGHT.ron gives per photo time the sun's normal
/// irradiance (or Hidden) and the sky (a fitted-sky file from `campanile
/// sky fit`, or a fisheye HDR image of the sky to fit); the sun's
/// direction is given, or computed from the site. The README's "Outdoor
/// files" documents the three formats.
///
/// Writes to --out: albedo/materials.ron and its EXR atlases (what
/// `campanile render --materials` and `outdoor render` read), cells.csv
/// (each cell's pseudo-albedos, uncertainty and status), cell_points.csv
/// (16 points over each cell, its centroid for a sliver), outdoor.json (diagnostics), quality.json
/// (verdicts: the fit's residual, each sky's), recovery.json (the inputs,
/// for `outdoor render`).
///
/// Example: campanile outdoor recover --scene site/scene.ron --photos site/photos.ron \
///            --light site/light.ron --out site/recovered
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct RecoverArgs {
    /// The scene description (RON).
    #[arg(long, value_name = "SCENE.ron")]
    scene: PathBuf,
    /// The photographs (RON).
    #[arg(long, value_name = "PHOTOS.ron")]
    photos: PathBuf,
    /// The sun and sky at each photo's time (RON).
    #[arg(long, value_name = "LIGHT.ron")]
    light: PathBuf,
    /// Output directory (created; files in it are replaced).
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
    /// The side of the grid's cells on the surfaces, metres (§5.4).
    #[arg(long, value_name = "M", default_value_t = ReflectanceSettings::default().spacing_m, value_parser = grid_spacing)]
    grid_spacing: f64,
    /// Quality thresholds (a `Quality(...)` RON file, any subset of the gates).
    #[arg(long, value_name = "FILE.ron")]
    thresholds: Option<PathBuf>,
}

/// Render views at new times from recovered pseudo-albedos (§5.5–5.6).
///
/// RECOVERED is the output directory of `outdoor recover` (its
/// recovery.json names the scene and the training photos). Each photo of
/// PHOTOS.ron is rendered from its camera at its time under LIGHT.ron's sun
/// and sky for that time, with the texture the training photographs show
/// finer than the grid (eq. 5.16; --grid-only for the grid alone). Where
/// the photo has an image, the render is compared with it: the relative
/// RMSE of 4×4-pixel block means over the target pixels is its verdict.
///
/// Writes to --out: CAMERA@TIME.exr per view, render.json (figures),
/// quality.json.
///
/// Example: campanile outdoor render site/recovered --photos site/photos-1430.ron \
///            --light site/light.ron --out site/renders
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct RenderArgs {
    /// The directory `outdoor recover` wrote.
    #[arg(value_name = "RECOVERED")]
    recovered: PathBuf,
    /// The views to render (RON, the photos format; images optional).
    #[arg(long, value_name = "PHOTOS.ron")]
    photos: PathBuf,
    /// The sun and sky at each view's time (RON).
    #[arg(long, value_name = "LIGHT.ron")]
    light: PathBuf,
    /// Output directory.
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
    /// The scene description, instead of the one recovery.json names.
    #[arg(long, value_name = "SCENE.ron")]
    scene: Option<PathBuf>,
    /// The grid's pseudo-albedos alone: no texture from the training photographs.
    #[arg(long)]
    grid_only: bool,
    /// Rays per pixel side (N × N per pixel, box filtered, as a camera
    /// integrates its pixels; default 2). 1: one ray through each pixel centre, as a
    /// renderer without anti-aliasing samples (RADIANCE's `rpict -ps 1
    /// -pj 0`): compare like with like, or a building's edges count as
    /// error.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..=16))]
    pixel_samples: Option<u16>,
    /// Quality thresholds (a `Quality(...)` RON file).
    #[arg(long, value_name = "FILE.ron")]
    thresholds: Option<PathBuf>,
}

fn grid_spacing(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|e| format!("{s:?}: {e}"))?;
    if (0.05..=50.0).contains(&v) {
        Ok(v)
    } else {
        Err(format!("{v} m: expected a cell side in [0.05, 50] m"))
    }
}

pub fn run(cmd: OutdoorCommand) -> Result<()> {
    match cmd {
        OutdoorCommand::Recover(args) => recover(args),
        OutdoorCommand::Render(args) => render(args),
    }
}

fn recover(args: RecoverArgs) -> Result<()> {
    let thresholds = super::verdicts::thresholds(args.thresholds.as_deref(), None)?;
    let opts = RecoverOptions {
        scene: args.scene,
        photos: args.photos,
        light: args.light,
        out: args.out,
        grid_spacing: args.grid_spacing,
        thresholds,
    };
    let r = outdoor_files::recover(&opts)?;
    let (scene, refl) = (&r.scene, &r.reflectance);
    outln!(
        "{} photos at {} times, {} cells of {} m on {} surfaces: {} solved, {} never sunlit, {} never shadowed, {} ill-conditioned, {} unseen ({:.1} s)",
        r.photos,
        r.times,
        refl.cells.len(),
        refl.grid.spacing_m,
        scene.targets.len(),
        refl.count(CellStatus::Solved),
        refl.count(CellStatus::NeverSunlit),
        refl.count(CellStatus::NeverShadowed),
        refl.count(CellStatus::IllConditioned),
        refl.count(CellStatus::Unseen),
        r.seconds
    )?;
    outln!(
        "{:<24} {:>6} {:>22} {:>22}",
        "surface",
        "cells",
        "rho_se median (r g b)",
        "rho_sun median (r g b)"
    )?;
    for &s in &scene.targets {
        let name = &scene.scene.surfaces()[s];
        let cells: Vec<usize> = (0..refl.cells.len())
            .filter(|&k| refl.grid.cells[k].surface == s && refl.cells[k].status != CellStatus::Unseen)
            .collect();
        let median = |f: &dyn Fn(usize) -> f64| {
            let mut v: Vec<f64> = cells.iter().map(|&k| f(k)).collect();
            v.sort_by(f64::total_cmp);
            v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
        };
        let se = [0, 1, 2].map(|c| median(&|k| refl.cells[k].rho_se[c]));
        let sun = [0, 1, 2].map(|c| median(&|k| refl.cells[k].rho_sun[c]));
        outln!(
            "{:<24} {:>6} {:>6.3} {:>6.3} {:>6.3}    {:>6.3} {:>6.3} {:>6.3}",
            name,
            cells.len(),
            se[0],
            se[1],
            se[2],
            sun[0],
            sun[1],
            sun[2]
        )?;
    }
    for d in &refl.diagnostics {
        outln!("  note: {d}")?;
    }
    outln!("materials: {}", r.materials.display())?;
    super::verdicts::finish(&r.quality, &opts.out.join("quality.json"))
}

fn render(args: RenderArgs) -> Result<()> {
    let thresholds = super::verdicts::thresholds(args.thresholds.as_deref(), None)?;
    let opts = RenderOptions {
        recovered: args.recovered,
        photos: args.photos,
        light: args.light,
        out: args.out,
        scene: args.scene,
        grid_only: args.grid_only,
        pixel_samples: args.pixel_samples,
        thresholds,
    };
    let r = outdoor_files::render(&opts)?;
    for v in &r.views {
        match &v.compared {
            Some(c) => outln!(
                "{}: 4x4 block relative RMSE {:.2} % ({} blocks; grid only {:.2} %), per pixel {:.2} %, texture from {} photos",
                v.label,
                100.0 * c.rmse_block,
                c.blocks,
                100.0 * c.rmse_block_grid,
                100.0 * c.rmse_pixel,
                v.references
            )?,
            None => outln!("{}: rendered (no photograph to compare with)", v.label)?,
        }
    }
    super::verdicts::finish(&r.quality, &opts.out.join("quality.json"))
}

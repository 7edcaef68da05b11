//! Issue 28's end-to-end criterion on the simulated tower: the outdoor
//! reflectance solver (thesis §5.4, eqs. 5.11–5.12) run on the same
//! photographs of the campanile day twice, on the tower's true geometry
//! and on the geometry its simulated range scans give (segmented, meshed,
//! [`super::scanned_scene`]), each tower surface's pseudo-albedo errors
//! from both against the world's truth, and their ratio (the issue asks
//! for within 1.5×). `examples/outdoor_from_scans.rs` prints it;
//! `tests/outdoor_from_scans.rs` asserts it on a small setup.
//!
//! The scans: the five poses of [`super::range_scanner::building_poses`],
//! segmented with the derived parameters. The groups standing for a tower
//! surface ([`TOWER`]) replace its true triangles and are the solver's
//! targets under its name; the ground and the landscape keep their true
//! geometry (the scans see only the ground near the tower, and the solver
//! needs the whole environment for the light it reflects).

use campanile_process::outdoor::{CellStatus, OutdoorError, Reflectance, ReflectanceSettings, recover_reflectance};
use campanile_process::render::{Scene, SceneError};
use campanile_scan::mesh::{GroupMesh, MeshOptions, mesh_groups};
use campanile_scan::segment::metrics::{Metrics, compare};
use campanile_scan::segment::params::Overrides;
use campanile_scan::segment::segment;

use super::campanile_day::{CampanileDay, DayError, TOWER, illuminations, training_times};
use super::range_scanner::{RangeScanError, ScannerSettings, building_poses, building_scene, scan_scene};
use super::scanned_scene::{
    CellErrors, ErrorRatios, GroupUse, Majority, cell_errors, error_ratios, majority_surfaces, projected_cell_truth,
    scanned_scene,
};

/// Sub-samples per cell side for a cell's truth.
pub const TRUTH_PER_SIDE: usize = 64;
/// Errors are floored at this before a ratio is taken.
pub const RATIO_FLOOR: f64 = 0.005;

/// What to run.
#[derive(Debug, Clone, PartialEq)]
pub struct TowerSetup {
    /// The scanner's grid: rows, columns.
    pub scan_grid: (usize, usize),
    /// Photographs: width, pixels (height 3/4 of it).
    pub width: usize,
    /// Photographs: samples per pixel.
    pub samples_per_pixel: u32,
    /// The tower keeps its texture (bricks); else its materials have their
    /// mean albedo, so that a cell's truth is unambiguous.
    pub textured: bool,
    /// The solver's grid spacing, metres.
    pub spacing_m: f64,
    /// How the groups are meshed.
    pub mesh: MeshOptions,
    /// Surfaces that keep their true triangles on the scans' side (an
    /// error budget's knob), by name.
    pub keep_true: Vec<String>,
}

impl Default for TowerSetup {
    /// 90 × 180 scans (as `tests/range_segmentation.rs`), 128 × 96
    /// photographs at 64 samples per pixel, the tower flattened, a 2 m grid
    /// (as `tests/outdoor_error_budget.rs`), the default meshing.
    fn default() -> TowerSetup {
        TowerSetup {
            scan_grid: (90, 180),
            width: 128,
            samples_per_pixel: 64,
            textured: false,
            spacing_m: 2.0,
            mesh: MeshOptions::default(),
            keep_true: Vec::new(),
        }
    }
}

/// Why the comparison could not be run.
#[derive(Debug, thiserror::Error)]
pub enum TowerError {
    /// The campanile day could not be set up.
    #[error(transparent)]
    Day(#[from] DayError),
    /// The scans could not be made.
    #[error(transparent)]
    Scan(#[from] RangeScanError),
    /// Segmenting, scoring or meshing the scans failed.
    #[error("the scans: {0}")]
    Segmentation(String),
    /// A surface named to keep its true triangles is not in the scene.
    #[error("keep_true: {name:?} is not a surface of the scene (expected one of {known:?})")]
    UnknownSurface {
        /// The name given.
        name: String,
        /// The scene's surfaces.
        known: Vec<String>,
    },
    /// The rebuilt scene is not a scene.
    #[error("the scans' geometry: {0}")]
    Scene(#[from] SceneError),
    /// The solver refused a geometry.
    #[error("{geometry}: {source}")]
    Solver {
        /// Which geometry.
        geometry: &'static str,
        /// Why.
        source: OutdoorError,
    },
}

/// One geometry's solve.
#[derive(Debug, Clone)]
pub struct Solve {
    /// The estimates.
    pub reflectance: Reflectance,
    /// The truth of each cell.
    pub truth: Vec<[f64; 3]>,
    /// The area of the cells some photo saw, m².
    pub seen_area_m2: f64,
}

/// One line of the comparison: a tower surface, or the whole tower.
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceComparison {
    /// The surface's name ("tower": all of them).
    pub name: String,
    /// The errors on the true geometry.
    pub on_truth: CellErrors,
    /// The errors on the scans' geometry.
    pub on_scans: CellErrors,
    /// Their ratios (`None` when either saw no cell).
    pub ratios: Option<ErrorRatios>,
}

/// The comparison and what it was made from.
#[derive(Debug, Clone)]
pub struct TowerComparison {
    /// The segmentation against the scans' truth.
    pub metrics: Metrics,
    /// Every group's mesh.
    pub meshes: Vec<GroupMesh>,
    /// Every group's majority true surface.
    pub majority: Vec<Option<Majority>>,
    /// The groups standing for tower surfaces.
    pub groups: Vec<GroupUse>,
    /// The scene's surface names.
    pub surfaces: Vec<String>,
    /// The true area of each surface, m².
    pub true_area_m2: Vec<f64>,
    /// On the true geometry.
    pub on_truth: Solve,
    /// On the scans' geometry.
    pub on_scans: Solve,
    /// Per [`TOWER`] surface, then the whole tower.
    pub lines: Vec<SurfaceComparison>,
}

impl TowerComparison {
    /// The worst ratio the bound applies to: every surface's
    /// medians and the whole tower's 95th percentiles.
    pub fn worst_ratio(&self) -> f64 {
        let last = self.lines.len().saturating_sub(1);
        self.lines
            .iter()
            .enumerate()
            .filter_map(|(k, l)| {
                let r = l.ratios?;
                let m = r.se_median.max(r.sun_median);
                Some(if k == last { m.max(r.se_p95).max(r.sun_p95) } else { m })
            })
            .fold(0.0, f64::max)
    }

    /// Surfaces some photo saw on the true geometry but none on the
    /// scans' (the segmenter merged them into another group).
    pub fn absent(&self) -> Vec<String> {
        self.lines
            .iter()
            .filter(|l| l.on_truth.seen > 0 && l.on_scans.seen == 0)
            .map(|l| l.name.clone())
            .collect()
    }

    /// The scans' seen area over the true geometry's.
    pub fn coverage(&self) -> f64 {
        self.on_scans.seen_area_m2 / self.on_truth.seen_area_m2
    }
}

fn solve(
    day: &CampanileDay,
    scene: &Scene,
    geometry: &'static str,
    targets: &[usize],
    photos: &[campanile_process::outdoor::Photo],
    settings: &ReflectanceSettings,
) -> Result<Solve, TowerError> {
    let days = day.daylights(&training_times())?;
    let (reflectance, _) = recover_reflectance(scene, targets, photos, &illuminations(&days), settings)
        .map_err(|source| TowerError::Solver { geometry, source })?;
    let truth = projected_cell_truth(&day.world, &reflectance.grid, scene, TRUTH_PER_SIDE);
    let seen_area_m2 = (0..reflectance.cells.len())
        .filter(|&c| reflectance.cells[c].status != CellStatus::Unseen)
        .map(|c| reflectance.grid.cells[c].area_m2)
        .sum();
    Ok(Solve {
        reflectance,
        truth,
        seen_area_m2,
    })
}

/// Scans, segments and meshes the tower, photographs the campanile day,
/// and solves on both geometries.
pub fn compare_tower(setup: &TowerSetup) -> Result<TowerComparison, TowerError> {
    let mut day = CampanileDay::load(setup.samples_per_pixel, 2)?;
    if !setup.textured {
        day.flatten_tower()?;
    }
    let truth_scene = day.world.scene.scene.clone();
    let surfaces = truth_scene.surfaces().to_vec();
    let targets = day.targets()?;
    let keep_true = setup
        .keep_true
        .iter()
        .map(|name| {
            truth_scene
                .surface_index(name)
                .ok_or_else(|| TowerError::UnknownSurface {
                    name: name.clone(),
                    known: surfaces.clone(),
                })
        })
        .collect::<Result<Vec<usize>, _>>()?;

    let (rows, columns) = setup.scan_grid;
    let scans = scan_scene(
        &building_scene()?,
        &building_poses(),
        &ScannerSettings::new(rows, columns),
    )?;
    let seg = |e: &dyn std::fmt::Display| TowerError::Segmentation(e.to_string());
    let (found, _) = segment(&scans.scans, &Overrides::default(), &|_| {}).map_err(|e| seg(&e))?;
    let metrics = compare(&scans.scans, &found, &scans.truth).map_err(|e| seg(&e))?;
    let meshes = mesh_groups(&scans.scans, &found, &setup.mesh).map_err(|e| seg(&e))?;
    let majority = majority_surfaces(&found, &scans.truth);
    let rebuilt = scanned_scene(&truth_scene, &meshes, &majority, &targets, &keep_true)?;

    let photos = day.photographs(&training_times(), setup.width, setup.width * 3 / 4)?;
    let settings = ReflectanceSettings {
        spacing_m: setup.spacing_m,
        ..ReflectanceSettings::default()
    };
    let on_truth = solve(&day, &truth_scene, "the true geometry", &targets, &photos, &settings)?;
    let on_scans = solve(
        &day,
        &rebuilt.scene,
        "the scans' geometry",
        &targets,
        &photos,
        &settings,
    )?;

    let mut sets: Vec<(String, Vec<usize>)> = TOWER
        .iter()
        .zip(&targets)
        .map(|(name, &s)| (name.to_string(), vec![s]))
        .collect();
    sets.push(("tower".into(), targets.clone()));
    let lines = sets
        .into_iter()
        .map(|(name, ids)| {
            let a = cell_errors(&on_truth.reflectance, &on_truth.truth, &ids);
            let b = cell_errors(&on_scans.reflectance, &on_scans.truth, &ids);
            SurfaceComparison {
                name,
                on_truth: a,
                on_scans: b,
                ratios: error_ratios(&a, &b, RATIO_FLOOR),
            }
        })
        .collect();
    let true_area_m2 = (0..surfaces.len())
        .map(|s| {
            truth_scene
                .triangles()
                .iter()
                .filter(|t| t.surface as usize == s)
                .map(|t| t.area())
                .sum()
        })
        .collect();
    Ok(TowerComparison {
        metrics,
        meshes,
        majority,
        groups: rebuilt.groups,
        surfaces,
        true_area_m2,
        on_truth,
        on_scans,
        lines,
    })
}

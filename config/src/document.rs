//! Loading configuration files: reading, parsing, validating, and
//! checking plans against scenes and stations.

use std::path::Path;

use crate::error::{ConfigError, ConfigErrors};
use crate::plan::{self, Plan};
use crate::scene::Scene;
use crate::source::SourceFile;
use crate::station::Station;
use crate::validate::{Validate, Validator};

/// The kinds of configuration file, named by their top-level value.
pub const KINDS: [&str; 4] = ["Station", "Plan", "Scene", "Targets"];

/// A value with the file it came from.
#[derive(Debug, Clone)]
pub struct Loaded<T> {
    /// The value.
    pub value: T,
    /// Its file.
    pub source: SourceFile,
}

/// A plan with the scene it names, if any.
#[derive(Debug, Clone)]
pub struct LoadedPlan {
    /// The plan.
    pub plan: Loaded<Plan>,
    /// Its scene.
    pub scene: Option<Loaded<Scene>>,
}

/// Any configuration file.
#[derive(Debug, Clone)]
pub enum Document {
    /// A station description.
    Station(Box<Loaded<Station>>),
    /// A plan (and its scene).
    Plan(Box<LoadedPlan>),
    /// A scene description.
    Scene(Box<Loaded<Scene>>),
    /// A calibrated camera (`campanile sky calibrate`'s file).
    CameraCalibration(Box<Loaded<crate::camera_calibration::CameraCalibration>>),
    /// Surveyed coded targets (`campanile register`).
    Targets(Box<Loaded<crate::targets::Targets>>),
}

fn load_valid<T>(source: SourceFile) -> Result<Loaded<T>, ConfigErrors>
where
    T: serde::de::DeserializeOwned + Validate,
{
    let value: T = source.parse()?;
    let mut v = Validator::new(source.base_dir());
    value.validate(&mut v);
    let issues = v.into_issues();
    if issues.is_empty() {
        Ok(Loaded { value, source })
    } else {
        Err(ConfigErrors(issues.into_iter().map(|i| source.locate(i)).collect()))
    }
}

/// Reads and validates a station file.
pub fn load_station(path: &Path) -> Result<Loaded<Station>, ConfigErrors> {
    load_valid(expect_kind(SourceFile::read(path)?, "Station")?)
}

/// Reads and validates a camera calibration file (`CameraCalibration(...)`,
/// as `campanile sky calibrate` writes it).
pub fn load_camera_calibration(
    path: &Path,
) -> Result<Loaded<crate::camera_calibration::CameraCalibration>, ConfigErrors> {
    load_valid(expect_kind(SourceFile::read(path)?, "CameraCalibration")?)
}

/// Reads and validates a scene file, including its OBJ geometry's groups.
pub fn load_scene(path: &Path) -> Result<Loaded<Scene>, ConfigErrors> {
    load_valid(expect_kind(SourceFile::read(path)?, "Scene")?)
}

/// Reads and validates a quality-thresholds file (`Quality(...)`, any
/// subset of the fields of [`crate::quality::Quality`]).
pub fn load_quality(path: &Path) -> Result<Loaded<crate::quality::Quality>, ConfigErrors> {
    load_valid(expect_kind(SourceFile::read(path)?, "Quality")?)
}

/// Reads and validates a surveyed-targets file (`Targets(...)`, see
/// [`crate::targets`]).
pub fn load_targets(path: &Path) -> Result<Loaded<crate::targets::Targets>, ConfigErrors> {
    load_valid(expect_kind(SourceFile::read(path)?, "Targets")?)
}

/// Reads and validates a plan file and the scene it names.
pub fn load_plan(path: &Path) -> Result<LoadedPlan, ConfigErrors> {
    load_plan_source(expect_kind(SourceFile::read(path)?, "Plan")?)
}

fn load_plan_source(source: SourceFile) -> Result<LoadedPlan, ConfigErrors> {
    let plan: Loaded<Plan> = load_valid(source)?;
    let scene = match &plan.value.scene {
        None => None,
        Some(rel) => {
            let scene_path = plan.source.base_dir().join(rel);
            if !scene_path.is_file() {
                let issue = crate::validate::Issue {
                    path: crate::validate::FieldPath(vec!["scene".into()]),
                    value: format!("{:?}", rel.display().to_string()),
                    expected: format!(
                        "the path of a scene file, relative to this file ({} does not exist)",
                        scene_path.display()
                    ),
                };
                return Err(plan.source.locate(issue).into());
            }
            Some(load_scene(&scene_path)?)
        }
    };
    let mut v = Validator::new(plan.source.base_dir());
    plan::check_against_scene(&plan.value, scene.as_ref().map(|s| &s.value), &mut v);
    let issues = v.into_issues();
    if !issues.is_empty() {
        return Err(ConfigErrors(
            issues.into_iter().map(|i| plan.source.locate(i)).collect(),
        ));
    }
    Ok(LoadedPlan { plan, scene })
}

fn expect_kind(source: SourceFile, kind: &str) -> Result<SourceFile, ConfigError> {
    match source.top_level_name() {
        Some((name, _)) if name == kind => Ok(source),
        found => Err(kind_error(
            &source,
            found,
            &format!("a `{kind}(...)` file, named by its top-level value"),
        )),
    }
}

fn kind_error(source: &SourceFile, found: Option<(String, usize)>, expected: &str) -> ConfigError {
    let (value, offset) = match found {
        Some((name, offset)) => (format!("`{name}`"), offset),
        None => ("no named top-level value".to_owned(), 0),
    };
    ConfigError {
        file: source.path.clone(),
        position: Some(crate::span_tree::line_col(&source.text, offset)),
        field: Some("(top level)".to_owned()),
        value: Some(value),
        message: expected.to_owned(),
    }
}

/// Reads and validates any configuration file, telling its kind from its
/// top-level name.
pub fn load(path: &Path) -> Result<Document, ConfigErrors> {
    load_source(SourceFile::read(path)?)
}

/// Like [`load`], on text already in memory; `path` names it in errors and
/// anchors its relative paths.
pub fn load_text(path: &Path, text: String) -> Result<Document, ConfigErrors> {
    load_source(SourceFile::from_text(path, text))
}

fn load_source(source: SourceFile) -> Result<Document, ConfigErrors> {
    match source.top_level_name() {
        Some((name, _)) if name == "Station" => Ok(Document::Station(Box::new(load_valid(source)?))),
        Some((name, _)) if name == "Plan" => Ok(Document::Plan(Box::new(load_plan_source(source)?))),
        Some((name, _)) if name == "Scene" => Ok(Document::Scene(Box::new(load_valid(source)?))),
        Some((name, _)) if name == "CameraCalibration" => {
            Ok(Document::CameraCalibration(Box::new(load_valid(source)?)))
        }
        Some((name, _)) if name == "Targets" => Ok(Document::Targets(Box::new(load_valid(source)?))),
        found => Err(kind_error(
            &source,
            found,
            "a named top-level value: `Station(...)`, `Plan(...)`, `Scene(...)`, `CameraCalibration(...)` or `Targets(...)`",
        )
        .into()),
    }
}

/// Checks that a plan can run on a station: every filter, light and pose it
/// names exists there and is reachable. Errors point into the plan file.
pub fn check_plan_on_station(plan: &LoadedPlan, station: &Station) -> Result<(), ConfigErrors> {
    let mut v = Validator::new(plan.plan.source.base_dir());
    plan::check_against_station(&plan.plan.value, plan.scene.as_ref().map(|s| &s.value), station, &mut v);
    let issues = v.into_issues();
    if issues.is_empty() {
        Ok(())
    } else {
        Err(ConfigErrors(
            issues.into_iter().map(|i| plan.plan.source.locate(i)).collect(),
        ))
    }
}

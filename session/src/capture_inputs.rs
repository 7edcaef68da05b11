//! What a capture runs: the plan, the station and the plan's scene, read
//! from their files or from a session's snapshot (to resume it), with the
//! timeline the plan makes on the station; and, for a simulated station,
//! the world it photographs.

use std::path::Path;
use std::sync::Arc;

use anyhow::Context;
use campanile_capture::schedule::{SceneGeometry, Timeline, TimelineOptions, timeline};
use campanile_capture::store::{PLAN_FILE, Provenance, SCENE_FILE, STATION_FILE, Snapshot, SourcePaths};
use campanile_config::document::{Document, load_text};
use campanile_config::{Station, check_plan_on_station, load_plan, load_station};
use campanile_sim::world::{World, load_scene};

use crate::Result;

/// The plan, station and scene, as `plan check` reads them.
pub struct Inputs {
    pub plan: campanile_config::document::LoadedPlan,
    pub station: Station,
    pub timeline: Timeline,
    pub snapshot: Snapshot,
    /// How to name the plan and station in messages.
    pub plan_label: String,
    pub station_label: String,
    /// Whether they were read from a session's snapshot.
    pub from_session: bool,
}

impl Inputs {
    /// The session `resume` began with, or `plan` on `station` (both or
    /// neither given), for `days` days of the plan.
    pub fn load(resume: Option<&Path>, plan: Option<&Path>, station: Option<&Path>, days: Option<u32>) -> Result<Self> {
        match (resume, plan, station) {
            (Some(dir), None, None) => Self::from_session(dir, days),
            (_, Some(plan), Some(station)) => Self::from_files(plan, station, days),
            (Some(_), _, _) => bail!(
                "give both PLAN and --station STATION, or neither (to resume with the session's own plan.ron and station.ron)"
            ),
            (None, _, _) => bail!("give PLAN and --station STATION"),
        }
    }

    /// Read PLAN and STATION (and the plan's scene) from their files.
    pub fn from_files(plan_path: &Path, station_path: &Path, days: Option<u32>) -> Result<Self> {
        let plan = load_plan(plan_path).map_err(|e| anyhow::anyhow!("{e}"))?;
        let loaded = load_station(station_path).map_err(|e| anyhow::anyhow!("{e}"))?;
        let absolute = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
        let snapshot = Snapshot {
            plan_ron: plan.plan.source.text.clone(),
            station_ron: loaded.source.text.clone(),
            scene_ron: plan.scene.as_ref().map(|s| s.source.text.clone()),
            provenance: Provenance {
                campanile_version: env!("CARGO_PKG_VERSION").to_owned(),
                created_utc: chrono::Utc::now(),
                calibration: Vec::new(),
                sources: Some(SourcePaths {
                    plan: absolute(plan_path),
                    station: absolute(station_path),
                    scene: plan.scene.as_ref().map(|s| absolute(&s.source.path)),
                }),
            },
        };
        Self::new(
            plan,
            loaded.value,
            snapshot,
            plan_path.display().to_string(),
            station_path.display().to_string(),
            false,
            days,
        )
    }

    /// Read the plan, station and scene from the snapshot of the session
    /// in `dir`. Their relative paths (the scene's OBJ geometry) resolve
    /// against the files the session was created from; the scene file
    /// there must still be the one snapshotted.
    pub fn from_session(dir: &Path, days: Option<u32>) -> Result<Self> {
        let snapshot = Snapshot::read_dir(dir)
            .with_context(|| format!("reading the snapshot of the session in {}", dir.display()))?;
        let sources = snapshot.provenance.sources.clone();
        let plan_path = sources.as_ref().map_or_else(|| dir.join(PLAN_FILE), |s| s.plan.clone());
        let station_path = sources
            .as_ref()
            .map_or_else(|| dir.join(STATION_FILE), |s| s.station.clone());
        let plan = match load_text(&plan_path, snapshot.plan_ron.clone()) {
            Ok(Document::Plan(p)) => *p,
            Ok(_) => bail!(
                "{}: the session's plan snapshot is not a `Plan(...)`",
                dir.join(PLAN_FILE).display()
            ),
            Err(e) => bail!(
                "{e}\nthe session's plan snapshot ({}) does not load as if at {}; give PLAN and --station again",
                dir.join(PLAN_FILE).display(),
                plan_path.display()
            ),
        };
        if let (Some(scene), Some(snap)) = (&plan.scene, &snapshot.scene_ron)
            && &scene.source.text != snap
        {
            bail!(
                "the scene file {} has changed since the session in {} began (its snapshot is {}); restore it to resume",
                scene.source.path.display(),
                dir.display(),
                dir.join(SCENE_FILE).display()
            );
        }
        let station = match load_text(&station_path, snapshot.station_ron.clone()) {
            Ok(Document::Station(s)) => s.value,
            Ok(_) => bail!(
                "{}: the session's station snapshot is not a `Station(...)`",
                dir.join(STATION_FILE).display()
            ),
            Err(e) => bail!(
                "{e}\nthe session's station snapshot ({}) does not load",
                dir.join(STATION_FILE).display()
            ),
        };
        Self::new(
            plan,
            station,
            snapshot,
            dir.join(PLAN_FILE).display().to_string(),
            dir.join(STATION_FILE).display().to_string(),
            true,
            days,
        )
    }

    fn new(
        plan: campanile_config::document::LoadedPlan,
        station: Station,
        snapshot: Snapshot,
        plan_label: String,
        station_label: String,
        from_session: bool,
        days: Option<u32>,
    ) -> Result<Self> {
        check_plan_on_station(&plan, &station).map_err(|e| {
            anyhow::anyhow!(
                "{e}\nthe plan does not run on station {:?} ({station_label})",
                station.name
            )
        })?;
        let scene = match &plan.scene {
            Some(s) => Some(SceneGeometry::load(&s.value, &s.source.base_dir()).context("reading the plan's scene")?),
            None => None,
        };
        let t = timeline(&plan.plan.value, &station, scene.as_ref(), &TimelineOptions { days })
            .with_context(|| format!("{plan_label}: cannot simulate the plan"))?;
        Ok(Self {
            plan,
            station,
            timeline: t,
            snapshot,
            plan_label,
            station_label,
            from_session,
        })
    }
}

/// The simulated world a plan's scene makes, where the station stands in
/// it (the scene's first pose), and the station's simulation seed.
pub struct SimulatedWorld {
    pub world: Arc<World>,
    pub home: [f64; 3],
    pub seed: u64,
}

/// Build the simulated world of `inputs` rendered with `samples` per pixel
/// and `bounces`.
pub fn simulated_world(inputs: &Inputs, samples: u32, bounces: u32) -> Result<SimulatedWorld> {
    let scene_path = inputs
        .plan
        .scene
        .as_ref()
        .map(|s| s.source.path.clone())
        .context("a simulated station needs the plan's scene to photograph (the plan has no `scene`)")?;
    let mut world = World::new(
        &inputs.station,
        load_scene(&scene_path).with_context(|| format!("loading {}", scene_path.display()))?,
    );
    world.quality.samples_per_pixel = samples.max(1);
    world.quality.max_bounces = bounces;
    let home = inputs
        .plan
        .scene
        .as_ref()
        .and_then(|s| s.value.poses.first())
        .map_or([0.0; 3], |p| [p.position_m.0, p.position_m.1, p.position_m.2]);
    let seed = inputs.station.simulation.as_ref().map_or(0, |s| s.seed);
    Ok(SimulatedWorld {
        world: Arc::new(world),
        home,
        seed,
    })
}

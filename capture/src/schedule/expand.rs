//! The expansion rules: how each kind of step becomes planned shots. This is
//! the one place they live, so that `plan check`'s counts and the
//! controller's frames agree exactly. Within a step, targets (`t`) and
//! frames (`f`) are numbered from 0 in the order they are taken.
//!
//! | Step | Shots |
//! | --- | --- |
//! | `Bracket` | one Data shot per listed exposure (`Fixed`), at the aim, through the step's filter |
//! | `AutoBracket` | one Metering shot (`Auto`), then `max_frames` Data shots (`Auto`), of which only the first is promised: the controller takes the fewest that cover the metered dynamic range, 1..=`max_frames` |
//! | `SunShot` (§5.3.1) | one Centering shot at the sun through the densest listed filter (`Fixed` 1 ms, within the camera's limits), then 3 Data shots if `triplet` else 1, at the sun, `Auto`, through `LightestUnsaturated(filters)`; retries on saturation are extra frames, not promised |
//! | `SkyScan` (§5.3.2) | the sky tiling ([`sky_rows`]: rows from `min_elevation_deg`, then the zenith), each tile a 3-frame bracket `Metered` −2, 0, +2 stops; then for each aureole radius, the ring of tiles around the sun's position at the occurrence's start ([`ring_tiles`]), each one Data frame at `Metered` −4 stops |
//! | `EnvironmentTiles` (§5.3.3) | the band tiling from `min_elevation_deg` to `max_elevation_deg` ([`band_rows`]), each tile a 3-frame bracket −2, 0, +2 stops |
//! | `Views` | per pose, a 5-frame bracket −4, −2, 0, +2, +4 stops |
//! | `LightSequence` (§4.7.2) | per pose: each listed light alone, then (if `all_on`) every listed light on; each a 3-frame bracket −2, 0, +2 stops, with light levels 0 or 1 per station channel |
//!
//! Tiles of a row are taken in order of the head's pan angle, alternating
//! direction from row to row (a serpentine), so the head sweeps rather than
//! rewinds; tiles the head cannot reach keep their place at the end of the
//! row and are reported as not covered.

use campanile_config::plan::{Aim, Step};
use campanile_config::station::Station;

use super::error::ScheduleError;
use super::field_of_view::FieldOfView;
use super::scene_geometry::SceneGeometry;
use super::shot::{FilterChoice, PlannedAim, PlannedExposure, PlannedShot, ShotKind};
use super::tiling::{Rows, Tile, band_rows, ring_tiles, sky_rows};

/// Stops of a sky or environment tile's bracket, and of each light state.
pub const TILE_BRACKET_STOPS: [f64; 3] = [-2.0, 0.0, 2.0];
/// Stops of a view's bracket.
pub const VIEW_BRACKET_STOPS: [f64; 5] = [-4.0, -2.0, 0.0, 2.0, 4.0];
/// Stops of an aureole tile (a faster shutter near the sun, §5.3.2).
pub const AUREOLE_STOPS: f64 = -4.0;
/// Exposure of the sun-centering shot, seconds (clamped into the camera's limits).
pub const SUN_CENTERING_EXPOSURE_S: f64 = 0.001;

/// What the expansion of one session's steps needs.
#[derive(Debug, Clone, Copy)]
pub struct Expansion<'a> {
    /// The station (camera, head, lights).
    pub station: &'a Station,
    /// The scene, for named poses.
    pub scene: Option<&'a SceneGeometry>,
    /// The camera's field of view.
    pub fov: FieldOfView,
    /// The session's name, for errors.
    pub session: &'a str,
}

struct Builder<'a> {
    occurrence: &'a str,
    step: usize,
    shots: Vec<PlannedShot>,
}

impl Builder<'_> {
    #[allow(clippy::too_many_arguments)]
    fn push(
        &mut self,
        target: usize,
        frame: usize,
        kind: ShotKind,
        aim: &PlannedAim,
        exposure: PlannedExposure,
        filter: &FilterChoice,
        lights: Option<Vec<f64>>,
        promised: bool,
    ) {
        self.shots.push(PlannedShot {
            key: format!("{}/s{}/t{target}/f{frame}", self.occurrence, self.step),
            step: self.step,
            kind,
            aim: aim.clone(),
            exposure,
            filter: filter.clone(),
            lights,
            promised,
        });
    }

    fn bracket(&mut self, target: usize, aim: &PlannedAim, stops: &[f64], lights: Option<Vec<f64>>) {
        for (f, &s) in stops.iter().enumerate() {
            self.push(
                target,
                f,
                ShotKind::Data,
                aim,
                PlannedExposure::Metered { stops: s },
                &FilterChoice::None,
                lights.clone(),
                true,
            );
        }
    }
}

impl Expansion<'_> {
    /// The shots of step `index` of an occurrence keyed `occurrence`, with
    /// the sun at `sun` (azimuth, elevation in degrees) at its start.
    pub fn step_shots(
        &self,
        occurrence: &str,
        index: usize,
        step: &Step,
        sun: (f64, f64),
    ) -> Result<Vec<PlannedShot>, ScheduleError> {
        let mut b = Builder {
            occurrence,
            step: index,
            shots: Vec::new(),
        };
        match step {
            Step::Bracket {
                aim,
                exposures_s,
                filter,
                ..
            } => {
                let aim = self.aim(aim)?;
                let filter = filter.clone().map_or(FilterChoice::None, FilterChoice::Slot);
                for (f, &t) in exposures_s.iter().enumerate() {
                    b.push(
                        0,
                        f,
                        ShotKind::Data,
                        &aim,
                        PlannedExposure::Fixed { seconds: t },
                        &filter,
                        None,
                        true,
                    );
                }
            }
            Step::AutoBracket { aim, max_frames, .. } => {
                let aim = self.aim(aim)?;
                let none = FilterChoice::None;
                b.push(0, 0, ShotKind::Metering, &aim, PlannedExposure::Auto, &none, None, true);
                for f in 0..*max_frames as usize {
                    b.push(
                        0,
                        f + 1,
                        ShotKind::Data,
                        &aim,
                        PlannedExposure::Auto,
                        &none,
                        None,
                        f == 0,
                    );
                }
            }
            Step::SunShot { filters, triplet, .. } => {
                let densest = filters.last().cloned().map_or(FilterChoice::None, FilterChoice::Slot);
                let limits = self.station.camera.exposure;
                let centering = SUN_CENTERING_EXPOSURE_S.clamp(limits.min_s, limits.max_s.max(limits.min_s));
                let sun = PlannedAim::Sun;
                b.push(
                    0,
                    0,
                    ShotKind::Centering,
                    &sun,
                    PlannedExposure::Fixed { seconds: centering },
                    &densest,
                    None,
                    true,
                );
                let chosen = FilterChoice::LightestUnsaturated(filters.clone());
                for f in 0..if *triplet { 3 } else { 1 } {
                    b.push(
                        0,
                        f + 1,
                        ShotKind::Data,
                        &sun,
                        PlannedExposure::Auto,
                        &chosen,
                        None,
                        true,
                    );
                }
            }
            Step::SkyScan {
                min_elevation_deg,
                overlap,
                aureole_bands_deg,
                ..
            } => {
                let rows = sky_rows(&self.fov, *overlap, *min_elevation_deg)?;
                let mut target = self.tiles(&mut b, 0, &rows);
                for &r in aureole_bands_deg {
                    for tile in ring_tiles(&self.fov, *overlap, sun.0, sun.1, r) {
                        b.push(
                            target,
                            0,
                            ShotKind::Data,
                            &sky(&tile),
                            PlannedExposure::Metered { stops: AUREOLE_STOPS },
                            &FilterChoice::None,
                            None,
                            true,
                        );
                        target += 1;
                    }
                }
            }
            Step::EnvironmentTiles {
                min_elevation_deg,
                max_elevation_deg,
                overlap,
                ..
            } => {
                let rows = band_rows(&self.fov, *overlap, *min_elevation_deg, *max_elevation_deg)?;
                self.tiles(&mut b, 0, &rows);
            }
            Step::Views { poses, .. } => {
                for (t, p) in poses.iter().enumerate() {
                    b.bracket(t, &self.pose(p)?, &VIEW_BRACKET_STOPS, None);
                }
            }
            Step::LightSequence {
                lights, all_on, poses, ..
            } => {
                let channels = self.light_channels(lights)?;
                let n = self.station.lights.as_ref().map_or(0, |l| l.channels.len());
                let mut states: Vec<Vec<f64>> = channels
                    .iter()
                    .map(|&c| (0..n).map(|i| if i == c { 1.0 } else { 0.0 }).collect())
                    .collect();
                if *all_on {
                    states.push((0..n).map(|i| if channels.contains(&i) { 1.0 } else { 0.0 }).collect());
                }
                let mut t = 0;
                for p in poses {
                    let aim = self.pose(p)?;
                    for levels in &states {
                        b.bracket(t, &aim, &TILE_BRACKET_STOPS, Some(levels.clone()));
                        t += 1;
                    }
                }
            }
        }
        Ok(b.shots)
    }

    /// Brackets every tile of `rows`, serpentine by pan; returns the next target index.
    fn tiles(&self, b: &mut Builder<'_>, first_target: usize, rows: &Rows) -> usize {
        let mut t = first_target;
        for (i, row) in rows.iter().enumerate() {
            let mut ordered: Vec<(Option<f64>, &Tile)> = row
                .iter()
                .map(|tile| {
                    let pan = self
                        .station
                        .head
                        .reach(tile.azimuth_deg, tile.elevation_deg)
                        .map(|p| p.0);
                    (pan, tile)
                })
                .collect();
            ordered.sort_by(|a, b| match (a.0, b.0) {
                (Some(x), Some(y)) if i % 2 == 0 => x.total_cmp(&y),
                (Some(x), Some(y)) => y.total_cmp(&x),
                (Some(_), None) => std::cmp::Ordering::Less,
                (None, Some(_)) => std::cmp::Ordering::Greater,
                (None, None) => a.1.azimuth_deg.total_cmp(&b.1.azimuth_deg),
            });
            for (_, tile) in ordered {
                b.bracket(t, &sky(tile), &TILE_BRACKET_STOPS, None);
                t += 1;
            }
        }
        t
    }

    fn aim(&self, aim: &Aim) -> Result<PlannedAim, ScheduleError> {
        match aim {
            Aim::PanTilt { pan_deg, tilt_deg } => Ok(PlannedAim::Head {
                pan_deg: *pan_deg,
                tilt_deg: *tilt_deg,
            }),
            Aim::Pose(name) => self.pose(name),
            Aim::Sun => Ok(PlannedAim::Sun),
        }
    }

    fn pose(&self, name: &str) -> Result<PlannedAim, ScheduleError> {
        let pose = self
            .scene
            .and_then(|s| s.scene.pose(name))
            .ok_or_else(|| ScheduleError::Unknown {
                session: self.session.to_owned(),
                what: "camera pose",
                name: name.to_owned(),
                place: match self.scene {
                    Some(s) => format!("a pose of scene {:?}", s.scene.name),
                    None => "available: the plan has no scene".to_owned(),
                },
            })?;
        Ok(PlannedAim::Pose {
            name: pose.name.clone(),
            position_m: pose.position_m,
            azimuth_deg: pose.azimuth_deg,
            elevation_deg: pose.elevation_deg,
        })
    }

    fn light_channels(&self, names: &[String]) -> Result<Vec<usize>, ScheduleError> {
        names
            .iter()
            .map(|name| {
                self.station
                    .lights
                    .as_ref()
                    .and_then(|l| l.channels.iter().position(|c| &c.name == name))
                    .ok_or_else(|| ScheduleError::Unknown {
                        session: self.session.to_owned(),
                        what: "light",
                        name: name.clone(),
                        place: format!("a light of station {:?}", self.station.name),
                    })
            })
            .collect()
    }
}

fn sky(tile: &Tile) -> PlannedAim {
    PlannedAim::Sky {
        azimuth_deg: tile.azimuth_deg,
        elevation_deg: tile.elevation_deg,
    }
}

//! The scheduler: when sessions run and what shots they take, as a pure
//! function of the plan, the station, the scene and the calendar (the Ekos
//! scheduler's `simulate()`, in the manner of STYLE.md). It is the single
//! source of truth for *what* is shot: the controller executes the planned
//! shots of [`timeline()`] in order, resolving only runtime choices (metered
//! exposures, which ND slot), and `campanile plan check` prints the same
//! timeline without devices.
//!
//! - [`trigger`]: when clock, solar elevation, solar azimuth and face
//!   triggers fire on a plan day (bisection on the ephemeris to 1 ms).
//! - [`sun_track`]: the sun over the site; a plan day is the site's mean
//!   solar day, centred on local mean noon.
//! - [`expand`]: the expansion rules, step by step (thesis §5.3.1 sun shots,
//!   §5.3.2 sky scans with aureole bands, §5.3.3 environment tiles, §4.7.2
//!   light sequences).
//! - [`tiling`] and [`field_of_view`]: sky, environment and aureole tiles
//!   planned from the camera's field of view.
//! - [`duration`]: slews, exposures, readout and filter changes.
//! - [`scene_geometry`]: surface orientations from the scene's OBJ file.
//! - [`timeline`](mod@timeline): occurrences, repeats, and what will not be covered
//!   ([`Uncovered`]): triggers that never fire, overlapping occurrences,
//!   aims out of the head's reach, sun shots with the sun down, and faces
//!   of an outdoor scene never photographed in sunlight.
//!
//! Frame counts: every planned shot is a frame the controller writes to the
//! session store, metering and centering shots included. All are promised
//! except auto-bracket frames after the first, so a timeline promises
//! [`Timeline::frames_promised`] frames exactly and takes at most
//! [`Timeline::frames_at_most`]. Retries after failures or saturation are
//! extra frames, never promised; shots that fail are recorded as missed.
//!
//! Not modelled: self-shadowing of a face by other geometry; the sun moving
//! during an occurrence (aureole rings and sun-shot reachability use the
//! sun at the occurrence's start); the base's level offsets (left to the
//! controller's exact kinematics, as in [`PanTiltHead::reach`](campanile_config::head::PanTiltHead::reach)).

pub mod duration;
pub mod error;
pub mod expand;
pub mod field_of_view;
pub mod scene_geometry;
pub mod shot;
pub mod sun_track;
pub mod tiling;
pub mod timeline;
pub mod trigger;

pub use error::ScheduleError;
pub use scene_geometry::{SceneGeometry, SurfaceOrientation};
pub use shot::{FilterChoice, PlannedAim, PlannedExposure, PlannedShot, ShotKind};
pub use timeline::{Occurrence, Timeline, TimelineOptions, Uncovered, timeline};

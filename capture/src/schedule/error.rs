//! What can stop the scheduler from planning at all. Anything that merely
//! will not be covered (a trigger that never fires, an unreachable tile) is
//! not an error: it is an [`Uncovered`](super::Uncovered) entry of the timeline.

use std::path::PathBuf;

use campanile_process::sun::SunError;
use chrono::NaiveDate;

/// Errors of [`timeline()`](super::timeline()) and of loading scene geometry.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ScheduleError {
    /// The ephemeris refused an instant or the site.
    #[error("solar ephemeris: {0}")]
    Sun(#[from] SunError),
    /// A step or trigger names something the station or scene does not have.
    #[error("session {session:?}: {what} {name:?} is not {place}")]
    Unknown {
        /// The session.
        session: String,
        /// What kind of thing: "camera pose", "light", "surface".
        what: &'static str,
        /// The name.
        name: String,
        /// Where it was looked for, e.g. "a pose of the plan's scene".
        place: String,
    },
    /// The scene's OBJ file could not be read.
    #[error("{}: cannot read the scene geometry: {reason}", path.display())]
    Geometry {
        /// The OBJ file.
        path: PathBuf,
        /// Why.
        reason: String,
    },
    /// A plan day falls outside the calendar chrono can represent.
    #[error("day {days} after {date} is outside the calendar")]
    Date {
        /// The plan's start date.
        date: NaiveDate,
        /// The offset in days.
        days: u64,
    },
    /// A tiling could not be planned (a field of view too small to tile).
    #[error("cannot tile the region: {reason}")]
    Tiling {
        /// Why.
        reason: String,
    },
}

//! The session controller: it executes a [`Timeline`](crate::schedule::Timeline)'s
//! planned shots, exactly those and in order, through the device traits,
//! into a [`SessionStore`](crate::store::SessionStore), reading time only
//! through a [`Clock`](crate::clock::Clock).
//!
//! - [`run()`]: occurrences, waits, lateness, error policies, reconnects,
//!   the watchdog, and the journal (see its module for the rules).
//! - [`rig`]: the devices as one [`Rig`], with reconnect and simulator hooks.
//! - [`metering`]: metered exposures from unstored test captures.
//! - [`auto_bracket`]: the fewest frames that expose every pixel well.
//! - [`sun_shot`]: the disc, the ND filter and exposure, triplet agreement.
//! - [`aim`]: head angles through the mount's exact kinematics.
//! - [`options`]: [`RunOptions`], [`RunReport`] and [`Progress`].
//! - [`supervisor`]: a [`Supervisor`] that may stop a run between shots,
//!   seed and damp metered exposures, and hears of device failures.
//!
//! Frames: every promised shot ends as one journal line, a frame (`done`
//! or `late`) or `missed` with the reason. Auto-bracket frames after the
//! first are taken only when needed and are not journaled otherwise.
//! Metering test captures and saturated sun frames retaken through a
//! denser filter are not stored (the journal notes the retake).
//!
//! Resume: a shot complete in the store is never retaken; what a later
//! shot needs from an earlier one (a metered exposure, the sun's centring,
//! the frames of an auto-bracket) is recomputed or re-read from the store,
//! so a resumed run decides exactly as an uninterrupted one. With
//! [`Rig::number_frames_from`] (the simulator) its frames are identical.
//!
//! Not done: real-camera gain control (gain stays at unity); per-shot
//! deadlines within an occurrence (lateness is the occurrence's); the
//! sun moving during a metering loop is ignored.

pub mod aim;
pub mod auto_bracket;
pub mod error;
pub mod metering;
pub mod options;
pub mod rig;
pub mod run;
pub mod sun_shot;
pub mod supervisor;

pub use error::RunError;
pub use options::{AutoBracketUse, NoProgress, Progress, RunOptions, RunReport, ShotOutcome};
pub use rig::{DeviceKind, Rig};
pub use run::{run, run_supervised};
pub use supervisor::{Metering, Supervisor, Unsupervised};

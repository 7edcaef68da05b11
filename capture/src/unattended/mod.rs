//! Unattended station mode: a plan with daily-repeating triggers (a sky
//! scan and a sun triplet every N minutes while the sun is up) run for
//! days, with no one watching. `campanile station run` drives it.
//!
//! - [`run()`](run::run): the loop over the plan's occurrences (see its
//!   module for the order of things).
//! - [`stop`]: a [`StopHandle`] a signal handler or a test uses to stop at
//!   a frame boundary; the same command continues.
//! - [`day_rollover`]: one session directory per plan day (the site's
//!   mean solar day), `STORE/YYYY-MM-DD/`.
//! - [`storage_budget`]: the oldest raw frames of processed scans are
//!   deleted when the store is over budget, journaled `pruned`.
//! - [`scan_hook`]: the [`ScanHook`] through which a processor turns a
//!   settled scan into products (and lists it as processed).
//! - [`heartbeat`]: `STORE/heartbeat.json`, for outside monitoring.
//! - [`outage`]: device health; outages journaled with start and end.
//! - [`exposure_plan`]: exposures planned across the day and damped from
//!   scan to scan, so they do not flap.
//! - [`supervision`]: the controller [`Supervisor`](crate::controller::Supervisor)
//!   that joins the stop handle, the exposure plan and device health.
//!
//! Not done: a real station's camera is not probed between scans (no
//! harmless query), so a camera outage is seen only at the next scan; the
//! processing hook runs in the station's task (a long one delays the next
//! scan); the budget does not count processed products.

pub mod day_rollover;
pub mod exposure_plan;
pub mod heartbeat;
pub mod liveness;
pub mod outage;
pub mod run;
pub mod scan_hook;
pub mod stop;
pub mod storage_budget;
pub mod supervision;

pub use exposure_plan::{ExposureChoice, ExposureDamping, ExposurePlan};
pub use heartbeat::{HEARTBEAT_FILE, Heartbeat, StationState};
pub use liveness::Liveness;
pub use outage::{DeviceHealth, DeviceState, EndedOutage};
pub use run::{StationEnd, StationError, StationFailure, StationInputs, StationOptions, StationReport, run};
pub use scan_hook::{NoProcessing, ScanHook};
pub use stop::StopHandle;
pub use storage_budget::{StorageBudget, parse_bytes};

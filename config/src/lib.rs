//! Campanile's configuration: the station (site, camera, head, filter
//! wheel, lights), plans, and scenes, as serde types read from RON files.
//!
//! Every file is validated after parsing: ranges and units, names, and
//! cross-references (a plan step naming a filter slot, light, pose or face
//! that does not exist; a head pose beyond the head's limits). Every error
//! names the file, line and column, the field, the value, and what was
//! expected, and no input makes the loader panic.
//!
//! ```no_run
//! let station = campanile_config::load_station("examples/sim-station.ron".as_ref())?;
//! println!("{} at {:.4}°N", station.value.name, station.value.site.latitude_deg);
//! # Ok::<(), campanile_config::ConfigErrors>(())
//! ```

pub mod camera;
pub mod camera_calibration;
pub mod document;
pub mod error;
pub mod filter_wheel;
pub mod head;
pub mod lights;
pub mod link;
pub mod plan;
pub mod quality;
pub mod scene;
pub mod shutter;
pub mod site;
pub mod source;
pub mod span_tree;
pub mod station;
pub mod summary;
pub mod targets;
pub mod validate;

#[cfg(test)]
mod arbitrary;
#[cfg(test)]
mod roundtrip;

pub use camera::Camera;
pub use document::{
    Document, Loaded, LoadedPlan, check_plan_on_station, load, load_plan, load_quality, load_scene, load_station,
    load_targets, load_text,
};
pub use error::{ConfigError, ConfigErrors};
pub use filter_wheel::FilterWheel;
pub use head::PanTiltHead;
pub use lights::Lights;
pub use plan::Plan;
pub use quality::Quality;
pub use scene::Scene;
pub use site::Site;
pub use station::Station;

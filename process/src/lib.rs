//! The science: pure, synchronous, deterministic solvers. See the README table for what exists.
//!
//! - [`camera`]: the photographic model of a camera (response curve, sensor
//!   noise, quantization, saturation). The simulator photographs its scenes
//!   through this model, and the HDR tests use it as ground truth.
//! - [`hdr`]: camera response recovery (Debevec–Malik, Robertson), HDR
//!   assembly, lens falloff, and the checks on the input images.
//! - [`exr_io`]: OpenEXR output and input of radiance maps.
//! - [`rgbe_file`]: Radiance RGBE (`.hdr`) output of radiance maps.
//! - [`radiance_file`]: reading an HDR radiance image (OpenEXR, RGBE, PFM).
//! - [`texture`]: texture maps from registered photographs (thesis §3.4).

pub mod brdf;
pub mod camera;
pub mod csv_cell;
pub mod environment;
pub mod error_figures;
pub mod exr_io;
pub mod hdr;
pub mod igi;
pub mod irradiance;
pub mod material_export;
pub mod model_choice;
pub mod outdoor;
pub mod pipeline;
pub mod pose;
pub mod quality;
pub mod radiance_file;
pub mod registration;
pub mod render;
pub mod report;
pub mod rgbe_file;
pub mod scene_geometry;
pub mod sky;
pub mod sky_camera_calibration;
pub mod sky_series;
pub mod sun;
pub mod texture;
pub mod visibility;

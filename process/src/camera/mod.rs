//! The photographic model of a camera: what happens between scene radiance
//! and the integer codes in an image file.
//!
//! `code = quantize(f(clip(exposure + noise)))`, with `exposure = L · t · k`
//! (radiance `L` in W·m⁻²·sr⁻¹, exposure time `t` in s, a per-channel sensor
//! gain `k`), shot and read noise, clipping at the full well, a nonlinear
//! monotone response `f` ([`response::ParametricResponse`]) and quantization to
//! 8, 12 or 16 bits ([`sensor::CameraModel`]).

pub mod bayer;
pub mod code_table;
pub mod image;
pub mod response;
pub mod sensor;
pub mod test_chart;
pub mod textured_scene;

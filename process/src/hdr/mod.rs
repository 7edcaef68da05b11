//! Camera response recovery and HDR assembly.
//!
//! - [`bracket`]: a validated exposure bracket (sizes, bit depths, times).
//! - [`align`]: registration of hand-held brackets (median threshold bitmaps, then sub-pixel Lucas–Kanade).
//! - [`deghost`]: exclusion of samples inconsistent with the reference exposure (moving objects).
//! - [`bracket_files`]: a bracket on disk, decoded one frame at a time (bounded memory).
//! - [`exposure_codes`]: what response recovery reads of a bracket, whole or sampled.
//! - [`sampled_bracket`]: a bracket read from files keeping only the pixels sampling looks at.
//! - [`bracket_list`]: bracket list files and `1/30`-style times.
//! - [`sampling`]: seeded, intensity-stratified, edge- and motion-free sample selection.
//! - [`debevec`]: Debevec–Malik response recovery (f64 Schur-complement normal equations).
//! - [`robertson`]: Robertson–Borman–Stevenson iterative recovery, for comparison.
//! - [`noise_bias`]: bootstrap correction of the dark end's noise bias.
//! - [`curve`]: the recovered response curve, its uncertainty, CSV I/O and error metrics.
//! - [`curve_plot`]: SVG plot of a curve with its uncertainty band.
//! - [`merge`]: the single-pass, LUT-driven, noise-optimal radiance merge.
//! - [`merge_stream`]: the same merge over a bracket on disk, one frame at a time.
//! - [`lens`]: the radial falloff and distortion model `1 + a r² + b r⁴` and its fit.
//! - [`resampled`]: a statistic of resampling in 8-bit images (measured, not a check).
//! - [`image_file`]: reading brackets from PNG/TIFF/JPEG files, turned upright.
//! - [`exposure_metadata`]: EXIF exposure time, f-number, ISO, orientation; effective times.
//! - [`white_point`]: each frame's effective white point per channel (clipping below the largest code).
//! - [`raw_file`]: reading camera RAW files (rawler) into [`linear_frame`]s.
//! - [`linear_codes`]: linear frames as logarithmic codes for the session pipeline, and their exact curve.
//! - [`linear_merge`]: merging linear frames without a response curve.
//! - [`dng_file`]: writing DNG files (for the simulated RAW path).
//! - [`tiff_structure`]: the IFD structure of a TIFF/DNG, without its pixels.
//! - [`error`]: the typed errors of all of the above ([`raw_error`] for the RAW path).

pub mod align;
pub mod bracket;
pub mod bracket_files;
pub mod bracket_list;
pub mod curve;
pub mod curve_plot;
pub mod debevec;
pub mod deghost;
pub mod dng_file;
pub mod error;
pub mod exposure_codes;
pub mod exposure_metadata;
pub mod fits_file;
pub mod image_file;
pub mod lens;
pub mod linear_codes;
pub mod linear_frame;
pub mod linear_merge;
pub mod merge;
pub mod merge_stream;
pub mod noise_bias;
pub mod raw_error;
pub mod raw_file;
pub mod resampled;
pub mod robertson;
pub mod sampled_bracket;
pub mod sampling;
pub mod tiff_structure;
pub mod white_point;

pub use error::HdrError;

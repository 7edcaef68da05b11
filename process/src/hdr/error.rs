//! Typed errors of response recovery and merging. Each names the image, pixel
//! or value at fault and what was expected.

use std::path::PathBuf;

/// Everything that can go wrong in `hdr`.
#[derive(Debug, thiserror::Error)]
pub enum HdrError {
    /// No image at all.
    #[error("no images given: expected at least one exposure")]
    NoImages,
    /// Calibration needs at least two exposures.
    #[error("{0} exposure given: response recovery needs at least 2 exposures with different times")]
    SingleExposure(usize),
    /// The number of times does not match the number of images.
    #[error("{images} images but {times} exposure times: expected one time per image")]
    TimeCountMismatch {
        /// Number of images.
        images: usize,
        /// Number of times.
        times: usize,
    },
    /// An exposure time is not a finite positive number.
    #[error("image '{image}': exposure time {time_s} s is invalid: expected a finite time > 0")]
    InvalidTime {
        /// The image.
        image: String,
        /// The value.
        time_s: f64,
    },
    /// Two images carry the same exposure time.
    #[error(
        "images '{first}' and '{second}' both have exposure time {time_s} s: expected distinct times \
         (some phones write the same EXIF time for different frames: leave one out, or give the true \
         times with --times or --list)"
    )]
    DuplicateTime {
        /// First image.
        first: String,
        /// Second image.
        second: String,
        /// The shared time.
        time_s: f64,
    },
    /// The brightness order of the images contradicts their times.
    #[error(
        "image '{brighter}' (t = {brighter_time_s} s) is brighter than '{darker}' (t = {darker_time_s} s): \
         the exposure times are probably listed in the wrong order"
    )]
    TimesContradictBrightness {
        /// The brighter image.
        brighter: String,
        /// Its labelled time.
        brighter_time_s: f64,
        /// The darker image.
        darker: String,
        /// Its labelled time.
        darker_time_s: f64,
    },
    /// Images of different sizes.
    #[error("image '{image}' is {width}×{height}, but '{first}' is {first_width}×{first_height}: expected equal sizes")]
    SizeMismatch {
        /// The odd image.
        image: String,
        /// Its width.
        width: usize,
        /// Its height.
        height: usize,
        /// The first image.
        first: String,
        /// First width.
        first_width: usize,
        /// First height.
        first_height: usize,
    },
    /// Images of different bit depths.
    #[error("image '{image}' has {bits} bits per sample, but '{first}' has {first_bits}: expected equal bit depths")]
    BitDepthMismatch {
        /// The odd image.
        image: String,
        /// Its depth.
        bits: u8,
        /// The first image.
        first: String,
        /// First depth.
        first_bits: u8,
    },
    /// A buffer whose length does not match its size.
    #[error("image '{image}': {len} samples for {width}×{height} RGB: expected {expected}")]
    BufferLength {
        /// The image.
        image: String,
        /// Actual length.
        len: usize,
        /// Width.
        width: usize,
        /// Height.
        height: usize,
        /// Expected length.
        expected: usize,
    },
    /// Empty image, or unsupported bit depth.
    #[error("image '{image}': {what}")]
    BadImage {
        /// The image.
        image: String,
        /// What is wrong.
        what: String,
    },
    /// A code above the maximum of the declared bit depth.
    #[error("image '{image}': pixel ({x}, {y}) channel {channel} has code {code}, above the {bits}-bit maximum {max}")]
    CodeOutOfRange {
        /// The image.
        image: String,
        /// Column.
        x: usize,
        /// Row.
        y: usize,
        /// Channel.
        channel: usize,
        /// Value.
        code: u16,
        /// Bit depth.
        bits: u8,
        /// Maximum.
        max: u16,
    },
    /// Not enough usable samples.
    #[error(
        "channel {channel}: only {found} usable samples (unclipped, edge- and motion-free): expected at least {needed}"
    )]
    TooFewSamples {
        /// Channel.
        channel: usize,
        /// Found.
        found: usize,
        /// Needed.
        needed: usize,
    },
    /// An option out of range.
    #[error("option {name} = {value}: expected {expected}")]
    BadOption {
        /// Option name.
        name: &'static str,
        /// Its value, as text.
        value: String,
        /// What was expected.
        expected: &'static str,
    },
    /// The linear solve failed.
    #[error("channel {channel}: the normal equations are singular ({what})")]
    Singular {
        /// Channel.
        channel: usize,
        /// Detail.
        what: String,
    },
    /// The curve and the images disagree.
    #[error("response curve is for {curve_bits}-bit codes but the images have {image_bits} bits")]
    CurveBitsMismatch {
        /// Curve depth.
        curve_bits: u8,
        /// Image depth.
        image_bits: u8,
    },
    /// A malformed curve or lens file.
    #[error("{path}:{line}: {what}")]
    Parse {
        /// File.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// What was expected.
        what: String,
    },
    /// A file's EXIF block: unreadable, or a field missing or impossible.
    #[error("{path}: EXIF: {what}")]
    Exif {
        /// File.
        path: PathBuf,
        /// What is wrong, and what was expected.
        what: String,
    },
    /// File I/O.
    #[error("{path}: {cause}")]
    Io {
        /// File.
        path: PathBuf,
        /// Cause (shown in the message, not chained, so it prints once).
        cause: std::io::Error,
    },
    /// Image decoding or encoding.
    #[error("{path}: {cause}")]
    Image {
        /// File.
        path: PathBuf,
        /// Cause.
        cause: image::ImageError,
    },
    /// OpenEXR reading or writing.
    #[error("{path}: {cause}")]
    Exr {
        /// File.
        path: PathBuf,
        /// Cause.
        cause: exr::error::Error,
    },
    /// Reading a RAW file or merging linear frames (see [`super::raw_error`]).
    #[error(transparent)]
    Raw(#[from] super::raw_error::RawError),
}

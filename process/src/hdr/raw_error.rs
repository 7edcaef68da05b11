//! Typed errors of reading camera RAW files and merging linear frames. Each
//! names the file, the field or pixel, what was found and what was expected.

use std::path::PathBuf;

/// Everything that can go wrong reading a RAW file or merging linear frames.
#[derive(Debug, thiserror::Error)]
pub enum RawError {
    /// The file could not be read.
    #[error("{path}: {cause}")]
    Io {
        /// The file.
        path: PathBuf,
        /// Cause.
        cause: std::io::Error,
    },
    /// The decoder (rawler) refused the file.
    #[error("{path}: the RAW decoder could not read it: {cause}")]
    Decode {
        /// The file.
        path: PathBuf,
        /// The decoder's message.
        cause: String,
    },
    /// A DNG whose only image is a preview or thumbnail.
    #[error(
        "{path}: no pixel data: the only image is a {width}×{height} {bits}-bit {what} \
         (NewSubFileType {subfile_type}); expected a full-resolution CFA or LinearRaw image \
         (NewSubFileType 0){declared}; a thumbnail is never merged"
    )]
    ThumbnailOnly {
        /// The file.
        path: PathBuf,
        /// Width of the largest image found.
        width: u32,
        /// Height of the largest image found.
        height: u32,
        /// Its bits per sample.
        bits: u16,
        /// What it is ("RGB preview", …).
        what: String,
        /// Its NewSubFileType.
        subfile_type: u32,
        /// The declared size, if the file states one (", declared …").
        declared: String,
    },
    /// The decoded raw image is much smaller than the size the file declares.
    #[error(
        "{path}: the image found is {width}×{height} but the file declares {declared_width}×{declared_height}: \
         a preview, not the raw data; never merged"
    )]
    SmallerThanDeclared {
        /// The file.
        path: PathBuf,
        /// Width found.
        width: usize,
        /// Height found.
        height: usize,
        /// Declared width.
        declared_width: usize,
        /// Declared height.
        declared_height: usize,
    },
    /// A colour filter array other than a 2×2 RGB Bayer pattern.
    #[error(
        "{path}: unsupported CFA '{pattern}' ({pattern_width}×{pattern_height}): expected a 2×2 Bayer pattern \
         (RGGB, BGGR, GRBG or GBRG)"
    )]
    UnsupportedCfa {
        /// The file.
        path: PathBuf,
        /// The pattern as letters.
        pattern: String,
        /// Pattern width.
        pattern_width: usize,
        /// Pattern height.
        pattern_height: usize,
    },
    /// A layout the reader does not handle (samples per pixel, float data, …).
    #[error("{path}: unsupported raw layout: {what}")]
    UnsupportedLayout {
        /// The file.
        path: PathBuf,
        /// What was found and what is expected.
        what: String,
    },
    /// White level not above the black level.
    #[error("{path}: white level {white} is not above the black level {black}: expected white > black > … ≥ 0")]
    BadLevels {
        /// The file.
        path: PathBuf,
        /// White level.
        white: f64,
        /// Largest black level.
        black: f64,
    },
    /// An exposure field missing or invalid in the metadata.
    #[error("{path}: {field} is {found}: expected {expected}")]
    Metadata {
        /// The file.
        path: PathBuf,
        /// The field (ExposureTime, FNumber, ISO, …).
        field: &'static str,
        /// What was found.
        found: String,
        /// What was expected.
        expected: &'static str,
    },
    /// Frames of different sizes in one merge.
    #[error("{image}: {width}×{height}, but {first} is {first_width}×{first_height}: expected equal sizes")]
    SizeMismatch {
        /// The odd frame.
        image: String,
        /// Its width.
        width: usize,
        /// Its height.
        height: usize,
        /// The first frame.
        first: String,
        /// First width.
        first_width: usize,
        /// First height.
        first_height: usize,
    },
    /// A non-finite or out-of-range value in a frame.
    #[error("{image}: pixel ({x}, {y}) channel {channel} is {value}: expected a finite value")]
    BadValue {
        /// The frame.
        image: String,
        /// Column.
        x: usize,
        /// Row.
        y: usize,
        /// Channel.
        channel: usize,
        /// The value.
        value: f32,
    },
    /// A frame whose buffers do not match its size.
    #[error("{image}: {what}")]
    BadFrame {
        /// The frame.
        image: String,
        /// What is wrong.
        what: String,
    },
    /// No frames, or an option out of range.
    #[error("option {name} = {value}: expected {expected}")]
    BadOption {
        /// Option name.
        name: &'static str,
        /// Its value, as text.
        value: String,
        /// What was expected.
        expected: &'static str,
    },
    /// Writing a DNG failed.
    #[error("writing {path}: {cause}")]
    Write {
        /// The file.
        path: PathBuf,
        /// Cause.
        cause: std::io::Error,
    },
}

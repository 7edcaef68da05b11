//! A linear frame: a demosaiced RAW exposure, normalized so that black is 0
//! and the white level is 1 in each raw channel (before white balance), with
//! a per-pixel, per-channel clipped flag and the metadata the linear merge
//! and the colour conversion need.

/// What the file says about the frame.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FrameMetadata {
    /// Make, as in the file.
    pub make: String,
    /// Model, as in the file.
    pub model: String,
    /// Exposure time in seconds (EXIF ExposureTime).
    pub exposure_time_s: Option<f64>,
    /// Aperture f-number (EXIF FNumber).
    pub f_number: Option<f64>,
    /// ISO speed (EXIF ISOSpeedRatings, or ISOSpeed).
    pub iso: Option<f64>,
    /// The colour filter pattern, e.g. "RGGB".
    pub cfa: String,
    /// Black level per position of the 2×2 pattern (row-major, relative to
    /// the image's top-left photosite), in raw codes.
    pub black_levels: [f64; 4],
    /// White level in raw codes.
    pub white_level: f64,
    /// The white level in electrons, when the metadata gives it. DNG and
    /// the common RAW formats do not (it needs the sensor's conversion
    /// gain), so this is `None` for files and set only by simulations.
    pub white_level_electrons: Option<f64>,
    /// As-shot white-balance multipliers per camera channel, normalized to
    /// green = 1 (for a DNG, 1 / AsShotNeutral).
    pub wb_multipliers: Option<[f64; 3]>,
    /// XYZ → camera matrix (the DNG ColorMatrix convention), row-major, and
    /// the EXIF light source code of its calibration illuminant.
    pub xyz_to_camera: Option<([[f64; 3]; 3], u16)>,
}

/// A demosaiced linear exposure.
#[derive(Debug, Clone, PartialEq)]
pub struct LinearFrame {
    /// Where it came from (the file), for messages.
    pub label: String,
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Interleaved camera RGB: 0 = black, 1 = the white level, per raw
    /// channel, before white balance. Slightly negative values (read noise
    /// below black) are kept.
    pub rgb: Vec<f32>,
    /// Per pixel: bit `1 << c` set when channel `c` was estimated from a
    /// photosite at or above the white level.
    pub clipped: Vec<u8>,
    /// Metadata.
    pub meta: FrameMetadata,
}

impl LinearFrame {
    /// Whether channel `c` of pixel `p` (`y · width + x`) is clipped.
    pub fn is_clipped(&self, p: usize, c: usize) -> bool {
        self.clipped[p] & (1 << c) != 0
    }
}

//! Image buffers: integer sensor codes as they come from a camera or a file,
//! and linear radiance as it comes from a scene or a merge.

/// An RGB image of integer codes (8, 12 or 16 significant bits), stored
/// interleaved (`[r, g, b, r, g, b, …]`, row-major) in `u16`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CodeImage {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Significant bits per sample: codes lie in `0..=2^bits − 1`.
    pub bits: u8,
    /// Interleaved RGB codes, `width · height · 3` of them.
    pub data: Vec<u16>,
    /// Where the image came from (a file name, or a description), for error messages.
    pub label: String,
}

impl CodeImage {
    /// Largest code this bit depth can hold.
    pub fn max_code(&self) -> u16 {
        max_code(self.bits)
    }

    /// The code of channel `c` at pixel (`x`, `y`).
    pub fn code(&self, x: usize, y: usize, c: usize) -> u16 {
        self.data[(y * self.width + x) * 3 + c]
    }

    /// Number of pixels.
    pub fn pixel_count(&self) -> usize {
        self.width * self.height
    }
}

/// Largest code of a `bits`-bit sample.
pub fn max_code(bits: u8) -> u16 {
    ((1u32 << bits.min(16)) - 1) as u16
}

/// A linear RGB radiance image in W·m⁻²·sr⁻¹ per camera channel, interleaved, f32.
#[derive(Debug, Clone, PartialEq)]
pub struct RadianceImage {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Interleaved RGB radiance, `width · height · 3` values.
    pub data: Vec<f32>,
}

impl RadianceImage {
    /// The radiance of channel `c` at pixel (`x`, `y`).
    pub fn radiance(&self, x: usize, y: usize, c: usize) -> f32 {
        self.data[(y * self.width + x) * 3 + c]
    }
}

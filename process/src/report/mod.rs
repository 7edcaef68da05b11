//! The processing report: one self-contained HTML page (every image inline
//! as a data URI, no scripts or fonts fetched), with sections of text,
//! tables and figures. `campanile demo` and `campanile process` write it.
//!
//! The page carries a small inline check: once loaded, it counts the images
//! that decoded and writes `data-images-loaded="N/M"` on `<body>`, so a
//! headless browser's DOM dump says whether every figure loads.

mod html;
mod image_encode;
mod plot;

pub use html::{ColourScale, Figure, Report, Section, SummaryRow, Table, flagged};
pub use image_encode::{false_colour_png, tonemapped_png};
pub use plot::{LABEL_PX, Series, line_plot_svg};

/// Why a figure could not be made.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// An image buffer does not match its size.
    #[error("{what}: {len} values for a {width}×{height} image (expected {expected})")]
    Size {
        /// The figure.
        what: String,
        /// Values given.
        len: usize,
        /// Width.
        width: usize,
        /// Height.
        height: usize,
        /// Values expected.
        expected: usize,
    },
    /// Encoding failed.
    #[error("{what}: {message}")]
    Encode {
        /// The figure.
        what: String,
        /// Why.
        message: String,
    },
}

//! The file a camera delivers a frame as, when it delivers one: a DSLR
//! through gphoto2 or INDI gives its JPEG or RAW file, a webcam its MJPEG
//! frame. The session store keeps such a file byte for byte (no
//! re-encoding, so nothing is lost) and processing decodes it through the
//! HDR readers of `campanile-process`.

use serde::{Deserialize, Serialize};

/// A frame file's format, as journaled (`"format": "jpeg"`). Journals from
/// before the field existed hold 16-bit PNGs: the default.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FrameFormat {
    /// A 16-bit RGB PNG of the codes, unscaled (the store's own encoding
    /// of decoded frames).
    #[default]
    Png,
    /// A camera's JPEG (8-bit codes, EXIF orientation applied on reading).
    Jpeg,
    /// A DNG RAW file (read as a linear frame: black level removed, white
    /// level the largest code, clipped samples flagged).
    Dng,
    /// A FITS image as astronomical cameras send it (an INDI `CCD1` BLOB):
    /// integer codes, the camera's header kept in the file.
    Fits,
}

impl FrameFormat {
    /// Every format, for listing.
    pub const ALL: [FrameFormat; 4] = [FrameFormat::Png, FrameFormat::Jpeg, FrameFormat::Dng, FrameFormat::Fits];

    /// The file name extension the store gives it (no dot).
    pub fn extension(self) -> &'static str {
        match self {
            FrameFormat::Png => "png",
            FrameFormat::Jpeg => "jpg",
            FrameFormat::Dng => "dng",
            FrameFormat::Fits => "fits",
        }
    }

    /// The format's name in messages.
    pub fn name(self) -> &'static str {
        match self {
            FrameFormat::Png => "PNG",
            FrameFormat::Jpeg => "JPEG",
            FrameFormat::Dng => "DNG",
            FrameFormat::Fits => "FITS",
        }
    }

    /// Why `bytes` cannot be a file of this format, judged by its first
    /// bytes (PNG signature, JPEG start-of-image marker, TIFF header), if
    /// they cannot.
    pub fn signature_problem(self, bytes: &[u8]) -> Option<String> {
        let ok = match self {
            FrameFormat::Png => bytes.starts_with(b"\x89PNG\r\n\x1a\n"),
            FrameFormat::Jpeg => bytes.starts_with(&[0xFF, 0xD8, 0xFF]),
            FrameFormat::Dng => bytes.starts_with(b"II*\0") || bytes.starts_with(b"MM\0*"),
            FrameFormat::Fits => bytes.starts_with(b"SIMPLE  ="),
        };
        (!ok).then(|| {
            let head: Vec<String> = bytes.iter().take(8).map(|b| format!("{b:02x}")).collect();
            let expected = match self {
                FrameFormat::Png => "the PNG signature 89 50 4e 47 0d 0a 1a 0a",
                FrameFormat::Jpeg => "the JPEG start of image ff d8 ff",
                FrameFormat::Dng => "a TIFF header (49 49 2a 00 or 4d 4d 00 2a)",
                FrameFormat::Fits => "the FITS card \"SIMPLE  =\" (53 49 4d 50 4c 45 20 20 3d)",
            };
            format!(
                "{} bytes starting [{}], expected {expected} for a {} file",
                bytes.len(),
                head.join(" "),
                self.name()
            )
        })
    }

    /// Why `bytes` cannot be a whole file of this format, judged by its
    /// end, if they cannot: a JPEG must end with its end-of-image marker
    /// (ff d9, trailing zero padding allowed). JPEG decoders fill a file cut
    /// short with grey instead of failing, so a truncated frame would
    /// otherwise be merged as data.
    pub fn end_problem(self, bytes: &[u8]) -> Option<String> {
        if self != FrameFormat::Jpeg {
            return None;
        }
        let end = bytes.iter().rposition(|&b| b != 0).map_or(0, |i| i + 1);
        (!bytes[..end].ends_with(&[0xFF, 0xD9])).then(|| {
            let tail: Vec<String> = bytes[end.saturating_sub(4)..end]
                .iter()
                .map(|b| format!("{b:02x}"))
                .collect();
            format!(
                "{} bytes ending [{}], expected the JPEG end of image ff d9: the file is cut short",
                bytes.len(),
                tail.join(" ")
            )
        })
    }
}

/// A frame as the camera's file delivered it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FrameFile {
    /// Its format.
    pub format: FrameFormat,
    /// Its bytes, exactly as delivered.
    pub bytes: Vec<u8>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn signatures_are_checked_and_named() {
        assert_eq!(FrameFormat::Jpeg.signature_problem(&[0xFF, 0xD8, 0xFF, 0xE0]), None);
        assert_eq!(FrameFormat::Dng.signature_problem(b"II*\0\x08\0\0\0"), None);
        let p = FrameFormat::Jpeg.signature_problem(b"II*\0").unwrap();
        assert!(p.contains("[49 49 2a 00]") && p.contains("ff d8 ff"), "{p}");
        let p = FrameFormat::Dng.signature_problem(&[]).unwrap();
        assert!(p.starts_with("0 bytes"), "{p}");
    }
}

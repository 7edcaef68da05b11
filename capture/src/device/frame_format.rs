//! The file a camera delivers a frame as, when it delivers one: a DSLR
//! through gphoto2 or INDI gives its JPEG or RAW file (DNG or the maker's:
//! CR2, CR3, NEF, ARW, RAF, RW2, ORF, PEF, SRW), a webcam its MJPEG
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
    /// A Canon CR2 RAW file (TIFF-based), read like a DNG through `rawler`
    /// (so are the RAW formats below).
    Cr2,
    /// A Canon CR3 RAW file (ISO base media, brand `crx `).
    Cr3,
    /// A Nikon NEF RAW file (TIFF-based).
    Nef,
    /// A Sony ARW RAW file (TIFF-based).
    Arw,
    /// A Fujifilm RAF RAW file.
    Raf,
    /// A Panasonic RW2 RAW file.
    Rw2,
    /// An Olympus ORF RAW file.
    Orf,
    /// A Pentax PEF RAW file (TIFF-based).
    Pef,
    /// A Samsung SRW RAW file (TIFF-based).
    Srw,
}

impl FrameFormat {
    /// Every format, for listing.
    pub const ALL: [FrameFormat; 13] = [
        FrameFormat::Png,
        FrameFormat::Jpeg,
        FrameFormat::Dng,
        FrameFormat::Fits,
        FrameFormat::Cr2,
        FrameFormat::Cr3,
        FrameFormat::Nef,
        FrameFormat::Arw,
        FrameFormat::Raf,
        FrameFormat::Rw2,
        FrameFormat::Orf,
        FrameFormat::Pef,
        FrameFormat::Srw,
    ];

    /// The file name extension the store gives it (no dot).
    pub fn extension(self) -> &'static str {
        match self {
            FrameFormat::Png => "png",
            FrameFormat::Jpeg => "jpg",
            FrameFormat::Dng => "dng",
            FrameFormat::Fits => "fits",
            FrameFormat::Cr2 => "cr2",
            FrameFormat::Cr3 => "cr3",
            FrameFormat::Nef => "nef",
            FrameFormat::Arw => "arw",
            FrameFormat::Raf => "raf",
            FrameFormat::Rw2 => "rw2",
            FrameFormat::Orf => "orf",
            FrameFormat::Pef => "pef",
            FrameFormat::Srw => "srw",
        }
    }

    /// The format's name in messages.
    pub fn name(self) -> &'static str {
        match self {
            FrameFormat::Png => "PNG",
            FrameFormat::Jpeg => "JPEG",
            FrameFormat::Dng => "DNG",
            FrameFormat::Fits => "FITS",
            FrameFormat::Cr2 => "CR2",
            FrameFormat::Cr3 => "CR3",
            FrameFormat::Nef => "NEF",
            FrameFormat::Arw => "ARW",
            FrameFormat::Raf => "RAF",
            FrameFormat::Rw2 => "RW2",
            FrameFormat::Orf => "ORF",
            FrameFormat::Pef => "PEF",
            FrameFormat::Srw => "SRW",
        }
    }

    /// Whether it is a camera RAW file (DNG or a maker's), read as a
    /// linear frame.
    pub fn is_raw(self) -> bool {
        !matches!(self, FrameFormat::Png | FrameFormat::Jpeg | FrameFormat::Fits)
    }

    /// The format a file name's extension names (case-insensitive; `jpeg`
    /// and `fit` too), if any.
    pub fn from_file_name(name: &str) -> Option<Self> {
        let ext = name.rsplit_once('.')?.1.to_ascii_lowercase();
        match ext.as_str() {
            "jpeg" => Some(FrameFormat::Jpeg),
            "fit" | "fts" => Some(FrameFormat::Fits),
            e => Self::ALL.into_iter().find(|f| f.extension() == e),
        }
    }

    /// Why `bytes` cannot be a file of this format, judged by its first
    /// bytes (PNG signature, JPEG start-of-image marker, TIFF header), if
    /// they cannot.
    pub fn signature_problem(self, bytes: &[u8]) -> Option<String> {
        let tiff = bytes.starts_with(b"II*\0") || bytes.starts_with(b"MM\0*");
        let ok = match self {
            FrameFormat::Png => bytes.starts_with(b"\x89PNG\r\n\x1a\n"),
            FrameFormat::Jpeg => bytes.starts_with(&[0xFF, 0xD8, 0xFF]),
            FrameFormat::Dng
            | FrameFormat::Cr2
            | FrameFormat::Nef
            | FrameFormat::Arw
            | FrameFormat::Pef
            | FrameFormat::Srw => tiff,
            FrameFormat::Fits => bytes.starts_with(b"SIMPLE  ="),
            FrameFormat::Cr3 => bytes.get(4..12) == Some(b"ftypcrx "),
            FrameFormat::Raf => bytes.starts_with(b"FUJIFILMCCD-RAW"),
            FrameFormat::Rw2 => bytes.starts_with(b"IIU\0"),
            FrameFormat::Orf => bytes.starts_with(b"IIRO") || bytes.starts_with(b"IIRS") || bytes.starts_with(b"MMOR"),
        };
        (!ok).then(|| {
            let head: Vec<String> = bytes.iter().take(8).map(|b| format!("{b:02x}")).collect();
            let expected = match self {
                FrameFormat::Png => "the PNG signature 89 50 4e 47 0d 0a 1a 0a",
                FrameFormat::Jpeg => "the JPEG start of image ff d8 ff",
                FrameFormat::Dng
                | FrameFormat::Cr2
                | FrameFormat::Nef
                | FrameFormat::Arw
                | FrameFormat::Pef
                | FrameFormat::Srw => "a TIFF header (49 49 2a 00 or 4d 4d 00 2a)",
                FrameFormat::Fits => "the FITS card \"SIMPLE  =\" (53 49 4d 50 4c 45 20 20 3d)",
                FrameFormat::Cr3 => "an ISO media box of brand \"crx \" (ftyp crx at byte 4)",
                FrameFormat::Raf => "\"FUJIFILMCCD-RAW\"",
                FrameFormat::Rw2 => "the Panasonic header 49 49 55 00",
                FrameFormat::Orf => "an Olympus header (IIRO, IIRS or MMOR)",
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

    #[test]
    fn camera_raw_formats_have_their_names_and_signatures() {
        assert_eq!(FrameFormat::from_file_name("IMG_0001.CR2"), Some(FrameFormat::Cr2));
        assert_eq!(FrameFormat::from_file_name("DSC_0001.nef"), Some(FrameFormat::Nef));
        assert_eq!(FrameFormat::from_file_name("a.JPEG"), Some(FrameFormat::Jpeg));
        assert_eq!(FrameFormat::from_file_name("a.tif"), None);
        assert_eq!(FrameFormat::from_file_name("noext"), None);
        let raw: Vec<&str> = FrameFormat::ALL
            .iter()
            .filter(|f| f.is_raw())
            .map(|f| f.extension())
            .collect();
        assert_eq!(
            raw,
            ["dng", "cr2", "cr3", "nef", "arw", "raf", "rw2", "orf", "pef", "srw"]
        );
        // Each extension names its own format back.
        for f in FrameFormat::ALL {
            assert_eq!(FrameFormat::from_file_name(&format!("x.{}", f.extension())), Some(f));
        }
        assert_eq!(FrameFormat::Nef.signature_problem(b"MM\0*\0\0\0\x08"), None);
        assert_eq!(
            FrameFormat::Cr3.signature_problem(b"\0\0\0\x18ftypcrx \0\0\0\x01"),
            None
        );
        assert_eq!(FrameFormat::Raf.signature_problem(b"FUJIFILMCCD-RAW 0201"), None);
        assert_eq!(FrameFormat::Rw2.signature_problem(b"IIU\0\x18\0\0\0"), None);
        assert_eq!(FrameFormat::Orf.signature_problem(b"IIRO\x08\0\0\0"), None);
        let p = FrameFormat::Cr3.signature_problem(b"II*\0\x08\0\0\0").unwrap();
        assert!(p.contains("brand \"crx \"") && p.contains("CR3 file"), "{p}");
        let p = FrameFormat::Cr2.signature_problem(&[0xFF, 0xD8, 0xFF, 0xE1]).unwrap();
        assert!(p.contains("TIFF header") && p.contains("CR2 file"), "{p}");
    }
}

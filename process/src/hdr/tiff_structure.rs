//! The structure of a TIFF file, without its pixels: the image file
//! directories (IFD0, its chain and its SubIFDs), each a list of tags with
//! their numeric values. Enough to tell a DNG from a plain TIFF (the
//! DNGVersion tag) and a raw image from a thumbnail (NewSubFileType,
//! PhotometricInterpretation, size) before any decoder sees the file.
//!
//! Both byte orders; every offset is checked against the buffer, so a
//! truncated or hostile file gives `None`, never a panic.

/// TIFF tag: NewSubFileType (bit 0 set = reduced-resolution preview).
pub const TAG_NEW_SUBFILE_TYPE: u16 = 254;
/// TIFF tag: ImageWidth.
pub const TAG_IMAGE_WIDTH: u16 = 256;
/// TIFF tag: ImageLength.
pub const TAG_IMAGE_LENGTH: u16 = 257;
/// TIFF tag: BitsPerSample.
pub const TAG_BITS_PER_SAMPLE: u16 = 258;
/// TIFF tag: PhotometricInterpretation.
pub const TAG_PHOTOMETRIC: u16 = 262;
/// TIFF tag: SamplesPerPixel.
pub const TAG_SAMPLES_PER_PIXEL: u16 = 277;
/// TIFF tag: SubIFDs.
pub const TAG_SUB_IFDS: u16 = 330;
/// DNG tag: DNGVersion.
pub const TAG_DNG_VERSION: u16 = 50706;
/// DNG tag: DefaultCropSize.
pub const TAG_DEFAULT_CROP_SIZE: u16 = 50720;
/// PhotometricInterpretation of a colour filter array image.
pub const PHOTOMETRIC_CFA: u64 = 32803;
/// PhotometricInterpretation of a demosaiced linear DNG.
pub const PHOTOMETRIC_LINEAR_RAW: u64 = 34892;

/// One image file directory: `(tag, values)` in file order. Rational values
/// are kept as their numerators (enough for the integer tags read here).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Ifd {
    /// Tags and their values (integers; the first value of a rational).
    pub entries: Vec<(u16, Vec<u64>)>,
}

impl Ifd {
    /// The values of `tag`, if present.
    pub fn get(&self, tag: u16) -> Option<&[u64]> {
        self.entries.iter().find(|(t, _)| *t == tag).map(|(_, v)| v.as_slice())
    }

    /// The first value of `tag`, if present.
    pub fn first(&self, tag: u16) -> Option<u64> {
        self.get(tag).and_then(|v| v.first().copied())
    }

    /// Width × height, 0 where missing.
    pub fn size(&self) -> (u64, u64) {
        (
            self.first(TAG_IMAGE_WIDTH).unwrap_or(0),
            self.first(TAG_IMAGE_LENGTH).unwrap_or(0),
        )
    }

    /// Whether this IFD is a reduced-resolution image (NewSubFileType bit 0).
    pub fn is_reduced(&self) -> bool {
        self.first(TAG_NEW_SUBFILE_TYPE).unwrap_or(0) & 1 == 1
    }
}

/// The directories of a TIFF file: IFD0 first, then the rest of its chain,
/// then the SubIFDs of each (depth first, at most 64 in all).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TiffStructure {
    /// IFD0.
    pub ifd0: Ifd,
    /// Every other directory found.
    pub others: Vec<Ifd>,
}

impl TiffStructure {
    /// IFD0 and the others, in order.
    pub fn all(&self) -> impl Iterator<Item = &Ifd> {
        std::iter::once(&self.ifd0).chain(self.others.iter())
    }

    /// Whether IFD0 carries the DNGVersion tag.
    pub fn is_dng(&self) -> bool {
        self.ifd0.get(TAG_DNG_VERSION).is_some()
    }
}

struct Reader<'a> {
    b: &'a [u8],
    little: bool,
}

impl Reader<'_> {
    fn bytes<const N: usize>(&self, at: usize) -> Option<[u8; N]> {
        self.b.get(at..at.checked_add(N)?)?.try_into().ok()
    }
    fn u16(&self, at: usize) -> Option<u16> {
        let a = self.bytes::<2>(at)?;
        Some(if self.little {
            u16::from_le_bytes(a)
        } else {
            u16::from_be_bytes(a)
        })
    }
    fn u32(&self, at: usize) -> Option<u32> {
        let a = self.bytes::<4>(at)?;
        Some(if self.little {
            u32::from_le_bytes(a)
        } else {
            u32::from_be_bytes(a)
        })
    }

    /// Reads the IFD at `at`: its entries and the offset of the next one.
    fn ifd(&self, at: usize) -> Option<(Ifd, usize)> {
        let n = usize::from(self.u16(at)?);
        let mut entries = Vec::with_capacity(n);
        for i in 0..n {
            let e = at + 2 + 12 * i;
            let tag = self.u16(e)?;
            let typ = self.u16(e + 2)?;
            let count = self.u32(e + 4)? as usize;
            let size = match typ {
                1 | 2 | 6 | 7 => 1,
                3 | 8 => 2,
                4 | 9 | 11 | 13 => 4,
                5 | 10 | 12 => 8,
                _ => 0,
            };
            // Only small integer arrays are read; other values are skipped.
            let shown = count.min(64);
            let total = size * count;
            let data = if total <= 4 { e + 8 } else { self.u32(e + 8)? as usize };
            let mut values = Vec::with_capacity(shown);
            for k in 0..shown {
                let v = match typ {
                    1 | 2 | 6 | 7 => u64::from(*self.b.get(data + k)?),
                    3 | 8 => u64::from(self.u16(data + 2 * k)?),
                    4 | 9 | 13 => u64::from(self.u32(data + 4 * k)?),
                    5 | 10 => u64::from(self.u32(data + 8 * k)?),
                    _ => break,
                };
                values.push(v);
            }
            entries.push((tag, values));
        }
        let next = self.u32(at + 2 + 12 * n)? as usize;
        Some((Ifd { entries }, next))
    }
}

/// Parses the directory structure of TIFF bytes; `None` if `bytes` is not a
/// TIFF (no `II*\0` / `MM\0*` header) or IFD0 cannot be read.
pub fn parse(bytes: &[u8]) -> Option<TiffStructure> {
    let little = match bytes.get(0..4)? {
        [b'I', b'I', 42, 0] => true,
        [b'M', b'M', 0, 42] => false,
        _ => return None,
    };
    let r = Reader { b: bytes, little };
    let (ifd0, mut next) = r.ifd(r.u32(4)? as usize)?;
    let mut out = TiffStructure {
        ifd0,
        others: Vec::new(),
    };
    let mut pending: Vec<usize> = out
        .ifd0
        .get(TAG_SUB_IFDS)
        .unwrap_or(&[])
        .iter()
        .map(|&o| o as usize)
        .collect();
    let mut seen = 1;
    while next != 0 && seen < 64 {
        let Some((ifd, n)) = r.ifd(next) else { break };
        pending.extend(ifd.get(TAG_SUB_IFDS).unwrap_or(&[]).iter().map(|&o| o as usize));
        out.others.push(ifd);
        next = n;
        seen += 1;
    }
    while let Some(at) = pending.pop() {
        if seen >= 64 {
            break;
        }
        if let Some((ifd, _)) = r.ifd(at) {
            pending.extend(ifd.get(TAG_SUB_IFDS).unwrap_or(&[]).iter().map(|&o| o as usize));
            out.others.push(ifd);
        }
        seen += 1;
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn not_tiff_and_truncated_give_none() {
        assert!(parse(b"\x89PNG\r\n\x1a\n").is_none());
        assert!(parse(b"II*\0\x08\0\0\0\x05\0").is_none());
        assert!(parse(b"").is_none());
    }
}

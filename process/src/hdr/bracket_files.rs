//! A bracket on disk, read one frame at a time.
//!
//! [`Bracket`](super::bracket::Bracket) holds every frame decoded (18 frames
//! of 21 MP as `u16` codes are 2.3 GB). A [`BracketFiles`] knows its frames'
//! exposures from the command line, a list or EXIF (no pixel is decoded to
//! learn them), sorts them, and [`BracketFiles::scan`] decodes each frame
//! once, in ascending exposure, hands it to a [`FrameVisitor`] (the merge's
//! per-pixel sums, calibration's sampled pixels) and drops it. Every check
//! of [`Bracket::new`](super::bracket::Bracket::new) is made on the way
//! (sizes, depths, codes, times, brightness rising with time), and the
//! white points are found by [`WhitePointScan`], which keeps one byte per
//! sample of the previous frame. The next frame is decoded on its own
//! thread while the visitor works on this one, so a scan takes about as
//! long as decoding (a 7-frame 12 MP PNG bracket: the streamed merge 1.19×
//! decoding alone, against 2.0× one frame after another;
//! `bench/hdr/merge_stages.sh`); two decoded frames are held at a time.
//!
//! A frame's white point is decided only when the scan ends, so samples
//! that a pile-up may clip are set aside ([`PileUpSamples`]) and settled by
//! the visitor at [`FrameVisitor::finish`].

use std::path::PathBuf;

use super::HdrError;
use rayon::prelude::*;

use super::bracket::{check_codes, check_shape};
use super::bracket_list::{FrameRecord, TimeSource};
use super::exposure_metadata::{effective_times, read_exposure_metadata};
use super::image_file::read_frame_into;
use super::white_point::{WhitePoint, WhitePointScan, WhitePoints};
use crate::camera::image::CodeImage;

/// What a scan hands each frame to.
pub trait FrameVisitor {
    /// Frame `j` (by ascending exposure), its codes as decoded. `pile_up[c]`
    /// is the first code (below the largest) that the frame's white point in
    /// channel `c` may clip; whether it does is told at
    /// [`finish`](Self::finish).
    fn frame(&mut self, j: usize, image: &CodeImage, pile_up: [Option<u16>; 3]) -> Result<(), HdrError>;

    /// The white points of every frame (`[j][c]`), once all were seen.
    fn finish(&mut self, white_points: &[[Option<WhitePoint>; 3]]) -> Result<(), HdrError>;
}

/// The files of a bracket with their exposure times, sorted by time.
#[derive(Debug, Clone)]
pub struct BracketFiles {
    records: Vec<FrameRecord>,
}

impl BracketFiles {
    /// The files `paths` with the times given (`times_s`, one per file) or,
    /// with `None`, their EXIF effective times (t·ISO/N², see
    /// [`super::exposure_metadata`]). Only the EXIF is read. Times must be
    /// finite, positive and distinct.
    pub fn open(paths: &[PathBuf], times_s: Option<&[f64]>) -> Result<Self, HdrError> {
        if paths.is_empty() {
            return Err(HdrError::NoImages);
        }
        if let Some(t) = times_s
            && t.len() != paths.len()
        {
            return Err(HdrError::TimeCountMismatch {
                images: paths.len(),
                times: t.len(),
            });
        }
        let frames = paths
            .iter()
            .map(|p| Ok((p.clone(), read_exposure_metadata(p)?)))
            .collect::<Result<Vec<_>, HdrError>>()?;
        let (times, source) = match times_s {
            Some(t) => (t.to_vec(), TimeSource::Given),
            None => (effective_times(&frames)?, TimeSource::Exif),
        };
        let mut records: Vec<FrameRecord> = frames
            .into_iter()
            .zip(times)
            .map(|((path, metadata), time_s)| FrameRecord {
                path,
                metadata,
                time_s,
                source,
            })
            .collect();
        if let Some(r) = records.iter().find(|r| !(r.time_s.is_finite() && r.time_s > 0.0)) {
            return Err(HdrError::InvalidTime {
                image: r.path.display().to_string(),
                time_s: r.time_s,
            });
        }
        records.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
        if let Some(w) = records.windows(2).find(|w| w[0].time_s == w[1].time_s) {
            return Err(HdrError::DuplicateTime {
                first: w[0].path.display().to_string(),
                second: w[1].path.display().to_string(),
                time_s: w[0].time_s,
            });
        }
        Ok(Self { records })
    }

    /// The frames, shortest exposure first.
    pub fn records(&self) -> &[FrameRecord] {
        &self.records
    }

    /// The exposure times, ascending.
    pub fn times_s(&self) -> Vec<f64> {
        self.records.iter().map(|r| r.time_s).collect()
    }

    /// Number of frames.
    pub fn len(&self) -> usize {
        self.records.len()
    }

    /// Whether there is no frame (never, once opened).
    pub fn is_empty(&self) -> bool {
        self.records.is_empty()
    }

    /// Decodes each frame once, shortest exposure first, turned upright,
    /// checks it against the first (size, depth, codes) and the previous
    /// (brightness must not fall as time rises, as in
    /// [`Bracket::new`](super::bracket::Bracket::new)), and hands it to
    /// `visitor`; `progress(k)` after the `k`-th frame. Returns the white
    /// points (also given to the visitor).
    pub fn scan(&self, visitor: &mut dyn FrameVisitor, progress: &dyn Fn(usize)) -> Result<WhitePoints, HdrError> {
        // The next frame is decoded on its own thread while this one is
        // checked and visited: decoding (single-threaded in the image
        // codecs) then hides the visitor's parallel passes. A rendezvous
        // channel holds at most one decoded frame waiting, and the visited
        // frame's buffer goes back to the decoder for reuse.
        let (frames_tx, frames_rx) = std::sync::mpsc::sync_channel::<Result<(CodeImage, f64), HdrError>>(0);
        let (spare_tx, spare_rx) = std::sync::mpsc::channel::<CodeImage>();
        std::thread::scope(|scope| {
            let decoder = std::thread::Builder::new().name("frame decoder".into());
            let spawned = decoder.spawn_scoped(scope, move || {
                let mut bytes = Vec::new();
                for r in &self.records {
                    let mut image = spare_rx.try_recv().unwrap_or_else(|_| empty_image());
                    let t0 = std::time::Instant::now();
                    let decoded = read_frame_into(&r.path, &mut bytes, &mut image).map(|_| image);
                    let ok = decoded.is_ok();
                    if frames_tx
                        .send(decoded.map(|im| (im, t0.elapsed().as_secs_f64())))
                        .is_err()
                        || !ok
                    {
                        // The scan stopped (an error there or here).
                        return;
                    }
                }
            });
            if let Err(cause) = spawned {
                return Err(HdrError::Io {
                    path: "(frame decoder thread)".into(),
                    cause,
                });
            }
            // The receiver is dropped when this closure returns, before the
            // scope joins the decoder: a decoder waiting to hand over a frame
            // after an error here then stops instead of waiting forever.
            let frames_rx = frames_rx;
            self.visit_decoded(&frames_rx, &spare_tx, visitor, progress)
        })
    }

    /// The consuming half of [`scan`](Self::scan): checks each decoded
    /// frame, hands it to `visitor`, and returns its buffer.
    fn visit_decoded(
        &self,
        frames: &std::sync::mpsc::Receiver<Result<(CodeImage, f64), HdrError>>,
        spare: &std::sync::mpsc::Sender<CodeImage>,
        visitor: &mut dyn FrameVisitor,
        progress: &dyn Fn(usize),
    ) -> Result<WhitePoints, HdrError> {
        let mut first: Option<CodeImage> = None;
        let mut previous: Option<(String, f64, f64)> = None;
        let mut white = None;
        let (mut decode_s, mut visit_s) = (0.0, 0.0);
        let started = std::time::Instant::now();
        for (j, r) in self.records.iter().enumerate() {
            let (image, seconds) = frames.recv().map_err(|_| HdrError::NoImages)??;
            decode_s += seconds;
            let t0 = std::time::Instant::now();
            let shape = first.get_or_insert_with(|| CodeImage {
                width: image.width,
                height: image.height,
                bits: image.bits,
                data: Vec::new(),
                label: image.label.clone(),
            });
            check_shape(&image, shape)?;
            // One parallel pass for the mean and the range of the codes.
            let (sum, largest) = image
                .data
                .par_chunks(1 << 16)
                .map(|c| c.iter().fold((0u64, 0u16), |(s, m), &z| (s + u64::from(z), m.max(z))))
                .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1.max(b.1)));
            if largest > image.max_code() {
                check_codes(&image)?;
            }
            let mean = sum as f64 / image.data.len() as f64;
            let tol = 0.005 * f64::from(image.max_code());
            if let Some((label, t, m)) = &previous
                && *m > mean + tol
            {
                return Err(HdrError::TimesContradictBrightness {
                    brighter: label.clone(),
                    brighter_time_s: *t,
                    darker: image.label.clone(),
                    darker_time_s: r.time_s,
                });
            }
            previous = Some((image.label.clone(), r.time_s, mean));
            let scan = white.get_or_insert_with(|| WhitePointScan::new(self.records.len(), image.bits));
            let pile_up = scan.push(&image);
            visitor.frame(j, &image, pile_up)?;
            visit_s += t0.elapsed().as_secs_f64();
            // The decoder may have finished: then the buffer is just dropped.
            let _ = spare.send(image);
            progress(j + 1);
        }
        let white = white.map_or_else(Vec::new, WhitePointScan::finish);
        let t0 = std::time::Instant::now();
        visitor.finish(&white)?;
        tracing::debug!(
            frames = self.records.len(),
            decode_s = format!("{decode_s:.3}"),
            visit_s = format!("{visit_s:.3}"),
            finish_s = format!("{:.3}", t0.elapsed().as_secs_f64()),
            wall_s = format!("{:.3}", started.elapsed().as_secs_f64()),
            "bracket scanned (frames decoded on their own thread while the previous one was visited)"
        );
        Ok(white)
    }
}

/// A code image with no pixels, for a decoder to fill.
fn empty_image() -> CodeImage {
    CodeImage {
        width: 0,
        height: 0,
        bits: 8,
        data: Vec::new(),
        label: String::new(),
    }
}

/// The samples of each frame and channel that a pile-up may clip: pixel
/// index and code, set aside until the white points are known.
#[derive(Debug, Clone, Default)]
pub struct PileUpSamples {
    /// `[j][c]` → (pixel, code).
    held: Vec<[Vec<(u32, u16)>; 3]>,
}

impl PileUpSamples {
    /// Whether code `z` of a channel whose pile-up starts at `pile_up` waits
    /// for the white point (at or above the pile-up, below the largest code).
    #[inline(always)]
    pub fn waits(pile_up: Option<u16>, z: u16, max: u16) -> bool {
        pile_up.is_some_and(|k| z >= k && z < max)
    }

    /// Sets aside frame `j`'s samples that [`waits`](Self::waits).
    pub fn hold(&mut self, j: usize, image: &CodeImage, pile_up: [Option<u16>; 3]) {
        if self.held.len() <= j {
            self.held.resize_with(j + 1, Default::default);
        }
        let max = image.max_code();
        for (c, held) in self.held[j].iter_mut().enumerate() {
            if pile_up[c].is_none() {
                continue;
            }
            for (p, px) in image.data.chunks_exact(3).enumerate() {
                if Self::waits(pile_up[c], px[c], max) {
                    held.push((p as u32, px[c]));
                }
            }
        }
    }

    /// Frame `j`'s samples set aside in channel `c`.
    pub fn of(&self, j: usize, c: usize) -> &[(u32, u16)] {
        self.held.get(j).map_or(&[], |h| h[c].as_slice())
    }
}

/// A bracket written to PNG files for the tests of the streamed readers.
#[cfg(test)]
pub(super) mod fixture {
    use std::path::{Path, PathBuf};

    use crate::camera::image::CodeImage;
    use crate::camera::sensor::CameraModel;
    use crate::camera::test_chart::{SEVEN_STOP_TIMES_S, hdr_chart};
    use crate::hdr::image_file::write_png;

    /// The seven-stop chart (96 × 64, 8 bits) with two pile-ups: a "moon"
    /// whose green is clipped at 254 in every frame (confirmed), and a flat
    /// patch at 240 in red in the shortest frame that rises with exposure
    /// (not confirmed). Written to `dir` in reverse time order; returns the
    /// paths, their times and the images (in time order).
    pub fn written(dir: &Path) -> (Vec<PathBuf>, Vec<f64>, Vec<CodeImage>) {
        let cam = CameraModel::typical(8);
        let scene = hdr_chart(96, 64);
        let mut images: Vec<CodeImage> = SEVEN_STOP_TIMES_S
            .iter()
            .enumerate()
            .map(|(j, &t)| cam.photograph(&scene, t, j as u64))
            .collect();
        for (j, im) in images.iter_mut().enumerate() {
            for p in 0..400 {
                let (x, y) = (p % 20, p / 20);
                let moon = (y * 96 + x) * 3;
                im.data[moon] = im.data[moon].max(200);
                im.data[moon + 1] = 254;
                let patch = ((y + 30) * 96 + x + 60) * 3;
                im.data[patch] = if j == 0 { 240 } else { 255 };
            }
        }
        let mut paths = Vec::new();
        let mut times = Vec::new();
        for (j, im) in images.iter().enumerate().rev() {
            let p = dir.join(format!("f{j}.png"));
            write_png(im, &p).unwrap();
            paths.push(p);
            times.push(SEVEN_STOP_TIMES_S[j]);
        }
        for im in &mut images {
            im.label = String::new();
        }
        (paths, times, images)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hdr::image_file::write_png;

    /// Counts the frames it is handed; fails at frame `fail_at`, if any.
    struct Counting {
        seen: Vec<usize>,
        fail_at: Option<usize>,
        finished: bool,
    }

    impl FrameVisitor for Counting {
        fn frame(&mut self, j: usize, image: &CodeImage, _: [Option<u16>; 3]) -> Result<(), HdrError> {
            if self.fail_at == Some(j) {
                return Err(HdrError::BadImage {
                    image: image.label.clone(),
                    what: "refused by the test's visitor".into(),
                });
            }
            self.seen.push(j);
            Ok(())
        }

        fn finish(&mut self, _: &[[Option<WhitePoint>; 3]]) -> Result<(), HdrError> {
            self.finished = true;
            Ok(())
        }
    }

    fn counting(fail_at: Option<usize>) -> Counting {
        Counting {
            seen: Vec::new(),
            fail_at,
            finished: false,
        }
    }

    #[test]
    fn every_frame_is_visited_once_in_time_order() {
        let dir = tempfile::tempdir().unwrap();
        let (paths, times, images) = fixture::written(dir.path());
        let files = BracketFiles::open(&paths, Some(&times)).unwrap();
        let mut v = counting(None);
        let white = files.scan(&mut v, &|_| {}).unwrap();
        assert_eq!(v.seen, (0..7).collect::<Vec<_>>());
        assert!(v.finished);
        assert_eq!(white.len(), images.len());
    }

    /// A frame of another size in the middle of the bracket stops the scan
    /// there with the error naming it (the decoder, a frame ahead, stops
    /// too: the test would hang otherwise).
    #[test]
    fn a_frame_of_another_size_stops_the_scan_with_its_name() {
        let dir = tempfile::tempdir().unwrap();
        let (paths, times, images) = fixture::written(dir.path());
        // paths are in reverse time order: index 4 is the third shortest.
        let small = CodeImage {
            width: 48,
            height: 32,
            bits: 8,
            data: images[2].data[..48 * 32 * 3].to_vec(),
            label: String::new(),
        };
        write_png(&small, &paths[4]).unwrap();
        let files = BracketFiles::open(&paths, Some(&times)).unwrap();
        let mut v = counting(None);
        let e = files.scan(&mut v, &|_| {}).unwrap_err();
        assert!(
            matches!(
                e,
                HdrError::SizeMismatch {
                    width: 48,
                    height: 32,
                    ..
                }
            ),
            "{e}"
        );
        assert!(e.to_string().contains("f2.png"), "{e}");
        assert_eq!(v.seen, vec![0, 1]);
        assert!(!v.finished);
    }

    #[test]
    fn an_unreadable_frame_and_a_visitor_error_stop_the_scan() {
        let dir = tempfile::tempdir().unwrap();
        let (paths, times, _) = fixture::written(dir.path());
        let files = BracketFiles::open(&paths, Some(&times)).unwrap();
        let mut v = counting(Some(1));
        let e = files.scan(&mut v, &|_| {}).unwrap_err();
        assert!(e.to_string().contains("refused by the test's visitor"), "{e}");
        assert_eq!(v.seen, vec![0]);

        // The fifth frame by time cut to half its bytes after opening.
        let bytes = std::fs::read(&paths[2]).unwrap();
        std::fs::write(&paths[2], &bytes[..bytes.len() / 2]).unwrap();
        let mut v = counting(None);
        let e = files.scan(&mut v, &|_| {}).unwrap_err();
        assert!(e.to_string().contains("f4.png"), "{e}");
        assert_eq!(v.seen, vec![0, 1, 2, 3]);
    }
}

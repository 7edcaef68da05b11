//! Several registered scans, one at a time (thesis §2.3.2: the scans are
//! merged incrementally, so that memory holds one scan's points and
//! whatever the consumer keeps of the earlier ones, not all of them).
//!
//! # Interface
//!
//! [`ScanStream`] is an iterator of `Result<Scan, ReadError>` over the
//! files given, in order, and over each E57 file's scans in the file's
//! order. It holds at most one scan: an E57 file is opened again for each
//! of its scans and only that scan's points are decoded. A consumer (the
//! segmenter's incremental clustering) takes a scan, folds it into its
//! nodes, and drops it before asking for the next:
//!
//! ```no_run
//! # use std::path::PathBuf;
//! use campanile_scan::read::stream::ScanStream;
//! let mut points = 0;
//! for scan in ScanStream::new(vec![PathBuf::from("a.e57"), PathBuf::from("b.ply")]) {
//!     let scan = scan?; // the file, element and value on a bad file
//!     points += scan.len(); // fold the scan in, then let it go
//! }
//! # Ok::<(), campanile_scan::read::ReadError>(())
//! ```
//!
//! Scans are already registered (in the scene frame) when read; the stream
//! does not register them. After an error, the rest of that file is skipped
//! and the stream goes on with the next file.

use std::collections::VecDeque;
use std::path::PathBuf;

use super::{Format, ReadError};
use crate::cloud::Scan;

/// The scans of several files, one at a time.
#[derive(Debug)]
pub struct ScanStream {
    files: VecDeque<PathBuf>,
    /// The E57 file being read, its next scan and its scan count.
    e57: Option<(PathBuf, usize, usize)>,
}

impl ScanStream {
    /// A stream over the scans of `files`, in order.
    pub fn new(files: impl IntoIterator<Item = PathBuf>) -> ScanStream {
        ScanStream {
            files: files.into_iter().collect(),
            e57: None,
        }
    }
}

impl Iterator for ScanStream {
    type Item = Result<Scan, ReadError>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            if let Some((path, next, count)) = self.e57.take()
                && next < count
            {
                let scan = super::e57::read_one(&path, next);
                if scan.is_ok() {
                    self.e57 = Some((path, next + 1, count));
                }
                return Some(scan);
            }
            let path = self.files.pop_front()?;
            match Format::of(&path) {
                Ok(Format::E57) => match super::e57::scan_count(&path) {
                    Ok(count) => self.e57 = Some((path, 0, count)),
                    Err(e) => return Some(Err(e)),
                },
                Ok(_) => {
                    return Some(super::read_scan(&path).map(|mut scans| scans.remove(0)));
                }
                Err(e) => return Some(Err(e)),
            }
        }
    }
}

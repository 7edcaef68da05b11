//! The crash-safe session store: one directory per session, frames written
//! atomically and an append-only journal, resumable after a crash.
//!
//! # Layout
//!
//! ```text
//! SESSION/
//!   plan.ron, station.ron, scene.ron   the descriptions the session runs under (scene optional)
//!   provenance.json                    campanile version, creation time, calibration files and checksums
//!   journal.jsonl                      one JSON line per shot (done, late or missed), per pruning, per outage
//!   frames/<key>-<crc>.png             raw sensor codes, 16-bit RGB PNG, unscaled
//!   processed/products.ron             occurrences whose processed products exist (optional)
//! ```
//!
//! A `pruned` journal line ([`PrunedEntry`]) lists completed shots whose
//! frame files were deleted on purpose: they stay complete (never
//! retaken), resume and verify do not look for their files, and readers
//! leave them out of [`SessionReader::frames`]. The line is journaled
//! before the files are removed, so a crash in between leaves files that
//! resume removes as unjournaled.
//!
//! Journal lines ([`JournalEntry`]) carry the time, head pose asked for
//! and reached, exposure asked for and applied, gain, filter, lights,
//! temperature if known, lateness and notes ([`FrameMeta`]), and for a
//! frame its file, CRC-32C, size, bit depth and camera sequence number.
//!
//! # Write order
//!
//! Each frame is written to `frames/.<name>.tmp`, fsynced, renamed into
//! place and the directory fsynced; only then is its journal line appended
//! (one write of the whole line) and the journal fsynced. So after a crash
//! at any point a frame is either journaled and complete, or not journaled
//! (and [`SessionStore::resume`] removes its file, to be retaken).
//!
//! # Resume
//!
//! [`SessionStore::resume`] cuts a torn last journal line, removes
//! temporary files and unjournaled frames, checks every journaled frame's
//! checksum, and says what it did in a [`ResumeReport`]. The controller
//! then skips every key [`SessionStore::completed`] reports: nothing is
//! lost and nothing repeated. A journaled frame that is missing or damaged
//! is an error naming the file, never dropped.
//!
//! # Disk full
//!
//! A write that fails for lack of space is [`StoreError::DiskFull`], with
//! a message saying what to do; the temporary file is removed, nothing is
//! left at the final path, and the journal is exactly as before the shot.
//!
//! # Not done yet
//!
//! - Frames are PNG only (no TIFF), and PNG carries no `sBIT` chunk: the
//!   bit depth lives in the journal.
//! - `resume` reads every frame to check its checksum: on a session of
//!   many gigabytes that takes as long as reading them.
//! - The journal has no format version field yet.
//!
//! Storage goes through the [`Storage`] trait; [`FsStorage`] is the real
//! file system, and [`fault`] has storages that crash or fill up, for
//! tests.

mod checksum;
mod error;
pub mod fault;
mod frame_file;
mod journal;
mod key;
mod products;
mod reader;
mod report;
mod session;
mod snapshot;
mod storage;

pub use checksum::crc32c;
pub use error::{DiskFull, StoreError, is_disk_full};
pub use frame_file::{check_frame, decode_frame, decode_png, encode_png};
pub use journal::{
    FrameEntry, FrameMeta, JournalEntry, LightLevel, MissedEntry, OutageEntry, ParsedJournal, PoseDeg, PrunedEntry,
    ShotKind, parse_journal,
};
pub use key::{MAX_KEY_BYTES, check_key, frame_file_name, frame_file_name_as};
pub use products::{PROCESSED_DIR, PRODUCTS_FILE, ProcessedProducts, ProductsError, products_path};
pub use reader::SessionReader;
pub use report::{ResumeReport, TornLine, VerifyReport};
pub use session::{FRAMES_DIR, JOURNAL_FILE, SessionStore};
pub use snapshot::{
    CalibrationRef, PLAN_FILE, PROVENANCE_FILE, Provenance, SCENE_FILE, STATION_FILE, Snapshot, SourcePaths,
};
pub use storage::{AtomicWriteError, FsStorage, Storage, is_temp_name, write_atomic};

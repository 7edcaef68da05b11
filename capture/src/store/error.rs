//! What can go wrong in the session store, each error naming the file and
//! what was expected.

use std::io;
use std::path::PathBuf;
use thiserror::Error;

/// An error from the session store.
#[derive(Debug, Error)]
pub enum StoreError {
    /// An I/O operation failed (other than a full disk).
    #[error("{action} {}: {source}", path.display())]
    Io {
        /// What the store was doing ("writing", "renaming", …).
        action: &'static str,
        /// The file or directory.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: io::Error,
    },

    /// The disk (or quota) filled while writing. The store has stopped
    /// cleanly: no partial file at a final path, the journal as it was
    /// before the failed shot.
    #[error(transparent)]
    DiskFull(Box<DiskFull>),

    /// `create` was given a directory that already has files in it.
    #[error(
        "{} is not empty ({entries} entries): a new session needs an empty or absent directory \
         (to continue a session there, use `campanile capture --resume {}`)",
        dir.display(),
        dir.display()
    )]
    SessionExists {
        /// The directory.
        dir: PathBuf,
        /// How many entries it holds.
        entries: usize,
    },

    /// `resume` was given a directory that is not a (complete) session.
    #[error("{} is not a session directory: {} is missing", dir.display(), missing.display())]
    NotASession {
        /// The directory.
        dir: PathBuf,
        /// The file expected in it.
        missing: PathBuf,
    },

    /// A shot key that cannot be journaled or named as a file.
    #[error("invalid shot key {key:?}: {reason}")]
    InvalidKey {
        /// The key as given.
        key: String,
        /// What is wrong with it.
        reason: &'static str,
    },

    /// The shot was already recorded: a frame is never taken twice.
    #[error("shot {key:?} is already in the journal ({status}); it is not recorded again")]
    Duplicate {
        /// The key.
        key: String,
        /// "completed", or "missed in this run".
        status: &'static str,
    },

    /// A shot's frame cannot be pruned: it has none, or it is pruned already.
    #[error("the frame of shot {key:?} cannot be pruned: {reason}")]
    NotPrunable {
        /// The key.
        key: String,
        /// Why.
        reason: String,
    },

    /// Two different keys map to the same frame file name.
    #[error("shot keys {key:?} and {other:?} both map to the frame file {file}")]
    FileNameClash {
        /// The key being recorded.
        key: String,
        /// The key already journaled under that file name.
        other: String,
        /// The file name.
        file: String,
    },

    /// A frame from the camera that does not describe itself consistently.
    #[error("frame for shot {key:?} is malformed: {reason}")]
    BadFrame {
        /// The key.
        key: String,
        /// What is inconsistent.
        reason: String,
    },

    /// Shot metadata that cannot be journaled (a NaN, a negative
    /// exposure, a light level outside 0..=1).
    #[error("metadata for shot {key:?} is invalid: {reason}")]
    BadMeta {
        /// The key.
        key: String,
        /// Which field, its value and what was expected.
        reason: String,
    },

    /// A journal line that is complete but cannot be read.
    #[error("{}:{line}: {reason}", path.display())]
    JournalCorrupt {
        /// The journal.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What was expected.
        reason: String,
    },

    /// A journaled frame whose file is absent.
    #[error("frame file {} for shot {key:?} is in the journal but missing on disk", path.display())]
    MissingFrame {
        /// The key.
        key: String,
        /// The file expected.
        path: PathBuf,
    },

    /// A journaled frame whose bytes do not match the journal.
    #[error(
        "frame file {} for shot {key:?} is damaged: expected CRC-32C {expected:08x} over {expected_len} bytes, \
         found {actual:08x} over {actual_len} bytes",
        path.display()
    )]
    ChecksumMismatch {
        /// The key.
        key: String,
        /// The file.
        path: PathBuf,
        /// CRC-32C in the journal.
        expected: u32,
        /// CRC-32C of the file.
        actual: u32,
        /// Size in the journal.
        expected_len: u64,
        /// Size of the file.
        actual_len: u64,
    },

    /// A frame file that is not the 16-bit RGB PNG the journal describes.
    #[error("frame file {}: {reason}", path.display())]
    BadFrameFile {
        /// The file.
        path: PathBuf,
        /// What was expected.
        reason: String,
    },

    /// A snapshot file (plan, station, provenance) that cannot be read.
    #[error("snapshot {}: {reason}", path.display())]
    BadSnapshot {
        /// The file.
        path: PathBuf,
        /// What was expected.
        reason: String,
    },

    /// A failure left the session in a state only `resume` can repair
    /// (for example the journal could not be cut back after a failed
    /// append); the store refuses further writes.
    #[error(
        "the session {} needs repair after an earlier failure ({reason}); run `campanile capture --resume {}`",
        dir.display(),
        dir.display()
    )]
    NeedsResume {
        /// The session directory.
        dir: PathBuf,
        /// The earlier failure.
        reason: String,
    },
}

/// Where and how the disk filled ([`StoreError::DiskFull`]).
#[derive(Debug, Error)]
#[error(
    "disk full while writing {what} for shot {key:?} to {}; the session {} is intact up to {} \
     ({frames} frames journaled); free space and run `campanile capture --resume {}`",
    path.display(),
    session.display(),
    match last_completed { Some(k) => format!("shot {k:?}"), None => "its start".to_string() },
    session.display()
)]
pub struct DiskFull {
    /// What was being written ("frame", "journal line").
    pub what: &'static str,
    /// The shot being recorded.
    pub key: String,
    /// The file being written.
    pub path: PathBuf,
    /// The session directory.
    pub session: PathBuf,
    /// The last shot journaled, if any.
    pub last_completed: Option<String>,
    /// Frames journaled so far.
    pub frames: usize,
    /// The underlying error (`StorageFull`, `ENOSPC` or `EDQUOT`).
    #[source]
    pub source: io::Error,
}

/// Whether an I/O error means the disk or quota is full (`StorageFull`,
/// `QuotaExceeded`, or raw `ENOSPC` = 28 / `EDQUOT` = 122 on Linux).
pub fn is_disk_full(e: &io::Error) -> bool {
    matches!(e.kind(), io::ErrorKind::StorageFull | io::ErrorKind::QuotaExceeded)
        || matches!(e.raw_os_error(), Some(28) | Some(122))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn enospc_and_storage_full_are_disk_full() {
        assert!(is_disk_full(&io::Error::from_raw_os_error(28)));
        assert!(is_disk_full(&io::Error::new(io::ErrorKind::StorageFull, "quota")));
        assert!(!is_disk_full(&io::Error::new(io::ErrorKind::PermissionDenied, "no")));
    }
}

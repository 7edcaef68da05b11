//! Read-only access to a session, for processing: the snapshot, the
//! journal and the frames, changing nothing on disk.
//!
//! Unlike [`SessionStore::resume`](super::SessionStore::resume), a reader
//! repairs nothing. A torn last journal line (a capture that crashed, or is
//! still running) is left alone and counted in [`SessionReader::torn_bytes`];
//! its frame is simply not in the session yet.

use std::path::{Path, PathBuf};

use super::error::StoreError;
use super::frame_file::read_checked_frame;
use super::journal::{FrameEntry, JournalEntry, parse_journal};
use super::session::{FRAMES_DIR, JOURNAL_FILE};
use super::snapshot::Snapshot;
use super::storage::{FsStorage, Storage};
use campanile_process::camera::image::CodeImage;

/// A session directory opened for reading.
#[derive(Debug)]
pub struct SessionReader {
    dir: PathBuf,
    snapshot: Snapshot,
    entries: Vec<JournalEntry>,
    torn_bytes: u64,
}

impl SessionReader {
    /// Opens the session in `dir`: reads its snapshot and journal. A journal
    /// line that is not an entry is [`StoreError::JournalCorrupt`] naming it.
    pub fn open(dir: &Path) -> Result<SessionReader, StoreError> {
        let storage = FsStorage;
        let journal = dir.join(JOURNAL_FILE);
        let bytes = match storage.read(&journal) {
            Ok(b) => b,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                return Err(StoreError::NotASession {
                    dir: dir.to_path_buf(),
                    missing: journal,
                });
            }
            Err(source) => {
                return Err(StoreError::Io {
                    action: "reading",
                    path: journal,
                    source,
                });
            }
        };
        let snapshot = Snapshot::read(&storage, dir)?;
        let parsed = parse_journal(&journal, &bytes)?;
        Ok(SessionReader {
            dir: dir.to_path_buf(),
            snapshot,
            entries: parsed.entries,
            torn_bytes: parsed.torn_len,
        })
    }

    /// The session directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The plan, station and scene the session was captured under.
    pub fn snapshot(&self) -> &Snapshot {
        &self.snapshot
    }

    /// Every journal line, in order.
    pub fn entries(&self) -> &[JournalEntry] {
        &self.entries
    }

    /// The journaled frames still on disk, in order (done and late; frames
    /// deleted on purpose by a `pruned` line are left out).
    pub fn frames(&self) -> impl Iterator<Item = &FrameEntry> {
        let pruned = self.pruned_keys();
        self.entries
            .iter()
            .filter_map(JournalEntry::frame)
            .filter(move |f| !pruned.contains(f.key.as_str()))
    }

    /// The keys of completed shots whose frames were deleted on purpose.
    pub fn pruned_keys(&self) -> std::collections::HashSet<&str> {
        self.entries
            .iter()
            .filter_map(|e| match e {
                JournalEntry::Pruned(p) => Some(p.keys.iter().map(String::as_str)),
                _ => None,
            })
            .flatten()
            .collect()
    }

    /// Bytes of a torn last journal line (0 if none).
    pub fn torn_bytes(&self) -> u64 {
        self.torn_bytes
    }

    /// The codes of a journaled frame, after checking its size and CRC-32C.
    pub fn read_frame(&self, entry: &FrameEntry) -> Result<CodeImage, StoreError> {
        let path = self.dir.join(&entry.file);
        if !entry.file.starts_with(&format!("{FRAMES_DIR}/")) || entry.file.contains("..") {
            return Err(StoreError::BadFrameFile {
                path,
                reason: format!(
                    "the journal names {:?}, expected a file under {FRAMES_DIR}/",
                    entry.file
                ),
            });
        }
        read_checked_frame(&FsStorage, &path, entry)
    }
}

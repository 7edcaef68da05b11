//! The session store: one directory per session, frames written
//! atomically and an append-only journal, resumable after a crash.

use super::checksum::crc32c;
use super::error::{DiskFull, StoreError, is_disk_full};
use super::frame_file::{check_frame, encode_png, read_checked_bytes, read_checked_frame};
use super::journal::{FrameEntry, FrameMeta, JournalEntry, MissedEntry, OutageEntry, PrunedEntry, parse_journal};
use super::key::{check_key, frame_file_name_as};
use super::report::{ResumeReport, TornLine, VerifyReport};
use super::snapshot::{PLAN_FILE, PROVENANCE_FILE, SCENE_FILE, STATION_FILE, Snapshot};
use super::storage::{AtomicWriteError, FsStorage, Storage, is_temp_name, write_atomic};
use crate::device::{Frame, FrameFormat};
use campanile_process::camera::image::CodeImage;
use chrono::{DateTime, Utc};
use std::collections::{HashMap, HashSet};
use std::io;
use std::path::{Path, PathBuf};

/// File name of the journal.
pub const JOURNAL_FILE: &str = "journal.jsonl";
/// Name of the frames directory.
pub const FRAMES_DIR: &str = "frames";

/// A session directory open for recording.
///
/// Every shot key has at most one frame line (`done` or `late`) and at
/// most one `missed` line, and no line after its frame: the journal holds
/// at most one `missed` line per shot however often the session is
/// resumed.
///
/// **Missed shots.** A key recorded missed is final *for the run* (this
/// `SessionStore` value): [`SessionStore::record_frame`] and
/// [`SessionStore::record_missed`] refuse it with
/// [`StoreError::Duplicate`]. A later run (after [`SessionStore::resume`])
/// may retake it: [`SessionStore::missed`] tells the controller it was
/// missed, and a frame recorded for it then appears as a later journal
/// line, after the `missed` line, so the journal keeps both facts. If the
/// later run misses it again, [`SessionStore::record_missed`] writes no
/// second line: the first `missed` line (its time and reason) stands. A
/// completed key is final for the session.
#[derive(Debug)]
pub struct SessionStore<S: Storage = FsStorage> {
    storage: S,
    dir: PathBuf,
    snapshot: Snapshot,
    entries: Vec<JournalEntry>,
    /// Completed key → index in `entries`.
    done: HashMap<String, usize>,
    /// Frame file name → key.
    files: HashMap<String, String>,
    /// Keys with a `missed` line and no frame since.
    missed: HashSet<String>,
    /// Keys recorded missed by this run.
    missed_this_run: HashSet<String>,
    /// Completed keys whose frame files were deleted on purpose.
    pruned: HashSet<String>,
    /// Journal length in bytes (all complete lines).
    journal_len: u64,
    /// Set when a failure left the directory needing `resume`.
    broken: Option<String>,
    /// Made by `create` (whether the directory existed before); `None`
    /// when resumed.
    created: Option<bool>,
}

impl SessionStore<FsStorage> {
    /// Start a new session in `dir` (created if absent; refused if it has
    /// any entry), writing the snapshot and an empty journal.
    pub fn create(dir: &Path, snapshot: Snapshot) -> Result<Self, StoreError> {
        Self::create_with(FsStorage, dir, snapshot)
    }

    /// Open the session in `dir` after a crash or a stop: repair what a
    /// crash can leave (see [`SessionStore::resume_with`]).
    pub fn resume(dir: &Path) -> Result<(Self, ResumeReport), StoreError> {
        Self::resume_with(FsStorage, dir)
    }
}

impl<S: Storage> SessionStore<S> {
    /// [`SessionStore::create`] on any storage.
    ///
    /// The snapshot files are written atomically first and the empty
    /// journal last, so a directory with a journal always has its
    /// snapshot. A failure during `create` (a full disk) removes what it
    /// made, leaving the directory as it was (absent or empty). A crash
    /// during `create` leaves a directory that `create` refuses and
    /// `resume` does not accept; remove it and start again.
    pub fn create_with(storage: S, dir: &Path, snapshot: Snapshot) -> Result<Self, StoreError> {
        let listing = storage.list(dir).map_err(io_error("listing", dir))?;
        if let Some(names) = &listing
            && !names.is_empty()
        {
            return Err(StoreError::SessionExists {
                dir: dir.to_path_buf(),
                entries: names.len(),
            });
        }
        let existed = listing.is_some();
        if let Err(e) = lay_out(&storage, dir, &snapshot) {
            // A failure (not a crash) undoes what was made, so the
            // directory is as it was and `create` accepts it again.
            if let Err(undo) = undo_create(&storage, dir, existed) {
                tracing::warn!(dir = %dir.display(), error = %undo, "could not remove the unfinished session");
            }
            return Err(e);
        }
        Ok(Self {
            storage,
            dir: dir.to_path_buf(),
            snapshot,
            entries: Vec::new(),
            done: HashMap::new(),
            files: HashMap::new(),
            missed: HashSet::new(),
            missed_this_run: HashSet::new(),
            pruned: HashSet::new(),
            journal_len: 0,
            broken: None,
            created: Some(existed),
        })
    }

    /// Remove a session this value created and never recorded in (an
    /// empty journal, no frames), leaving its directory as it was before
    /// [`SessionStore::create`]: absent, or empty. For a run that could not
    /// start. Returns whether it removed the session; a resumed session,
    /// or one with journal lines, is kept.
    pub fn discard_unused(self) -> Result<bool, StoreError> {
        let Some(existed) = self.created else {
            return Ok(false);
        };
        if !self.entries.is_empty() || self.journal_len > 0 || self.broken.is_some() {
            return Ok(false);
        }
        undo_create(&self.storage, &self.dir, existed).map_err(io_error("removing the unused session", &self.dir))?;
        Ok(true)
    }

    /// [`SessionStore::resume`] on any storage.
    ///
    /// In order: reads the snapshot and the journal (a complete line that
    /// is not a journal entry, or a key completed twice, is
    /// [`StoreError::JournalCorrupt`]); removes temporary files; cuts a
    /// torn last line back to the last complete one; removes frame files
    /// that are not journaled (their shots will be retaken); and checks
    /// that every journaled frame is present with its journaled size and
    /// CRC-32C ([`StoreError::MissingFrame`], [`StoreError::ChecksumMismatch`]).
    /// Every repair is listed in the [`ResumeReport`]. Running it again
    /// after a crash during it is safe.
    pub fn resume_with(storage: S, dir: &Path) -> Result<(Self, ResumeReport), StoreError> {
        let io_err = |action, path: &Path| {
            let path = path.to_path_buf();
            move |source| StoreError::Io { action, path, source }
        };
        let journal = dir.join(JOURNAL_FILE);
        let journal_bytes = match storage.read(&journal) {
            Ok(b) => b,
            Err(e) if e.kind() == io::ErrorKind::NotFound => {
                return Err(StoreError::NotASession {
                    dir: dir.to_path_buf(),
                    missing: journal,
                });
            }
            Err(e) => return Err(io_err("reading", &journal)(e)),
        };
        let snapshot = Snapshot::read(&storage, dir)?;
        let parsed = parse_journal(&journal, &journal_bytes)?;

        let mut store = Self {
            storage,
            dir: dir.to_path_buf(),
            snapshot,
            entries: Vec::new(),
            done: HashMap::new(),
            files: HashMap::new(),
            missed: HashSet::new(),
            missed_this_run: HashSet::new(),
            pruned: HashSet::new(),
            journal_len: parsed.complete_len,
            broken: None,
            created: None,
        };
        for (i, entry) in parsed.entries.into_iter().enumerate() {
            store.admit(entry).map_err(|reason| StoreError::JournalCorrupt {
                path: journal.clone(),
                line: i + 1,
                reason,
            })?;
        }

        let mut report = ResumeReport::default();
        let frames = dir.join(FRAMES_DIR);
        let s = &store.storage;

        // Temporary files, in the session directory and the frames one.
        for d in [dir, frames.as_path()] {
            let names = s.list(d).map_err(io_err("listing", d))?.unwrap_or_default();
            let mut removed = false;
            for name in names.iter().filter(|n| is_temp_name(n)) {
                let p = d.join(name);
                s.remove(&p).map_err(io_err("removing temporary file", &p))?;
                report.temp_files_removed.push(p);
                removed = true;
            }
            if removed {
                s.sync_dir(d).map_err(io_err("fsyncing directory", d))?;
            }
        }

        // A torn last line.
        if parsed.torn_len > 0 {
            s.truncate(&journal, parsed.complete_len)
                .map_err(io_err("cutting the torn last line of", &journal))?;
            s.sync_file(&journal).map_err(io_err("fsyncing", &journal))?;
            report.torn_line = Some(TornLine {
                offset: parsed.complete_len,
                bytes: parsed.torn_len,
            });
        }

        // Frame files not in the journal.
        let names = match s.list(&frames).map_err(io_err("listing", &frames))? {
            Some(names) => names,
            None => {
                s.create_dir_all(&frames)
                    .map_err(io_err("creating directory", &frames))?;
                Vec::new()
            }
        };
        let mut removed = false;
        for name in names {
            if store.files.contains_key(&name) || is_temp_name(&name) {
                continue;
            }
            let p = frames.join(&name);
            if FrameFormat::ALL
                .iter()
                .any(|f| name.ends_with(&format!(".{}", f.extension())))
            {
                s.remove(&p).map_err(io_err("removing unjournaled frame", &p))?;
                report.orphan_frames_removed.push(p);
                removed = true;
            } else {
                report.unknown_files.push(p);
            }
        }
        if removed {
            s.sync_dir(&frames).map_err(io_err("fsyncing directory", &frames))?;
        }

        // Every journaled frame present and intact (pruned ones are gone on purpose).
        for entry in store.entries.iter().filter_map(JournalEntry::frame) {
            if !store.pruned.contains(&entry.key) {
                store.frame_bytes(entry)?;
            }
        }
        report.frames = store.done.len();
        report.missed = store.missed.len();
        report.last_key = store.entries.last().map(|e| e.key().to_string());
        Ok((store, report))
    }

    /// Take a journal entry read back into the in-memory state; the
    /// problem, if it contradicts earlier lines.
    fn admit(&mut self, entry: JournalEntry) -> Result<(), String> {
        if let JournalEntry::Pruned(p) = &entry {
            for key in &p.keys {
                self.check_prunable(key)?;
            }
            for key in &p.keys {
                self.forget_file(key);
            }
        }
        if matches!(entry, JournalEntry::Pruned(_) | JournalEntry::Outage(_)) {
            self.entries.push(entry);
            return Ok(());
        }
        let key = entry.key().to_string();
        if self.done.contains_key(&key) {
            return Err(format!("shot {key:?} appears again after it was completed"));
        }
        match &entry {
            JournalEntry::Done(f) | JournalEntry::Late(f) => {
                let name = f
                    .file
                    .strip_prefix(&format!("{FRAMES_DIR}/"))
                    .filter(|n| !n.contains(['/', '\\']) && !n.is_empty() && !n.starts_with('.'))
                    .ok_or_else(|| format!("frame file {:?} is not a plain name under {FRAMES_DIR}/", f.file))?;
                if let Some(other) = self.files.insert(name.to_string(), key.clone()) {
                    return Err(format!(
                        "frame file {:?} is journaled for both {other:?} and {key:?}",
                        f.file
                    ));
                }
                self.missed.remove(&key);
                self.done.insert(key, self.entries.len());
            }
            JournalEntry::Missed(_) => {
                self.missed.insert(key);
            }
            JournalEntry::Pruned(_) | JournalEntry::Outage(_) => {}
        }
        self.entries.push(entry);
        Ok(())
    }

    /// Why `key`'s frame cannot be pruned, if it cannot: it must be
    /// completed and not pruned already.
    fn check_prunable(&self, key: &str) -> Result<(), String> {
        if !self.done.contains_key(key) {
            return Err(format!("pruned shot {key:?} has no journaled frame before"));
        }
        if self.pruned.contains(key) {
            return Err(format!("shot {key:?} is pruned twice"));
        }
        Ok(())
    }

    /// Mark `key`'s frame pruned: its file is no longer the session's.
    fn forget_file(&mut self, key: &str) {
        if let Some(name) = self
            .frame_entry(key)
            .and_then(|f| f.file.strip_prefix(&format!("{FRAMES_DIR}/")))
            .map(str::to_owned)
        {
            self.files.remove(&name);
        }
        self.pruned.insert(key.to_string());
    }

    /// The session directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The snapshot the session was created with.
    pub fn snapshot(&self) -> &Snapshot {
        &self.snapshot
    }

    /// Every journal line, in order.
    pub fn entries(&self) -> &[JournalEntry] {
        &self.entries
    }

    /// Whether `key` has a frame in the journal (never to be taken again).
    pub fn completed(&self, key: &str) -> bool {
        self.done.contains_key(key)
    }

    /// Whether `key` was recorded missed and has no frame since (in this
    /// run or an earlier one).
    pub fn missed(&self, key: &str) -> bool {
        self.missed.contains(key)
    }

    /// Whether `key` was recorded missed by this run (so it is final until
    /// the next resume).
    pub fn missed_in_this_run(&self, key: &str) -> bool {
        self.missed_this_run.contains(key)
    }

    /// Whether `key`'s frame was deleted on purpose (a `pruned` line);
    /// the shot stays completed.
    pub fn pruned(&self, key: &str) -> bool {
        self.pruned.contains(key)
    }

    /// The journaled frame for `key`, if completed and not pruned.
    pub fn frame_entry(&self, key: &str) -> Option<&FrameEntry> {
        if self.pruned.contains(key) {
            return None;
        }
        self.done
            .get(key)
            .and_then(|&i| self.entries.get(i))
            .and_then(JournalEntry::frame)
    }

    /// The storage the store writes through.
    pub fn storage(&self) -> &S {
        &self.storage
    }

    /// The path of a journaled frame's file.
    pub fn frame_path(&self, entry: &FrameEntry) -> PathBuf {
        self.dir.join(&entry.file)
    }

    /// Record a frame: checks the key (not completed, not missed in this
    /// run), the frame and the metadata; writes the camera's file as
    /// delivered (`frame.file`: JPEG, DNG; its first bytes checked against
    /// its format), or else the codes as a 16-bit RGB PNG, via a temporary
    /// file, fsync, rename and directory fsync; then
    /// appends one journal line (`late` if `meta.late_by_s` is set, else
    /// `done`) and fsyncs the journal. Returns the entry journaled.
    ///
    /// On any failure the session is left as before the call: no file at
    /// the frame's final path and the journal unchanged (a failed append
    /// is cut back and the frame file removed). A full disk is
    /// [`StoreError::DiskFull`]. If even that clean-up fails, the store
    /// refuses further writes with [`StoreError::NeedsResume`].
    pub fn record_frame(&mut self, key: &str, meta: &FrameMeta, frame: &Frame) -> Result<JournalEntry, StoreError> {
        self.check_writable()?;
        self.check_new_key(key)?;
        if let Some(reason) = meta.problem() {
            return Err(StoreError::BadMeta {
                key: key.to_string(),
                reason,
            });
        }
        check_frame(key, frame)?;
        let format = frame.file.as_ref().map_or(FrameFormat::Png, |f| f.format);
        if let Some(file) = &frame.file
            && let Some(reason) = file.format.signature_problem(&file.bytes)
        {
            return Err(StoreError::BadFrame {
                key: key.to_string(),
                reason: format!("the camera's file: {reason}"),
            });
        }
        let name = frame_file_name_as(key, format);
        if let Some(other) = self.files.get(&name) {
            return Err(StoreError::FileNameClash {
                key: key.to_string(),
                other: other.clone(),
                file: name,
            });
        }
        // A camera's file is kept as delivered; decoded codes become a PNG.
        let encoded;
        let bytes: &[u8] = match &frame.file {
            Some(file) => &file.bytes,
            None => {
                encoded = encode_png(key, frame)?;
                &encoded
            }
        };
        let frames = self.dir.join(FRAMES_DIR);
        let target = frames.join(&name);
        if let Err(e) = write_atomic(&self.storage, &frames, &name, bytes) {
            return Err(if is_disk_full(&e.source) {
                self.disk_full("frame", key, target, e.source)
            } else {
                atomic_io_error(e)
            });
        }
        let entry = FrameEntry {
            key: key.to_string(),
            file: format!("{FRAMES_DIR}/{name}"),
            format,
            crc32c: crc32c(bytes),
            bytes: bytes.len() as u64,
            // check_frame has bounded both by u32.
            width: u32::try_from(frame.width).unwrap_or(u32::MAX),
            height: u32::try_from(frame.height).unwrap_or(u32::MAX),
            bits: frame.bits,
            sequence: frame.sequence,
            meta: meta.clone(),
        };
        let entry = if meta.late_by_s.is_some() {
            JournalEntry::Late(entry)
        } else {
            JournalEntry::Done(entry)
        };
        self.append(&entry, Some(&target))?;
        self.files.insert(name, key.to_string());
        self.missed.remove(key);
        self.done.insert(key.to_string(), self.entries.len());
        self.entries.push(entry.clone());
        Ok(entry)
    }

    /// Record that the shot `key` was not taken, at `time`, and why: one
    /// journal line with status `missed`. Refused for a completed key, or
    /// one already missed in this run ([`StoreError::Duplicate`]). A key
    /// already journaled missed by an earlier run gets no second line: it
    /// is marked missed in this run and its first line, returned, stands.
    pub fn record_missed(&mut self, key: &str, reason: &str, time: DateTime<Utc>) -> Result<JournalEntry, StoreError> {
        self.check_writable()?;
        self.check_new_key(key)?;
        if self.missed.contains(key)
            && let Some(first) = self
                .entries
                .iter()
                .find(|e| matches!(e, JournalEntry::Missed(m) if m.key == key))
        {
            let first = first.clone();
            self.missed_this_run.insert(key.to_string());
            return Ok(first);
        }
        let entry = JournalEntry::Missed(MissedEntry {
            key: key.to_string(),
            time,
            reason: reason.to_string(),
        });
        self.append(&entry, None)?;
        self.missed.insert(key.to_string());
        self.missed_this_run.insert(key.to_string());
        self.entries.push(entry.clone());
        Ok(entry)
    }

    /// Delete the frame files of the completed shots `keys` on purpose,
    /// at `time`, for `reason`: one journal line with status `pruned`
    /// (keys, bytes freed, reason), then the files are removed and the
    /// frames directory fsynced. The shots stay completed. Refused
    /// ([`StoreError::NotPrunable`]) for a key without a frame, already
    /// pruned or listed twice; nothing is journaled then.
    ///
    /// The line is journaled first: after a crash before the files are
    /// gone, [`SessionStore::resume`] removes them as unjournaled frames.
    /// A file that cannot be removed is logged and left (resume removes
    /// it); the line stands.
    pub fn record_pruned(
        &mut self,
        keys: &[String],
        reason: &str,
        time: DateTime<Utc>,
    ) -> Result<JournalEntry, StoreError> {
        self.check_writable()?;
        let mut bytes = 0;
        let mut seen = HashSet::new();
        for key in keys {
            let listed_twice = !seen.insert(key.as_str());
            let problem = self
                .check_prunable(key)
                .err()
                .or_else(|| listed_twice.then(|| "it is listed twice".to_owned()));
            if let Some(reason) = problem {
                return Err(StoreError::NotPrunable {
                    key: key.clone(),
                    reason,
                });
            }
            bytes += self.frame_entry(key).map_or(0, |f| f.bytes);
        }
        let files: Vec<PathBuf> = keys
            .iter()
            .filter_map(|k| self.frame_entry(k))
            .map(|f| self.frame_path(f))
            .collect();
        let entry = JournalEntry::Pruned(PrunedEntry {
            time,
            keys: keys.to_vec(),
            bytes,
            reason: reason.to_string(),
        });
        self.append(&entry, None)?;
        for key in keys {
            self.forget_file(key);
        }
        self.entries.push(entry.clone());
        for f in &files {
            if let Err(e) = self.storage.remove(f)
                && e.kind() != io::ErrorKind::NotFound
            {
                tracing::warn!(file = %f.display(), error = %e, "could not remove a pruned frame; resume will");
            }
        }
        let frames = self.dir.join(FRAMES_DIR);
        if let Err(e) = self.storage.sync_dir(&frames) {
            tracing::warn!(dir = %frames.display(), error = %e, "fsyncing after pruning failed");
        }
        Ok(entry)
    }

    /// Record that `device` was down from `start` to `end` (`open`: still
    /// down when the run stopped at `end`): one journal line with status
    /// `outage`.
    pub fn record_outage(
        &mut self,
        device: &str,
        start: DateTime<Utc>,
        end: DateTime<Utc>,
        open: bool,
    ) -> Result<JournalEntry, StoreError> {
        self.check_writable()?;
        let entry = JournalEntry::Outage(OutageEntry {
            device: device.to_string(),
            start,
            end,
            open,
        });
        self.append(&entry, None)?;
        self.entries.push(entry.clone());
        Ok(entry)
    }

    /// Re-read every journaled frame: its size, CRC-32C, and that it
    /// decodes by its format (a 16-bit RGB PNG, a JPEG, a DNG) to the
    /// journaled size. Damaged or
    /// missing frames are listed in the report; only a failure to read
    /// (other than a missing file) is an error.
    pub fn verify(&self) -> Result<VerifyReport, StoreError> {
        let mut report = VerifyReport::default();
        for entry in self.entries.iter().filter_map(JournalEntry::frame) {
            if self.pruned.contains(&entry.key) {
                report.frames_pruned += 1;
                continue;
            }
            report.frames_checked += 1;
            match self.read_frame(entry) {
                Ok(_) => report.bytes_checked += entry.bytes,
                Err(e @ StoreError::Io { .. }) => return Err(e),
                Err(problem) => report.problems.push(problem),
            }
        }
        Ok(report)
    }

    /// The codes of a journaled frame, decoded by its format (see
    /// [`decode_frame`](super::decode_frame)), after checking
    /// its checksum.
    pub fn read_frame(&self, entry: &FrameEntry) -> Result<CodeImage, StoreError> {
        read_checked_frame(&self.storage, &self.frame_path(entry), entry)
    }

    /// A journaled frame's bytes, checked against its size and CRC-32C.
    fn frame_bytes(&self, entry: &FrameEntry) -> Result<Vec<u8>, StoreError> {
        read_checked_bytes(&self.storage, &self.frame_path(entry), entry)
    }

    fn check_writable(&self) -> Result<(), StoreError> {
        match &self.broken {
            Some(reason) => Err(StoreError::NeedsResume {
                dir: self.dir.clone(),
                reason: reason.clone(),
            }),
            None => Ok(()),
        }
    }

    fn check_new_key(&self, key: &str) -> Result<(), StoreError> {
        check_key(key)?;
        let status = if self.done.contains_key(key) {
            "completed"
        } else if self.missed_this_run.contains(key) {
            "missed in this run"
        } else {
            return Ok(());
        };
        Err(StoreError::Duplicate {
            key: key.to_string(),
            status,
        })
    }

    /// Append `entry`'s line and fsync the journal; on failure cut the
    /// journal back, remove `frame` (the file just renamed into place) and
    /// report.
    fn append(&mut self, entry: &JournalEntry, frame: Option<&Path>) -> Result<(), StoreError> {
        let journal = self.dir.join(JOURNAL_FILE);
        let line = entry.to_line();
        let result = self
            .storage
            .append(&journal, &line)
            .map_err(|e| ("appending to", e))
            .and_then(|()| self.storage.sync_file(&journal).map_err(|e| ("fsyncing", e)));
        let (action, source) = match result {
            Ok(()) => {
                self.journal_len += line.len() as u64;
                return Ok(());
            }
            Err(e) => e,
        };
        self.roll_back(&journal, frame, &source);
        Err(if is_disk_full(&source) {
            self.disk_full("journal line", entry.key(), journal, source)
        } else {
            StoreError::Io {
                action,
                path: journal,
                source,
            }
        })
    }

    /// Put the journal back to its last complete line and remove `frame`;
    /// if that fails, mark the store as needing `resume`.
    fn roll_back(&mut self, journal: &Path, frame: Option<&Path>, cause: &io::Error) {
        let s = &self.storage;
        let journal_back = s
            .truncate(journal, self.journal_len)
            .and_then(|()| s.sync_file(journal));
        let frame_gone = match frame {
            Some(f) => s.remove(f).and_then(|()| match f.parent() {
                Some(d) => s.sync_dir(d),
                None => Ok(()),
            }),
            None => Ok(()),
        };
        if let Err(e) = journal_back.and(frame_gone) {
            self.broken = Some(format!("journal append failed ({cause}) and could not be undone ({e})"));
        }
    }

    fn disk_full(&self, what: &'static str, key: &str, path: PathBuf, source: io::Error) -> StoreError {
        StoreError::DiskFull(Box::new(DiskFull {
            what,
            key: key.to_string(),
            path,
            session: self.dir.clone(),
            last_completed: self.entries.last().map(|e| e.key().to_string()),
            frames: self.done.len(),
            source,
        }))
    }
}

#[cfg(test)]
#[path = "session_tests.rs"]
mod tests;

#[cfg(test)]
#[path = "camera_file_tests.rs"]
mod camera_file_tests;

fn io_error(action: &'static str, path: &Path) -> impl FnOnce(io::Error) -> StoreError {
    let path = path.to_path_buf();
    move |source| StoreError::Io { action, path, source }
}

/// Make a new session's files in `dir` (empty or absent): the frames
/// directory, the snapshot, then the empty journal.
fn lay_out<S: Storage>(storage: &S, dir: &Path, snapshot: &Snapshot) -> Result<(), StoreError> {
    let frames = dir.join(FRAMES_DIR);
    storage
        .create_dir_all(&frames)
        .map_err(io_error("creating directory", &frames))?;
    storage.sync_dir(dir).map_err(io_error("fsyncing directory", dir))?;
    if let Some(parent) = dir.parent().filter(|p| !p.as_os_str().is_empty()) {
        storage
            .sync_dir(parent)
            .map_err(io_error("fsyncing directory", parent))?;
    }
    for (name, bytes) in snapshot.files() {
        write_atomic(storage, dir, name, &bytes).map_err(atomic_io_error)?;
    }
    write_atomic(storage, dir, JOURNAL_FILE, b"").map_err(atomic_io_error)?;
    Ok(())
}

/// Remove what [`lay_out`] makes in `dir` (which held nothing before, and
/// did not exist unless `existed`): the journal, the snapshot files and
/// temporary files, the empty frames directory, and `dir` itself if it was
/// made. Anything else stays (and keeps `dir`).
fn undo_create<S: Storage>(storage: &S, dir: &Path, existed: bool) -> io::Result<()> {
    let ours = [JOURNAL_FILE, PLAN_FILE, STATION_FILE, SCENE_FILE, PROVENANCE_FILE];
    let frames = dir.join(FRAMES_DIR);
    if let Some(names) = storage.list(&frames)? {
        for name in names.iter().filter(|n| is_temp_name(n)) {
            storage.remove(&frames.join(name))?;
        }
        storage.remove_dir(&frames)?;
    }
    for name in storage.list(dir)?.unwrap_or_default() {
        if ours.contains(&name.as_str()) || is_temp_name(&name) {
            storage.remove(&dir.join(name))?;
        }
    }
    if !existed {
        storage.remove_dir(dir)?;
        if let Some(parent) = dir.parent().filter(|p| !p.as_os_str().is_empty()) {
            storage.sync_dir(parent)?;
        }
    } else {
        storage.sync_dir(dir)?;
    }
    Ok(())
}

fn atomic_io_error(e: AtomicWriteError) -> StoreError {
    StoreError::Io {
        action: e.action,
        path: e.path,
        source: e.source,
    }
}

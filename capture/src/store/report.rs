//! What `resume` repaired and what `verify` found.

use super::error::StoreError;
use std::fmt;
use std::path::PathBuf;

/// A journal line torn by a crash mid-append, cut off by `resume`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TornLine {
    /// Where the line began (the journal's length after the cut), bytes.
    pub offset: u64,
    /// How many bytes of it there were.
    pub bytes: u64,
}

/// What `resume` found and repaired.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ResumeReport {
    /// A torn last journal line, cut back to the last complete line.
    pub torn_line: Option<TornLine>,
    /// Temporary files left by a crash, removed.
    pub temp_files_removed: Vec<PathBuf>,
    /// Frame files written but never journaled (a crash between the rename
    /// and the journal append), removed: those shots will be retaken.
    pub orphan_frames_removed: Vec<PathBuf>,
    /// Files in the frames directory that are not the store's, left alone.
    pub unknown_files: Vec<PathBuf>,
    /// Frames in the journal, all present with matching checksums.
    pub frames: usize,
    /// Missed shots in the journal (not taken since).
    pub missed: usize,
    /// The last key journaled.
    pub last_key: Option<String>,
}

impl ResumeReport {
    /// Whether the session was left cleanly (nothing to repair).
    pub fn is_clean(&self) -> bool {
        self.torn_line.is_none() && self.temp_files_removed.is_empty() && self.orphan_frames_removed.is_empty()
    }
}

impl ResumeReport {
    /// Each repair made and each file left alone, in words, e.g. "cut a
    /// torn journal line of 17 bytes at offset 4096"; empty when clean.
    pub fn repairs(&self) -> Vec<String> {
        let mut out = Vec::new();
        if let Some(t) = self.torn_line {
            out.push(format!(
                "cut a torn journal line of {} bytes at offset {}",
                t.bytes, t.offset
            ));
        }
        for p in &self.temp_files_removed {
            out.push(format!("removed temporary file {}", p.display()));
        }
        for p in &self.orphan_frames_removed {
            out.push(format!("removed unjournaled frame {} (to be retaken)", p.display()));
        }
        for p in &self.unknown_files {
            out.push(format!("left unknown file {}", p.display()));
        }
        out
    }
}

impl fmt::Display for ResumeReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} frames and {} missed shots journaled", self.frames, self.missed)?;
        if let Some(k) = &self.last_key {
            write!(f, " (last: {k:?})")?;
        }
        for r in self.repairs() {
            write!(f, "; {r}")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_resume_report_reads_as_words_not_a_struct() {
        let clean = ResumeReport {
            frames: 12,
            missed: 3,
            last_key: Some("morning@2026-08-28/s0/t1/f2".into()),
            ..ResumeReport::default()
        };
        assert_eq!(
            clean.to_string(),
            "12 frames and 3 missed shots journaled (last: \"morning@2026-08-28/s0/t1/f2\")"
        );
        assert!(clean.repairs().is_empty());
        let repaired = ResumeReport {
            torn_line: Some(TornLine {
                offset: 4096,
                bytes: 17,
            }),
            temp_files_removed: vec!["s/.plan.ron.tmp".into()],
            orphan_frames_removed: vec!["s/frames/a.png".into()],
            ..clean
        };
        assert_eq!(
            repaired.repairs(),
            [
                "cut a torn journal line of 17 bytes at offset 4096",
                "removed temporary file s/.plan.ron.tmp",
                "removed unjournaled frame s/frames/a.png (to be retaken)",
            ]
        );
        assert!(!repaired.to_string().contains("torn_line"), "{repaired}");
    }
}

/// What `verify` found.
#[derive(Debug, Default)]
pub struct VerifyReport {
    /// Journaled frames checked.
    pub frames_checked: usize,
    /// Bytes read.
    pub bytes_checked: u64,
    /// Journaled frames deleted on purpose (a `pruned` line): not checked,
    /// not problems.
    pub frames_pruned: usize,
    /// Frames that failed: [`StoreError::MissingFrame`],
    /// [`StoreError::ChecksumMismatch`] or [`StoreError::BadFrameFile`],
    /// each naming the file.
    pub problems: Vec<StoreError>,
}

impl VerifyReport {
    /// Whether every journaled frame is present and intact.
    pub fn is_ok(&self) -> bool {
        self.problems.is_empty()
    }
}

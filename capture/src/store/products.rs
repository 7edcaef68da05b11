//! Which scans of a session have their processed products on disk.
//!
//! This is the contract between the unattended station (which may delete a
//! scan's raw frames to stay within its storage budget) and `campanile
//! process` (which writes a scan's products): raw frames of an occurrence
//! may be removed only once that occurrence is listed here.
//!
//! The file is `SESSION/processed/products.ron`:
//!
//! ```text
//! ProcessedProducts(
//!     occurrences: ["sky@2026-06-21#3", "sky@2026-06-21#4"],
//! )
//! ```
//!
//! It is written atomically (temporary file, fsync, rename), so a reader
//! sees either the old list or the new one, never a torn file.

use serde::{Deserialize, Serialize};
use std::collections::BTreeSet;
use std::fs;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

/// Directory, inside a session, that holds its processed products.
pub const PROCESSED_DIR: &str = "processed";
/// File name, inside [`PROCESSED_DIR`], of the list of processed occurrences.
pub const PRODUCTS_FILE: &str = "products.ron";

/// The occurrences (scan ids: the first component of a frame key,
/// `{session}@{date}` or `{session}@{date}#{n}`) whose processed products exist.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct ProcessedProducts {
    /// Occurrence ids, sorted and unique.
    pub occurrences: BTreeSet<String>,
}

/// Why the products list could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum ProductsError {
    /// Reading or writing the file failed.
    #[error("{action} {}: {source}", path.display())]
    Io {
        /// What was being done.
        action: &'static str,
        /// The file.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: io::Error,
    },
    /// The file is not a `ProcessedProducts(occurrences: [...])` RON document.
    #[error("{}: not a products list (expected `ProcessedProducts(occurrences: [\"…\"])`): {message}", path.display())]
    Parse {
        /// The file.
        path: PathBuf,
        /// The parser's message, with line and column.
        message: String,
    },
}

/// The path of the products list of the session in `session_dir`.
pub fn products_path(session_dir: &Path) -> PathBuf {
    session_dir.join(PROCESSED_DIR).join(PRODUCTS_FILE)
}

impl ProcessedProducts {
    /// Reads the products list of `session_dir`; an absent file is an empty list.
    pub fn read(session_dir: &Path) -> Result<ProcessedProducts, ProductsError> {
        let path = products_path(session_dir);
        let text = match fs::read_to_string(&path) {
            Ok(text) => text,
            Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(ProcessedProducts::default()),
            Err(source) => {
                return Err(ProductsError::Io {
                    action: "reading",
                    path,
                    source,
                });
            }
        };
        ron::from_str(&text).map_err(|e| ProductsError::Parse {
            path,
            message: e.to_string(),
        })
    }

    /// Whether `occurrence` has its products.
    pub fn contains(&self, occurrence: &str) -> bool {
        self.occurrences.contains(occurrence)
    }

    /// Writes the list atomically into `session_dir/processed/products.ron`.
    pub fn write(&self, session_dir: &Path) -> Result<(), ProductsError> {
        let path = products_path(session_dir);
        let io_err = |action: &'static str, path: &Path| {
            let path = path.to_path_buf();
            move |source| ProductsError::Io { action, path, source }
        };
        let dir = session_dir.join(PROCESSED_DIR);
        fs::create_dir_all(&dir).map_err(io_err("creating", &dir))?;
        let text =
            ron::ser::to_string_pretty(self, ron::ser::PrettyConfig::default()).map_err(|e| ProductsError::Io {
                action: "serialising",
                path: path.clone(),
                source: io::Error::other(e.to_string()),
            })?;
        let tmp = dir.join(format!(".{PRODUCTS_FILE}.tmp"));
        {
            let mut file = fs::File::create(&tmp).map_err(io_err("creating", &tmp))?;
            file.write_all(text.as_bytes()).map_err(io_err("writing", &tmp))?;
            file.sync_all().map_err(io_err("syncing", &tmp))?;
        }
        fs::rename(&tmp, &path).map_err(io_err("renaming into", &path))?;
        if let Ok(d) = fs::File::open(&dir) {
            let _ = d.sync_all();
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_and_absent_is_empty() {
        let dir = tempfile::tempdir().unwrap();
        assert_eq!(ProcessedProducts::read(dir.path()).unwrap().occurrences.len(), 0);
        let mut p = ProcessedProducts::default();
        p.occurrences.insert("sky#0002".into());
        p.occurrences.insert("sky#0001".into());
        p.write(dir.path()).unwrap();
        let back = ProcessedProducts::read(dir.path()).unwrap();
        assert_eq!(back, p);
        assert!(back.contains("sky#0001") && !back.contains("sky#0003"));
    }

    #[test]
    fn a_damaged_file_is_an_error_naming_it() {
        let dir = tempfile::tempdir().unwrap();
        fs::create_dir_all(dir.path().join(PROCESSED_DIR)).unwrap();
        fs::write(products_path(dir.path()), "ProcessedProducts(occurrences: [1, 2").unwrap();
        let err = ProcessedProducts::read(dir.path()).unwrap_err().to_string();
        assert!(err.contains("products.ron") && err.contains("expected"), "{err}");
    }
}

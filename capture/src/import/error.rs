//! What can go wrong importing a folder of camera files.

use std::path::PathBuf;

use crate::store::StoreError;

/// Why a folder could not be imported. Every variant but
/// [`ImportError::Store`] on a write is bad input (exit 2 in the binary):
/// see [`ImportError::is_bad_input`].
#[derive(Debug, thiserror::Error)]
pub enum ImportError {
    /// The folder could not be listed.
    #[error("{path}: cannot list the folder: {source}")]
    Folder {
        /// The folder.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The folder holds no image files.
    #[error("{path}: no camera files in the folder (expected JPEG brackets, e.g. IMG_0001.JPG …)")]
    NoImages {
        /// The folder.
        path: PathBuf,
    },
    /// A file is not a JPEG.
    #[error(
        "{path}: not a JPEG camera file: {reason} (session import takes in-camera JPEGs; move other files out of the folder)"
    )]
    NotJpeg {
        /// The file.
        path: PathBuf,
        /// What its bytes are.
        reason: String,
    },
    /// A file could not be read.
    #[error("{path}: cannot read: {source}")]
    Read {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// A file has no EXIF block at all.
    #[error(
        "{path}: no EXIF block: the time and exposure of a hand-taken photograph come from its EXIF (DateTimeOriginal, ExposureTime); import the camera's original files"
    )]
    NoExif {
        /// The file.
        path: PathBuf,
    },
    /// An EXIF tag is missing or has a value that cannot be used.
    #[error("{path}: EXIF {tag} is {value}: expected {expected}")]
    Tag {
        /// The file.
        path: PathBuf,
        /// The tag, e.g. `DateTimeOriginal`.
        tag: &'static str,
        /// Its value as found (`absent` when missing).
        value: String,
        /// What was expected, and what to do.
        expected: String,
    },
    /// Something the command line must give is missing or wrong.
    #[error("{0}")]
    Option(String),
    /// The files do not form a session (mixed cameras, a lone frame, …).
    #[error("{0}")]
    Grouping(String),
    /// A description file (poses, scene, station, times) is wrong.
    #[error("{0}")]
    Description(String),
    /// The session store refused or failed.
    #[error("{0}")]
    Store(#[from] StoreError),
}

impl ImportError {
    /// Whether the error is bad input (a file, a tag, an option, the
    /// output directory) rather than a failure while working.
    pub fn is_bad_input(&self) -> bool {
        match self {
            ImportError::Store(e) => !matches!(e, StoreError::DiskFull(_) | StoreError::NeedsResume { .. }),
            _ => true,
        }
    }
}

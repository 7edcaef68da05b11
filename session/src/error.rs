//! The session library's error, and which errors mean bad input.
//!
//! The processing code works with `anyhow` inside (every file and value
//! named in its context chain); what crosses the library's boundary is an
//! [`Error`]: bad input (the command line exits 2), a product that failed
//! its quality gate (exit 3) or a failure while working (exit 1, unless its
//! chain holds a library error that means bad input: [`is_bad_input`]).

/// Why processing a session stopped.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// Bad input from the user: an argument, a file or a value.
    #[error("{message}")]
    Input {
        /// What was wrong, naming the file, field and value.
        message: String,
    },
    /// The work finished and its products were written, but `failed` did
    /// not pass their quality gates.
    #[error("finished, but products failed their quality checks: {}", failed.join("; "))]
    Quality {
        /// The products that failed, each with its figures.
        failed: Vec<String>,
    },
    /// A failure while working, with its context chain.
    #[error(transparent)]
    Work(#[from] anyhow::Error),
}

/// The library's result.
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    /// Bad input, with `message` as its text.
    pub fn input(message: impl Into<String>) -> Error {
        Error::Input {
            message: message.into(),
        }
    }

    /// Whether this error means bad input: an [`Error::Input`], or work that
    /// failed on a library error about what the user gave ([`is_bad_input`]).
    pub fn is_bad_input(&self) -> bool {
        match self {
            Error::Input { .. } => true,
            Error::Quality { .. } => false,
            Error::Work(e) => e.chain().any(is_bad_input),
        }
    }

    /// Whether this error is a failed quality gate (here or in its chain).
    pub fn is_quality_failure(&self) -> bool {
        match self {
            Error::Input { .. } => false,
            Error::Quality { .. } => true,
            Error::Work(e) => e.chain().any(is_quality_failure),
        }
    }
}

/// The errors of the crates and the standard library that the processing
/// meets: each is work that failed, its chain kept whole (a missing input
/// file still reads as bad input, see [`is_bad_input`]).
macro_rules! work_from {
    ($($t:ty),* $(,)?) => {
        $(impl From<$t> for Error {
            fn from(e: $t) -> Error {
                Error::Work(anyhow::Error::from(e))
            }
        })*
    };
}

work_from!(
    std::io::Error,
    std::num::ParseIntError,
    serde_json::Error,
    ron::Error,
    campanile_capture::store::ProductsError,
    campanile_process::hdr::HdrError,
    campanile_process::igi::scene_file::SceneFileError,
    campanile_process::outdoor::OutdoorError,
    campanile_process::pipeline::LightError,
    campanile_process::pipeline::PipelineError,
    campanile_process::report::ReportError,
    campanile_process::sky_series::SkySeriesError,
    campanile_process::sun::SunError,
);

/// A number as an error message shows it: the shortest text that reads
/// back as `x`, in scientific notation when huge or tiny (`1e308`, not
/// 309 digits).
pub fn shown(x: f64) -> String {
    if x != 0.0 && x.is_finite() && !(1e-4..1e15).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// An `anyhow` error that is bad input, with `message` as its text.
pub fn bad_input(message: impl Into<String>) -> anyhow::Error {
    anyhow::Error::new(Error::input(message))
}

/// Whether `cause` means bad input: an [`Error`] that does, or a library
/// error about what the user gave: a configuration file, a table, a site,
/// a session directory, a RON file, or an input path that does not exist.
pub fn is_bad_input(cause: &(dyn std::error::Error + 'static)) -> bool {
    use campanile_capture::store::StoreError;
    use campanile_process::sun::{SunError, SunTableError};
    cause.downcast_ref::<Error>().is_some_and(Error::is_bad_input)
        || cause.is::<campanile_config::ConfigError>()
        || cause.is::<campanile_config::ConfigErrors>()
        || cause.is::<SunError>()
        || cause.is::<campanile_process::sky::SampleTableError>()
        || cause.is::<campanile_process::csv_cell::TableError>()
        || cause.is::<campanile_process::igi::scene_file::SceneFileError>()
        || cause.is::<ron::error::SpannedError>()
        || cause
            .downcast_ref::<SunTableError>()
            .is_some_and(|e| !matches!(e, SunTableError::Write(_)))
        || cause
            .downcast_ref::<StoreError>()
            .is_some_and(|e| matches!(e, StoreError::NotASession { .. } | StoreError::InvalidKey { .. }))
        || cause
            .downcast_ref::<std::io::Error>()
            .is_some_and(|e| e.kind() == std::io::ErrorKind::NotFound)
}

/// Whether `cause` is a failed quality gate ([`Error::Quality`]).
pub fn is_quality_failure(cause: &(dyn std::error::Error + 'static)) -> bool {
    cause.downcast_ref::<Error>().is_some_and(Error::is_quality_failure)
}

#[cfg(test)]
mod tests {
    use super::*;
    use anyhow::Context;

    /// Work that failed on bad input, wrapped again on its way out, is
    /// still bad input, and reads as the chain it was made of.
    #[test]
    fn bad_input_survives_the_wrapping() {
        let inner: anyhow::Result<()> = Err(bad_input("--lat 95: expected −90 to 90"));
        let e = Error::from(inner.context("reading the site").unwrap_err());
        assert!(e.is_bad_input());
        assert!(!e.is_quality_failure());
        let outer = anyhow::Error::new(e);
        assert!(outer.chain().any(is_bad_input));
        assert_eq!(format!("{outer:#}"), "reading the site: --lat 95: expected −90 to 90");
        let missing = std::fs::read("/no/such/input.csv")
            .map_err(anyhow::Error::from)
            .unwrap_err();
        assert!(Error::from(missing).is_bad_input());
        let denied = anyhow::Error::from(std::io::Error::from(std::io::ErrorKind::PermissionDenied));
        assert!(!Error::from(denied).is_bad_input());
        let q = Error::Quality {
            failed: vec!["response: condition 1e9 > 1e6".into()],
        };
        assert_eq!(
            q.to_string(),
            "finished, but products failed their quality checks: response: condition 1e9 > 1e6"
        );
        assert!(Error::from(anyhow::Error::new(q)).is_quality_failure());
    }
}

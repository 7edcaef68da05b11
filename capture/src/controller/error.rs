//! Why a run stopped.

use super::options::RunReport;
use crate::store::StoreError;
use thiserror::Error;

/// A run stopped by a store failure (disk full, I/O error, a simulated
/// crash). Device failures never stop a run: they are retried, then
/// journaled missed per the step's policy.
#[derive(Debug, Error)]
#[error("the session stopped: {error}")]
pub struct RunError {
    /// The store's error (its message says what to do, e.g. for a full disk).
    #[source]
    pub error: StoreError,
    /// What the run did before it stopped.
    pub report: Box<RunReport>,
}

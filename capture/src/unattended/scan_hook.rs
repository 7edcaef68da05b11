//! What the station does with a scan once it is settled: the hook through
//! which a processor (the sky time series of `campanile process`) turns an
//! occurrence's frames into products and lists it in the session's
//! `processed/products.ron` ([`crate::store::ProcessedProducts`]), which
//! is what lets the storage budget delete its raw frames.

use std::path::Path;

use crate::schedule::Occurrence;

/// Called once an occurrence is settled (every promised shot journaled,
/// as a frame or missed), in the station's task, before the storage budget
/// is enforced. It runs synchronously: the station waits for it (a
/// simulated station's clock stands still meanwhile; a real station's next
/// scan may then start late). It may be called again for an occurrence
/// after a restart, so it must be idempotent.
pub trait ScanHook: Send {
    /// Process `occurrence` of the day session in `session_dir`. An error
    /// is logged and the station goes on (the scan's frames then stay, as
    /// its products do not exist).
    fn on_occurrence_done(&mut self, session_dir: &Path, occurrence: &Occurrence) -> Result<(), String>;
}

/// No processing: frames are never deletable, so a storage budget can
/// only warn.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoProcessing;

impl ScanHook for NoProcessing {
    fn on_occurrence_done(&mut self, _session_dir: &Path, _occurrence: &Occurrence) -> Result<(), String> {
        Ok(())
    }
}

impl<F> ScanHook for F
where
    F: FnMut(&Path, &Occurrence) -> Result<(), String> + Send,
{
    fn on_occurrence_done(&mut self, session_dir: &Path, occurrence: &Occurrence) -> Result<(), String> {
        self(session_dir, occurrence)
    }
}

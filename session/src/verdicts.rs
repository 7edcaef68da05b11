//! Quality verdicts: the thresholds a session's products are held to, and
//! the verdicts file (`quality.json`) beside them.

use std::path::Path;

use anyhow::Context;
use campanile_process::quality::{Quality, QualityReport};

use crate::Result;
use crate::error::Error;

/// The thresholds: `file` (a `Quality(...)` RON file, `--thresholds`),
/// else the plan's `quality`, else the defaults.
pub fn thresholds(file: Option<&Path>, plan: Option<&campanile_config::Plan>) -> Result<Quality> {
    match file {
        Some(path) => campanile_config::load_quality(path)
            .map(|l| l.value)
            .map_err(|e| Error::input(format!("--thresholds: {e}"))),
        None => Ok(plan.and_then(|p| p.quality.clone()).unwrap_or_default()),
    }
}

/// Writes the verdicts to `path` (through a temporary file and a rename).
pub fn write(report: &QualityReport, path: &Path) -> Result<()> {
    let tmp = path.with_extension("json.partial");
    std::fs::write(&tmp, report.to_json()).with_context(|| format!("{}: cannot write", tmp.display()))?;
    std::fs::rename(&tmp, path).with_context(|| format!("{}: cannot write", path.display()))?;
    Ok(())
}

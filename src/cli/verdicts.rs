//! Quality verdicts on the command line: the thresholds a command holds
//! its products to, `quality.json` beside them, the one-line summary, and
//! exit status 3 when a product failed its gate (all in
//! [`campanile_session::verdicts`]; here bound to standard output).

use std::path::Path;

use anyhow::Result;
use campanile_process::quality::{Quality, QualityReport};
pub use campanile_session::verdicts::beside;

/// The thresholds: `--thresholds FILE` (a `Quality(...)` RON file), else
/// the plan's `quality`, else the defaults.
pub fn thresholds(file: Option<&Path>, plan: Option<&campanile_config::Plan>) -> Result<Quality> {
    Ok(campanile_session::verdicts::thresholds(file, plan)?)
}

/// Writes the verdicts to `path`, prints the one-line summary, and turns
/// a failed product into the error that exits 3.
pub fn finish(report: &QualityReport, path: &Path) -> Result<()> {
    Ok(campanile_session::verdicts::finish(
        report,
        path,
        &mut std::io::stdout(),
    )?)
}

/// For a product written to standard output: the one-line summary on
/// standard error (no quality.json), and exit 3 for a failed product.
pub fn finish_on_stderr(report: &QualityReport) -> Result<()> {
    eprintln!("{}", report.summary_line());
    Ok(campanile_session::verdicts::gate(report, "the line above")?)
}

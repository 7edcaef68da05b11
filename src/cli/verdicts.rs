//! Quality verdicts on the command line: the thresholds a command holds
//! its products to, `quality.json` beside them, the one-line summary, and
//! exit status 3 when a product failed its gate.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use campanile_process::quality::{ProductQuality, Quality, QualityReport, Verdict};

use super::exit::bad_input;

/// The thresholds: `--thresholds FILE` (a `Quality(...)` RON file), else
/// the plan's `quality`, else the defaults.
pub fn thresholds(file: Option<&Path>, plan: Option<&campanile_config::Plan>) -> Result<Quality> {
    Ok(campanile_session::verdicts::thresholds(file, plan)?)
}

/// Where the verdicts of a one-file product go: `DIR/NAME.quality.json`
/// beside `DIR/NAME.EXT`.
pub fn beside(product: &Path) -> PathBuf {
    let stem = product
        .file_stem()
        .map_or_else(|| "product".into(), |s| s.to_string_lossy().into_owned());
    product.with_file_name(format!("{stem}.quality.json"))
}

/// The verdict an input product was written with, if its
/// `NAME.quality.json` lies beside it: a product made from it inherits it
/// ([`ProductQuality::inherit`]), so a failed curve or sky is never used
/// in silence. `None` when there is no verdict file; an unreadable one is
/// bad input.
pub fn of_input(product: &Path) -> Result<Option<ProductQuality>> {
    let path = beside(product);
    if !path.is_file() {
        return Ok(None);
    }
    let text = std::fs::read_to_string(&path).with_context(|| format!("{}: cannot read", path.display()))?;
    let report: QualityReport = serde_json::from_str(&text)
        .map_err(|e| bad_input(format!("{}: not a quality report ({e})", path.display())))?;
    let mut p = ProductQuality::new(product.display().to_string(), Vec::new());
    p.verdict = report.verdict;
    p.own_verdict = report.verdict;
    Ok(Some(p))
}

/// Writes the verdicts to `path`, prints the one-line summary, and turns
/// a failed product into the error that exits 3.
pub fn finish(report: &QualityReport, path: &Path) -> Result<()> {
    write(report, path)?;
    outln!("{}", report.summary_line())?;
    gate(report, &path.display().to_string())
}

/// Writes the verdicts to `path` (through a temporary file and a rename).
pub fn write(report: &QualityReport, path: &Path) -> Result<()> {
    Ok(campanile_session::verdicts::write(report, path)?)
}

/// For a product written to standard output: the one-line summary on
/// standard error (no quality.json), and exit 3 for a failed product.
pub fn finish_on_stderr(report: &QualityReport) -> Result<()> {
    eprintln!("{}", report.summary_line());
    gate(report, "the line above")
}

fn gate(report: &QualityReport, see: &str) -> Result<()> {
    if report.verdict == Verdict::Failed {
        let mut failed: Vec<String> = report
            .with(Verdict::Failed)
            .filter(|p| p.own_verdict == Verdict::Failed)
            .map(|p| p.product.clone())
            .collect();
        let inherited = report.counts.failed - failed.len();
        if inherited > 0 {
            failed.push(format!("{inherited} more through what they inherited"));
        }
        failed.push(format!("see {see}"));
        return Err(campanile_session::Error::Quality { failed }.into());
    }
    Ok(())
}

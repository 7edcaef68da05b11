//! Quality verdicts: the thresholds a session's products are held to, and
//! the verdicts file (`quality.json`) beside them.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::Context;
use campanile_process::quality::{ProductQuality, Quality, QualityReport, Verdict};

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
        .map_err(|e| Error::input(format!("{}: not a quality report ({e})", path.display())))?;
    let mut p = ProductQuality::new(product.display().to_string(), Vec::new());
    p.verdict = report.verdict;
    p.own_verdict = report.verdict;
    Ok(Some(p))
}

/// Writes the verdicts to `path`, prints the one-line summary to `out`,
/// and turns a failed product into [`Error::Quality`] (exit 3).
pub fn finish(report: &QualityReport, path: &Path, out: &mut dyn Write) -> Result<()> {
    write(report, path)?;
    writeln!(out, "{}", report.summary_line())?;
    gate(report, &path.display().to_string())
}

/// [`Error::Quality`] naming the products that failed their own gates
/// (and how many more failed through what they inherited), pointing to
/// `see` for the figures; `Ok` when none failed.
pub fn gate(report: &QualityReport, see: &str) -> Result<()> {
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
        return Err(Error::Quality { failed });
    }
    Ok(())
}

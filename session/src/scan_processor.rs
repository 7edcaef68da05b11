//! What turns a settled scan of the unattended station into products: the
//! [`ScanProcessor`] trait, the sky time series' [`SkySeriesProcessor`],
//! and the station's hook over any processor ([`StationHook`]).
//!
//! `campanile station run --process` runs the sky time series after each
//! scan through [`StationHook`]; tests call a processor directly, without
//! the binary.

use std::path::{Path, PathBuf};

use campanile_capture::schedule::Occurrence;
use campanile_capture::store::PROCESSED_DIR;
use campanile_capture::unattended::ScanHook;
use campanile_process::hdr::debevec::DebevecOptions;
use campanile_process::quality::{Quality, QualityReport, Verdict};

use crate::Result;
use crate::condition_hook::ConditionHook;
use crate::sky_series::{SkySeriesOptions, process_scan, recompute_day, series_quality};

/// Processes one settled scan of a day session.
pub trait ScanProcessor {
    /// Processes `occurrence` of the day session in `session_dir` and
    /// brings the day's products up to date; returns the verdicts of this
    /// scan's products.
    fn process(&mut self, session_dir: &Path, occurrence: &str) -> Result<QualityReport>;
}

/// The sky time series of a sky-only day (`campanile process DAY
/// --occurrence ID --response CSV`, without the report page): the scan's
/// sun and sky into `DAY/processed/scans/`, the day recomputed, and the
/// day's verdicts in `DAY/processed/quality.json`.
#[derive(Debug, Clone)]
pub struct SkySeriesProcessor {
    /// The response curve (CSV), as `--response` gives it.
    pub response: PathBuf,
    /// The thresholds the scans are held to.
    pub thresholds: Quality,
    /// A calibrated camera (`campanile sky calibrate`'s file) the scans
    /// are processed with instead of the station's camera and mount.
    pub camera_calibration: Option<PathBuf>,
    /// The command run when a scan changes the sky condition
    /// (`--on-condition-change`, see [`crate::condition_hook`]).
    pub on_condition_change: Option<ConditionHook>,
}

impl ScanProcessor for SkySeriesProcessor {
    fn process(&mut self, session_dir: &Path, occurrence: &str) -> Result<QualityReport> {
        let opts = SkySeriesOptions {
            out: session_dir.join(PROCESSED_DIR),
            response: Some(self.response.clone()),
            shard: None,
            debevec: DebevecOptions::default(),
            camera_calibration: self.camera_calibration.clone(),
        };
        process_scan(session_dir, occurrence, &opts)?;
        let series = recompute_day(&opts.out)?;
        if let Some(hook) = &self.on_condition_change {
            hook.on_scan(&series, occurrence);
        }
        // The day's verdicts beside its products.
        let day = series_quality(series.scans.iter(), &self.thresholds);
        crate::verdicts::write(&day, &opts.out.join("quality.json"))?;
        Ok(series_quality(
            series.scans.iter().filter(|s| s.occurrence == occurrence),
            &self.thresholds,
        ))
    }
}

/// The station's [`ScanHook`] over a [`ScanProcessor`]: an error is
/// returned with its chain (the station logs it and goes on: the next
/// scan may be clear); a scan whose products are not all `ok` is logged
/// as a warning.
pub struct StationHook<P>(pub P);

impl<P: ScanProcessor + Send> ScanHook for StationHook<P> {
    fn on_occurrence_done(&mut self, session_dir: &Path, occurrence: &Occurrence) -> std::result::Result<(), String> {
        let this = self
            .0
            .process(session_dir, &occurrence.key)
            .map_err(|e| format!("{e:#}"))?;
        if this.verdict != Verdict::Ok {
            tracing::warn!(scan = %occurrence.key, "{}", this.summary_line());
        }
        Ok(())
    }
}

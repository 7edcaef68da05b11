//! The series on disk, in an output directory OUT:
//!
//! ```text
//! OUT/scans/<occurrence>.ron    one ScanProducts per scan (the source of truth)
//! OUT/sky-series.csv            one row per scan, columns documented in its header
//! OUT/sky-series.parquet        the same, typed columns, units in its metadata
//! OUT/extinction.csv            β and E₀ per day and channel
//! OUT/plots/*.svg               sky scale, sky shape, irradiance, Langley
//! OUT/keogram.png, OUT/keogram-residual.png
//! ```
//!
//! Per-scan files are written atomically and never depend on other scans,
//! so shards writing disjoint scans merge by taking the union of their
//! `scans/` directories; the per-day files are always recomputed from
//! `scans/` alone ([`write_day`]).

use std::fs;
use std::io::Write as _;
use std::path::{Path, PathBuf};

use super::SkySeriesError;
use super::day::SkySeries;
use super::keogram::{keogram_png, keogram_residual_png};
use super::plots::{conditions_svg, irradiance_svg, langley_svg, shape_parameters_svg, zenith_scale_svg};
use super::scan::{ScanProducts, scan_file_stem};
use super::series_csv::{extinction_csv, series_csv};
use super::series_parquet::series_parquet;

/// Directory of the per-scan files inside OUT.
pub const SCANS_DIR: &str = "scans";

/// The per-scan file of `occurrence` in `out`.
pub fn scan_path(out: &Path, occurrence: &str) -> PathBuf {
    out.join(SCANS_DIR).join(format!("{}.ron", scan_file_stem(occurrence)))
}

fn io(action: &'static str, path: &Path) -> impl FnOnce(std::io::Error) -> SkySeriesError {
    let path = path.to_path_buf();
    move |source| SkySeriesError::Io { action, path, source }
}

/// Writes `bytes` to `path` through a temporary file, synced, then renamed.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), SkySeriesError> {
    if let Some(dir) = path.parent() {
        fs::create_dir_all(dir).map_err(io("creating", dir))?;
    }
    let name = path
        .file_name()
        .map_or("out".into(), |n| n.to_string_lossy().into_owned());
    let tmp = path.with_file_name(format!(".{name}.tmp"));
    {
        let mut f = fs::File::create(&tmp).map_err(io("creating", &tmp))?;
        f.write_all(bytes).map_err(io("writing", &tmp))?;
        f.sync_all().map_err(io("syncing", &tmp))?;
    }
    fs::rename(&tmp, path).map_err(io("renaming into", path))
}

/// Writes one scan's products (atomically) and returns the file.
pub fn write_scan(out: &Path, scan: &ScanProducts) -> Result<PathBuf, SkySeriesError> {
    let path = scan_path(out, &scan.occurrence);
    let text = scan.to_ron().map_err(|e| SkySeriesError::Parse {
        path: path.clone(),
        message: format!("serialising: {e}"),
    })?;
    write_atomic(&path, text.as_bytes())?;
    Ok(path)
}

/// Reads one per-scan file.
pub fn read_scan(path: &Path) -> Result<ScanProducts, SkySeriesError> {
    let text = fs::read_to_string(path).map_err(io("reading", path))?;
    ron::from_str(&text).map_err(|e| SkySeriesError::Parse {
        path: path.to_path_buf(),
        message: format!("not a scan's products (ScanProducts(occurrence: …)): {e}"),
    })
}

/// Every per-scan file in `out/scans` (none if the directory is absent), sorted by file name.
pub fn scan_files(out: &Path) -> Result<Vec<PathBuf>, SkySeriesError> {
    let dir = out.join(SCANS_DIR);
    let entries = match fs::read_dir(&dir) {
        Ok(e) => e,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(io("listing", &dir)(e)),
    };
    let mut files = Vec::new();
    for e in entries {
        let p = e.map_err(io("listing", &dir))?.path();
        let hidden = p.file_name().is_some_and(|n| n.to_string_lossy().starts_with('.'));
        if !hidden && p.extension().is_some_and(|x| x == "ron") {
            files.push(p);
        }
    }
    files.sort();
    Ok(files)
}

/// Every scan's products in `out/scans`.
pub fn read_scans(out: &Path) -> Result<Vec<ScanProducts>, SkySeriesError> {
    scan_files(out)?.iter().map(|p| read_scan(p)).collect()
}

/// Copies the per-scan files of each shard output directory in `shards`
/// into `out/scans` (a file already there with other bytes is an error:
/// two shards disagree). Returns how many files were copied.
pub fn merge_scan_dirs(out: &Path, shards: &[PathBuf]) -> Result<usize, SkySeriesError> {
    let mut copied = 0;
    for shard in shards {
        if !shard.join(SCANS_DIR).is_dir() {
            return Err(SkySeriesError::NotAShard { dir: shard.clone() });
        }
        for src in scan_files(shard)? {
            let Some(name) = src.file_name() else { continue };
            let dst = out.join(SCANS_DIR).join(name);
            let bytes = fs::read(&src).map_err(io("reading", &src))?;
            match fs::read(&dst) {
                Ok(existing) if existing == bytes => continue,
                Ok(_) => {
                    return Err(SkySeriesError::Conflict {
                        first: dst,
                        second: src,
                    });
                }
                Err(_) => {
                    write_atomic(&dst, &bytes)?;
                    copied += 1;
                }
            }
        }
    }
    Ok(copied)
}

/// Recomputes the per-day products from `out/scans` alone and writes them
/// (CSV, extinction, plots, keograms). Returns the series.
pub fn write_day(out: &Path) -> Result<SkySeries, SkySeriesError> {
    let series = SkySeries::new(read_scans(out)?);
    write_atomic(&out.join("sky-series.csv"), series_csv(&series).as_bytes())?;
    let parquet_path = out.join("sky-series.parquet");
    let parquet = series_parquet(&series).map_err(|e| SkySeriesError::Io {
        action: "encode the series as Parquet for",
        path: parquet_path.clone(),
        source: std::io::Error::other(e),
    })?;
    write_atomic(&parquet_path, &parquet)?;
    write_atomic(&out.join("extinction.csv"), extinction_csv(&series).as_bytes())?;
    if !series.scans.is_empty() {
        let plots = out.join("plots");
        for (name, svg) in [
            ("sky-scale.svg", zenith_scale_svg(&series)),
            ("sky-shape.svg", shape_parameters_svg(&series)),
            ("irradiance.svg", irradiance_svg(&series)),
            ("conditions.svg", conditions_svg(&series)),
        ] {
            // A plot with no finite point (no sky fitted all day) is left out.
            if let Ok(svg) = svg {
                write_atomic(&plots.join(name), svg.as_bytes())?;
            }
        }
        if series.days.iter().any(|d| !d.points.is_empty()) {
            write_atomic(&plots.join("langley.svg"), langley_svg(&series)?.as_bytes())?;
        }
        write_atomic(&out.join("keogram.png"), &keogram_png(&series.scans)?)?;
        write_atomic(&out.join("keogram-residual.png"), &keogram_residual_png(&series.scans)?)?;
    }
    Ok(series)
}

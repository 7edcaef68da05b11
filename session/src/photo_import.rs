//! Sessions from hand-taken photographs (`campanile session import`),
//! and checking a session's frames (`session verify`).

use std::io::Write;
use std::path::Path;

use campanile_capture::import::{ImportError, ImportOptions, plan_import, write_session};
use campanile_capture::store::SessionReader;

use crate::{Error, Result};

fn import_error(e: ImportError) -> Error {
    if e.is_bad_input() {
        Error::input(e.to_string())
    } else {
        Error::Work(anyhow::Error::new(e))
    }
}

/// Imports the photographs `opts` names into a new session at `session`,
/// with progress bars, and writes what was made to `out`: one line per
/// bracket, what was left out, unused poses and what was estimated.
pub fn import(opts: &ImportOptions, session: &Path, out: &mut dyn Write) -> Result<()> {
    if !(opts.occurrence_gap_s.is_finite() && opts.occurrence_gap_s >= 0.0) {
        return Err(Error::input(format!(
            "--occurrence-gap-min {}: expected minutes ≥ 0",
            opts.occurrence_gap_s / 60.0
        )));
    }
    let bar = crate::progress::bar(0, "reading EXIF");
    let plan = plan_import(opts, &|i, n| {
        bar.set_length(n as u64);
        bar.set_position(i as u64);
    })
    .map_err(import_error)?;
    bar.finish_and_clear();
    let bar = crate::progress::bar(0, "copying frames");
    let record = write_session(&plan, session, &|i, n| {
        bar.set_length(n as u64);
        bar.set_position(i as u64);
    })
    .map_err(import_error)?;
    bar.finish_and_clear();

    writeln!(
        out,
        "imported {} → {}: {} brackets, {} frames, camera {} (station {})",
        opts.folder.display(),
        session.display(),
        record.brackets.len(),
        record.brackets.iter().map(|b| b.frames.len()).sum::<usize>(),
        record.camera,
        record.station_from
    )?;
    writeln!(
        out,
        "{:<28} {:<5} {:>3}  {:<16} {:<16} {:<26} {:<20} began",
        "group", "kind", "n", "first", "last", "start (UTC)", "exposures (s)"
    )?;
    for b in &record.brackets {
        let (first, last) = (&b.frames[0], &b.frames[b.frames.len() - 1]);
        let exposures: Vec<f64> = b.frames.iter().map(|f| f.exposure_time_s).collect();
        let lo = exposures.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = exposures.iter().copied().fold(0.0, f64::max);
        writeln!(
            out,
            "{:<28} {:<5} {:>3}  {:<16} {:<16} {:<26} {:<20} {}",
            b.group,
            b.purpose,
            b.frames.len(),
            first.file,
            last.file,
            first.utc,
            format!("{lo}…{hi}"),
            if b.began.is_empty() { "first" } else { &b.began }
        )?;
    }
    for s in &record.skipped {
        writeln!(out, "left out: {s}")?;
    }
    for p in &plan.unused_poses {
        writeln!(out, "warning: poses entry {p:?} matches no bracket's first file")?;
    }
    for e in &record.estimated {
        writeln!(out, "estimated ({}): {}", e.what, e.how)?;
    }
    Ok(())
}

/// Reads back every frame of the session at `session` against its
/// checksum, writing the count and each damaged or missing frame to `out`;
/// any such frame is bad input (the session's, listed).
pub fn verify(session: &Path, out: &mut dyn Write) -> Result<()> {
    let reader = SessionReader::open(session).map_err(|e| Error::input(e.to_string()))?;
    let mut problems = Vec::new();
    let mut checked = 0;
    for f in reader.frames() {
        checked += 1;
        if let Err(e) = reader.read_frame(f) {
            problems.push(e.to_string());
        }
    }
    writeln!(
        out,
        "{}: {checked} frames checked, {} damaged or missing",
        session.display(),
        problems.len()
    )?;
    for p in &problems {
        writeln!(out, "  {p}")?;
    }
    if problems.is_empty() {
        Ok(())
    } else {
        Err(Error::input(format!(
            "{}: {} of {checked} frames damaged or missing (listed above)",
            session.display(),
            problems.len()
        )))
    }
}

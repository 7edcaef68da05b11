//! The unattended station's heartbeat read back (`campanile station
//! status`): its state, devices, disk and last frame, whether its process
//! still runs, and whether the heartbeat is fresh.

use std::io::Write;
use std::path::Path;

use campanile_capture::unattended::{self, DeviceState, Heartbeat, Liveness};
use chrono::{DateTime, Utc};

use crate::{Error, Result};

/// Writes the heartbeat of the station storing into `store` to `out`, and
/// whether the station is alive: `Ok(true)` when the heartbeat is at most
/// `max_age_s` old and no process it names has died; `Ok(false)` when it is
/// stale or its process is gone (each said on its own line).
pub fn status(store: &Path, max_age_s: f64, out: &mut dyn Write) -> Result<bool> {
    if !(max_age_s.is_finite() && max_age_s >= 0.0) {
        return Err(Error::input(format!(
            "--max-age: found {}; expected a number of seconds, 0 or more",
            crate::error::shown(max_age_s)
        )));
    }
    let beat = Heartbeat::read(store).map_err(|e| anyhow::anyhow!("{e}"))?;
    let age = beat.age_s(Utc::now());
    let t = |d: DateTime<Utc>| d.format("%Y-%m-%d %H:%M:%S UTC").to_string();
    writeln!(
        out,
        "station heartbeat {}",
        store.join(unattended::HEARTBEAT_FILE).display()
    )?;
    let state = serde_json::to_value(beat.state)
        .ok()
        .and_then(|v| v.as_str().map(str::to_owned))
        .unwrap_or_default();
    if beat.detail.is_empty() {
        writeln!(out, "  state        {state}")?;
    } else {
        writeln!(out, "  state        {state}: {}", beat.detail)?;
    }
    writeln!(
        out,
        "  written      {} station time; {age:.0} s ago on this computer's clock (pid {})",
        t(beat.written_utc),
        beat.pid
    )?;
    match (&beat.last_frame_utc, &beat.last_frame_key) {
        (Some(at), Some(key)) => writeln!(out, "  last frame   {} {key}", t(*at))?,
        _ => writeln!(out, "  last frame   none in this run")?,
    }
    if let (Some(day), Some(dir)) = (beat.day, &beat.session_dir) {
        writeln!(
            out,
            "  today        {day}: {} frames in {}",
            beat.frames_today,
            dir.display()
        )?;
    }
    for d in &beat.devices {
        let line = match &d.state {
            DeviceState::Unknown => "not asked yet".to_owned(),
            DeviceState::Up { last_answer } => format!("up (last answer {})", t(*last_answer)),
            DeviceState::Down { since, error, probes } => {
                format!("DOWN since {} ({probes} failed probes): {error}", t(*since))
            }
        };
        writeln!(out, "  {:<12} {line}", d.device)?;
    }
    let mb = |b: u64| format!("{:.1} MB", b as f64 / 1e6);
    writeln!(
        out,
        "  disk         {} free; the store holds {}{}",
        beat.free_disk_bytes.map_or("unknown".to_owned(), mb),
        mb(beat.store_bytes),
        beat.budget_bytes
            .map_or(String::new(), |b| format!(" of a {} budget", mb(b)))
    )?;
    // A station that ends on its own writes `stopped`, `finished` or
    // `failed`; one whose heartbeat says it runs must still run.
    let live = beat.liveness();
    match &live {
        Liveness::Running => writeln!(out, "  process      pid {} on this host: running", beat.pid)?,
        Liveness::NotRunning(why) => writeln!(out, "  process      {why}")?,
        Liveness::OtherHost(host) => writeln!(
            out,
            "  process      pid {} on host {host}, not this one: judged by the heartbeat's age only",
            beat.pid
        )?,
        Liveness::Unknown(why) => writeln!(out, "  process      {why}; judged by the heartbeat's age only")?,
    }
    if beat.state.claims_running()
        && let Liveness::NotRunning(why) = &live
    {
        writeln!(out, "not running (killed?): the heartbeat says {state}, but {why}")?;
        return Ok(false);
    }
    if age > max_age_s {
        writeln!(
            out,
            "STALE: written {age:.0} s ago, more than --max-age {max_age_s:.0} s: the station is not running or is stuck"
        )?;
        Ok(false)
    } else {
        writeln!(out, "fresh: written {age:.0} s ago (--max-age {max_age_s:.0} s)")?;
        Ok(true)
    }
}

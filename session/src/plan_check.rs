//! A plan simulated forward on a station without devices (`campanile
//! plan check`): its timeline, frames, durations, and what it will not
//! cover.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::Context;
use campanile_capture::schedule::{Occurrence, SceneGeometry, ShotKind, Timeline, TimelineOptions, timeline};
use campanile_config::{Station, check_plan_on_station, load_plan, load_station};

use crate::{Error, Result};

/// A plan simulated forward on a station, as `campanile plan check` shows it.
pub struct PlanCheck {
    /// The timeline: occurrences, shots, durations and what it will not cover.
    pub timeline: Timeline,
    /// The station it ran on.
    pub station: Station,
    /// The plan's name.
    pub plan_name: String,
    /// The plan file.
    pub plan_path: PathBuf,
    /// The station file.
    pub station_path: PathBuf,
    /// Only the first days were simulated.
    pub days: Option<u32>,
}

/// Simulates the plan file `plan` on the station file `station` (only the
/// first `days` days, if given): every error is about the files given.
pub fn simulate(plan_path: &Path, station_path: &Path, days: Option<u32>) -> Result<PlanCheck> {
    simulate_files(plan_path, station_path, days).map_err(|e| Error::input(format!("{e:#}")))
}

fn simulate_files(plan_path: &Path, station_path: &Path, days: Option<u32>) -> anyhow::Result<PlanCheck> {
    let plan = load_plan(plan_path).map_err(|e| anyhow::anyhow!("{e}"))?;
    let station = load_station(station_path).map_err(|e| anyhow::anyhow!("{e}"))?.value;
    check_plan_on_station(&plan, &station).map_err(|e| {
        anyhow::anyhow!(
            "{e}\nthe plan does not run on station {:?} ({})",
            station.name,
            station_path.display()
        )
    })?;
    let scene = match &plan.scene {
        Some(s) => Some(SceneGeometry::load(&s.value, &s.source.base_dir()).context("reading the plan's scene")?),
        None => None,
    };
    let t = timeline(&plan.plan.value, &station, scene.as_ref(), &TimelineOptions { days })
        .with_context(|| format!("{}: cannot simulate the plan", plan_path.display()))?;
    Ok(PlanCheck {
        timeline: t,
        station,
        plan_name: plan.plan.value.name,
        plan_path: plan_path.to_path_buf(),
        station_path: station_path.to_path_buf(),
        days,
    })
}

fn frames(promised: usize, at_most: usize) -> String {
    if promised == at_most {
        promised.to_string()
    } else {
        format!("{promised}–{at_most}")
    }
}

fn hms(d: std::time::Duration) -> String {
    let s = d.as_secs_f64().round() as u64;
    match (s / 3600, s / 60 % 60, s % 60) {
        (0, 0, s) => format!("{s} s"),
        (0, m, s) => format!("{m} min {s:02} s"),
        (h, m, s) => format!("{h} h {m:02} min {s:02} s"),
    }
}

fn kinds(o: &Occurrence) -> String {
    [
        (ShotKind::Data, "data"),
        (ShotKind::Metering, "metering"),
        (ShotKind::Centering, "centering"),
    ]
    .into_iter()
    .filter_map(|(k, name)| {
        let (p, m) = o.count(k);
        (m > 0).then(|| format!("{} {name}", frames(p, m)))
    })
    .collect::<Vec<_>>()
    .join(", ")
}

/// Writes the check to `out`: the plan and site, the timeline (one line
/// per occurrence: start, sun, frames, duration, frames by kind), the
/// totals, and what the plan will not cover.
pub fn write(c: &PlanCheck, out: &mut dyn Write) -> Result<()> {
    let (t, station, plan_name) = (&c.timeline, &c.station, &c.plan_name);
    let zone: chrono_tz::Tz = station.site.time_zone.parse().unwrap_or(chrono_tz::UTC);
    writeln!(
        out,
        "plan {plan_name:?} ({}) on station {:?} ({})",
        c.plan_path.display(),
        station.name,
        c.station_path.display()
    )?;
    writeln!(
        out,
        "site {}: {}°, {}°; local times in {}",
        station.site.name, station.site.latitude_deg, station.site.longitude_deg, station.site.time_zone
    )?;
    if let Some(n) = c.days {
        writeln!(out, "simulating the first {n} day(s) only")?;
    }
    writeln!(out)?;
    let n = t.occurrences.len();
    writeln!(out, "Timeline ({n} occurrence{})", if n == 1 { "" } else { "s" })?;
    let width = t.occurrences.iter().map(|o| o.key.len()).max().unwrap_or(10).max(10);
    writeln!(
        out,
        "  {:width$}  {:20}  {:22}  {:>7}  {:>7}  {:>9}  {:>14}  frames by kind",
        "occurrence", "start (UTC)", "local", "sun az", "sun el", "frames", "est. duration"
    )?;
    for o in &t.occurrences {
        let local = o.start.with_timezone(&zone).format("%Y-%m-%d %H:%M:%S %Z").to_string();
        writeln!(
            out,
            "  {:width$}  {:20}  {:22}  {:>6.1}°  {:>6.1}°  {:>9}  {:>14}  {}{}",
            o.key,
            o.start.format("%Y-%m-%d %H:%M:%S").to_string(),
            local,
            o.sun.0,
            o.sun.1,
            frames(o.frames_promised(), o.frames_at_most()),
            hms(o.estimated_duration),
            kinds(o),
            if o.held_out { " (held out)" } else { "" }
        )?;
    }
    writeln!(out)?;
    writeln!(out, "Totals")?;
    writeln!(out, "  occurrences          {}", t.occurrences.len())?;
    writeln!(out, "  frames promised      {} (exactly)", t.frames_promised())?;
    if t.frames_at_most() != t.frames_promised() {
        writeln!(
            out,
            "  frames at most       {} ({} more if every auto-bracket takes all its frames)",
            t.frames_at_most(),
            t.frames_at_most() - t.frames_promised()
        )?;
    }
    writeln!(out, "  estimated time       {}", hms(t.estimated_duration()))?;
    writeln!(out)?;
    if t.uncovered.is_empty() {
        writeln!(out, "Will not cover: nothing. The plan is fully covered.")?;
    } else {
        writeln!(out, "Will not cover ({})", t.uncovered.len())?;
        for u in &t.uncovered {
            let warning = if u.is_warning() {
                " (a warning: every shot is still taken; exit status 0 if nothing else is listed)"
            } else {
                ""
            };
            writeln!(out, "  - {u}{warning}")?;
        }
    }
    Ok(())
}

//! `campanile plan check`: simulate a plan forward without devices.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use campanile_capture::schedule::{Occurrence, SceneGeometry, ShotKind, Timeline, TimelineOptions, timeline};
use campanile_config::{Station, check_plan_on_station, load_plan, load_station};
use clap::{Args, Subcommand};

use super::{EXIT_FAILURE, EXIT_OK, EXIT_USAGE};

#[derive(Debug, Subcommand)]
pub enum PlanCommand {
    /// Simulate a plan on a station, without devices, and say what it will not cover.
    ///
    /// Plays the plan forward day by day on the station's site and prints:
    ///   - the timeline: one line per occurrence of a session, with its key
    ///     (session@day, plus #n for every-N-minutes repeats), its start in
    ///     UTC and in the site's local time, the sun's azimuth and elevation
    ///     then, its frames by kind (a range where auto-brackets decide at
    ///     run time) and its estimated duration;
    ///   - totals: the frames the plan promises (exactly: the controller
    ///     writes that many to the session directory), the most it may take,
    ///     and the estimated time;
    ///   - "Will not cover": triggers that never fire on a day (with the
    ///     reason, e.g. the day's highest sun), occurrences that overlap,
    ///     shots the head cannot reach, sun shots with the sun down, and faces
    ///     of an outdoor scene never photographed in sunlight.
    ///
    /// A plan day is the site's mean solar day (24 h centred on local mean
    /// noon), so a day's morning and evening share a day wherever the site
    /// is. Clock times are UTC. Solar instants are bisected on the NREL SPA
    /// ephemeris to 1 ms.
    ///
    /// The plan is first checked against the station as `config check` does.
    ///
    /// Exit status: 0 when the plan is fully covered, or when all it will
    /// not cover are warnings (a face never sunlit at its times: every shot
    /// is taken, but that face's sun reflectance is not measured); 1 when
    /// shots will be missed or late (or the --ron file cannot be written);
    /// 2 for bad input
    /// (unreadable or invalid files, a plan that does not run on the station).
    ///
    /// Examples:
    ///   campanile plan check examples/campanile-day.ron --station examples/sim-station.ron
    ///   campanile plan check examples/campanile-day.ron --station examples/sim-station.ron --ron timeline.ron
    #[command(verbatim_doc_comment)]
    Check(CheckArgs),
}

#[derive(Debug, Args)]
pub struct CheckArgs {
    /// The plan (RON); its scene is read from the plan's `scene` field.
    #[arg(value_name = "PLAN")]
    plan: PathBuf,
    /// The station (RON) that will run it.
    #[arg(long, value_name = "STATION")]
    station: PathBuf,
    /// Simulate only the first N days from the plan's start date.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
    days: Option<u32>,
    /// Also write the whole timeline, every planned shot included, as RON.
    #[arg(long, value_name = "FILE")]
    ron: Option<PathBuf>,
}

pub fn run(cmd: PlanCommand) -> Result<u8> {
    match cmd {
        PlanCommand::Check(args) => check(&args),
    }
}

fn check(args: &CheckArgs) -> Result<u8> {
    let (t, station, plan_name) = match simulate(args) {
        Ok(v) => v,
        Err(e) => {
            eprintln!("error: {e:#}");
            return Ok(EXIT_USAGE);
        }
    };
    print(&t, &station, &plan_name, args)?;
    if let Some(out) = &args.ron
        && let Err(e) = super::ron_output::write_ron(&t, Some(out))
    {
        eprintln!("error: {e:#}");
        return Ok(EXIT_FAILURE);
    }
    Ok(if t.is_covered() { EXIT_OK } else { EXIT_FAILURE })
}

fn simulate(args: &CheckArgs) -> Result<(Timeline, Station, String)> {
    let plan = load_plan(&args.plan).map_err(|e| anyhow::anyhow!("{e}"))?;
    let station = load_station(&args.station).map_err(|e| anyhow::anyhow!("{e}"))?.value;
    check_plan_on_station(&plan, &station).map_err(|e| {
        anyhow::anyhow!(
            "{e}\nthe plan does not run on station {:?} ({})",
            station.name,
            args.station.display()
        )
    })?;
    let scene = match &plan.scene {
        Some(s) => Some(SceneGeometry::load(&s.value, &s.source.base_dir()).context("reading the plan's scene")?),
        None => None,
    };
    let options = TimelineOptions { days: args.days };
    let t = timeline(&plan.plan.value, &station, scene.as_ref(), &options)
        .with_context(|| format!("{}: cannot simulate the plan", args.plan.display()))?;
    Ok((t, station, plan.plan.value.name))
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

fn print(t: &Timeline, station: &Station, plan_name: &str, args: &CheckArgs) -> Result<()> {
    let zone: chrono_tz::Tz = station.site.time_zone.parse().unwrap_or(chrono_tz::UTC);
    let mut out = std::io::stdout().lock();
    writeln!(
        out,
        "plan {plan_name:?} ({}) on station {:?} ({})",
        args.plan.display(),
        station.name,
        display(&args.station)
    )?;
    writeln!(
        out,
        "site {}: {}°, {}°; local times in {}",
        station.site.name, station.site.latitude_deg, station.site.longitude_deg, station.site.time_zone
    )?;
    if let Some(n) = args.days {
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

fn display(p: &Path) -> String {
    p.display().to_string()
}

//! `campanile plan check`: simulate a plan forward without devices.

use std::path::PathBuf;

use anyhow::Result;
use campanile_session::plan_check;
use clap::{Args, Subcommand};

use super::{EXIT_FAILURE, EXIT_OK};

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
    let c = plan_check::simulate(&args.plan, &args.station, args.days)?;
    plan_check::write(&c, &mut std::io::stdout().lock())?;
    if let Some(out) = &args.ron
        && let Err(e) = super::ron_output::write_ron(&c.timeline, Some(out))
    {
        eprintln!("error: {e:#}");
        return Ok(EXIT_FAILURE);
    }
    Ok(if c.timeline.is_covered() { EXIT_OK } else { EXIT_FAILURE })
}

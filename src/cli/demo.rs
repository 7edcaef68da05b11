//! `campanile demo`: the whole station on the simulated hardware, in one
//! command: capture a day at the campanile, process it, write a report
//! (the work is `campanile_session::demo`'s).

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};
use campanile_session::demo::{DemoHost, DemoOptions};
use clap::{Args, Parser};

use super::capture::CaptureArgs;

/// Run the whole station on simulated hardware and write a report.
///
/// With no hardware and no arguments, it:
///   1. builds the simulated station (examples/sim-station.ron);
///   2. captures a simulated day at the campanile (examples/campanile-day.ron:
///      four training times and one held-out time; --quick: two and one);
///   3. processes it (response, HDR, sun, sky, environment, pseudo-albedos,
///      the held-out time re-rendered under the predicted light);
///   4. recovers the BRDFs of the thesis's simulated cube (inverse global
///      illumination, §4.7.1);
///   5. photographs the simulated room under its lamps, triangulates the
///      lamps, recovers its BRDFs and albedo maps and relights it under new
///      lamps (§4.7.2), beside the simulator's render;
///   6. writes OUT/report.html, with every figure beside the simulator's truth.
///
/// The session directories and every product stay in OUT.
///
/// Example:
///   campanile demo --out campanile-demo
///   campanile demo --quick --out demo-quick
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct DemoArgs {
    /// Where to write the sessions, the products and report.html.
    #[arg(long, value_name = "DIR", default_value = "campanile-demo")]
    out: PathBuf,
    /// A smaller, faster run (two training times, fewer views): what the tests use.
    #[arg(long)]
    quick: bool,
    /// Diagnostic: after the held-out comparison, measure where its error
    /// comes from, term by term, against the simulator (renders the held-out
    /// views again at many samples per pixel; adds a report section and
    /// OUT/held-out-budget.json).
    #[arg(long)]
    held_out_budget: bool,
    /// Development: reuse OUT/campanile-session if it is there instead of
    /// capturing the day again (the capture is most of the demo's time).
    #[arg(long)]
    reuse_session: bool,
}

/// Parses a `capture` command line, as the user would type it.
#[derive(Debug, Parser)]
struct CaptureLine {
    #[command(flatten)]
    args: CaptureArgs,
}

/// The demo's captures run `campanile capture`; its notes go to standard error.
struct CommandLine;

impl DemoHost for CommandLine {
    fn capture(&self, plan: &Path, station: &Path, session: &Path, extra: &[&str]) -> campanile_session::Result<()> {
        Ok(capture_simulated(plan, station, session, extra)?)
    }

    fn note(&self, line: &str) {
        eprintln!("{line}");
    }
}

/// Captures `plan` on the simulated `station` into `session` (cleared
/// first) through `campanile capture`, with `extra` arguments.
fn capture_simulated(plan: &Path, station: &Path, session: &Path, extra: &[&str]) -> Result<()> {
    use anyhow::Context;
    if session.exists() {
        std::fs::remove_dir_all(session).with_context(|| format!("{}: cannot clear", session.display()))?;
    }
    let mut line: Vec<&std::ffi::OsStr> = vec![
        "capture".as_ref(),
        plan.as_os_str(),
        "--station".as_ref(),
        station.as_os_str(),
        "--out".as_ref(),
        session.as_os_str(),
    ];
    line.extend(extra.iter().map(std::ffi::OsStr::new));
    let line = CaptureLine::try_parse_from(line)?;
    if super::capture::run(line.args)? != super::EXIT_OK {
        bail!(
            "the simulated capture of {} did not complete (see above)",
            plan.display()
        );
    }
    Ok(())
}

pub fn run(args: DemoArgs) -> Result<()> {
    let opts = DemoOptions {
        out: args.out,
        quick: args.quick,
        held_out_budget: args.held_out_budget,
        reuse_session: args.reuse_session,
    };
    let run = campanile_session::demo::run(&opts, &CommandLine)?;
    outln!(
        "demo finished in {:.1} s: {} ({} figures)",
        run.seconds,
        run.report.display(),
        run.figures
    )?;
    super::verdicts::finish(&run.quality, &opts.out.join("quality.json"))
}

//! `campanile config check`: validate configuration files and summarize them.

use std::path::PathBuf;

use campanile_config::{Document, check_plan_on_station};
use clap::Subcommand;

use super::{EXIT_OK, EXIT_USAGE};

#[derive(Debug, Subcommand)]
pub enum ConfigCommand {
    /// Validate station, plan, scene and camera calibration files, and print what they describe.
    ///
    /// The kind of each file is told by its top-level value: `Station(...)`,
    /// `Plan(...)`, `Scene(...)` `CameraCalibration(...)` or `Targets(...)`. A plan's scene (its `scene` field) is
    /// read and checked with it. Every plan is also checked against every
    /// station given in the same command: filter slots, lights and poses it
    /// names must exist there, exposures must be within the camera's limits,
    /// and head poses within the head's limits.
    ///
    /// Errors name the file, line and column, the field, the value found and
    /// what was expected. Exit status: 0 if every file is valid, 2 otherwise.
    ///
    /// Example:
    ///   campanile config check examples/campanile-day.ron examples/sim-station.ron examples/real-station.ron
    #[command(verbatim_doc_comment)]
    Check {
        /// Configuration files (RON).
        #[arg(required = true, value_name = "FILE")]
        files: Vec<PathBuf>,
    },
}

pub fn run(cmd: ConfigCommand) -> anyhow::Result<u8> {
    match cmd {
        ConfigCommand::Check { files } => check(&files),
    }
}

fn check(files: &[PathBuf]) -> anyhow::Result<u8> {
    let mut failed = false;
    let mut docs = Vec::new();
    for path in files {
        match campanile_config::load(path) {
            Ok(doc) => docs.push((path, doc)),
            Err(errors) => {
                failed = true;
                eprintln!("{errors}");
            }
        }
    }
    let stations: Vec<_> = docs
        .iter()
        .filter_map(|(p, d)| match d {
            Document::Station(s) => Some((*p, &s.value)),
            _ => None,
        })
        .collect();
    for (path, doc) in &docs {
        outln!("{}: valid {}", path.display(), doc.kind())?;
        out!("{}", doc.summary())?;
        if let Document::Plan(plan) = doc {
            if stations.is_empty() {
                outln!("  (not checked against a station: give a station file in the same command)")?;
            }
            for (spath, station) in &stations {
                match check_plan_on_station(plan, station) {
                    Ok(()) => outln!("  runs on station {:?} ({})", station.name, spath.display())?,
                    Err(errors) => {
                        failed = true;
                        eprintln!("{errors}");
                        outln!("  does NOT run on station {:?} ({})", station.name, spath.display())?;
                    }
                }
            }
        }
    }
    Ok(if failed { EXIT_USAGE } else { EXIT_OK })
}

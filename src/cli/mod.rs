//! Argument parsing and dispatch. One module per subcommand.

mod config_check;
mod logging;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// Exit code for success.
pub const EXIT_OK: u8 = 0;
/// Exit code for a usage error or an invalid configuration file.
pub const EXIT_USAGE: u8 = 2;

/// Campanile: a capture-and-process station for real scenes.
///
/// It drives a camera, a pan-tilt head, an ND filter wheel and light
/// controllers; captures brackets, sun shots, sky scans and panoramas; and
/// recovers radiance, sun, sky, environment illumination and surface
/// reflectance so that the scene can be rendered at other times or under new
/// lights.
#[derive(Debug, Parser)]
#[command(
    name = "campanile",
    version,
    propagate_version = true,
    max_term_width = 100,
    after_help = "Exit status: 0 success, 1 failure while working, 2 usage or configuration error.\n\
                  Examples: campanile config check examples/*.ron"
)]
pub struct Cli {
    #[command(flatten)]
    pub logging: logging::LogArgs,

    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Read and validate configuration files (station, plan, scene).
    Config {
        #[command(subcommand)]
        action: config_check::ConfigCommand,
    },
}

/// Parses the command line, sets up logging and runs the subcommand.
pub fn run() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(err) => {
            let code = if err.use_stderr() { EXIT_USAGE } else { EXIT_OK };
            let _ = err.print();
            return ExitCode::from(code);
        }
    };
    logging::init(&cli.logging);
    let code = match cli.command {
        Command::Config { action } => config_check::run(action),
    };
    ExitCode::from(code)
}

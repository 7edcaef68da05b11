//! Argument parsing and dispatch. One module per subcommand.

#[macro_use]
mod output;
mod capture;
mod config_check;
mod demo;
mod devices;
mod edit;
mod env;
pub mod exit;
mod hdr;
mod igi;
mod logging;
mod outdoor;
mod plan;
mod process;
mod register;
mod render;
mod ron_output;
mod segment;
mod session;
mod sky;
mod station;
mod sun;
mod texture;
mod verdicts;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

pub use exit::{EXIT_FAILURE, EXIT_OK, EXIT_USAGE};

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
    after_help = concat!(
        "Exit status: 0 ok; 1 failure while working; 2 bad input or usage (an argument, a configuration or input \
         file, a value); 3 finished, but a product failed its quality gate (quality.json names it).\n",
        "Examples: campanile config check examples/*.ron"
    )
)]
pub struct Cli {
    #[command(flatten)]
    pub logging: logging::LogArgs,

    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    // Tuple variants take their help (and example) from their arguments'
    // doc comments.
    Demo(demo::DemoArgs),
    /// Read and validate configuration files (station, plan, scene).
    Config {
        #[command(subcommand)]
        action: config_check::ConfigCommand,
    },
    /// Camera response recovery, HDR merging and lens calibration on plain files.
    Hdr {
        #[command(subcommand)]
        action: hdr::HdrCommand,
    },
    Sun(sun::SunArgs),
    /// The environment: fit region radiance models, predict them under new light.
    Env {
        #[command(subcommand)]
        action: env::EnvCommand,
    },
    /// Sky models: fit them to sky samples, predict them at other sun positions, evaluate them.
    Sky {
        #[command(subcommand)]
        action: sky::SkyCommand,
    },
    Igi(igi::IgiArgs),
    /// Outdoor reflectance on plain files: pseudo-albedos from posed HDR photos, views at new times.
    Outdoor {
        #[command(subcommand)]
        action: outdoor::OutdoorCommand,
    },
    Capture(capture::CaptureArgs),
    /// The unattended station: run a plan day after day (`station run`), read its heartbeat (`station status`), serve its live page (`station serve`).
    Station {
        #[command(subcommand)]
        action: station::StationCommand,
    },
    /// Sessions from hand-taken photographs (`session import FOLDER --out SESSION`), and checking one (`session verify`).
    Session {
        #[command(subcommand)]
        action: session::SessionCommand,
    },
    Process(process::ProcessArgs),
    Devices(devices::DevicesArgs),
    Render(render::RenderArgs),
    Register(register::RegisterArgs),
    Texture(texture::TextureArgs),
    Segment(segment::SegmentArgs),
    Edit(edit::EditArgs),
    /// Plans: simulate one forward without devices (timeline, frames, durations, what it will not cover).
    Plan {
        #[command(subcommand)]
        action: plan::PlanCommand,
    },
}

/// Prints an error chain and maps it to an exit code (see [`exit`]).
fn report(result: anyhow::Result<()>) -> u8 {
    finish(result.map(|()| EXIT_OK))
}

/// The exit code of a subcommand that chose its own, or the error's
/// (printed). A closed standard output ends the output: exit 0, silently.
fn finish(result: anyhow::Result<u8>) -> u8 {
    match result {
        Ok(code) => code,
        Err(e) if output::is_broken_pipe(&e) => EXIT_OK,
        Err(e) => {
            eprintln!("error: {e:#}");
            exit::code_of(&e)
        }
    }
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
        Command::Config { action } => finish(config_check::run(action)),
        Command::Hdr { action } => report(hdr::run(action)),
        Command::Sun(args) => report(sun::run(args)),
        Command::Sky { action } => report(sky::run(action)),
        Command::Env { action } => report(env::run(action)),
        Command::Plan { action } => finish(plan::run(action)),
        Command::Capture(args) => finish(capture::run(args)),
        Command::Station { action } => finish(station::run(action)),
        Command::Demo(args) => report(demo::run(args)),
        Command::Session { action } => report(session::run(action)),
        Command::Process(args) => report(process::run(args)),
        Command::Devices(args) => finish(devices::run(args)),
        Command::Render(args) => report(render::run(args)),
        Command::Register(args) => finish(register::run(args)),
        Command::Texture(args) => finish(texture::run(args)),
        Command::Segment(args) => finish(segment::run(args)),
        Command::Edit(args) => finish(edit::run(args)),
        Command::Igi(args) => report(igi::run(args)),
        Command::Outdoor { action } => report(outdoor::run(action)),
    };
    ExitCode::from(code)
}

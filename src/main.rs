//! The `campanile` command line. It parses arguments and calls the crates;
//! no science and no device logic live here.

mod cli;

use std::process::ExitCode;

fn main() -> ExitCode {
    cli::run()
}

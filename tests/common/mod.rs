//! What the command-line tests share: running the binary as a user would.

use std::process::{Command, Output};

/// Runs `campanile ARGS…` from the repository root.
pub fn campanile(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_campanile"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("the binary runs")
}

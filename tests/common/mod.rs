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

/// Runs `campanile ARGS…`, asserting its exit code; returns its stdout and
/// stderr, which the assertion shows when the code differs.
#[allow(dead_code)] // not every test binary that includes this module uses it
pub fn campanile_exits(args: &[&str], code: i32) -> String {
    let out = campanile(args);
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(out.status.code(), Some(code), "campanile {args:?}:\n{text}");
    text
}

//! Standard output that never panics.
//!
//! `println!` panics when standard output is closed (`campanile … | head -1`).
//! The subcommands print through [`outln!`] and [`out!`] instead: they
//! return an `io::Result`, and a closed pipe (`BrokenPipe`) travels up the
//! error chain to `cli::run`, which treats it as the end of the output and
//! exits 0 without a message, as `ripgrep` does.

use std::fmt;
use std::io::{self, Write};

/// Writes `args` to standard output; `Err` when it is closed or failing.
pub fn write(args: fmt::Arguments<'_>) -> io::Result<()> {
    io::stdout().lock().write_fmt(args)
}

/// `print!` that returns an `io::Result` instead of panicking.
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::cli::output::write(format_args!($($arg)*))
    };
}

/// `println!` that returns an `io::Result` instead of panicking.
macro_rules! outln {
    () => {
        $crate::cli::output::write(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        $crate::cli::output::write(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// True when `err` comes from writing to a closed pipe.
pub fn is_broken_pipe(err: &anyhow::Error) -> bool {
    err.chain()
        .filter_map(|c| c.downcast_ref::<io::Error>())
        .any(|e| e.kind() == io::ErrorKind::BrokenPipe)
}

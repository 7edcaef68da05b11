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
    err.chain().any(is_broken_pipe_cause)
}

/// Whether `cause` is a closed pipe, or library work that failed on one
/// (output written from a library's callback).
fn is_broken_pipe_cause(cause: &(dyn std::error::Error + 'static)) -> bool {
    cause
        .downcast_ref::<io::Error>()
        .is_some_and(|e| e.kind() == io::ErrorKind::BrokenPipe)
        || cause
            .downcast_ref::<campanile_session::Error>()
            .is_some_and(|e| matches!(e, campanile_session::Error::Work(w) if w.chain().any(is_broken_pipe_cause)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed pipe met in a library's callback (`render` prints each
    /// frame from one) still ends the output silently.
    #[test]
    fn a_closed_pipe_inside_library_work_is_a_closed_pipe() {
        let pipe = campanile_session::Error::from(io::Error::from(io::ErrorKind::BrokenPipe));
        assert!(is_broken_pipe(&anyhow::Error::new(pipe)));
        let full = campanile_session::Error::from(io::Error::from(io::ErrorKind::StorageFull));
        assert!(!is_broken_pipe(&anyhow::Error::new(full)));
    }
}

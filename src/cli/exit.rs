//! Exit statuses, and the error kinds that choose them.
//!
//! | status | meaning |
//! |---|---|
//! | 0 | success: every product passed its quality gate (`ok` or `poor`) |
//! | 1 | failure while working (a device, a file that could not be written, a solver that broke down) |
//! | 2 | bad input or usage: an argument, a configuration file, an input file or one of its values |
//! | 3 | finished, but a product failed its quality gate (`quality.json` names it) |
//!
//! Subcommands return `anyhow::Result`. An error whose chain holds a
//! [`campanile_session::Error::Input`], or a library error that means bad
//! input (see [`is_bad_input`]), exits 2; one that holds a
//! [`campanile_session::Error::Quality`] exits 3; any other exits 1.

/// Exit code for success.
pub const EXIT_OK: u8 = 0;
/// Exit code for a failure while doing the work.
pub const EXIT_FAILURE: u8 = 1;
/// Exit code for a usage error, an invalid configuration or input file, or a bad value.
pub const EXIT_USAGE: u8 = 2;
/// Exit code for a command that finished but whose products failed a quality gate.
pub const EXIT_QUALITY: u8 = 3;

/// An `anyhow` error that exits 2, with `message` as its text.
pub fn bad_input(message: impl Into<String>) -> anyhow::Error {
    campanile_session::error::bad_input(message)
}

/// The exit status for an error: 2 for bad input, 3 for a failed quality
/// gate, 1 otherwise.
pub fn code_of(err: &anyhow::Error) -> u8 {
    if err.chain().any(is_bad_input) {
        return EXIT_USAGE;
    }
    if err.chain().any(campanile_session::error::is_quality_failure) {
        return EXIT_QUALITY;
    }
    EXIT_FAILURE
}

/// Whether `cause` means bad input (see [`campanile_session::error::is_bad_input`]).
pub fn is_bad_input(cause: &(dyn std::error::Error + 'static)) -> bool {
    campanile_session::error::is_bad_input(cause)
}

pub use campanile_session::error::shown;

/// `--error F`: a relative standard error a relight can aim at (a fraction
/// above 0 and below 1), or bad input naming the flag and the value.
pub fn error_target(error: Option<f64>) -> anyhow::Result<()> {
    match error.map(|e| (e, campanile_process::igi::error_target::ErrorTarget::new(e).check())) {
        Some((e, Err(why))) => Err(bad_input(format!("--error {}: expected {}", shown(e), why.expected))),
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use anyhow::Context;

    #[test]
    fn codes_follow_the_chain() {
        let plain = anyhow::anyhow!("disk on fire");
        assert_eq!(code_of(&plain), EXIT_FAILURE);
        let bad: anyhow::Result<()> = Err(bad_input("--lat 95: expected −90 to 90"));
        let bad = bad.context("reading the site").unwrap_err();
        assert_eq!(code_of(&bad), EXIT_USAGE);
        let q = anyhow::Error::new(campanile_session::Error::Quality {
            failed: vec!["response: condition 1e9 > 1e6".into()],
        });
        assert_eq!(code_of(&q), EXIT_QUALITY);
        assert!(
            q.to_string()
                .starts_with("finished, but products failed their quality checks: response")
        );
        let missing = std::fs::read("/no/such/input.csv")
            .map_err(anyhow::Error::from)
            .unwrap_err();
        assert_eq!(code_of(&missing.context("reading the table")), EXIT_USAGE);
        let denied = std::io::Error::from(std::io::ErrorKind::PermissionDenied);
        assert_eq!(code_of(&anyhow::Error::from(denied)), EXIT_FAILURE);
    }

    #[test]
    fn numbers_in_errors_are_short() {
        assert_eq!(shown(1e308), "1e308");
        assert_eq!(shown(-2.5e-7), "-2.5e-7");
        assert_eq!(shown(95.0), "95");
        assert_eq!(shown(-1013.25), "-1013.25");
        assert_eq!(shown(f64::NAN), "NaN");
    }
}

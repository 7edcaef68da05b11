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
//! [`BadInput`] exits 2, one that holds a [`QualityFailed`] exits 3, any
//! other exits 1.

use std::fmt;

/// Exit code for success.
pub const EXIT_OK: u8 = 0;
/// Exit code for a failure while doing the work.
pub const EXIT_FAILURE: u8 = 1;
/// Exit code for a usage error, an invalid configuration or input file, or a bad value.
pub const EXIT_USAGE: u8 = 2;
/// Exit code for a command that finished but whose products failed a quality gate.
pub const EXIT_QUALITY: u8 = 3;

/// Bad input from the user: an argument, a file or a value. Exits 2.
#[derive(Debug)]
pub struct BadInput(pub String);

impl fmt::Display for BadInput {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for BadInput {}

/// An `anyhow` error that exits 2, with `message` as its text.
#[allow(dead_code)] // until the subcommands use it (issue 21)
pub fn bad_input(message: impl Into<String>) -> anyhow::Error {
    anyhow::Error::new(BadInput(message.into()))
}

/// The command finished and wrote its products, but `failed` did not pass
/// their quality gates. Exits 3.
#[derive(Debug)]
pub struct QualityFailed {
    /// The products that failed, each with its figures.
    pub failed: Vec<String>,
}

impl fmt::Display for QualityFailed {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "finished, but products failed their quality checks: {}",
            self.failed.join("; ")
        )
    }
}

impl std::error::Error for QualityFailed {}

/// The exit status for an error: 2 for bad input, 3 for a failed quality
/// gate, 1 otherwise.
pub fn code_of(err: &anyhow::Error) -> u8 {
    for cause in err.chain() {
        if cause.is::<BadInput>() {
            return EXIT_USAGE;
        }
        if cause.is::<QualityFailed>() {
            return EXIT_QUALITY;
        }
    }
    EXIT_FAILURE
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
        let q = anyhow::Error::new(QualityFailed {
            failed: vec!["response: condition 1e9 > 1e6".into()],
        });
        assert_eq!(code_of(&q), EXIT_QUALITY);
        assert!(
            q.to_string()
                .starts_with("finished, but products failed their quality checks: response")
        );
    }
}

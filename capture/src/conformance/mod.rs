//! Conformance suites: functions that take any device behind a trait and
//! check its behaviour, in the manner of ASCOM's ConformU. CI runs them
//! against the firmware emulators; `campanile devices test` runs the same
//! functions against real hardware.

pub mod camera;
pub mod filter_wheel;
pub mod lights;
pub mod pan_tilt;

/// The outcome of one check.
#[derive(Debug, Clone, PartialEq)]
pub struct Check {
    /// What was checked.
    pub name: &'static str,
    /// `None` if it passed, otherwise what went wrong.
    pub failure: Option<String>,
}

/// The outcome of a suite.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Report {
    /// Every check, in the order run.
    pub checks: Vec<Check>,
}

impl Report {
    /// The checks that failed.
    pub fn failures(&self) -> Vec<&Check> {
        self.checks.iter().filter(|c| c.failure.is_some()).collect()
    }

    /// Whether every check passed (and at least one ran).
    pub fn passed(&self) -> bool {
        !self.checks.is_empty() && self.failures().is_empty()
    }

    fn record(&mut self, name: &'static str, result: Result<(), String>) {
        self.checks.push(Check {
            name,
            failure: result.err(),
        });
    }
}

impl std::fmt::Display for Report {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        for c in &self.checks {
            match &c.failure {
                None => writeln!(f, "pass  {}", c.name)?,
                Some(why) => writeln!(f, "FAIL  {}: {why}", c.name)?,
            }
        }
        Ok(())
    }
}

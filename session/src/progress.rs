//! Progress bars on standard error, drawn only when it is a terminal.

use std::io::IsTerminal;

use campanile_capture::controller::{Progress, ShotOutcome};
use campanile_capture::schedule::{Occurrence, PlannedShot};
use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};

/// A bar of `len` steps labelled `what` (hidden when standard error is
/// not a terminal); `finish_and_clear` it when the stage ends.
pub fn bar(len: u64, what: &str) -> ProgressBar {
    let bar = ProgressBar::new(len);
    if std::io::stderr().is_terminal() {
        bar.set_style(
            ProgressStyle::with_template("{msg:>24} [{bar:40}] {pos}/{len} {elapsed}")
                .unwrap_or_else(|_| ProgressStyle::default_bar())
                .progress_chars("=> "),
        );
    } else {
        bar.set_draw_target(ProgressDrawTarget::hidden());
    }
    bar.set_message(what.to_owned());
    bar
}

/// A capture's bars: the session's promised frames, and the current
/// occurrence's step (drawn only on a terminal).
pub struct CaptureBars {
    session: ProgressBar,
    step: ProgressBar,
    _multi: MultiProgress,
}

impl CaptureBars {
    /// Bars for a capture that promises `promised` frames.
    pub fn new(promised: usize) -> Self {
        let target = if std::io::stderr().is_terminal() {
            ProgressDrawTarget::stderr()
        } else {
            ProgressDrawTarget::hidden()
        };
        let multi = MultiProgress::with_draw_target(target);
        let style = ProgressStyle::with_template("{prefix:>24} [{bar:40}] {pos}/{len} {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> ");
        let session = multi.add(ProgressBar::new(promised as u64).with_style(style.clone()));
        session.set_prefix("session");
        let step = multi.add(ProgressBar::new(0).with_style(style));
        Self {
            session,
            step,
            _multi: multi,
        }
    }

    /// Clears both bars.
    pub fn finish(&self) {
        self.session.finish_and_clear();
        self.step.finish_and_clear();
    }
}

impl Progress for CaptureBars {
    fn occurrence(&mut self, occurrence: &Occurrence) {
        self.session.set_message(occurrence.key.clone());
    }

    fn step(&mut self, occurrence: &Occurrence, step: usize, kind: &str, shots: usize) {
        self.step.reset();
        self.step.set_length(shots as u64);
        self.step.set_prefix(format!("{} s{step} {kind}", occurrence.name));
    }

    fn shot(&mut self, shot: &PlannedShot, outcome: ShotOutcome) {
        self.step.inc(1);
        if shot.promised && outcome != ShotOutcome::NotNeeded {
            self.session.inc(1);
        }
    }
}

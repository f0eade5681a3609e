//! A progress bar with an ETA on a terminal; nothing otherwise.

use std::io::IsTerminal;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use whitted::render::Progress;

/// Shows render progress on standard error when it is a terminal.
pub struct ProgressReport {
    bar: Option<ProgressBar>,
}

impl ProgressReport {
    /// A bar over `total` pixels, shown only on a terminal and when not
    /// `quiet`.
    pub fn new(total: u64, quiet: bool) -> Self {
        let show = !quiet && std::io::stderr().is_terminal();
        let bar = show.then(|| {
            let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
            let style = ProgressStyle::with_template(
                "{spinner} rendering [{bar:40}] {percent:>3}%  {elapsed_precise} elapsed, ETA {eta_precise}",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> ");
            bar.set_style(style);
            bar
        });
        Self { bar }
    }

    /// Records progress (callable from any thread).
    pub fn update(&self, progress: Progress) {
        if let Some(bar) = &self.bar {
            bar.set_position(progress.done);
        }
    }

    /// Removes the bar.
    pub fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}

/// A spinner with a message for work of unknown length, on a terminal only.
pub struct Status {
    spinner: Option<ProgressBar>,
}

impl Status {
    /// A spinner, shown only on a terminal and when not `quiet`.
    pub fn new(quiet: bool) -> Self {
        let show = !quiet && std::io::stderr().is_terminal();
        let spinner = show.then(|| {
            let s = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
            s.enable_steady_tick(std::time::Duration::from_millis(120));
            s
        });
        Self { spinner }
    }

    /// Says what is being done now.
    pub fn set(&self, message: String) {
        if let Some(s) = &self.spinner {
            s.set_message(message);
        }
    }

    /// Removes the spinner.
    pub fn finish(&self) {
        if let Some(s) = &self.spinner {
            s.finish_and_clear();
        }
    }
}

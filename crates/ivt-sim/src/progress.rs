//! A terminal progress bar for long runs (indicatif), or nothing.

use indicatif::{ProgressBar, ProgressStyle};

/// A progress callback for [`crate::run::Simulation::progress`]: a bar on stderr when
/// `show`, else a no-op (e.g. under `--json`). Call `finish` afterwards.
pub struct Progress(Option<ProgressBar>);

impl Progress {
    /// A bar labelled `label` if `show`.
    pub fn new(show: bool, label: &str) -> Self {
        Self(show.then(|| {
            let bar = ProgressBar::new(1000);
            if let Ok(style) =
                ProgressStyle::with_template("{msg} [{bar:40}] {percent:>3}% {elapsed}")
            {
                bar.set_style(style.progress_chars("=> "));
            }
            bar.set_message(label.to_string());
            bar
        }))
    }

    /// Report the fraction done.
    pub fn update(&mut self, fraction: f64) {
        if let Some(b) = &self.0 {
            b.set_position((fraction.clamp(0.0, 1.0) * 1000.0) as u64);
        }
    }

    /// Remove the bar.
    pub fn finish(&self) {
        if let Some(b) = &self.0 {
            b.finish_and_clear();
        }
    }
}

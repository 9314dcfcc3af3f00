//! A progress bar on stderr for long work (renders, benchmarks).

use std::io::{IsTerminal, Write};
use std::time::Instant;

/// A one-line progress bar on stderr with elapsed and estimated remaining
/// time. It shows once the work has run for a second, and only on a terminal
/// unless forced.
pub struct ProgressBar {
    start: Instant,
    enabled: bool,
    shown: bool,
    label: String,
}

impl ProgressBar {
    /// A bar that starts timing now; `force` shows it even when stderr is
    /// not a terminal.
    pub fn new(force: bool) -> Self {
        Self {
            start: Instant::now(),
            enabled: force || std::io::stderr().is_terminal(),
            shown: false,
            label: String::new(),
        }
    }

    /// Text shown after the bar (what is being done now).
    pub fn set_label(&mut self, label: impl Into<String>) {
        self.label = label.into();
    }

    /// Redraws the bar at `done` of `total` units.
    pub fn update(&mut self, done: u64, total: u64) {
        let elapsed = self.start.elapsed().as_secs_f64();
        if !self.enabled || elapsed < 1.0 || total == 0 {
            return;
        }
        let frac = (done as f64 / total as f64).clamp(0.0, 1.0);
        let eta = if frac > 0.0 { elapsed * (1.0 - frac) / frac } else { 0.0 };
        let width = 30;
        let filled = (frac * width as f64) as usize;
        eprint!(
            "\r[{}{}] {:5.1}%  {:.1}s elapsed, {:.1}s left {}\x1b[K",
            "#".repeat(filled),
            " ".repeat(width - filled),
            100.0 * frac,
            elapsed,
            eta,
            self.label
        );
        let _ = std::io::stderr().flush();
        self.shown = true;
    }

    /// Ends the bar's line, if it was shown.
    pub fn finish(&self) {
        if self.shown {
            eprintln!();
        }
    }
}

//! A progress bar on stderr for long work (renders, benchmarks), drawn by
//! `indicatif`.

use std::io::{IsTerminal, Write};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use indicatif::{ProgressDrawTarget, ProgressStyle, TermLike};

/// A one-line progress bar on stderr with elapsed and estimated remaining
/// time. It shows once the work has run for a second, and only on a
/// terminal unless forced; forced onto a file or pipe, it writes a plain
/// line a second instead of redrawing one.
pub struct ProgressBar {
    bar: indicatif::ProgressBar,
    start: Instant,
    /// Where it draws, until it is shown.
    target: Arc<Mutex<Option<ProgressDrawTarget>>>,
    /// Whether it still shows [`COMPILING`] instead of the bar.
    compiling: bool,
}

/// What the line says before the first unit of work is done, where
/// [`ProgressBar::compiling`] asks for it: a Vulkan driver may compile the
/// shaders at their first dispatch (lavapipe does), for seconds to a minute
/// the first time a variant is used and never again (its shader cache).
pub const COMPILING: &str = "compiling shaders (first use of this variant)";

/// The bar's template.
const BAR: &str = "[{bar:30}] {percent:>3}%  {elapsed} elapsed, {eta} left {msg}";

/// Draws on stderr as lines: for logs, where cursor movement would leave
/// control characters.
#[derive(Debug)]
struct LogLines;

impl TermLike for LogLines {
    fn width(&self) -> u16 {
        100
    }
    fn move_cursor_up(&self, _: usize) -> std::io::Result<()> {
        Ok(())
    }
    fn move_cursor_down(&self, _: usize) -> std::io::Result<()> {
        Ok(())
    }
    fn move_cursor_right(&self, _: usize) -> std::io::Result<()> {
        Ok(())
    }
    fn move_cursor_left(&self, _: usize) -> std::io::Result<()> {
        Ok(())
    }
    fn write_line(&self, s: &str) -> std::io::Result<()> {
        writeln!(std::io::stderr(), "{s}")
    }
    fn write_str(&self, s: &str) -> std::io::Result<()> {
        if s.trim().is_empty() {
            return Ok(());
        }
        writeln!(std::io::stderr(), "{s}")
    }
    fn clear_line(&self) -> std::io::Result<()> {
        Ok(())
    }
    fn flush(&self) -> std::io::Result<()> {
        std::io::stderr().flush()
    }
}

impl ProgressBar {
    /// A bar that starts timing now; `force` shows it even when stderr is
    /// not a terminal.
    pub fn new(force: bool) -> Self {
        let target = if std::io::stderr().is_terminal() {
            Some(ProgressDrawTarget::stderr())
        } else if force {
            Some(ProgressDrawTarget::term_like_with_hz(Box::new(LogLines), 1))
        } else {
            None
        };
        let bar = indicatif::ProgressBar::with_draw_target(None, ProgressDrawTarget::hidden());
        bar.set_style(ProgressStyle::with_template(BAR).expect("a valid template").progress_chars("#> "));
        Self { bar, start: Instant::now(), target: Arc::new(Mutex::new(target)), compiling: false }
    }

    /// Until the first [`ProgressBar::update`], the line says [`COMPILING`]
    /// with the time elapsed (redrawn every second from a thread, since the
    /// work reports nothing while the driver compiles), shown after a
    /// second as the bar is.
    pub fn compiling(mut self) -> Self {
        self.compiling = true;
        self.bar.set_style(ProgressStyle::with_template("{spinner} {msg}: {elapsed}").expect("a valid template"));
        self.bar.set_message(COMPILING);
        let (bar, target) = (self.bar.clone(), self.target.clone());
        std::thread::spawn(move || {
            std::thread::sleep(Duration::from_secs(1));
            let Ok(mut target) = target.lock() else { return };
            if let Some(t) = target.take() {
                bar.set_draw_target(t);
                bar.enable_steady_tick(Duration::from_secs(1));
            }
        });
        self
    }

    /// Text shown after the bar (what is being done now).
    pub fn set_label(&mut self, label: impl Into<String>) {
        self.bar.set_message(label.into());
    }

    /// Moves the bar to `done` of `total` units.
    pub fn update(&mut self, done: u64, total: u64) {
        if total == 0 {
            return;
        }
        if self.compiling {
            self.compiling = false;
            self.bar.disable_steady_tick();
            self.bar.set_style(ProgressStyle::with_template(BAR).expect("a valid template").progress_chars("#> "));
            self.bar.set_message("");
        }
        self.bar.set_length(total);
        self.bar.set_position(done.min(total));
        if self.start.elapsed() >= Duration::from_secs(1) {
            if let Some(target) = self.target.lock().ok().and_then(|mut t| t.take()) {
                self.bar.set_draw_target(target);
            }
        }
    }

    /// Ends the bar's line, if it was shown.
    pub fn finish(&self) {
        // A line not shown yet never will be.
        if let Ok(mut t) = self.target.lock() {
            t.take();
        }
        self.bar.disable_steady_tick();
        if !self.bar.is_hidden() {
            self.bar.finish();
        }
    }
}

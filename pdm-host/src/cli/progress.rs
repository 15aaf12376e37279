//! The progress bar on stderr: shown only when stderr is a terminal and only once the
//! computation has run for more than a second.

use std::io::IsTerminal as _;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use pdm_host::validate::Progress;

/// Delay before the bar appears.
const SHOW_AFTER: Duration = Duration::from_secs(1);

/// An indicatif bar that stays hidden for the first second and when stderr is not a terminal.
pub struct Bar {
    bar: ProgressBar,
    start: Instant,
    terminal: bool,
    shown: AtomicBool,
}

impl Bar {
    /// A bar over `total` patches.
    pub fn new(total: u64) -> Self {
        Self::with_units(total, "patches")
    }

    /// A bar over `total` units named `units`.
    pub fn with_units(total: u64, units: &str) -> Self {
        let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::hidden());
        let template = format!("{{msg:<15}} [{{bar:30}}] {{pos}}/{{len}} {units}, {{elapsed}} (eta {{eta}})");
        if let Ok(style) = ProgressStyle::with_template(&template) {
            bar.set_style(style.progress_chars("=> "));
        }
        Self { bar, start: Instant::now(), terminal: std::io::stderr().is_terminal(), shown: AtomicBool::new(false) }
    }

    fn maybe_show(&self) {
        if self.terminal && self.start.elapsed() > SHOW_AFTER && !self.shown.swap(true, Ordering::Relaxed) {
            self.bar.set_draw_target(ProgressDrawTarget::stderr_with_hz(8));
        }
    }

    /// Sets the units done.
    pub fn set_position(&self, done: u64) {
        self.bar.set_position(done);
        self.maybe_show();
    }

    /// Removes the bar from the terminal.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

impl Progress for Bar {
    fn stage(&self, label: &str) {
        self.bar.set_message(label.to_string());
        self.maybe_show();
    }
    fn advance(&self, n: u64) {
        self.bar.inc(n);
        self.maybe_show();
    }
}

/// A spinner with the elapsed time for a computation that reports no units (the independent
/// reference), on stderr when it is a terminal; hidden otherwise.
pub struct Spinner {
    bar: ProgressBar,
}

impl Spinner {
    /// Starts spinning with `message`.
    pub fn new(message: String) -> Self {
        if !std::io::stderr().is_terminal() {
            return Self { bar: ProgressBar::hidden() };
        }
        let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr_with_hz(4));
        if let Ok(style) = ProgressStyle::with_template("{spinner} {msg} ({elapsed})") {
            bar.set_style(style);
        }
        bar.set_message(message);
        bar.enable_steady_tick(Duration::from_millis(250));
        Self { bar }
    }

    /// Removes the spinner from the terminal.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

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
    /// A bar over `total` units.
    pub fn new(total: u64) -> Self {
        let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::hidden());
        if let Ok(style) =
            ProgressStyle::with_template("{msg:<15} [{bar:30}] {pos}/{len} patches, {elapsed} (eta {eta})")
        {
            bar.set_style(style.progress_chars("=> "));
        }
        Self { bar, start: Instant::now(), terminal: std::io::stderr().is_terminal(), shown: AtomicBool::new(false) }
    }

    fn maybe_show(&self) {
        if self.terminal && self.start.elapsed() > SHOW_AFTER && !self.shown.swap(true, Ordering::Relaxed) {
            self.bar.set_draw_target(ProgressDrawTarget::stderr_with_hz(8));
        }
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

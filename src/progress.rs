//! A progress bar for long runs: it appears only once a run has lasted a second, and only when
//! stdout is a terminal (so logs and pipes stay clean).

use std::io::IsTerminal;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};

pub struct Progress {
    start: Instant,
    total: u64,
    enabled: bool,
    bar: Option<ProgressBar>,
}

impl Progress {
    /// A progress over `total` steps; `enabled` false keeps it silent (library use, tests).
    pub fn new(total: usize, enabled: bool) -> Self {
        Progress {
            start: Instant::now(),
            total: total as u64,
            enabled: enabled && std::io::stdout().is_terminal(),
            bar: None,
        }
    }

    /// Reports that `done` steps are complete.
    pub fn tick(&mut self, done: usize) {
        if !self.enabled {
            return;
        }
        if self.bar.is_none() && self.start.elapsed() > Duration::from_secs(1) {
            let bar = ProgressBar::new(self.total);
            if let Ok(style) =
                ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {pos}/{len} steps, {per_sec}, eta {eta}")
            {
                bar.set_style(style.progress_chars("=> "));
            }
            self.bar = Some(bar);
        }
        if let Some(bar) = &self.bar {
            bar.set_position(done as u64);
        }
    }

    pub fn finish(&mut self) {
        if let Some(bar) = self.bar.take() {
            bar.finish_and_clear();
        }
    }
}

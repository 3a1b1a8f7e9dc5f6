//! A progress bar on stderr (`indicatif`) for renders that take longer than a
//! second: it counts tiles from the start but stays hidden until the first
//! second has passed, and never shows when stderr is not a terminal, so short
//! renders, pipes and CI logs stay clean.

use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// How long a render runs before its bar appears.
const DELAY: Duration = Duration::from_secs(1);

/// Tile progress of one render. 48 bytes (the bar itself is shared on the heap).
#[derive(Debug)]
pub struct Progress {
    bar: ProgressBar,
    start: Instant,
    /// Whether the bar may ever be shown (stderr is a terminal).
    enabled: bool,
    shown: AtomicBool,
}

impl Progress {
    /// A bar over `tiles` tiles, shown after a second when stderr is a terminal.
    pub fn new(tiles: usize) -> Self {
        Self::with_terminal(tiles, std::io::stderr().is_terminal())
    }

    /// A bar that shows after a second only if `enabled`.
    pub fn with_terminal(tiles: usize, enabled: bool) -> Self {
        let bar = ProgressBar::with_draw_target(Some(tiles as u64), ProgressDrawTarget::hidden());
        bar.set_style(
            ProgressStyle::with_template("{elapsed:>4} [{bar:40}] {pos}/{len} tiles, eta {eta}")
                .expect("valid template")
                .progress_chars("=> "),
        );
        Self {
            bar,
            start: Instant::now(),
            enabled,
            shown: AtomicBool::new(false),
        }
    }

    /// One more tile done; shows the bar once the delay has passed.
    pub fn tile_done(&self) {
        self.bar.inc(1);
        if self.enabled && !self.shown.load(Ordering::Relaxed) && self.start.elapsed() >= DELAY {
            // Only the first thread to get here switches the bar on.
            if !self.shown.swap(true, Ordering::Relaxed) {
                self.bar.set_draw_target(ProgressDrawTarget::stderr());
            }
        }
    }

    /// Tiles done so far.
    pub fn done(&self) -> u64 {
        self.bar.position()
    }

    /// Whether the bar has been switched on.
    pub fn is_shown(&self) -> bool {
        self.shown.load(Ordering::Relaxed)
    }

    /// Remove the bar from the terminal.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_tiles_and_stays_hidden_without_a_terminal_or_before_a_second() {
        let quiet = Progress::with_terminal(10, false);
        for _ in 0..10 {
            quiet.tile_done();
        }
        assert_eq!(quiet.done(), 10);
        assert!(!quiet.is_shown());
        let fast = Progress::with_terminal(3, true);
        fast.tile_done();
        assert!(!fast.is_shown(), "shown before its delay");
        quiet.finish();
        fast.finish();
    }
}

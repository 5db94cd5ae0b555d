//! A progress bar on stderr while a body file is read and packed: drawn only when stderr
//! is a terminal and the work has already taken a second, so that a quick command, a
//! pipe or a log file sees nothing of it. The library tells how far reading has come
//! through a callback (`fxbody::body::LoadOptions::progress`); this module only draws.

use std::io::IsTerminal;
use std::sync::mpsc::{self, RecvTimeoutError, Sender};
use std::thread::JoinHandle;
use std::time::Duration;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// How long the work runs before the bar appears; `FXBODY_PROGRESS_DELAY_MS` overrides it
/// (the tests set 0 to see the bar, or its absence, on a small body).
fn delay() -> Duration {
    std::env::var("FXBODY_PROGRESS_DELAY_MS")
        .ok()
        .and_then(|v| v.parse().ok())
        .map_or(Duration::from_secs(1), Duration::from_millis)
}

/// The bar of one command; cleared when dropped (before any error message is printed).
pub struct Progress {
    bar: ProgressBar,
    /// What follows reading (`checking`, `packing`), shown once every byte is read.
    after: &'static str,
    /// Dropping the sender tells the thread that shows the bar that the work is done.
    shower: Option<(Sender<()>, JoinHandle<()>)>,
}

impl Progress {
    /// A bar for reading a body file, then doing `after`; hidden unless stderr is a
    /// terminal and the work lasts longer than [`delay`].
    pub fn start(after: &'static str) -> Progress {
        let bar = ProgressBar::hidden();
        let style = ProgressStyle::with_template(
            "{msg} [{wide_bar}] {bytes}/{total_bytes} ({binary_bytes_per_sec})",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar())
        .progress_chars("=> ");
        bar.set_style(style);
        bar.set_message("reading");
        let delay = delay();
        let terminal = std::io::stderr().is_terminal();
        if terminal && delay.is_zero() {
            // Due at once: shown here, not by a thread that the work might outrun.
            show(&bar);
        }
        let shower = (terminal && !delay.is_zero()).then(|| {
            let (done, wait) = mpsc::channel::<()>();
            let shown = bar.clone();
            let thread = std::thread::spawn(move || {
                if wait.recv_timeout(delay) == Err(RecvTimeoutError::Timeout) {
                    show(&shown);
                    // Until the work is done (the sender is dropped).
                    let _ = wait.recv();
                }
            });
            (done, thread)
        });
        Progress { bar, after, shower }
    }

    /// Reading has come to `done` of `total` bytes (the library's callback).
    pub fn update(&self, done: u64, total: u64) {
        self.bar.set_length(total);
        self.bar.set_position(done);
        if done >= total {
            self.bar.set_message(self.after);
        }
    }
}

/// Draw `bar` on stderr from now on, redrawn ten times a second.
fn show(bar: &ProgressBar) {
    bar.set_draw_target(ProgressDrawTarget::stderr());
    bar.enable_steady_tick(Duration::from_millis(100));
}

impl Drop for Progress {
    fn drop(&mut self) {
        if let Some((done, thread)) = self.shower.take() {
            drop(done);
            let _ = thread.join();
        }
        self.bar.finish_and_clear();
    }
}

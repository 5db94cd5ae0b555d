//! The whole-model import's stages on stderr: one spinner line naming the stage in work
//! (read, order and factor, eigen-solve, static modes, projection, body, write) and the
//! time it has taken, each finished stage left as a line with its time. Drawn only when
//! stderr is a terminal and `--quiet` is not given, so pipes, logs and tests see nothing.

use std::io::IsTerminal;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// The stage display of one import; the last stage is finished when dropped.
pub struct StageBar {
    bar: Option<ProgressBar>,
    current: Option<(String, Instant)>,
}

impl StageBar {
    /// A display on stderr, or none when `quiet` or stderr is not a terminal.
    pub fn new(quiet: bool) -> StageBar {
        let shown = !quiet && std::io::stderr().is_terminal();
        let bar = shown.then(|| {
            let bar = ProgressBar::new_spinner();
            bar.set_draw_target(ProgressDrawTarget::stderr());
            let style = ProgressStyle::with_template("{spinner} import: {msg} ({elapsed})")
                .unwrap_or_else(|_| ProgressStyle::default_spinner());
            bar.set_style(style);
            bar.enable_steady_tick(Duration::from_millis(100));
            bar
        });
        StageBar { bar, current: None }
    }

    /// The stage `name` starts now (the one before ends).
    pub fn stage(&mut self, name: &str) {
        self.finish();
        if let Some(bar) = &self.bar {
            bar.reset_elapsed();
            bar.set_message(name.to_string());
        }
        self.current = Some((name.to_string(), Instant::now()));
    }

    fn finish(&mut self) {
        if let (Some(bar), Some((name, t))) = (&self.bar, self.current.take()) {
            bar.println(format!(
                "  import: {name:<18} {:8.2} s",
                t.elapsed().as_secs_f64()
            ));
        }
    }
}

impl Drop for StageBar {
    fn drop(&mut self) {
        self.finish();
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}

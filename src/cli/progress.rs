//! What the command line shows while the pipeline runs: per stage on standard error (only on a
//! terminal, never with `-q`, and only once a stage has run for a second), a bar with the
//! position, length, percentage and ETA for a stage that reports its progress
//! ([`Observer::progress`]), a spinner for one that does not; and the stage timings for
//! `--timings`.

use std::io::IsTerminal as _;
use std::time::Duration;

use hypersynth::limits::MemoryLimit;
use hypersynth::stage::{Observer, Stage, Timings};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use super::output;

/// Records the timings and shows a spinner or a bar for the stage that is running.
pub struct Progress {
    pub timings: Timings,
    bar: Option<ProgressBar>,
    /// Whether the running stage's bar shows a fraction yet.
    has_length: bool,
    show: bool,
}

/// How long a stage runs before anything about it is drawn.
const DELAY: Duration = Duration::from_secs(1);
/// How often a visible spinner or bar is redrawn.
const REDRAW: Duration = Duration::from_millis(100);

impl Progress {
    pub fn new() -> Progress {
        Progress {
            timings: Timings::default(),
            bar: None,
            has_length: false,
            show: !output::quiet() && std::io::stderr().is_terminal(),
        }
    }

    /// The `--timings` line: seconds per stage that ran, then the total.
    pub fn timings_line(&self) -> String {
        let stages: Vec<String> = Stage::ALL
            .into_iter()
            .filter(|&stage| self.timings.get(stage) > 0.0)
            .map(|stage| format!("{} {:.3}", stage.name(), self.timings.get(stage)))
            .collect();
        format!(
            "timings: {}; total {:.3} s",
            stages.join(", "),
            self.timings.total()
        )
    }
}

impl Observer for Progress {
    fn started(&mut self, stage: Stage) {
        self.has_length = false;
        if !self.show {
            return;
        }
        // Hidden until the stage has run for a second: a helper thread then moves it to
        // standard error and starts redrawing it, unless the stage has ended (and dropped it).
        let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::hidden());
        bar.set_style(
            ProgressStyle::with_template("hypersynth: {spinner} {msg} ({elapsed})")
                .unwrap_or_else(|_| ProgressStyle::default_spinner()),
        );
        bar.set_message(stage.name());
        let later = bar.downgrade();
        std::thread::spawn(move || {
            std::thread::sleep(DELAY);
            if let Some(bar) = later.upgrade()
                && !bar.is_finished()
            {
                output::showing(&bar);
                bar.set_draw_target(ProgressDrawTarget::stderr());
                bar.enable_steady_tick(REDRAW);
            }
        });
        self.bar = Some(bar);
    }

    fn progress(&mut self, _stage: Stage, done: u64, total: u64) {
        let Some(bar) = &self.bar else {
            return;
        };
        if !self.has_length {
            self.has_length = true;
            bar.set_style(
                ProgressStyle::with_template(
                    "hypersynth: {msg} [{wide_bar}] {human_pos}/{human_len} ({percent}%, ETA {eta})",
                )
                .unwrap_or_else(|_| ProgressStyle::default_bar())
                .progress_chars("=> "),
            );
            bar.set_length(total);
        }
        bar.set_position(done);
    }

    fn finished(&mut self, stage: Stage, seconds: f64) {
        if let Some(bar) = self.bar.take() {
            bar.finish_and_clear();
        }
        self.timings.finished(stage, seconds);
    }

    fn warning(&mut self, message: &str) {
        output::warn(message);
    }

    /// Against `--max-memory`, with what is resident now.
    fn reserve(
        &mut self,
        _stage: Stage,
        bytes: u64,
        what: &dyn Fn() -> String,
    ) -> Result<(), MemoryLimit> {
        super::memory::reserve(bytes, what)
    }
}

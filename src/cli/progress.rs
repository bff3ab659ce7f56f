//! What the command line shows while the pipeline runs: per stage on standard error (only on a
//! terminal, never with `-q`, and only once a stage has run for a second), a bar with the
//! position, length, percentage and ETA for a stage that reports its progress
//! ([`Observer::progress`]), a spinner for one that does not; and the stage timings for
//! `--stats`.

use std::io::IsTerminal as _;
use std::time::{Duration, Instant};

use hypersynth::stage::{Observer, Stage, Timings};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// Records the timings and shows a spinner for the stage that is running.
pub struct Progress {
    pub timings: Timings,
    spinner: Option<ProgressBar>,
    /// When the running stage started, and whether its bar shows a fraction yet.
    since: Instant,
    has_length: bool,
    show: bool,
}

/// How long a stage runs before anything about it is drawn.
const DELAY: Duration = Duration::from_secs(1);

impl Progress {
    pub fn new() -> Progress {
        Progress {
            timings: Timings::default(),
            spinner: None,
            since: Instant::now(),
            has_length: false,
            show: !super::quiet() && std::io::stderr().is_terminal(),
        }
    }

    /// The `--stats` line: seconds per stage that ran, then the total.
    pub fn stats_line(&self) -> String {
        let stages: Vec<String> = Stage::ALL
            .into_iter()
            .filter(|&stage| self.timings.get(stage) > 0.0)
            .map(|stage| format!("{} {:.3}", stage.name(), self.timings.get(stage)))
            .collect();
        format!(
            "stats: {}; total {:.3} s",
            stages.join(", "),
            self.timings.total()
        )
    }
}

impl Observer for Progress {
    fn started(&mut self, stage: Stage) {
        if self.show {
            // The spinner draws nothing until its first tick, a second from now.
            let spinner = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
            spinner.set_style(
                ProgressStyle::with_template("hypersynth: {spinner} {msg} ({elapsed})")
                    .unwrap_or_else(|_| ProgressStyle::default_spinner()),
            );
            spinner.set_message(stage.name());
            spinner.enable_steady_tick(DELAY);
            self.spinner = Some(spinner);
            self.since = Instant::now();
            self.has_length = false;
        }
    }

    fn progress(&mut self, _stage: Stage, done: u64, total: u64) {
        let Some(bar) = &self.spinner else {
            return;
        };
        // Setting a length draws at once: not before the stage has run for a second.
        if self.since.elapsed() < DELAY {
            return;
        }
        if !self.has_length {
            self.has_length = true;
            bar.set_style(
                ProgressStyle::with_template(
                    "hypersynth: {msg} [{bar:30}] {human_pos}/{human_len} ({percent}%, ETA {eta})",
                )
                .unwrap_or_else(|_| ProgressStyle::default_bar())
                .progress_chars("=> "),
            );
            bar.set_length(total);
        }
        bar.set_position(done);
    }

    fn finished(&mut self, stage: Stage, seconds: f64) {
        if let Some(spinner) = self.spinner.take() {
            spinner.finish_and_clear();
        }
        self.timings.finished(stage, seconds);
    }

    fn warning(&mut self, message: &str) {
        super::warn(message);
    }
}

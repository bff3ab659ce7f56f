//! What the command line shows while the pipeline runs: a spinner per stage on standard error
//! (only on a terminal, never with `-q`, and only once a stage has run for a second), and the
//! stage timings for `--stats`.

use std::io::IsTerminal as _;
use std::time::Duration;

use hypersynth::stage::{Observer, Stage, Timings};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// Records the timings and shows a spinner for the stage that is running.
pub struct Progress {
    pub timings: Timings,
    spinner: Option<ProgressBar>,
    show: bool,
}

impl Progress {
    pub fn new() -> Progress {
        Progress {
            timings: Timings::default(),
            spinner: None,
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
            spinner.enable_steady_tick(Duration::from_secs(1));
            self.spinner = Some(spinner);
        }
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

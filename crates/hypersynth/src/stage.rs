//! The pipeline's stages, how long each took, and a hook to watch them run.
//!
//! The library never prints: a caller that wants progress bars or a timing line passes an
//! [`Observer`] to the stages that take one, and is told when each stage starts and ends.
//! [`Timings`] is an observer that records the seconds per stage; `()` ignores everything.
//!
//! ```
//! use hypersynth::stage::{Stage, Timings, timed};
//!
//! let mut timings = Timings::default();
//! let sum = timed(&mut timings, Stage::Solve, || (1..=10).sum::<u32>());
//! assert_eq!(sum, 55);
//! assert!(timings.get(Stage::Solve) >= 0.0);
//! ```

use std::time::Instant;

use serde::Serialize;

/// A stage of the pipeline, in pipeline order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Stage {
    /// Reading the arena (and the formulas' syntax).
    Parse,
    /// Formulas to DFAs (or HOA files read).
    Translate,
    /// The hypergame product.
    Product,
    /// The three attractors and win-labels.
    Attractors,
    /// The adversary model.
    Adversary,
    /// The hypergame MDP.
    MdpBuild,
    /// The certified values.
    Solve,
    /// The opportunistic policy (tie-breaking included).
    Policy,
    /// The controller evaluated as a Markov chain.
    Evaluation,
    /// Simulated runs and the trace.
    Simulation,
}

impl Stage {
    /// Every stage, in pipeline order: `stage as usize` is the index of `stage` here.
    pub const ALL: [Stage; 10] = [
        Stage::Parse,
        Stage::Translate,
        Stage::Product,
        Stage::Attractors,
        Stage::Adversary,
        Stage::MdpBuild,
        Stage::Solve,
        Stage::Policy,
        Stage::Evaluation,
        Stage::Simulation,
    ];

    /// The stage's name in reports (the JSON key of [`Timings`]).
    pub fn name(self) -> &'static str {
        match self {
            Stage::Parse => "parse",
            Stage::Translate => "translate",
            Stage::Product => "product",
            Stage::Attractors => "attractors",
            Stage::Adversary => "adversary",
            Stage::MdpBuild => "mdp_build",
            Stage::Solve => "solve",
            Stage::Policy => "policy",
            Stage::Evaluation => "evaluation",
            Stage::Simulation => "simulation",
        }
    }
}

/// Told when stages start and finish, and of warnings about the input (all default to doing
/// nothing).
pub trait Observer {
    /// `stage` starts.
    fn started(&mut self, _stage: Stage) {}
    /// `stage` finished after `seconds`.
    fn finished(&mut self, _stage: Stage, _seconds: f64) {}
    /// Something about the input deserves a warning (one line, no trailing period).
    fn warning(&mut self, _message: &str) {}
}

impl Observer for () {}

/// Runs `work` as `stage`, telling `observer`.
pub fn timed<T>(observer: &mut dyn Observer, stage: Stage, work: impl FnOnce() -> T) -> T {
    observer.started(stage);
    let start = Instant::now();
    let result = work();
    observer.finished(stage, start.elapsed().as_secs_f64());
    result
}

/// Seconds spent in each stage (0 for stages that did not run).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Timings {
    seconds: [f64; Stage::ALL.len()],
}

impl Timings {
    /// The seconds spent in `stage` (0 when it did not run).
    pub fn get(&self, stage: Stage) -> f64 {
        self.seconds[stage as usize]
    }

    /// The seconds spent in all stages together.
    pub fn total(&self) -> f64 {
        self.seconds.iter().sum()
    }
}

impl Observer for Timings {
    fn finished(&mut self, stage: Stage, seconds: f64) {
        self.seconds[stage as usize] += seconds;
    }
}

impl Serialize for Timings {
    /// An object with one key per stage, in pipeline order, and `total`.
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut map = serializer.serialize_map(Some(Stage::ALL.len() + 1))?;
        for stage in Stage::ALL {
            map.serialize_entry(stage.name(), &self.get(stage))?;
        }
        map.serialize_entry("total", &self.total())?;
        map.end()
    }
}

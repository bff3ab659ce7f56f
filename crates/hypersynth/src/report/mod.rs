//! Reports of every stage as text tables and JSON.
//!
//! A [`Report`] holds the problem's [`Presentation`], the games stage's summary ([`Games`]) and,
//! unless the problem stopped after the games, the MDP stage's [`Synthesis`]: one data model,
//! written as text by `text.rs` and as JSON by `json.rs`, both in the words and layout the
//! presentation gives (the paper's terms or the general form's). `games.rs` also holds the
//! export of the reactive strategies. **Invariant:** nothing here computes a stage; the
//! pipeline hands every value in.

mod games;
mod json;
mod synthesis;
mod text;

use std::fmt;

pub use games::{
    ArenaSummary, AutomatonSummary, BeliefSummary, Games, InitialSummary, ProductFacts,
    RegionFacts, RegionSummary, SetPayoff, StrategyExport, TaskAutomaton, TaskSummary,
};
pub use synthesis::{
    InitialDecision, RobustChoice, RobustSimulation, RobustSummary, Settings, SolverSummary,
    StageError, Synthesis, TraceReport, TraceRow,
};
pub(crate) use synthesis::{moves, number};
pub use text::counted;

use crate::opportunistic::presentation::Presentation;
use crate::stage::Timings;

/// The report of a run: how it is named, the games and, unless it stopped after them, the MDP
/// stage.
#[derive(Clone, Debug, PartialEq)]
pub struct Report {
    /// How the problem is named and laid out.
    pub presentation: Presentation,
    /// The games stage.
    pub games: Games,
    /// The MDP stage, `None` for a run that stopped after the games.
    pub synthesis: Option<Synthesis>,
}

impl Report {
    /// The report as JSON text (pretty, with a final newline), with the stage timings under
    /// `timings` (last) when given. Keys come in a fixed order (`json.rs` lists it).
    pub fn to_json(&self, timings: Option<&Timings>) -> Result<String, serde_json::Error> {
        let json = json::Json {
            presentation: &self.presentation,
            games: &self.games,
            synthesis: self.synthesis.as_ref(),
            timings,
        };
        Ok(serde_json::to_string_pretty(&json)? + "\n")
    }
}

/// The text report.
impl fmt::Display for Report {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        text::write(f, &self.presentation, &self.games, self.synthesis.as_ref())
    }
}

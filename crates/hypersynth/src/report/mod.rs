//! Reports of every stage as text tables and JSON, in the paper's form or the general one.
//!
//! A [`Report`] holds the games stage's summary ([`Games`]: the paper's [`GamesReport`] or the
//! general [`SubtaskGamesReport`]) and, unless the problem stopped after the games, the MDP
//! stage's [`Synthesis`], one type for both forms. `games.rs` and `general.rs` hold the two
//! forms' games summaries, `paper.rs` and `general.rs` the two presentations of the synthesis,
//! `synthesis.rs` its data and the text both print. **Invariant:** nothing here computes a
//! stage; the pipeline hands every value in.

mod games;
mod general;
mod paper;
mod synthesis;

use std::fmt;

pub use games::{
    ArenaSummary, AutomataSummary, AutomatonSummary, GamesReport, InitialSummary, PerTask,
    StrategyExport, TaskAutomaton,
};
pub use general::{
    BeliefSummary, RegionSummary, SetPayoff, SubtaskGamesReport, SubtaskInitial,
    SubtaskStrategyExport, SubtaskSummary,
};
pub use paper::{OutcomeCounts, RunOutcome};
pub use synthesis::{
    CurvePoint, InitialDecision, RobustChoice, RobustSimulation, RobustSummary, Settings,
    SolverSummary, StageError, Synthesis, TraceReport, TraceRow,
};
pub(crate) use synthesis::{moves, number};

use crate::game::Form;
use crate::stage::Timings;

/// The games stage's summary, in the problem's form.
#[derive(Clone, Debug, PartialEq)]
pub enum Games {
    /// The paper's: win-labels of `phi1`, `phi2`, `phi`.
    Paper(Box<GamesReport>),
    /// The general form's: regions of every set of sub-tasks and their labels.
    General(Box<SubtaskGamesReport>),
}

/// The report of a run: the games and, unless it stopped after them, the MDP stage.
#[derive(Clone, Debug, PartialEq)]
pub struct Report {
    /// The games stage.
    pub games: Games,
    /// The MDP stage, `None` for a run that stopped after the games.
    pub synthesis: Option<Synthesis>,
}

impl Report {
    /// The form the report is presented in.
    pub fn form(&self) -> Form {
        match self.games {
            Games::Paper(_) => Form::Paper,
            Games::General(_) => Form::General,
        }
    }

    /// The report as JSON text (pretty, with a final newline), with the stage timings under
    /// `timings` when given. The paper's form sorts its keys; the general form keeps its
    /// fields' order (see the presentations' documentation).
    pub fn to_json(&self, timings: Option<&Timings>) -> Result<String, serde_json::Error> {
        let text = match &self.games {
            Games::Paper(games) => {
                let mut value = paper::to_json(games, self.synthesis.as_ref())?;
                if let (Some(timings), serde_json::Value::Object(map)) = (timings, &mut value) {
                    map.insert("timings".into(), serde_json::to_value(timings)?);
                }
                serde_json::to_string_pretty(&value)?
            }
            Games::General(games) => serde_json::to_string_pretty(&general::Json::new(
                games,
                self.synthesis.as_ref(),
                timings,
            ))?,
        };
        Ok(text + "\n")
    }
}

/// The text report.
impl fmt::Display for Report {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.games {
            Games::Paper(games) => write!(f, "{games}")?,
            Games::General(games) => write!(f, "{games}")?,
        }
        match (&self.games, &self.synthesis) {
            (_, None) => Ok(()),
            (Games::Paper(_), Some(synthesis)) => paper::write(f, synthesis),
            (Games::General(_), Some(synthesis)) => general::write(f, synthesis),
        }
    }
}

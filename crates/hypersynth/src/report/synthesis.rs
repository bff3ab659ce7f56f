//! What the MDP stage reports: its settings, the MDP's sizes, the solver's figures, the value of
//! h0 and the controller's first decision there, and when asked for a decision table, a
//! simulation and a trace ([`Synthesis`]).

use serde::Serialize;

use crate::mdp::robust::IntervalError;
use crate::mdp::solve::SolveError;
use crate::opportunistic::adversary::AdversaryError;
use crate::opportunistic::build::{BuildError, MdpSizes, Risk};
use crate::opportunistic::controller::Explanation;
use crate::opportunistic::evaluate::EvaluationError;
use crate::opportunistic::observations::{CurvePoint, ObservationsErrors, RegionError};
use crate::opportunistic::simulate::{Ending, Simulation};

/// Why the MDP stage (adversary model, MDP, solution, controller evaluation) failed.
#[derive(Debug, thiserror::Error)]
pub enum StageError {
    /// The adversary's weights file is malformed or does not match the arena.
    #[error(transparent)]
    Adversary(#[from] AdversaryError),
    /// The MDP could not be built (an arena action named `stop`).
    #[error(transparent)]
    Build(#[from] BuildError),
    /// Value iteration was refused or did not reach the requested precision.
    #[error(transparent)]
    Solve(#[from] SolveError),
    /// The controller's Markov chains did not reach the requested precision.
    #[error(transparent)]
    Evaluation(#[from] EvaluationError),
    /// A run of the observations that does not fit the game.
    #[error(transparent)]
    Observations(ObservationsErrors),
    /// A confidence parameter outside (0, 1).
    #[error(transparent)]
    Region(#[from] RegionError),
    /// A learning curve's point that uses no run, or more runs than were observed.
    #[error(
        "a learning curve point uses the first {runs} runs, but the observations have {available} \
         (a point uses 1 to {available})"
    )]
    CurveRuns {
        /// The runs the point asks for.
        runs: usize,
        /// The runs observed.
        available: usize,
    },
    /// A learning curve asked of observations that hold no run.
    #[error("a learning curve needs observed runs, and the observations have none")]
    CurveWithoutRuns,
    /// Intervals the region cannot give (a bug, never an input error).
    #[error("internal error: {0}")]
    Intervals(#[from] IntervalError),
    /// The controller collects less (or more) than the certified value: a bug, never an input
    /// error.
    #[error(
        "internal error: the controller's value at h0 is in [{policy_lower}, {policy_upper}] \
         but the certified value is in [{lower}, {upper}]"
    )]
    ControllerMismatch {
        /// Lower bound of the controller's own value at h0.
        policy_lower: f64,
        /// Upper bound of the controller's own value at h0.
        policy_upper: f64,
        /// Lower bound of the certified value of h0.
        lower: f64,
        /// Upper bound of the certified value of h0.
        upper: f64,
    },
}

/// One row of the decision table at h0: an action's robust and nominal values.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RobustChoice {
    /// The action (an arena action or `stop`).
    pub action: String,
    /// Its robust value (the lower bounds after it, the worst reply within the region).
    pub robust: f64,
    /// Its nominal value (the estimate's lower bounds after it).
    pub nominal: f64,
}

/// The robust controller simulated against the given adversary model (the "truth").
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RobustSimulation {
    /// Runs simulated.
    pub runs: u32,
    /// Mean payoff collected.
    pub mean_payoff: f64,
    /// 95% confidence interval of the mean.
    pub ci_low: f64,
    /// Upper end of the interval.
    pub ci_high: f64,
}

/// What the report says of the robust stage.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RobustSummary {
    /// The observations file.
    pub observations: String,
    /// The confidence parameter.
    pub delta: f64,
    /// The number of runs.
    pub runs: u32,
    /// Adversary steps counted as observations of sigma_L.
    pub counted: u64,
    /// Adversary steps where sigma_W rules (not counted).
    pub sigma_w_steps: u64,
    /// Of those, unsafe ones: misfits of the model.
    pub misfits: u32,
    /// The (state, action) pairs of the union bound.
    pub pairs: u32,
    /// Adversary arena states where sigma_L rules somewhere, with two actions or more.
    pub sigma_l_states: u32,
    /// Of those, the ones never observed (`[0, 1]` intervals).
    pub never_observed: u32,
    /// Certified lower bound of the robust value of h0.
    pub value: f64,
    /// Its upper bound.
    pub value_upper: f64,
    /// Certified lower bound of the nominal value of h0 (the estimate, uniform unobserved).
    pub nominal_value: f64,
    /// Its upper bound.
    pub nominal_value_upper: f64,
    /// The robust controller's action at h0 (`None` where the adversary moves first or
    /// nothing is to be gained).
    pub action: Option<String>,
    /// The nominal policy's action at h0.
    pub nominal_action: Option<String>,
    /// What the robust controller collects against the worst-case reply (nominal solver).
    pub worst_case_value: f64,
    /// Solver sweeps of the robust solve.
    pub iterations: u32,
    /// Its certified gap.
    pub gap: f64,
    /// The decision table at h0 with both values (empty where the adversary moves first).
    pub choices: Vec<RobustChoice>,
    /// The robust controller simulated against the adversary model of the options.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub simulation: Option<RobustSimulation>,
    /// The learning curve, when asked for: both values at h0 from the first runs only.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub learning_curve: Vec<CurvePoint>,
}

impl RobustSummary {
    /// The point of a learning curve that this summary gives.
    pub fn curve_point(&self) -> CurvePoint {
        CurvePoint {
            runs: self.runs,
            counted: self.counted,
            never_observed: self.never_observed,
            value: self.value,
            value_upper: self.value_upper,
            nominal_value: self.nominal_value,
            nominal_value_upper: self.nominal_value_upper,
        }
    }
}

/// The inputs of the MDP stage, echoed in the report.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Settings {
    /// `uniform`, `random` or `file:PATH`.
    pub sigma_l: String,
    /// The seed of random weights (`random`) and of the simulations.
    pub seed: u64,
    /// Which arena actions a robot state that can settle keeps.
    pub risk: Risk,
    /// The discount factor `g` (0 < g ≤ 1; 1 is the paper's undiscounted value).
    pub discount: f64,
    /// The solver's bound on `upper − lower` at every state.
    pub epsilon: f64,
}

/// What value iteration did, serialised as `{iterations, gap, end_components}`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SolverSummary {
    /// Gauss–Seidel sweeps and policy-iteration rounds, summed over the components.
    pub iterations: u32,
    /// `max(upper − lower)` over all states at the end (at most the requested epsilon).
    pub gap: f64,
    /// How many maximal end components were collapsed (always 0 when g < 1).
    pub end_components: u32,
}

/// The value of h0 (bounds at most `gap` apart), the controller's first decision there, and
/// what the controller really collects from there.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct InitialDecision {
    /// Certified lower bound of the value of h0: the best expected payoff, a policy attains it.
    pub value: f64,
    /// Certified upper bound of the value of h0.
    pub value_upper: f64,
    /// The first action (`stop` included); `None` when h0 is absorbing or the adversary's, and
    /// where nothing can be gained when the presentation states guarantees.
    pub action: Option<String>,
    /// The set the controller commits to at h0 (absorbing or `stop`), if it does there.
    pub commits_to: Option<Vec<String>>,
    /// Whether the adversary moves first (the value is then the expectation over its move).
    pub adversary_first: bool,
    /// The controller's expected number of robot moves before it commits (infinite if it may
    /// never).
    pub expected_moves: f64,
    /// Lower bound of the controller's own expected payoff, evaluated as a Markov chain.
    pub policy_value: f64,
    /// Upper bound of the controller's own expected payoff.
    pub policy_value_upper: f64,
}

/// One step of a traced run, as reports show it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TraceRow {
    /// The product state's display name.
    pub state: String,
    /// Its label (win-label, or the general form's label).
    pub label: String,
    /// The action played here (`stop`, an arena action), or `None` where the run ends or
    /// commits.
    pub action: Option<String>,
    /// The set committed to so far (`phi1`, or `A,B`).
    pub committed: Option<String>,
}

/// A traced run, as reports show it.
#[derive(Clone, Debug, PartialEq)]
pub struct TraceReport {
    /// How the run ended.
    pub ending: Ending,
    /// The payoff it collected.
    pub payoff: f64,
    /// Its steps from h0.
    pub steps: Vec<TraceRow>,
}

/// The whole report of the MDP stage.
#[derive(Clone, Debug, PartialEq)]
pub struct Synthesis {
    /// The MDP stage's inputs (`settings`).
    pub settings: Settings,
    /// The MDP's sizes (`mdp`).
    pub mdp: MdpSizes,
    /// What value iteration did (`solver`).
    pub solver: SolverSummary,
    /// The value of h0, the first decision and the controller's own value.
    pub decision: InitialDecision,
    /// The decision table of the requested state (`explain`), when asked for.
    pub explanation: Option<Explanation>,
    /// The simulation's outcome counts and mean payoff (`simulation`), when asked for.
    pub simulation: Option<Simulation>,
    /// One traced run (`trace`), when asked for.
    pub trace: Option<TraceReport>,
    /// The robust stage's summary (`robust`), with observations.
    pub robust: Option<RobustSummary>,
}

/// A value or probability as reports print it: to six decimals without trailing zeros (`300`,
/// `294.021143`, `0.5`), so that whole payoffs read as whole numbers.
pub(crate) fn number(x: f64) -> String {
    let text = format!("{x:.6}");
    let text = text.trim_end_matches('0').trim_end_matches('.');
    if text == "-0" {
        "0".to_string()
    } else {
        text.to_string()
    }
}

/// An expected number of moves, to one decimal (or "infinitely many").
pub(crate) fn moves(expected: f64) -> String {
    if expected.is_finite() {
        format!("{expected:.1}")
    } else {
        "infinitely many".to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::number;

    #[test]
    fn numbers_print_to_six_decimals_without_trailing_zeros() {
        assert_eq!(number(300.0), "300");
        assert_eq!(number(294.0211434018923), "294.021143");
        assert_eq!(number(295.27477), "295.27477");
        assert_eq!(number(1.0 / 3.0), "0.333333");
        assert_eq!(number(0.5), "0.5");
        assert_eq!(number(0.0), "0");
        assert_eq!(number(-1e-9), "0");
        assert_eq!(number(1e-7), "0");
    }
}

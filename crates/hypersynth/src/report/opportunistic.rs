//! The opportunistic report (`hypersynth --phi PHI --psi PSI ARENA`): the games report extended
//! with the hypergame MDP, its solution at h0, and optionally a decision table, a simulation
//! and a trace.
//!
//! JSON: the games report's object with `initial` extended by `value` and `value_upper` (the
//! certified interval), `action` (the policy's first action, `null` if h0 is absorbing or the
//! adversary's), `expected_moves` (the controller's expected number of robot moves before it
//! commits) and `policy_value`, `policy_value_upper` (the controller's own value, evaluated as a
//! Markov chain independently of the solver), and the keys `settings`,
//! `mdp`, `solver`, and, when asked for, `explain`, `simulation`, `trace`. Keys keep a fixed
//! order (sorted: the object goes through `serde_json::Value`), so the same inputs give
//! byte-identical output.

use std::fmt;

use serde::Serialize;
use serde_json::{Map, Value};

use super::GamesReport;
use crate::mdp::solve::SolveError;
use crate::opportunistic::adversary::AdversaryError;
use crate::opportunistic::build::{BuildError, MdpSizes, Payoffs};
use crate::opportunistic::controller::Explanation;
use crate::opportunistic::evaluate::EvaluationError;
use crate::opportunistic::simulate::{Run, SimulationReport, TraceStep};

/// Why the MDP stage (adversary model, MDP, solution, controller evaluation) failed, for either
/// form.
#[derive(Debug, thiserror::Error)]
pub enum StageError {
    /// The adversary's weights file is malformed or does not match the arena.
    #[error(transparent)]
    Adversary(#[from] AdversaryError),
    /// The MDP could not be built (e.g. payoffs that break `r ≥ r1 + r2`).
    #[error(transparent)]
    Build(#[from] BuildError),
    /// Value iteration was refused or did not reach the requested precision.
    #[error(transparent)]
    Solve(#[from] SolveError),
    /// The controller's Markov chains did not reach the requested precision.
    #[error(transparent)]
    Evaluation(#[from] EvaluationError),
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

/// The inputs of the MDP stage, echoed in the report.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MdpSettings {
    /// `uniform`, `random` or `file:PATH`.
    pub sigma_l: String,
    /// The seed of random weights (`random`) and of the simulations.
    pub seed: u64,
    /// The payoffs `r1`, `r2`, `r`.
    pub payoffs: Payoffs,
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

/// The value of h0 (bounds at most `gap` apart), the policy's action there, and what the
/// controller really collects from there.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct InitialDecision {
    /// Certified lower bound of the value of h0: the best expected payoff, a policy attains it.
    pub value: f64,
    /// Certified upper bound of the value of h0.
    pub value_upper: f64,
    /// `None` when h0 is absorbing or the adversary's.
    pub action: Option<String>,
    /// Whether the adversary moves first (the value is then the expectation over its move).
    pub adversary_first: bool,
    /// The controller's expected number of robot moves before it commits (infinite if it may
    /// never).
    pub expected_moves: f64,
    /// Bounds on the controller's own expected payoff, evaluated as a Markov chain.
    pub policy_value: f64,
    /// Upper bound of the controller's own expected payoff (`policy_value` is the lower one).
    pub policy_value_upper: f64,
}

/// A traced run.
#[derive(Clone, Debug, PartialEq)]
pub struct TracedRun {
    /// How the run ended and the payoff it collected.
    pub run: Run,
    /// The run's steps from h0, one per move.
    pub steps: Vec<TraceStep>,
}

/// The whole report of the MDP stage (paper form): text via `Display`, JSON via [`Self::to_json`].
#[derive(Clone, Debug, PartialEq)]
pub struct OpportunisticReport {
    /// The games report the MDP stage extends.
    pub games: GamesReport,
    /// The MDP stage's inputs (`settings`).
    pub settings: MdpSettings,
    /// The MDP's size in the paper's terms (`mdp`).
    pub mdp: MdpSizes,
    /// The value of h0, the first action and the controller's own value (merged into `initial`).
    pub initial: InitialDecision,
    /// What value iteration did (`solver`).
    pub solver: SolverSummary,
    /// The decision table at the requested states (`explain`), when asked for.
    pub explanation: Option<Explanation>,
    /// The simulation's outcome counts and mean payoff (`simulation`), when asked for.
    pub simulation: Option<SimulationReport>,
    /// One traced run (`trace`: `{outcome, payoff, steps}`), when asked for.
    pub trace: Option<TracedRun>,
}

impl OpportunisticReport {
    /// The report as one JSON object (see the module's documentation for its keys).
    pub fn to_json(&self) -> Result<Value, serde_json::Error> {
        let mut root = match serde_json::to_value(&self.games)? {
            Value::Object(map) => map,
            _ => Map::new(),
        };
        if let Some(Value::Object(initial)) = root.get_mut("initial")
            && let Value::Object(decision) = serde_json::to_value(&self.initial)?
        {
            initial.extend(decision);
        }
        root.insert("settings".into(), serde_json::to_value(&self.settings)?);
        root.insert("mdp".into(), serde_json::to_value(self.mdp)?);
        root.insert("solver".into(), serde_json::to_value(&self.solver)?);
        if let Some(explanation) = &self.explanation {
            root.insert("explain".into(), serde_json::to_value(explanation)?);
        }
        if let Some(simulation) = &self.simulation {
            root.insert("simulation".into(), serde_json::to_value(simulation)?);
        }
        if let Some(trace) = &self.trace {
            let steps = serde_json::to_value(&trace.steps)?;
            root.insert(
                "trace".into(),
                serde_json::json!({
                    "outcome": trace.run.outcome,
                    "payoff": trace.run.payoff,
                    "steps": steps,
                }),
            );
        }
        Ok(Value::Object(root))
    }
}

impl fmt::Display for OpportunisticReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.games)?;
        let s = &self.settings;
        writeln!(f)?;
        writeln!(
            f,
            "adversary      sigma_W uniform over safe actions; sigma_L {} (seed {})",
            s.sigma_l, s.seed
        )?;
        writeln!(
            f,
            "payoffs        r1 = {}, r2 = {}, r = {}; discount {}",
            s.payoffs.get(crate::game::Task::Phi1),
            s.payoffs.get(crate::game::Task::Phi2),
            s.payoffs.get(crate::game::Task::Phi),
            s.discount
        )?;
        let m = &self.mdp;
        writeln!(
            f,
            "MDP            {} decision nodes (robot states): {} absorbing, {} with an opportunity, {} without ({} stuck)",
            m.robot_states, m.absorbing, m.with_opportunity, m.without_opportunity, m.stuck
        )?;
        write_model_and_solver(
            f,
            [m.chance_nodes, m.states, m.choices, m.transitions],
            &self.solver,
            s.epsilon,
        )?;
        let i = &self.initial;
        let action = match (&i.action, i.adversary_first) {
            (Some(action), _) => action.as_str(),
            (None, true) => "none (the adversary moves first)",
            (None, false) => "none (absorbing)",
        };
        writeln!(
            f,
            "value of h0    {:.6} (upper bound {:.6}), expected {} robot moves; action {action}",
            i.value,
            i.value_upper,
            moves(i.expected_moves)
        )?;
        writeln!(
            f,
            "controller     collects {:.6} (upper bound {:.6}), evaluated as a Markov chain",
            i.policy_value, i.policy_value_upper
        )?;
        if let Some(table) = &self.explanation {
            write_explanation(f, table)?;
        }
        if let Some(sim) = &self.simulation {
            let outcomes = sim
                .outcomes
                .iter()
                .map(|(o, count)| (o.name().to_string(), count));
            write_simulation(f, sim.runs, sim.seed, sim.max_steps, outcomes)?;
            write_mean(
                f,
                sim.mean_payoff,
                sim.ci_low,
                sim.ci_high,
                self.initial.value,
            )?;
        }
        if let Some(trace) = &self.trace {
            write_trace(f, &trace.steps)?;
            writeln!(
                f,
                "  outcome {}, payoff {}",
                trace.run.outcome.name(),
                trace.run.payoff
            )?;
        }
        Ok(())
    }
}

/// A simulation's header and outcome counts.
pub(super) fn write_simulation(
    f: &mut fmt::Formatter<'_>,
    runs: u32,
    seed: u64,
    max_steps: u32,
    outcomes: impl Iterator<Item = (String, u32)>,
) -> fmt::Result {
    writeln!(f)?;
    writeln!(
        f,
        "simulation     {runs} runs, seed {seed}, at most {max_steps} steps"
    )?;
    for (outcome, count) in outcomes {
        writeln!(
            f,
            "  {outcome:<16} {count:>8}  {:>6.2}%",
            100.0 * f64::from(count) / f64::from(runs.max(1))
        )?;
    }
    Ok(())
}

/// A simulation's mean payoff beside the value it estimates.
pub(super) fn write_mean(
    f: &mut fmt::Formatter<'_>,
    mean: f64,
    low: f64,
    high: f64,
    value: f64,
) -> fmt::Result {
    writeln!(
        f,
        "  mean payoff      {mean:.4}  95% CI [{low:.4}, {high:.4}]  (value of h0 {value:.4})"
    )
}

/// A traced run, state by state (without its outcome line).
pub(super) fn write_trace(f: &mut fmt::Formatter<'_>, steps: &[TraceStep]) -> fmt::Result {
    writeln!(f)?;
    writeln!(f, "trace")?;
    for (i, step) in steps.iter().enumerate() {
        let committed = step
            .committed
            .as_ref()
            .map_or(String::new(), |t| format!("  [{t}]"));
        writeln!(
            f,
            "  {i:>4}  {}  {}  {}{committed}",
            step.state,
            step.label,
            step.action.as_deref().unwrap_or("-")
        )?;
    }
    Ok(())
}

/// The report lines after the decision nodes: the MDP's own size (chance nodes, states,
/// choices, transitions) and the solver's figures. Shared with the general form's report.
pub(super) fn write_model_and_solver(
    f: &mut fmt::Formatter<'_>,
    [chance_nodes, states, choices, transitions]: [u32; 4],
    solver: &SolverSummary,
    epsilon: f64,
) -> fmt::Result {
    writeln!(
        f,
        "               {chance_nodes} chance nodes (adversary states); {states} states, \
         {choices} choices, {transitions} transitions"
    )?;
    writeln!(
        f,
        "solver         {} iterations, gap {:e} (epsilon {epsilon:e}), {} end components collapsed",
        solver.iterations, solver.gap, solver.end_components
    )
}

/// An expected number of moves, to one decimal (or "infinitely many").
pub(super) fn moves(expected: f64) -> String {
    if expected.is_finite() {
        format!("{expected:.1}")
    } else {
        "infinitely many".to_string()
    }
}

/// The decision table: per action, its value and its possible next states.
pub(super) fn write_explanation(f: &mut fmt::Formatter<'_>, table: &Explanation) -> fmt::Result {
    writeln!(f)?;
    writeln!(
        f,
        "decision table of {}  {}  value {:.6}, expected {} robot moves",
        table.state,
        table.label,
        table.value,
        moves(table.expected_moves)
    )?;
    if table.actions.is_empty() {
        writeln!(
            f,
            "  no decision: the state is absorbing or an adversary state"
        )?;
    }
    for row in &table.actions {
        writeln!(
            f,
            "  {:<6} value {:.6}, expected {} robot moves",
            row.action,
            row.value,
            moves(row.expected_moves)
        )?;
        for outcome in &row.outcomes {
            writeln!(
                f,
                "         {:<24} {}  p = {:.6}  value {:.6}",
                outcome.state, outcome.label, outcome.probability, outcome.value
            )?;
        }
    }
    writeln!(f, "  chosen: {}", table.chosen.as_deref().unwrap_or("-"))
}

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
use crate::game::HState;
use crate::mdp::MdpState;
use crate::mdp::adversary::{AdversaryError, AdversaryModel, SigmaL};
use crate::mdp::build::{BuildError, HypergameMdp, MdpSizes, Payoffs};
use crate::mdp::controller::{Controller, Explanation};
use crate::mdp::evaluate::{ControllerEvaluation, EvaluationError, Plan};
use crate::mdp::solve::{Solution, SolveError, SolveOptions, solve_observed};
use crate::mdp::view::{GameView, SolvedHypergame};
use crate::simulate::{Run, SimulationOptions, SimulationReport, TraceStep, simulate, trace};
use crate::stage::{Observer, Stage, timed};

/// What the MDP stage is asked to do.
#[derive(Clone, Debug, PartialEq)]
pub struct MdpConfig {
    pub sigma_l: SigmaL,
    /// How `sigma_l` is named in the report.
    pub sigma_l_name: String,
    pub seed: u64,
    pub payoffs: Payoffs,
    pub solve: SolveOptions,
    /// The state whose decision table to include.
    pub explain: Option<HState>,
    /// Number of simulated runs.
    pub simulate: Option<u32>,
    pub trace: bool,
    pub max_steps: u32,
}

#[derive(Debug, thiserror::Error)]
pub enum StageError {
    #[error(transparent)]
    Adversary(#[from] AdversaryError),
    #[error(transparent)]
    Build(#[from] BuildError),
    #[error(transparent)]
    Solve(#[from] SolveError),
    #[error(transparent)]
    Evaluation(#[from] EvaluationError),
    /// The controller collects less (or more) than the certified value: a bug, never an input
    /// error.
    #[error(
        "internal error: the controller's value at h0 is in [{policy_lower}, {policy_upper}] \
         but the certified value is in [{lower}, {upper}]"
    )]
    ControllerMismatch {
        policy_lower: f64,
        policy_upper: f64,
        lower: f64,
        upper: f64,
    },
}

/// Builds, solves and reports the hypergame MDP of `game`, telling `observer` about each
/// stage; also returns the MDP (for export).
pub fn opportunistic_report(
    game: &SolvedHypergame,
    games: GamesReport,
    config: &MdpConfig,
    observer: &mut dyn Observer,
) -> Result<(OpportunisticReport, HypergameMdp), StageError> {
    let adversary = timed(observer, Stage::Adversary, || {
        AdversaryModel::new(game, &config.sigma_l)
    })?;
    let built = timed(observer, Stage::MdpBuild, || {
        HypergameMdp::build(game, &adversary, config.payoffs)
    })?;
    let solution = solve_observed(built.mdp(), &config.solve, observer)?;
    let controller = Controller {
        game,
        mdp: &built,
        solution: &solution,
        payoffs: config.payoffs,
    };
    let s0 = built.mdp().initial();
    let h0 = game.initial();
    let evaluation = timed(observer, Stage::Evaluation, || {
        checked_evaluation(&controller, &adversary, &solution, s0, &config.solve)
    })?;
    let (value, policy_value) = (solution.value(s0), evaluation.value(h0));
    observer.started(Stage::Simulation);
    let simulation_start = std::time::Instant::now();
    let simulation = config.simulate.map(|runs| {
        let options = SimulationOptions {
            runs,
            seed: config.seed,
            max_steps: config.max_steps,
        };
        simulate(&controller, &adversary, options)
    });
    let traced = config.trace.then(|| {
        let (run, steps) = trace(&controller, &adversary, config.seed, config.max_steps);
        TracedRun { run, steps }
    });
    observer.finished(Stage::Simulation, simulation_start.elapsed().as_secs_f64());
    let report = OpportunisticReport {
        games,
        settings: MdpSettings {
            sigma_l: config.sigma_l_name.clone(),
            seed: config.seed,
            payoffs: config.payoffs,
            discount: config.solve.discount.get(),
            epsilon: config.solve.epsilon,
        },
        mdp: built.sizes(game, &solution),
        initial: InitialDecision {
            value: value.lower,
            value_upper: value.upper,
            action: solution
                .policy(s0)
                .filter(|_| game.is_robot(h0))
                .map(|c| built.mdp().action_name(c).to_string()),
            adversary_first: !game.is_robot(h0),
            expected_moves: evaluation.expected_moves(h0),
            policy_value: policy_value.lower,
            policy_value_upper: policy_value.upper,
        },
        solver: SolverSummary {
            iterations: solution.iterations(),
            gap: solution.gap(),
            end_components: solution.end_components(),
        },
        explanation: config.explain.map(|h| controller.explain(h, &evaluation)),
        simulation,
        trace: traced,
    };
    Ok((report, built))
}

/// The controller evaluated as a Markov chain, refused (`ControllerMismatch`) when what it
/// collects from h0 (MDP state `s0`) is not the certified value within epsilon.
pub(super) fn checked_evaluation(
    controller: &impl Plan,
    adversary: &AdversaryModel,
    solution: &Solution,
    s0: MdpState,
    options: &SolveOptions,
) -> Result<ControllerEvaluation, StageError> {
    let evaluation = ControllerEvaluation::new(
        controller,
        adversary,
        options.epsilon,
        options.max_iterations,
    )?;
    let (value, policy_value) = (
        solution.value(s0),
        evaluation.value(controller.game().initial()),
    );
    let tolerance = options.epsilon + 1e-9 * value.upper.max(1.0);
    if policy_value.upper < value.lower - tolerance || policy_value.lower > value.upper + tolerance
    {
        return Err(StageError::ControllerMismatch {
            policy_lower: policy_value.lower,
            policy_upper: policy_value.upper,
            lower: value.lower,
            upper: value.upper,
        });
    }
    Ok(evaluation)
}

/// The inputs of the MDP stage, echoed in the report.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MdpSettings {
    /// `uniform`, `random` or `file:PATH`.
    pub sigma_l: String,
    pub seed: u64,
    pub payoffs: Payoffs,
    pub discount: f64,
    pub epsilon: f64,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SolverSummary {
    pub iterations: u32,
    pub gap: f64,
    pub end_components: u32,
}

/// The value of h0 (bounds at most `gap` apart), the policy's action there, and what the
/// controller really collects from there.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct InitialDecision {
    pub value: f64,
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
    pub policy_value_upper: f64,
}

/// A traced run.
#[derive(Clone, Debug, PartialEq)]
pub struct TracedRun {
    pub run: Run,
    pub steps: Vec<TraceStep>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct OpportunisticReport {
    pub games: GamesReport,
    pub settings: MdpSettings,
    pub mdp: MdpSizes,
    pub initial: InitialDecision,
    pub solver: SolverSummary,
    pub explanation: Option<Explanation>,
    pub simulation: Option<SimulationReport>,
    pub trace: Option<TracedRun>,
}

impl OpportunisticReport {
    pub fn to_json(&self) -> Value {
        let mut root = match serde_json::to_value(&self.games) {
            Ok(Value::Object(map)) => map,
            _ => Map::new(),
        };
        if let Some(Value::Object(initial)) = root.get_mut("initial")
            && let Value::Object(decision) = json(&self.initial)
        {
            initial.extend(decision);
        }
        let mut insert = |key: &str, value: Value| {
            root.insert(key.to_string(), value);
        };
        insert("settings", json(&self.settings));
        insert("mdp", json(&self.mdp));
        insert("solver", json(&self.solver));
        if let Some(explanation) = &self.explanation {
            insert("explain", json(explanation));
        }
        if let Some(simulation) = &self.simulation {
            insert("simulation", json(simulation));
        }
        if let Some(trace) = &self.trace {
            insert(
                "trace",
                serde_json::json!({
                    "outcome": trace.run.outcome,
                    "payoff": trace.run.payoff,
                    "steps": trace.steps,
                }),
            );
        }
        Value::Object(root)
    }
}

fn json(value: &impl Serialize) -> Value {
    serde_json::to_value(value).unwrap_or(Value::Null)
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

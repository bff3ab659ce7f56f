//! The opportunistic report (`hypersynth --phi PHI --psi PSI ARENA`): the games report extended
//! with the hypergame MDP, its solution at h0, and optionally a decision table, a simulation
//! and a trace.
//!
//! JSON: the games report's object with `initial` extended by `value` (certified lower bound) and
//! `action` (the policy's first action, `null` if h0 is absorbing), and the keys `settings`,
//! `mdp`, `solver`, and, when asked for, `explain`, `simulation`, `trace`. Keys keep a fixed
//! order (sorted: the object goes through `serde_json::Value`), so the same inputs give
//! byte-identical output.

use std::fmt;

use serde::Serialize;
use serde_json::{Map, Value};

use super::GamesReport;
use crate::game::HState;
use crate::mdp::adversary::{AdversaryError, AdversaryModel, SigmaL};
use crate::mdp::build::{BuildError, HypergameMdp, MdpSizes, Payoffs};
use crate::mdp::controller::{Controller, Explanation};
use crate::mdp::solve::{SolveError, SolveOptions, solve};
use crate::mdp::view::SolvedHypergame;
use crate::simulate::{Run, SimulationOptions, SimulationReport, TraceStep, simulate, trace};

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
}

/// Builds, solves and reports the hypergame MDP of `game`; also returns the MDP (for export).
pub fn opportunistic_report(
    game: &SolvedHypergame,
    games: GamesReport,
    config: &MdpConfig,
) -> Result<(OpportunisticReport, HypergameMdp), StageError> {
    let adversary = AdversaryModel::new(game, &config.sigma_l)?;
    let built = HypergameMdp::build(game, &adversary, config.payoffs)?;
    let solution = solve(built.mdp(), &config.solve)?;
    let controller = Controller {
        game,
        mdp: &built,
        solution: &solution,
        payoffs: config.payoffs,
    };
    let s0 = built.mdp().initial();
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
    let report = OpportunisticReport {
        games,
        settings: MdpSettings {
            sigma_l: config.sigma_l_name.clone(),
            seed: config.seed,
            payoffs: config.payoffs,
            discount: config.solve.discount.get(),
            epsilon: config.solve.epsilon,
        },
        mdp: built.sizes(&solution),
        initial: InitialDecision {
            value: solution.value(s0).lower,
            value_upper: solution.value(s0).upper,
            action: solution
                .policy(s0)
                .map(|c| built.mdp().action_name(c).to_string()),
        },
        solver: SolverSummary {
            iterations: solution.iterations(),
            gap: solution.gap(),
            end_components: solution.end_components(),
        },
        explanation: config.explain.map(|h| controller.explain(h)),
        simulation,
        trace: traced,
    };
    Ok((report, built))
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

/// The value of h0 (bounds at most `gap` apart) and the policy's action there.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct InitialDecision {
    pub value: f64,
    pub value_upper: f64,
    pub action: Option<String>,
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
        if let Some(Value::Object(initial)) = root.get_mut("initial") {
            initial.insert("value".into(), self.initial.value.into());
            initial.insert("value_upper".into(), self.initial.value_upper.into());
            initial.insert("action".into(), self.initial.action.clone().into());
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
            "MDP            {} decision nodes (robot states), {} absorbing; {} with an opportunity, {} without",
            m.robot_states, m.absorbing, m.with_opportunity, m.without_opportunity
        )?;
        writeln!(
            f,
            "solver         {} iterations, gap {:e} (epsilon {:e}), {} end components collapsed",
            self.solver.iterations, self.solver.gap, s.epsilon, self.solver.end_components
        )?;
        writeln!(
            f,
            "value of h0    {:.6} (upper bound {:.6}); action {}",
            self.initial.value,
            self.initial.value_upper,
            self.initial.action.as_deref().unwrap_or("none (absorbing)")
        )?;
        if let Some(table) = &self.explanation {
            write_explanation(f, table)?;
        }
        if let Some(sim) = &self.simulation {
            writeln!(f)?;
            writeln!(
                f,
                "simulation     {} runs, seed {}, at most {} steps",
                sim.runs, sim.seed, sim.max_steps
            )?;
            for (outcome, count) in sim.outcomes.iter() {
                writeln!(
                    f,
                    "  {:<16} {:>8}  {:>6.2}%",
                    outcome.name(),
                    count,
                    100.0 * f64::from(count) / f64::from(sim.runs.max(1))
                )?;
            }
            writeln!(
                f,
                "  mean payoff      {:.4}  95% CI [{:.4}, {:.4}]  (value of h0 {:.4})",
                sim.mean_payoff, sim.ci_low, sim.ci_high, self.initial.value
            )?;
        }
        if let Some(trace) = &self.trace {
            writeln!(f)?;
            writeln!(f, "trace")?;
            for (i, step) in trace.steps.iter().enumerate() {
                let committed = step.committed.map_or(String::new(), |t| format!("  [{t}]"));
                writeln!(
                    f,
                    "  {i:>4}  {}  {}  {}{committed}",
                    step.state,
                    step.label,
                    step.action.as_deref().unwrap_or("-")
                )?;
            }
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

/// The decision table: per action, its value and its possible next states.
fn write_explanation(f: &mut fmt::Formatter<'_>, table: &Explanation) -> fmt::Result {
    writeln!(f)?;
    match table.value {
        Some(value) => writeln!(
            f,
            "decision table of {}  {}  value {value:.6}",
            table.state, table.label
        )?,
        None => writeln!(f, "decision table of {}  {}", table.state, table.label)?,
    }
    if table.actions.is_empty() {
        writeln!(
            f,
            "  no decision: the state is absorbing or an adversary state"
        )?;
    }
    for row in &table.actions {
        writeln!(f, "  {:<6} value {:.6}", row.action, row.value)?;
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

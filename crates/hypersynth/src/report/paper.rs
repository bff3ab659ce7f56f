//! The paper's form of the MDP stage's report (`hypersynth --phi PHI --psi PSI ARENA`): the games
//! report extended with the hypergame MDP, its solution at h0, and optionally a decision table,
//! a simulation and a trace, in the paper's terms (tasks `phi1`, `phi2`, `phi`).
//!
//! JSON: the games report's object with `initial` extended by `value` and `value_upper` (the
//! certified interval), `action` (the policy's first action, `null` if h0 is absorbing or the
//! adversary's), `expected_moves` (the controller's expected number of robot moves before it
//! commits) and `policy_value`, `policy_value_upper` (the controller's own value, evaluated as a
//! Markov chain independently of the solver), and the keys `settings`, `mdp`, `solver`, and,
//! when asked for, `explain`, `simulation`, `trace`. Keys keep a fixed order (sorted: the object
//! goes through `serde_json::Value`), so the same inputs give byte-identical output.

use std::fmt;

use serde::Serialize;
use serde_json::{Map, Value};

use super::GamesReport;
use super::synthesis::{Synthesis, write_details, write_model_and_solver, write_value};
use crate::game::Task;
use crate::opportunistic::simulate::{Ending, Simulation};

/// How a run ended, in the paper's terms.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RunOutcome {
    /// The robot committed to phi and satisfied it.
    Phi,
    /// It committed to phi1 (stop) and satisfied it.
    Phi1Only,
    /// It committed to phi2 and satisfied it.
    Phi2Only,
    /// The adversary was stuck (no enabled action), which counts as a win for the robot.
    AdversaryStuck,
    /// It reached a state of value 0 before committing (a stuck `(L,L,L)` state among them),
    /// or its reactive strategy had no move.
    None,
    /// The step bound was hit first.
    StepBound,
}

impl RunOutcome {
    /// Every outcome, in the order reports list them.
    pub const ALL: [RunOutcome; 6] = [
        RunOutcome::Phi,
        RunOutcome::Phi1Only,
        RunOutcome::Phi2Only,
        RunOutcome::AdversaryStuck,
        RunOutcome::None,
        RunOutcome::StepBound,
    ];

    /// The outcome of a run that ended so (the paper's form has two sub-tasks).
    pub fn of(ending: Ending) -> RunOutcome {
        match ending {
            Ending::Satisfied(set) => match Task::of_set(set) {
                Some(Task::Phi1) => RunOutcome::Phi1Only,
                Some(Task::Phi2) => RunOutcome::Phi2Only,
                _ => RunOutcome::Phi,
            },
            Ending::AdversaryStuck => RunOutcome::AdversaryStuck,
            Ending::None => RunOutcome::None,
            Ending::StepBound => RunOutcome::StepBound,
        }
    }

    /// The outcome's name in reports (`phi satisfied`, `step bound hit`...).
    pub fn name(self) -> &'static str {
        match self {
            RunOutcome::Phi => "phi satisfied",
            RunOutcome::Phi1Only => "phi1 only",
            RunOutcome::Phi2Only => "phi2 only",
            RunOutcome::AdversaryStuck => "adversary stuck",
            RunOutcome::None => "none",
            RunOutcome::StepBound => "step bound hit",
        }
    }
}

/// How many runs ended each way (JSON `outcomes`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct OutcomeCounts {
    /// Runs that committed to phi and satisfied it.
    pub phi: u32,
    /// Runs that committed to phi1 and satisfied it.
    pub phi1_only: u32,
    /// Runs that committed to phi2 and satisfied it.
    pub phi2_only: u32,
    /// Runs that met a stuck adversary.
    pub adversary_stuck: u32,
    /// Runs that gained nothing: they reached a state of value 0, or the strategy had no move.
    pub none: u32,
    /// Runs that hit the step bound.
    pub step_bound: u32,
}

impl OutcomeCounts {
    /// The counts of a simulation of the paper's form.
    pub fn of(simulation: &Simulation) -> OutcomeCounts {
        let satisfied = |task: Task| simulation.satisfied[task.set().0 as usize];
        OutcomeCounts {
            phi: satisfied(Task::Phi),
            phi1_only: satisfied(Task::Phi1),
            phi2_only: satisfied(Task::Phi2),
            adversary_stuck: simulation.adversary_stuck,
            none: simulation.none,
            step_bound: simulation.step_bound,
        }
    }

    /// The counts in the order of [`RunOutcome::ALL`].
    pub fn iter(&self) -> impl Iterator<Item = (RunOutcome, u32)> {
        RunOutcome::ALL.into_iter().zip([
            self.phi,
            self.phi1_only,
            self.phi2_only,
            self.adversary_stuck,
            self.none,
            self.step_bound,
        ])
    }
}

/// A simulation as the paper's JSON shows it.
#[derive(Serialize)]
struct SimulationJson {
    runs: u32,
    seed: u64,
    max_steps: u32,
    outcomes: OutcomeCounts,
    mean_payoff: f64,
    ci_low: f64,
    ci_high: f64,
}

/// The MDP stage's part of the paper's text report, after the games report.
pub(super) fn write(f: &mut fmt::Formatter<'_>, s: &Synthesis) -> fmt::Result {
    let settings = &s.settings;
    writeln!(f)?;
    writeln!(
        f,
        "adversary      sigma_W uniform over safe actions; sigma_L {} (seed {})",
        settings.sigma_l, settings.seed
    )?;
    let payoffs = settings.payoffs.unwrap_or_default();
    writeln!(
        f,
        "payoffs        r1 = {}, r2 = {}, r = {}; discount {}",
        payoffs.get(Task::Phi1),
        payoffs.get(Task::Phi2),
        payoffs.get(Task::Phi),
        settings.discount
    )?;
    let m = &s.mdp;
    writeln!(
        f,
        "MDP            {} decision nodes (robot states): {} absorbing, {} with an opportunity, {} without ({} stuck)",
        m.robot_states, m.absorbing, m.with_opportunity, m.without_opportunity, m.stuck
    )?;
    write_model_and_solver(f, m, &s.solver, settings.epsilon)?;
    let d = &s.decision;
    let action = match (&d.action, d.adversary_first) {
        (Some(action), _) => action.as_str(),
        (None, true) => "none (the adversary moves first)",
        (None, false) => "none (absorbing)",
    };
    write_value(f, d, action)?;
    let outcomes: Vec<(String, u32)> = s.simulation.as_ref().map_or(Vec::new(), |sim| {
        OutcomeCounts::of(sim)
            .iter()
            .map(|(outcome, count)| (outcome.name().to_string(), count))
            .collect()
    });
    let trace_outcome = s
        .trace
        .as_ref()
        .map_or("", |trace| RunOutcome::of(trace.ending).name());
    write_details(f, s, &outcomes, trace_outcome)
}

/// The paper's JSON report: the games report's object extended as the module documentation
/// says.
pub(super) fn to_json(
    games: &GamesReport,
    s: Option<&Synthesis>,
) -> Result<Value, serde_json::Error> {
    let mut root = match serde_json::to_value(games)? {
        Value::Object(map) => map,
        _ => Map::new(),
    };
    let Some(s) = s else {
        return Ok(Value::Object(root));
    };
    if let Some(Value::Object(initial)) = root.get_mut("initial")
        && let Value::Object(mut decision) = serde_json::to_value(&s.decision)?
    {
        decision.remove("commits_to");
        initial.extend(decision);
    }
    root.insert("settings".into(), serde_json::to_value(&s.settings)?);
    root.insert("mdp".into(), serde_json::to_value(s.mdp)?);
    root.insert("solver".into(), serde_json::to_value(&s.solver)?);
    if let Some(explanation) = &s.explanation {
        root.insert("explain".into(), serde_json::to_value(explanation)?);
    }
    if let Some(sim) = &s.simulation {
        let json = SimulationJson {
            runs: sim.options.runs,
            seed: sim.options.seed,
            max_steps: sim.options.max_steps,
            outcomes: OutcomeCounts::of(sim),
            mean_payoff: sim.mean_payoff,
            ci_low: sim.ci_low,
            ci_high: sim.ci_high,
        };
        root.insert("simulation".into(), serde_json::to_value(json)?);
    }
    if let Some(trace) = &s.trace {
        root.insert(
            "trace".into(),
            serde_json::json!({
                "outcome": RunOutcome::of(trace.ending),
                "payoff": trace.payoff,
                "steps": serde_json::to_value(&trace.steps)?,
            }),
        );
    }
    Ok(Value::Object(root))
}

//! The MDP stage on a solved hypergame, for both forms: the adversary model, the hypergame MDP,
//! its certified solution and the controller's own evaluation, computed once and then asked for
//! reports, decision tables, simulations, pictures and exports.

use super::PipelineError;
use crate::arena::ActionId;
use crate::certificate::certify;
use crate::game::{HState, TaskSet};
use crate::mdp::solve::{Solution, SolveOptions, solve_observed};
use crate::mdp::{ChoiceId, DrnForm, MdpState, write_drn, write_induced_drn};
use crate::opportunistic::adversary::{AdversaryModel, SigmaL};
use crate::opportunistic::build::{HypergameMdp, Risk, STOP};
use crate::opportunistic::controller::{Controller, Decision, reported_interval};
use crate::opportunistic::evaluate::{ControllerEvaluation, Plan};
use crate::opportunistic::export::{ExportInputs, ModelRules, SigmaLRule, export};
use crate::opportunistic::observations::Observations;
use crate::opportunistic::simulate::{
    SimulationOptions, Trace, TraceAction, simulate_metered, trace,
};
use crate::opportunistic::view::{GameView, SolvedGame, SolvedHypergame};
use crate::report::{
    InitialDecision, Settings, SolverSummary, StageError, Synthesis, TraceReport, TraceRow,
};
use crate::stage::{Meter, Observer, Stage, metered, timed};

/// What the MDP stage is asked to compute.
#[derive(Clone, Debug, PartialEq)]
pub struct MdpOptions {
    /// The adversary's distribution where it believes it has lost.
    pub sigma_l: SigmaL,
    /// The seed of random weights and of simulations.
    pub seed: u64,
    /// Discount, precision and sweep limit of the solver.
    pub solve: SolveOptions,
    /// sigma_L learnt from observations: the report adds the robust stage
    /// (docs/semantics.md §10); `sigma_l` is then the model simulations run against.
    pub learnt: Option<Learnt>,
}

/// sigma_L learnt from observations: the runs and the confidence parameter.
#[derive(Clone, Debug, PartialEq)]
pub struct Learnt {
    /// The observed runs.
    pub observations: Observations,
    /// The file's name, as reports show it.
    pub file: String,
    /// The region holds with probability at least `1 − delta`.
    pub delta: f64,
}

/// What the report adds to the solution at h0: a decision table, simulations, a trace.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ReportRequests {
    /// The state whose decision table to include.
    pub explain: Option<HState>,
    /// Number of simulated runs.
    pub simulate: Option<u32>,
    /// Step bound of simulated and traced runs.
    pub max_steps: u32,
}

/// The solved hypergame MDP of one solved hypergame, with its controller's evaluation.
pub struct OpportunisticSolution {
    /// The adversary model (sigma_W, sigma_L) the MDP was built from.
    pub adversary: AdversaryModel,
    /// The hypergame MDP with its map to product states.
    pub mdp: HypergameMdp,
    /// Certified values and the opportunistic policy.
    pub solution: Solution,
    /// The controller evaluated as Markov chains, checked against the certified value.
    pub evaluation: ControllerEvaluation,
    /// The options it was solved with.
    pub options: MdpOptions,
    /// The risk rule the MDP was built with.
    pub risk: Risk,
}

impl OpportunisticSolution {
    /// Builds and solves the hypergame MDP of `game` under the risk rule `risk`, telling
    /// `observer` about each stage, and evaluates the controller; refuses
    /// (`ControllerMismatch`) a controller that does not collect the certified value at h0.
    pub fn solve(
        game: &SolvedHypergame,
        risk: Risk,
        options: &MdpOptions,
        observer: &mut dyn Observer,
    ) -> Result<OpportunisticSolution, StageError> {
        let adversary = timed(observer, Stage::Adversary, || {
            AdversaryModel::new(game, &options.sigma_l)
        })?;
        let mdp = metered(observer, Stage::MdpBuild, |meter| {
            HypergameMdp::build_metered(game, &adversary, risk, meter)
        })?;
        let solution = solve_observed(mdp.mdp(), &options.solve, observer)?;
        let controller = Controller {
            game,
            mdp: &mdp,
            solution: &solution,
        };
        let evaluation = metered(observer, Stage::Evaluation, |meter| {
            checked_evaluation(
                &controller,
                &adversary,
                &solution,
                mdp.node(game.initial()),
                &options.solve,
                meter,
            )
        })?;
        Ok(OpportunisticSolution {
            adversary,
            mdp,
            solution,
            evaluation,
            options: options.clone(),
            risk,
        })
    }

    /// The opportunistic controller on `game` (the hypergame this was solved for).
    pub fn controller<'s, G: SolvedGame>(&'s self, game: &'s G) -> Controller<'s, G> {
        Controller {
            game,
            mdp: &self.mdp,
            solution: &self.solution,
        }
    }

    /// The MDP in Storm's DRN format in `form`, its states named after the product states;
    /// with `induced`, only the controller's choices (the policy's, and each chance node's
    /// one), so that Storm's value of it is the controller's own (`policy_value`).
    pub fn drn(&self, game: &impl SolvedGame, induced: bool, form: DrnForm) -> String {
        let (mdp, discount) = (self.mdp.mdp(), self.options.solve.discount);
        let name = |s| Some(self.mdp.state_name(game, s));
        if induced {
            let policy: bit_set::BitSet = mdp
                .states()
                .filter_map(|s| self.solution.policy(s))
                .map(ChoiceId::index)
                .collect();
            write_induced_drn(mdp, discount, form, name, |c| policy.contains(c.index()))
        } else {
            write_drn(mdp, discount, form, name)
        }
    }

    /// The controller as an exported file (docs/semantics.md §9), as compact JSON; with
    /// `certificate`, with its certificate (§9.4) made from the controller's evaluation and the
    /// solver's upper bounds.
    pub fn export_controller(
        &self,
        game: &SolvedHypergame,
        inputs: &ExportInputs,
        certificate: bool,
    ) -> Result<String, PipelineError> {
        let rules = ModelRules {
            risk: self.risk,
            sigma_l: SigmaLRule::of(&self.options.sigma_l),
        };
        let bounds = |h: HState| {
            [
                self.evaluation.value(h).lower,
                self.solution.value(self.mdp.node(h)).upper,
            ]
        };
        let controller = self.controller(game);
        controller_file(
            &controller,
            &self.adversary,
            rules,
            inputs,
            certificate,
            bounds,
        )
    }

    /// One run of the controller from the seed of the options (the first of the simulation).
    pub fn trace(&self, game: &impl SolvedGame, max_steps: u32) -> Trace {
        trace(
            &self.controller(game),
            &self.adversary,
            self.options.seed,
            max_steps,
        )
    }

    /// A traced run as reports show it: state names, labels, actions and commitments.
    pub fn trace_report(&self, game: &impl SolvedGame, trace: &Trace) -> TraceReport {
        TraceReport {
            ending: trace.ending,
            payoff: trace.payoff,
            steps: game_trace_rows(game, trace),
        }
    }

    /// The MDP stage's report: the solution at h0, and what `requests` ask for (the
    /// simulations run here, as the `simulation` stage; `trace` is the run to report, if
    /// any).
    pub fn synthesis(
        &self,
        game: &impl SolvedGame,
        requests: &ReportRequests,
        trace: Option<&Trace>,
        observer: &mut dyn Observer,
    ) -> Synthesis {
        let controller = self.controller(game);
        let (solution, options) = (&self.solution, &self.options);
        let h0 = game.initial();
        let s0 = self.mdp.node(h0);
        let layout = game.presentation().layout();
        let robot_first = game.is_robot(h0);
        let (action, commits_to) = match robot_first.then(|| controller.decide(h0)) {
            Some(Decision::Move { action, .. }) => {
                (Some(game.action_name(action).to_string()), None)
            }
            Some(Decision::Stop(set)) => (Some(STOP.to_string()), Some(set.names(game.names()))),
            Some(Decision::Commit(set)) => (None, Some(set.names(game.names()))),
            Some(Decision::GiveUp) | None => (None, None),
        };
        // Reports that state no guarantee name the policy's action at h0 even where nothing can
        // be gained.
        let action = match layout.states_guarantees {
            true => action,
            false => solution
                .policy(s0)
                .filter(|_| robot_first)
                .map(|c| self.mdp.mdp().action_name(c).to_string()),
        };
        let simulation = metered(observer, Stage::Simulation, |meter| {
            requests.simulate.map(|runs| {
                let simulation = SimulationOptions {
                    runs,
                    seed: options.seed,
                    max_steps: requests.max_steps,
                };
                simulate_metered(&controller, &self.adversary, simulation, meter)
            })
        });
        let value = reported_interval(solution.value(s0), game);
        let policy_value = reported_interval(self.evaluation.value(h0), game);
        Synthesis {
            settings: Settings {
                sigma_l: options.sigma_l.name(),
                seed: options.seed,
                risk: self.risk,
                discount: options.solve.discount.get(),
                epsilon: options.solve.epsilon,
            },
            mdp: self.mdp.sizes(game, solution),
            solver: SolverSummary {
                iterations: solution.iterations(),
                gap: solution.gap(),
                end_components: solution.end_components(),
            },
            decision: InitialDecision {
                value: value.lower,
                value_upper: value.upper,
                action,
                commits_to,
                adversary_first: !robot_first,
                expected_moves: self.evaluation.expected_moves(h0),
                policy_value: policy_value.lower,
                policy_value_upper: policy_value.upper,
            },
            explanation: requests
                .explain
                .map(|h| controller.explain(h, &self.evaluation)),
            simulation,
            trace: trace.map(|trace| self.trace_report(game, trace)),
            robust: None,
        }
    }
}

/// The steps of a traced run on `game` as reports show them.
pub(super) fn game_trace_rows(game: &impl SolvedGame, trace: &Trace) -> Vec<TraceRow> {
    trace_rows(
        trace,
        |h| game.state_name(h),
        |h| game.label(h),
        |a| game.action_name(a).to_string(),
        |set| game.set_name(set),
    )
}

/// The steps of a traced run as reports show them, with either engine's names of states,
/// labels, actions and sets.
pub(super) fn trace_rows(
    trace: &Trace,
    name: impl Fn(HState) -> String,
    label: impl Fn(HState) -> String,
    action: impl Fn(ActionId) -> String,
    set_name: impl Fn(TaskSet) -> String,
) -> Vec<TraceRow> {
    trace
        .steps
        .iter()
        .map(|step| TraceRow {
            state: name(step.state),
            label: label(step.state),
            action: step.action.map(|played| match played {
                TraceAction::Move(a) => action(a),
                TraceAction::Stop => STOP.to_string(),
            }),
            committed: step.committed.map(&set_name),
        })
        .collect()
}

/// The controller evaluated as a Markov chain, refused (`ControllerMismatch`) when what it
/// collects from h0 (MDP state `s0`) is not the certified value within epsilon.
fn checked_evaluation(
    controller: &impl Plan,
    adversary: &AdversaryModel,
    solution: &Solution,
    s0: MdpState,
    options: &SolveOptions,
    meter: &mut Meter<'_>,
) -> Result<ControllerEvaluation, StageError> {
    let evaluation = ControllerEvaluation::new_metered(
        controller,
        adversary,
        options.epsilon,
        options.max_iterations,
        meter,
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

/// `controller` (on `game`'s product, its MDP built with `rules` against `adversary`) as an
/// exported file (docs/semantics.md §9), as compact JSON; with `certificate`, with the
/// certificate (§9.4) made from the approximate `[lower, upper]` values `bounds` gives per
/// product state: the controller's own value and the MDP's upper bound.
pub(crate) fn controller_file(
    controller: &Controller<'_, SolvedHypergame<'_, '_>>,
    adversary: &AdversaryModel,
    rules: ModelRules,
    inputs: &ExportInputs,
    certificate: bool,
    bounds: impl Fn(HState) -> [f64; 2],
) -> Result<String, PipelineError> {
    let mut file = export(controller, adversary, rules, inputs);
    if certificate {
        let game = controller.game;
        let product = game.game();
        let tuples = product.num_automata_slots() as usize;
        let mut lower = vec![f64::NAN; product.arena().num_states() * tuples];
        let mut upper = lower.clone();
        for h in game.states() {
            let entry = game.arena_state(h).index() * tuples + product.automata_slot(h) as usize;
            [lower[entry], upper[entry]] = bounds(h);
        }
        let at = |values: &[f64], entry: usize| values.get(entry).copied().unwrap_or(f64::NAN);
        file.certificate = Some(certify(
            &file,
            |entry| at(&lower, entry),
            |entry| at(&upper, entry),
        )?);
    }
    Ok(serde_json::to_string(&file).map(|text| text + "\n")?)
}

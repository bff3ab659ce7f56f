//! The paper's MDP stage on a solved hypergame: the adversary model, the hypergame MDP, its
//! certified solution and the controller's own evaluation, computed once and then asked for
//! reports, decision tables, simulations, pictures and exports.

use crate::game::HState;
use crate::mdp::solve::{Solution, SolveOptions, solve_observed};
use crate::mdp::{MdpState, write_drn};
use crate::opportunistic::adversary::{AdversaryModel, SigmaL};
use crate::opportunistic::build::{HypergameMdp, Payoffs};
use crate::opportunistic::controller::Controller;
use crate::opportunistic::evaluate::{ControllerEvaluation, Plan};
use crate::opportunistic::simulate::{SimulationOptions, simulate_metered, trace};
use crate::opportunistic::view::{GameView, SolvedHypergame};
use crate::report::{
    GamesReport, InitialDecision, MdpSettings, OpportunisticReport, SolverSummary, StageError,
    TracedRun,
};
use crate::stage::{Meter, Observer, Stage, metered, timed};

/// What the MDP stage is asked to compute.
#[derive(Clone, Debug, PartialEq)]
pub struct MdpOptions {
    /// The adversary's distribution where it believes it has lost.
    pub sigma_l: SigmaL,
    /// The seed of random weights and of simulations.
    pub seed: u64,
    /// The payoffs of phi1, phi2 and phi.
    pub payoffs: Payoffs,
    /// Discount, precision and sweep limit of the solver.
    pub solve: SolveOptions,
}

impl MdpOptions {
    /// The settings in one line, for a picture's title.
    pub fn title(&self) -> String {
        use crate::game::Task;
        format!(
            "sigma_L {}, discount {}, payoffs r1 = {}, r2 = {}, r = {}",
            self.sigma_l.title(),
            self.solve.discount.get(),
            self.payoffs.get(Task::Phi1),
            self.payoffs.get(Task::Phi2),
            self.payoffs.get(Task::Phi)
        )
    }
}

/// What the report adds to the solution at h0: a decision table, simulations, a trace.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ReportRequests {
    /// The state whose decision table to include.
    pub explain: Option<HState>,
    /// Number of simulated runs.
    pub simulate: Option<u32>,
    /// Whether to trace one run.
    pub trace: bool,
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
}

impl OpportunisticSolution {
    /// Builds and solves the hypergame MDP of `game`, telling `observer` about each stage, and
    /// evaluates the controller; refuses (`ControllerMismatch`) a controller that does not
    /// collect the certified value at h0.
    pub fn solve(
        game: &SolvedHypergame,
        options: &MdpOptions,
        observer: &mut dyn Observer,
    ) -> Result<OpportunisticSolution, StageError> {
        let adversary = timed(observer, Stage::Adversary, || {
            AdversaryModel::new(game, &options.sigma_l)
        })?;
        let mdp = metered(observer, Stage::MdpBuild, |meter| {
            HypergameMdp::build_metered(game, &adversary, options.payoffs, meter)
        })?;
        let solution = solve_observed(mdp.mdp(), &options.solve, observer)?;
        let controller = Controller {
            game,
            mdp: &mdp,
            solution: &solution,
            payoffs: options.payoffs,
        };
        let evaluation = metered(observer, Stage::Evaluation, |meter| {
            checked_evaluation(
                &controller,
                &adversary,
                &solution,
                mdp.mdp().initial(),
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
        })
    }

    /// The opportunistic controller on `game` (the hypergame this was solved for).
    pub fn controller<'s, 'g, 'a>(
        &'s self,
        game: &'s SolvedHypergame<'g, 'a>,
    ) -> Controller<'s, SolvedHypergame<'g, 'a>> {
        Controller {
            game,
            mdp: &self.mdp,
            solution: &self.solution,
            payoffs: self.options.payoffs,
        }
    }

    /// The MDP in Storm's DRN format, its states named after the product states.
    pub fn drn(&self, game: &SolvedHypergame) -> String {
        write_drn(self.mdp.mdp(), self.options.solve.discount, |s| {
            Some(self.mdp.state_name(game, s))
        })
    }

    /// The opportunistic report: `games` extended with the solution at h0 and what `requests`
    /// ask for (simulations and the trace run here, as the `simulation` stage).
    pub fn report(
        &self,
        game: &SolvedHypergame,
        games: GamesReport,
        requests: &ReportRequests,
        observer: &mut dyn Observer,
    ) -> OpportunisticReport {
        let controller = self.controller(game);
        let (solution, options) = (&self.solution, &self.options);
        let s0 = self.mdp.mdp().initial();
        let h0 = game.initial();
        let (value, policy_value) = (solution.value(s0), self.evaluation.value(h0));
        let (simulation, traced) = metered(observer, Stage::Simulation, |meter| {
            let simulation = requests.simulate.map(|runs| {
                let simulation = SimulationOptions {
                    runs,
                    seed: options.seed,
                    max_steps: requests.max_steps,
                };
                simulate_metered(&controller, &self.adversary, simulation, meter)
            });
            let traced = requests.trace.then(|| {
                let (run, steps) = trace(
                    &controller,
                    &self.adversary,
                    options.seed,
                    requests.max_steps,
                );
                TracedRun { run, steps }
            });
            (simulation, traced)
        });
        OpportunisticReport {
            games,
            settings: MdpSettings {
                sigma_l: options.sigma_l.name(),
                seed: options.seed,
                payoffs: options.payoffs,
                discount: options.solve.discount.get(),
                epsilon: options.solve.epsilon,
            },
            mdp: self.mdp.sizes(game, solution),
            initial: InitialDecision {
                value: value.lower,
                value_upper: value.upper,
                action: solution
                    .policy(s0)
                    .filter(|_| game.is_robot(h0))
                    .map(|c| self.mdp.mdp().action_name(c).to_string()),
                adversary_first: !game.is_robot(h0),
                expected_moves: self.evaluation.expected_moves(h0),
                policy_value: policy_value.lower,
                policy_value_upper: policy_value.upper,
            },
            solver: SolverSummary {
                iterations: solution.iterations(),
                gap: solution.gap(),
                end_components: solution.end_components(),
            },
            explanation: requests
                .explain
                .map(|h| controller.explain(h, &self.evaluation)),
            simulation,
            trace: traced,
        }
    }
}

/// The controller evaluated as a Markov chain, refused (`ControllerMismatch`) when what it
/// collects from h0 (MDP state `s0`) is not the certified value within epsilon.
pub(crate) fn checked_evaluation(
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

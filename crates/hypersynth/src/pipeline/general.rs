//! The general form's MDP stage (DESIGN.md 3.8) on a product of k sub-tasks with its regions:
//! the adversary model, the general MDP under a risk rule, its certified solution and the
//! controller's own evaluation, computed once, then asked for the report, the picture and the
//! DRN export ([`run_general`] also exports the reactive strategies of every set).

use super::opportunistic::{ReportRequests, checked_evaluation};
use super::picture::{GeneralPictureSubject, draw_general};
use super::{PaperTasks, PipelineError, Requests, Task};
use crate::arena::Arena;
use crate::arena::gridworld::Gridworld;
use crate::automata::Dfa;
use crate::game::{Belief, Hypergame, States, SubsetPayoffs, TaskRegions, TaskSet, match_belief};
use crate::ltl::Formula;
use crate::mdp::solve::{Solution, SolveOptions, solve_observed};
use crate::mdp::write_drn;
use crate::opportunistic::adversary::{AdversaryModel, SigmaL};
use crate::opportunistic::build::Payoffs;
use crate::opportunistic::build::STOP;
use crate::opportunistic::evaluate::{ControllerEvaluation, Plan};
use crate::opportunistic::simulate::{
    Ending, RunOutcome, SimulationOptions, simulate_plan_metered, trace_plan,
};
use crate::opportunistic::subtasks::{
    Risk, SubtaskController, SubtaskDecision, SubtaskGame, SubtaskMdp,
};
use crate::opportunistic::view::GameView;
use crate::report::TaskAutomaton;
use crate::report::{
    GoalTrace, SolverSummary, StageError, SubtaskDecisionSummary, SubtaskGamesReport,
    SubtaskReport, SubtaskSettings, SubtaskStrategyExport,
};
use crate::stage::{Observer, Stage, metered, timed};
use crate::translate::{TranslateError, Translator};

/// What the general MDP stage is asked to compute.
#[derive(Clone, Debug, PartialEq)]
pub struct SubtaskOptions {
    /// The adversary's distribution where it believes it has lost.
    pub sigma_l: SigmaL,
    /// The seed of random weights and of simulations.
    pub seed: u64,
    /// Discount, precision and sweep limit of the solver.
    pub solve: SolveOptions,
}

/// The solved general MDP of one product, with its controller's evaluation.
pub struct SubtaskSolution {
    /// The adversary model the MDP was built from.
    pub adversary: AdversaryModel,
    /// The general MDP.
    pub mdp: SubtaskMdp,
    /// Certified values and the policy.
    pub solution: Solution,
    /// The controller evaluated as Markov chains, checked against the certified value.
    pub evaluation: ControllerEvaluation,
    /// The risk rule and options it was solved with.
    pub risk: Risk,
    /// The options it was solved with.
    pub options: SubtaskOptions,
}

impl SubtaskSolution {
    /// Builds the general MDP of `game` under the risk rule `risk`, solves it (telling
    /// `observer` about each stage) and evaluates the controller; refuses
    /// (`ControllerMismatch`) a controller that does not collect the certified value at h0.
    pub fn solve(
        game: &SubtaskGame,
        risk: Risk,
        options: &SubtaskOptions,
        observer: &mut dyn Observer,
    ) -> Result<SubtaskSolution, StageError> {
        let adversary = timed(observer, Stage::Adversary, || {
            AdversaryModel::new(game, &options.sigma_l)
        })?;
        let mdp = metered(observer, Stage::MdpBuild, |meter| {
            SubtaskMdp::build_metered(game, &adversary, risk, meter)
        })?;
        let solution = solve_observed(mdp.mdp(), &options.solve, observer)?;
        let controller = SubtaskController {
            game,
            mdp: &mdp,
            solution: &solution,
        };
        let h0 = game.initial();
        let evaluation = metered(observer, Stage::Evaluation, |meter| {
            checked_evaluation(
                &controller,
                &adversary,
                &solution,
                mdp.node(h0),
                &options.solve,
                meter,
            )
        })?;
        Ok(SubtaskSolution {
            adversary,
            mdp,
            solution,
            evaluation,
            risk,
            options: options.clone(),
        })
    }

    /// The general controller on `game` (the product this was solved for).
    pub fn controller<'s>(&'s self, game: &'s SubtaskGame<'s, 's>) -> SubtaskController<'s> {
        SubtaskController {
            game,
            mdp: &self.mdp,
            solution: &self.solution,
        }
    }

    /// The MDP in Storm's DRN format, its states named after the product states.
    pub fn drn(&self, game: &SubtaskGame) -> String {
        write_drn(self.mdp.mdp(), self.options.solve.discount, |s| {
            Some(self.mdp.state_name(game, s))
        })
    }

    /// The general report: `games` extended with the solution at h0 and what `requests` ask
    /// for (simulations and the trace run here, as the `simulation` stage).
    pub fn report(
        &self,
        game: &SubtaskGame,
        games: SubtaskGamesReport,
        requests: &ReportRequests,
        observer: &mut dyn Observer,
    ) -> SubtaskReport {
        let controller = self.controller(game);
        let (solution, options) = (&self.solution, &self.options);
        let h0 = game.initial();
        let s0 = self.mdp.node(h0);
        let (value, policy_value) = (solution.value(s0), self.evaluation.value(h0));
        let names = game.names();
        let robot_first = game.is_robot(h0);
        let (action, commits_to) = match robot_first.then(|| controller.decide(h0)) {
            Some(SubtaskDecision::Move { action, .. }) => {
                (Some(game.action_name(action).to_string()), None)
            }
            Some(SubtaskDecision::Stop(set)) => (Some(STOP.to_string()), Some(set.names(names))),
            Some(SubtaskDecision::Commit(set)) => (None, Some(set.names(names))),
            Some(SubtaskDecision::GiveUp) | None => (None, None),
        };
        let (simulation, trace) = metered(observer, Stage::Simulation, |meter| {
            let simulation = requests.simulate.map(|runs| {
                let simulation = SimulationOptions {
                    runs,
                    seed: options.seed,
                    max_steps: requests.max_steps,
                };
                simulate_plan_metered(&controller, &self.adversary, simulation, meter)
            });
            let trace = requests.trace.then(|| {
                let (ending, payoff, steps) = trace_plan(
                    &controller,
                    &self.adversary,
                    options.seed,
                    requests.max_steps,
                );
                let outcome = match ending {
                    Ending::Satisfied(goal) => {
                        format!("{} satisfied", controller.goal_name(goal))
                    }
                    Ending::AdversaryStuck => RunOutcome::AdversaryStuck.name().to_string(),
                    Ending::None => RunOutcome::None.name().to_string(),
                    Ending::StepBound => RunOutcome::StepBound.name().to_string(),
                };
                GoalTrace {
                    outcome,
                    payoff,
                    steps,
                }
            });
            (simulation, trace)
        });
        SubtaskReport {
            games,
            settings: SubtaskSettings {
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
            decision: SubtaskDecisionSummary {
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
            trace,
        }
    }
}

/// A named sub-task of the general form.
#[derive(Clone, Debug)]
pub struct Subtask {
    /// Its name (`A` in `--task A=…`).
    pub name: String,
    /// Its automaton.
    pub task: Task,
}

/// The adversary's belief psi.
#[derive(Clone, Debug)]
pub enum Believed {
    /// psi is the conjunction of these sub-tasks (named as `formula`).
    Tasks {
        /// psi as printed.
        formula: String,
        /// The sub-tasks whose conjunction psi is.
        set: TaskSet,
    },
    /// psi has its own automaton.
    Automaton(Box<Task>),
}

impl Believed {
    /// psi given as a formula: the set of sub-tasks whose conjunction it is (up to the order of
    /// conjuncts), or else its own automaton translated by `translator`.
    pub fn from_formula(
        formula: Formula,
        tasks: &[Subtask],
        translator: &dyn Translator,
    ) -> Result<Believed, TranslateError> {
        let formulas: Vec<Option<&Formula>> =
            tasks.iter().map(|t| t.task.formula.as_ref()).collect();
        Ok(match match_belief(&formulas, &formula) {
            Some(set) => Believed::Tasks {
                formula: formula.to_string(),
                set,
            },
            None => Believed::Automaton(Box::new(Task::from_formula(formula, translator)?)),
        })
    }

    fn belief(&self) -> Belief {
        match self {
            Believed::Tasks { set, .. } => Belief::Tasks(*set),
            Believed::Automaton(_) => Belief::Automaton,
        }
    }
}

/// The general form's problem (DESIGN.md 3.8): an arena, k named sub-tasks, payoffs on their
/// sets, the adversary's belief, and the MDP stage's options (`None` to stop after the games).
pub struct GeneralProblem {
    /// The arena's name in messages.
    pub arena_name: String,
    /// The arena.
    pub arena: Arena,
    /// The map the arena was built from, if any (pictures need it).
    pub map: Option<Gridworld>,
    /// The sub-tasks, in the order that breaks ties between sets of equal payoff.
    pub tasks: Vec<Subtask>,
    /// The payoff of every set of sub-tasks.
    pub payoffs: SubsetPayoffs,
    /// What the adversary believes the robot's task is.
    pub believed: Believed,
    /// Which actions a robot state that can settle for something keeps.
    pub risk: Risk,
    /// Which product states to enumerate.
    pub states: States,
    /// The MDP stage's options; `None` stops after the games.
    pub mdp: Option<SubtaskOptions>,
}

impl GeneralProblem {
    /// The paper's special case: two sub-tasks, psi one of them, the paper's risk rule and
    /// payoffs the paper accepts (positive, r >= r1 + r2). Its report is
    /// the paper form's, with phi1 = psi, phi2 the other sub-task and phi their conjunction.
    pub fn paper_special_case(&self) -> Option<(PaperTasks, Payoffs)> {
        let ([a, b], Believed::Tasks { set, .. }) = (self.tasks.as_slice(), &self.believed) else {
            return None;
        };
        let (phi1, phi2, set2) = match set.0 {
            0b01 => (a, b, TaskSet(0b10)),
            0b10 => (b, a, TaskSet(0b01)),
            _ => return None,
        };
        let payoffs = Payoffs::new(
            self.payoffs.get(*set),
            self.payoffs.get(set2),
            self.payoffs.all(),
        )
        .ok()
        .filter(|_| self.risk == Risk::Paper)?;
        let tasks = PaperTasks::new(phi1.task.clone(), phi2.task.clone());
        Some((tasks, payoffs))
    }
}

/// The general form's report: the games alone, or extended with the MDP stage.
#[derive(Clone, Debug)]
pub enum GeneralReport {
    /// The problem stopped after the games.
    Games(Box<SubtaskGamesReport>),
    /// The full report (which holds the games report).
    Full(Box<SubtaskReport>),
}

/// What [`run_general`] produced.
#[derive(Clone, Debug)]
pub struct GeneralOutcome {
    /// The report.
    pub report: GeneralReport,
    /// The MDP in DRN, when asked.
    pub drn: Option<String>,
    /// The reactive strategies of every set of sub-tasks and of psi as JSON, when asked.
    pub strategy: Option<String>,
    /// The picture as SVG, when asked.
    pub svg: Option<String>,
}

/// Runs the general form on `problem`: the product of the sub-tasks' automata (and psi's),
/// `Win(T)` for every set and `Win(psi)`, then (unless games only) the general MDP, with the
/// report, strategy export, picture and DRN export `requests` ask for.
pub fn run_general(
    problem: &GeneralProblem,
    requests: &Requests,
    observer: &mut dyn Observer,
) -> Result<GeneralOutcome, PipelineError> {
    let mut automata: Vec<(&str, &Dfa)> = problem
        .tasks
        .iter()
        .map(|t| (t.name.as_str(), &t.task.dfa))
        .collect();
    let (psi_name, psi_task) = match &problem.believed {
        Believed::Tasks { formula, .. } => (formula.as_str(), None),
        Believed::Automaton(task) => (task.name.as_str(), Some(&**task)),
    };
    if let Some(psi) = psi_task {
        automata.push(("psi", &psi.dfa));
    }
    let mut product = metered(observer, Stage::Product, |meter| {
        Hypergame::with_automata_metered(&problem.arena, &automata, problem.states, meter)
    })?;
    super::warn_missing_propositions(&product, &problem.arena_name, observer);
    let k = problem.tasks.len();
    let regions = metered(observer, Stage::Attractors, |meter| {
        TaskRegions::compute_metered(&product, k, problem.believed.belief(), meter)
    });
    // Only the attractors walk the graph backwards: the MDP and its solver need the memory.
    product.release_predecessors();
    let task_automata: Vec<(String, TaskAutomaton)> = problem
        .tasks
        .iter()
        .map(|t| (t.name.clone(), t.task.automaton()))
        .collect();
    let games = SubtaskGamesReport::new(
        &task_automata,
        (psi_name, psi_task.map(Task::automaton)),
        &problem.payoffs,
        &product,
        &regions,
    );
    let names: Vec<String> = problem.tasks.iter().map(|t| t.name.clone()).collect();
    let strategy = requests
        .export_strategy
        .then(|| {
            let export =
                SubtaskStrategyExport::new(&product, &regions, &problem.payoffs, &names, psi_name);
            serde_json::to_string_pretty(&export)
        })
        .transpose()?;
    let picture = |solution: Option<(&SubtaskGame, &SubtaskSolution)>| {
        requests
            .picture
            .as_ref()
            .map(|request| {
                let subject = GeneralPictureSubject {
                    map_name: &problem.arena_name,
                    map: problem.map.as_ref(),
                    tasks: &problem.tasks,
                    believed: psi_name,
                    product: &product,
                    regions: &regions,
                    payoffs: &problem.payoffs,
                    solution,
                    max_steps: requests.max_steps,
                };
                draw_general(&subject, request)
            })
            .transpose()
    };
    let Some(options) = &problem.mdp else {
        let svg = picture(None)?;
        return Ok(GeneralOutcome {
            report: GeneralReport::Games(Box::new(games)),
            drn: None,
            strategy,
            svg,
        });
    };
    let explain = super::explained_state(&product, requests)?;
    let game = SubtaskGame::new(&product, &regions, &problem.payoffs, &names);
    let solution = SubtaskSolution::solve(&game, problem.risk, options, observer)?;
    let svg = picture(Some((&game, &solution)))?;
    let report_requests = ReportRequests {
        explain,
        simulate: requests.simulate,
        trace: requests.trace,
        max_steps: requests.max_steps,
    };
    let report = solution.report(&game, games, &report_requests, observer);
    Ok(GeneralOutcome {
        report: GeneralReport::Full(Box::new(report)),
        drn: requests.export_mdp.then(|| solution.drn(&game)),
        strategy,
        svg,
    })
}

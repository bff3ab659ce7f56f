//! The whole pipeline as library calls: the stages one by one (see the crate's example), or
//! [`run`] for a whole problem, in the paper's form or the general one, returning finished
//! reports and exports.
//!
//! ```
//! use hypersynth::arena::{ArenaBuilder, Owner};
//! use hypersynth::game::States;
//! use hypersynth::ltl;
//! use hypersynth::game::Payoffs;
//! use hypersynth::pipeline::{self, Problem, Requests, Tasks};
//! use hypersynth::translate::{Builtin, TranslationLimits};
//!
//! // The robot moves from `r` to the adversary's `a`, which can send it on to `g` (A and B
//! // hold there) or back; the adversary believes the task is `F A`.
//! let mut builder = ArenaBuilder::new();
//! let r = builder.add_state("r", Owner::Robot, [], None)?;
//! let a = builder.add_state("a", Owner::Adversary, [], None)?;
//! let g = builder.add_state("g", Owner::Robot, ["A", "B"], None)?;
//! builder.add_transition(r, "go", a)?;
//! builder.add_transition(a, "on", g)?;
//! builder.add_transition(a, "back", r)?;
//! builder.add_transition(g, "stay", g)?;
//! builder.set_initial(r);
//! let translator = Builtin::new(TranslationLimits::default());
//! let problem = Problem {
//!     arena_name: "example".into(),
//!     arena: builder.build()?,
//!     map: None,
//!     tasks: Tasks::from_formulas(
//!         &ltl::parse("F A & F B")?,
//!         &ltl::parse("F A")?,
//!         None,
//!         &translator,
//!         Payoffs::default(),
//!     )?,
//!     states: States::Full,
//!     mdp: None, // stop after the games
//! };
//! let outcome = pipeline::run(&problem, &Requests::default(), &mut ())?;
//! // The adversary can send the robot back forever: no task is winnable from h0.
//! assert!(outcome.report.games.regions.iter().all(|region| !region.realizable));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! Costs are those of the stages: the product is linear in `|arena| · |DFA1| · |DFA2|`, the
//! attractors linear in its edges; for the MDP solver see
//! [`crate::mdp::solve`](mod@crate::mdp::solve).

mod engine;
mod explorer;
mod opportunistic;
mod picture;
mod robust;
mod robust_implicit;
mod shown;
pub mod spec;
mod tasks;

pub use engine::{
    ImplicitError, ImplicitProduct, ImplicitSolution, Output, RunError, Sinks, Source,
    explicit_bytes, implicit_bytes, implicit_outcome, solve, solve_into,
};
pub use explorer::{ALL_SLICES, ALL_TABLES, ExplorerError, explorer, page};
pub use opportunistic::{Learnt, MdpOptions, OpportunisticSolution, ReportRequests};
pub use picture::{Picture, PictureError, PictureRequest, PictureSubject, draw};
pub use robust::{RobustSolution, curve_runs, learning_curve, sigma_l_states};
pub use tasks::{Believed, HoaTaskError, Subtask, Task, Tasks, TasksError, is_task_name};

use crate::arena::Arena;
use crate::arena::gridworld::Gridworld;
use crate::game::{Hypergame, HypergameError, StateNameError, States, TaskRegions};
use crate::mdp::DrnForm;
use crate::opportunistic::export::{ArenaSource, ExportInputs, Scope};
use crate::opportunistic::observations::CurvePoint;
use crate::opportunistic::view::SolvedHypergame;
use crate::render::{self, Title, TitleChoice};
use crate::report::{Games, ProductFacts, Report, StageError, StrategyExport, TaskAutomaton};
use crate::stage::{Observer, Stage, metered};

impl Tasks {
    /// The hypergame of the tasks on `arena`: the product of the arena with the sub-tasks'
    /// automata (and psi's when it has one).
    pub fn hypergame<'a>(
        &'a self,
        arena: &'a Arena,
        states: States,
    ) -> Result<Hypergame<'a>, HypergameError> {
        Hypergame::with_automata(arena, &self.automata(), states)
    }

    /// The winning regions of the tasks on `game`, their hypergame: `Win(T)` for every set of
    /// sub-tasks and `Win(psi)`.
    pub fn regions(&self, game: &Hypergame) -> TaskRegions {
        TaskRegions::compute(game, self.subtasks().len(), self.believed().belief())
    }

    /// The games stage's summary of `game`, their hypergame, with its `regions`.
    pub fn games(&self, game: &Hypergame, regions: &TaskRegions) -> Games {
        let facts = ProductFacts::of(game, regions);
        self.games_of(facts)
    }

    /// The games stage's summary of the product with these `facts` (either engine's).
    pub(crate) fn games_of(&self, facts: ProductFacts) -> Games {
        let automata: Vec<TaskAutomaton> =
            self.subtasks().iter().map(|t| t.task.automaton()).collect();
        let psi = match self.believed() {
            Believed::Automaton(task) => Some(task.automaton()),
            Believed::Tasks { .. } => None,
        };
        Games::from_facts(
            self.presentation(),
            &automata,
            (self.believed().name(), psi),
            self.payoffs(),
            facts,
        )
    }
}

/// A whole problem: an arena (or map), the robot's tasks, and the MDP stage's options (`None`
/// to stop after the games).
pub struct Problem {
    /// The arena's name in messages and titles (its file, `<stdin>`...).
    pub arena_name: String,
    /// The arena.
    pub arena: Arena,
    /// The map the arena was built from, if any (pictures need it).
    pub map: Option<Gridworld>,
    /// The sub-tasks, their payoffs, the belief and the risk rule (the paper's form or not).
    pub tasks: Tasks,
    /// Which product states to enumerate.
    pub states: States,
    /// The MDP stage's options; `None` stops after the games.
    pub mdp: Option<MdpOptions>,
}

/// What [`run`] should produce besides the report.
#[derive(Clone, Debug, Default)]
pub struct Requests {
    /// The state (`ARENA_STATE|Q1|Q2`, or `h0`) whose decision table to include.
    pub explain: Option<String>,
    /// Number of simulated runs.
    pub simulate: Option<u32>,
    /// Whether to trace one run.
    pub trace: bool,
    /// Step bound of simulated and traced runs.
    pub max_steps: u32,
    /// Whether to write the MDP in DRN.
    pub export_mdp: bool,
    /// Whether that DRN keeps only the controller's choices.
    pub induced: bool,
    /// How that DRN encodes the payoffs (for the nominal and the interval model alike).
    pub drn_form: DrnForm,
    /// Whether to export the controller (docs/semantics.md §9).
    pub export_controller: bool,
    /// Which robot states the exported controller decides at.
    pub controller_scope: Scope,
    /// Whether the exported controller carries a certificate (docs/semantics.md §9.4).
    pub certificate: bool,
    /// Whether to export the reactive strategies as JSON.
    pub export_strategy: bool,
    /// A picture to draw.
    pub picture: Option<PictureRequest>,
    /// Whether to give the simulated runs (`simulate`) in the observations format
    /// ([`crate::opportunistic::observations::record`]).
    pub record: bool,
    /// Whether to make the explorer page (HTML).
    pub html: bool,
    /// A learning curve, when sigma_L is learnt from observations.
    pub learning_curve: Option<CurveRequest>,
}

/// A learning curve to add to the report (docs/semantics.md §10), and perhaps to draw.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct CurveRequest {
    /// The numbers of runs to learn from, each from 1 to all of them; empty: [`curve_runs`]
    /// of all the runs observed.
    pub runs: Vec<usize>,
    /// Whether to draw it (SVG), and with which title.
    pub picture: Option<TitleChoice>,
}

/// What [`run`] produced.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// The report.
    pub report: Report,
    /// The MDP in DRN, when asked.
    pub drn: Option<String>,
    /// The reactive strategies as JSON, when asked.
    pub strategy: Option<String>,
    /// The picture as SVG, when asked.
    pub svg: Option<String>,
    /// The exported controller (JSON, format `hypersynth-controller/2`), when asked.
    pub controller: Option<String>,
    /// The simulated runs in the observations format (`Requests::record`).
    pub record: Option<String>,
    /// The explorer page (HTML), when asked.
    pub html: Option<String>,
    /// The learning curve as SVG, when asked.
    pub curve_svg: Option<String>,
}

/// Why a run failed after its inputs were read.
#[derive(Debug, thiserror::Error)]
pub enum PipelineError {
    /// The product could not be built.
    #[error(transparent)]
    Hypergame(#[from] HypergameError),
    /// The state to explain is not a product state.
    #[error(transparent)]
    Explain(StateNameError),
    /// The MDP stage failed.
    #[error(transparent)]
    Stage(#[from] StageError),
    /// The picture could not be drawn.
    #[error(transparent)]
    Picture(#[from] PictureError),
    /// The explorer page could not be made.
    #[error(transparent)]
    Explorer(#[from] ExplorerError),
    /// A learning curve was asked for without observations to learn from.
    #[error("a learning curve needs the opportunistic stage with observations to learn from")]
    CurveWithoutObservations,
    /// A question of the MDP stage was asked of a solution of the games only.
    #[error("the problem was solved without the MDP stage")]
    NoMdpStage,
    /// The exported controller's certificate could not be made.
    #[error("cannot certify the exported controller: {0}")]
    Certificate(#[from] crate::certificate::CertifyError),
    /// A JSON export could not be serialised.
    #[error("cannot serialise the export: {0}")]
    Json(#[from] serde_json::Error),
}

/// Runs `problem`: the product of the sub-tasks' automata (and psi's), `Win(T)` for every set
/// and `Win(psi)`, then (unless games only) the MDP stage, with the reports, exports and picture
/// `requests` ask for, in the problem's form. `observer` is told about every stage and warned
/// about propositions no arena state carries.
pub fn run(
    problem: &Problem,
    requests: &Requests,
    observer: &mut dyn Observer,
) -> Result<Outcome, PipelineError> {
    Solved::new(problem, observer)?.outcome(requests, observer)
}

/// A problem solved: its hypergame, winning regions and (unless games only) MDP stage, kept so
/// that reports, exports, pictures and per-state questions can be asked of it any number of
/// times without solving again ([`run`] asks once).
pub struct Solved<'p> {
    /// The problem solved.
    pub problem: &'p Problem,
    /// Its hypergame (predecessors released).
    pub product: Hypergame<'p>,
    /// `Win(T)` for every set of sub-tasks and `Win(psi)`.
    pub regions: TaskRegions,
    /// The MDP stage's result, unless the problem stops after the games.
    pub solution: Option<OpportunisticSolution>,
}

impl<'p> Solved<'p> {
    /// Solves `problem` (see [`run`]), telling `observer` about every stage.
    pub fn new(problem: &'p Problem, observer: &mut dyn Observer) -> Result<Self, PipelineError> {
        let tasks = &problem.tasks;
        let mut product = metered(observer, Stage::Product, |meter| {
            Hypergame::with_automata_metered(
                &problem.arena,
                &tasks.automata(),
                problem.states,
                meter,
            )
        })?;
        warn_missing_propositions(&product, &problem.arena_name, observer);
        let k = tasks.subtasks().len();
        let regions = metered(observer, Stage::Attractors, |meter| {
            TaskRegions::compute_metered(&product, k, tasks.believed().belief(), meter)
        });
        // Only the attractors walk the graph backwards: the MDP and its solver need the memory.
        product.release_predecessors();
        let solution = match &problem.mdp {
            Some(options) => {
                let game =
                    SolvedHypergame::new(&product, &regions, tasks.payoffs(), tasks.presentation());
                Some(OpportunisticSolution::solve(
                    &game,
                    tasks.risk(),
                    options,
                    observer,
                )?)
            }
            None => None,
        };
        Ok(Solved {
            problem,
            product,
            regions,
            solution,
        })
    }

    /// The solved hypergame as the MDP stage, the controller and the reports see it (linear in
    /// the product's size: build it once for many questions).
    pub fn game(&self) -> SolvedHypergame<'_, 'p> {
        let tasks = &self.problem.tasks;
        SolvedHypergame::new(
            &self.product,
            &self.regions,
            tasks.payoffs(),
            tasks.presentation(),
        )
    }

    /// The reactive strategies' export of the solved hypergame (serialise it to write it).
    pub fn strategy_export(&self) -> StrategyExport<'_> {
        let tasks = &self.problem.tasks;
        StrategyExport::new(
            &self.product,
            &self.regions,
            tasks.payoffs(),
            tasks.presentation(),
            tasks.believed().name(),
        )
    }

    /// The report, exports, picture and explorer page that `requests` ask for (simulations
    /// are run here, as the `simulation` stage told to `observer`).
    pub fn outcome(
        &self,
        requests: &Requests,
        observer: &mut dyn Observer,
    ) -> Result<Outcome, PipelineError> {
        let (problem, product, regions) = (self.problem, &self.product, &self.regions);
        let tasks = &problem.tasks;
        let presentation = tasks.presentation();
        let games = tasks.games(product, regions);
        let strategy = requests
            .export_strategy
            .then(|| serde_json::to_string_pretty(&self.strategy_export()))
            .transpose()?;
        let game = self.game();
        let solution = &self.solution;
        // The one traced run, for the report, the picture and the explorer alike.
        let wants_trace = requests.trace
            || requests.html
            || requests
                .picture
                .as_ref()
                .is_some_and(|p| p.picture == Picture::Trace);
        let trace = solution
            .as_ref()
            .filter(|_| wants_trace)
            .map(|solution| solution.trace(&game, requests.max_steps));
        let subject = PictureSubject {
            map_name: &problem.arena_name,
            map: problem.map.as_ref(),
            tasks,
            game: &game,
            solution: solution.as_ref(),
            trace: trace.as_ref(),
        };
        let svg = match &requests.picture {
            Some(request) => Some(draw(&subject, request)?),
            None => None,
        };
        let explain = match solution {
            Some(_) => explained_state(requests, product.initial(), |text| {
                product.parse_state(text)
            })?,
            None => None,
        };
        let mut synthesis = solution.as_ref().map(|solution| {
            let report_requests = ReportRequests {
                explain,
                simulate: requests.simulate,
                max_steps: requests.max_steps,
            };
            let trace = trace.as_ref().filter(|_| requests.trace);
            solution.synthesis(&game, &report_requests, trace, observer)
        });
        // The simulated runs as observations: the controller against the model's sigma_L.
        let record = match (&solution, &problem.mdp, requests.simulate) {
            (Some(solution), Some(options), Some(runs)) if requests.record => {
                Some(crate::opportunistic::observations::record(
                    &solution.controller(&game),
                    &solution.adversary,
                    runs,
                    options.seed,
                    requests.max_steps,
                ))
            }
            _ => None,
        };
        let mut drn = solution
            .as_ref()
            .filter(|_| requests.export_mdp)
            .map(|solution| solution.drn(&game, requests.induced, requests.drn_form));
        // The robust stage, when sigma_L is learnt: its summary joins the report, its interval
        // model replaces the nominal one as the DRN.
        let mut curve_svg = None;
        let mut robust_solution = None;
        if let (Some(options), Some(solution), Some(synthesis)) =
            (&problem.mdp, &solution, synthesis.as_mut())
            && let Some(learnt) = &options.learnt
        {
            let robust = RobustSolution::solve(&game, tasks.risk(), options, learnt, observer)?;
            if requests.export_mdp {
                drn = Some(robust.drn(&game, options, requests.drn_form));
            }
            let simulate = requests.simulate.map(|runs| (runs, requests.max_steps));
            let mut summary = robust.summary(&game, learnt, options, &solution.adversary, simulate);
            if let Some(request) = &requests.learning_curve {
                let about = (problem.arena_name.as_str(), learnt, options);
                let value = synthesis.decision.value;
                curve_svg = curve(request, about, (&mut summary, value), |prefix| {
                    let robust =
                        RobustSolution::solve(&game, tasks.risk(), options, prefix, observer)?;
                    // No simulation: the summary's adversary model is not used.
                    let summary = robust.summary(&game, prefix, options, &robust.adversary, None);
                    Ok::<_, PipelineError>(summary.curve_point())
                })?;
            }
            synthesis.robust = Some(summary);
            robust_solution = Some(robust);
        } else if requests.learning_curve.is_some() {
            return Err(PipelineError::CurveWithoutObservations);
        }
        let controller = match solution.as_ref().filter(|_| requests.export_controller) {
            Some(solution) => {
                let arena = match &problem.map {
                    Some(map) => ArenaSource::Map(crate::arena::map::write(map)),
                    None => ArenaSource::Text(crate::arena::write(&problem.arena)),
                };
                let inputs = ExportInputs {
                    arena,
                    believed: tasks.believed().as_file(tasks.names().len()),
                    automata: &tasks.automata(),
                    scope: requests.controller_scope,
                };
                // With a learnt sigma_L, the robust controller, which has the guarantee.
                Some(match &robust_solution {
                    Some(robust) => robust.export_controller(
                        &game,
                        tasks.risk(),
                        &inputs,
                        requests.certificate,
                    )?,
                    None => solution.export_controller(&game, &inputs, requests.certificate)?,
                })
            }
            None => None,
        };
        let report = Report {
            presentation: presentation.clone(),
            games,
            synthesis,
        };
        let html = match requests.html {
            true => Some(explorer(&subject, &report)?),
            false => None,
        };
        Ok(Outcome {
            report,
            drn,
            strategy,
            svg,
            controller,
            record,
            html,
            curve_svg,
        })
    }
}

/// The learning curve's picture: both values against the runs, with the value under the
/// options' sigma_L (`value`, the truth when it is known) as the reference.
/// The learning curve `request` asks of `summary`, the robust stage learnt from `learnt` on
/// the arena named `arena_name` (each other point made by `point` from the observations' first
/// runs, [`learning_curve`]), set in the summary, and its picture when asked (`value`: h0's
/// value under the model's own sigma_L, the picture's reference line).
fn curve<E: From<StageError>>(
    request: &CurveRequest,
    (arena_name, learnt, options): (&str, &Learnt, &MdpOptions),
    (summary, value): (&mut crate::report::RobustSummary, f64),
    point: impl FnMut(&Learnt) -> Result<CurvePoint, E>,
) -> Result<Option<String>, E> {
    let runs = match request.runs.is_empty() {
        true => curve_runs(learnt.observations.num_runs()),
        false => request.runs.clone(),
    };
    summary.learning_curve = robust::curve_points(learnt, &runs, Some(summary), point)?;
    let Some(title) = &request.picture else {
        return Ok(None);
    };
    let lines = vec![
        "Learning curve: the value of h0 learnt from the first runs observed".to_string(),
        format!(
            "{}, observations {} ({} runs), δ = {}, discount {}",
            arena_name,
            learnt.file,
            learnt.observations.num_runs(),
            learnt.delta,
            options.solve.discount.get()
        ),
    ];
    let reference = render::title::symbols(&format!(
        "value under sigma_L {}: {}",
        options.sigma_l.title(),
        crate::report::number(value)
    ));
    Ok(Some(render::learning_curve(
        &Title::new(lines, title),
        &summary.learning_curve,
        Some((value, &reference)),
    )))
}

/// Warns `observer` of each proposition of the tasks that the arena does not know
/// ([`Hypergame::unknown_propositions`]).
fn warn_missing_propositions(game: &Hypergame, arena_name: &str, observer: &mut dyn Observer) {
    for proposition in game.unknown_propositions() {
        observer.warning(&format!(
            "proposition `{proposition}` is not a proposition of {arena_name} (no state carries \
             it and the arena does not declare it): it is always false"
        ));
    }
}

/// The product state whose decision table `requests` ask for (`h0` is the `initial` state,
/// any other name is read by `parse`): either engine's.
fn explained_state<S>(
    requests: &Requests,
    initial: S,
    parse: impl FnOnce(&str) -> Result<S, StateNameError>,
) -> Result<Option<S>, PipelineError> {
    Ok(match requests.explain.as_deref() {
        None => None,
        Some("h0") => Some(initial),
        Some(text) => Some(parse(text).map_err(PipelineError::Explain)?),
    })
}

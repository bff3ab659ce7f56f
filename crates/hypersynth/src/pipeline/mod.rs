//! The whole pipeline as library calls: the stages one by one (see the crate's example), or
//! [`run`] and [`run_general`] for a whole problem, returning finished reports and exports.
//!
//! ```
//! use hypersynth::arena::{ArenaBuilder, Owner};
//! use hypersynth::game::States;
//! use hypersynth::ltl;
//! use hypersynth::pipeline::{self, MdpOptions, PaperTasks, Problem, Report, Requests};
//! use hypersynth::translate::{Builtin, Limits};
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
//! let translator = Builtin::new(Limits::default());
//! let problem = Problem {
//!     arena_name: "example".into(),
//!     arena: builder.build()?,
//!     map: None,
//!     tasks: PaperTasks::from_formulas(
//!         &ltl::parse("F A & F B")?,
//!         &ltl::parse("F A")?,
//!         None,
//!         &translator,
//!     )?,
//!     states: States::Full,
//!     mdp: None, // stop after the games
//! };
//! let outcome = pipeline::run(&problem, &Requests::default(), &mut ())?;
//! let Report::Games(games) = outcome.report else { unreachable!() };
//! // The adversary can send the robot back forever: no task is winnable from h0.
//! assert_eq!(games.realizable.get(hypersynth::game::Task::Phi), &false);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! Costs are those of the stages: the product is linear in `|arena| · |DFA1| · |DFA2|`, the
//! attractors linear in its edges; for the MDP solver see
//! [`crate::mdp::solve`](mod@crate::mdp::solve).

mod general;
mod opportunistic;
mod picture;
mod tasks;

pub use general::{
    Believed, GeneralOutcome, GeneralProblem, GeneralReport, Subtask, SubtaskOptions,
    SubtaskSolution, run_general,
};
pub use opportunistic::{MdpOptions, OpportunisticSolution, ReportRequests};
pub use picture::{
    GeneralPictureSubject, Picture, PictureError, PictureRequest, PictureSubject, draw,
    draw_general,
};
pub use tasks::{PaperTasks, Task, TasksError};

use crate::arena::Arena;
use crate::arena::gridworld::Gridworld;
use crate::game::{HState, Hypergame, HypergameError, StateNameError, States, WinningRegions};
use crate::mdp::view::SolvedHypergame;
use crate::report::{GamesReport, OpportunisticReport, StageError, StrategyExport};
use crate::stage::{Meter, Observer, Stage, metered};

impl PaperTasks {
    /// The hypergame of the two tasks on `arena`.
    pub fn hypergame<'a>(
        &'a self,
        arena: &'a Arena,
        states: States,
    ) -> Result<Hypergame<'a>, HypergameError> {
        self.hypergame_metered(arena, states, &mut Meter::unobserved(Stage::Product))
    }

    /// [`PaperTasks::hypergame`], reporting its progress to `meter`
    /// ([`Hypergame::with_automata_metered`]).
    pub fn hypergame_metered<'a>(
        &'a self,
        arena: &'a Arena,
        states: States,
        meter: &mut Meter<'_>,
    ) -> Result<Hypergame<'a>, HypergameError> {
        let automata = [("phi1", &self.phi1.dfa), ("phi2", &self.phi2.dfa)];
        Hypergame::with_automata_metered(arena, &automata, states, meter)
    }
}

/// The main form's problem: an arena (or map), the paper's two tasks, and the MDP stage's
/// options (`None` to stop after the games).
pub struct Problem {
    /// The arena's name in messages and titles (its file, `<stdin>`...).
    pub arena_name: String,
    /// The arena.
    pub arena: Arena,
    /// The map the arena was built from, if any (pictures need it).
    pub map: Option<Gridworld>,
    /// phi1 and phi2.
    pub tasks: PaperTasks,
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
    /// Whether to export the reactive strategies as JSON.
    pub export_strategy: bool,
    /// A picture to draw.
    pub picture: Option<PictureRequest>,
}

/// The main form's report: the games alone, or extended with the MDP stage.
#[derive(Clone, Debug)]
pub enum Report {
    /// The problem stopped after the games.
    Games(Box<GamesReport>),
    /// The opportunistic report (which holds the games report).
    Opportunistic(Box<OpportunisticReport>),
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
}

/// Why the main form failed after its inputs were read.
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
    /// A JSON export could not be serialised.
    #[error("cannot serialise the export: {0}")]
    Json(#[from] serde_json::Error),
}

/// Runs the main form on `problem`: product, attractors, then (unless games only) the MDP
/// stage, with the reports, exports and picture `requests` ask for. `observer` is told about
/// every stage and warned about propositions no arena state carries.
pub fn run(
    problem: &Problem,
    requests: &Requests,
    observer: &mut dyn Observer,
) -> Result<Outcome, PipelineError> {
    let tasks = &problem.tasks;
    let mut game = metered(observer, Stage::Product, |meter| {
        tasks.hypergame_metered(&problem.arena, problem.states, meter)
    })?;
    warn_missing_propositions(&game, &problem.arena_name, observer);
    let regions = metered(observer, Stage::Attractors, |meter| {
        WinningRegions::compute_metered(&game, meter)
    });
    // Only the attractors walk the graph backwards: the MDP and its solver need the memory.
    game.release_predecessors();
    let strategy = requests
        .export_strategy
        .then(|| serde_json::to_string_pretty(&StrategyExport::new(&game, &regions)))
        .transpose()?;
    let games = GamesReport::new(
        &tasks.phi,
        [tasks.phi1.automaton(), tasks.phi2.automaton()],
        &game,
        &regions,
    );
    let solved = SolvedHypergame::new(&game, &regions);
    let solution = match &problem.mdp {
        Some(options) => Some(OpportunisticSolution::solve(&solved, options, observer)?),
        None => None,
    };
    let svg = match &requests.picture {
        Some(request) => {
            let subject = PictureSubject {
                map_name: &problem.arena_name,
                map: problem.map.as_ref(),
                formulas: [&tasks.phi, &tasks.phi1.name, &tasks.phi2.name],
                game: &game,
                regions: &regions,
                solution: solution.as_ref(),
                max_steps: requests.max_steps,
            };
            Some(draw(&subject, request)?)
        }
        None => None,
    };
    let (report, drn) = match &solution {
        Some(solution) => {
            let explain = explained_state(&game, requests)?;
            let report_requests = ReportRequests {
                explain,
                simulate: requests.simulate,
                trace: requests.trace,
                max_steps: requests.max_steps,
            };
            let report = solution.report(&solved, games, &report_requests, observer);
            let drn = requests.export_mdp.then(|| solution.drn(&solved));
            (Report::Opportunistic(Box::new(report)), drn)
        }
        None => (Report::Games(Box::new(games)), None),
    };
    Ok(Outcome {
        report,
        drn,
        strategy,
        svg,
    })
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

/// The product state whose decision table `requests` ask for (`h0` is the initial state).
fn explained_state(game: &Hypergame, requests: &Requests) -> Result<Option<HState>, PipelineError> {
    Ok(match requests.explain.as_deref() {
        None => None,
        Some("h0") => Some(game.initial()),
        Some(text) => Some(game.parse_state(text).map_err(PipelineError::Explain)?),
    })
}

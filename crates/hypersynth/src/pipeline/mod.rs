//! The whole pipeline from code: tasks, arena and adversary model in; reports, the solution,
//! exports and pictures out.
//!
//! ```
//! use hypersynth::arena;
//! use hypersynth::game::{States, WinningRegions};
//! use hypersynth::ltl;
//! use hypersynth::mdp::adversary::SigmaL;
//! use hypersynth::mdp::build::Payoffs;
//! use hypersynth::mdp::solve::SolveOptions;
//! use hypersynth::mdp::view::SolvedHypergame;
//! use hypersynth::pipeline::{MdpOptions, OpportunisticSolution, PaperTasks};
//! use hypersynth::translate::{Builtin, Limits};
//!
//! // The case study: a 5x5 gridworld, the robot must visit A and B avoiding obstacles (O); the
//! // adversary believes it only has to visit A.
//! let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../specs/case-study/arena.txt");
//! let arena = arena::parse(&std::fs::read_to_string(path)?)?.arena;
//! let phi = ltl::parse("(!O U A) & (!O U B)")?;
//! let psi = ltl::parse("!O U A")?;
//! let translator = Builtin::new(Limits::default());
//! let tasks = PaperTasks::from_formulas(&phi, &psi, None, &translator)?;
//!
//! // Each stage is a function over plain values: the hypergame, its winning regions...
//! let game = tasks.hypergame(&arena, States::Full)?;
//! let regions = WinningRegions::compute(&game);
//! let solved = SolvedHypergame::new(&game, &regions);
//! // ... then the MDP of the adversary's stochastic strategies, solved with a certified bound.
//! let options = MdpOptions {
//!     sigma_l: SigmaL::Random { seed: 2019 },
//!     sigma_l_name: "random".into(),
//!     seed: 2019,
//!     payoffs: Payoffs::default(),
//!     solve: SolveOptions::default(),
//! };
//! let solution = OpportunisticSolution::solve(&solved, &options, &mut ())?;
//!
//! // From h0 the robot can force phi1 only, yet it collects r = 300 (both tasks): the
//! // adversary, believing the robot is after A alone, leaves the way to B open.
//! let value = solution.solution.value(solution.mdp.mdp().initial());
//! assert!((value.lower - 300.0).abs() < 1e-6 && value.upper - value.lower <= 1e-6);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! [`run`] does all of it for the command line's main form and returns finished texts;
//! the stages can also be called one by one (as above), so that a caller can stop after any
//! of them. Costs are those of the stages: the product is linear in `|arena| · |DFA1| ·
//! |DFA2|`, the attractors linear in its edges, the MDP solver see [`crate::mdp::solve`].

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
use crate::stage::{Observer, Stage, timed};

impl PaperTasks {
    /// The hypergame of the two tasks on `arena`.
    pub fn hypergame<'a>(
        &'a self,
        arena: &'a Arena,
        states: States,
    ) -> Result<Hypergame<'a>, HypergameError> {
        Hypergame::new(arena, &self.phi1.dfa, &self.phi2.dfa, states)
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
    let game = timed(observer, Stage::Product, || {
        tasks.hypergame(&problem.arena, problem.states)
    })?;
    warn_missing_propositions(&game, &problem.arena_name, observer);
    let regions = timed(observer, Stage::Attractors, || {
        WinningRegions::compute(&game)
    });
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

/// Warns `observer` of each proposition of the tasks that no state of the arena carries.
fn warn_missing_propositions(game: &Hypergame, arena_name: &str, observer: &mut dyn Observer) {
    for proposition in game.missing_propositions() {
        observer.warning(&format!(
            "proposition `{proposition}` is carried by no state of {arena_name}: it is always \
             false"
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

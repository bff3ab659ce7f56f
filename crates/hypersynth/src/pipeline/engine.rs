//! A problem's specification run on either engine ([`solve`]): the explicit engine stores the
//! product and every stage's result, the implicit one ([`crate::implicit`]) computes states and
//! edges from the arena's rules and never expands a map. Both give the same [`Report`] but for
//! the line that names the engine and the solver's own line (sweeps, gap, end components); the
//! implicit engine makes the report, a state's decision table, the controller's export (the
//! same search and tables, `opportunistic::export::export_from`), the DRN (the same writer,
//! streamed into a sink of [`Sinks`] when given), the reactive strategies (the same writer,
//! `report::StrategyExport`, streamed likewise), the simulations, the pictures and the
//! explorer page (the same drawing and page, read through `pipeline::shown`) and the robust
//! stage of a learnt sigma_L (`robust_implicit.rs`), with either enumeration: every output.
//!
//! The implicit engine runs in steps: [`ImplicitProduct`] (the space, the regions, the games
//! report), [`ImplicitSolution`] (the MDP and robust stages, solved once and kept) and
//! [`ImplicitSolution::outcome`], which answers any requests from the kept solution (the
//! command line asks once, the Python package's `Solution` many times).
//!
//! The choice, when the specification leaves it open: the explicit engine when its estimate
//! ([`explicit_bytes`]) fits what the observer allows, since it is faster on what fits; else the
//! implicit one. The implicit engine asks for its memory in two steps: its bits and bytes per
//! product state before the regions ([`implicit_bytes`]), its bounds per live state before the
//! solve.

use rayon::prelude::*;

use super::MdpOptions;
use super::explorer::{About, ExplorerError, page_on};
use super::opportunistic::trace_rows;
use super::picture::{Picture, draw_on};
use super::robust_implicit::ImplicitRobust;
use super::shown::{Controlled, ImplicitShown};
use super::spec::{Field, MdpSpec, ProblemSpec, ReadArena, SpecError, SpecErrorKind};
use super::{Outcome, PipelineError, Requests, Tasks, curve};
use crate::arena::gridworld::Gridworld;
use crate::arena::{Arena, Owner};
use crate::certificate::certify;
use crate::game::SubsetPayoffs;
use crate::game::{Engine, HState, HypergameError, StateNameError, States, TaskSet};
use crate::game::{classes_of, won_bits};
use crate::implicit::{
    self, ArenaMoves, Distribution, Kind, MapMoves, Model, Moves, Regions, SourceMoves, Space,
};
use crate::limits::{Bytes, MemoryLimit};
use crate::mdp::DrnForm;
use crate::mdp::drn::{stream_model, write_model};
use crate::mdp::solve::Interval;
use crate::opportunistic::adversary::SigmaL;
use crate::opportunistic::build::{BuildError, MdpSizes, STOP, SizeCount};
use crate::opportunistic::controller::{Explanation, clamped};
use crate::opportunistic::export::{
    ArenaSource, ExportInputs, ModelRules, SigmaLRule, export_from,
};
use crate::opportunistic::observations::{RunNames, record_on};
use crate::opportunistic::presentation::Presentation;
use crate::opportunistic::simulate::{Simulation, SimulationOptions, simulate_on, trace_on};
use crate::report::ArenaSummary;
use crate::report::RobustSummary;
use crate::report::{Games, ProductFacts, RegionFacts, Report, StrategyExport};
use crate::report::{InitialDecision, Settings, SolverSummary, Synthesis, TraceReport};
use crate::stage::{Meter, Observer, Stage, metered};

/// Bytes per product state the explicit engine needs with the MDP stage (measured: 144 to 157
/// on the 40x40 map, docs/engines.md), and for the games alone.
const EXPLICIT_WITH_MDP: u64 = 160;
const EXPLICIT_GAMES: u64 = 90;
/// Bytes per product state the implicit engine needs before its solve: a bit per region, the
/// levels' two bytes, the attractor's one-byte counter while it runs.
const IMPLICIT_PER_STATE: u64 = 4;
/// Bytes per live state of the implicit solve: two bounds, the components' order and search.
pub(super) const IMPLICIT_PER_LIVE: u64 = 24;
/// Bytes per live state the nominal solve may add for the compiled edges of the component it
/// sweeps.
pub(super) const IMPLICIT_COMPILED: u64 = implicit::COMPILED_PER_LIVE as u64;

/// About what the explicit engine needs for a product of `states` states.
pub fn explicit_bytes(states: u64, with_mdp: bool) -> u64 {
    states.saturating_mul(match with_mdp {
        true => EXPLICIT_WITH_MDP,
        false => EXPLICIT_GAMES,
    })
}

/// About what the implicit engine needs for a product of `states` states of which `live` are
/// chance or non-absorbing decision nodes (0 for the games alone).
pub fn implicit_bytes(states: u64, live: u64) -> u64 {
    states
        .saturating_mul(IMPLICIT_PER_STATE)
        .saturating_add(live.saturating_mul(IMPLICIT_PER_LIVE))
}

impl From<crate::report::StageError> for RunError {
    fn from(error: crate::report::StageError) -> RunError {
        RunError::Pipeline(PipelineError::Stage(error))
    }
}

/// Why [`solve`] failed.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The specification is wrong (or its arena too large to read).
    #[error(transparent)]
    Spec(#[from] SpecError),
    /// The run failed after its inputs were read.
    #[error(transparent)]
    Pipeline(#[from] PipelineError),
    /// A stage of the implicit engine failed.
    #[error(transparent)]
    Implicit(#[from] ImplicitError),
    /// A stage of the implicit engine would need more memory than the observer allows.
    #[error(transparent)]
    Memory(#[from] MemoryLimit),
    /// An output could not be written into its sink ([`Sinks`]).
    #[error("cannot write the {what}: {error}", what = .0.describe(), error = .1)]
    Write(Output, std::io::Error),
}

/// Why a stage of the implicit engine failed.
#[derive(Debug, thiserror::Error)]
pub enum ImplicitError {
    /// The model could not be made.
    #[error(transparent)]
    Model(#[from] implicit::ModelError),
    /// The values were not certified.
    #[error(transparent)]
    Solve(#[from] implicit::SolveError),
    /// The policy could not be made or does not collect the certified value.
    #[error(transparent)]
    Policy(#[from] implicit::PolicyError),
}

/// Where a run writes an output as it makes it, instead of returning its text in the
/// [`Outcome`].
#[derive(Default)]
pub struct Sinks<'a> {
    /// The MDP in DRN, when `Requests::export_mdp` asks for it: the implicit engine streams it
    /// here state by state; the explicit engine writes its text here once made.
    pub drn: Option<&'a mut dyn std::io::Write>,
    /// The reactive strategies, when `Requests::export_strategy` asks for them: both engines
    /// stream them here state by state.
    pub strategy: Option<&'a mut dyn std::io::Write>,
}

/// An output written into a sink of [`Sinks`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Output {
    /// The MDP in DRN.
    Drn,
    /// The reactive strategies.
    Strategy,
}

impl Output {
    /// What it is, for messages.
    pub fn describe(self) -> &'static str {
        match self {
            Output::Drn => "MDP",
            Output::Strategy => "strategies",
        }
    }
}

/// Writes the strategies' `export` into `sink` as it is serialised, or returns its text
/// without a sink: the same bytes either way.
fn write_strategies(
    export: &impl serde::Serialize,
    sink: Option<&mut dyn std::io::Write>,
) -> std::io::Result<Option<String>> {
    match sink {
        Some(sink) => {
            serde_json::to_writer_pretty(sink, export)?;
            Ok(None)
        }
        None => Ok(Some(serde_json::to_string_pretty(export)?)),
    }
}

/// Runs the problem `spec` describes on the engine it names, or the one its size calls for
/// (module documentation), with the reports and exports `requests` ask for.
pub fn solve(
    spec: &ProblemSpec,
    requests: &Requests,
    observer: &mut dyn Observer,
) -> Result<Outcome, RunError> {
    solve_into(spec, requests, Sinks::default(), observer)
}

/// [`solve`], writing into `sinks` the outputs they take (those are `None` in the
/// [`Outcome`]).
pub fn solve_into(
    spec: &ProblemSpec,
    requests: &Requests,
    mut sinks: Sinks<'_>,
    observer: &mut dyn Observer,
) -> Result<Outcome, RunError> {
    let tasks = spec.build_tasks(observer)?;
    let with_mdp = spec.mdp.is_some();
    let (read, engine) = metered(observer, Stage::Parse, |meter| {
        let read = spec.arena.read(meter)?;
        let states = product_states(&read, &tasks).map_err(PipelineError::Hypergame)?;
        let engine = match spec.engine {
            Some(engine) => engine,
            None => choose(states, with_mdp, meter)?,
        };
        Ok::<_, RunError>((read, engine))
    })?;
    match engine {
        Engine::Explicit => {
            let (arena, map) = metered(observer, Stage::Parse, |meter| read.expand(meter))?;
            let problem = spec.problem(tasks, arena, map)?;
            let solved = super::Solved::new(&problem, observer)?;
            // The strategies are streamed into their sink, not made as a text.
            let streamed = requests.export_strategy && sinks.strategy.is_some();
            let requests = Requests {
                export_strategy: requests.export_strategy && !streamed,
                ..requests.clone()
            };
            let mut outcome = solved.outcome(&requests, observer)?;
            if streamed {
                write_strategies(&solved.strategy_export(), sinks.strategy)
                    .map_err(|e| RunError::Write(Output::Strategy, e))?;
            }
            if let Some(sink) = sinks.drn.as_deref_mut()
                && let Some(text) = outcome.drn.take()
            {
                sink.write_all(text.as_bytes())
                    .map_err(|e| RunError::Write(Output::Drn, e))?;
            }
            Ok(outcome)
        }
        Engine::Implicit => {
            let source = match &read {
                ReadArena::Arena(arena, _) => Source::Arena(arena),
                ReadArena::Map(world) => Source::Map(world),
            };
            let about = (spec.arena.name(), source);
            implicit(
                (spec.states, spec.mdp.as_ref()),
                &tasks,
                about,
                requests,
                sinks,
                observer,
            )
        }
    }
}

/// What the implicit engine makes of `tasks` on `arena` named `name` (by `map`'s rules, when
/// the arena was expanded from one: the map itself is not expanded again), enumerating `states`,
/// with the MDP stage of `mdp` when given and the outputs `requests` ask for: what [`solve`]
/// makes with the implicit engine, for a caller that holds its tasks and arena already (the
/// Python package).
pub fn implicit_outcome(
    tasks: &Tasks,
    (name, arena, map): (&str, &Arena, Option<&Gridworld>),
    (states, mdp): (States, Option<&MdpSpec>),
    requests: &Requests,
    observer: &mut dyn Observer,
) -> Result<Outcome, RunError> {
    let source = map.map_or(Source::Arena(arena), Source::Map);
    implicit(
        (states, mdp),
        tasks,
        (name, source),
        requests,
        Sinks::default(),
        observer,
    )
}

/// Where the implicit engine reads the arena's moves from.
#[derive(Clone, Copy)]
pub enum Source<'a> {
    /// A stored arena (its CSR and transpose).
    Arena(&'a Arena),
    /// A map's rules, never expanded.
    Map(&'a Gridworld),
}

impl<'a> Source<'a> {
    /// Its moves: the arena's, or the map's rules after the checks that expanding the map
    /// makes (the same errors).
    pub fn moves(self) -> Result<SourceMoves<'a>, RunError> {
        Ok(match self {
            Source::Arena(arena) => SourceMoves::Arena(ArenaMoves::new(arena)),
            Source::Map(world) => SourceMoves::Map(Box::new(map_moves(world)?)),
        })
    }

    /// The map, when the arena is one.
    fn map(self) -> Option<&'a Gridworld> {
        match self {
            Source::Map(world) => Some(world),
            Source::Arena(_) => None,
        }
    }

    /// What an exported controller carries of the arena.
    fn arena(self) -> ArenaSource {
        match self {
            Source::Arena(arena) => ArenaSource::Text(crate::arena::write(arena)),
            Source::Map(world) => ArenaSource::Map(crate::arena::map::write(world)),
        }
    }
}

/// The number of product states of `tasks` on the arena `read` (every state: both engines'
/// full enumeration).
fn product_states(read: &ReadArena, tasks: &Tasks) -> Result<u64, HypergameError> {
    let automata: Vec<_> = tasks.automata().into_iter().map(|(_, dfa)| dfa).collect();
    Ok(match read {
        ReadArena::Arena(arena, _) => Space::new(&ArenaMoves::new(arena), &automata)?.num_states(),
        ReadArena::Map(world) => match MapMoves::new(world) {
            Ok(moves) => Space::new(&moves, &automata)?.num_states(),
            // The map's own error comes when it is expanded.
            Err(_) => 0,
        },
    } as u64)
}

/// The explicit engine if its estimate fits beside what is in use, else the implicit one if
/// its own does; else the refusal, naming both estimates.
fn choose(states: u64, with_mdp: bool, meter: &mut Meter<'_>) -> Result<Engine, MemoryLimit> {
    let explicit = explicit_bytes(states, with_mdp);
    if meter.reserve(explicit, String::new).is_ok() {
        return Ok(Engine::Explicit);
    }
    let implicit = implicit_bytes(states, 0);
    meter.reserve(implicit, || {
        format!(
            "a product of {states} states (the explicit engine would need about {})",
            Bytes(explicit)
        )
    })?;
    Ok(Engine::Implicit)
}

/// The implicit engine's run of the product enumerating `states`, with the MDP stage of `mdp`:
/// the product, its solution, then the outputs `requests` ask for.
fn implicit(
    mdp: (States, Option<&MdpSpec>),
    tasks: &Tasks,
    (name, source): (&str, Source<'_>),
    requests: &Requests,
    sinks: Sinks<'_>,
    observer: &mut dyn Observer,
) -> Result<Outcome, RunError> {
    fn on<M: Moves>(
        mdp: (States, Option<&MdpSpec>),
        tasks: &Tasks,
        about: (&str, Source<'_>),
        moves: &M,
        (requests, sinks): (&Requests, Sinks<'_>),
        observer: &mut dyn Observer,
    ) -> Result<Outcome, RunError> {
        let product = ImplicitProduct::new(tasks, about, moves, mdp, observer)?;
        // A bad state to explain is refused before anything is solved, and the strategies
        // are written (their ranks made and freed) before the MDP stage holds its memory.
        product.explained(requests)?;
        let Sinks { drn, strategy } = sinks;
        let strategy = match requests.export_strategy {
            true => product.strategies(strategy, observer)?,
            false => None,
        };
        let solution = ImplicitSolution::new(&product, observer)?;
        let requests = Requests {
            export_strategy: false,
            ..requests.clone()
        };
        let sinks = Sinks {
            drn,
            strategy: None,
        };
        let outcome = solution.outcome(&requests, sinks, observer)?;
        Ok(Outcome {
            strategy,
            ..outcome
        })
    }
    let about = (name, source);
    match source {
        Source::Arena(arena) => {
            let moves = ArenaMoves::new(arena);
            on(mdp, tasks, about, &moves, (requests, sinks), observer)
        }
        Source::Map(world) => {
            let moves = map_moves(world)?;
            on(mdp, tasks, about, &moves, (requests, sinks), observer)
        }
    }
}

/// A map's rules, after the checks that expanding the map makes (the same errors).
fn map_moves(world: &Gridworld) -> Result<MapMoves, RunError> {
    MapMoves::new(world)
        .map_err(|e| SpecError::new(Field::Arena, SpecErrorKind::Gridworld(e)).into())
}

/// The implicit engine's product of a problem's tasks with an arena's `moves`: its space, its
/// winning regions, the games report and the MDP stage's options (checked against the rules).
/// What [`ImplicitSolution`] solves.
pub struct ImplicitProduct<'s, 'm, M> {
    tasks: &'s Tasks,
    name: &'s str,
    source: Source<'s>,
    space: Space<'m, M>,
    regions: Regions,
    games: Games,
    options: Option<MdpOptions>,
}

impl<'s, 'm, M: Moves> ImplicitProduct<'s, 'm, M> {
    /// The product of `tasks` with `moves` (the rules of `source`, named `name`), enumerating
    /// `states`, with the MDP stage of `mdp` when given; the memory it keeps asked of
    /// `observer` first.
    pub fn new(
        tasks: &'s Tasks,
        (name, source): (&'s str, Source<'s>),
        moves: &'m M,
        (states, mdp): (States, Option<&MdpSpec>),
        observer: &mut dyn Observer,
    ) -> Result<Self, RunError> {
        // sigma_L's weights checked against the rules before any work, as the explicit engine
        // checks them against its arena.
        let options = mdp.map(|mdp| mdp.build_on(moves)).transpose()?;
        let automata: Vec<_> = tasks.automata().into_iter().map(|(_, dfa)| dfa).collect();
        let space = metered(observer, Stage::Product, |meter| {
            let space = Space::new(moves, &automata).map_err(PipelineError::Hypergame)?;
            let states = space.num_states() as u64;
            meter.reserve(implicit_bytes(states, 0), || {
                format!("the implicit engine's regions of {states} product states")
            })?;
            Ok::<_, RunError>(space)
        })?;
        let space = match states {
            States::Full => space,
            States::Reachable => reachable(space, observer)?,
        };
        let k = tasks.subtasks().len();
        let regions = metered(observer, Stage::Attractors, |_| {
            Regions::compute(&space, k, tasks.believed().belief())
        });
        let games = games(tasks, &space, &regions);
        Ok(ImplicitProduct {
            tasks,
            name,
            source,
            space,
            regions,
            games,
            options,
        })
    }

    /// The product's space.
    pub fn space(&self) -> &Space<'m, M> {
        &self.space
    }

    /// The winning regions.
    pub fn regions(&self) -> &Regions {
        &self.regions
    }

    /// The tasks.
    pub fn tasks(&self) -> &'s Tasks {
        self.tasks
    }

    /// The MDP stage's options (none for the games only).
    pub fn options(&self) -> Option<&MdpOptions> {
        self.options.as_ref()
    }

    /// The games report.
    pub fn games(&self) -> &Games {
        &self.games
    }

    /// The state named `text` (`ARENA_STATE|Q1|…`, not `h0`).
    pub fn parse_state(&self, text: &str) -> Result<u32, StateNameError> {
        let names: Vec<String> = self
            .tasks
            .automata()
            .into_iter()
            .map(|(name, _)| name.to_string())
            .collect();
        self.space.parse_state(text, &names)
    }

    /// The strategies' export, streamed into `sink` (its text without one).
    fn strategies(
        &self,
        sink: Option<&mut dyn std::io::Write>,
        observer: &mut dyn Observer,
    ) -> Result<Option<String>, RunError> {
        strategies(self.tasks, &self.space, &self.regions, sink, observer)
    }

    /// The product state whose decision table `requests` ask for (none without the MDP stage,
    /// as on the explicit engine).
    fn explained(&self, requests: &Requests) -> Result<Option<u32>, PipelineError> {
        if self.options.is_none() {
            return Ok(None);
        }
        super::explained_state(requests, self.space.initial(), |text| {
            self.parse_state(text)
        })
    }
}

/// The MDP stage of an [`ImplicitSolution`].
struct MdpStage<'a, 'm, M> {
    options: &'a MdpOptions,
    model: Model<'a, 'm, M>,
    /// The report's synthesis without the outputs of requests.
    synthesis: Synthesis,
    solution: implicit::Solution,
    policy: implicit::Policy,
    /// The robust stage, when sigma_L is learnt.
    robust: Option<ImplicitRobust<'a, 'm, M>>,
}

/// An [`ImplicitProduct`] solved once (its MDP stage, and the robust stage when sigma_L is
/// learnt), whose outputs ([`ImplicitSolution::outcome`] and the questions below) read the
/// kept solution: the command line asks once, the Python package's `Solution` many times.
pub struct ImplicitSolution<'a, 'm, M> {
    product: &'a ImplicitProduct<'a, 'm, M>,
    mdp: Option<MdpStage<'a, 'm, M>>,
}

impl<'a, 'm, M: Moves> ImplicitSolution<'a, 'm, M> {
    /// Solves `product`'s MDP stage (none without its options) and robust stage.
    pub fn new(
        product: &'a ImplicitProduct<'a, 'm, M>,
        observer: &mut dyn Observer,
    ) -> Result<Self, RunError> {
        let (tasks, space, regions) = (product.tasks, &product.space, &product.regions);
        let Some(options) = &product.options else {
            return Ok(ImplicitSolution { product, mdp: None });
        };
        let model = model(tasks, space, regions, &options.sigma_l, observer)?;
        let (synthesis, solution, policy) = synthesis(tasks, &model, options, observer)?;
        let robust = match &options.learnt {
            Some(learnt) => Some(ImplicitRobust::solve(
                tasks,
                (space, regions),
                options,
                learnt,
                observer,
            )?),
            None => None,
        };
        Ok(ImplicitSolution {
            product,
            mdp: Some(MdpStage {
                options,
                model,
                synthesis,
                solution,
                policy,
                robust,
            }),
        })
    }

    /// The product solved.
    pub fn product(&self) -> &'a ImplicitProduct<'a, 'm, M> {
        self.product
    }

    /// The MDP stage, or the error that there is none.
    fn stage(&self) -> Result<&MdpStage<'a, 'm, M>, RunError> {
        self.mdp
            .as_ref()
            .ok_or(RunError::Pipeline(PipelineError::NoMdpStage))
    }

    /// The decision at h0 as the report gives it (none without the MDP stage).
    pub fn decision(&self) -> Option<&InitialDecision> {
        Some(&self.mdp.as_ref()?.synthesis.decision)
    }

    /// The certified value of product state `h` under the problem's sigma_L (none without
    /// the MDP stage).
    pub fn value(&self, h: u32) -> Option<Interval> {
        let stage = self.mdp.as_ref()?;
        Some(stage.solution.value(&stage.model, h))
    }

    /// How reports label product state `h`.
    pub fn label(&self, h: u32) -> String {
        let product = self.product;
        let presentation = product.tasks.presentation();
        presentation.state_label(
            &product.regions,
            product.tasks.payoffs(),
            HState::from_u32(h),
        )
    }

    /// The decision table of product state `h`.
    pub fn explain(&self, h: u32, observer: &mut dyn Observer) -> Result<Explanation, RunError> {
        let stage = self.stage()?;
        let solved = (&stage.solution, &stage.policy);
        explanation(&stage.model, solved, h, stage.options, observer)
    }

    /// The simulation of `requests.simulate` runs and the traced run `requests.trace` asks
    /// for, from `seed`, as the report gives them (the recorded runs when asked).
    pub fn runs(
        &self,
        requests: &Requests,
        seed: u64,
        observer: &mut dyn Observer,
    ) -> Result<Runs, RunError> {
        let stage = self.stage()?;
        let solved = (&stage.solution, &stage.policy);
        let tasks = self.product.tasks;
        runs(tasks, &stage.model, solved, seed, requests, observer)
    }

    /// The MDP under the problem's sigma_L in DRN (only the controller's choices with
    /// `induced`), in `form`.
    pub fn drn(
        &self,
        induced: bool,
        form: DrnForm,
        observer: &mut dyn Observer,
    ) -> Result<String, RunError> {
        let stage = self.stage()?;
        let written = drn_model(&stage.model, induced.then_some(&stage.policy), observer)?;
        let mut text = String::new();
        write_model(
            &mut text,
            &written,
            stage.options.solve.discount.get(),
            form,
        )
        .expect("formatting into a String does not fail");
        Ok(text)
    }

    /// The robust stage's summary, when sigma_L is learnt, with the robust controller's
    /// `simulate` runs (runs, step bound) when asked.
    pub fn robust_summary(
        &self,
        simulate: Option<(u32, u32)>,
        observer: &mut dyn Observer,
    ) -> Result<Option<RobustSummary>, RunError> {
        let Some(stage) = &self.mdp else {
            return Ok(None);
        };
        let (Some(robust), Some(learnt)) = (&stage.robust, &stage.options.learnt) else {
            return Ok(None);
        };
        let about = (learnt, stage.options);
        Ok(Some(robust.summary(
            self.product.tasks,
            about,
            simulate,
            observer,
        )?))
    }

    /// The report and the outputs `requests` ask for, from the kept solution, writing into
    /// `sinks` the outputs they take (those are `None` in the [`Outcome`]).
    pub fn outcome(
        &self,
        requests: &Requests,
        sinks: Sinks<'_>,
        observer: &mut dyn Observer,
    ) -> Result<Outcome, RunError> {
        let product = self.product;
        let (tasks, space, regions) = (product.tasks, &product.space, &product.regions);
        let explained = product.explained(requests)?;
        let Sinks {
            drn: drn_sink,
            strategy: strategy_sink,
        } = sinks;
        let strategy = match requests.export_strategy {
            true => product.strategies(strategy_sink, observer)?,
            false => None,
        };
        // A learning curve needs the robust stage of a learnt sigma_L.
        if requests.learning_curve.is_some()
            && self.mdp.as_ref().is_none_or(|stage| stage.robust.is_none())
        {
            return Err(PipelineError::CurveWithoutObservations.into());
        }
        let (mut controller, mut drn, mut record, mut curve_svg) = (None, None, None, None);
        let synthesis = match &self.mdp {
            Some(stage) => {
                let (options, model) = (stage.options, &stage.model);
                let (solution, policy) = (&stage.solution, &stage.policy);
                let mut synthesis = stage.synthesis.clone();
                if let Some(h) = explained {
                    synthesis.explanation = Some(self.explain(h, observer)?);
                }
                if requests.simulate.is_some() || requests.trace {
                    (synthesis.simulation, synthesis.trace, record) =
                        self.runs(requests, options.seed, observer)?;
                }
                // The robust stage, when sigma_L is learnt: its summary joins the report and
                // its controller, which has the guarantee, is the one exported.
                let robust = match (&stage.robust, &options.learnt) {
                    (Some(robust), Some(learnt)) => {
                        let simulate = requests.simulate.map(|runs| (runs, requests.max_steps));
                        let mut summary =
                            robust.summary(tasks, (learnt, options), simulate, observer)?;
                        if let Some(request) = &requests.learning_curve {
                            let about = (product.name, learnt, options);
                            let value = synthesis.decision.value;
                            let space_regions = (space, regions);
                            curve_svg = curve(request, about, (&mut summary, value), |prefix| {
                                let robust = ImplicitRobust::solve(
                                    tasks,
                                    space_regions,
                                    options,
                                    prefix,
                                    observer,
                                )?;
                                let summary =
                                    robust.summary(tasks, (prefix, options), None, observer)?;
                                Ok::<_, RunError>(summary.curve_point())
                            })?;
                        }
                        synthesis.robust = Some(summary);
                        Some(robust)
                    }
                    _ => None,
                };
                if requests.export_mdp {
                    // With a learnt sigma_L, the interval MDP of the robust stage.
                    let written = match robust {
                        Some(robust) => drn_model(&robust.model, None, observer)?
                            .with_intervals(&robust.intervals),
                        None => drn_model(model, requests.induced.then_some(policy), observer)?,
                    };
                    let (g, form) = (options.solve.discount.get(), requests.drn_form);
                    match drn_sink {
                        Some(sink) => {
                            stream_model(sink, &written, g, form)
                                .map_err(|e| RunError::Write(Output::Drn, e))?;
                        }
                        None => {
                            let mut text = String::new();
                            write_model(&mut text, &written, g, form)
                                .expect("formatting into a String does not fail");
                            drn = Some(text);
                        }
                    }
                }
                if requests.export_controller {
                    let exported = match robust {
                        Some(robust) => {
                            let rules = ModelRules {
                                risk: tasks.risk(),
                                sigma_l: SigmaLRule::Learnt {
                                    delta: robust.region.delta,
                                    counts: robust.counts.entries(space.moves()),
                                },
                            };
                            let solved = (&*robust.solution, &robust.policy);
                            let file = (rules, Lower::Solution, product.source.arena());
                            export(tasks, &robust.model, solved, file, requests, observer)?
                        }
                        None => {
                            let rules = ModelRules {
                                risk: tasks.risk(),
                                sigma_l: SigmaLRule::of(&options.sigma_l),
                            };
                            let solved = (solution, policy);
                            let file = (rules, Lower::Chain(options), product.source.arena());
                            export(tasks, model, solved, file, requests, observer)?
                        }
                    };
                    controller = Some(exported);
                }
                Some(synthesis)
            }
            None => None,
        };
        let report = Report {
            presentation: tasks.presentation().clone(),
            games: product.games.clone(),
            synthesis,
        };
        let solved = self.mdp.as_ref().map(|stage| {
            let solved = (&stage.solution, &stage.policy);
            (&stage.model, solved, stage.options)
        });
        let shown = ImplicitShown {
            space,
            regions,
            payoffs: tasks.payoffs(),
            presentation: tasks.presentation(),
        };
        let about = Drawn {
            name: product.name,
            map: product.source.map(),
        };
        let (svg, html) = drawings(&shown, solved, (tasks, about, &report), requests, observer)?;
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

/// What the implicit engine's pictures and page show besides the product: the arena's name
/// and the map, when the arena is one.
struct Drawn<'a> {
    name: &'a str,
    map: Option<&'a Gridworld>,
}

/// The picture and the explorer page `requests` ask for, of the implicit engine's product
/// `shown` and its solved model (unless games only), from one controller: the explicit
/// engine's drawing and page ([`draw_on`], [`page_on`]) read through `Shown`, the traced run
/// as the explicit engine traces it (the simulation's first run).
fn drawings<M: Moves>(
    shown: &ImplicitShown<'_, '_, M>,
    solved: Option<(&Model<'_, '_, M>, Solved<'_>, &MdpOptions)>,
    (tasks, about, report): (&Tasks, Drawn<'_>, &Report),
    requests: &Requests,
    observer: &mut dyn Observer,
) -> Result<(Option<String>, Option<String>), RunError> {
    let picture = requests.picture.as_ref();
    if picture.is_none() && !requests.html {
        return Ok((None, None));
    }
    let page = About {
        map_name: about.name,
        map: about.map,
        tasks,
        report,
    };
    let draw = |controlled: Option<&Controlled>| -> Result<_, PipelineError> {
        let svg = picture
            .map(|request| draw_on(about.map, tasks, shown, controlled, request))
            .transpose()?;
        let html = match requests.html {
            true => Some(
                crate::explorer::html(&page_on(&page, shown, controlled)?)
                    .map_err(ExplorerError::Json)?,
            ),
            false => None,
        };
        Ok((svg, html))
    };
    let Some((model, solved, options)) = solved else {
        return Ok(draw(None)?);
    };
    let wants_trace = requests.html || picture.is_some_and(|p| p.picture == Picture::Trace);
    let (epsilon, max_iterations) = (options.solve.epsilon, options.solve.max_iterations);
    let made = with_controller(Stage::Simulation, model, solved, observer, |controller| {
        let trace =
            wants_trace.then(|| trace_on(controller, controller, options.seed, requests.max_steps));
        let explain = |states: &[HState]| {
            let states: Vec<u32> = states.iter().map(|h| h.as_u32()).collect();
            controller.explain_all(&states, epsilon, max_iterations)
        };
        let controlled = Controlled {
            controller,
            explain: &explain,
            options,
            trace: trace.as_ref(),
        };
        draw(Some(&controlled))
    })?;
    Ok(made?)
}

/// `space` enumerating only the states reachable from h0, their bit per index asked of the
/// observer first.
fn reachable<'m, M: Moves>(
    space: Space<'m, M>,
    observer: &mut dyn Observer,
) -> Result<Space<'m, M>, RunError> {
    metered(observer, Stage::Product, |meter| {
        let states = space.num_states() as u64;
        meter.reserve(Space::<M>::reachable_bytes(states), || {
            format!("the reachable states among {states} product states")
        })?;
        Ok(space.reachable())
    })
}

/// The strategies' export of the implicit engine's product, streamed into `sink` (its text
/// without one): each region's ranks (and with the reachable enumeration the search that
/// orders the states) asked of the observer before they are computed, a refusal ending the
/// export with it.
fn strategies<M: Moves>(
    tasks: &Tasks,
    space: &Space<'_, M>,
    regions: &Regions,
    sink: Option<&mut dyn std::io::Write>,
    observer: &mut dyn Observer,
) -> Result<Option<String>, RunError> {
    metered(observer, Stage::Attractors, |meter| {
        let states = space.num_states();
        if space.enumeration() == States::Reachable {
            // The search that lists the reachable states in order.
            meter.reserve(Space::<M>::reachable_bytes(states as u64), || {
                format!("the order of the reachable states among {states} product states")
            })?;
        }
        let what = || format!("the ranks of a winning region over {states} product states");
        let written = budgeted(meter, what, |budget| {
            let source = implicit::Strategies::new(space, regions, budget);
            let (payoffs, psi) = (tasks.payoffs(), tasks.believed().name());
            let export = StrategyExport::of(source, payoffs, tasks.presentation(), psi);
            write_strategies(&export, sink)
        })?;
        written.map_err(|e| RunError::Write(Output::Strategy, e))
    })
}

/// Runs `f` with a budget that asks `meter` for the bytes offered to it (`what` names them):
/// after the first refusal the budget says no, and the run ends with that refusal.
fn budgeted<T>(
    meter: &mut Meter<'_>,
    what: impl Fn() -> String,
    f: impl FnOnce(&mut dyn FnMut(u64) -> bool) -> T,
) -> Result<T, RunError> {
    let mut refusal = None;
    let made = f(&mut |bytes| {
        refusal = meter.reserve(bytes, &what).err();
        refusal.is_none()
    });
    match refusal {
        Some(refusal) => Err(RunError::Memory(refusal)),
        None => Ok(made),
    }
}

/// The implicit engine's solved `model` (with `chain`, the Markov chain it induces) as the DRN
/// writer reads it, what its numbering holds asked of the observer first.
fn drn_model<'a, 'b, 'm, M: Moves>(
    model: &'a Model<'b, 'm, M>,
    chain: Option<&'a implicit::Policy>,
    observer: &mut dyn Observer,
) -> Result<implicit::Drn<'a, 'b, 'm, M>, RunError> {
    metered(observer, Stage::MdpBuild, |meter| {
        let bytes = implicit::Drn::bytes(model.space());
        meter.reserve(bytes, || {
            let states = model.space().num_enumerated();
            format!("the numbers of {states} reachable product states")
        })?;
        Ok(implicit::Drn::new(model, chain))
    })
}

/// The decision table of product state `h` of the implicit engine's solved `model`.
fn explanation<M: Moves>(
    model: &Model<'_, '_, M>,
    solved: (&implicit::Solution, &implicit::Policy),
    h: u32,
    options: &MdpOptions,
    observer: &mut dyn Observer,
) -> Result<Explanation, RunError> {
    let solve = &options.solve;
    let table = with_controller(Stage::Evaluation, model, solved, observer, |controller| {
        controller.explain(h, solve.epsilon, solve.max_iterations)
    })?;
    Ok(table.map_err(ImplicitError::Policy)?)
}

/// Runs `f` on the controller of the implicit engine's solved `model` in `stage`: each set's
/// ranks (what its reactive strategy reads) asked of the observer before they are computed, a
/// refusal ending the stage with it.
fn with_controller<M: Moves, T>(
    stage: Stage,
    model: &Model<'_, '_, M>,
    (solution, policy): (&implicit::Solution, &implicit::Policy),
    observer: &mut dyn Observer,
    f: impl FnOnce(&implicit::Controller<'_, '_, '_, M>) -> T,
) -> Result<T, RunError> {
    metered(observer, stage, |meter| {
        let states = model.space().num_states();
        let what = || format!("the ranks of a reactive strategy over {states} product states");
        budgeted(meter, what, |budget| {
            f(&implicit::Controller::new(model, solution, policy).with_budget(budget))
        })
    })
}

/// The implicit engine's solution and policy.
type Solved<'a> = (&'a implicit::Solution, &'a implicit::Policy);

/// The simulation, the traced run and the recorded runs (observations text) of a run.
type Runs = (Option<Simulation>, Option<TraceReport>, Option<String>);

/// What the implicit engine's simulation stage makes of its solved `model`: the simulation,
/// the traced run and the recorded runs `requests` ask for, all from one controller (so a
/// committed set's ranks are computed once), as the explicit engine makes them.
fn runs<M: Moves>(
    tasks: &Tasks,
    model: &Model<'_, '_, M>,
    solved: (&implicit::Solution, &implicit::Policy),
    seed: u64,
    requests: &Requests,
    observer: &mut dyn Observer,
) -> Result<Runs, RunError> {
    let (space, moves) = (model.space(), model.space().moves());
    let max_steps = requests.max_steps;
    with_controller(Stage::Simulation, model, solved, observer, |controller| {
        let simulation = requests.simulate.map(|runs| {
            // The runs share one random stream: no progress is reported but the stage's time
            // (the meter answers the ranks' reservations).
            let options = SimulationOptions {
                runs,
                seed,
                max_steps,
            };
            let unobserved = &mut Meter::unobserved(Stage::Simulation);
            simulate_on(controller, controller, options, unobserved)
        });
        // The first run of the simulation, as the explicit engine traces it.
        let trace = requests.trace.then(|| {
            let trace = trace_on(controller, controller, seed, max_steps);
            let presentation = tasks.presentation();
            TraceReport {
                ending: trace.ending,
                payoff: trace.payoff,
                steps: trace_rows(
                    &trace,
                    |h| space.name(h.as_u32()),
                    |h| controller.label(h.as_u32()),
                    |a| moves.actions()[a as usize].clone(),
                    |set| presentation.set_name(set),
                ),
            }
        });
        // The simulated runs again, one line each, as the explicit engine records them.
        let record = requests.simulate.filter(|_| requests.record).map(|runs| {
            let names = RunNames {
                arena_state: &|h| space.arena_state(h.as_u32()),
                state: &|s| moves.name(s),
                action: &|a| moves.actions()[a as usize].clone(),
            };
            record_on(controller, controller, &names, (runs, seed, max_steps))
        });
        (simulation, trace, record)
    })
}

/// Where an exported controller's certificate takes its lower bounds: the controller's own
/// values (its Markov chain from h0, solved to the options' precision), or the solution's
/// (the robust stage's, which its policy collects against every adversary).
enum Lower<'o> {
    Chain(&'o MdpOptions),
    Solution,
}

/// The controller of the implicit engine's solved `model` as an exported file with `rules`
/// (the explicit engine's search and tables, [`export_from`]); its certificate, when asked,
/// from the `lower` bounds and the solution's upper ones.
fn export<M: Moves>(
    tasks: &Tasks,
    model: &Model<'_, '_, M>,
    solved: (&implicit::Solution, &implicit::Policy),
    (rules, lower, arena): (ModelRules, Lower<'_>, ArenaSource),
    requests: &Requests,
    observer: &mut dyn Observer,
) -> Result<String, RunError> {
    let inputs = ExportInputs {
        arena,
        believed: tasks.believed().as_file(tasks.names().len()),
        automata: &tasks.automata(),
        scope: requests.controller_scope,
    };
    let mut file = with_controller(Stage::Policy, model, solved, observer, |controller| {
        export_from(controller, rules, &inputs)
    })?;
    if requests.certificate {
        // Below, as the explicit engine makes them; entry `s · |tuples| + t` is product state
        // `s · |tuples| + t` here.
        let (solution, policy) = solved;
        let chain = match lower {
            Lower::Chain(options) => Some(metered(observer, Stage::Policy, |meter| {
                let states = model.space().num_states() as u64;
                let bytes = states / 8 + 24 * policy.num_live() as u64;
                meter.reserve(bytes, || {
                    format!(
                        "the controller's values for its certificate over {states} product \
                         states"
                    )
                })?;
                let solve = &options.solve;
                implicit::chain(model, policy, solve.epsilon, solve.max_iterations)
                    .map_err(|e| RunError::Implicit(ImplicitError::Policy(e)))
            })?),
            Lower::Solution => None,
        };
        let state = |entry: usize| u32::try_from(entry).ok();
        let lower = |entry| {
            let value = |h| match &chain {
                Some(chain) => chain.value(h),
                None => Some(solution.value(model, h)),
            };
            state(entry)
                .and_then(value)
                .map_or(f64::NAN, |value| value.lower)
        };
        let upper = |entry| state(entry).map_or(f64::NAN, |h| solution.value(model, h).upper);
        let certificate = certify(&file, lower, upper).map_err(PipelineError::from)?;
        file.certificate = Some(certificate);
    }
    let text = serde_json::to_string(&file).map_err(PipelineError::from)?;
    Ok(text + "\n")
}

/// The games report of the implicit engine's product.
fn games<M: Moves>(tasks: &Tasks, space: &Space<'_, M>, regions: &Regions) -> Games {
    let moves = space.moves();
    let k = regions.num_tasks();
    let robot_arena = (0..moves.num_states() as u32)
        .filter(|&s| moves.owner(s) == Owner::Robot)
        .count();
    let mut robot_in = vec![0usize; (1 << k) - 1];
    let classes = classes_of(
        k,
        space.states().map(|h| {
            let won = won_bits(k, |set| regions.wins(set, h));
            let owner = space.owner(h);
            if owner == Owner::Robot {
                for set in TaskSet::non_empty(k).filter(|&set| regions.wins(set, h)) {
                    robot_in[set.0 as usize - 1] += 1;
                }
            }
            (owner, won, regions.believed().contains(h as usize))
        }),
    );
    let h0 = space.initial();
    let facts = ProductFacts {
        arena: ArenaSummary {
            states: moves.num_states(),
            robot_states: robot_arena,
            adversary_states: moves.num_states() - robot_arena,
            transitions: (0..moves.num_states() as u32)
                .map(|s| moves.degree(s) as usize)
                .sum(),
        },
        enumerated: (0..space.num_automata())
            .map(|i| space.automaton_states(i))
            .collect(),
        states: space.enumeration(),
        engine: Engine::Implicit,
        product_states: space.num_enumerated(),
        product_edges: space.num_edges(),
        regions: TaskSet::non_empty(k)
            .map(|set| {
                let region = regions.region(set);
                RegionFacts {
                    states: region.states.count(),
                    robot_states: robot_in[set.0 as usize - 1],
                    max_rank: region.max_rank,
                    initial_rank: region.initial_rank,
                }
            })
            .collect(),
        believed_region: regions.believed().count(),
        classes,
        initial: space.name(h0),
        initial_wins: TaskSet::non_empty(k)
            .filter(|&set| regions.wins(set, h0))
            .collect(),
        initial_psi: regions.believed().contains(h0 as usize),
        belief: tasks.believed().belief(),
        missing_propositions: space.missing_propositions().to_vec(),
    };
    tasks.games_of(facts)
}

/// The hypergame MDP of the implicit engine's product, the adversary playing `sigma_l` where
/// it believes it has lost.
pub(super) fn model<'a, 'm, M: Moves>(
    tasks: &'a Tasks,
    space: &'a Space<'m, M>,
    regions: &'a Regions,
    sigma_l: &SigmaL,
    observer: &mut dyn Observer,
) -> Result<Model<'a, 'm, M>, RunError> {
    if space.moves().actions().iter().any(|action| action == STOP) {
        return Err(PipelineError::Stage(BuildError::ReservedAction.into()).into());
    }
    Ok(metered(observer, Stage::MdpBuild, |_| {
        Model::new(
            space,
            regions,
            tasks.payoffs(),
            tasks.presentation(),
            tasks.risk(),
            sigma_l,
        )
    })
    .map_err(ImplicitError::Model)?)
}

/// The MDP stage on the implicit engine's `model`: its certified values, the policy and its
/// evaluation from h0, reported as the explicit engine reports them.
fn synthesis<M: Moves>(
    tasks: &Tasks,
    model: &Model<'_, '_, M>,
    options: &MdpOptions,
    observer: &mut dyn Observer,
) -> Result<(Synthesis, implicit::Solution, implicit::Policy), RunError> {
    let (space, regions) = (model.space(), model.regions());
    let (payoffs, presentation) = (tasks.payoffs(), tasks.presentation());
    let live = model.num_live();
    metered(observer, Stage::Solve, |meter| {
        meter.reserve(
            live.saturating_mul(IMPLICIT_PER_LIVE + IMPLICIT_COMPILED),
            || format!("the implicit engine's bounds of {live} live states"),
        )
    })?;
    let solve = &options.solve;
    let (g, max_iterations) = (solve.discount.get(), solve.max_iterations);
    let solution = metered(observer, Stage::Solve, |_| {
        let precision = match solve.relative {
            true => implicit::Precision::relative(solve.epsilon),
            false => implicit::Precision::absolute(solve.epsilon),
        };
        implicit::solve(model, g, precision, max_iterations)
    })
    .map_err(ImplicitError::Solve)?;
    let policy = metered(observer, Stage::Policy, |_| {
        implicit::policy(model, &solution, g, max_iterations)
    })
    .map_err(ImplicitError::Policy)?;
    let h0 = space.initial();
    let top = payoffs.all();
    let value = clamped(solution.value(model, h0), top);
    let evaluation = metered(observer, Stage::Evaluation, |_| {
        implicit::evaluate(model, &policy, value, solve.epsilon, max_iterations)
    })
    .map_err(ImplicitError::Policy)?;
    let policy_value = clamped(evaluation.value, top);
    let robot_first = space.owner(h0) == Owner::Robot;
    let names = tasks.names();
    let best = |h: u32| regions.best(payoffs, h).unwrap_or_default();
    // The c-th choice of `h`, named as the explicit MDP names it.
    let choice_name = |h: u32, c: u8| {
        let choice = model.choice(h, c);
        model.choice_name(choice.expect("the policy's choice is one of the state's"))
    };
    let worthless = value.upper == 0.0;
    let (action, commits_to) = match robot_first {
        false => (None, None),
        true if worthless => (None, None),
        true if model.commits(h0) => (None, Some(best(h0).names(&names))),
        true => match policy.choice(h0) {
            Some(c) => {
                let name = choice_name(h0, c);
                let set = (name == STOP).then(|| best(h0).names(&names));
                (Some(name), set)
            }
            None => (None, None),
        },
    };
    // Reports that state no guarantee name the policy's action at h0 even where nothing can be
    // gained.
    let action = match presentation.layout().states_guarantees {
        true => action,
        false => policy
            .mdp_choice(h0)
            .filter(|_| robot_first)
            .map(|c| choice_name(h0, c)),
    };
    let synthesis = Synthesis {
        settings: Settings {
            sigma_l: options.sigma_l.name(),
            seed: options.seed,
            risk: tasks.risk(),
            discount: g,
            epsilon: solve.epsilon,
        },
        mdp: sizes(model, &solution, regions, payoffs, presentation),
        solver: SolverSummary {
            iterations: solution.iterations(),
            gap: solution.gap(),
            end_components: 0,
        },
        decision: InitialDecision {
            value: value.lower,
            value_upper: value.upper,
            action,
            commits_to,
            adversary_first: !robot_first,
            expected_moves: evaluation.expected_moves,
            policy_value: policy_value.lower,
            policy_value_upper: policy_value.upper,
        },
        explanation: None,
        simulation: None,
        trace: None,
        robust: None,
    };
    Ok((synthesis, solution, policy))
}

/// The MDP's sizes as the explicit build counts them ([`MdpSizes`]), from the model's rules.
fn sizes<M: Moves>(
    model: &Model<'_, '_, M>,
    solution: &implicit::Solution,
    regions: &Regions,
    payoffs: &SubsetPayoffs,
    presentation: &Presentation,
) -> MdpSizes {
    let space = model.space();
    // One state's counts: its kind, its choices and the transitions they have (parallel edges
    // to one state are one transition, as the MDP merges them).
    let count = |h: u32, sizes: &mut SizeCount, (distribution, targets): &mut Scratch| {
        let kind = model.kind(h);
        if space.owner(h) == Owner::Adversary {
            if kind == Kind::Chance {
                sizes.chance_nodes(1);
                model.distribution(h, distribution);
                targets.clear();
                targets.extend(distribution.iter().map(|(t, _)| t));
                targets.sort_unstable();
                targets.dedup();
                sizes.choices(1, targets.len() as u32);
            }
            return;
        }
        let value = solution.value(model, h);
        let above = value.lower > regions.guarantee(payoffs, h) + solution.gap();
        let stuck = space.degree(h) == 0;
        sizes.robot_state(stuck, model.commits(h), value.upper, above);
        if kind == Kind::Decision {
            let mut choices = 0;
            model.choices(h, |_| choices += 1);
            sizes.choices(choices, choices);
        }
    };
    // Blocks of states counted on all threads, their counts added.
    type Scratch = (Distribution, Vec<u32>);
    const BLOCK: u32 = 1 << 14;
    let n = space.num_states() as u32;
    let sizes = (0..n.div_ceil(BLOCK))
        .into_par_iter()
        .fold(
            || (SizeCount::new(0, 0, 0), Scratch::default()),
            |(mut sizes, mut scratch), b| {
                for h in b * BLOCK..n.min((b + 1) * BLOCK) {
                    if space.enumerated(h) {
                        count(h, &mut sizes, &mut scratch);
                    }
                }
                (sizes, scratch)
            },
        )
        .map(|(sizes, _)| sizes)
        .reduce(
            || SizeCount::new(0, 0, 0),
            |mut a, b| {
                a.add(&b);
                a
            },
        );
    MdpSizes {
        states: (space.num_enumerated() + model.sinks().len()) as u32,
        ..sizes.finish(presentation.layout().states_guarantees)
    }
}

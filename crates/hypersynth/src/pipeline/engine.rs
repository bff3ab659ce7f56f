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
//! The choice, when the specification leaves it open: the explicit engine when its estimate
//! ([`explicit_bytes`]) fits what the observer allows, since it is faster on what fits; else the
//! implicit one. The implicit engine asks for its memory in two steps: its bits and bytes per
//! product state before the regions ([`implicit_bytes`]), its bounds per live state before the
//! solve.

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
use crate::game::{Engine, HState, HypergameError, States, TaskSet, classes_of, won_bits};
use crate::implicit::{
    self, ArenaMoves, Distribution, Kind, MapMoves, Model, Moves, Regions, Space,
};
use crate::limits::{Bytes, MemoryLimit};
use crate::mdp::drn::{stream_model, write_model};
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
            let about = Drawn {
                name: spec.arena.name(),
                map: match &read {
                    ReadArena::Map(world) => Some(world),
                    ReadArena::Arena(..) => None,
                },
            };
            implicit(
                (spec.states, spec.mdp.as_ref()),
                &tasks,
                source,
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
    let about = Drawn { name, map };
    implicit(
        (states, mdp),
        tasks,
        source,
        about,
        requests,
        Sinks::default(),
        observer,
    )
}

/// Where the implicit engine reads the arena's moves from.
enum Source<'a> {
    /// A stored arena (its CSR and transpose).
    Arena(&'a Arena),
    /// A map's rules, never expanded.
    Map(&'a Gridworld),
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

/// The implicit engine's run of the product enumerating `states`, with the MDP stage of `mdp`.
fn implicit(
    mdp: (States, Option<&MdpSpec>),
    tasks: &Tasks,
    source: Source<'_>,
    about: Drawn<'_>,
    requests: &Requests,
    sinks: Sinks<'_>,
    observer: &mut dyn Observer,
) -> Result<Outcome, RunError> {
    // What an exported controller carries of the arena.
    let arena = || match source {
        Source::Arena(arena) => ArenaSource::Text(crate::arena::write(arena)),
        Source::Map(world) => ArenaSource::Map(crate::arena::map::write(world)),
    };
    let drawn = (arena, about);
    match source {
        Source::Arena(arena_) => {
            let moves = ArenaMoves::new(arena_);
            implicit_on(mdp, tasks, &moves, drawn, requests, sinks, observer)
        }
        Source::Map(world) => {
            let moves = MapMoves::new(world)
                .map_err(|e| SpecError::new(Field::Arena, SpecErrorKind::Gridworld(e)))?;
            implicit_on(mdp, tasks, &moves, drawn, requests, sinks, observer)
        }
    }
}

fn implicit_on<M: Moves>(
    (states, mdp): (States, Option<&MdpSpec>),
    tasks: &Tasks,
    moves: &M,
    (arena, about): (impl Fn() -> ArenaSource, Drawn<'_>),
    requests: &Requests,
    sinks: Sinks<'_>,
    observer: &mut dyn Observer,
) -> Result<Outcome, RunError> {
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
    let explained = explained(tasks, &space, mdp, requests)?;
    let k = tasks.subtasks().len();
    let regions = metered(observer, Stage::Attractors, |_| {
        Regions::compute(&space, k, tasks.believed().belief())
    });
    let games = games(tasks, &space, &regions);
    let Sinks {
        drn: drn_sink,
        strategy: strategy_sink,
    } = sinks;
    let strategy = match requests.export_strategy {
        true => strategies(tasks, &space, &regions, strategy_sink, observer)?,
        false => None,
    };
    let (mut controller, mut drn, mut record, mut curve_svg) = (None, None, None, None);
    let model = match &options {
        Some(options) => Some(model(tasks, &space, &regions, &options.sigma_l, observer)?),
        None => None,
    };
    let mut solved = None;
    let synthesis = match (&options, &model) {
        (Some(options), Some(model)) => {
            let (mut synthesis, solution, policy) = synthesis(tasks, model, options, observer)?;
            if let Some(h) = explained {
                let solved = (&solution, &policy);
                let table = explanation(model, solved, h, options, observer)?;
                synthesis.explanation = Some(table);
            }
            if requests.simulate.is_some() || requests.trace {
                let runs = runs(
                    tasks,
                    model,
                    (&solution, &policy),
                    options,
                    requests,
                    observer,
                )?;
                (synthesis.simulation, synthesis.trace, record) = runs;
            }
            // The robust stage, when sigma_L is learnt: its summary joins the report and its
            // controller, which has the guarantee, is the one exported.
            let robust = match &options.learnt {
                Some(learnt) => {
                    let space_regions = (&space, &regions);
                    let robust =
                        ImplicitRobust::solve(tasks, space_regions, options, learnt, observer)?;
                    let simulate = requests.simulate.map(|runs| (runs, requests.max_steps));
                    let mut summary =
                        robust.summary(tasks, (learnt, options), simulate, observer)?;
                    if let Some(request) = &requests.learning_curve {
                        let about = (about.name, learnt, options);
                        let value = synthesis.decision.value;
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
                None if requests.learning_curve.is_some() => {
                    return Err(PipelineError::CurveWithoutObservations.into());
                }
                None => None,
            };
            if requests.export_mdp {
                // With a learnt sigma_L, the interval MDP of the robust stage.
                let written = match &robust {
                    Some(robust) => {
                        drn_model(&robust.model, None, observer)?.with_intervals(&robust.intervals)
                    }
                    None => drn_model(model, requests.induced.then_some(&policy), observer)?,
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
                let exported = match &robust {
                    Some(robust) => {
                        let rules = ModelRules {
                            risk: tasks.risk(),
                            sigma_l: SigmaLRule::Learnt {
                                delta: robust.region.delta,
                                counts: robust.counts.entries(space.moves()),
                            },
                        };
                        let solved = (&*robust.solution, &robust.policy);
                        let lower = Lower::Solution;
                        let file = (rules, lower, arena());
                        export(tasks, &robust.model, solved, file, requests, observer)?
                    }
                    None => {
                        let rules = ModelRules {
                            risk: tasks.risk(),
                            sigma_l: SigmaLRule::of(&options.sigma_l),
                        };
                        let solved = (&solution, &policy);
                        let file = (rules, Lower::Chain(options), arena());
                        export(tasks, model, solved, file, requests, observer)?
                    }
                };
                controller = Some(exported);
            }
            solved = Some((solution, policy));
            Some(synthesis)
        }
        _ => None,
    };
    let report = Report {
        presentation: tasks.presentation().clone(),
        games,
        synthesis,
    };
    let solved = match (&model, &solved, &options) {
        (Some(model), Some((solution, policy)), Some(options)) => {
            Some((model, (solution, policy), options))
        }
        _ => None,
    };
    let shown = ImplicitShown {
        space: &space,
        regions: &regions,
        payoffs: tasks.payoffs(),
        presentation: tasks.presentation(),
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

/// The product state whose decision table `requests` ask for, read in `space` (none without
/// the MDP stage, as on the explicit engine), before anything is solved.
fn explained<M: Moves>(
    tasks: &Tasks,
    space: &Space<'_, M>,
    mdp: Option<&MdpSpec>,
    requests: &Requests,
) -> Result<Option<u32>, PipelineError> {
    if mdp.is_none() {
        return Ok(None);
    }
    let names: Vec<String> = tasks
        .automata()
        .into_iter()
        .map(|(name, _)| name.to_string())
        .collect();
    super::explained_state(requests, space.initial(), |text| {
        space.parse_state(text, &names)
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
    options: &MdpOptions,
    requests: &Requests,
    observer: &mut dyn Observer,
) -> Result<Runs, RunError> {
    let (space, moves) = (model.space(), model.space().moves());
    let (seed, max_steps) = (options.seed, requests.max_steps);
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
    let n = space.num_states();
    let live = (0..n as u32)
        .filter(|&h| !matches!(model.kind(h), Kind::Absorbing(_)))
        .count() as u64;
    metered(observer, Stage::Solve, |meter| {
        meter.reserve(live.saturating_mul(IMPLICIT_PER_LIVE), || {
            format!("the implicit engine's bounds of {live} live states")
        })
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
    let (mut choices, mut transitions, mut chance) = (0u32, 0u32, 0u32);
    let mut sizes = SizeCount::new(0, 0, 0);
    let mut distribution = Distribution::default();
    let mut targets: Vec<u32> = Vec::new();
    for h in space.states() {
        let kind = model.kind(h);
        if space.owner(h) == Owner::Adversary {
            if kind == Kind::Chance {
                chance += 1;
                choices += 1;
                // Parallel edges to one state are one transition, as the MDP merges them.
                model.distribution(h, &mut distribution);
                targets.clear();
                targets.extend(distribution.iter().map(|(t, _)| t));
                targets.sort_unstable();
                targets.dedup();
                transitions += targets.len() as u32;
            }
            continue;
        }
        let value = solution.value(model, h);
        let above = value.lower > regions.guarantee(payoffs, h) + solution.gap();
        let stuck = space.degree(h) == 0;
        sizes.robot_state(stuck, model.commits(h), value.upper, above);
        if kind == Kind::Decision {
            model.choices(h, |_| {
                choices += 1;
                transitions += 1;
            });
        }
    }
    sizes.chance_nodes(chance);
    MdpSizes {
        states: (space.num_enumerated() + model.sinks().len()) as u32,
        choices,
        transitions,
        ..sizes.finish(presentation.layout().states_guarantees)
    }
}

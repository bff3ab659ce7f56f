//! A problem as plain data: [`ProblemSpec`], what a front end gives (the command line maps its
//! options onto it, the Python package its arguments), checked and built into a [`Problem`]
//! once. Every rule on the inputs lives here: task names, at most
//! [`MAX_TASKS`] sub-tasks given once each, payoffs on sets of known
//! names (each finite and ≥ 0, monotone), the paper's `r ≥ r1 + r2`, sigma_L's weights against
//! the arena, the discount and the precision.
//!
//! A rule that fails gives one [`SpecError`]: the [`Field`] it comes from (a task by index and
//! name, a payoff's member, the belief, a weight's state and action...), the [`Position`]
//! inside that field's text when there is one, and what is wrong ([`SpecErrorKind`]). The
//! library names no option: a front end says the field in its own terms (`--task:1:5` on the
//! command line, `tasks[A]` in Python).
//!
//! The inputs are checked in the order the pipeline needs them, each field as a whole before
//! the next: the tasks (the translation stage, with the translator made on first need), the
//! arena (the parse stage), then the MDP stage's options. The first failing rule is the error.
//!
//! ```
//! use hypersynth::game::States;
//! use hypersynth::pipeline::spec::{
//!     ArenaSpec, Field, GeneralSpec, NamedTask, PayoffPart, ProblemSpec, SetPayoff,
//!     SpecErrorKind, TaskSource, TasksSpec, Translation,
//! };
//! use hypersynth::pipeline::{self, Requests};
//! use hypersynth::opportunistic::build::Risk;
//! use hypersynth::translate::TranslatorChoice;
//!
//! // Robot `r` moves to the adversary's `a`, which sends it on to `g` (A and B hold there) or
//! // back.
//! let arena = "propositions A B
//! state r robot {}
//! state a adversary {}
//! state g robot {A B}
//! initial r
//! edge r go a
//! edge a on g
//! edge a back r
//! edge g stay g
//! ";
//! let task = |name: &str, formula: &str| NamedTask {
//!     name: name.into(),
//!     task: TaskSource::Formula(formula.into()),
//! };
//! let mut spec = ProblemSpec {
//!     arena: ArenaSpec::Text { name: "tiny".into(), text: arena.into() },
//!     tasks: TasksSpec::General(GeneralSpec {
//!         tasks: vec![task("A", "F A"), task("B", "F B")],
//!         // Both together pay less than A and B apart: not the paper's preset.
//!         payoffs: vec![SetPayoff { set: vec!["A".into(), "B".into()], value: 150.0 }],
//!         believed: TaskSource::Formula("F A".into()),
//!         risk: Risk::Paper,
//!     }),
//!     states: States::Full,
//!     translation: Translation { choice: TranslatorChoice::Builtin, ..Translation::default() },
//!     mdp: None, // stop after the games
//!     engine: None, // the engine the product's size calls for
//! };
//! let problem = spec.build(&mut ())?;
//! assert_eq!(problem.tasks.names(), ["A", "B"]);
//! let outcome = pipeline::run(&problem, &Requests::default(), &mut ())?;
//! assert!(outcome.report.synthesis.is_none());
//!
//! // A payoff on a set naming no sub-task: the error says which payoff, and which member.
//! let TasksSpec::General(general) = &mut spec.tasks else { unreachable!() };
//! general.payoffs[0].set[1] = "C".into();
//! let Err(error) = spec.build(&mut ()) else { unreachable!() };
//! assert_eq!(error.field, Field::Payoff { index: 0, part: PayoffPart::Member(1) });
//! assert!(matches!(*error.kind, SpecErrorKind::UnknownTask(ref name) if name == "C"));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::fmt;
use std::path::PathBuf;
use std::time::Duration;

use super::{
    Believed, HoaTaskError, Learnt, MdpOptions, Problem, Subtask, Task, Tasks, TasksError,
};
use crate::arena::gridworld::{Gridworld, GridworldError};
use crate::arena::map::{self, MapErrorKind};
use crate::arena::{self, Arena, ParseErrorKind};
use crate::diagnostic::{Collector, DEFAULT_LIMIT, Diagnostic, Diagnostics};
use crate::game::{
    Engine, MAX_TASKS, Operand, Payoffs, SplitError, States, SubsetPayoffs, TaskSet, is_payoff,
};
use crate::limits::{Deadline, MemoryLimit};
use crate::ltl::{self, Formula};
use crate::mdp::solve::{Discount, SolveError, SolveOptions};
use crate::opportunistic::adversary::{
    ArenaLookup, EntryError, SigmaL, TableError, WeightsFile, WeightsFileErrors,
};
use crate::opportunistic::build::Risk;
use crate::opportunistic::observations::{Observations, ObservationsErrors};
use crate::position::Position;
use crate::stage::{Meter, Observer, Stage, metered, timed};
use crate::translate::{self, TranslateError, TranslationLimits, Translator, TranslatorChoice};

/// The payoff of a sub-task that no payoff names alone.
pub const DEFAULT_PAYOFF: f64 = 100.0;

/// A whole problem as plain data: what [`ProblemSpec::build`] checks and turns into a
/// [`Problem`].
#[derive(Clone, Debug, PartialEq)]
pub struct ProblemSpec {
    /// The arena (or map).
    pub arena: ArenaSpec,
    /// The robot's tasks, their payoffs, the belief and the risk rule.
    pub tasks: TasksSpec,
    /// Which product states to enumerate.
    pub states: States,
    /// How formulas become automata.
    pub translation: Translation,
    /// The MDP stage's options; `None` stops after the games.
    pub mdp: Option<MdpSpec>,
    /// Which engine holds the product; `None` chooses by the memory each would need
    /// ([`crate::pipeline::solve`]).
    pub engine: Option<Engine>,
}

/// The arena of a problem.
#[derive(Clone, Debug, PartialEq)]
pub enum ArenaSpec {
    /// An arena's text, or a map's (recognised by its header, [`map::is_map`]); `name` names
    /// it in reports.
    Text {
        /// The arena's name in reports and titles (its file...).
        name: String,
        /// The text.
        text: String,
    },
    /// A map's text, read as a map whatever its first line.
    Map {
        /// The map's name in reports and titles.
        name: String,
        /// The text.
        text: String,
    },
    /// An arena already built, with the map it was built from, if any.
    Built {
        /// The arena's name in reports and titles.
        name: String,
        /// The arena.
        arena: Box<Arena>,
        /// Its map (pictures need it).
        map: Option<Box<Gridworld>>,
    },
}

/// A task: a formula, an automaton in HOA, or one already read.
#[derive(Clone, Debug, PartialEq)]
pub enum TaskSource {
    /// A co-safe LTL formula's text.
    Formula(String),
    /// The text of a HOA file holding one automaton, read as a DFA of good prefixes and
    /// minimised; reports name the task `name` (its file...).
    Hoa {
        /// How reports name the task, and the name of the text in messages.
        name: String,
        /// The HOA text.
        text: String,
    },
    /// A task already made.
    Automaton(Task),
}

impl TaskSource {
    /// The text errors of this task are located in (none for a task already made).
    pub fn text(&self) -> Option<&str> {
        match self {
            TaskSource::Formula(text) | TaskSource::Hoa { text, .. } => Some(text),
            TaskSource::Automaton(_) => None,
        }
    }
}

/// The paper's payoffs of phi1, phi2 and phi (docs/semantics.md §6.1), as given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PaperPayoffs {
    /// The payoff of phi1.
    pub r1: f64,
    /// The payoff of phi2.
    pub r2: f64,
    /// The payoff of phi, at least `r1 + r2`.
    pub r: f64,
}

impl Default for PaperPayoffs {
    /// The case study's: 200, 100 and 300.
    fn default() -> Self {
        let payoffs = Payoffs::default();
        PaperPayoffs {
            r1: payoffs.r1(),
            r2: payoffs.r2(),
            r: payoffs.r(),
        }
    }
}

/// The robot's tasks.
#[derive(Clone, Debug, PartialEq)]
pub enum TasksSpec {
    /// The paper's form from formulas: `phi` split into `phi1 = psi` and `phi2` (the conjuncts
    /// of phi not in psi, or `phi2` when given), both translated.
    Paper {
        /// The robot's task.
        phi: String,
        /// What the adversary believes the task is: some conjuncts of phi.
        psi: String,
        /// The rest of phi, when given.
        phi2: Option<String>,
        /// The payoffs (checked only when the MDP stage runs: the games do not need them).
        payoffs: PaperPayoffs,
    },
    /// The paper's form from its two tasks given separately; phi is their conjunction.
    PaperParts {
        /// phi1, which the adversary believes is the whole task ([`Field::Psi`]).
        phi1: TaskSource,
        /// phi2 ([`Field::Phi2`]).
        phi2: TaskSource,
        /// The payoffs (checked only when the MDP stage runs).
        payoffs: PaperPayoffs,
    },
    /// Named sub-tasks, payoffs on their sets, any belief (docs/semantics.md §8).
    General(GeneralSpec),
}

/// The general form's tasks.
#[derive(Clone, Debug, PartialEq)]
pub struct GeneralSpec {
    /// The sub-tasks in product order, which breaks ties between sets of equal payoff.
    pub tasks: Vec<NamedTask>,
    /// Payoffs of sets of sub-tasks: a sub-task named alone pays its payoff
    /// ([`DEFAULT_PAYOFF`] if none names it alone), a set named pays its payoff, any other set
    /// the sum of its members'.
    pub payoffs: Vec<SetPayoff>,
    /// The task the adversary believes the robot has: when a formula that is the conjunction of
    /// some sub-tasks, Win(psi) is theirs; otherwise psi has its own automaton.
    pub believed: TaskSource,
    /// Which actions a robot state that can settle for something keeps.
    pub risk: Risk,
}

/// A named sub-task.
#[derive(Clone, Debug, PartialEq)]
pub struct NamedTask {
    /// Its name: letters, digits and `_`, not starting with a digit.
    pub name: String,
    /// The task.
    pub task: TaskSource,
}

/// The payoff of a set of sub-tasks, named.
#[derive(Clone, Debug, PartialEq)]
pub struct SetPayoff {
    /// The sub-tasks' names, each once.
    pub set: Vec<String>,
    /// The payoff: finite and ≥ 0.
    pub value: f64,
}

/// How formulas become automata: which translator, found where, under which limits.
#[derive(Clone, Debug, PartialEq)]
pub struct Translation {
    /// The translator.
    pub choice: TranslatorChoice,
    /// Spot's `ltl2tgba`, as the front end found it (the library reads no environment).
    pub ltl2tgba: Option<PathBuf>,
    /// The limits of each translation (their deadline is set from `timeout`).
    pub limits: TranslationLimits,
    /// The time all translations of a problem may take together, from when the translator is
    /// made (on first need); `None`: no deadline.
    pub timeout: Option<Duration>,
}

impl Default for Translation {
    /// Spot when found (here: not, as no executable is given), the library's default limits,
    /// no deadline.
    fn default() -> Self {
        Translation {
            choice: TranslatorChoice::Auto,
            ltl2tgba: None,
            limits: TranslationLimits::default(),
            timeout: None,
        }
    }
}

impl Translation {
    /// The translator, its deadline (if any) starting now.
    pub fn translator(&self) -> Result<Box<dyn Translator>, TranslateError> {
        let limits = match self.timeout {
            Some(timeout) => self.limits.with_deadline(Deadline::after(timeout)),
            None => self.limits,
        };
        translate::resolve(self.choice, self.ltl2tgba.clone(), limits)
    }
}

/// The MDP stage's options, as given.
#[derive(Clone, Debug, PartialEq)]
pub struct MdpSpec {
    /// The adversary's distribution where it believes it has lost.
    pub sigma_l: SigmaLSpec,
    /// The seed of simulations.
    pub seed: u64,
    /// The discount per robot move, `0 < g ≤ 1`.
    pub discount: f64,
    /// The certified bound on the values' error.
    pub precision: Precision,
    /// Sweeps after which the solver gives up.
    pub max_iterations: u32,
    /// sigma_L learnt from observed runs (docs/semantics.md §10).
    pub learnt: Option<LearntSpec>,
}

impl Default for MdpSpec {
    /// Random weights seeded with 2019, no discount, the solver's default precision and sweeps.
    fn default() -> Self {
        let solve = SolveOptions::default();
        MdpSpec {
            sigma_l: SigmaLSpec::Value(SigmaL::Random { seed: 2019 }),
            seed: 2019,
            discount: solve.discount.get(),
            precision: Precision::Absolute(solve.epsilon),
            max_iterations: solve.max_iterations,
            learnt: None,
        }
    }
}

/// sigma_L as given.
#[derive(Clone, Debug, PartialEq)]
pub enum SigmaLSpec {
    /// sigma_L as a value: uniform, random, or a weight table (checked against the arena,
    /// errors at [`Field::Weight`]).
    Value(SigmaL),
    /// Weights in the weights-file format (errors located in it, at [`Field::Weights`]).
    WeightsFile {
        /// The file's name, as reports show it.
        name: String,
        /// Its text.
        text: String,
    },
}

/// The solver's precision.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Precision {
    /// Every state's bounds at most this far apart.
    Absolute(f64),
    /// Every state's bounds at most this times its lower bound apart.
    Relative(f64),
}

/// Observed runs to learn sigma_L from.
#[derive(Clone, Debug, PartialEq)]
pub struct LearntSpec {
    /// The observations file's name, as reports show it.
    pub name: String,
    /// Its text.
    pub text: String,
    /// The learnt region holds with probability at least `1 − delta`.
    pub delta: f64,
}

/// Where in a [`ProblemSpec`] an error comes from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Field {
    /// The arena's text.
    Arena,
    /// The paper's `phi`.
    Phi,
    /// The paper's `psi`, the task phi1 the adversary believes.
    Psi,
    /// The paper's `phi2`.
    Phi2,
    /// The paper's payoffs.
    PaperPayoffs,
    /// The general form's sub-tasks as a whole (their number).
    Tasks,
    /// One sub-task: its name, or its text.
    Task {
        /// Its index in [`GeneralSpec::tasks`].
        index: usize,
        /// Its name.
        name: String,
    },
    /// One payoff of a [`GeneralSpec`]'s payoffs.
    Payoff {
        /// Its index.
        index: usize,
        /// Which part of it.
        part: PayoffPart,
    },
    /// The payoffs together (monotonicity).
    Payoffs,
    /// The general form's belief.
    Believed,
    /// The translator (it could not be made).
    Translator,
    /// A weights file's text.
    Weights,
    /// One weight of a weight table given as a value.
    Weight {
        /// The entry's arena state.
        state: String,
        /// The entry's action.
        action: String,
    },
    /// The observations' text.
    Observations,
    /// The discount.
    Discount,
    /// The precision.
    Precision,
}

/// A part of a [`SetPayoff`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PayoffPart {
    /// The member of [`SetPayoff::set`] at this index.
    Member(usize),
    /// The set as a whole.
    Set,
    /// The value.
    Value,
}

impl fmt::Display for Field {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Field::Arena => f.write_str("arena"),
            Field::Phi => f.write_str("phi"),
            Field::Psi => f.write_str("psi"),
            Field::Phi2 => f.write_str("phi2"),
            Field::PaperPayoffs => f.write_str("payoffs"),
            Field::Tasks => f.write_str("tasks"),
            Field::Task { name, .. } => write!(f, "task {name}"),
            Field::Payoff { index, .. } => write!(f, "payoff {index}"),
            Field::Payoffs => f.write_str("payoffs"),
            Field::Believed => f.write_str("believed"),
            Field::Translator => f.write_str("translator"),
            Field::Weights => f.write_str("weights"),
            Field::Weight { state, action } => write!(f, "weight of {state} {action}"),
            Field::Observations => f.write_str("observations"),
            Field::Discount => f.write_str("discount"),
            Field::Precision => f.write_str("precision"),
        }
    }
}

/// What is wrong in a field.
#[derive(Debug, thiserror::Error)]
pub enum SpecErrorKind {
    /// The arena's text does not read.
    #[error(transparent)]
    Arena(Diagnostics<ParseErrorKind>),
    /// The map's text does not read.
    #[error(transparent)]
    Map(Diagnostics<MapErrorKind>),
    /// The map's arena cannot be generated.
    #[error(transparent)]
    Gridworld(GridworldError),
    /// The map's arena would not fit in memory.
    #[error(transparent)]
    Memory(MemoryLimit),
    /// A formula does not read.
    #[error(transparent)]
    Formula(Diagnostics),
    /// A formula reads but is not syntactically co-safe: every operator that keeps it from
    /// being so, located.
    #[error(transparent)]
    NotCoSafe(Diagnostics),
    /// A HOA text does not read.
    #[error(transparent)]
    Hoa(Diagnostics),
    /// A HOA text that does not hold exactly one automaton (how many it holds).
    #[error("expected one automaton, found {0}")]
    AutomatonCount(usize),
    /// The translator could not be made (Spot asked for and not found).
    #[error(transparent)]
    Translator(TranslateError),
    /// A formula did not translate.
    #[error(transparent)]
    Translate(TranslateError),
    /// psi (or phi2) is not made of conjuncts of phi.
    #[error(transparent)]
    Split(SplitError),
    /// The paper's payoffs.
    #[error(transparent)]
    PaperPayoffs(crate::game::PayoffError),
    /// More sub-tasks than [`MAX_TASKS`] (how many).
    #[error("at most {MAX_TASKS} sub-tasks are supported, got {0}")]
    TooManyTasks(usize),
    /// A name that cannot name a sub-task ([`super::is_task_name`]).
    #[error("`{0}` is not a sub-task name (letters, digits and `_`, not starting with a digit)")]
    TaskName(String),
    /// Two sub-tasks of one name.
    #[error("sub-task `{0}` is given twice")]
    DuplicateTask(String),
    /// A payoff's set names a sub-task that does not exist.
    #[error("no sub-task is named `{0}`")]
    UnknownTask(String),
    /// A payoff's set names a sub-task twice.
    #[error("`{0}` is listed twice")]
    ListedTwice(String),
    /// A payoff's set names no sub-task.
    #[error("the set names no sub-task")]
    EmptySet,
    /// Two payoffs of one set.
    #[error("the payoff of this set is given twice")]
    SetGivenTwice,
    /// A payoff that is not a finite number ≥ 0.
    #[error("invalid payoff `{0}` (a finite number >= 0)")]
    InvalidPayoff(f64),
    /// The payoffs together (not monotone).
    #[error(transparent)]
    Payoffs(crate::game::PayoffError),
    /// A weights file's text does not read, or does not fit the arena.
    #[error(transparent)]
    WeightsFile(WeightsFileErrors),
    /// A weight of a table given as a value does not fit the arena.
    #[error(transparent)]
    Weight(EntryError),
    /// The observations' text does not read.
    #[error(transparent)]
    Observations(ObservationsErrors),
    /// The discount or the precision is out of range.
    #[error(transparent)]
    Solve(SolveError),
}

/// Why a [`ProblemSpec`] does not give a [`Problem`]: which field, where in its text (when the
/// error is in a text: the first error's position), and what.
#[derive(Debug, thiserror::Error)]
#[error("{field}: {kind}")]
pub struct SpecError {
    /// The field the error comes from.
    pub field: Field,
    /// Where in the field's text, when the field is a text.
    pub position: Option<Position>,
    /// What is wrong.
    pub kind: Box<SpecErrorKind>,
}

impl SpecError {
    /// The field, the position in its text and what is wrong, for a front end to say in its
    /// own terms.
    pub fn into_parts(self) -> (Field, Option<Position>, SpecErrorKind) {
        (self.field, self.position, *self.kind)
    }

    /// `kind` in `field`, at no position.
    pub(crate) fn new(field: Field, kind: SpecErrorKind) -> SpecError {
        SpecError {
            field,
            position: None,
            kind: Box::new(kind),
        }
    }

    /// `kind` at `position` of `field`'s text.
    fn at(field: Field, position: Position, kind: SpecErrorKind) -> SpecError {
        SpecError {
            field,
            position: Some(position),
            kind: Box::new(kind),
        }
    }

    /// Errors located in `field`'s text (the first one's position).
    fn located<M>(
        field: Field,
        diagnostics: Diagnostics<M>,
        kind: impl FnOnce(Diagnostics<M>) -> SpecErrorKind,
    ) -> SpecError {
        let position = diagnostics.first().position;
        SpecError::at(field, position, kind(diagnostics))
    }

    /// A translation error of `text` (the text of `field`), located when it can be.
    fn translate(field: Field, text: &str, error: TranslateError) -> SpecError {
        SpecError {
            field,
            position: error.position(text),
            kind: Box::new(SpecErrorKind::Translate(error)),
        }
    }
}

impl ProblemSpec {
    /// The problem: the tasks (told to `observer` as the translation stage), the arena (the
    /// parse stage), then the MDP stage's options; the first rule that fails is the error.
    pub fn build(&self, observer: &mut dyn Observer) -> Result<Problem, SpecError> {
        let tasks = self.build_tasks(observer)?;
        let (arena, map) = metered(observer, Stage::Parse, |meter| self.arena.build(meter))?;
        self.problem(tasks, arena, map)
    }

    /// The tasks, told to `observer` as the translation stage.
    pub(crate) fn build_tasks(&self, observer: &mut dyn Observer) -> Result<Tasks, SpecError> {
        timed(observer, Stage::Translate, || {
            self.tasks.build(&self.translation, self.mdp.is_some())
        })
    }

    /// The problem of `tasks` on `arena` (built from `map`, if any), with the MDP stage's
    /// options.
    pub(crate) fn problem(
        &self,
        tasks: Tasks,
        arena: Arena,
        map: Option<Gridworld>,
    ) -> Result<Problem, SpecError> {
        let mdp = match &self.mdp {
            Some(mdp) => Some(mdp.build(&arena)?),
            None => None,
        };
        Ok(Problem {
            arena_name: self.arena.name().to_string(),
            arena,
            map,
            tasks,
            states: self.states,
            mdp,
        })
    }
}

/// An arena as read: a stored arena (with the map it was built from, if any), or a map not
/// expanded yet (the implicit engine never expands it).
#[derive(Debug)]
pub(crate) enum ReadArena {
    /// A stored arena, and its map.
    Arena(Box<Arena>, Option<Gridworld>),
    /// A map.
    Map(Gridworld),
}

impl ReadArena {
    /// The arena, and its map when it is one; a map's arena is built without display names
    /// (only the arena writer shows them), after `meter` agrees to its memory.
    pub(crate) fn expand(
        self,
        meter: &mut Meter<'_>,
    ) -> Result<(Arena, Option<Gridworld>), SpecError> {
        let error = |kind| SpecError::new(Field::Arena, kind);
        match self {
            ReadArena::Arena(arena, map) => Ok((*arena, map)),
            ReadArena::Map(world) => {
                if let Ok(bytes) = world.build_bytes() {
                    meter
                        .reserve(bytes, || {
                            format!("the arena of the {}x{} map", world.width, world.height)
                        })
                        .map_err(|e| error(SpecErrorKind::Memory(e)))?;
                }
                let arena = world
                    .build_without_display_names()
                    .map_err(|e| error(SpecErrorKind::Gridworld(e)))?;
                Ok((arena, Some(world)))
            }
        }
    }
}

impl ArenaSpec {
    /// The arena's name in reports.
    pub fn name(&self) -> &str {
        match self {
            ArenaSpec::Text { name, .. }
            | ArenaSpec::Map { name, .. }
            | ArenaSpec::Built { name, .. } => name,
        }
    }

    /// The arena's text, unless it is built.
    pub fn text(&self) -> Option<&str> {
        match self {
            ArenaSpec::Text { text, .. } | ArenaSpec::Map { text, .. } => Some(text),
            ArenaSpec::Built { .. } => None,
        }
    }

    /// The arena, and its map when it is one; a map's arena is built without display names
    /// (only the arena writer shows them), after `meter` agrees to its memory.
    pub fn build(&self, meter: &mut Meter<'_>) -> Result<(Arena, Option<Gridworld>), SpecError> {
        self.read(meter)?.expand(meter)
    }

    /// The arena read, a map not expanded.
    pub(crate) fn read(&self, meter: &mut Meter<'_>) -> Result<ReadArena, SpecError> {
        match self {
            ArenaSpec::Text { text, .. } if !map::is_map(text) => {
                let parsed = arena::parse_metered(text, meter)
                    .map_err(|e| SpecError::located(Field::Arena, e, SpecErrorKind::Arena))?;
                Ok(ReadArena::Arena(Box::new(parsed.arena), None))
            }
            ArenaSpec::Text { text, .. } | ArenaSpec::Map { text, .. } => {
                let world = map::parse(text)
                    .map_err(|e| SpecError::located(Field::Arena, e, SpecErrorKind::Map))?;
                Ok(ReadArena::Map(world))
            }
            ArenaSpec::Built { arena, map, .. } => {
                Ok(ReadArena::Arena(arena.clone(), map.as_deref().cloned()))
            }
        }
    }
}

/// The translator of a problem, made on first need (so that tasks given as automata need
/// none, and its deadline starts with the first translation).
struct OnDemand<'a> {
    translation: &'a Translation,
    made: Option<Box<dyn Translator>>,
}

impl OnDemand<'_> {
    fn get(&mut self) -> Result<&dyn Translator, SpecError> {
        if self.made.is_none() {
            let translator = self
                .translation
                .translator()
                .map_err(|e| SpecError::new(Field::Translator, SpecErrorKind::Translator(e)))?;
            self.made = Some(translator);
        }
        Ok(self.made.as_deref().expect("made above"))
    }
}

/// `text`, the text of `field`, as a formula.
/// A task's formula: it reads, and it is syntactically co-safe. Every error of the text is
/// reported at once, located: all its syntax errors, else every operator that keeps it from
/// being co-safe.
fn parse(field: &Field, text: &str) -> Result<Formula, SpecError> {
    let formula = ltl::parse(text)
        .map_err(|e| SpecError::located(field.clone(), e, SpecErrorKind::Formula))?;
    let mut errors = Collector::new(DEFAULT_LIMIT);
    for error in ltl::co_safety_errors(&formula) {
        errors.push(Diagnostic::new(error.position(text), error.to_string()));
    }
    errors
        .or_ok(formula)
        .map_err(|e| SpecError::located(field.clone(), e, SpecErrorKind::NotCoSafe))
}

impl TaskSource {
    /// The task, errors in `field`.
    fn task(&self, field: &Field, translator: &mut OnDemand) -> Result<Task, SpecError> {
        match self {
            TaskSource::Formula(text) => {
                let formula = parse(field, text)?;
                Task::from_formula(formula, translator.get()?)
                    .map_err(|e| SpecError::translate(field.clone(), text, e))
            }
            TaskSource::Hoa { name, text } => {
                Task::from_hoa(name, text).map_err(|error| match error {
                    HoaTaskError::Parse(e) => {
                        SpecError::located(field.clone(), e, SpecErrorKind::Hoa)
                    }
                    HoaTaskError::Count(n) => {
                        SpecError::new(field.clone(), SpecErrorKind::AutomatonCount(n))
                    }
                })
            }
            TaskSource::Automaton(task) => Ok(task.clone()),
        }
    }
}

impl PaperPayoffs {
    /// The payoffs, when the MDP stage runs (`with_mdp`); else the games ignore them.
    fn check(self, with_mdp: bool) -> Result<Payoffs, SpecError> {
        match Payoffs::new(self.r1, self.r2, self.r) {
            Ok(payoffs) => Ok(payoffs),
            Err(_) if !with_mdp => Ok(Payoffs::default()),
            Err(e) => Err(SpecError::new(
                Field::PaperPayoffs,
                SpecErrorKind::PaperPayoffs(e),
            )),
        }
    }
}

impl TasksSpec {
    /// The tasks, formulas translated as `translation` says; the paper's payoffs are checked
    /// only `with_mdp` (when the MDP stage runs).
    pub fn build(&self, translation: &Translation, with_mdp: bool) -> Result<Tasks, SpecError> {
        let mut translator = OnDemand {
            translation,
            made: None,
        };
        match self {
            TasksSpec::Paper {
                phi,
                psi,
                phi2,
                payoffs,
            } => {
                let phi_formula = parse(&Field::Phi, phi)?;
                let psi_formula = parse(&Field::Psi, psi)?;
                let phi2_formula = phi2
                    .as_deref()
                    .map(|t| parse(&Field::Phi2, t))
                    .transpose()?;
                let translator = translator.get()?;
                let payoffs = payoffs.check(with_mdp)?;
                // phi2's subformulas come from phi2's text when given, else from phi's.
                let text = |operand| match operand {
                    Operand::Phi => (Field::Phi, phi.as_str()),
                    Operand::Psi => (Field::Psi, psi.as_str()),
                    Operand::Phi2 => match phi2 {
                        Some(text) => (Field::Phi2, text.as_str()),
                        None => (Field::Phi, phi.as_str()),
                    },
                };
                Tasks::from_formulas(
                    &phi_formula,
                    &psi_formula,
                    phi2_formula.as_ref(),
                    translator,
                    payoffs,
                )
                .map_err(|error| match error {
                    TasksError::Split(error) => {
                        let (field, text) = text(error.operand());
                        let position = Position::of_offset(text, error.span().start);
                        SpecError::at(field, position, SpecErrorKind::Split(error))
                    }
                    TasksError::Translate { operand, error } => {
                        let (field, text) = text(operand);
                        SpecError::translate(field, text, error)
                    }
                })
            }
            TasksSpec::PaperParts {
                phi1,
                phi2,
                payoffs,
            } => {
                let phi1 = phi1.task(&Field::Psi, &mut translator)?;
                let phi2 = phi2.task(&Field::Phi2, &mut translator)?;
                Ok(Tasks::from_parts(phi1, phi2, payoffs.check(with_mdp)?))
            }
            TasksSpec::General(general) => general.build(&mut translator),
        }
    }
}

impl GeneralSpec {
    fn build(&self, translator: &mut OnDemand) -> Result<Tasks, SpecError> {
        check_count(self.tasks.len())?;
        let mut subtasks: Vec<Subtask> = Vec::with_capacity(self.tasks.len());
        for (index, named) in self.tasks.iter().enumerate() {
            let field = Field::Task {
                index,
                name: named.name.clone(),
            };
            if !super::is_task_name(&named.name) {
                let kind = SpecErrorKind::TaskName(named.name.clone());
                return Err(SpecError::new(field, kind));
            }
            subtasks.push(Subtask {
                name: named.name.clone(),
                task: named.task.task(&field, translator)?,
            });
        }
        for (index, task) in subtasks.iter().enumerate() {
            if subtasks[..index]
                .iter()
                .any(|other| other.name == task.name)
            {
                let field = Field::Task {
                    index,
                    name: task.name.clone(),
                };
                let kind = SpecErrorKind::DuplicateTask(task.name.clone());
                return Err(SpecError::new(field, kind));
            }
        }
        let names: Vec<String> = subtasks.iter().map(|t| t.name.clone()).collect();
        let payoffs = self.payoffs(&names)?;
        let believed = match &self.believed {
            TaskSource::Formula(text) => {
                let formula = parse(&Field::Believed, text)?;
                Believed::from_formula(formula, &subtasks, translator.get()?)
                    .map_err(|e| SpecError::translate(Field::Believed, text, e))?
            }
            other => Believed::Automaton(Box::new(other.task(&Field::Believed, translator)?)),
        };
        Ok(Tasks::new(subtasks, payoffs, believed, self.risk))
    }

    /// `r(T)` for every set of the sub-tasks `names`: [`GeneralSpec::payoffs`] checked in
    /// order, each member, then the value, then the set.
    fn payoffs(&self, names: &[String]) -> Result<SubsetPayoffs, SpecError> {
        let mut per_task = vec![DEFAULT_PAYOFF; names.len()];
        let mut overrides: Vec<(TaskSet, f64)> = Vec::new();
        let mut seen: Vec<TaskSet> = Vec::new();
        for (index, payoff) in self.payoffs.iter().enumerate() {
            let error = |part, kind| SpecError::new(Field::Payoff { index, part }, kind);
            let mut set = TaskSet::default();
            for (member, name) in payoff.set.iter().enumerate() {
                let part = PayoffPart::Member(member);
                if !super::is_task_name(name) {
                    return Err(error(part, SpecErrorKind::TaskName(name.clone())));
                }
                let Some(i) = names.iter().position(|n| n == name) else {
                    return Err(error(part, SpecErrorKind::UnknownTask(name.clone())));
                };
                if set.contains(i) {
                    return Err(error(part, SpecErrorKind::ListedTwice(name.clone())));
                }
                set = TaskSet(set.0 | 1 << i);
            }
            if set.is_empty() {
                return Err(error(PayoffPart::Set, SpecErrorKind::EmptySet));
            }
            if !is_payoff(payoff.value) {
                let kind = SpecErrorKind::InvalidPayoff(payoff.value);
                return Err(error(PayoffPart::Value, kind));
            }
            if seen.contains(&set) {
                return Err(error(PayoffPart::Set, SpecErrorKind::SetGivenTwice));
            }
            seen.push(set);
            if set.len() == 1 {
                per_task[set.iter().next().expect("one member")] = payoff.value;
            } else {
                overrides.push((set, payoff.value));
            }
        }
        SubsetPayoffs::new(&per_task, &overrides, names)
            .map_err(|e| SpecError::new(Field::Payoffs, SpecErrorKind::Payoffs(e)))
    }
}

/// Whether `count` sub-tasks are not too many (at most [`MAX_TASKS`]); a front end may ask
/// before it reads them.
pub fn check_count(count: usize) -> Result<(), SpecError> {
    if count > MAX_TASKS {
        return Err(SpecError::new(
            Field::Tasks,
            SpecErrorKind::TooManyTasks(count),
        ));
    }
    Ok(())
}

impl MdpSpec {
    /// The MDP stage's options on `arena`: sigma_L's weights checked against it, the discount
    /// and the precision in range, the observations read.
    pub fn build(&self, arena: &Arena) -> Result<MdpOptions, SpecError> {
        self.build_on(arena)
    }

    /// [`MdpSpec::build`] on a stored arena or on the implicit engine's rules
    /// ([`ArenaLookup`]): the same checks, the same errors.
    pub(crate) fn build_on(&self, arena: &impl ArenaLookup) -> Result<MdpOptions, SpecError> {
        self.build_with(self.sigma_l.build(arena)?)
    }

    /// The options with `sigma_l`, the rest checked.
    fn build_with(&self, sigma_l: SigmaL) -> Result<MdpOptions, SpecError> {
        let discount = Discount::new(self.discount)
            .map_err(|e| SpecError::new(Field::Discount, SpecErrorKind::Solve(e)))?;
        let (epsilon, relative) = match self.precision {
            Precision::Absolute(epsilon) => (epsilon, false),
            Precision::Relative(epsilon) => (epsilon, true),
        };
        let solve = SolveOptions {
            discount,
            epsilon,
            relative,
            max_iterations: self.max_iterations,
        };
        solve
            .epsilon()
            .map_err(|e| SpecError::new(Field::Precision, SpecErrorKind::Solve(e)))?;
        let learnt = match &self.learnt {
            Some(learnt) => Some(Learnt {
                observations: Observations::parse(&learnt.text).map_err(|e| {
                    SpecError::located(Field::Observations, e, SpecErrorKind::Observations)
                })?,
                file: learnt.name.clone(),
                delta: learnt.delta,
            }),
            None => None,
        };
        Ok(MdpOptions {
            sigma_l,
            seed: self.seed,
            solve,
            learnt,
        })
    }
}

impl SigmaLSpec {
    /// sigma_L, its weights checked against `arena`.
    fn build(&self, arena: &impl ArenaLookup) -> Result<SigmaL, SpecError> {
        match self {
            SigmaLSpec::Value(sigma_l) => {
                if let SigmaL::Weights { table, .. } = sigma_l {
                    table.check(arena).map_err(|errors| {
                        let TableError { entry, error, .. } = errors.first().clone();
                        let weight = &table.entries()[entry];
                        let field = Field::Weight {
                            state: weight.state.clone(),
                            action: weight.action.clone(),
                        };
                        SpecError::new(field, SpecErrorKind::Weight(error))
                    })?;
                }
                Ok(sigma_l.clone())
            }
            SigmaLSpec::WeightsFile { name, text } => {
                let file = WeightsFile::parse(text)
                    .and_then(|file| file.check(arena).map(|()| file))
                    .map_err(|e| {
                        SpecError::located(Field::Weights, e, SpecErrorKind::WeightsFile)
                    })?;
                Ok(SigmaL::Weights {
                    table: file.table,
                    file: name.clone(),
                })
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Robot `r` moves `go` to the adversary's `a`, which sends it `on` to `g` (A and B hold
    /// there) or `back`; `g` loops.
    const ARENA: &str = "propositions A B C
state r robot {}
state a adversary {}
state g robot {A B}
initial r
edge r go a
edge a on g
edge a back r
edge g stay g
";

    fn formula(text: &str) -> TaskSource {
        TaskSource::Formula(text.into())
    }

    fn named(name: &str, text: &str) -> NamedTask {
        NamedTask {
            name: name.into(),
            task: formula(text),
        }
    }

    fn payoff(set: &[&str], value: f64) -> SetPayoff {
        SetPayoff {
            set: set.iter().map(|name| name.to_string()).collect(),
            value,
        }
    }

    /// Sub-tasks A = `F A`, B = `F B`, C = `F C`, the belief `F A`, the MDP stage's defaults.
    fn general() -> ProblemSpec {
        ProblemSpec {
            arena: ArenaSpec::Text {
                name: "tiny".into(),
                text: ARENA.into(),
            },
            tasks: TasksSpec::General(GeneralSpec {
                tasks: vec![named("A", "F A"), named("B", "F B"), named("C", "F C")],
                payoffs: Vec::new(),
                believed: formula("F A"),
                risk: Risk::Paper,
            }),
            states: States::Full,
            translation: Translation {
                choice: TranslatorChoice::Builtin,
                ..Translation::default()
            },
            mdp: Some(MdpSpec::default()),
            engine: None,
        }
    }

    /// The paper's tasks from formulas on the same arena.
    fn paper(phi: &str, psi: &str, phi2: Option<&str>) -> ProblemSpec {
        ProblemSpec {
            tasks: TasksSpec::Paper {
                phi: phi.into(),
                psi: psi.into(),
                phi2: phi2.map(str::to_string),
                payoffs: PaperPayoffs::default(),
            },
            ..general()
        }
    }

    fn general_tasks(spec: &mut ProblemSpec) -> &mut GeneralSpec {
        match &mut spec.tasks {
            TasksSpec::General(general) => general,
            _ => unreachable!("a general spec"),
        }
    }

    fn mdp(spec: &mut ProblemSpec) -> &mut MdpSpec {
        spec.mdp.as_mut().expect("an MDP stage")
    }

    /// The error of `spec`: its field, its position as (line, column), and its kind.
    fn error(spec: &ProblemSpec) -> (Field, Option<(usize, usize)>, SpecErrorKind) {
        let error = spec.build(&mut ()).err().expect("an error");
        let at = error.position.map(|p| (p.line, p.column));
        (error.field, at, *error.kind)
    }

    fn task(index: usize, name: &str) -> Field {
        Field::Task {
            index,
            name: name.into(),
        }
    }

    fn member(index: usize, member: usize) -> Field {
        Field::Payoff {
            index,
            part: PayoffPart::Member(member),
        }
    }

    #[test]
    fn a_valid_spec_builds_its_problem() {
        let mut spec = general();
        general_tasks(&mut spec).payoffs = vec![payoff(&["A"], 200.0), payoff(&["A", "B"], 350.0)];
        let problem = spec.build(&mut ()).unwrap();
        assert_eq!(problem.arena_name, "tiny");
        assert_eq!(problem.arena.num_states(), 3);
        assert_eq!(problem.tasks.names(), ["A", "B", "C"]);
        let r = |mask| problem.tasks.payoffs().get(TaskSet(mask));
        // A named alone, B and C the default 100, {A,B} named, the other sets the sums of their
        // members'.
        assert_eq!([r(0b001), r(0b010), r(0b100)], [200.0, 100.0, 100.0]);
        assert_eq!([r(0b011), r(0b101), r(0b111)], [350.0, 300.0, 400.0]);
        let options = problem.mdp.expect("the MDP stage");
        assert_eq!(options.sigma_l, SigmaL::Random { seed: 2019 });
        assert_eq!(options.solve, SolveOptions::default());
    }

    #[test]
    fn the_papers_preset_and_its_payoffs() {
        let problem = paper("F A & F B", "F A", None).build(&mut ()).unwrap();
        let presentation = problem.tasks.presentation();
        assert_eq!(presentation.names(), ["phi1", "phi2"]);
        assert_eq!(presentation.whole_task(), Some("FA & FB"));
        // r < r1 + r2: refused when the MDP stage runs, ignored by the games alone.
        let mut spec = paper("F A & F B", "F A", None);
        let TasksSpec::Paper { payoffs, .. } = &mut spec.tasks else {
            unreachable!()
        };
        payoffs.r = 250.0;
        let (field, at, kind) = error(&spec);
        assert_eq!((field, at), (Field::PaperPayoffs, None));
        assert!(matches!(kind, SpecErrorKind::PaperPayoffs(_)));
        spec.mdp = None;
        assert!(spec.build(&mut ()).is_ok());
    }

    #[test]
    fn formula_errors_are_located_in_their_field() {
        let (field, at, kind) = error(&paper("F (A", "F A", None));
        assert_eq!((field, at), (Field::Phi, Some((1, 5))));
        assert!(matches!(kind, SpecErrorKind::Formula(_)));
        let (field, at, _) = error(&paper("F A & F B", "F A &", None));
        assert_eq!((field, at), (Field::Psi, Some((1, 6))));
        let (field, at, _) = error(&paper("F A & F B", "F A", Some("(F B")));
        assert_eq!((field, at), (Field::Phi2, Some((1, 5))));
        let mut spec = general();
        general_tasks(&mut spec).tasks[1] = named("B", "F B U");
        let (field, at, _) = error(&spec);
        assert_eq!((field, at), (task(1, "B"), Some((1, 6))));
        let mut spec = general();
        general_tasks(&mut spec).believed = formula("\n  X");
        let (field, at, _) = error(&spec);
        assert_eq!((field, at), (Field::Believed, Some((2, 4))));
    }

    #[test]
    fn split_and_translation_errors_are_located_in_the_text_they_come_from() {
        // psi is not a conjunct of phi: at psi's conjunct.
        let (field, at, kind) = error(&paper("F A & F B", "F A & F C", None));
        assert_eq!((field, at), (Field::Psi, Some((1, 7))));
        assert!(matches!(
            kind,
            SpecErrorKind::Split(SplitError::PsiNotInPhi(_))
        ));
        // A conjunct of phi in neither psi nor phi2: at phi's.
        let (field, at, _) = error(&paper("F A & F B & F C", "F A", Some("F B")));
        assert_eq!((field, at), (Field::Phi, Some((1, 13))));
        // Not co-safe: a formula error of the text that has it, phi's first...
        let (field, at, kind) = error(&paper("F A & G B", "F A", Some("G B")));
        assert_eq!((field, at), (Field::Phi, Some((1, 7))));
        assert!(matches!(kind, SpecErrorKind::NotCoSafe(_)));
        // ... phi2's when phi is co-safe.
        let (field, at, _) = error(&paper("F A & F B", "F A", Some("G B")));
        assert_eq!((field, at), (Field::Phi2, Some((1, 1))));
        let mut spec = general();
        general_tasks(&mut spec).tasks[2] = named("C", "F C | G A");
        let (field, at, kind) = error(&spec);
        assert_eq!((field, at), (task(2, "C"), Some((1, 7))));
        assert!(matches!(kind, SpecErrorKind::NotCoSafe(_)));
    }

    /// The formulas' own errors come before the relations between them, and each formula's
    /// come all at once: `G A` is not co-safe, which psi not being a conjunct of phi hid.
    #[test]
    fn formula_errors_come_all_at_once_before_the_relations_between_formulas() {
        let (field, at, kind) = error(&paper("G A", "!O U A", None));
        assert_eq!((field, at), (Field::Phi, Some((1, 1))));
        let SpecErrorKind::NotCoSafe(errors) = kind else {
            panic!("a co-safety error: {kind:?}")
        };
        assert_eq!(errors.total(), 1);
        assert!(errors.first().message.contains("`G` (globally)"));
        // Three offending operators of one formula, each at its column, in text order; psi
        // (itself not co-safe) waits for phi to be right.
        let (field, _, kind) = error(&paper("G A & (B R C) & !F D", "F E & G A", None));
        assert_eq!(field, Field::Phi);
        let SpecErrorKind::NotCoSafe(errors) = kind else {
            panic!("a co-safety error: {kind:?}")
        };
        let at: Vec<_> = errors
            .iter()
            .map(|d| (d.position.line, d.position.column))
            .collect();
        assert_eq!(at, [(1, 1), (1, 10), (1, 18)]);
        // phi right, psi's errors, before the split (F E is not a conjunct of phi).
        let (field, _, kind) = error(&paper("F A & F B", "F E & G A & (A W B)", None));
        assert_eq!(field, Field::Psi);
        let SpecErrorKind::NotCoSafe(errors) = kind else {
            panic!("a co-safety error: {kind:?}")
        };
        assert_eq!(errors.total(), 2);
    }

    #[test]
    fn hoa_tasks_are_read_and_their_errors_located() {
        let good = crate::automata::hoa::write(
            &crate::translate::Builtin::default()
                .translate(&ltl::parse("F B").unwrap())
                .unwrap(),
            Some("F B"),
        )
        .unwrap();
        let hoa = |text: &str| TaskSource::Hoa {
            name: "b.hoa".into(),
            text: text.into(),
        };
        let parts = |phi2: TaskSource| ProblemSpec {
            tasks: TasksSpec::PaperParts {
                phi1: formula("F A"),
                phi2,
                payoffs: PaperPayoffs::default(),
            },
            ..general()
        };
        let problem = parts(hoa(&good)).build(&mut ()).unwrap();
        assert_eq!(
            problem.tasks.presentation().whole_task(),
            Some("(FA) & b.hoa")
        );
        assert_eq!(problem.tasks.subtasks()[1].task.translator, "hoa");
        let (field, at, kind) = error(&parts(hoa("HOA: v1\nStates: x\n")));
        assert_eq!((field, at), (Field::Phi2, Some((2, 9))));
        assert!(matches!(kind, SpecErrorKind::Hoa(_)));
        let (field, at, kind) = error(&parts(hoa(&format!("{good}{good}"))));
        assert_eq!((field, at), (Field::Phi2, None));
        assert!(matches!(kind, SpecErrorKind::AutomatonCount(2)));
    }

    #[test]
    fn the_translator_is_made_only_when_a_formula_needs_it() {
        let spot = Translation {
            choice: TranslatorChoice::Spot,
            ..Translation::default()
        };
        let mut spec = ProblemSpec {
            translation: spot,
            ..general()
        };
        let (field, at, kind) = error(&spec);
        assert_eq!((field, at), (Field::Translator, None));
        assert!(matches!(kind, SpecErrorKind::Translator(_)));
        // Automata only: no translator needed.
        let automaton = |text: &str| {
            let dfa = crate::translate::Builtin::default()
                .translate(&ltl::parse(text).unwrap())
                .unwrap();
            TaskSource::Automaton(Task::from_automaton(text, &dfa))
        };
        let general = general_tasks(&mut spec);
        for task in &mut general.tasks {
            task.task = automaton(&format!("F {}", task.name));
        }
        general.believed = automaton("F A");
        assert!(spec.build(&mut ()).is_ok());
    }

    #[test]
    fn sub_tasks_are_named_once_each_and_at_most_eight() {
        let mut spec = general();
        general_tasks(&mut spec).tasks[1].name = "1B".into();
        let (field, at, kind) = error(&spec);
        assert_eq!((field, at), (task(1, "1B"), None));
        assert!(matches!(kind, SpecErrorKind::TaskName(name) if name == "1B"));
        let mut spec = general();
        general_tasks(&mut spec).tasks[2].name = "A".into();
        let (field, _, kind) = error(&spec);
        assert_eq!(field, task(2, "A"));
        assert!(matches!(kind, SpecErrorKind::DuplicateTask(name) if name == "A"));
        let mut spec = general();
        general_tasks(&mut spec).tasks = (0..9).map(|i| named(&format!("T{i}"), "F A")).collect();
        let (field, _, kind) = error(&spec);
        assert_eq!(field, Field::Tasks);
        assert_eq!(kind.to_string(), "at most 8 sub-tasks are supported, got 9");
        assert!(check_count(8).is_ok());
    }

    #[test]
    fn payoffs_are_on_sets_of_known_names_finite_non_negative_and_monotone() {
        // The payoffs, the field of their first error, and whether its kind is the expected.
        type Case = (Vec<SetPayoff>, Field, fn(&SpecErrorKind) -> bool);
        let cases: Vec<Case> = vec![
            (
                vec![payoff(&["A", "2x"], 1.0)],
                member(0, 1),
                |k| matches!(k, SpecErrorKind::TaskName(n) if n == "2x"),
            ),
            (
                vec![payoff(&["A"], 1.0), payoff(&["B", "D"], 1.0)],
                member(1, 1),
                |k| matches!(k, SpecErrorKind::UnknownTask(n) if n == "D"),
            ),
            (
                vec![payoff(&["C", "A", "C"], 1.0)],
                member(0, 2),
                |k| matches!(k, SpecErrorKind::ListedTwice(n) if n == "C"),
            ),
            (
                vec![payoff(&[], 1.0)],
                Field::Payoff {
                    index: 0,
                    part: PayoffPart::Set,
                },
                |k| matches!(k, SpecErrorKind::EmptySet),
            ),
            (
                vec![payoff(&["A"], -1.0)],
                Field::Payoff {
                    index: 0,
                    part: PayoffPart::Value,
                },
                |k| matches!(k, SpecErrorKind::InvalidPayoff(v) if *v == -1.0),
            ),
            (
                vec![payoff(&["B"], f64::NAN)],
                Field::Payoff {
                    index: 0,
                    part: PayoffPart::Value,
                },
                |k| matches!(k, SpecErrorKind::InvalidPayoff(v) if v.is_nan()),
            ),
            (
                vec![payoff(&["A"], f64::INFINITY)],
                Field::Payoff {
                    index: 0,
                    part: PayoffPart::Value,
                },
                |k| matches!(k, SpecErrorKind::InvalidPayoff(_)),
            ),
            (
                vec![payoff(&["A", "B"], 1.0), payoff(&["B", "A"], 2.0)],
                Field::Payoff {
                    index: 1,
                    part: PayoffPart::Set,
                },
                |k| matches!(k, SpecErrorKind::SetGivenTwice),
            ),
            (
                vec![payoff(&["A"], 300.0), payoff(&["A", "C"], 250.0)],
                Field::Payoffs,
                |k| {
                    k.to_string()
                        == "payoffs must be monotone: a set of sub-tasks pays at least as much \
                            as each of its subsets, but r(A) = 300 > r(A,C) = 250"
                },
            ),
        ];
        for (payoffs, expected, is_expected) in cases {
            let mut spec = general();
            general_tasks(&mut spec).payoffs = payoffs.clone();
            let (field, at, kind) = error(&spec);
            assert_eq!((&field, at), (&expected, None), "{payoffs:?}");
            assert!(is_expected(&kind), "{payoffs:?}: {kind:?}");
        }
    }

    #[test]
    fn arena_errors_are_located_in_its_text() {
        let mut spec = general();
        spec.arena = ArenaSpec::Text {
            name: "bad".into(),
            text: ARENA.replace("state a adversary", "state a sideways"),
        };
        let (field, at, kind) = error(&spec);
        assert_eq!((field, at), (Field::Arena, Some((3, 9))));
        assert!(matches!(kind, SpecErrorKind::Arena(_)));
        // A map, recognised by its header, or read as one.
        let map = "hypersynth map v1\ngrid\n@r . @a\n. A B\n";
        spec.arena = ArenaSpec::Text {
            name: "map".into(),
            text: map.into(),
        };
        let problem = spec.build(&mut ()).unwrap();
        assert!(problem.map.is_some());
        spec.arena = ArenaSpec::Map {
            name: "map".into(),
            text: map.replace("@a", "@q"),
        };
        let (field, at, kind) = error(&spec);
        assert_eq!((field, at), (Field::Arena, Some((3, 6))));
        assert!(matches!(kind, SpecErrorKind::Map(_)));
        // An arena built: used as it is.
        let arena = arena::parse(ARENA).unwrap().arena;
        spec.arena = ArenaSpec::Built {
            name: "built".into(),
            arena: Box::new(arena.clone()),
            map: None,
        };
        assert_eq!(spec.build(&mut ()).unwrap().arena, arena);
    }

    #[test]
    fn weights_are_checked_against_the_arena_where_they_are_given() {
        let mut spec = general();
        mdp(&mut spec).sigma_l = SigmaLSpec::WeightsFile {
            name: "w.txt".into(),
            text: "a on 2\na back 1\n".into(),
        };
        let options = spec.build(&mut ()).unwrap().mdp.unwrap();
        let mut table = crate::opportunistic::adversary::WeightTable::new();
        table.add("a", "on", 2.0);
        table.add("a", "back", 1.0);
        let from_values = SigmaL::Weights {
            table,
            file: "w.txt".into(),
        };
        assert_eq!(options.sigma_l, from_values);
        // A file: its reading errors and its lines that do not fit the arena, located in it.
        mdp(&mut spec).sigma_l = SigmaLSpec::WeightsFile {
            name: "w.txt".into(),
            text: "a on 2\na  up 1\n".into(),
        };
        let (field, at, kind) = error(&spec);
        assert_eq!((field, at), (Field::Weights, Some((2, 4))));
        assert!(matches!(kind, SpecErrorKind::WeightsFile(_)));
        mdp(&mut spec).sigma_l = SigmaLSpec::WeightsFile {
            name: "w.txt".into(),
            text: "a on\n".into(),
        };
        let (field, at, _) = error(&spec);
        assert_eq!((field, at), (Field::Weights, Some((1, 1))));
        // A table of values: its first wrong entry, by state and action.
        let mut table = crate::opportunistic::adversary::WeightTable::new();
        table.add("a", "on", 1.0);
        table.add("r", "go", 1.0);
        mdp(&mut spec).sigma_l = SigmaLSpec::Value(SigmaL::Weights {
            table,
            file: "values".into(),
        });
        let (field, at, kind) = error(&spec);
        let expected = Field::Weight {
            state: "r".into(),
            action: "go".into(),
        };
        assert_eq!((field, at), (expected, None));
        assert!(matches!(
            kind,
            SpecErrorKind::Weight(EntryError::RobotState { .. })
        ));
    }

    #[test]
    fn solver_options_and_observations_are_checked() {
        let mut spec = general();
        mdp(&mut spec).discount = 1.5;
        let (field, _, kind) = error(&spec);
        assert_eq!(field, Field::Discount);
        assert!(matches!(
            kind,
            SpecErrorKind::Solve(SolveError::InvalidDiscount(_))
        ));
        for precision in [Precision::Absolute(0.0), Precision::Relative(f64::NAN)] {
            let mut spec = general();
            mdp(&mut spec).precision = precision;
            let (field, _, kind) = error(&spec);
            assert_eq!(field, Field::Precision);
            assert!(matches!(
                kind,
                SpecErrorKind::Solve(SolveError::InvalidEpsilon(_))
            ));
        }
        let mut spec = general();
        mdp(&mut spec).precision = Precision::Relative(1e-3);
        let solve = spec.build(&mut ()).unwrap().mdp.unwrap().solve;
        assert!(solve.relative && solve.epsilon == 1e-3);
        mdp(&mut spec).learnt = Some(LearntSpec {
            name: "runs.txt".into(),
            text: "r go a on g\nr go\n".into(),
            delta: 0.05,
        });
        let (field, at, kind) = error(&spec);
        assert_eq!((field, at), (Field::Observations, Some((2, 3))));
        assert!(matches!(kind, SpecErrorKind::Observations(_)));
        // Without the MDP stage, its options are not read.
        spec.mdp = None;
        assert!(spec.build(&mut ()).is_ok());
    }

    #[test]
    fn the_tasks_are_checked_before_the_arena_and_the_arena_before_the_weights() {
        let mut spec = general();
        general_tasks(&mut spec).tasks[0] = named("A", "F (");
        spec.arena = ArenaSpec::Text {
            name: "bad".into(),
            text: "nonsense\n".into(),
        };
        mdp(&mut spec).discount = 0.0;
        assert_eq!(error(&spec).0, task(0, "A"));
        general_tasks(&mut spec).tasks[0] = named("A", "F A");
        assert_eq!(error(&spec).0, Field::Arena);
        spec.arena = general().arena;
        assert_eq!(error(&spec).0, Field::Discount);
    }
}

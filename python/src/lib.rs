//! `hypersynth._hypersynth`: the Python extension over the library's pipeline
//! (`hypersynth::pipeline`). It holds no logic of its own beyond turning Python values into the
//! library's and back: arenas, tasks, the problem, its solution (kept solved, so that every
//! question asked of it reads the one solution) and the exported controller's executor.
//!
//! Invariants: every library error becomes one exception of the `hypersynth.Error` hierarchy
//! whose message is the command line's (located texts are named after the Python argument that
//! gave them); the GIL is released while a problem is solved, and the solve polls Python's
//! signal handlers through the stage observer, so that Ctrl-C unwinds it through
//! `stage::interruptible`.

use std::sync::Arc;
use std::time::{Duration, Instant};

use numpy::PyArray1;
use pyo3::exceptions::{PyException, PyKeyboardInterrupt};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use pyo3::{PyTypeInfo, create_exception};

use hypersynth::arena::gridworld::Gridworld;
use hypersynth::arena::{self as lib_arena, Owner, map};
use hypersynth::automata::hoa;
use hypersynth::diagnostic::{Diagnostics, Source};
use hypersynth::game::{Payoffs, States, SubsetPayoffs, TaskSet};
use hypersynth::ltl::{self, Formula};
use hypersynth::mdp::DrnForm;
use hypersynth::mdp::solve::{Discount, SolveOptions};
use hypersynth::opportunistic::adversary::{SigmaL, WeightTable};
use hypersynth::opportunistic::build::Risk;
use hypersynth::opportunistic::executor::Executor;
use hypersynth::opportunistic::simulate::{Ending, SimulationOptions, simulate, trace};
use hypersynth::opportunistic::view::{GameView, SolvedGame};
use hypersynth::pipeline::{
    self, Believed, MdpOptions, Picture, PictureRequest, PipelineError, Requests, Solved, Subtask,
    Task, Tasks, TasksError, is_task_name,
};
use hypersynth::position::Position;
use hypersynth::render::title::TitleChoice;
use hypersynth::report::StageError;
use hypersynth::stage::{self, Observer};
use hypersynth::translate::{self, TranslateError, Translator, TranslatorChoice};

create_exception!(
    _hypersynth,
    Error,
    PyException,
    "Every error of hypersynth. `file`, `line` and `column` locate it when it is in a text \
     (None otherwise); the message is the command line's."
);
create_exception!(
    _hypersynth,
    ParseError,
    Error,
    "A text (arena, map, formula, HOA automaton, adversary weights, state name) is malformed."
);
create_exception!(
    _hypersynth,
    ArenaError,
    Error,
    "An arena cannot be built (a duplicate state, an unknown state, a bad map)."
);
create_exception!(
    _hypersynth,
    TranslationError,
    Error,
    "A formula cannot be translated to a DFA (not co-safe, too large, Spot missing or failing)."
);
create_exception!(
    _hypersynth,
    TaskError,
    Error,
    "The tasks do not fit together (psi not a conjunct of phi, payoffs not monotone, bad names)."
);
create_exception!(
    _hypersynth,
    OptionsError,
    Error,
    "A solve option is out of range (discount, epsilon, sigma_l, a picture's name)."
);
create_exception!(
    _hypersynth,
    SolveError,
    Error,
    "The MDP stage failed (iteration limit, the controller's check)."
);
create_exception!(
    _hypersynth,
    ControllerError,
    Error,
    "An exported controller is invalid, or was given a state it cannot take."
);

/// An exception of kind `E` with `message`, located at `position` of `file` when known.
fn exception<E: PyTypeInfo>(
    message: impl Into<String>,
    file: Option<&str>,
    position: Option<Position>,
) -> PyErr {
    let err = PyErr::new::<E, _>(message.into());
    Python::attach(|py| {
        let value = err.value(py);
        // Setting attributes on a fresh exception object cannot fail short of memory.
        let _ = value.setattr("file", file);
        let _ = value.setattr("line", position.map(|p| p.line));
        let _ = value.setattr("column", position.map(|p| p.column));
    });
    err
}

/// The errors of a reader of `text` (named `name`), rendered as the command line renders them:
/// `NAME:LINE:COL: message`, the line and a caret, for each.
fn located<E: PyTypeInfo, M: std::fmt::Display>(
    name: &str,
    text: &str,
    diagnostics: &Diagnostics<M>,
) -> PyErr {
    let message = Source::new(name, text).render(diagnostics).join("\n");
    exception::<E>(message, Some(name), Some(diagnostics.first().position))
}

/// One error at `position` of `text`, rendered as [`located`] does.
fn located_at<E: PyTypeInfo>(
    name: &str,
    text: &str,
    position: Position,
    message: &dyn std::fmt::Display,
) -> PyErr {
    let diagnostics: Diagnostics =
        hypersynth::diagnostic::Diagnostic::new(position, message.to_string()).into();
    located::<E, _>(name, text, &diagnostics)
}

fn parse_formula(name: &str, text: &str) -> PyResult<Formula> {
    ltl::parse(text).map_err(|errors| located::<ParseError, _>(name, text, &errors))
}

fn translate_error(name: &str, text: &str, error: TranslateError) -> PyErr {
    match error.position(text) {
        Some(position) => located_at::<TranslationError>(name, text, position, &error),
        None => exception::<TranslationError>(format!("{name}: {error}"), Some(name), None),
    }
}

fn translator(choice: &str) -> PyResult<Box<dyn Translator>> {
    let choice = match choice {
        "auto" => TranslatorChoice::Auto,
        "builtin" => TranslatorChoice::Builtin,
        "spot" => TranslatorChoice::Spot,
        other => {
            return Err(exception::<OptionsError>(
                format!("translator: `{other}` is not one of auto, builtin, spot"),
                None,
                None,
            ));
        }
    };
    // As the command line finds it: $HYPERSYNTH_LTL2TGBA, else PATH.
    let ltl2tgba = translate::spot::locate_ltl2tgba(
        None,
        std::env::var_os(translate::spot::LTL2TGBA_VARIABLE).as_deref(),
        std::env::var_os("PATH").as_deref(),
    );
    // The library's default limits: 2^20 states and a bounded amount of work.
    translate::resolve(choice, ltl2tgba, translate::Limits::default())
        .map_err(|e| exception::<TranslationError>(format!("translator: {e}"), None, None))
}

// ---------------------------------------------------------------------------------------------
// Arenas

/// A two-player arena: robot and adversary states, labelled by propositions. Build one with
/// `Arena.from_file`, `Arena.from_string`, `Arena.from_map` or `ArenaBuilder`.
#[pyclass(frozen, module = "hypersynth")]
#[derive(Clone)]
struct Arena {
    name: String,
    arena: Arc<lib_arena::Arena>,
    map: Option<Arc<Gridworld>>,
}

impl Arena {
    fn read(name: &str, text: &str) -> PyResult<Arena> {
        if map::is_map(text) {
            return Arena::of_map(name, text);
        }
        let parsed = lib_arena::parse(text)
            .map_err(|errors| located::<ParseError, _>(name, text, &errors))?;
        Ok(Arena {
            name: name.to_string(),
            arena: Arc::new(parsed.arena),
            map: None,
        })
    }

    fn of_map(name: &str, text: &str) -> PyResult<Arena> {
        let world =
            map::parse(text).map_err(|errors| located::<ParseError, _>(name, text, &errors))?;
        // As the command line solves maps: display names serve only the arena writer.
        let arena = world
            .build_without_display_names()
            .map_err(|e| exception::<ArenaError>(format!("{name}: {e}"), Some(name), None))?;
        Ok(Arena {
            name: name.to_string(),
            arena: Arc::new(arena),
            map: Some(Arc::new(world)),
        })
    }
}

#[pymethods]
impl Arena {
    /// Reads an arena file, or a map file (recognised by its header).
    #[staticmethod]
    fn from_file(path: std::path::PathBuf) -> PyResult<Arena> {
        let name = path.display().to_string();
        let text = std::fs::read_to_string(&path).map_err(|e| {
            exception::<Error>(format!("{name}: cannot read: {e}"), Some(&name), None)
        })?;
        Arena::read(&name, &text)
    }

    /// Reads an arena (or a map) from its text; `name` names it in messages and reports.
    #[staticmethod]
    #[pyo3(signature = (text, name = "<string>"))]
    fn from_string(text: &str, name: &str) -> PyResult<Arena> {
        Arena::read(name, text)
    }

    /// Builds the arena of a map's text (the map format of the README).
    #[staticmethod]
    #[pyo3(signature = (text, name = "<map>"))]
    fn from_map(text: &str, name: &str) -> PyResult<Arena> {
        Arena::of_map(name, text)
    }

    /// The name of the arena in messages and reports.
    #[getter]
    fn name(&self) -> &str {
        &self.name
    }

    fn __len__(&self) -> usize {
        self.arena.num_states()
    }

    /// The states' names, in arena order.
    #[getter]
    fn names(&self) -> Vec<&str> {
        self.arena.states().map(|s| self.arena.name(s)).collect()
    }

    /// Per state, `"robot"` or `"adversary"`.
    #[getter]
    fn owners(&self) -> Vec<&'static str> {
        self.arena
            .states()
            .map(|s| match self.arena.owner(s) {
                Owner::Robot => "robot",
                Owner::Adversary => "adversary",
            })
            .collect()
    }

    /// Per state, the set of propositions that hold there.
    #[getter]
    fn labels(&self) -> Vec<std::collections::BTreeSet<&str>> {
        let propositions = self.arena.propositions();
        self.arena
            .states()
            .map(|s| {
                self.arena
                    .label(s)
                    .iter()
                    .map(|p| propositions[p].as_str())
                    .collect()
            })
            .collect()
    }

    /// The initial state's name.
    #[getter]
    fn initial(&self) -> &str {
        self.arena.name(self.arena.initial())
    }

    /// The arena's propositions.
    #[getter]
    fn propositions(&self) -> Vec<String> {
        self.arena.propositions().to_vec()
    }

    /// The arena's actions.
    #[getter]
    fn actions(&self) -> Vec<String> {
        self.arena.actions().to_vec()
    }

    /// The transitions of state `name`: `(action, successor)` pairs.
    fn transitions(&self, name: &str) -> PyResult<Vec<(String, String)>> {
        let state = self.arena.find_state(name).ok_or_else(|| {
            exception::<ArenaError>(format!("no state is named `{name}`"), None, None)
        })?;
        Ok(self
            .arena
            .edges(state)
            .map(|(a, t)| {
                let action = self.arena.action_name(a).to_string();
                (action, self.arena.name(t).to_string())
            })
            .collect())
    }

    /// The arena in the arena format.
    fn to_text(&self) -> String {
        lib_arena::write(&self.arena)
    }

    /// The map as SVG (a map-based arena only; None otherwise).
    fn _repr_svg_(&self) -> Option<String> {
        let world = self.map.as_deref()?;
        let size = format!("Map, {} × {} cells", world.width, world.height);
        let title = hypersynth::render::title::Title::new(vec![size], &TitleChoice::Default);
        Some(hypersynth::render::picture::map(world, &title))
    }

    fn __repr__(&self) -> String {
        format!(
            "<hypersynth.Arena {:?}: {} states, {} transitions{}>",
            self.name,
            self.arena.num_states(),
            self.arena.num_transitions(),
            if self.map.is_some() { ", a map" } else { "" }
        )
    }
}

/// Builds an arena in code: `add_state`, `add_transition`, `set_initial`, then `build`.
#[pyclass(module = "hypersynth")]
struct ArenaBuilder {
    builder: Option<lib_arena::ArenaBuilder>,
}

impl ArenaBuilder {
    fn builder(&mut self) -> PyResult<&mut lib_arena::ArenaBuilder> {
        self.builder.as_mut().ok_or_else(|| {
            exception::<ArenaError>("this builder has already built its arena", None, None)
        })
    }

    fn state(&mut self, name: &str) -> PyResult<lib_arena::StateId> {
        self.builder()?.find_state(name).ok_or_else(|| {
            exception::<ArenaError>(format!("no state is named `{name}`"), None, None)
        })
    }
}

#[pymethods]
impl ArenaBuilder {
    #[new]
    fn new() -> Self {
        ArenaBuilder {
            builder: Some(lib_arena::ArenaBuilder::new()),
        }
    }

    /// Adds state `name` owned by `owner` (`"robot"` or `"adversary"`) where `labels` hold.
    #[pyo3(signature = (name, owner, labels = Vec::new()))]
    fn add_state(&mut self, name: &str, owner: &str, labels: Vec<String>) -> PyResult<()> {
        let owner = match owner {
            "robot" => Owner::Robot,
            "adversary" => Owner::Adversary,
            other => {
                return Err(exception::<ArenaError>(
                    format!("owner `{other}` is not `robot` or `adversary`"),
                    None,
                    None,
                ));
            }
        };
        let labels: Vec<&str> = labels.iter().map(String::as_str).collect();
        self.builder()?
            .add_state(name, owner, labels, None)
            .map_err(|e| exception::<ArenaError>(e.to_string(), None, None))?;
        Ok(())
    }

    /// Adds the transition `source --action--> target` (states by name).
    fn add_transition(&mut self, source: &str, action: &str, target: &str) -> PyResult<()> {
        let (s, t) = (self.state(source)?, self.state(target)?);
        self.builder()?
            .add_transition(s, action, t)
            .map_err(|e| exception::<ArenaError>(e.to_string(), None, None))?;
        Ok(())
    }

    /// Makes state `name` the initial one (default: the first added).
    fn set_initial(&mut self, name: &str) -> PyResult<()> {
        let state = self.state(name)?;
        self.builder()?.set_initial(state);
        Ok(())
    }

    /// The arena built (the builder cannot be used after).
    #[pyo3(signature = (name = "<builder>"))]
    fn build(&mut self, name: &str) -> PyResult<Arena> {
        let builder = self.builder.take().ok_or_else(|| {
            exception::<ArenaError>("this builder has already built its arena", None, None)
        })?;
        let arena = builder
            .build()
            .map_err(|e| exception::<ArenaError>(e.to_string(), None, None))?;
        Ok(Arena {
            name: name.to_string(),
            arena: Arc::new(arena),
            map: None,
        })
    }
}

// ---------------------------------------------------------------------------------------------
// Automata

/// A task's automaton: the minimal DFA of its good prefixes, with its HOA text.
#[pyclass(frozen, module = "hypersynth")]
#[derive(Clone)]
struct Automaton {
    task: Task,
}

#[pymethods]
impl Automaton {
    /// Reads the one automaton of a HOA text (from any tool: Spot's Python bindings give it
    /// with `aut.to_str("hoa")`); `name` names it in reports.
    #[staticmethod]
    #[pyo3(signature = (text, name = "<hoa>"))]
    fn from_hoa(text: &str, name: &str) -> PyResult<Automaton> {
        Ok(Automaton {
            task: read_hoa(name, text)?,
        })
    }

    /// The automaton in HOA.
    #[getter]
    fn hoa(&self) -> PyResult<String> {
        hoa::write(&self.task.dfa, Some(&self.task.name))
            .map_err(|e| exception::<Error>(e.to_string(), None, None))
    }

    /// How reports name it: its formula, or the name it was read under.
    #[getter]
    fn name(&self) -> &str {
        &self.task.name
    }

    /// What made it: a translator's name, or `hoa`.
    #[getter]
    fn translator(&self) -> &str {
        &self.task.translator
    }

    /// Its number of states.
    #[getter]
    fn num_states(&self) -> usize {
        self.task.dfa.num_states()
    }

    /// Its atomic propositions.
    #[getter]
    fn propositions(&self) -> Vec<String> {
        self.task.dfa.aps().to_vec()
    }

    fn __repr__(&self) -> String {
        format!(
            "<hypersynth.Automaton {:?}: {} states, by {}>",
            self.task.name,
            self.task.dfa.num_states(),
            self.task.translator
        )
    }
}

fn read_hoa(name: &str, text: &str) -> PyResult<Task> {
    let automata =
        hoa::parse(text).map_err(|errors| located::<ParseError, _>(name, text, &errors))?;
    let [automaton] = automata.as_slice() else {
        return Err(exception::<ParseError>(
            format!("{name}: expected one automaton, found {}", automata.len()),
            Some(name),
            None,
        ));
    };
    Ok(Task::from_automaton(name, &automaton.dfa))
}

/// Translates co-safe LTL `formula` to the minimal DFA of its good prefixes, by `translator`
/// (`"auto"`: Spot's `ltl2tgba` when on PATH, else the built-in translation; `"builtin"`;
/// `"spot"`).
#[pyfunction(name = "translate")]
#[pyo3(signature = (formula, translator = "auto"))]
fn translate_formula(formula: &str, translator: &str) -> PyResult<Automaton> {
    let parsed = parse_formula("formula", formula)?;
    let chosen = self::translator(translator)?;
    let task = Task::from_formula(parsed, chosen.as_ref())
        .map_err(|e| translate_error("formula", formula, e))?;
    Ok(Automaton { task })
}

/// A task given from Python: a formula's text, an `Automaton`, or a HOA text.
fn task_of(
    name: &str,
    value: &Bound<'_, PyAny>,
    translator: &mut dyn FnMut() -> PyResult<Box<dyn Translator>>,
    chosen: &mut Option<Box<dyn Translator>>,
) -> PyResult<Task> {
    if let Ok(automaton) = value.cast::<Automaton>() {
        return Ok(automaton.get().task.clone());
    }
    let text: String = value.extract()?;
    if text.trim_start().starts_with("HOA:") {
        return read_hoa(name, &text);
    }
    let formula = parse_formula(name, &text)?;
    let t = match chosen {
        Some(t) => t,
        None => chosen.insert(translator()?),
    };
    Task::from_formula(formula, t.as_ref()).map_err(|e| translate_error(name, &text, e))
}

// ---------------------------------------------------------------------------------------------
// Problems

/// A problem: an arena and the robot's tasks, in the paper's form
/// (`Problem(arena, phi=..., psi=...)`) or the general one
/// (`Problem(arena, tasks={...}, payoffs={...}, believed=..., risk=...)`). Solve it with
/// `solve`.
#[pyclass(frozen, module = "hypersynth")]
struct Problem {
    arena: Arena,
    tasks: Tasks,
    states: States,
}

fn risk(text: &str) -> PyResult<Risk> {
    Ok(match text {
        "paper" => Risk::Paper,
        "strict" => Risk::Strict,
        "neutral" => Risk::Neutral,
        other => {
            return Err(exception::<OptionsError>(
                format!("risk: `{other}` is not one of paper, strict, neutral"),
                None,
                None,
            ));
        }
    })
}

fn task_error(message: impl Into<String>) -> PyErr {
    exception::<TaskError>(message, None, None)
}

/// The payoffs of the general form: `{name or names: value}`, keys a sub-task's name, a tuple
/// or set of names, or names joined by `,`; a sub-task without one pays 100 and a set without
/// one the sum of its members.
fn subset_payoffs(
    payoffs: Option<&Bound<'_, PyDict>>,
    names: &[String],
) -> PyResult<SubsetPayoffs> {
    let mut per_task = vec![100.0; names.len()];
    let mut overrides: Vec<(TaskSet, f64)> = Vec::new();
    for (key, value) in payoffs.into_iter().flat_map(|d| d.iter()) {
        let members: Vec<String> = match key.extract::<String>() {
            Ok(text) => text.split(',').map(|s| s.trim().to_string()).collect(),
            Err(_) => key
                .try_iter()?
                .map(|m| m?.extract())
                .collect::<PyResult<_>>()?,
        };
        let mut set = TaskSet::default();
        for name in &members {
            let Some(i) = names.iter().position(|n| n == name) else {
                return Err(task_error(format!(
                    "payoffs: no sub-task is named `{name}` (give it in tasks)"
                )));
            };
            set = TaskSet(set.0 | 1 << i);
        }
        let value: f64 = value.extract()?;
        if !(value.is_finite() && value >= 0.0) {
            return Err(task_error(format!(
                "payoffs: invalid payoff `{value}` (a finite number >= 0)"
            )));
        }
        match set.len() {
            0 => return Err(task_error("payoffs: a key names no sub-task")),
            1 => per_task[set.iter().next().expect("one member")] = value,
            _ => overrides.push((set, value)),
        }
    }
    SubsetPayoffs::new(&per_task, &overrides, names)
        .map_err(|e| task_error(format!("payoffs: {e}")))
}

#[pymethods]
impl Problem {
    #[new]
    #[pyo3(signature = (
        arena, phi = None, psi = None, phi2 = None, *, tasks = None, payoffs = None,
        believed = None, risk = "paper", r1 = 200.0, r2 = 100.0, r = 300.0,
        translator = "auto", states = "full"
    ))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        arena: &Bound<'_, Arena>,
        phi: Option<&Bound<'_, PyAny>>,
        psi: Option<&Bound<'_, PyAny>>,
        phi2: Option<&Bound<'_, PyAny>>,
        tasks: Option<&Bound<'_, PyDict>>,
        payoffs: Option<&Bound<'_, PyDict>>,
        believed: Option<&Bound<'_, PyAny>>,
        risk: &str,
        r1: f64,
        r2: f64,
        r: f64,
        translator: &str,
        states: &str,
    ) -> PyResult<Problem> {
        let states = match states {
            "full" => States::Full,
            "reachable" => States::Reachable,
            other => {
                return Err(exception::<OptionsError>(
                    format!("states: `{other}` is not one of full, reachable"),
                    None,
                    None,
                ));
            }
        };
        let mut make = || self::translator(translator);
        let mut chosen = None;
        let tasks = match tasks {
            Some(tasks) => {
                if phi.is_some() || psi.is_some() || phi2.is_some() {
                    return Err(task_error(
                        "tasks (the general form) cannot be given with phi, psi or phi2",
                    ));
                }
                let believed = believed.ok_or_else(|| {
                    task_error("the adversary's belief is missing: give believed=FORMULA")
                })?;
                let mut subtasks: Vec<Subtask> = Vec::new();
                for (name, task) in tasks.iter() {
                    let name: String = name.extract()?;
                    if !is_task_name(&name) {
                        return Err(task_error(format!(
                            "`{name}` is not a sub-task name (letters, digits and `_`, not \
                             starting with a digit)"
                        )));
                    }
                    let label = format!("tasks[{name}]");
                    let task = task_of(&label, &task, &mut make, &mut chosen)?;
                    subtasks.push(Subtask { name, task });
                }
                if subtasks.len() > hypersynth::game::MAX_TASKS {
                    return Err(task_error(format!(
                        "at most {} sub-tasks are supported, got {}",
                        hypersynth::game::MAX_TASKS,
                        subtasks.len()
                    )));
                }
                let names: Vec<String> = subtasks.iter().map(|t| t.name.clone()).collect();
                let payoffs = subset_payoffs(payoffs, &names)?;
                let believed = if let Ok(text) = believed.extract::<String>()
                    && !text.trim_start().starts_with("HOA:")
                {
                    let formula = parse_formula("believed", &text)?;
                    let t = match &mut chosen {
                        Some(t) => t,
                        None => chosen.insert(make()?),
                    };
                    Believed::from_formula(formula, &subtasks, t.as_ref())
                        .map_err(|e| translate_error("believed", &text, e))?
                } else {
                    let task = task_of("believed", believed, &mut make, &mut chosen)?;
                    Believed::Automaton(Box::new(task))
                };
                Tasks::new(subtasks, payoffs, believed, self::risk(risk)?)
            }
            None => {
                if payoffs.is_some() || believed.is_some() {
                    return Err(task_error(
                        "payoffs and believed belong to the general form: give the sub-tasks \
                         with tasks={NAME: FORMULA}",
                    ));
                }
                let payoffs = Payoffs::new(r1, r2, r).map_err(|e| task_error(e.to_string()))?;
                match (phi, psi) {
                    (Some(phi), Some(psi)) if phi.extract::<String>().is_ok() => {
                        let phi_text: String = phi.extract()?;
                        let psi_text: String = psi.extract()?;
                        let phi2_text: Option<String> = phi2.map(|p| p.extract()).transpose()?;
                        let phi = parse_formula("phi", &phi_text)?;
                        let psi = parse_formula("psi", &psi_text)?;
                        let phi2 = phi2_text
                            .as_deref()
                            .map(|t| parse_formula("phi2", t))
                            .transpose()?;
                        let t = make()?;
                        let texts = |operand| match operand {
                            hypersynth::game::Operand::Phi => ("phi", phi_text.as_str()),
                            hypersynth::game::Operand::Psi => ("psi", psi_text.as_str()),
                            hypersynth::game::Operand::Phi2 => match &phi2_text {
                                Some(text) => ("phi2", text.as_str()),
                                None => ("phi", phi_text.as_str()),
                            },
                        };
                        Tasks::from_formulas(&phi, &psi, phi2.as_ref(), t.as_ref(), payoffs)
                            .map_err(|error| match error {
                                TasksError::Split(error) => {
                                    let (name, text) = texts(error.operand());
                                    let at = Position::of_offset(text, error.span().start);
                                    located_at::<TaskError>(name, text, at, &error)
                                }
                                TasksError::Translate { operand, error } => {
                                    let (name, text) = texts(operand);
                                    translate_error(name, text, error)
                                }
                            })?
                    }
                    (None, Some(psi)) => {
                        let phi2 = phi2.ok_or_else(|| {
                            task_error("phi2 is missing: without phi, give psi and phi2")
                        })?;
                        let phi1 = task_of("psi", psi, &mut make, &mut chosen)?;
                        let phi2 = task_of("phi2", phi2, &mut make, &mut chosen)?;
                        Tasks::from_parts(phi1, phi2, payoffs)
                    }
                    _ => {
                        return Err(task_error(
                            "the robot's task is missing: give phi=PHI and psi=PSI, or \
                             tasks={NAME: FORMULA} with believed=PSI",
                        ));
                    }
                }
            }
        };
        Ok(Problem {
            arena: arena.get().clone(),
            tasks,
            states,
        })
    }

    /// `"paper"` or `"general"`: how the problem is reported (the paper's preset is
    /// recognised whatever way the tasks were given).
    #[getter]
    fn form(&self) -> &'static str {
        self.tasks.presentation().form().name()
    }

    /// The sub-tasks' names, in product order (`phi1`, `phi2` in the paper's form).
    #[getter]
    fn task_names(&self) -> Vec<String> {
        self.tasks.names()
    }

    /// The sub-tasks' automata, in product order.
    #[getter]
    fn automata(&self) -> Vec<Automaton> {
        self.tasks
            .subtasks()
            .iter()
            .map(|s| Automaton {
                task: s.task.clone(),
            })
            .collect()
    }

    /// Solves the problem: the hypergame, its winning regions and the hypergame MDP, with
    /// `discount` in (0, 1], the adversary's `sigma_l` where it believes it has lost
    /// (`"uniform"`, `"random"` seeded by `seed`, or weights `{state: {action: weight}}`), and
    /// the solver's precision `epsilon`. The GIL is released meanwhile; Ctrl-C interrupts it.
    #[pyo3(signature = (
        discount = 1.0, sigma_l = None, seed = 2019, epsilon = 1e-6, max_iterations = None
    ))]
    fn solve(
        &self,
        py: Python<'_>,
        discount: f64,
        sigma_l: Option<&Bound<'_, PyAny>>,
        seed: u64,
        epsilon: f64,
        max_iterations: Option<u32>,
    ) -> PyResult<Solution> {
        let options = MdpOptions {
            sigma_l: self.sigma_l(sigma_l, seed)?,
            seed,
            solve: SolveOptions {
                discount: Discount::new(discount)
                    .map_err(|e| exception::<OptionsError>(format!("discount: {e}"), None, None))?,
                epsilon,
                max_iterations: max_iterations.unwrap_or(SolveOptions::default().max_iterations),
                ..SolveOptions::default()
            },
            learnt: None,
        };
        if !(epsilon.is_finite() && epsilon > 0.0) {
            return Err(exception::<OptionsError>(
                format!("epsilon: {epsilon} is not a finite number > 0"),
                None,
                None,
            ));
        }
        let problem = pipeline::Problem {
            arena_name: self.arena.name.clone(),
            arena: (*self.arena.arena).clone(),
            map: self.arena.map.as_deref().cloned(),
            tasks: self.tasks.clone(),
            states: self.states,
            mdp: Some(options),
        };
        let (solved, warnings) = py.detach(|| {
            let mut observer = Interruptible::default();
            let solved = stage::interruptible(|| {
                SolvedCell::try_new(problem, |problem| Solved::new(problem, &mut observer))
            });
            (solved, (observer.warnings, observer.pending))
        });
        let (warnings, pending) = warnings;
        let cell = match solved {
            Ok(Ok(cell)) => cell,
            Ok(Err(e)) => return Err(pipeline_error(e)),
            Err(stage::Interrupted) => {
                return Err(pending.unwrap_or_else(|| PyKeyboardInterrupt::new_err(())));
            }
        };
        warn(py, &warnings)?;
        Solution::new(cell)
    }

    fn __repr__(&self) -> String {
        format!(
            "<hypersynth.Problem on {:?}, {} form: {}>",
            self.arena.name,
            self.form(),
            self.tasks.names().join(", ")
        )
    }
}

impl Problem {
    fn sigma_l(&self, sigma_l: Option<&Bound<'_, PyAny>>, seed: u64) -> PyResult<SigmaL> {
        let Some(value) = sigma_l else {
            return Ok(SigmaL::Random { seed });
        };
        if let Ok(text) = value.extract::<String>() {
            return match text.as_str() {
                "uniform" => Ok(SigmaL::Uniform),
                "random" => Ok(SigmaL::Random { seed }),
                other => Err(exception::<OptionsError>(
                    format!(
                        "sigma_l: `{other}` is not one of uniform, random (or a dict of weights)"
                    ),
                    None,
                    None,
                )),
            };
        }
        // A dict {state: {action: weight}}, written as a weights file and read as one.
        let table: &Bound<'_, PyDict> = value.cast()?;
        let quote = |name: &str| format!("\"{}\"", name.replace('\\', "\\\\").replace('"', "\\\""));
        let mut text = String::new();
        for (state, weights) in table.iter() {
            let state: String = state.extract()?;
            for (action, weight) in weights.cast::<PyDict>()?.iter() {
                let action: String = action.extract()?;
                let weight: f64 = weight.extract()?;
                text += &format!("{} {} {weight:e}\n", quote(&state), quote(&action));
            }
        }
        let table = WeightTable::parse(&text)
            .and_then(|table| table.check(&self.arena.arena).map(|()| table))
            .map_err(|errors| located::<OptionsError, _>("sigma_l", &text, &errors))?;
        Ok(SigmaL::Weights {
            table,
            file: "sigma_l".to_string(),
        })
    }
}

/// Emits the library's warnings as Python `UserWarning`s.
fn warn(py: Python<'_>, warnings: &[String]) -> PyResult<()> {
    for warning in warnings {
        let message = std::ffi::CString::new(warning.as_str()).unwrap_or_default();
        PyErr::warn(
            py,
            &py.get_type::<pyo3::exceptions::PyUserWarning>(),
            &message,
            1,
        )?;
    }
    Ok(())
}

fn pipeline_error(error: PipelineError) -> PyErr {
    match error {
        PipelineError::Stage(e @ StageError::Solve(_) | e @ StageError::Evaluation(_)) => {
            exception::<SolveError>(format!("{e}; raise max_iterations or epsilon"), None, None)
        }
        PipelineError::Stage(e) => exception::<SolveError>(e.to_string(), None, None),
        PipelineError::Explain(e) => exception::<ParseError>(e.to_string(), None, None),
        PipelineError::Picture(e) => exception::<OptionsError>(e.to_string(), None, None),
        other => exception::<Error>(other.to_string(), None, None),
    }
}

/// The observer of a solve from Python: keeps the warnings, and asks Python's signal handlers
/// (at most every 20 ms) whether to stop; the handler's exception is kept to be raised.
struct Interruptible {
    warnings: Vec<String>,
    pending: Option<PyErr>,
    last: Instant,
}

impl Default for Interruptible {
    fn default() -> Self {
        Interruptible {
            warnings: Vec::new(),
            pending: None,
            last: Instant::now(),
        }
    }
}

impl Observer for Interruptible {
    fn warning(&mut self, message: &str) {
        self.warnings.push(message.to_string());
    }

    fn interrupted(&mut self) -> bool {
        if self.pending.is_some() {
            return true;
        }
        if self.last.elapsed() < Duration::from_millis(20) {
            return false;
        }
        self.last = Instant::now();
        if let Err(e) = Python::attach(|py| py.check_signals()) {
            self.pending = Some(e);
        }
        self.pending.is_some()
    }
}

// ---------------------------------------------------------------------------------------------
// Solutions

self_cell::self_cell!(
    /// A problem with its solution, which borrows it.
    struct SolvedCell {
        owner: pipeline::Problem,
        #[covariant]
        dependent: Solved,
    }
);

/// A solved problem: the value of h0, the controller's decisions, per-state values and
/// labels (NumPy arrays), reports, pictures, the DRN and the exported controller.
#[pyclass(frozen, module = "hypersynth")]
struct Solution {
    cell: SolvedCell,
    decision: hypersynth::report::InitialDecision,
}

impl Solution {
    fn new(cell: SolvedCell) -> PyResult<Solution> {
        let decision = cell.with_dependent(|_, solved| {
            let solution = solved.solution.as_ref().expect("solved with the MDP stage");
            let requests = pipeline::ReportRequests::default();
            solution
                .synthesis(&solved.game(), &requests, None, &mut ())
                .decision
        });
        Ok(Solution { cell, decision })
    }

    fn solved(&self) -> &Solved<'_> {
        self.cell.borrow_dependent()
    }

    fn opportunistic(&self) -> &pipeline::OpportunisticSolution {
        self.solved()
            .solution
            .as_ref()
            .expect("solved with the MDP stage")
    }

    fn outcome(&self, requests: &Requests) -> PyResult<pipeline::Outcome> {
        self.solved()
            .outcome(requests, &mut ())
            .map_err(pipeline_error)
    }

    fn state(&self, name: &str) -> PyResult<hypersynth::game::HState> {
        let product = &self.solved().product;
        if name == "h0" {
            return Ok(product.initial());
        }
        product.parse_state(name).map_err(|e| {
            let shown = e.to_string();
            let position = match &e {
                hypersynth::game::StateNameError::Malformed(p, _)
                | hypersynth::game::StateNameError::UnknownArenaState(p, _)
                | hypersynth::game::StateNameError::Unreachable(p, _)
                | hypersynth::game::StateNameError::NoSuchDfaState { position: p, .. }
                | hypersynth::game::StateNameError::NotEnumerated { position: p, .. } => *p,
            };
            let message = shown
                .strip_prefix(&format!("{position}: "))
                .unwrap_or(&shown)
                .to_string();
            located_at::<ParseError>("state", name, position, &message)
        })
    }

    /// Per product state, `f` of it, as a NumPy array (one buffer, no Python object per state).
    fn array<'py, T: numpy::Element>(
        &self,
        py: Python<'py>,
        f: impl Fn(hypersynth::game::HState) -> T,
    ) -> Bound<'py, PyArray1<T>> {
        let values: Vec<T> = self.solved().product.states().map(f).collect();
        PyArray1::from_vec(py, values)
    }
}

#[pymethods]
impl Solution {
    /// The certified lower bound of the value of h0.
    #[getter]
    fn value(&self) -> f64 {
        self.decision.value
    }

    /// The certified upper bound of the value of h0.
    #[getter]
    fn value_upper(&self) -> f64 {
        self.decision.value_upper
    }

    /// What the controller itself collects from h0 (lower bound), evaluated as Markov chains.
    #[getter]
    fn policy_value(&self) -> f64 {
        self.decision.policy_value
    }

    /// The controller's expected number of robot moves from h0 before it commits.
    #[getter]
    fn expected_moves(&self) -> f64 {
        self.decision.expected_moves
    }

    /// The controller's action at h0 (None when the adversary moves first or nothing can be
    /// gained).
    #[getter]
    fn action(&self) -> Option<String> {
        self.decision.action.clone()
    }

    /// The set of sub-tasks the controller commits to at h0, if it does.
    #[getter]
    fn commits_to(&self) -> Option<Vec<String>> {
        self.decision.commits_to.clone()
    }

    /// The product state h0's name.
    #[getter]
    fn initial_state(&self) -> String {
        self.solved()
            .game()
            .state_name(self.solved().product.initial())
    }

    /// The number of product states (the length of the arrays).
    fn __len__(&self) -> usize {
        self.solved().product.num_states()
    }

    /// The name of product state `index` (`ARENA_STATE|Q1|Q2`).
    fn state_name(&self, index: usize) -> PyResult<String> {
        let product = &self.solved().product;
        if index >= product.num_states() {
            return Err(pyo3::exceptions::PyIndexError::new_err(format!(
                "product state {index} out of range (0..{})",
                product.num_states()
            )));
        }
        Ok(self
            .solved()
            .game()
            .state_name(hypersynth::game::HState::new(index)))
    }

    /// The index of product state `name` (or `"h0"`) in the arrays.
    fn state_index(&self, name: &str) -> PyResult<usize> {
        Ok(self.state(name)?.index())
    }

    /// Per product state, the certified lower bound of its value.
    #[getter]
    fn values<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let (solution, mdp) = (&self.opportunistic().solution, &self.opportunistic().mdp);
        self.array(py, |h| solution.value(mdp.node(h)).lower)
    }

    /// Per product state, the certified upper bound of its value.
    #[getter]
    fn values_upper<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let (solution, mdp) = (&self.opportunistic().solution, &self.opportunistic().mdp);
        self.array(py, |h| solution.value(mdp.node(h)).upper)
    }

    /// Per product state, whether the robot moves there.
    #[getter]
    fn is_robot<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<bool>> {
        let game = self.solved().game();
        self.array(py, |h| game.is_robot(h))
    }

    /// Per product state, its arena state's index (`Arena.names` order).
    #[getter]
    fn arena_states<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u32>> {
        let game = self.solved().game();
        self.array(py, |h| game.arena_state(h).index() as u32)
    }

    /// Per product state, the set of sub-tasks it settles for, as a bit mask (bit i: sub-task
    /// i of `task_names`): the win-label's numeric form.
    #[getter]
    fn best<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u8>> {
        let game = self.solved().game();
        self.array(py, |h| game.best(h).0)
    }

    /// Per product state, the payoff the robot can force from it (its guarantee).
    #[getter]
    fn guarantees<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let game = self.solved().game();
        self.array(py, |h| game.guarantee(h))
    }

    /// The sub-tasks' names, in product order (the bits of `best`).
    #[getter]
    fn task_names(&self) -> Vec<String> {
        self.solved().problem.tasks.names()
    }

    /// Per product state, how reports label it (its win-label `(W, L, L)` in the paper's
    /// form), as strings.
    #[getter]
    fn labels(&self) -> Vec<String> {
        let game = self.solved().game();
        self.solved()
            .product
            .states()
            .map(|h| game.label(h))
            .collect()
    }

    /// The certified value interval `(lower, upper)` of product state `state` (`"h0"` or
    /// `ARENA_STATE|Q1|Q2`).
    #[pyo3(signature = (state = "h0"))]
    fn state_value(&self, state: &str) -> PyResult<(f64, f64)> {
        let h = self.state(state)?;
        let solution = self.opportunistic();
        let value = solution.solution.value(solution.mdp.node(h));
        Ok((value.lower, value.upper))
    }

    /// How reports label product state `state`: its win-label `(W, L, L)` in the paper's form.
    #[pyo3(signature = (state = "h0"))]
    fn label(&self, state: &str) -> PyResult<String> {
        let h = self.state(state)?;
        Ok(self.solved().game().label(h))
    }

    /// The decision table of `state` (the paper's Table II), as the JSON report gives it.
    #[pyo3(signature = (state = "h0"))]
    fn decision_table<'py>(&self, py: Python<'py>, state: &str) -> PyResult<Bound<'py, PyAny>> {
        let h = self.state(state)?;
        let solved = self.solved();
        let game = solved.game();
        let solution = self.opportunistic();
        let explanation = solution.controller(&game).explain(h, &solution.evaluation);
        let text = serde_json::to_string(&explanation)
            .map_err(|e| exception::<Error>(e.to_string(), None, None))?;
        json_loads(py, &text)
    }

    /// Simulates `n` runs of the controller against the adversary model (seed: the solve's by
    /// default); outcome counts and the mean payoff with its 95% confidence interval.
    #[pyo3(signature = (n, seed = None, max_steps = 1000))]
    fn simulate<'py>(
        &self,
        py: Python<'py>,
        n: u32,
        seed: Option<u64>,
        max_steps: u32,
    ) -> PyResult<Bound<'py, PyDict>> {
        let solution = self.opportunistic();
        let options = SimulationOptions {
            runs: n,
            seed: seed.unwrap_or(solution.options.seed),
            max_steps,
        };
        let simulation = py.detach(|| {
            let game = self.solved().game();
            simulate(&solution.controller(&game), &solution.adversary, options)
        });
        let dict = PyDict::new(py);
        dict.set_item("runs", n)?;
        let satisfied = PyDict::new(py);
        let game = self.solved().game();
        for (mask, count) in simulation.satisfied.iter().enumerate().skip(1) {
            if *count > 0 {
                satisfied.set_item(game.set_name(TaskSet(mask as u8)), count)?;
            }
        }
        dict.set_item("satisfied", satisfied)?;
        dict.set_item("adversary_stuck", simulation.adversary_stuck)?;
        dict.set_item("none", simulation.none)?;
        dict.set_item("step_bound", simulation.step_bound)?;
        dict.set_item("mean_payoff", simulation.mean_payoff)?;
        dict.set_item("ci_low", simulation.ci_low)?;
        dict.set_item("ci_high", simulation.ci_high)?;
        Ok(dict)
    }

    /// One run of the controller (seed: the solve's by default): how it ended, its payoff and
    /// its steps (state, label, action, committed set).
    #[pyo3(signature = (seed = None, max_steps = 1000))]
    fn trace<'py>(
        &self,
        py: Python<'py>,
        seed: Option<u64>,
        max_steps: u32,
    ) -> PyResult<Bound<'py, PyDict>> {
        let solution = self.opportunistic();
        let game = self.solved().game();
        let run = trace(
            &solution.controller(&game),
            &solution.adversary,
            seed.unwrap_or(solution.options.seed),
            max_steps,
        );
        let report = solution.trace_report(&game, &run);
        let dict = PyDict::new(py);
        let ending = match report.ending {
            Ending::Satisfied(set) => format!("satisfied {}", game.set_name(set)),
            Ending::AdversaryStuck => "adversary stuck".to_string(),
            Ending::None => "none".to_string(),
            Ending::StepBound => "step bound".to_string(),
        };
        dict.set_item("ending", ending)?;
        dict.set_item("payoff", report.payoff)?;
        let steps = PyList::empty(py);
        for step in report.steps {
            let row = PyDict::new(py);
            row.set_item("state", step.state)?;
            row.set_item("label", step.label)?;
            row.set_item("action", step.action)?;
            row.set_item("committed", step.committed)?;
            steps.append(row)?;
        }
        dict.set_item("steps", steps)?;
        Ok(dict)
    }

    /// The command line's report (`format="text"` or `"json"`), with the decision table of
    /// `explain` (a state name or `"h0"`), `simulate` runs and a `trace` if asked.
    #[pyo3(signature = (format = "text", explain = None, simulate = None, trace = false, max_steps = 1000))]
    fn report(
        &self,
        format: &str,
        explain: Option<String>,
        simulate: Option<u32>,
        trace: bool,
        max_steps: u32,
    ) -> PyResult<String> {
        let requests = Requests {
            explain,
            simulate,
            trace,
            max_steps,
            ..Requests::default()
        };
        let outcome = self.outcome(&requests)?;
        match format {
            "text" => Ok(outcome.report.to_string()),
            "json" => outcome
                .report
                .to_json(None)
                .map_err(|e| exception::<Error>(e.to_string(), None, None)),
            other => Err(exception::<OptionsError>(
                format!("format: `{other}` is not one of text, json"),
                None,
                None,
            )),
        }
    }

    /// The hypergame MDP in Storm's DRN format (only the controller's choices with `induced`),
    /// in `form` `"reward"` (`R{"r"}max=? [C]` is the value) or `"reachability"` (`r_max *
    /// Pmax=? [F "goal"]` is).
    #[pyo3(signature = (induced = false, form = "reward"))]
    fn to_drn(&self, induced: bool, form: &str) -> PyResult<String> {
        let form = match form {
            "reward" => DrnForm::Reward,
            "reachability" => DrnForm::Reachability,
            other => {
                return Err(exception::<OptionsError>(
                    format!("form: `{other}` is not one of reward, reachability"),
                    None,
                    None,
                ));
            }
        };
        Ok(self
            .opportunistic()
            .drn(&self.solved().game(), induced, form))
    }

    /// A picture of a map-based problem as SVG: `"map"`, `"partition"`, `"value"` or
    /// `"trace"`; `title` replaces the default title (`""`: none).
    #[pyo3(signature = (picture = "partition", title = None))]
    fn svg(&self, picture: &str, title: Option<String>) -> PyResult<String> {
        let picture = match picture {
            "map" => Picture::Map,
            "partition" => Picture::Partition,
            "value" => Picture::Value,
            "trace" => Picture::Trace,
            other => {
                return Err(exception::<OptionsError>(
                    format!("picture: `{other}` is not one of map, partition, value, trace"),
                    None,
                    None,
                ));
            }
        };
        let title = match title {
            None => TitleChoice::Default,
            Some(text) if text.is_empty() => TitleChoice::None,
            Some(text) => TitleChoice::Text(text),
        };
        let requests = Requests {
            picture: Some(PictureRequest {
                picture,
                adversary_at: None,
                automata: None,
                title,
            }),
            max_steps: 1000,
            ..Requests::default()
        };
        Ok(self.outcome(&requests)?.svg.unwrap_or_default())
    }

    /// The partition picture, for Jupyter (None when the arena is not a map).
    fn _repr_svg_(&self) -> Option<String> {
        self.cell.borrow_owner().map.as_ref()?;
        self.svg("partition", None).ok()
    }

    /// The controller exported as JSON (format `hypersynth-controller/1`), as
    /// `--export-controller` writes it.
    fn controller_json(&self) -> PyResult<String> {
        let requests = Requests {
            export_controller: true,
            ..Requests::default()
        };
        Ok(self.outcome(&requests)?.controller.unwrap_or_default())
    }

    /// The exported controller, ready to run step by step.
    fn controller(&self) -> PyResult<Controller> {
        Controller::from_json(&self.controller_json()?)
    }

    /// The games report's section as the JSON report gives it (the paper's or the general
    /// form's).
    fn games_json(&self) -> PyResult<String> {
        let outcome = self.outcome(&Requests::default())?;
        let report = hypersynth::report::Report {
            synthesis: None,
            ..outcome.report
        };
        report
            .to_json(None)
            .map_err(|e| exception::<Error>(e.to_string(), None, None))
    }

    fn __repr__(&self) -> String {
        let form = self.cell.borrow_owner().tasks.presentation().form().name();
        format!(
            "<hypersynth.Solution ({form} form): value of h0 in [{}, {}], {} product states>",
            self.decision.value,
            self.decision.value_upper,
            self.solved().product.num_states()
        )
    }
}

fn json_loads<'py>(py: Python<'py>, text: &str) -> PyResult<Bound<'py, PyAny>> {
    py.import("json")?.call_method1("loads", (text,))
}

// ---------------------------------------------------------------------------------------------
// The exported controller

/// An exported controller run step by step: give it each arena state the play reaches
/// (`step`), and it answers the robot's action at robot states.
#[pyclass(module = "hypersynth")]
struct Controller {
    executor: Executor,
    off_model: Option<String>,
}

#[pymethods]
impl Controller {
    /// Reads an exported controller (the JSON of `--export-controller`).
    #[staticmethod]
    fn from_json(text: &str) -> PyResult<Controller> {
        let executor = Executor::from_json(text)
            .map_err(|e| exception::<ControllerError>(e.to_string(), None, None))?;
        Ok(Controller {
            executor,
            off_model: None,
        })
    }

    /// Observes the arena state `state` the play reached: at a robot state, the answer as
    /// `hypersynth execute` prints it (`ACTION`, `commit SET ACTION`, `stop SET ACTION`,
    /// `done`, `give up`); None at the adversary's.
    fn step(&mut self, state: &str) -> PyResult<Option<String>> {
        let turn = self
            .executor
            .observe(state)
            .map_err(|e| exception::<ControllerError>(e.to_string(), None, None))?;
        self.off_model = turn.off_model.map(|o| o.to_string());
        Ok(turn.answer.map(|a| self.executor.answer_line(&a)))
    }

    /// Starts a new play.
    fn reset(&mut self) {
        self.executor.reset();
        self.off_model = None;
    }

    /// The set committed to, if any.
    #[getter]
    fn committed(&self) -> Option<String> {
        self.executor.committed().map(|s| self.executor.set_name(s))
    }

    /// Whether the committed set holds.
    #[getter]
    fn is_done(&self) -> bool {
        self.executor.is_done()
    }

    /// The automata's states after the last step.
    #[getter]
    fn automata(&self) -> Vec<u32> {
        self.executor.automata().to_vec()
    }

    /// The message of the last step's off-model move, if it was one.
    #[getter]
    fn off_model(&self) -> Option<String> {
        self.off_model.clone()
    }
}

// ---------------------------------------------------------------------------------------------

#[pymodule]
fn _hypersynth(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add_class::<Arena>()?;
    m.add_class::<ArenaBuilder>()?;
    m.add_class::<Automaton>()?;
    m.add_class::<Problem>()?;
    m.add_class::<Solution>()?;
    m.add_class::<Controller>()?;
    m.add_function(wrap_pyfunction!(translate_formula, m)?)?;
    m.add("Error", py.get_type::<Error>())?;
    m.add("ParseError", py.get_type::<ParseError>())?;
    m.add("ArenaError", py.get_type::<ArenaError>())?;
    m.add("TranslationError", py.get_type::<TranslationError>())?;
    m.add("TaskError", py.get_type::<TaskError>())?;
    m.add("OptionsError", py.get_type::<OptionsError>())?;
    m.add("SolveError", py.get_type::<SolveError>())?;
    m.add("ControllerError", py.get_type::<ControllerError>())?;
    Ok(())
}

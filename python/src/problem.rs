//! Problems: the Python arguments mapped onto the library's problem specification
//! (`hypersynth::pipeline::spec`), whose rules check them; the errors name the arguments.

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyString, PyTuple};

use hypersynth::game::Engine;
use hypersynth::game::States;
use hypersynth::mdp::solve::SolveOptions;
use hypersynth::opportunistic::adversary::{SigmaL, WeightTable};
use hypersynth::opportunistic::build::Risk;
use hypersynth::opportunistic::observations::DEFAULT_DELTA;
use hypersynth::pipeline::spec::{
    Field, GeneralSpec, LearntSpec, MdpSpec, NamedTask, PaperPayoffs, PayoffPart, Precision,
    SetPayoff, SigmaLSpec, SpecError, SpecErrorKind, TaskSource, TasksSpec,
};
use hypersynth::pipeline::{self, RunError, Tasks};

use crate::arena::Arena;
use crate::automaton::{Automaton, Origin, translation};
use crate::controller::Controller;
use crate::errors::{Error, OptionsError, SolveError, TaskError, exception, file_error, in_field};
use crate::solution::{ImplicitInputs, Solution, interruptibly, pipeline_error};

/// A problem: an arena and the robot's tasks, in the paper's form
/// (`Problem(arena, phi=..., psi=...)`) or the general one
/// (`Problem(arena, tasks={...}, payoffs={...}, believed=..., risk=...)`). Solve it with
/// `solve`. A problem pickles as the arguments it was made of (the arena as its text), so it
/// can be solved in another process or on another machine.
///
/// >>> arena = hs.Arena.from_file("specs/case-study/arena.txt")
/// >>> problem = hs.Problem(arena, phi="(!O U A) & (!O U B)", psi="!O U A")
/// >>> problem.form, problem.task_names
/// ('paper', ['phi1', 'phi2'])
#[pyclass(frozen, module = "hypersynth")]
pub(crate) struct Problem {
    pub(crate) arena: Arena,
    tasks: Tasks,
    states: States,
    /// The arguments it was made with, positional and by name (to pickle it).
    args: Py<PyTuple>,
    kwargs: Py<PyDict>,
}

/// An option given by name (`states`, `risk`...): one of `choices`, as values.
fn choice<T: Copy>(option: &str, given: &str, choices: &[(&str, T)]) -> PyResult<T> {
    match choices.iter().find(|(name, _)| *name == given) {
        Some((_, value)) => Ok(*value),
        None => {
            let names: Vec<&str> = choices.iter().map(|(name, _)| *name).collect();
            Err(exception::<OptionsError>(
                format!("{option}: `{given}` is not one of {}", names.join(", ")),
                None,
                None,
            ))
        }
    }
}

fn task_error(message: impl Into<String>) -> PyErr {
    exception::<TaskError>(message, None, None)
}

/// A task given from Python: an `Automaton`, a HOA text (named `name` in reports), or a
/// formula's text.
fn task_source(name: &str, value: &Bound<'_, PyAny>) -> PyResult<TaskSource> {
    if let Ok(automaton) = value.cast::<Automaton>() {
        return Ok(TaskSource::Automaton(automaton.get().task.clone()));
    }
    let text: String = value.extract()?;
    Ok(match text.trim_start().starts_with("HOA:") {
        true => TaskSource::Hoa {
            name: name.to_string(),
            text,
        },
        false => TaskSource::Formula(text),
    })
}

/// The payoffs of the general form: `{name or names: value}`, keys a sub-task's name, a tuple
/// or set of names, or names joined by `,`.
fn set_payoffs(payoffs: Option<&Bound<'_, PyDict>>) -> PyResult<Vec<SetPayoff>> {
    let mut out = Vec::new();
    for (key, value) in payoffs.into_iter().flat_map(|d| d.iter()) {
        let set: Vec<String> = match key.extract::<String>() {
            Ok(text) => text.split(',').map(|s| s.trim().to_string()).collect(),
            Err(_) => key
                .try_iter()?
                .map(|m| m?.extract())
                .collect::<PyResult<_>>()?,
        };
        out.push(SetPayoff {
            set,
            value: value.extract()?,
        });
    }
    Ok(out)
}

/// The tasks' arguments of `Problem(...)` as the library's specification: the general form
/// with `tasks`, else the paper's.
#[allow(clippy::too_many_arguments)]
fn tasks_spec(
    phi: Option<&Bound<'_, PyAny>>,
    psi: Option<&Bound<'_, PyAny>>,
    phi2: Option<&Bound<'_, PyAny>>,
    tasks: Option<&Bound<'_, PyDict>>,
    payoffs: Option<&Bound<'_, PyDict>>,
    believed: Option<&Bound<'_, PyAny>>,
    risk: Risk,
    paper: PaperPayoffs,
) -> PyResult<TasksSpec> {
    if let Some(tasks) = tasks {
        if phi.is_some() || psi.is_some() || phi2.is_some() {
            return Err(task_error(
                "tasks (the general form) cannot be given with phi, psi or phi2",
            ));
        }
        let believed = believed.ok_or_else(|| {
            task_error("the adversary's belief is missing: give believed=FORMULA")
        })?;
        let tasks = tasks
            .iter()
            .map(|(name, task)| {
                let name: String = name.extract()?;
                let task = task_source(&format!("tasks[{name}]"), &task)?;
                Ok(NamedTask { name, task })
            })
            .collect::<PyResult<_>>()?;
        return Ok(TasksSpec::General(GeneralSpec {
            tasks,
            payoffs: set_payoffs(payoffs)?,
            believed: task_source("believed", believed)?,
            risk,
        }));
    }
    if payoffs.is_some() || believed.is_some() {
        return Err(task_error(
            "payoffs and believed belong to the general form: give the sub-tasks with \
             tasks={NAME: FORMULA}",
        ));
    }
    match (phi, psi) {
        (Some(phi), Some(psi)) if phi.extract::<String>().is_ok() => Ok(TasksSpec::Paper {
            phi: phi.extract()?,
            psi: psi.extract()?,
            phi2: phi2.map(|p| p.extract()).transpose()?,
            payoffs: paper,
        }),
        (None, Some(psi)) => {
            let phi2 =
                phi2.ok_or_else(|| task_error("phi2 is missing: without phi, give psi and phi2"))?;
            Ok(TasksSpec::PaperParts {
                phi1: task_source("psi", psi)?,
                phi2: task_source("phi2", phi2)?,
                payoffs: paper,
            })
        }
        _ => Err(task_error(
            "the robot's task is missing: give phi=PHI and psi=PSI, or tasks={NAME: FORMULA} \
             with believed=PSI",
        )),
    }
}

/// An error of the tasks of `spec` naming the Python argument it comes from (`phi`,
/// `tasks[A]`, `payoffs`...), located in its text when it has a place there.
fn tasks_error(spec: &TasksSpec, error: SpecError) -> PyErr {
    let (field, position, kind) = error.into_parts();
    let source = |name: &str, task: &TaskSource| match task {
        // A HOA text is named as the task is in reports.
        TaskSource::Hoa { name, text } => (name.clone(), Some(text.clone())),
        other => (name.to_string(), other.text().map(str::to_string)),
    };
    let (name, text) = match (&field, spec) {
        (Field::Phi, TasksSpec::Paper { phi, .. }) => ("phi".to_string(), Some(phi.clone())),
        (Field::Psi, TasksSpec::Paper { psi, .. }) => ("psi".to_string(), Some(psi.clone())),
        (Field::Phi2, TasksSpec::Paper { phi2, .. }) => ("phi2".to_string(), phi2.clone()),
        (Field::Psi, TasksSpec::PaperParts { phi1, .. }) => source("psi", phi1),
        (Field::Phi2, TasksSpec::PaperParts { phi2, .. }) => source("phi2", phi2),
        (Field::Task { index, name }, TasksSpec::General(general)) => {
            source(&format!("tasks[{name}]"), &general.tasks[*index].task)
        }
        (Field::Believed, TasksSpec::General(general)) => source("believed", &general.believed),
        (Field::Payoff { part, .. }, _) => match (part, &kind) {
            (PayoffPart::Member(_), SpecErrorKind::UnknownTask(_)) => {
                return task_error(format!("payoffs: {kind} (give it in tasks)"));
            }
            (PayoffPart::Set, SpecErrorKind::EmptySet) => {
                return task_error("payoffs: a key names no sub-task");
            }
            _ => ("payoffs".to_string(), None),
        },
        (field, _) => (field.to_string(), None),
    };
    in_field(&name, text.as_deref(), position, kind)
}

#[pymethods]
impl Problem {
    /// The problem of `arena` and the robot's tasks (see the class); every argument is checked
    /// by the library's rules, and the tasks are translated now.
    ///
    /// >>> arena = hs.Arena.from_file("specs/decoy/arena.txt")
    /// >>> problem = hs.Problem(arena, tasks={"A": "!O U A", "B": "!O U B", "C": "F C"},
    /// ...                      payoffs={"A": 200, "B": 100, "C": 50}, believed="F C")
    /// >>> problem.form
    /// 'general'
    #[new]
    #[pyo3(signature = (
        arena, phi = None, psi = None, phi2 = None, *, tasks = None, payoffs = None,
        believed = None, risk = "paper", r1 = 200.0, r2 = 100.0, r = 300.0,
        translator = "auto", states = "full"
    ))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
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
        let args = PyTuple::new(py, [Some(arena.as_any()), phi, psi, phi2])?;
        let kwargs = PyDict::new(py);
        kwargs.set_item("tasks", tasks)?;
        kwargs.set_item("payoffs", payoffs)?;
        kwargs.set_item("believed", believed)?;
        kwargs.set_item("risk", risk)?;
        kwargs.set_item("r1", r1)?;
        kwargs.set_item("r2", r2)?;
        kwargs.set_item("r", r)?;
        kwargs.set_item("translator", translator)?;
        kwargs.set_item("states", states)?;
        let states = choice(
            "states",
            states,
            &[("full", States::Full), ("reachable", States::Reachable)],
        )?;
        let risk = choice(
            "risk",
            risk,
            &[
                ("paper", Risk::Paper),
                ("strict", Risk::Strict),
                ("neutral", Risk::Neutral),
            ],
        )?;
        let paper = PaperPayoffs { r1, r2, r };
        let spec = tasks_spec(phi, psi, phi2, tasks, payoffs, believed, risk, paper)?;
        let translation = translation(translator)?;
        // A problem from Python is always solved with the MDP stage: its payoffs are checked.
        let tasks = spec
            .build(&translation, true)
            .map_err(|error| tasks_error(&spec, error))?;
        Ok(Problem {
            arena: arena.get().clone(),
            tasks,
            states,
            args: args.unbind(),
            kwargs: kwargs.unbind(),
        })
    }

    /// `"paper"` or `"general"`: how the problem is reported (the paper's preset is
    /// recognised whatever way the tasks were given).
    ///
    /// >>> problem.form
    /// 'paper'
    #[getter]
    fn form(&self) -> &'static str {
        self.tasks.presentation().form().name()
    }

    /// The arena.
    ///
    /// >>> problem.arena.name
    /// 'specs/case-study/arena.txt'
    #[getter(arena)]
    fn arena_of(slf: &Bound<'_, Self>) -> PyResult<Py<PyAny>> {
        Ok(slf.get().args.bind(slf.py()).get_item(0)?.unbind())
    }

    /// The sub-tasks' names, in product order (`phi1`, `phi2` in the paper's form).
    ///
    /// >>> problem.task_names
    /// ['phi1', 'phi2']
    #[getter]
    fn task_names(&self) -> Vec<String> {
        self.tasks.names()
    }

    /// The sub-tasks' automata, in product order.
    ///
    /// >>> [a.num_states for a in problem.automata]
    /// [3, 3]
    #[getter]
    fn automata(&self) -> Vec<Automaton> {
        self.tasks
            .subtasks()
            .iter()
            .map(|s| Automaton {
                task: s.task.clone(),
                origin: Origin::Task,
            })
            .collect()
    }

    /// Solves the problem: the hypergame, its winning regions and the hypergame MDP, with
    /// `discount` in (0, 1], the adversary's `sigma_l` where it believes it has lost
    /// (`"uniform"`, `"random"` seeded by `seed`, weights `{state: {action: weight}}`, or a
    /// weights file's `pathlib.Path`, as `--adversary FILE`), and
    /// the solver's precision `epsilon`. With `observations` (an observations file's path, or
    /// its runs as a list of lines), sigma_L is also learnt from them with confidence
    /// `1 - delta` (default 0.05, as `--delta`), and the solution adds the robust stage (`Solution.robust`); `sigma_l` is
    /// then the model simulations run against, as on the command line. `engine` is
    /// `"explicit"` (it stores the product) or `"implicit"` (it computes the product's states
    /// and edges from the arena's rules, docs/engines.md): either solution answers the same
    /// questions, from one solve, with the same states index for index (but `Dynamics`, which
    /// needs the explicit engine's). The GIL is released meanwhile; Ctrl-C interrupts it.
    ///
    /// >>> solution = problem.solve(discount=0.99, sigma_l="uniform")
    /// >>> round(solution.value, 2), solution.action
    /// (294.02, 'N')
    /// >>> implicit = problem.solve(discount=0.99, sigma_l="uniform", engine="implicit")
    /// >>> implicit.action, abs(implicit.value - solution.value) < 1e-6
    /// ('N', True)
    #[pyo3(signature = (
        discount = 1.0, sigma_l = None, seed = 2019, epsilon = 1e-6, max_iterations = None,
        observations = None, delta = None, engine = "explicit"
    ))]
    #[allow(clippy::too_many_arguments)]
    fn solve(
        slf: &Bound<'_, Self>,
        py: Python<'_>,
        discount: f64,
        sigma_l: Option<&Bound<'_, PyAny>>,
        seed: u64,
        epsilon: f64,
        max_iterations: Option<u32>,
        observations: Option<&Bound<'_, PyAny>>,
        delta: Option<f64>,
        engine: &str,
    ) -> PyResult<Solution> {
        let this = slf.get();
        let engine = engine_of(engine)?;
        let learnt = learnt_of(py, observations, delta)?;
        let spec = mdp_spec(py, discount, sigma_l, seed, epsilon, max_iterations, learnt)?;
        let given = PyTuple::new(
            py,
            [
                slf.as_any().clone(),
                discount.into_pyobject(py)?.into_any(),
                sigma_l.map_or_else(|| py.None().into_bound(py), |s| s.clone()),
                seed.into_pyobject(py)?.into_any(),
                epsilon.into_pyobject(py)?.into_any(),
                max_iterations.into_pyobject(py)?.into_any(),
                observations.map_or_else(|| py.None().into_bound(py), |o| o.clone()),
                delta.into_pyobject(py)?.into_any(),
                engine.name().into_pyobject(py)?.into_any(),
            ],
        )?;
        if engine == Engine::Implicit {
            let arena = &this.arena;
            let inputs = ImplicitInputs {
                name: arena.name.clone(),
                arena: arena.arena.clone(),
                map: arena.map.clone(),
                tasks: this.tasks.clone(),
                states: this.states,
                spec,
            };
            return Solution::solve_implicit(py, inputs, given.unbind());
        }
        let options = spec
            .build(&this.arena.arena)
            .map_err(|error| spec_error(&spec, error))?;
        let problem = pipeline::Problem {
            arena_name: this.arena.name.clone(),
            arena: (*this.arena.arena).clone(),
            map: this.arena.map.as_deref().cloned(),
            tasks: this.tasks.clone(),
            states: this.states,
            mdp: Some(options),
        };
        Solution::solve(py, problem, given.unbind())
    }

    /// The command line's report of the problem (`format="text"` or `"json"`) made by
    /// `engine`: `"implicit"`, which computes the product's states and edges from the arena's
    /// rules and never stores the product (docs/engines.md; it numbers every product state),
    /// or `"explicit"`, the report of `solve(...)`. The MDP stage takes `solve`'s
    /// options (sigma_L a weight table too); `games_only` leaves it out. With the MDP stage,
    /// the decision table of `explain` (a state name or `"h0"`), `simulate` runs of at most
    /// `max_steps` robot moves and a `trace` if asked, as `Solution.report` adds them. The
    /// report names its engine (the `product` line, JSON `"engine"`). The GIL is released
    /// meanwhile; Ctrl-C interrupts it.
    ///
    /// >>> import json
    /// >>> report = json.loads(problem.report(format="json", discount=0.99, sigma_l="uniform"))
    /// >>> report["engine"], report["initial"]["action"]
    /// ('implicit', 'N')
    #[pyo3(signature = (
        format = "text", engine = "implicit", games_only = false, discount = 1.0,
        sigma_l = None, seed = 2019, epsilon = 1e-6, max_iterations = None, explain = None,
        simulate = None, trace = false, max_steps = 1000, observations = None, delta = None
    ))]
    #[allow(clippy::too_many_arguments)]
    fn report(
        &self,
        py: Python<'_>,
        format: &str,
        engine: &str,
        games_only: bool,
        discount: f64,
        sigma_l: Option<&Bound<'_, PyAny>>,
        seed: u64,
        epsilon: f64,
        max_iterations: Option<u32>,
        explain: Option<String>,
        simulate: Option<u32>,
        trace: bool,
        max_steps: u32,
        observations: Option<&Bound<'_, PyAny>>,
        delta: Option<f64>,
    ) -> PyResult<String> {
        if !matches!(format, "text" | "json") {
            let message = format!("format: `{format}` is not one of text, json");
            return Err(exception::<OptionsError>(message, None, None));
        }
        let learnt = learnt_of(py, observations, delta)?;
        let spec = mdp_spec(py, discount, sigma_l, seed, epsilon, max_iterations, learnt)?;
        let requests = pipeline::Requests {
            explain,
            simulate,
            trace,
            max_steps,
            ..pipeline::Requests::default()
        };
        let mdp = (!games_only).then_some(&spec);
        let report = self.outcome(py, engine, (&spec, mdp), &requests)?.report;
        match format {
            "json" => report
                .to_json(None)
                .map_err(|e| exception::<Error>(e.to_string(), None, None)),
            _ => Ok(report.to_string()),
        }
    }

    /// The controller `engine` (`"implicit"` or `"explicit"`, as `report`) synthesises with
    /// `solve`'s options, exported as JSON (`hypersynth-controller/2`) as `--export-controller`
    /// writes it; with `certificate`, with the certificate of its bounds that `hypersynth.check`
    /// checks. The implicit engine's file is the explicit one's but where two choices tie
    /// within the precision (docs/engines.md); it makes the controller of a model too large to
    /// store. The GIL is released meanwhile; Ctrl-C interrupts it.
    ///
    /// >>> import json
    /// >>> json.loads(problem.controller_json(discount=0.99, sigma_l="uniform"))["format"]
    /// 'hypersynth-controller/2'
    #[pyo3(signature = (
        engine = "implicit", certificate = false, discount = 1.0, sigma_l = None, seed = 2019,
        epsilon = 1e-6, max_iterations = None, observations = None, delta = None
    ))]
    #[allow(clippy::too_many_arguments)]
    fn controller_json(
        &self,
        py: Python<'_>,
        engine: &str,
        certificate: bool,
        discount: f64,
        sigma_l: Option<&Bound<'_, PyAny>>,
        seed: u64,
        epsilon: f64,
        max_iterations: Option<u32>,
        observations: Option<&Bound<'_, PyAny>>,
        delta: Option<f64>,
    ) -> PyResult<String> {
        let learnt = learnt_of(py, observations, delta)?;
        let spec = mdp_spec(py, discount, sigma_l, seed, epsilon, max_iterations, learnt)?;
        let requests = pipeline::Requests {
            export_controller: true,
            certificate,
            ..pipeline::Requests::default()
        };
        let outcome = self.outcome(py, engine, (&spec, Some(&spec)), &requests)?;
        Ok(outcome.controller.unwrap_or_default())
    }

    /// The controller of `controller_json` (without a certificate), ready to run step by
    /// step, as `Solution.controller` gives the explicit engine's.
    ///
    /// >>> problem.controller(discount=0.99, sigma_l="uniform").step("((0,2),(4,2),0)")
    /// Answer('move', action='N')
    #[pyo3(signature = (
        engine = "implicit", discount = 1.0, sigma_l = None, seed = 2019, epsilon = 1e-6,
        max_iterations = None, observations = None, delta = None
    ))]
    #[allow(clippy::too_many_arguments)]
    fn controller(
        &self,
        py: Python<'_>,
        engine: &str,
        discount: f64,
        sigma_l: Option<&Bound<'_, PyAny>>,
        seed: u64,
        epsilon: f64,
        max_iterations: Option<u32>,
        observations: Option<&Bound<'_, PyAny>>,
        delta: Option<f64>,
    ) -> PyResult<Controller> {
        let text = self.controller_json(
            py,
            engine,
            false,
            discount,
            sigma_l,
            seed,
            epsilon,
            max_iterations,
            observations,
            delta,
        )?;
        Controller::from_json(&text)
    }

    /// Pickles as the arguments it was made with.
    ///
    /// >>> import pickle
    /// >>> again = pickle.loads(pickle.dumps(problem))
    /// >>> again.solve(discount=0.99, sigma_l="uniform").value == solution.value
    /// True
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let py = slf.py();
        let this = slf.get();
        // `Problem(*args, **kwargs)`, through functools.partial (pickle passes no keywords).
        let partial = py
            .import("functools")?
            .getattr("partial")?
            .call((slf.get_type(),), Some(this.kwargs.bind(py)))?;
        Ok((partial, this.args.bind(py).clone()))
    }

    /// Its arena, form and sub-tasks.
    ///
    /// >>> problem
    /// <hypersynth.Problem on "specs/case-study/arena.txt", paper form: phi1, phi2>
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
    /// What `engine` (`"implicit"` or `"explicit"`) makes of the problem with the MDP stage
    /// `mdp` (`spec`'s, for errors; none: the games only) and `requests`.
    fn outcome(
        &self,
        py: Python<'_>,
        engine: &str,
        (spec, mdp): (&MdpSpec, Option<&MdpSpec>),
        requests: &pipeline::Requests,
    ) -> PyResult<pipeline::Outcome> {
        let engine = engine_of(engine)?;
        let arena = &self.arena;
        match engine {
            Engine::Implicit => {
                let (tasks, states) = (&self.tasks, self.states);
                let map = arena.map.as_deref();
                let source = (arena.name.as_str(), &*arena.arena, map);
                let run = interruptibly(py, |observer| {
                    Ok(pipeline::implicit_outcome(
                        tasks,
                        source,
                        (states, mdp),
                        requests,
                        observer,
                    ))
                })?;
                run.map_err(|error| run_error(spec, error))
            }
            Engine::Explicit => {
                let options = mdp
                    .map(|spec| spec.build(&arena.arena))
                    .transpose()
                    .map_err(|error| spec_error(spec, error))?;
                let problem = pipeline::Problem {
                    arena_name: arena.name.clone(),
                    arena: (*arena.arena).clone(),
                    map: arena.map.as_deref().cloned(),
                    tasks: self.tasks.clone(),
                    states: self.states,
                    mdp: options,
                };
                interruptibly(py, |observer| pipeline::run(&problem, requests, observer))
            }
        }
    }
}

/// The engine named `engine`: `"implicit"` or `"explicit"` (Python has no memory ceiling to
/// choose by).
fn engine_of(engine: &str) -> PyResult<Engine> {
    choice(
        "engine",
        engine,
        &[
            ("implicit", Engine::Implicit),
            ("explicit", Engine::Explicit),
        ],
    )
}

/// The observations `observations` (if given) with `delta` (by default
/// [`DEFAULT_DELTA`]), as `solve`, `report` and `controller_json` take them.
fn learnt_of(
    py: Python<'_>,
    observations: Option<&Bound<'_, PyAny>>,
    delta: Option<f64>,
) -> PyResult<Option<LearntSpec>> {
    observations
        .map(|value| observations_of(py, value, delta.unwrap_or(DEFAULT_DELTA)))
        .transpose()
}

/// The observations `solve` learns from: a path (read here; named so in reports) or the runs
/// as a list of lines (named `<observations>`), with the confidence parameter `delta`.
fn observations_of(py: Python<'_>, value: &Bound<'_, PyAny>, delta: f64) -> PyResult<LearntSpec> {
    if let Ok(lines) = value.cast::<PyList>() {
        let mut text = String::new();
        for line in lines.iter() {
            text.push_str(&line.extract::<String>()?);
            text.push('\n');
        }
        return Ok(LearntSpec {
            name: "<observations>".to_string(),
            text,
            delta,
        });
    }
    if value.is_instance_of::<PyString>() || value.hasattr("__fspath__")? {
        let path: std::path::PathBuf = value.extract()?;
        let name = path.display().to_string();
        let text = std::fs::read_to_string(&path).map_err(|e| file_error(py, &name, &e))?;
        return Ok(LearntSpec { name, text, delta });
    }
    Err(exception::<OptionsError>(
        "observations: give an observations file's path, or its runs as a list of lines",
        None,
        None,
    ))
}

/// `sigma_l` as given to `solve`: `"uniform"`, `"random"` (seeded by `seed`, the default),
/// weights `{state: {action: weight}}` (a table of the dicts' entries in their order), or a
/// weights file's path (a `pathlib.Path`, read here: its errors are located in it).
fn sigma_l_of(
    py: Python<'_>,
    sigma_l: Option<&Bound<'_, PyAny>>,
    seed: u64,
) -> PyResult<SigmaLSpec> {
    if let Some(value) = sigma_l
        && !value.is_instance_of::<PyString>()
        && value.hasattr("__fspath__")?
    {
        let path: std::path::PathBuf = value.extract()?;
        let name = path.display().to_string();
        let text = std::fs::read_to_string(&path).map_err(|e| file_error(py, &name, &e))?;
        return Ok(SigmaLSpec::WeightsFile { name, text });
    }
    sigma_l_value(sigma_l, seed).map(SigmaLSpec::Value)
}

/// `sigma_l` given as a value (see [`sigma_l_of`]).
fn sigma_l_value(sigma_l: Option<&Bound<'_, PyAny>>, seed: u64) -> PyResult<SigmaL> {
    let Some(value) = sigma_l else {
        return Ok(SigmaL::Random { seed });
    };
    if let Ok(text) = value.extract::<String>() {
        return match text.as_str() {
            "uniform" => Ok(SigmaL::Uniform),
            "random" => Ok(SigmaL::Random { seed }),
            other => Err(exception::<OptionsError>(
                format!("sigma_l: `{other}` is not one of uniform, random (or a dict of weights)"),
                None,
                None,
            )),
        };
    }
    let dict: &Bound<'_, PyDict> = value.cast()?;
    let mut table = WeightTable::new();
    for (state, weights) in dict.iter() {
        let state: String = state.extract()?;
        for (action, weight) in weights.cast::<PyDict>()?.iter() {
            table.add(
                state.clone(),
                action.extract::<String>()?,
                weight.extract()?,
            );
        }
    }
    Ok(SigmaL::Weights {
        table,
        file: "sigma_l".to_string(),
    })
}

/// The MDP stage's options from `solve`'s (and `report`'s) arguments, unchecked.
fn mdp_spec(
    py: Python<'_>,
    discount: f64,
    sigma_l: Option<&Bound<'_, PyAny>>,
    seed: u64,
    epsilon: f64,
    max_iterations: Option<u32>,
    learnt: Option<LearntSpec>,
) -> PyResult<MdpSpec> {
    Ok(MdpSpec {
        sigma_l: sigma_l_of(py, sigma_l, seed)?,
        seed,
        discount,
        precision: Precision::Absolute(epsilon),
        max_iterations: max_iterations.unwrap_or(SolveOptions::default().max_iterations),
        learnt,
    })
}

/// The Python error of the MDP stage's options `spec` refused: located in the argument
/// (`discount`, `epsilon`, `sigma_l[...]`, the weights' or observations' file).
fn spec_error(spec: &MdpSpec, error: SpecError) -> PyErr {
    let name = match &error.field {
        Field::Discount => "discount".to_string(),
        Field::Precision => "epsilon".to_string(),
        Field::Weight { state, action } => format!("sigma_l[{state:?}][{action:?}]"),
        Field::Observations => spec
            .learnt
            .as_ref()
            .map_or_else(|| "observations".to_string(), |l| l.name.clone()),
        Field::Weights => match &spec.sigma_l {
            SigmaLSpec::WeightsFile { name, .. } => name.clone(),
            SigmaLSpec::Value(_) => "sigma_l".to_string(),
        },
        other => other.to_string(),
    };
    let text = match (&error.field, &spec.sigma_l) {
        (Field::Observations, _) => spec.learnt.as_ref().map(|l| l.text.as_str()),
        (Field::Weights, SigmaLSpec::WeightsFile { text, .. }) => Some(text.as_str()),
        _ => None,
    };
    in_field(&name, text, error.position, *error.kind)
}

/// The Python error of a run of either engine on the MDP stage's options `spec`.
pub(crate) fn run_error(spec: &MdpSpec, error: RunError) -> PyErr {
    match error {
        RunError::Spec(error) => spec_error(spec, error),
        RunError::Pipeline(error) => pipeline_error(error),
        RunError::Implicit(error) => exception::<SolveError>(error.to_string(), None, None),
        RunError::Memory(error) => exception::<Error>(error.to_string(), None, None),
        // A report has no sink to write into; should one fail, the error says which.
        RunError::Write(..) => exception::<Error>(error.to_string(), None, None),
    }
}

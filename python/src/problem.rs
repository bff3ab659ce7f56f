//! Problems: the Python arguments mapped onto the library's problem specification
//! (`hypersynth::pipeline::spec`), whose rules check them; the errors name the arguments.

use pyo3::prelude::*;
use pyo3::types::PyDict;

use hypersynth::game::States;
use hypersynth::mdp::solve::SolveOptions;
use hypersynth::opportunistic::adversary::{SigmaL, WeightTable};
use hypersynth::opportunistic::build::Risk;
use hypersynth::pipeline::spec::{
    Field, GeneralSpec, MdpSpec, NamedTask, PaperPayoffs, PayoffPart, Precision, SetPayoff,
    SigmaLSpec, SpecError, SpecErrorKind, TaskSource, TasksSpec,
};
use hypersynth::pipeline::{self, Tasks};

use crate::arena::Arena;
use crate::automaton::{Automaton, translation};
use crate::errors::{OptionsError, TaskError, exception, in_field};
use crate::solution::Solution;

/// A problem: an arena and the robot's tasks, in the paper's form
/// (`Problem(arena, phi=..., psi=...)`) or the general one
/// (`Problem(arena, tasks={...}, payoffs={...}, believed=..., risk=...)`). Solve it with
/// `solve`.
#[pyclass(frozen, module = "hypersynth")]
pub(crate) struct Problem {
    arena: Arena,
    tasks: Tasks,
    states: States,
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
        let spec = MdpSpec {
            sigma_l: SigmaLSpec::Value(sigma_l_of(sigma_l, seed)?),
            seed,
            discount,
            precision: Precision::Absolute(epsilon),
            max_iterations: max_iterations.unwrap_or(SolveOptions::default().max_iterations),
            learnt: None,
        };
        let options = spec.build(&self.arena.arena).map_err(|error| {
            let name = match &error.field {
                Field::Discount => "discount".to_string(),
                Field::Precision => "epsilon".to_string(),
                Field::Weight { state, action } => format!("sigma_l[{state:?}][{action:?}]"),
                other => other.to_string(),
            };
            in_field(&name, None, error.position, *error.kind)
        })?;
        let problem = pipeline::Problem {
            arena_name: self.arena.name.clone(),
            arena: (*self.arena.arena).clone(),
            map: self.arena.map.as_deref().cloned(),
            tasks: self.tasks.clone(),
            states: self.states,
            mdp: Some(options),
        };
        Solution::solve(py, problem)
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

/// `sigma_l` as given to `solve`: `"uniform"`, `"random"` (seeded by `seed`, the default), or
/// weights `{state: {action: weight}}`, a table of the dicts' entries in their order.
fn sigma_l_of(sigma_l: Option<&Bound<'_, PyAny>>, seed: u64) -> PyResult<SigmaL> {
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

//! Solutions: a problem solved once and kept (`Solution`), whose every question (values,
//! decisions, simulations, reports, pictures, the DRN, the exported controller) reads the one
//! solution; the solve releases the GIL and stops on Ctrl-C.

use std::time::{Duration, Instant};

use numpy::PyArray1;
use pyo3::exceptions::PyKeyboardInterrupt;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use hypersynth::game::TaskSet;
use hypersynth::mdp::DrnForm;
use hypersynth::opportunistic::simulate::{Ending, SimulationOptions, simulate, trace};
use hypersynth::opportunistic::view::{GameView, SolvedGame};
use hypersynth::pipeline::{self, Picture, PictureRequest, PipelineError, Requests, Solved};
use hypersynth::render::title::TitleChoice;
use hypersynth::report::StageError;
use hypersynth::stage::{self, Observer};

use crate::controller::Controller;
use crate::errors::{Error, OptionsError, ParseError, SolveError, exception, located_at};

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
pub(crate) struct Solution {
    cell: SolvedCell,
    decision: hypersynth::report::InitialDecision,
}

impl Solution {
    /// Solves `problem` with the GIL released, polling Python's signal handlers; the library's
    /// warnings become `UserWarning`s.
    pub(crate) fn solve(py: Python<'_>, problem: pipeline::Problem) -> PyResult<Solution> {
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

    /// The controller exported as JSON (format `hypersynth-controller/2`), as
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

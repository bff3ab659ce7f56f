//! Solutions: a problem solved once and kept (`Solution`), whose every question (values,
//! decisions, simulations, reports, pictures, the DRN, the exported controller) reads the one
//! solution; the solve releases the GIL and stops on Ctrl-C.

use std::time::{Duration, Instant};

use numpy::PyArray1;
use pyo3::exceptions::PyKeyboardInterrupt;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyTuple};

use hypersynth::game::TaskSet;
use hypersynth::mdp::DrnForm;
use hypersynth::opportunistic::simulate::{Ending, SimulationOptions, simulate, trace};
use hypersynth::opportunistic::view::{GameView, SolvedGame};
use hypersynth::pipeline::{
    self, CurveRequest, Picture, PictureRequest, PipelineError, Requests, RobustSolution, Solved,
};
use hypersynth::render::title::TitleChoice;
use hypersynth::report::{RobustSummary, StageError};
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

pub(crate) fn pipeline_error(error: PipelineError) -> PyErr {
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
pub(crate) struct Interruptible {
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

/// A solved problem (`Problem.solve`): the value of h0, the controller's decisions,
/// per-state values and labels (NumPy arrays), reports, pictures, the DRN, the exported
/// controller and, with observations, the robust stage. Values are certified intervals: a
/// value is always its lower bound, a float (`value`, `values`, `state_value`), and its upper
/// bound is the name with `_upper` (`value_upper`, `values_upper`, `state_value_upper`). A
/// solution pickles as its problem and options: unpickling solves again (deterministically).
///
/// >>> solution
/// <hypersynth.Solution (paper form): value of h0 in [294.0211..., 294.0211...], 3200 product states>
#[pyclass(frozen, module = "hypersynth")]
pub(crate) struct Solution {
    cell: SolvedCell,
    decision: hypersynth::report::InitialDecision,
    /// `Problem.solve`'s arguments, the problem first (to pickle it).
    given: Py<PyTuple>,
    /// The robust stage, when sigma_L is learnt from observations.
    robust: Option<(RobustSolution, RobustSummary)>,
}

impl Solution {
    /// Solves `problem` with the GIL released, polling Python's signal handlers; the library's
    /// warnings become `UserWarning`s.
    /// Solves `problem` (`given`: the arguments of `Problem.solve`, the problem first), and
    /// its robust stage when sigma_L is learnt.
    pub(crate) fn solve(
        py: Python<'_>,
        problem: pipeline::Problem,
        given: Py<PyTuple>,
    ) -> PyResult<Solution> {
        let (cell, robust) = interruptibly(py, |observer| {
            let cell = SolvedCell::try_new(problem, |problem| Solved::new(problem, observer))?;
            let robust = cell.with_dependent(|problem, solved| {
                let options = problem.mdp.as_ref().expect("solved with the MDP stage");
                let Some(learnt) = &options.learnt else {
                    return Ok(None);
                };
                let game = solved.game();
                let opportunistic = solved.solution.as_ref().expect("the MDP stage");
                let risk = problem.tasks.risk();
                let robust = RobustSolution::solve(&game, risk, options, learnt, observer)?;
                let truth = &opportunistic.adversary;
                let summary = robust.summary(&game, learnt, options, truth, None);
                Ok::<_, PipelineError>(Some((robust, summary)))
            })?;
            Ok((cell, robust))
        })?;
        let decision = cell.with_dependent(|_, solved| {
            let solution = solved.solution.as_ref().expect("solved with the MDP stage");
            let requests = pipeline::ReportRequests::default();
            solution
                .synthesis(&solved.game(), &requests, None, &mut ())
                .decision
        });
        Ok(Solution {
            cell,
            decision,
            given,
            robust,
        })
    }

    pub(crate) fn solved(&self) -> &Solved<'_> {
        self.cell.borrow_dependent()
    }

    pub(crate) fn opportunistic(&self) -> &pipeline::OpportunisticSolution {
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

    /// The problem, its observations and the robust stage's summary, for a solution learnt
    /// from observations.
    fn learnt(&self) -> PyResult<(&pipeline::Problem, &pipeline::Learnt, &RobustSummary)> {
        let problem = self.cell.borrow_owner();
        let learnt = problem.mdp.as_ref().and_then(|o| o.learnt.as_ref());
        match (learnt, &self.robust) {
            (Some(learnt), Some((_, summary))) => Ok((problem, learnt, summary)),
            _ => Err(exception::<OptionsError>(
                "a learning curve needs a solution learnt from observations: \
                 solve(observations=...)",
                None,
                None,
            )),
        }
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
    /// The value of h0 (its certified lower bound).
    ///
    /// >>> round(solution.value, 2)
    /// 294.02
    #[getter]
    fn value(&self) -> f64 {
        self.decision.value
    }

    /// The certified upper bound of the value of h0.
    ///
    /// >>> solution.value <= solution.value_upper <= solution.value + 1e-6
    /// True
    #[getter]
    fn value_upper(&self) -> f64 {
        self.decision.value_upper
    }

    /// What the controller itself collects from h0 (lower bound), evaluated as Markov chains:
    /// the expected return of `Controller.as_policy()` in the Gymnasium environment.
    ///
    /// >>> round(solution.policy_value, 2)
    /// 294.02
    #[getter]
    fn policy_value(&self) -> f64 {
        self.decision.policy_value
    }

    /// The controller's expected number of robot moves from h0 before it commits.
    ///
    /// >>> round(solution.expected_moves, 1)
    /// 2.0
    #[getter]
    fn expected_moves(&self) -> f64 {
        self.decision.expected_moves
    }

    /// The controller's action at h0 (None when the adversary moves first or nothing can be
    /// gained).
    ///
    /// >>> solution.action
    /// 'N'
    #[getter]
    fn action(&self) -> Option<String> {
        self.decision.action.clone()
    }

    /// The set of sub-tasks the controller commits to at h0, if it does.
    ///
    /// >>> solution.commits_to is None
    /// True
    #[getter]
    fn commits_to(&self) -> Option<Vec<String>> {
        self.decision.commits_to.clone()
    }

    /// The product state h0's name.
    ///
    /// >>> solution.initial_state
    /// '((0,2),(4,2),0)|0|0'
    #[getter]
    fn initial_state(&self) -> String {
        self.solved()
            .game()
            .state_name(self.solved().product.initial())
    }

    /// The number of product states (the length of the arrays).
    ///
    /// >>> len(solution) == len(solution.values)
    /// True
    fn __len__(&self) -> usize {
        self.solved().product.num_states()
    }

    /// The name of product state `index` (`ARENA_STATE|Q1|Q2`).
    ///
    /// >>> solution.state_name(solution.state_index("h0"))
    /// '((0,2),(4,2),0)|0|0'
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
    ///
    /// >>> float(solution.values[solution.state_index("h0")]) == solution.value
    /// True
    fn state_index(&self, name: &str) -> PyResult<usize> {
        Ok(self.state(name)?.index())
    }

    /// Per product state, its value (the certified lower bound), a NumPy array.
    ///
    /// >>> solution.values.dtype, solution.values.shape == (len(solution),)
    /// (dtype('float64'), True)
    #[getter]
    fn values<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let (solution, mdp) = (&self.opportunistic().solution, &self.opportunistic().mdp);
        self.array(py, |h| solution.value(mdp.node(h)).lower)
    }

    /// Per product state, the certified upper bound of its value.
    ///
    /// >>> bool((solution.values <= solution.values_upper).all())
    /// True
    #[getter]
    fn values_upper<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let (solution, mdp) = (&self.opportunistic().solution, &self.opportunistic().mdp);
        self.array(py, |h| solution.value(mdp.node(h)).upper)
    }

    /// Per product state, whether the robot moves there.
    ///
    /// >>> int(solution.is_robot.sum())
    /// 1600
    #[getter]
    fn is_robot<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<bool>> {
        let game = self.solved().game();
        self.array(py, |h| game.is_robot(h))
    }

    /// Per product state, its arena state's index (`Arena.names` order).
    ///
    /// >>> names = problem.arena.names
    /// >>> names[solution.arena_states[solution.state_index("h0")]]
    /// '((0,2),(4,2),0)'
    #[getter]
    fn arena_states<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u32>> {
        let game = self.solved().game();
        self.array(py, |h| game.arena_state(h).index() as u32)
    }

    /// Per product state, the set of sub-tasks it settles for, as a bit mask (bit i: sub-task
    /// i of `task_names`): the win-label's numeric form.
    ///
    /// >>> int(solution.best[solution.state_index("h0")])  # phi1
    /// 1
    #[getter]
    fn best<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u8>> {
        let game = self.solved().game();
        self.array(py, |h| game.best(h).0)
    }

    /// Per product state, the payoff the robot can force from it (its guarantee).
    ///
    /// >>> float(solution.guarantees[solution.state_index("h0")])
    /// 200.0
    #[getter]
    fn guarantees<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let game = self.solved().game();
        self.array(py, |h| game.guarantee(h))
    }

    /// The sub-tasks' names, in product order (the bits of `best`).
    ///
    /// >>> solution.task_names
    /// ['phi1', 'phi2']
    #[getter]
    fn task_names(&self) -> Vec<String> {
        self.solved().problem.tasks.names()
    }

    /// Per product state, how reports label it (its win-label `(W, L, L)` in the paper's
    /// form), as strings.
    ///
    /// >>> solution.labels[solution.state_index("h0")]
    /// '(W, L, L)'
    #[getter]
    fn labels(&self) -> Vec<String> {
        let game = self.solved().game();
        self.solved()
            .product
            .states()
            .map(|h| game.label(h))
            .collect()
    }

    /// The value of product state `state` (`"h0"` or `ARENA_STATE|Q1|Q2`): its certified
    /// lower bound, as `values` has it.
    ///
    /// >>> solution.state_value("h0") == solution.value
    /// True
    #[pyo3(signature = (state = "h0"))]
    fn state_value(&self, state: &str) -> PyResult<f64> {
        let h = self.state(state)?;
        let solution = self.opportunistic();
        Ok(solution.solution.value(solution.mdp.node(h)).lower)
    }

    /// The certified upper bound of the value of product state `state`, as `values_upper` has
    /// it.
    ///
    /// >>> solution.state_value_upper("h0") == solution.value_upper
    /// True
    #[pyo3(signature = (state = "h0"))]
    fn state_value_upper(&self, state: &str) -> PyResult<f64> {
        let h = self.state(state)?;
        let solution = self.opportunistic();
        Ok(solution.solution.value(solution.mdp.node(h)).upper)
    }

    /// How reports label product state `state`: its win-label `(W, L, L)` in the paper's form.
    ///
    /// >>> solution.label("h0")
    /// '(W, L, L)'
    #[pyo3(signature = (state = "h0"))]
    fn label(&self, state: &str) -> PyResult<String> {
        let h = self.state(state)?;
        Ok(self.solved().game().label(h))
    }

    /// The decision table of `state` (the paper's Table II), as the JSON report gives it.
    ///
    /// >>> [(row["action"], round(row["value"], 2)) for row in solution.decision_table()["actions"]]
    /// [('N', 294.02), ('E', 290.77), ('NE', 290.77), ('stop', 200.0)]
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
    ///
    /// >>> runs = solution.simulate(1000, seed=7)
    /// >>> runs["runs"], runs["ci_low"] <= solution.value <= runs["ci_high"]
    /// (1000, True)
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
    ///
    /// >>> solution.trace(seed=7)["steps"][0]["action"]
    /// 'N'
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
    ///
    /// >>> import json
    /// >>> json.loads(solution.report(format="json"))["initial"]["action"]
    /// 'N'
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
    ///
    /// >>> solution.to_drn().splitlines()[0]
    /// '// hypersynth MDP: R{"r"}max=? [C] is the maximal expected payoff'
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
    ///
    /// >>> arena = hs.Arena.from_file("specs/case-study/map.txt")
    /// >>> on_map = hs.Problem(arena, phi="(!O U A) & (!O U B)", psi="!O U A").solve()
    /// >>> on_map.svg("partition", title="")[:4]
    /// '<svg'
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
        let requests = Requests {
            picture: Some(PictureRequest {
                picture,
                adversary_at: None,
                automata: None,
                title: title_choice(title),
            }),
            max_steps: 1000,
            ..Requests::default()
        };
        Ok(self.outcome(&requests)?.svg.unwrap_or_default())
    }

    /// The partition picture, for Jupyter (None when the arena is not a map).
    ///
    /// >>> solution._repr_svg_() is None
    /// True
    fn _repr_svg_(&self) -> Option<String> {
        self.cell.borrow_owner().map.as_ref()?;
        self.svg("partition", None).ok()
    }

    /// The controller exported as JSON (format `hypersynth-controller/2`), as
    /// `--export-controller` writes it; with `certificate`, with the certificate of its bounds
    /// that `hypersynth.check` checks (`--certificate`). For a solution learnt from
    /// observations, the robust controller, certified against the learnt region.
    ///
    /// >>> import json
    /// >>> json.loads(solution.controller_json())["format"]
    /// 'hypersynth-controller/2'
    /// >>> "certificate" in json.loads(solution.controller_json(certificate=True))
    /// True
    #[pyo3(signature = (certificate = false))]
    fn controller_json(&self, certificate: bool) -> PyResult<String> {
        let requests = Requests {
            export_controller: true,
            certificate,
            ..Requests::default()
        };
        Ok(self.outcome(&requests)?.controller.unwrap_or_default())
    }

    /// The exported controller, ready to run step by step (or as a policy of the Gymnasium
    /// environment: `Controller.as_policy`).
    ///
    /// >>> solution.controller().step("((0,2),(4,2),0)")
    /// Answer('move', action='N')
    fn controller(&self) -> PyResult<Controller> {
        Controller::from_json(&self.controller_json(false)?)
    }

    /// The games report's section as the JSON report gives it (the paper's or the general
    /// form's).
    ///
    /// >>> import json
    /// >>> sorted(json.loads(solution.games_json()))[:3]
    /// ['arena', 'automata', 'engine']
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

    /// The robust stage's summary, as the JSON report's `robust` gives it, when sigma_L is
    /// learnt from observations (None otherwise): the robust and nominal values of h0
    /// (`value`, `value_upper`, `nominal_value`, `nominal_value_upper`), their actions, and
    /// the decision table of h0 with both values per action (`choices`).
    ///
    /// >>> learnt = problem.solve(discount=0.99, observations="specs/learnt/runs.txt")
    /// >>> robust = learnt.robust
    /// >>> robust["runs"], robust["value"] <= robust["nominal_value"]
    /// (1000, True)
    /// >>> sorted(robust["choices"][0])
    /// ['action', 'nominal', 'robust']
    #[getter]
    fn robust<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        let Some((_, summary)) = &self.robust else {
            return Ok(None);
        };
        let text = serde_json::to_string(summary)
            .map_err(|e| exception::<Error>(e.to_string(), None, None))?;
        json_loads(py, &text).map(Some)
    }

    /// The learning curve (a solution learnt from observations only): per number of runs in
    /// `runs` (default: 1, 2, 5, 10, ... and all of them), the robust and nominal values of
    /// h0 learnt from the first that many runs, as the JSON report's `learning_curve` gives
    /// them. The GIL is released meanwhile; Ctrl-C interrupts it.
    ///
    /// >>> learnt = problem.solve(discount=0.99, observations="specs/learnt/runs.txt")
    /// >>> [point["runs"] for point in learnt.learning_curve([1, 10, 1000])]
    /// [1, 10, 1000]
    #[pyo3(signature = (runs = None))]
    fn learning_curve<'py>(
        &self,
        py: Python<'py>,
        runs: Option<Vec<usize>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (problem, learnt, summary) = self.learnt()?;
        let options = problem.mdp.as_ref().expect("solved with the MDP stage");
        let runs = runs.unwrap_or_else(|| pipeline::curve_runs(learnt.observations.num_runs()));
        let points = interruptibly(py, |observer| {
            let (game, risk) = (self.solved().game(), problem.tasks.risk());
            let all = Some(summary);
            pipeline::learning_curve(&game, risk, options, learnt, &runs, all, observer)
                .map_err(PipelineError::Stage)
        })?;
        let text = serde_json::to_string(&points)
            .map_err(|e| exception::<Error>(e.to_string(), None, None))?;
        json_loads(py, &text)
    }

    /// The learning curve's picture as SVG (`--learning-curve`): both values against the runs,
    /// with the value under the solve's sigma_L as the reference; `title` replaces the default
    /// title (`""`: none).
    ///
    /// >>> learnt = problem.solve(discount=0.99, observations="specs/learnt/runs.txt")
    /// >>> learnt.learning_curve_svg([1, 10, 1000])[:4]
    /// '<svg'
    #[pyo3(signature = (runs = None, title = None))]
    fn learning_curve_svg(
        &self,
        py: Python<'_>,
        runs: Option<Vec<usize>>,
        title: Option<String>,
    ) -> PyResult<String> {
        self.learnt()?;
        let requests = Requests {
            learning_curve: Some(CurveRequest {
                runs: runs.unwrap_or_default(),
                picture: Some(title_choice(title)),
            }),
            max_steps: 1000,
            ..Requests::default()
        };
        let outcome = interruptibly(py, |observer| self.solved().outcome(&requests, observer))?;
        Ok(outcome.curve_svg.unwrap_or_default())
    }

    /// The problem solved.
    ///
    /// >>> solution.problem.form
    /// 'paper'
    #[getter]
    fn problem<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.given.bind(py).get_item(0)
    }

    /// Pickles as its problem and `solve`'s arguments (an observations file is read again
    /// where it is unpickled).
    ///
    /// >>> import pickle
    /// >>> pickle.loads(pickle.dumps(solution)).value == solution.value
    /// True
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let py = slf.py();
        let given = slf.get().given.bind(py).clone();
        let solve = given.get_item(0)?.get_type().getattr("solve")?;
        Ok((solve, given))
    }

    /// Its form, the value of h0 and the number of product states.
    ///
    /// >>> solution
    /// <hypersynth.Solution (paper form): value of h0 in [294.0211..., 294.0211...], 3200 product states>
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

/// A picture's title as given: None the default, `""` none, else the text.
fn title_choice(title: Option<String>) -> TitleChoice {
    match title {
        None => TitleChoice::Default,
        Some(text) if text.is_empty() => TitleChoice::None,
        Some(text) => TitleChoice::Text(text),
    }
}

/// `work` with the GIL released, under `stage::interruptible` with an observer that polls
/// Python's signal handlers; the library's warnings become `UserWarning`s, its errors
/// exceptions, an interruption the handler's exception (`KeyboardInterrupt`).
pub(crate) fn interruptibly<T: Send>(
    py: Python<'_>,
    work: impl FnOnce(&mut Interruptible) -> Result<T, PipelineError> + Send,
) -> PyResult<T> {
    let (done, warnings, pending) = py.detach(|| {
        let mut observer = Interruptible::default();
        let done = stage::interruptible(|| work(&mut observer));
        (done, observer.warnings, observer.pending)
    });
    let done = match done {
        Ok(Ok(done)) => done,
        Ok(Err(e)) => return Err(pipeline_error(e)),
        Err(stage::Interrupted) => {
            return Err(pending.unwrap_or_else(|| PyKeyboardInterrupt::new_err(())));
        }
    };
    warn(py, &warnings)?;
    Ok(done)
}

fn json_loads<'py>(py: Python<'py>, text: &str) -> PyResult<Bound<'py, PyAny>> {
    py.import("json")?.call_method1("loads", (text,))
}

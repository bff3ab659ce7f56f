//! Solutions: a problem solved once and kept (`Solution`), whose every question (values,
//! decisions, simulations, reports, pictures, the DRN, the exported controller) reads the one
//! solution; the solve releases the GIL and stops on Ctrl-C.

use std::time::{Duration, Instant};

use numpy::PyArray1;
use pyo3::exceptions::PyKeyboardInterrupt;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyTuple};

use std::sync::Arc;

use hypersynth::arena::Owner;
use hypersynth::arena::gridworld::Gridworld;
use hypersynth::game::{HState, StateNameError, States, TaskSet};
use hypersynth::implicit::SourceMoves;
use hypersynth::mdp::DrnForm;
use hypersynth::opportunistic::presentation::Presentation;
use hypersynth::opportunistic::simulate::{Ending, Simulation, SimulationOptions, simulate, trace};
use hypersynth::opportunistic::view::{GameView, SolvedGame, SolvedHypergame};
use hypersynth::pipeline::spec::MdpSpec;
use hypersynth::pipeline::{
    self, CurveRequest, ImplicitProduct, ImplicitSolution, Picture, PictureRequest, PipelineError,
    Requests, RobustSolution, RunError, Sinks, Solved, Source, Tasks,
};
use hypersynth::render::title::TitleChoice;
use hypersynth::report::{Report, RobustSummary, StageError, TraceReport};
use hypersynth::stage::{self, Observer};

use crate::controller::Controller;
use crate::errors::{Error, OptionsError, ParseError, SolveError, exception, located_at};
use crate::problem::run_error;

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

/// What the implicit engine solves: a problem's inputs, owned.
pub(crate) struct ImplicitInputs {
    pub(crate) name: String,
    pub(crate) arena: Arc<hypersynth::arena::Arena>,
    pub(crate) map: Option<Arc<Gridworld>>,
    pub(crate) tasks: Tasks,
    pub(crate) states: States,
    /// The MDP stage's options as given (for errors).
    pub(crate) spec: MdpSpec,
}

impl ImplicitInputs {
    fn source(&self) -> Source<'_> {
        match &self.map {
            Some(world) => Source::Map(world),
            None => Source::Arena(&self.arena),
        }
    }
}

self_cell::self_cell!(
    /// The implicit engine's inputs with their moves, which borrow them.
    struct MovesCell {
        owner: ImplicitInputs,
        #[covariant]
        dependent: SourceMoves,
    }
);

type ProductOf<'a> = ImplicitProduct<'a, 'a, SourceMoves<'a>>;

self_cell::self_cell!(
    /// The product of those moves, which borrows them.
    struct ProductCell {
        owner: MovesCell,
        #[covariant]
        dependent: ProductOf,
    }
);

type SolutionOf<'a> = ImplicitSolution<'a, 'a, SourceMoves<'a>>;

self_cell::self_cell!(
    /// The product's solution, which borrows it.
    struct ImplicitCell {
        owner: ProductCell,
        #[covariant]
        dependent: SolutionOf,
    }
);

/// The solution of either engine.
enum Kept {
    /// The explicit engine's, with its robust stage when sigma_L is learnt.
    Explicit {
        cell: SolvedCell,
        robust: Option<Box<(RobustSolution, RobustSummary)>>,
    },
    /// The implicit engine's; with the reachable enumeration, its enumerated states in the
    /// explicit engine's order (the arrays' order) and, sorted, each with its place there.
    Implicit {
        cell: ImplicitCell,
        order: Option<Order>,
    },
}

/// The enumerated states in the explicit engine's order, and each state with its place there,
/// sorted by state.
type Order = (Vec<u32>, Vec<(u32, u32)>);

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
    kept: Kept,
    decision: hypersynth::report::InitialDecision,
    /// `Problem.solve`'s arguments, the problem first (to pickle it).
    given: Py<PyTuple>,
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
            kept: Kept::Explicit {
                cell,
                robust: robust.map(Box::new),
            },
            decision,
            given,
        })
    }

    /// Solves `inputs` with the implicit engine (`given`: as [`Solution::solve`]), once: every
    /// question is answered from the kept solution.
    pub(crate) fn solve_implicit(
        py: Python<'_>,
        inputs: ImplicitInputs,
        given: Py<PyTuple>,
    ) -> PyResult<Solution> {
        let spec = inputs.spec.clone();
        let solved = interruptibly(py, |observer| {
            let solve = || {
                let moves = MovesCell::try_new(inputs, |inputs| inputs.source().moves())?;
                let product = ProductCell::try_new(moves, |moves| {
                    let inputs = moves.borrow_owner();
                    let about = (inputs.name.as_str(), inputs.source());
                    let mdp = (inputs.states, Some(&inputs.spec));
                    let (tasks, moves) = (&inputs.tasks, moves.borrow_dependent());
                    ImplicitProduct::new(tasks, about, moves, mdp, observer)
                })?;
                ImplicitCell::try_new(product, |product| {
                    ImplicitSolution::new(product.borrow_dependent(), observer)
                })
            };
            Ok(solve())
        })?;
        let cell = solved.map_err(|error| run_error(&spec, error))?;
        let solution = cell.borrow_dependent();
        let decision = solution
            .decision()
            .expect("solved with the MDP stage")
            .clone();
        let space = solution.product().space();
        let order = (space.enumeration() == States::Reachable).then(|| {
            let mut order = Vec::with_capacity(space.num_enumerated());
            space.for_each_state(|h| order.push(h));
            let mut places: Vec<(u32, u32)> = order
                .iter()
                .enumerate()
                .map(|(i, &h)| (h, i as u32))
                .collect();
            places.sort_unstable();
            (order, places)
        });
        Ok(Solution {
            kept: Kept::Implicit { cell, order },
            decision,
            given,
        })
    }

    /// The explicit engine's solution (what `Dynamics` reads: it refuses the implicit one
    /// first, [`Solution::explicit_only`]).
    pub(crate) fn solved(&self) -> &Solved<'_> {
        match &self.kept {
            Kept::Explicit { cell, .. } => cell.borrow_dependent(),
            Kept::Implicit { .. } => unreachable!("checked by Solution::explicit_only"),
        }
    }

    /// The error that `what` needs a solution of the explicit engine, when this is not one.
    pub(crate) fn explicit_only(&self, what: &str) -> PyResult<()> {
        match &self.kept {
            Kept::Explicit { .. } => Ok(()),
            Kept::Implicit { .. } => Err(exception::<OptionsError>(
                format!(
                    "engine: {what} needs the explicit engine's solution (it steps through the \
                     stored MDP): solve(engine=\"explicit\")"
                ),
                None,
                None,
            )),
        }
    }

    /// The implicit engine's solution, if it is one.
    fn implicit(&self) -> Option<&SolutionOf<'_>> {
        match &self.kept {
            Kept::Implicit { cell, .. } => Some(cell.borrow_dependent()),
            Kept::Explicit { .. } => None,
        }
    }

    /// The problem's presentation (how it names sets of sub-tasks).
    fn presentation(&self) -> &Presentation {
        match self.implicit() {
            Some(solution) => solution.product().tasks().presentation(),
            None => self.solved().problem.tasks.presentation(),
        }
    }

    /// The implicit engine's answer to `requests`, from its kept solution.
    fn implicit_outcome(
        &self,
        solution: &SolutionOf<'_>,
        requests: &Requests,
        observer: &mut dyn Observer,
    ) -> PyResult<pipeline::Outcome> {
        solution
            .outcome(requests, Sinks::default(), observer)
            .map_err(|error| self.implicit_error(error))
    }

    /// A Python error of the implicit engine's answers.
    fn implicit_error(&self, error: RunError) -> PyErr {
        let Kept::Implicit { cell, .. } = &self.kept else {
            unreachable!("an error of the implicit engine")
        };
        let inputs = cell.borrow_owner().borrow_owner().borrow_owner();
        run_error(&inputs.spec, error)
    }

    pub(crate) fn opportunistic(&self) -> &pipeline::OpportunisticSolution {
        self.solved()
            .solution
            .as_ref()
            .expect("solved with the MDP stage")
    }

    /// Either engine's answer to `requests` (the implicit one's with the GIL held: what it
    /// makes is quick beside the solve).
    fn outcome(&self, requests: &Requests) -> PyResult<pipeline::Outcome> {
        match self.implicit() {
            Some(solution) => self.implicit_outcome(solution, requests, &mut ()),
            None => self
                .solved()
                .outcome(requests, &mut ())
                .map_err(pipeline_error),
        }
    }

    /// The product state named `name` (or `"h0"`): the explicit engine's number, or the
    /// implicit engine's index.
    fn state(&self, name: &str) -> PyResult<u32> {
        let parsed = match self.implicit() {
            Some(solution) => {
                let product = solution.product();
                if name == "h0" {
                    return Ok(product.space().initial());
                }
                product.parse_state(name)
            }
            None => {
                let product = &self.solved().product;
                if name == "h0" {
                    return Ok(product.initial().as_u32());
                }
                product.parse_state(name).map(|h| h.as_u32())
            }
        };
        parsed.map_err(|e| {
            let shown = e.to_string();
            let position = match &e {
                StateNameError::Malformed(p, _)
                | StateNameError::UnknownArenaState(p, _)
                | StateNameError::Unreachable(p, _)
                | StateNameError::NoSuchDfaState { position: p, .. }
                | StateNameError::NotEnumerated { position: p, .. } => *p,
            };
            let message = shown
                .strip_prefix(&format!("{position}: "))
                .unwrap_or(&shown)
                .to_string();
            located_at::<ParseError>("state", name, position, &message)
        })
    }

    /// The error that a learning curve needs a solution learnt from observations.
    fn not_learnt() -> PyErr {
        exception::<OptionsError>(
            "a learning curve needs a solution learnt from observations: \
             solve(observations=...)",
            None,
            None,
        )
    }

    /// The explicit engine's problem, its observations and the robust stage's summary, for a
    /// solution learnt from observations.
    fn learnt(&self) -> PyResult<(&pipeline::Problem, &pipeline::Learnt, &RobustSummary)> {
        let Kept::Explicit { cell, robust } = &self.kept else {
            unreachable!("an explicit solution")
        };
        let problem = cell.borrow_owner();
        let learnt = problem.mdp.as_ref().and_then(|o| o.learnt.as_ref());
        match (learnt, robust.as_deref()) {
            (Some(learnt), Some((_, summary))) => Ok((problem, learnt, summary)),
            _ => Err(Self::not_learnt()),
        }
    }

    /// The number of product states (the arrays' length).
    fn num_states(&self) -> usize {
        match self.implicit() {
            Some(solution) => solution.product().space().num_enumerated(),
            None => self.solved().product.num_states(),
        }
    }

    /// [`Solution::per_state`] as a NumPy array (one buffer, no Python object per state).
    fn array<'py, T: numpy::Element>(
        &self,
        py: Python<'py>,
        explicit: impl Fn(&SolvedHypergame<'_, '_>, HState) -> T,
        implicit: impl Fn(&SolutionOf<'_>, u32) -> T,
    ) -> Bound<'py, PyArray1<T>> {
        PyArray1::from_vec(py, self.per_state(explicit, implicit))
    }

    /// Per product state in the arrays' order, `explicit` of it (the explicit engine's) or
    /// `implicit` of it (the implicit engine's).
    fn per_state<T>(
        &self,
        explicit: impl Fn(&SolvedHypergame<'_, '_>, HState) -> T,
        implicit: impl Fn(&SolutionOf<'_>, u32) -> T,
    ) -> Vec<T> {
        match &self.kept {
            Kept::Explicit { .. } => {
                let game = self.solved().game();
                let states = self.solved().product.states();
                states.map(|h| explicit(&game, h)).collect()
            }
            Kept::Implicit { cell, order } => {
                let solution = cell.borrow_dependent();
                match order {
                    Some((order, _)) => order.iter().map(|&h| implicit(solution, h)).collect(),
                    None => {
                        let n = solution.product().space().num_states() as u32;
                        (0..n).map(|h| implicit(solution, h)).collect()
                    }
                }
            }
        }
    }

    /// Either engine's certified value of product state `h` ([`Solution::state`]).
    fn value_of(&self, h: u32) -> hypersynth::mdp::solve::Interval {
        match self.implicit() {
            Some(solution) => Self::implicit_value(solution, h),
            None => self.explicit_value(HState::from_u32(h)),
        }
    }

    /// The seed the implicit engine's problem was solved with.
    fn implicit_seed(solution: &SolutionOf<'_>) -> u64 {
        let options = solution.product().options();
        options.expect("solved with the MDP stage").seed
    }

    /// The implicit engine's certified value of `h` (it is solved with the MDP stage).
    fn implicit_value(solution: &SolutionOf<'_>, h: u32) -> hypersynth::mdp::solve::Interval {
        solution.value(h).expect("solved with the MDP stage")
    }

    /// The explicit engine's certified value of `h`.
    fn explicit_value(&self, h: HState) -> hypersynth::mdp::solve::Interval {
        let solution = self.opportunistic();
        solution.solution.value(solution.mdp.node(h))
    }

    /// Either engine's simulation of `n` runs from `seed`.
    fn simulation(
        &self,
        py: Python<'_>,
        n: u32,
        seed: Option<u64>,
        max_steps: u32,
    ) -> PyResult<Simulation> {
        match self.implicit() {
            Some(solution) => {
                let requests = Requests {
                    simulate: Some(n),
                    max_steps,
                    ..Requests::default()
                };
                let seed = seed.unwrap_or(Self::implicit_seed(solution));
                let (simulation, _, _) = py
                    .detach(|| solution.runs(&requests, seed, &mut ()))
                    .map_err(|error| self.implicit_error(error))?;
                Ok(simulation.expect("asked for"))
            }
            None => {
                let solution = self.opportunistic();
                let options = SimulationOptions {
                    runs: n,
                    seed: seed.unwrap_or(solution.options.seed),
                    max_steps,
                };
                Ok(py.detach(|| {
                    let game = self.solved().game();
                    simulate(&solution.controller(&game), &solution.adversary, options)
                }))
            }
        }
    }

    /// Either engine's traced run from `seed`.
    fn traced(&self, seed: Option<u64>, max_steps: u32) -> PyResult<TraceReport> {
        match self.implicit() {
            Some(solution) => {
                let requests = Requests {
                    trace: true,
                    max_steps,
                    ..Requests::default()
                };
                let seed = seed.unwrap_or(Self::implicit_seed(solution));
                let (_, trace, _) = solution
                    .runs(&requests, seed, &mut ())
                    .map_err(|error| self.implicit_error(error))?;
                Ok(trace.expect("asked for"))
            }
            None => {
                let solution = self.opportunistic();
                let game = self.solved().game();
                let run = trace(
                    &solution.controller(&game),
                    &solution.adversary,
                    seed.unwrap_or(solution.options.seed),
                    max_steps,
                );
                Ok(solution.trace_report(&game, &run))
            }
        }
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
        match self.implicit() {
            Some(solution) => {
                let space = solution.product().space();
                space.name(space.initial())
            }
            None => self
                .solved()
                .game()
                .state_name(self.solved().product.initial()),
        }
    }

    /// The number of product states (the length of the arrays).
    ///
    /// >>> len(solution) == len(solution.values)
    /// True
    fn __len__(&self) -> usize {
        self.num_states()
    }

    /// The name of product state `index` (`ARENA_STATE|Q1|Q2`).
    ///
    /// >>> solution.state_name(solution.state_index("h0"))
    /// '((0,2),(4,2),0)|0|0'
    fn state_name(&self, index: usize) -> PyResult<String> {
        let n = self.num_states();
        if index >= n {
            return Err(pyo3::exceptions::PyIndexError::new_err(format!(
                "product state {index} out of range (0..{n})"
            )));
        }
        Ok(match &self.kept {
            Kept::Explicit { .. } => self.solved().game().state_name(HState::new(index)),
            Kept::Implicit { cell, order } => {
                let h = order
                    .as_ref()
                    .map_or(index as u32, |(order, _)| order[index]);
                cell.borrow_dependent().product().space().name(h)
            }
        })
    }

    /// The index of product state `name` (or `"h0"`) in the arrays.
    ///
    /// >>> float(solution.values[solution.state_index("h0")]) == solution.value
    /// True
    fn state_index(&self, name: &str) -> PyResult<usize> {
        let h = self.state(name)?;
        Ok(match &self.kept {
            Kept::Implicit {
                order: Some((_, places)),
                ..
            } => {
                // A parsed state is enumerated: it has a place.
                let at = places.partition_point(|&(state, _)| state < h);
                places[at].1 as usize
            }
            _ => h as usize,
        })
    }

    /// Per product state, its value (the certified lower bound), a NumPy array.
    ///
    /// >>> solution.values.dtype, solution.values.shape == (len(solution),)
    /// (dtype('float64'), True)
    #[getter]
    fn values<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.array(
            py,
            |_, h| self.explicit_value(h).lower,
            |solution, h| Self::implicit_value(solution, h).lower,
        )
    }

    /// Per product state, the certified upper bound of its value.
    ///
    /// >>> bool((solution.values <= solution.values_upper).all())
    /// True
    #[getter]
    fn values_upper<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.array(
            py,
            |_, h| self.explicit_value(h).upper,
            |solution, h| Self::implicit_value(solution, h).upper,
        )
    }

    /// Per product state, whether the robot moves there.
    ///
    /// >>> int(solution.is_robot.sum())
    /// 1600
    #[getter]
    fn is_robot<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<bool>> {
        let space = |solution: &SolutionOf<'_>, h| solution.product().space().owner(h);
        self.array(
            py,
            |game, h| game.is_robot(h),
            |solution, h| space(solution, h) == Owner::Robot,
        )
    }

    /// Per product state, its arena state's index (`Arena.names` order).
    ///
    /// >>> names = problem.arena.names
    /// >>> names[solution.arena_states[solution.state_index("h0")]]
    /// '((0,2),(4,2),0)'
    #[getter]
    fn arena_states<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u32>> {
        self.array(
            py,
            |game, h| game.arena_state(h).index() as u32,
            |solution, h| solution.product().space().arena_state(h),
        )
    }

    /// Per product state, the set of sub-tasks it settles for, as a bit mask (bit i: sub-task
    /// i of `task_names`): the win-label's numeric form.
    ///
    /// >>> int(solution.best[solution.state_index("h0")])  # phi1
    /// 1
    #[getter]
    fn best<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u8>> {
        self.array(
            py,
            |game, h| game.best(h).0,
            |solution, h| {
                let (product, payoffs) = (solution.product(), solution.product().tasks().payoffs());
                product.regions().best(payoffs, h).unwrap_or_default().0
            },
        )
    }

    /// Per product state, the payoff the robot can force from it (its guarantee).
    ///
    /// >>> float(solution.guarantees[solution.state_index("h0")])
    /// 200.0
    #[getter]
    fn guarantees<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.array(
            py,
            |game, h| game.guarantee(h),
            |solution, h| {
                let (product, payoffs) = (solution.product(), solution.product().tasks().payoffs());
                product.regions().guarantee(payoffs, h)
            },
        )
    }

    /// The sub-tasks' names, in product order (the bits of `best`).
    ///
    /// >>> solution.task_names
    /// ['phi1', 'phi2']
    #[getter]
    fn task_names(&self) -> Vec<String> {
        match self.implicit() {
            Some(solution) => solution.product().tasks().names(),
            None => self.solved().problem.tasks.names(),
        }
    }

    /// Per product state, how reports label it (its win-label `(W, L, L)` in the paper's
    /// form), as strings.
    ///
    /// >>> solution.labels[solution.state_index("h0")]
    /// '(W, L, L)'
    #[getter]
    fn labels(&self) -> Vec<String> {
        self.per_state(|game, h| game.label(h), |solution, h| solution.label(h))
    }

    /// The value of product state `state` (`"h0"` or `ARENA_STATE|Q1|Q2`): its certified
    /// lower bound, as `values` has it.
    ///
    /// >>> solution.state_value("h0") == solution.value
    /// True
    #[pyo3(signature = (state = "h0"))]
    fn state_value(&self, state: &str) -> PyResult<f64> {
        Ok(self.value_of(self.state(state)?).lower)
    }

    /// The certified upper bound of the value of product state `state`, as `values_upper` has
    /// it.
    ///
    /// >>> solution.state_value_upper("h0") == solution.value_upper
    /// True
    #[pyo3(signature = (state = "h0"))]
    fn state_value_upper(&self, state: &str) -> PyResult<f64> {
        Ok(self.value_of(self.state(state)?).upper)
    }

    /// How reports label product state `state`: its win-label `(W, L, L)` in the paper's form.
    ///
    /// >>> solution.label("h0")
    /// '(W, L, L)'
    #[pyo3(signature = (state = "h0"))]
    fn label(&self, state: &str) -> PyResult<String> {
        let h = self.state(state)?;
        Ok(match self.implicit() {
            Some(solution) => solution.label(h),
            None => self.solved().game().label(HState::from_u32(h)),
        })
    }

    /// The decision table of `state` (the paper's Table II), as the JSON report gives it.
    ///
    /// >>> [(row["action"], round(row["value"], 2)) for row in solution.decision_table()["actions"]]
    /// [('N', 294.02), ('E', 290.77), ('NE', 290.77), ('stop', 200.0)]
    #[pyo3(signature = (state = "h0"))]
    fn decision_table<'py>(&self, py: Python<'py>, state: &str) -> PyResult<Bound<'py, PyAny>> {
        let h = self.state(state)?;
        let explanation = match self.implicit() {
            Some(solution) => py
                .detach(|| solution.explain(h, &mut ()))
                .map_err(|error| self.implicit_error(error))?,
            None => {
                let game = self.solved().game();
                let solution = self.opportunistic();
                solution
                    .controller(&game)
                    .explain(HState::from_u32(h), &solution.evaluation)
            }
        };
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
        let simulation = self.simulation(py, n, seed, max_steps)?;
        let dict = PyDict::new(py);
        dict.set_item("runs", n)?;
        let satisfied = PyDict::new(py);
        let presentation = self.presentation();
        for (mask, count) in simulation.satisfied.iter().enumerate().skip(1) {
            if *count > 0 {
                satisfied.set_item(presentation.set_name(TaskSet(mask as u8)), count)?;
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
        let report = py.detach(|| self.traced(seed, max_steps))?;
        let dict = PyDict::new(py);
        let ending = match report.ending {
            Ending::Satisfied(set) => format!("satisfied {}", self.presentation().set_name(set)),
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
        match self.implicit() {
            Some(solution) => solution
                .drn(induced, form, &mut ())
                .map_err(|error| self.implicit_error(error)),
            None => Ok(self
                .opportunistic()
                .drn(&self.solved().game(), induced, form)),
        }
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
        match &self.kept {
            Kept::Explicit { cell, .. } => cell.borrow_owner().map.as_ref().map(|_| ()),
            Kept::Implicit { cell, .. } => {
                let inputs = cell.borrow_owner().borrow_owner().borrow_owner();
                inputs.map.as_ref().map(|_| ())
            }
        }?;
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
        let report = match self.implicit() {
            Some(solution) => {
                let tasks = solution.product().tasks();
                Report {
                    presentation: tasks.presentation().clone(),
                    games: solution.product().games().clone(),
                    synthesis: None,
                }
            }
            None => Report {
                synthesis: None,
                ..self.outcome(&Requests::default())?.report
            },
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
        let summary = match &self.kept {
            Kept::Explicit { robust: None, .. } => return Ok(None),
            Kept::Explicit {
                robust: Some(robust),
                ..
            } => robust.1.clone(),
            Kept::Implicit { cell, .. } => {
                let solution = cell.borrow_dependent();
                match solution.robust_summary(None, &mut ()) {
                    Ok(Some(summary)) => summary,
                    Ok(None) => return Ok(None),
                    Err(error) => return Err(self.implicit_error(error)),
                }
            }
        };
        let text = serde_json::to_string(&summary)
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
        if let Some(solution) = self.implicit() {
            // The robust stage's learning curve, as the report gives it.
            if self.robust(py)?.is_none() {
                return Err(Self::not_learnt());
            }
            if runs.as_ref().is_some_and(Vec::is_empty) {
                return json_loads(py, "[]");
            }
            let requests = Requests {
                learning_curve: Some(CurveRequest {
                    runs: runs.unwrap_or_default(),
                    picture: None,
                }),
                ..Requests::default()
            };
            let outcome = interruptibly(py, |observer| {
                Ok(solution.outcome(&requests, Sinks::default(), observer))
            })?
            .map_err(|error| self.implicit_error(error))?;
            let synthesis = outcome.report.synthesis.expect("solved with the MDP stage");
            let points = synthesis.robust.expect("learnt").learning_curve;
            let text = serde_json::to_string(&points)
                .map_err(|e| exception::<Error>(e.to_string(), None, None))?;
            return json_loads(py, &text);
        }
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
        if self.robust(py)?.is_none() {
            return Err(Self::not_learnt());
        }
        let requests = Requests {
            learning_curve: Some(CurveRequest {
                runs: runs.unwrap_or_default(),
                picture: Some(title_choice(title)),
            }),
            max_steps: 1000,
            ..Requests::default()
        };
        let outcome = match self.implicit() {
            Some(solution) => interruptibly(py, |observer| {
                Ok(solution.outcome(&requests, Sinks::default(), observer))
            })?
            .map_err(|error| self.implicit_error(error))?,
            None => interruptibly(py, |observer| self.solved().outcome(&requests, observer))?,
        };
        Ok(outcome.curve_svg.unwrap_or_default())
    }

    /// The engine that solved it: `"explicit"` or `"implicit"` (`Problem.solve(engine=...)`).
    ///
    /// >>> solution.engine
    /// 'explicit'
    #[getter]
    fn engine(&self) -> &'static str {
        match self.kept {
            Kept::Explicit { .. } => "explicit",
            Kept::Implicit { .. } => "implicit",
        }
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
        let form = self.presentation().form().name();
        format!(
            "<hypersynth.Solution ({form} form): value of h0 in [{}, {}], {} product states>",
            self.decision.value,
            self.decision.value_upper,
            self.num_states()
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

//! The exported controller run step by step (`Controller`), as `hypersynth execute` runs it; its
//! answers as values (`Answer`); and the controller as a policy of the Gymnasium environment
//! (`ControllerPolicy`).

use pyo3::prelude::*;
use pyo3::types::PyDict;

use hypersynth::opportunistic::executor::{self, Executor, Then};

use crate::errors::{ControllerError, exception};

/// An exported controller run step by step: give it each arena state the play reaches
/// (`step`), and it answers the robot's action at robot states (an `Answer`).
///
/// >>> controller = solution.controller()
/// >>> controller.step("((0,2),(4,2),0)")
/// Answer('move', action='N')
/// >>> controller
/// <hypersynth.Controller (paper form, phi1, phi2): step 1, uncommitted>
#[pyclass(module = "hypersynth")]
pub(crate) struct Controller {
    executor: Executor,
    off_model: Option<String>,
    /// The states observed in this play.
    steps: usize,
}

/// The controller's answer at a robot state: `kind` is `"move"` (play `action`), `"commit"`
/// (the state commits to `set`; play `action`, the set's first move, or nothing when it holds
/// already), `"stop"` (play `stop` to settle for `set`, then `action` likewise), `"done"` (the
/// committed set holds) or `"give up"` (nothing can be gained). `str(answer)` is the line
/// `hypersynth execute` prints.
///
/// >>> answer = solution.controller().step("((0,2),(4,2),0)")
/// >>> answer.kind, answer.action, answer.set, str(answer)
/// ('move', 'N', None, 'N')
#[pyclass(frozen, eq, module = "hypersynth")]
#[derive(Clone, PartialEq, Eq)]
pub(crate) struct Answer {
    kind: &'static str,
    action: Option<String>,
    set: Option<String>,
    line: String,
}

#[pymethods]
impl Answer {
    /// `"move"`, `"commit"`, `"stop"`, `"done"` or `"give up"`.
    ///
    /// >>> solution.controller().step("((0,2),(4,2),0)").kind
    /// 'move'
    #[getter]
    fn kind(&self) -> &'static str {
        self.kind
    }

    /// The arena action to play now, if any (after a commitment: the set's first move).
    ///
    /// >>> solution.controller().step("((0,2),(4,2),0)").action
    /// 'N'
    #[getter]
    fn action(&self) -> Option<String> {
        self.action.clone()
    }

    /// The set committed to by this answer (`"commit"`, `"stop"`), as reports name it.
    ///
    /// >>> solution.controller().step("((0,2),(4,2),0)").set is None
    /// True
    #[getter]
    fn set(&self) -> Option<String> {
        self.set.clone()
    }

    /// The answer as `hypersynth execute` prints it: `ACTION`, `commit SET ACTION`,
    /// `stop SET ACTION`, `done` or `give up`.
    ///
    /// >>> str(solution.controller().step("((0,2),(4,2),0)"))
    /// 'N'
    fn __str__(&self) -> String {
        self.line.clone()
    }

    /// The answer's fields.
    ///
    /// >>> solution.controller().step("((0,2),(4,2),0)")
    /// Answer('move', action='N')
    fn __repr__(&self) -> String {
        let mut parts = vec![format!("{:?}", self.kind)];
        if let Some(set) = &self.set {
            parts.push(format!("set={set:?}"));
        }
        if let Some(action) = &self.action {
            parts.push(format!("action={action:?}"));
        }
        format!("Answer({})", parts.join(", ")).replace('"', "'")
    }
}

impl Controller {
    /// The library's answer as a value.
    fn answer(&self, answer: &executor::Answer) -> Answer {
        let name = |a| self.executor.arena().action_name(a).to_string();
        let (kind, action, set) = match answer {
            executor::Answer::Move(a) => ("move", Some(name(*a)), None),
            executor::Answer::Commit { set, stop, then } => {
                let action = match then {
                    Then::Move(a) => Some(name(*a)),
                    Then::Done => None,
                };
                let kind = if *stop { "stop" } else { "commit" };
                (kind, action, Some(self.executor.set_name(*set)))
            }
            executor::Answer::Done => ("done", None, None),
            executor::Answer::GiveUp => ("give up", None, None),
        };
        Answer {
            kind,
            action,
            set,
            line: self.executor.answer_line(answer),
        }
    }

    /// Observes `state`; the library's answer at a robot state.
    fn observe(&mut self, state: &str) -> PyResult<Option<executor::Answer>> {
        let turn = self
            .executor
            .observe(state)
            .map_err(|e| exception::<ControllerError>(e.to_string(), None, None))?;
        self.off_model = turn.off_model.map(|o| o.to_string());
        self.steps += 1;
        Ok(turn.answer)
    }
}

#[pymethods]
impl Controller {
    /// Reads an exported controller (the JSON of `--export-controller`).
    ///
    /// >>> hs.Controller.from_json(solution.controller_json()).committed is None
    /// True
    #[staticmethod]
    pub(crate) fn from_json(text: &str) -> PyResult<Controller> {
        let executor = Executor::from_json(text)
            .map_err(|e| exception::<ControllerError>(e.to_string(), None, None))?;
        Ok(Controller {
            executor,
            off_model: None,
            steps: 0,
        })
    }

    /// Observes the arena state `state` the play reached: at a robot state, the controller's
    /// `Answer`; None at the adversary's.
    ///
    /// >>> controller = solution.controller()
    /// >>> controller.step("((0,2),(4,2),0)")
    /// Answer('move', action='N')
    /// >>> controller.step("((0,3),(4,2),1)") is None
    /// True
    fn step(&mut self, state: &str) -> PyResult<Option<Answer>> {
        Ok(self.observe(state)?.map(|a| self.answer(&a)))
    }

    /// Starts a new play.
    ///
    /// >>> controller = solution.controller()
    /// >>> controller.step("((0,2),(4,2),0)")
    /// Answer('move', action='N')
    /// >>> controller.reset()
    /// >>> controller.step("((0,2),(4,2),0)")
    /// Answer('move', action='N')
    fn reset(&mut self) {
        self.executor.reset();
        self.off_model = None;
        self.steps = 0;
    }

    /// The set committed to, if any.
    ///
    /// >>> solution.controller().committed is None
    /// True
    #[getter]
    fn committed(&self) -> Option<String> {
        self.executor.committed().map(|s| self.executor.set_name(s))
    }

    /// Whether the committed set holds.
    ///
    /// >>> solution.controller().is_done
    /// False
    #[getter]
    fn is_done(&self) -> bool {
        self.executor.is_done()
    }

    /// The automata's states after the last step.
    ///
    /// >>> controller = solution.controller()
    /// >>> controller.step("((0,2),(4,2),0)")
    /// Answer('move', action='N')
    /// >>> controller.automata
    /// [0, 0]
    #[getter]
    fn automata(&self) -> Vec<u32> {
        self.executor.automata().to_vec()
    }

    /// The message of the last step's off-model move, if it was one.
    ///
    /// >>> solution.controller().off_model is None
    /// True
    #[getter]
    fn off_model(&self) -> Option<String> {
        self.off_model.clone()
    }

    /// The arena actions the controller plays, in the arena's order; with `stop`, the actions
    /// of the Gymnasium environment (`hypersynth.gym`), whose indices the policy returns.
    ///
    /// >>> solution.controller().actions
    /// ['N', 'S', 'E', 'W', 'NE', 'NW', 'SE', 'SW', 'STAY']
    #[getter]
    fn actions(&self) -> Vec<String> {
        self.executor.arena().actions().to_vec()
    }

    /// This controller as a policy of the Gymnasium environment (`hypersynth.gym`): called
    /// with an observation and its `info`, it steps the controller through the arena states
    /// the play passed (`info["passed"]`, restarting at an episode's first observation) and
    /// returns the index of its action (`stop` last). Giving up, it plays the first enabled
    /// action (nothing can be gained either way).
    ///
    /// >>> env = hs.gym.HypergameEnv(solution)
    /// >>> policy = solution.controller().as_policy()
    /// >>> observation, info = env.reset(seed=1)
    /// >>> env.actions[policy(observation, info)]
    /// 'N'
    fn as_policy(slf: Bound<'_, Self>) -> ControllerPolicy {
        ControllerPolicy {
            controller: slf.unbind(),
        }
    }

    /// The controller's form, tasks and where its play is.
    ///
    /// >>> solution.controller()
    /// <hypersynth.Controller (paper form, phi1, phi2): step 0, uncommitted>
    fn __repr__(&self) -> String {
        let file = self.executor.file();
        let committed = match self.committed() {
            Some(set) if self.is_done() => format!("committed to {set}, done"),
            Some(set) => format!("committed to {set}"),
            None => "uncommitted".to_string(),
        };
        format!(
            "<hypersynth.Controller ({} form, {}): step {}, {committed}>",
            file.form.name(),
            file.tasks.join(", "),
            self.steps,
        )
    }
}

/// A `Controller` as a policy of the Gymnasium environment (`Controller.as_policy()`):
/// `policy(observation, info)` is the index of the controller's action.
///
/// >>> env = hs.gym.HypergameEnv(solution)
/// >>> policy = solution.controller().as_policy()
/// >>> observation, info = env.reset(seed=1)
/// >>> policy(observation, info)
/// 0
#[pyclass(module = "hypersynth")]
pub(crate) struct ControllerPolicy {
    controller: Py<Controller>,
}

#[pymethods]
impl ControllerPolicy {
    /// The controller driven.
    ///
    /// >>> solution.controller().as_policy().controller
    /// <hypersynth.Controller (paper form, phi1, phi2): step 0, uncommitted>
    #[getter]
    fn controller(&self, py: Python<'_>) -> Py<Controller> {
        self.controller.clone_ref(py)
    }

    /// The index of the controller's action at the observation of `info` (see
    /// `Controller.as_policy`); the observation itself is not needed, as `info["passed"]` says
    /// where the play went.
    ///
    /// >>> env = hs.gym.HypergameEnv(solution)
    /// >>> policy = solution.controller().as_policy()
    /// >>> observation, info = env.reset(seed=1)
    /// >>> policy(observation, info)
    /// 0
    #[pyo3(signature = (observation, info))]
    fn __call__(
        &self,
        py: Python<'_>,
        observation: &Bound<'_, PyAny>,
        info: &Bound<'_, PyDict>,
    ) -> PyResult<usize> {
        let _ = observation;
        let mut controller = self.controller.borrow_mut(py);
        let item = |key: &str| {
            info.get_item(key)?.ok_or_else(|| {
                exception::<ControllerError>(
                    format!("info has no `{key}`: the policy drives hypersynth.gym environments"),
                    None,
                    None,
                )
            })
        };
        if item("moves")?.extract::<u64>()? == 0 {
            controller.reset();
        }
        let mut answer = None;
        for state in item("passed")?.try_iter()? {
            answer = controller.observe(&state?.extract::<String>()?)?;
        }
        let actions = controller.executor.arena().actions();
        // A commitment is `stop`: the environment shows a state that commits without moving
        // only before the robot's first move, where `stop` collects its payoff.
        let chosen = match &answer {
            Some(executor::Answer::Move(a)) => Some(*a as usize),
            Some(executor::Answer::Commit { .. }) => Some(actions.len()),
            _ => None,
        };
        match chosen {
            Some(action) => Ok(action),
            // Giving up (or done, or at a state the environment ends in): the first enabled.
            None => {
                let mask = item("action_mask")?;
                let mask: Vec<bool> = mask
                    .try_iter()?
                    .map(|m| m?.is_truthy())
                    .collect::<PyResult<_>>()?;
                Ok(mask.iter().position(|&m| m).unwrap_or(actions.len()))
            }
        }
    }

    /// The controller it drives.
    ///
    /// >>> solution.controller().as_policy()
    /// <hypersynth.ControllerPolicy of <hypersynth.Controller (paper form, phi1, phi2): step 0, uncommitted>>
    fn __repr__(&self, py: Python<'_>) -> String {
        format!(
            "<hypersynth.ControllerPolicy of {}>",
            self.controller.borrow(py).__repr__()
        )
    }
}

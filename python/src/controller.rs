//! The exported controller run step by step (`Controller`), as `hypersynth execute` runs it.

use pyo3::prelude::*;

use hypersynth::opportunistic::executor::Executor;

use crate::errors::{ControllerError, exception};

/// An exported controller run step by step: give it each arena state the play reaches
/// (`step`), and it answers the robot's action at robot states.
#[pyclass(module = "hypersynth")]
pub(crate) struct Controller {
    executor: Executor,
    off_model: Option<String>,
}

#[pymethods]
impl Controller {
    /// Reads an exported controller (the JSON of `--export-controller`).
    #[staticmethod]
    pub(crate) fn from_json(text: &str) -> PyResult<Controller> {
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

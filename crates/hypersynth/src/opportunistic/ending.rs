//! How a run of the controller ends: what simulations count, traces report and reports name
//! (in the words of the problem's [`Presentation`](super::presentation::Presentation)).

use crate::game::TaskSet;

/// How a run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ending {
    /// It committed to this set of sub-tasks and satisfied it.
    Satisfied(TaskSet),
    /// The adversary had no enabled action (a win for the robot).
    AdversaryStuck,
    /// It reached a state of value 0 before committing, or its reactive strategy had no move.
    None,
    /// The step bound was hit first.
    StepBound,
}

//! The one place the pictures ask the MDP stage's controller (its decision per robot state,
//! the values, a run), so that they follow that stage's API in one function. Any controller
//! will do ([`Exportable`]: either engine's).

use super::picture::Mark;
use crate::arena::gridworld::Move;
use crate::game::HState;
use crate::opportunistic::controller::Decision;
use crate::opportunistic::export::Exportable;
use crate::opportunistic::simulate::{TraceAction, TraceStep};

/// What the controller does and is worth in the requested robot states, and a run.
#[derive(Clone, Debug, PartialEq)]
pub struct ControllerView {
    /// Per requested state, in order: its mark and its value (lower bound).
    pub decisions: Vec<(Option<Mark>, Option<f64>)>,
    /// The run given, state by state with the action played there.
    pub run: Vec<(HState, Option<String>)>,
}

/// Asks `controller` about the robot states `states` (their decisions and the lower bounds of
/// their values), and names the actions of `run` (a traced run, possibly empty).
pub fn controller_view(
    controller: &dyn Exportable,
    states: &[HState],
    run: &[TraceStep],
) -> ControllerView {
    let decisions = states
        .iter()
        .map(|&h| {
            let mark = match controller.decide(h) {
                Decision::Move { action, .. } => controller
                    .action_name(action)
                    .parse::<Move>()
                    .ok()
                    .map(Mark::Move),
                Decision::Commit(_) => Some(Mark::Commit),
                Decision::Stop(_) => Some(Mark::Stop),
                Decision::GiveUp => Some(Mark::GiveUp),
            };
            (mark, Some(controller.value(h).lower))
        })
        .collect();
    let run = run
        .iter()
        .map(|step| {
            let action = step.action.map(|action| match action {
                TraceAction::Move(action) => controller.action_name(action).to_string(),
                TraceAction::Stop => crate::opportunistic::build::STOP.to_string(),
            });
            (step.state, action)
        })
        .collect();
    ControllerView { decisions, run }
}

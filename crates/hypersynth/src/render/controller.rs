//! The one place the pictures ask the MDP stage's controller (its decision per robot state,
//! the values, a run), so that they follow that stage's API in one function. Any controller
//! will do ([`Plan`]: the paper's and the general form's).

use super::picture::Mark;
use crate::arena::gridworld::Move;
use crate::game::HState;
use crate::opportunistic::evaluate::{Plan, Step};
use crate::opportunistic::simulate::{TraceAction, TraceStep};
use crate::opportunistic::view::GameView;

/// What the controller does and is worth in the requested robot states, and a run.
#[derive(Clone, Debug, PartialEq)]
pub struct ControllerView {
    /// Per requested state, in order: its mark and its value (lower bound).
    pub decisions: Vec<(Option<Mark>, Option<f64>)>,
    /// The run given, state by state with the action played there.
    pub run: Vec<(HState, Option<String>)>,
}

/// Asks `controller` about the robot states `states` (worth `value`, the solution's lower
/// bound), and names the actions of `run` (a traced run, possibly empty).
pub fn controller_view<P: Plan>(
    controller: &P,
    value: impl Fn(HState) -> f64,
    states: &[HState],
    run: &[TraceStep],
) -> ControllerView {
    let view = controller.game();
    let decisions = states
        .iter()
        .map(|&h| {
            let mark = match controller.step(h) {
                Step::Move { action, .. } => view
                    .action_name(action)
                    .parse::<Move>()
                    .ok()
                    .map(Mark::Move),
                Step::Commit { stop: false, .. } => Some(Mark::Commit),
                Step::Commit { stop: true, .. } => Some(Mark::Stop),
                Step::GiveUp => Some(Mark::GiveUp),
            };
            (mark, Some(value(h)))
        })
        .collect();
    let run = run
        .iter()
        .map(|step| {
            let action = step.action.map(|action| match action {
                TraceAction::Move(action) => view.action_name(action).to_string(),
                TraceAction::Stop => crate::opportunistic::build::STOP.to_string(),
            });
            (step.state, action)
        })
        .collect();
    ControllerView { decisions, run }
}

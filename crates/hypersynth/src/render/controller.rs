//! The one place the pictures ask the MDP stage's controller (its decision per robot state,
//! the values, a run), so that they follow that stage's API in one function.

use super::picture::Mark;
use crate::arena::gridworld::Move;
use crate::game::HState;
use crate::mdp::controller::{Controller, Decision};
use crate::mdp::view::{GameView, SolvedHypergame};
use crate::simulate::TraceStep;

/// What the controller does and is worth in the requested robot states, and a run.
#[derive(Clone, Debug, PartialEq)]
pub struct ControllerView {
    /// Per requested state, in order: its mark and its value (lower bound).
    pub decisions: Vec<(Option<Mark>, Option<f64>)>,
    /// The run given, state by state with the action played there.
    pub run: Vec<(HState, Option<String>)>,
}

/// Asks `controller` about the robot states `states`, and locates the steps of `run` (a
/// traced run, possibly empty) in the product.
pub fn controller_view(
    controller: &Controller<SolvedHypergame>,
    states: &[HState],
    run: &[TraceStep],
) -> ControllerView {
    let game = controller.game;
    let decisions = states
        .iter()
        .map(|&h| {
            let mark = match controller.decide(h) {
                Decision::Move { action, .. } => game
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
        .filter_map(|step| {
            let h = game.game().parse_state(&step.state).ok()?;
            Some((h, step.action.clone()))
        })
        .collect();
    ControllerView { decisions, run }
}

//! The one place the pictures call the MDP stage (the controller's decision per robot state,
//! the values, a simulated run), so that it follows that stage's API in one function.

use super::picture::Mark;
use crate::arena::gridworld::Move;
use crate::game::HState;
use crate::mdp::adversary::AdversaryModel;
use crate::mdp::build::HypergameMdp;
use crate::mdp::controller::{Controller, Decision};
use crate::mdp::solve::solve;
use crate::mdp::view::{GameView, SolvedHypergame};
use crate::report::{MdpConfig, StageError};
use crate::simulate;

/// What the controller does and is worth in the requested robot states, and a run.
#[derive(Clone, Debug, PartialEq)]
pub struct ControllerView {
    /// Per requested state, in order: its mark and its value (lower bound).
    pub decisions: Vec<(Option<Mark>, Option<f64>)>,
    /// When `config.trace`: the seeded run of `config.seed`, state by state with the action
    /// played there.
    pub run: Vec<(HState, Option<String>)>,
}

/// Builds and solves the hypergame MDP of `game` as `config` says, and asks its controller
/// about the robot states `states`.
pub fn controller_view(
    game: &SolvedHypergame,
    config: &MdpConfig,
    states: &[HState],
) -> Result<ControllerView, StageError> {
    let adversary = AdversaryModel::new(game, &config.sigma_l)?;
    let built = HypergameMdp::build(game, &adversary, config.payoffs)?;
    let solution = solve(built.mdp(), &config.solve)?;
    let controller = Controller {
        game,
        mdp: &built,
        solution: &solution,
        payoffs: config.payoffs,
    };
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
            (mark, Some(solution.value(built.node(h)).lower))
        })
        .collect();
    let run = if config.trace {
        let (_, steps) = simulate::trace(&controller, &adversary, config.seed, config.max_steps);
        steps
            .into_iter()
            .filter_map(|step| Some((game.game().parse_state(&step.state).ok()?, step.action)))
            .collect()
    } else {
        Vec::new()
    };
    Ok(ControllerView { decisions, run })
}

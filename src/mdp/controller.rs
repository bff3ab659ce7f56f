//! The controller (DESIGN.md 3.6): the opportunistic policy of the solved hypergame MDP, composed
//! with the reactive strategies once the robot commits to a task, and the decision table that
//! explains one of its choices.
//!
//! The robot *commits* to a task when the MDP would absorb it: on reaching `(W,W,W)` (to phi),
//! `(L,W,L)` (to phi2), a stuck adversary state (to phi: the attractor counts it as won), or by
//! playing `stop` (to phi1 in `(W,L,L)`; in `(W,W,L)` to the better sub-task, phi1 unless
//! r2 > r1). From then on it plays the reactive strategy of that task. The policy's tie-breaking
//! is the solver's (documented in `solve`).

use super::build::{HypergameMdp, NodeKind, Payoffs, node_kind};
use super::solve::Solution;
use super::view::{SolvedGame, win_label};
use crate::game::Task;

/// What the controller does in a robot state while it has not committed yet.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Decision {
    /// Play an arena action, reaching product state `successor`.
    Move { action: u32, successor: u32 },
    /// Commit to `goal` here without moving (the MDP absorbs this state).
    Commit(Task),
    /// Play `stop` (one robot move) and commit to `goal`.
    Stop(Task),
    /// A stuck `(L,L,L)` state: nothing can be gained.
    GiveUp,
}

/// The opportunistic controller of a solved hypergame MDP.
pub struct Controller<'a, G: SolvedGame> {
    pub game: &'a G,
    pub mdp: &'a HypergameMdp,
    pub solution: &'a Solution,
    pub payoffs: Payoffs,
}

impl<G: SolvedGame> Controller<'_, G> {
    /// The decision in robot state `h` before committing.
    pub fn decide(&self, h: u32) -> Decision {
        let kind = node_kind(self.game, h);
        match kind {
            Some(NodeKind::Phi) => return Decision::Commit(Task::Phi),
            Some(NodeKind::Phi2Only) => return Decision::Commit(Task::Phi2),
            _ => {}
        }
        let state = self.mdp.node(h).expect("robot states are MDP states");
        let Some(choice) = self.solution.policy(state) else {
            return Decision::GiveUp;
        };
        match self.mdp.arena_action(choice) {
            Some(action) => {
                let successor = self
                    .game
                    .edges(h)
                    .find(|&(a, _)| a == action)
                    .map(|(_, t)| t)
                    .expect("MDP choices are enabled actions");
                Decision::Move { action, successor }
            }
            None if kind == Some(NodeKind::BothSubtasks) => {
                Decision::Stop(self.payoffs.better_subtask())
            }
            None => Decision::Stop(Task::Phi1),
        }
    }

    /// The decision table of robot state `h` (the paper's Table II).
    pub fn explain(&self, h: u32) -> Explanation {
        let mdp = self.mdp.mdp();
        let state = self.mdp.node(h);
        let name_of = |s: u32| match self.mdp.product_state(s) {
            Some(t) => (self.game.state_name(t), win_label(self.game, t).to_string()),
            None => (
                mdp.state_name(s).unwrap_or_default().to_string(),
                "-".to_string(),
            ),
        };
        let rows = state
            .map(|s| {
                mdp.choices(s)
                    .map(|choice| ActionRow {
                        action: mdp.action_name(choice).to_string(),
                        value: self.solution.choice_value(mdp, choice).lower,
                        outcomes: mdp
                            .successors(choice)
                            .map(|(t, probability)| {
                                let (state, label) = name_of(t);
                                Outcome {
                                    state,
                                    label,
                                    probability,
                                    value: self.solution.value(t).lower,
                                }
                            })
                            .collect(),
                    })
                    .collect()
            })
            .unwrap_or_default();
        Explanation {
            state: self.game.state_name(h),
            label: win_label(self.game, h).to_string(),
            value: state.map(|s| self.solution.value(s).lower),
            actions: rows,
            chosen: state
                .and_then(|s| self.solution.policy(s))
                .map(|c| mdp.action_name(c).to_string()),
        }
    }
}

/// The decision table of one robot state.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Explanation {
    pub state: String,
    pub label: String,
    /// Its value (lower bound); `None` for an adversary state.
    pub value: Option<f64>,
    /// One row per enabled action, in MDP choice order (empty for an absorbing state).
    pub actions: Vec<ActionRow>,
    /// The policy's action; `None` for an absorbing state.
    pub chosen: Option<String>,
}

#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ActionRow {
    pub action: String,
    /// The value of playing it once and then optimally (lower bound).
    pub value: f64,
    pub outcomes: Vec<Outcome>,
}

/// A possible next robot state (or stop sink) of an action.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Outcome {
    pub state: String,
    pub label: String,
    pub probability: f64,
    pub value: f64,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mdp::build::tests::{build, game};
    use crate::mdp::solve::{SolveOptions, solve};
    use crate::mdp::view::testing::ToyGame;

    /// Runs `test` on the controller of the build tests' game, undiscounted.
    fn with_controller(test: impl FnOnce(Controller<'_, ToyGame>)) {
        let g = game();
        let built = build(&g);
        let solution = solve(built.mdp(), &SolveOptions::default()).unwrap();
        test(Controller {
            game: &g,
            mdp: &built,
            solution: &solution,
            payoffs: Payoffs::default(),
        });
    }

    #[test]
    fn decisions_commit_by_label_and_follow_the_policy() {
        with_controller(|controller| {
            // r0 plays `b` (value 250) towards adversary a4.
            assert_eq!(
                controller.decide(0),
                Decision::Move {
                    action: 1,
                    successor: 4
                }
            );
            assert_eq!(controller.decide(2), Decision::Commit(Task::Phi));
            // r5 `(W,W,L)`: stop (200) beats `a` (at most 166.7); r1 > r2 so phi1.
            assert_eq!(controller.decide(5), Decision::Stop(Task::Phi1));
            assert_eq!(controller.decide(8), Decision::Commit(Task::Phi2));
            assert_eq!(controller.decide(9), Decision::GiveUp);
            let swapped = Controller {
                payoffs: Payoffs::new(100.0, 200.0, 300.0).unwrap(),
                ..controller
            };
            assert_eq!(swapped.decide(5), Decision::Stop(Task::Phi2));
        });
    }

    #[test]
    fn explanation_lists_each_action_with_its_next_states() {
        with_controller(|controller| {
            let table = controller.explain(0);
            assert_eq!(table.label, "(W, L, L)");
            assert_eq!(table.chosen.as_deref(), Some("b"));
            type Row = (String, Vec<(String, String, f64)>);
            let summary: Vec<Row> = table
                .actions
                .iter()
                .map(|row| {
                    let outs = row
                        .outcomes
                        .iter()
                        .map(|o| (o.state.clone(), o.label.clone(), o.probability))
                        .collect();
                    (row.action.clone(), outs)
                })
                .collect();
            let s = |x: &str| x.to_string();
            assert_eq!(
                summary,
                vec![
                    (
                        s("b"),
                        vec![
                            (s("h2"), s("(W, W, W)"), 0.5),
                            (s("h5"), s("(W, W, L)"), 0.5)
                        ]
                    ),
                    (s("c"), vec![(s("h5"), s("(W, W, L)"), 1.0)]),
                    (s("stop"), vec![(s("stop(phi1)"), s("-"), 1.0)]),
                ]
            );
            assert!((table.actions[0].value - 250.0).abs() < 1e-5);
            assert!((table.actions[0].outcomes[1].value - 200.0).abs() < 1e-5);
        });
    }
}

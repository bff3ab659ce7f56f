//! The controller (DESIGN.md 3.6): the opportunistic policy of the solved hypergame MDP, composed
//! with the reactive strategies once the robot commits to a task, and the decision table that
//! explains one of its choices.
//!
//! The robot *commits* to a task when the MDP would absorb it: on reaching `(W,W,W)` (to phi),
//! `(L,W,L)` (to phi2), or by playing `stop` (to phi1 in `(W,L,L)`; in `(W,W,L)` to the better
//! sub-task, phi1 unless r2 > r1). From then on it plays the reactive strategy of that task. In a
//! state of value 0 it gives up: nothing can be gained there. The policy's tie-breaking is the
//! solver's (documented in `solve`): at g = 1, among the value-optimal actions, the one of least
//! expected number of robot moves.

use std::collections::BTreeMap;

use super::build::{HypergameMdp, NodeKind, Payoffs, node, node_kind};
use super::evaluate::{ControllerEvaluation, Plan};
use super::view::{GameView, SolvedGame, successor};
use crate::arena::ActionId;
use crate::game::{HState, Task};
use crate::mdp::model::{ChoiceId, Mdp, MdpState};
use crate::mdp::solve::{Interval, Solution};

/// What the controller does in a robot state while it has not committed yet.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Decision {
    /// Play an arena action, reaching product state `successor`.
    Move {
        /// The arena action played.
        action: ActionId,
        /// The product state it leads to.
        successor: HState,
    },
    /// Commit to `goal` here without moving (the MDP absorbs this state).
    Commit(Task),
    /// Play `stop` (instant: no robot move) and commit to `goal`.
    Stop(Task),
    /// A state of value 0 (a stuck `(L,L,L)` state among them): nothing can be gained.
    GiveUp,
}

/// The opportunistic controller of a solved hypergame MDP.
pub struct Controller<'a, G: SolvedGame> {
    /// The solved hypergame: tasks, win-labels and reactive strategies.
    pub game: &'a G,
    /// The hypergame MDP built from `game`.
    pub mdp: &'a HypergameMdp,
    /// The MDP's certified solution; its policy is the controller's before committing.
    pub solution: &'a Solution,
    /// The payoffs `r1`, `r2`, `r` the MDP was built with (they decide which sub-task `stop`
    /// commits to in `(W,W,L)`).
    pub payoffs: Payoffs,
}

impl<G: SolvedGame> Controller<'_, G> {
    /// The certified bounds on the value of product state `h`.
    pub fn value(&self, h: HState) -> Interval {
        self.solution.value(self.mdp.node(h))
    }

    /// Whether `h` is worth exactly 0 (it cannot reach a positive payoff under any policy).
    pub fn is_worthless(&self, h: HState) -> bool {
        self.value(h).upper == 0.0
    }

    /// The decision in robot state `h` before committing.
    pub fn decide(&self, h: HState) -> Decision {
        let kind = node_kind(self.game, h);
        match kind {
            Some(NodeKind::Phi) => return Decision::Commit(Task::Phi),
            Some(NodeKind::Phi2Only) => return Decision::Commit(Task::Phi2),
            _ => {}
        }
        if self.is_worthless(h) {
            return Decision::GiveUp;
        }
        let Some(choice) = self.solution.policy(self.mdp.node(h)) else {
            return Decision::GiveUp;
        };
        match self.mdp.arena_action(choice) {
            Some(action) => {
                let successor = successor(self.game, h, action);
                Decision::Move { action, successor }
            }
            None if kind == Some(NodeKind::BothSubtasks) => {
                Decision::Stop(self.payoffs.better_subtask())
            }
            None => Decision::Stop(Task::Phi1),
        }
    }

    /// The decision table of product state `h` (the paper's Table II): per enabled action its
    /// value, the controller's expected number of robot moves when playing it, and the next
    /// robot states (through the adversary's moves) with their probabilities.
    pub fn explain(&self, h: HState, evaluation: &ControllerEvaluation) -> Explanation {
        let names = StateNames {
            product_state: &|s| self.mdp.product_state(s),
            sink_name: &|s| self.mdp.state_name(self.game, s),
        };
        explain(self, self.mdp.mdp(), self.solution, evaluation, h, &names)
    }
}

/// How a decision table relates the states of a hypergame MDP to the product's: the product
/// state of an MDP state (`None` for the stop sinks), and the name of a stop sink.
pub struct StateNames<'a> {
    /// The product state of an MDP state, `None` for a stop sink.
    pub product_state: &'a dyn Fn(MdpState) -> Option<HState>,
    /// The name of a stop sink, e.g. `stop(phi1)`.
    pub sink_name: &'a dyn Fn(MdpState) -> String,
}

/// How a decision table shows a product state.
struct Described {
    name: String,
    label: String,
    robot: bool,
}

/// The decision table of product state `h`, shared by the paper's controller and the general
/// one (`controller` names and labels the product states): per choice of its MDP state its
/// Q-value, the expected number of robot moves when playing it, and the next robot states
/// through chance nodes.
pub fn explain(
    controller: &impl Plan,
    mdp: &Mdp,
    solution: &Solution,
    evaluation: &ControllerEvaluation,
    h: HState,
    names: &StateNames,
) -> Explanation {
    let game = controller.game();
    let describe = |t: HState| Described {
        name: game.state_name(t),
        label: controller.label(t),
        robot: game.is_robot(t),
    };
    let describe_state = |s: MdpState| (names.product_state)(s).map(describe);
    // The controller's expected number of robot moves from MDP state `s` (0 from a sink).
    let expected_moves =
        |s: MdpState| (names.product_state)(s).map_or(0.0, |t| evaluation.expected_moves(t));
    let state = node(h);
    let own = describe(h);
    let rows = if own.robot {
        mdp.choices(state)
            .map(|choice| {
                let moves = if mdp.is_instant(choice) { 0.0 } else { 1.0 };
                ActionRow {
                    action: mdp.action_name(choice).to_string(),
                    value: solution.choice_value(mdp, choice).lower,
                    expected_moves: moves
                        + mdp
                            .successors(choice)
                            .map(|(t, p)| p * expected_moves(t))
                            .sum::<f64>(),
                    outcomes: next_robot_states(
                        mdp,
                        solution,
                        choice,
                        &describe_state,
                        names.sink_name,
                    ),
                }
            })
            .collect()
    } else {
        Vec::new()
    };
    Explanation {
        state: own.name,
        label: own.label,
        robot: own.robot,
        value: solution.value(state).lower,
        expected_moves: evaluation.expected_moves(h),
        actions: rows,
        chosen: own
            .robot
            .then(|| solution.policy(state))
            .flatten()
            .map(|c| mdp.action_name(c).to_string()),
    }
}

/// Where `choice` leads once the adversary has moved: the first robot state, absorbing state
/// or stop sink reached, with its probability (probability mass pushed through chance nodes
/// until less than 1e-12 of it is still moving, for display only).
fn next_robot_states(
    mdp: &Mdp,
    solution: &Solution,
    choice: ChoiceId,
    describe: &dyn Fn(MdpState) -> Option<Described>,
    sink_name: &dyn Fn(MdpState) -> String,
) -> Vec<Outcome> {
    let mut reached: BTreeMap<MdpState, f64> = BTreeMap::new();
    let mut moving: Vec<(MdpState, f64)> = mdp.successors(choice).collect();
    let mut pushes = 0u32;
    while let Some((s, p)) = moving.pop() {
        let is_chance = describe(s).is_some_and(|d| !d.robot) && !mdp.is_absorbing(s);
        if !is_chance || p < 1e-12 || pushes > 1_000_000 {
            *reached.entry(s).or_default() += p;
            continue;
        }
        pushes += 1;
        let chance = mdp.choices(s).start();
        moving.extend(mdp.successors(chance).map(|(t, q)| (t, p * q)));
    }
    reached
        .into_iter()
        .map(|(s, probability)| {
            let (state, label) = match describe(s) {
                Some(d) => (d.name, d.label),
                None => (sink_name(s), "-".to_string()),
            };
            Outcome {
                state,
                label,
                probability,
                value: solution.value(s).lower,
            }
        })
        .collect()
}

/// The decision table of one state.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Explanation {
    /// The product state's name.
    pub state: String,
    /// Its label: the win-label `(W, L, L)` in the paper's form, the generalised label in the
    /// general one.
    pub label: String,
    /// Whether it is a robot state (adversary states have no decision).
    pub robot: bool,
    /// Its value (lower bound).
    pub value: f64,
    /// The controller's expected number of robot moves from here until it commits, gives up,
    /// or the adversary is stuck (infinite if that is not certain).
    pub expected_moves: f64,
    /// One row per enabled action, in MDP choice order (empty for an absorbing state).
    pub actions: Vec<ActionRow>,
    /// The policy's action; `None` for an absorbing or adversary state.
    pub chosen: Option<String>,
}

/// One row of a decision table: an enabled choice of the state's MDP state (an arena action or
/// `stop`).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ActionRow {
    /// The action's name (`stop` included).
    pub action: String,
    /// The value of playing it once and then optimally (lower bound).
    pub value: f64,
    /// The expected number of robot moves when playing it once and then following the
    /// controller (the action itself counts 1, `stop` 0).
    pub expected_moves: f64,
    /// Where it leads once the adversary has moved, one entry per state reached.
    pub outcomes: Vec<Outcome>,
}

/// A possible next robot state (or stop sink, or absorbing adversary state) of an action.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Outcome {
    /// The state's name: a product state's, or a stop sink's such as `stop(phi1)`.
    pub state: String,
    /// Its label (as in [`Explanation::label`]), `-` for a stop sink.
    pub label: String,
    /// The probability of reaching it first, through the adversary's moves.
    pub probability: f64,
    /// Its value (lower bound).
    pub value: f64,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mdp::solve::{SolveOptions, solve};
    use crate::opportunistic::adversary::{AdversaryModel, SigmaL};
    use crate::opportunistic::build::tests::{build, game};
    use crate::opportunistic::view::testing::{ToyGame, hs};

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
                controller.decide(hs(0)),
                Decision::Move {
                    action: 1,
                    successor: hs(4)
                }
            );
            assert_eq!(controller.decide(hs(2)), Decision::Commit(Task::Phi));
            // r5 `(W,W,L)`: stop (200) beats `a` (at most 166.7); r1 > r2 so phi1.
            assert_eq!(controller.decide(hs(5)), Decision::Stop(Task::Phi1));
            assert_eq!(controller.decide(hs(8)), Decision::Commit(Task::Phi2));
            assert_eq!(controller.decide(hs(9)), Decision::GiveUp);
            let swapped = Controller {
                payoffs: Payoffs::new(100.0, 200.0, 300.0).unwrap(),
                ..controller
            };
            assert_eq!(swapped.decide(hs(5)), Decision::Stop(Task::Phi2));
        });
    }

    #[test]
    fn explanation_lists_each_action_with_its_next_states() {
        with_controller(|controller| {
            let adversary = AdversaryModel::new(controller.game, &SigmaL::Uniform).unwrap();
            let evaluation =
                ControllerEvaluation::new(&controller, &adversary, 1e-9, 1000).unwrap();
            // The controller collects what the solver promises: 250 from r0 (b, then commit
            // in r2 or stop in r5), 300 from r3 (c, into the stuck adversary).
            for (h, v) in [(0, 250.0), (3, 300.0), (5, 200.0), (9, 0.0)] {
                let value = evaluation.value(hs(h));
                assert!(
                    value.lower <= v + 1e-9 && v <= value.upper + 1e-9,
                    "{h}: {value:?}"
                );
            }
            let table = controller.explain(hs(0), &evaluation);
            assert_eq!(table.label, "(W, L, L)");
            // One move (b), then the run commits (r2) or stops (r5) without moving.
            assert_eq!(table.expected_moves, 1.0);
            let moves: Vec<f64> = table.actions.iter().map(|a| a.expected_moves).collect();
            assert_eq!(moves, [1.0, 1.0, 0.0]);
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

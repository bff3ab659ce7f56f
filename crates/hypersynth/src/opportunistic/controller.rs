//! The controller (docs/semantics.md §6.7 and §8.6): the opportunistic policy of the solved
//! hypergame MDP, composed with the reactive strategies once the robot commits to a set of
//! sub-tasks, and the decision table that explains one of its choices.
//!
//! The robot *commits* where the MDP absorbs it (the form's rule, [`HypergameMdp::commits`]:
//! `(W,W,W)` and `(L,W,L)` in the paper's form), or by playing `stop`; either way to the set it
//! settles for ([`SolvedGame::best`]: phi in `(W,W,W)`, phi2 in `(L,W,L)`, phi1 in `(W,L,L)`, in
//! `(W,W,L)` the better sub-task, phi1 unless r2 > r1). From then on it plays the reactive
//! strategy of that set. In a state of value 0 it gives up: nothing can be gained there. The
//! policy's tie-breaking is the solver's (documented in `solve`): at g = 1, among the
//! value-optimal actions, the one of least expected number of robot moves.

use super::build::{HypergameMdp, node};
use super::evaluate::{ControllerEvaluation, Plan, Step, Steps};
use super::view::{SolvedGame, successor};
use crate::arena::ActionId;
use crate::game::{HState, TaskSet};
use crate::mdp::absorption::{choice_successors, first_exits};
use crate::mdp::model::{ChoiceId, MdpState};
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
    /// Commit to this set here without moving (the MDP absorbs this state).
    Commit(TaskSet),
    /// Play `stop` (instant: no robot move) and commit to this set.
    Stop(TaskSet),
    /// A state of value 0 (a stuck `(L,L,L)` state among them): nothing can be gained.
    GiveUp,
}

/// The opportunistic controller of a solved hypergame MDP.
pub struct Controller<'a, G: SolvedGame> {
    /// The solved hypergame: regions, payoffs and reactive strategies.
    pub game: &'a G,
    /// The hypergame MDP built from `game`.
    pub mdp: &'a HypergameMdp,
    /// The MDP's certified solution; its policy is the controller's before committing.
    pub solution: &'a Solution,
}

impl<G: SolvedGame> Controller<'_, G> {
    /// The certified bounds on the value of product state `h`.
    pub fn value(&self, h: HState) -> Interval {
        self.solution.value(node(h))
    }

    /// Whether `h` is worth exactly 0 (it cannot reach a positive payoff under any policy).
    pub fn is_worthless(&self, h: HState) -> bool {
        self.value(h).upper == 0.0
    }

    /// The decision in robot state `h` before committing: give up where the value is 0, commit
    /// where the MDP absorbs, else the policy's choice (a move, or `stop` to the set `h`
    /// settles for).
    pub fn decide(&self, h: HState) -> Decision {
        if self.is_worthless(h) {
            return Decision::GiveUp;
        }
        if self.mdp.commits(h) {
            return Decision::Commit(self.game.best(h));
        }
        let Some(choice) = self.solution.policy(node(h)) else {
            return Decision::GiveUp;
        };
        match self.mdp.arena_action(choice) {
            Some(action) => Decision::Move {
                action,
                successor: successor(self.game, h, action),
            },
            None => Decision::Stop(self.game.best(h)),
        }
    }

    /// The decision table of product state `h` (the paper's Table II): per enabled action its
    /// value, the controller's expected number of robot moves when playing it, and the next
    /// robot states (through the adversary's moves) with their probabilities.
    pub fn explain(&self, h: HState, evaluation: &ControllerEvaluation) -> Explanation {
        let (game, mdp, solution) = (self.game, self.mdp.mdp(), self.solution);
        let robot = game.is_robot(h);
        // The controller's expected number of robot moves from MDP state `s` (0 from a sink).
        let expected_moves = |s: MdpState| {
            self.mdp
                .product_state(s)
                .map_or(0.0, |t| evaluation.expected_moves(t))
        };
        let state = node(h);
        let rows = if robot {
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
                        outcomes: self.next_robot_states(choice),
                    }
                })
                .collect()
        } else {
            Vec::new()
        };
        Explanation {
            state: game.state_name(h),
            label: game.label(h),
            robot,
            value: solution.value(state).lower,
            expected_moves: evaluation.expected_moves(h),
            actions: rows,
            chosen: robot
                .then(|| solution.policy(state))
                .flatten()
                .map(|c| mdp.action_name(c).to_string()),
        }
    }

    /// Where `choice` leads once the adversary has moved: the first robot state, absorbing
    /// state or stop sink reached, with the probability of reaching it first (absorption
    /// probabilities through the chance nodes, exact on cycles and diamonds; mass the adversary
    /// keeps among its own states forever is shown as such).
    fn next_robot_states(&self, choice: ChoiceId) -> Vec<Outcome> {
        let (game, mdp) = (self.game, self.mdp.mdp());
        let is_chance = |s: MdpState| {
            !mdp.is_absorbing(s) && self.mdp.product_state(s).is_some_and(|t| !game.is_robot(t))
        };
        first_exits(mdp.successors(choice), is_chance, |s, out| {
            choice_successors(mdp, s, out)
        })
        .into_iter()
        .map(|(s, probability)| match s {
            Some(s) => {
                let value = self.solution.value(s).lower;
                match self.mdp.product_state(s) {
                    Some(t) => Outcome {
                        state: game.state_name(t),
                        label: game.label(t),
                        probability,
                        value,
                    },
                    None => Outcome::sink(self.mdp.state_name(game, s), probability, value),
                }
            }
            None => Outcome::never_leaves(probability),
        })
        .collect()
    }
}

/// How a decision table names the mass the adversary keeps among its own states forever.
pub const NEVER_LEAVES: &str = "(adversary forever)";

/// Goals are sets of sub-tasks, numbered by their masks.
impl<G: SolvedGame> Plan for Controller<'_, G> {
    type Game = G;
    fn game(&self) -> &G {
        self.game
    }
}

impl<G: SolvedGame> Steps for Controller<'_, G> {
    fn num_goals(&self) -> usize {
        1 << self.game.payoffs().num_tasks()
    }
    fn is_goal_target(&self, goal: usize, h: HState) -> bool {
        self.game.is_target(TaskSet(goal as u8), h)
    }
    fn goal_move(&self, goal: usize, h: HState) -> Option<(ActionId, HState)> {
        self.game.reactive_move(TaskSet(goal as u8), h)
    }
    fn step(&self, h: HState) -> Step {
        Step::of(self.decide(h), |set| self.game.payoffs().get(set))
    }
    fn stuck_payoff(&self) -> f64 {
        self.game.payoffs().all()
    }
    fn is_worthless(&self, h: HState) -> bool {
        Controller::is_worthless(self, h)
    }
    fn discount(&self) -> f64 {
        self.solution.discount().get()
    }
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
    /// The state's name: a product state's, a stop sink's such as `stop(phi1)`, or
    /// [`NEVER_LEAVES`].
    pub state: String,
    /// Its label (as in [`Explanation::label`]), `-` for a stop sink.
    pub label: String,
    /// The probability of reaching it first, through the adversary's moves.
    pub probability: f64,
    /// Its value (lower bound).
    pub value: f64,
}

impl Outcome {
    /// A stop sink called `name`, reached with `probability`, worth `value`.
    pub(crate) fn sink(name: String, probability: f64, value: f64) -> Outcome {
        Outcome {
            state: name,
            label: "-".to_string(),
            probability,
            value,
        }
    }

    /// The mass the adversary keeps among its own states forever ([`NEVER_LEAVES`]).
    pub(crate) fn never_leaves(probability: f64) -> Outcome {
        Outcome::sink(NEVER_LEAVES.to_string(), probability, 0.0)
    }
}

/// A certified interval as reports state it: lower ≤ upper ≤ the largest payoff. Rounding in
/// the last bits can put a lower bound a hair above its upper bound or the largest payoff
/// (`300.0000000000001`); both bounds are clamped into `[0, r(all)]` and the lower one to the
/// upper one, which keeps them within the certified error.
pub fn reported_interval(
    interval: crate::mdp::Interval,
    game: &impl SolvedGame,
) -> crate::mdp::Interval {
    clamped(interval, game.payoffs().all())
}

/// `interval` within `[0, top]`, the lower bound at most the upper one: values as reports show
/// them (either engine's).
pub(crate) fn clamped(interval: crate::mdp::Interval, top: f64) -> crate::mdp::Interval {
    let upper = interval.upper.clamp(0.0, top);
    crate::mdp::Interval {
        lower: interval.lower.clamp(0.0, upper),
        upper,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::game::{Payoffs, TaskSet};
    use crate::mdp::solve::{SolveOptions, solve};
    use crate::opportunistic::adversary::{AdversaryModel, SigmaL};
    use crate::opportunistic::build::tests::{build, game};
    use crate::opportunistic::view::SolvedGame;
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
            assert_eq!(controller.decide(hs(2)), Decision::Commit(TaskSet(0b11)));
            // r5 `(W,W,L)`: stop (200) beats `a` (at most 166.7); r1 > r2 so phi1.
            assert_eq!(controller.decide(hs(5)), Decision::Stop(TaskSet(0b01)));
            assert_eq!(controller.decide(hs(8)), Decision::Commit(TaskSet(0b10)));
            assert_eq!(controller.decide(hs(9)), Decision::GiveUp);
        });
        // With r2 > r1, stopping in `(W,W,L)` settles for phi2; with r1 = r2 for phi1.
        let swapped = game().with_payoffs(Payoffs::new(100.0, 200.0, 300.0).unwrap());
        assert_eq!(swapped.best(hs(5)), TaskSet(0b10));
        let equal = game().with_payoffs(Payoffs::new(100.0, 100.0, 300.0).unwrap());
        assert_eq!(equal.best(hs(5)), TaskSet(0b01));
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

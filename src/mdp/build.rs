//! The hypergame MDP (DESIGN.md 3.6).
//!
//! MDP states, in this order: one per robot product state and one per *stuck* adversary product
//! state, in increasing product order, then the two stop sinks `stop(phi1)` (payoff r1) and
//! `stop(best)` (payoff max(r1, r2)). Non-stuck adversary states are chance nodes and are folded
//! away: a robot action whose successor is an adversary state leads to the robot states the
//! adversary model can reach, through any chain of adversary states, with the product of the
//! probabilities along the chain (summed over chains); a cycle of adversary states is an error
//! (the run could stay out of the robot's control forever).
//!
//! By the win-label of a robot state:
//! - `(L,L,L)`: every action, no stop; with no enabled action, absorbing with payoff 0;
//! - `(W,L,L)`: the actions with probability 0 of reaching an `(L,L,L)` robot state next, plus
//!   `stop` → `stop(phi1)`;
//! - `(W,W,L)`: likewise, plus `stop` → `stop(best)`;
//! - `(L,W,L)`: absorbing, payoff r2; `(W,W,W)`: absorbing, payoff r.
//!
//! A stuck adversary state ends the play; the attractor counts it as won for every task, so it
//! is absorbing with payoff r. An impossible label (`Win(phi)` outside `Win(phi1) ∩ Win(phi2)`)
//! is an error. The initial state must be a robot state. Arena actions keep their names; `stop`
//! is reserved.

use bit_set::BitSet;
use thiserror::Error;

use super::adversary::AdversaryModel;
use super::model::{Mdp, MdpBuilder, MdpError};
use super::solve::Solution;
use super::view::{SolvedGame, win_label};
use crate::game::{Task, WinLabel};

/// The reserved action name of the robot's decision to settle for a sub-task.
pub const STOP: &str = "stop";

const NONE: u32 = u32::MAX;

/// The payoffs of `phi1`, `phi2` and `phi`: positive, with r ≥ r1 + r2.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Payoffs {
    r1: f64,
    r2: f64,
    r: f64,
}

impl Payoffs {
    pub fn new(r1: f64, r2: f64, r: f64) -> Result<Payoffs, BuildError> {
        let positive = |x: f64| x.is_finite() && x > 0.0;
        if !(positive(r1) && positive(r2) && positive(r) && r >= r1 + r2) {
            return Err(BuildError::Payoffs { r1, r2, r });
        }
        Ok(Payoffs { r1, r2, r })
    }

    pub fn get(self, goal: Task) -> f64 {
        match goal {
            Task::Phi1 => self.r1,
            Task::Phi2 => self.r2,
            Task::Phi => self.r,
        }
    }

    /// The sub-task a `stop` in `(W,W,L)` settles for: phi1 unless r2 pays strictly more.
    pub fn better_subtask(self) -> Task {
        if self.r2 > self.r1 {
            Task::Phi2
        } else {
            Task::Phi1
        }
    }
}

impl Default for Payoffs {
    /// The case study's payoffs.
    fn default() -> Self {
        Payoffs {
            r1: 200.0,
            r2: 100.0,
            r: 300.0,
        }
    }
}

#[derive(Debug, Error, PartialEq)]
pub enum BuildError {
    #[error("payoffs must be positive with r >= r1 + r2 (got r1 = {r1}, r2 = {r2}, r = {r})")]
    Payoffs { r1: f64, r2: f64, r: f64 },
    #[error("state {state} has the impossible win-label {label}")]
    ImpossibleLabel { state: String, label: String },
    #[error("the adversary states from {state} can cycle without the robot ever moving")]
    AdversaryCycle { state: String },
    #[error("the initial state {state} is not a robot state")]
    InitialNotRobot { state: String },
    #[error("the arena action `stop` clashes with the reserved stop action")]
    ReservedAction,
    #[error(transparent)]
    Mdp(#[from] MdpError),
}

/// How the MDP treats a robot state, by its win-label.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NodeKind {
    /// `(L,L,L)`.
    Losing,
    /// `(W,L,L)`.
    Phi1Only,
    /// `(W,W,L)`.
    BothSubtasks,
    /// `(L,W,L)`.
    Phi2Only,
    /// `(W,W,W)`.
    Phi,
}

/// The kind of robot state `h`; `None` for an impossible label.
pub fn node_kind(game: &impl SolvedGame, h: u32) -> Option<NodeKind> {
    match win_label(game, h) {
        WinLabel {
            phi: true,
            phi1: true,
            phi2: true,
        } => Some(NodeKind::Phi),
        WinLabel { phi: true, .. } => None,
        WinLabel {
            phi1: false,
            phi2: false,
            ..
        } => Some(NodeKind::Losing),
        WinLabel {
            phi1: true,
            phi2: false,
            ..
        } => Some(NodeKind::Phi1Only),
        WinLabel {
            phi1: true,
            phi2: true,
            ..
        } => Some(NodeKind::BothSubtasks),
        WinLabel {
            phi1: false,
            phi2: true,
            ..
        } => Some(NodeKind::Phi2Only),
    }
}

/// The hypergame MDP with the maps between its states and the product's.
#[derive(Clone, Debug, PartialEq)]
pub struct HypergameMdp {
    mdp: Mdp,
    /// Product state → MDP state (`NONE` for folded adversary states).
    node: Vec<u32>,
    /// MDP state → product state (`NONE` for the sinks).
    product: Vec<u32>,
    /// The MDP states that are robot states.
    robot: BitSet,
    /// MDP choice → arena action (`NONE` for `stop`).
    choice_action: Vec<u32>,
}

/// The sizes reported for a solved hypergame MDP.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct MdpSizes {
    /// Decision nodes in the sense of the paper: every robot product state.
    pub robot_states: u32,
    /// Robot states made absorbing (`(L,W,L)`, `(W,W,W)`, stuck `(L,L,L)`).
    pub absorbing: u32,
    /// Robot states of positive value.
    pub with_opportunity: u32,
    /// Robot states of value 0.
    pub without_opportunity: u32,
}

impl HypergameMdp {
    pub fn build(
        game: &impl SolvedGame,
        adversary: &AdversaryModel,
        payoffs: Payoffs,
    ) -> Result<HypergameMdp, BuildError> {
        let n = game.num_states();
        let name = |h: u32| game.state_name(h);
        if !game.is_robot(game.initial()) {
            return Err(BuildError::InitialNotRobot {
                state: name(game.initial()),
            });
        }
        let mut node = vec![NONE; n as usize];
        let mut product = Vec::new();
        for h in 0..n {
            if game.is_robot(h) || game.edges(h).next().is_none() {
                node[h as usize] = product.len() as u32;
                product.push(h);
            }
        }
        let stop_phi1 = product.len() as u32;
        let stop_best = stop_phi1 + 1;

        let mut builder = MdpBuilder::new();
        let stop = builder.action(STOP)?;
        let mut actions = Vec::new();
        for h in 0..n {
            for (a, _) in game.edges(h) {
                if actions.len() <= a as usize {
                    actions.resize(a as usize + 1, NONE);
                }
                if actions[a as usize] == NONE {
                    if game.action_name(a) == STOP {
                        return Err(BuildError::ReservedAction);
                    }
                    actions[a as usize] = builder.action(game.action_name(a))?;
                }
            }
        }
        let is_losing_robot = |t: u32| {
            game.is_robot(product[t as usize])
                && node_kind(game, product[t as usize]) == Some(NodeKind::Losing)
        };
        let mut robot = BitSet::with_capacity(product.len());
        let mut choice_action = Vec::new();
        let mut outcomes = Vec::new();
        for &h in &product {
            let kind = if game.is_robot(h) {
                node_kind(game, h).ok_or_else(|| BuildError::ImpossibleLabel {
                    state: name(h),
                    label: win_label(game, h).to_string(),
                })?
            } else {
                NodeKind::Phi
            };
            let state = match kind {
                NodeKind::Phi => builder.add_absorbing_state(payoffs.r)?,
                NodeKind::Phi2Only => builder.add_absorbing_state(payoffs.r2)?,
                NodeKind::Losing if game.edges(h).next().is_none() => {
                    builder.add_absorbing_state(0.0)?
                }
                _ => {
                    let state = builder.add_decision_state()?;
                    for (a, t) in game.edges(h) {
                        outcomes.clear();
                        fold(
                            game,
                            adversary,
                            &node,
                            t,
                            1.0,
                            &mut Vec::new(),
                            &mut outcomes,
                        )?;
                        if kind != NodeKind::Losing
                            && outcomes.iter().any(|&(t, _)| is_losing_robot(t))
                        {
                            continue;
                        }
                        builder.add_choice(actions[a as usize], &outcomes)?;
                        choice_action.push(a);
                    }
                    match kind {
                        NodeKind::Phi1Only => {
                            builder.add_choice(stop, &[(stop_phi1, 1.0)])?;
                            choice_action.push(NONE);
                        }
                        NodeKind::BothSubtasks => {
                            builder.add_choice(stop, &[(stop_best, 1.0)])?;
                            choice_action.push(NONE);
                        }
                        _ => {}
                    }
                    state
                }
            };
            if game.is_robot(h) {
                robot.insert(state as usize);
            }
            builder.set_state_name(state, name(h))?;
        }
        builder.add_absorbing_state(payoffs.r1)?;
        builder.set_state_name(stop_phi1, "stop(phi1)")?;
        builder.add_absorbing_state(payoffs.r1.max(payoffs.r2))?;
        builder.set_state_name(stop_best, "stop(best)")?;
        builder.set_initial(node[game.initial() as usize]);
        product.extend([NONE, NONE]);
        Ok(HypergameMdp {
            mdp: builder.build()?,
            node,
            product,
            robot,
            choice_action,
        })
    }

    pub fn mdp(&self) -> &Mdp {
        &self.mdp
    }

    /// The MDP state of robot (or stuck adversary) product state `h`.
    pub fn node(&self, h: u32) -> Option<u32> {
        Some(self.node[h as usize]).filter(|&s| s != NONE)
    }

    /// The product state of MDP state `s`; `None` for the stop sinks.
    pub fn product_state(&self, s: u32) -> Option<u32> {
        Some(self.product[s as usize]).filter(|&h| h != NONE)
    }

    /// The arena action of MDP choice `choice`; `None` for `stop`.
    pub fn arena_action(&self, choice: u32) -> Option<u32> {
        Some(self.choice_action[choice as usize]).filter(|&a| a != NONE)
    }

    pub fn sizes(&self, solution: &Solution) -> MdpSizes {
        let robot_nodes = || self.robot.iter().map(|s| s as u32);
        let robot_states = self.robot.count() as u32;
        let with_opportunity = robot_nodes()
            .filter(|&s| solution.value(s).lower > 0.0)
            .count() as u32;
        MdpSizes {
            robot_states,
            absorbing: robot_nodes().filter(|&s| self.mdp.is_absorbing(s)).count() as u32,
            with_opportunity,
            without_opportunity: robot_states - with_opportunity,
        }
    }
}

/// Adds to `outcomes` the MDP states reached, with their probabilities, when the play enters
/// product state `t` with probability `p`, folding adversary chance nodes (`chain` holds the
/// adversary states being folded, to detect cycles).
fn fold(
    game: &impl SolvedGame,
    adversary: &AdversaryModel,
    node: &[u32],
    t: u32,
    p: f64,
    chain: &mut Vec<u32>,
    outcomes: &mut Vec<(u32, f64)>,
) -> Result<(), BuildError> {
    if node[t as usize] != NONE {
        outcomes.push((node[t as usize], p));
        return Ok(());
    }
    if chain.contains(&t) {
        return Err(BuildError::AdversaryCycle {
            state: game.state_name(t),
        });
    }
    chain.push(t);
    for ((_, next), &q) in game.edges(t).zip(adversary.distribution(t)) {
        if q > 0.0 {
            fold(game, adversary, node, next, p * q, chain, outcomes)?;
        }
    }
    chain.pop();
    Ok(())
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::mdp::adversary::SigmaL;
    use crate::mdp::solve::{SolveOptions, solve};
    use crate::mdp::view::testing::ToyGame;

    /// A game exercising every rule (MDP node in brackets):
    /// - r0 [0] `(W,L,L)`: `a` → a1 (outside Win(phi1): sigma_W keeps only its safe `y` → r3
    ///   `(L,L,L)`, so `a` is filtered), `b` → a4 (in Win(phi1), uniform: r2 or r5), `c` → r5;
    /// - r2 [1] `(W,W,W)`; r3 [2] `(L,L,L)`: `a` → r3, `b` → r9, `c` → a10 (stuck adversary);
    /// - r5 [3] `(W,W,L)`: `a` → a6, which goes to a7 or r8 (a7 then to r2 or r5): a chain;
    ///   `b` → r3 is filtered;
    /// - r8 [4] `(L,W,L)`; r9 [5] `(L,L,L)` stuck; a10 [6] stuck; stop(phi1) [7]; stop(best) [8].
    pub(crate) fn game() -> ToyGame {
        let mut g = ToyGame::new(&["a", "b", "c", "x", "y"]);
        let r0 = g.state(true, "WLL", 2);
        let a1 = g.state(false, "LLL", 0);
        let r2 = g.state(true, "WWW", 0);
        let r3 = g.state(true, "LLL", 0);
        let a4 = g.state(false, "WLL", 1);
        let r5 = g.state(true, "WWL", 1);
        let a6 = g.state(false, "WWL", 1);
        let a7 = g.state(false, "WLL", 1);
        let r8 = g.state(true, "LWL", 0);
        let r9 = g.state(true, "LLL", 0);
        let a10 = g.state(false, "WWW", 0);
        for (from, action, to) in [
            (r0, "a", a1),
            (r0, "b", a4),
            (r0, "c", r5),
            (a1, "x", r2),
            (a1, "y", r3),
            (r3, "a", r3),
            (r3, "b", r9),
            (r3, "c", a10),
            (a4, "x", r2),
            (a4, "y", r5),
            (r5, "a", a6),
            (r5, "b", r3),
            (a6, "x", a7),
            (a6, "y", r8),
            (a7, "x", r2),
            (a7, "y", r5),
        ] {
            g.edge(from, action, to);
        }
        g
    }

    pub(crate) fn build(g: &ToyGame) -> HypergameMdp {
        let adversary = AdversaryModel::new(g, &SigmaL::Uniform).unwrap();
        HypergameMdp::build(g, &adversary, Payoffs::default()).unwrap()
    }

    type Choices = Vec<(String, Vec<(u32, f64)>)>;

    fn choices(mdp: &Mdp, s: u32) -> Choices {
        mdp.choices(s)
            .map(|c| (mdp.action_name(c).to_string(), mdp.successors(c).collect()))
            .collect()
    }

    fn expect(list: &[(&str, &[(u32, f64)])]) -> Choices {
        list.iter()
            .map(|(a, d)| (a.to_string(), d.to_vec()))
            .collect()
    }

    #[test]
    fn choices_stop_and_absorbing_states_follow_the_win_labels() {
        let g = game();
        let built = build(&g);
        let mdp = built.mdp();
        assert_eq!(mdp.num_states(), 9);
        assert_eq!(mdp.initial(), 0);
        assert_eq!(
            choices(mdp, 0),
            expect(&[
                ("b", &[(1, 0.5), (3, 0.5)]),
                ("c", &[(3, 1.0)]),
                ("stop", &[(7, 1.0)])
            ])
        );
        assert_eq!(
            choices(mdp, 2),
            expect(&[("a", &[(2, 1.0)]), ("b", &[(5, 1.0)]), ("c", &[(6, 1.0)])])
        );
        assert_eq!(
            choices(mdp, 3),
            expect(&[
                ("a", &[(1, 0.25), (3, 0.25), (4, 0.5)]),
                ("stop", &[(8, 1.0)])
            ])
        );
        let payoffs: Vec<Option<f64>> = (0..9).map(|s| mdp.payoff(s)).collect();
        assert_eq!(
            payoffs,
            [
                None,
                Some(300.0),
                None,
                None,
                Some(100.0),
                Some(0.0),
                Some(300.0),
                Some(200.0),
                Some(200.0)
            ]
        );
        assert_eq!(mdp.state_name(0), Some("h0"));
        assert_eq!(mdp.state_name(6), Some("h10"));
        assert_eq!(mdp.state_name(8), Some("stop(best)"));
        assert_eq!(
            (built.node(5), built.node(4), built.product_state(3)),
            (Some(3), None, Some(5))
        );
    }

    #[test]
    fn sizes_and_values_match_the_hand_computation() {
        let g = game();
        let built = build(&g);
        let solution = solve(built.mdp(), &SolveOptions::default()).unwrap();
        // r5: stop pays 200; `a` pays 0.25·300 + 0.25·V + 0.5·100, at most 166.7.
        // r0: `b` pays 0.5·300 + 0.5·200 = 250. r3: `c` reaches the stuck adversary: 300.
        for (s, v) in [(0, 250.0), (2, 300.0), (3, 200.0), (5, 0.0)] {
            let value = solution.value(s);
            assert!(
                value.lower <= v + 1e-9 && v - 1e-9 <= value.upper,
                "state {s}: {value:?}"
            );
        }
        assert_eq!(built.mdp().action_name(solution.policy(0).unwrap()), "b");
        assert_eq!(
            built.sizes(&solution),
            MdpSizes {
                robot_states: 6,
                absorbing: 3,
                with_opportunity: 5,
                without_opportunity: 1
            }
        );
    }

    #[test]
    fn payoffs_are_checked() {
        assert!(Payoffs::new(1.0, 2.0, 3.0).is_ok());
        assert!(matches!(
            Payoffs::new(1.0, 2.0, 2.9),
            Err(BuildError::Payoffs { .. })
        ));
        assert!(Payoffs::new(0.0, 2.0, 3.0).is_err());
        assert!(Payoffs::new(f64::NAN, 2.0, 3.0).is_err());
    }

    #[test]
    fn adversary_cycles_and_impossible_labels_are_errors() {
        let mut g = game();
        g.edge(7, "x", 6); // a7 → a6 → a7
        g.edges[7].swap(0, 2);
        let adversary = AdversaryModel::new(&g, &SigmaL::Uniform).unwrap();
        assert!(matches!(
            HypergameMdp::build(&g, &adversary, Payoffs::default()),
            Err(BuildError::AdversaryCycle { .. })
        ));
        let mut g = game();
        g.ranks[9] = [None, None, Some(0)];
        let adversary = AdversaryModel::new(&g, &SigmaL::Uniform).unwrap();
        assert!(matches!(
            HypergameMdp::build(&g, &adversary, Payoffs::default()),
            Err(BuildError::ImpossibleLabel { .. })
        ));
    }
}

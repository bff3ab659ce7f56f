//! The general hypergame MDP (DESIGN.md 3.8): k sub-tasks, payoffs on subsets, any believed task,
//! and its controller.
//!
//! MDP states: product state `h` is MDP state `h`; then one stop sink per non-empty set T of
//! sub-tasks, in mask order (`stop(A,B)`, payoff `r(T)`). Adversary states are chance nodes as in
//! the paper's MDP (one instant choice with the model's positive-probability moves; sigma_W outside
//! `Win(psi)`); a stuck adversary state is absorbing with payoff `r(all)`. A robot state is
//! absorbing with payoff `gr(h)` when no robot state of larger guarantee can be reached from it
//! (through any robot move and the adversary's moves of positive probability; a stuck adversary
//! state counts as `r(all)`): one backward search ([`greatest_reachable_level`]). Otherwise it
//! has `stop` (instant, to the sink of its preferred winnable set, when `gr(h) > 0`) and the arena
//! actions the [`Risk`] rule allows, judged on the least guarantee of the next robot state
//! ([`least_next_level`]). Levels are the ranks of the distinct payoff values, 0 for payoff 0.
//!
//! Cost: two backward searches and one pass over the product, O(|H| + |edges|) plus the
//! guarantee of each state (at most 2^k − 1 membership tests); the MDP has |H| + 2^k − 1 states.

use serde::Serialize;

use super::adversary::AdversaryModel;
use super::build::{BuildError, CHANCE, STOP};
use super::evaluate::{Plan, Step};
use super::levels::{UNREACHED, greatest_reachable_level, least_next_level};
use super::model::{Mdp, MdpBuilder};
use super::solve::{Interval, Solution};
use super::view::GameView;
use crate::arena::{Arena, Owner, StateId};
use crate::game::{Hypergame, SubsetPayoffs, TaskRegions, TaskSet};

const NONE: u32 = u32::MAX;

/// Which arena actions a robot state that can settle for something keeps (DESIGN.md 3.8).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Risk {
    /// Once `gr(h) > 0`, no action with a positive probability of a next robot state of
    /// guarantee 0 (the paper's rule).
    #[default]
    Paper,
    /// No action with a positive probability of a next robot state of lower guarantee.
    Strict,
    /// Every action.
    Neutral,
}

/// A product of k sub-task automata (and psi's) with its regions and payoffs, as the MDP stage
/// sees it.
pub struct SubtaskGame<'g, 'a> {
    game: &'g Hypergame<'a>,
    regions: &'g TaskRegions,
    payoffs: &'g SubsetPayoffs,
    names: &'g [String],
    /// Per product state: its preferred winnable set (mask 0: none).
    best: Vec<TaskSet>,
}

impl<'g, 'a> SubtaskGame<'g, 'a> {
    pub fn new(
        game: &'g Hypergame<'a>,
        regions: &'g TaskRegions,
        payoffs: &'g SubsetPayoffs,
        names: &'g [String],
    ) -> Self {
        let best = (0..game.num_states() as u32)
            .map(|h| regions.best(payoffs, h).unwrap_or_default())
            .collect();
        SubtaskGame {
            game,
            regions,
            payoffs,
            names,
            best,
        }
    }

    pub fn game(&self) -> &Hypergame<'a> {
        self.game
    }

    pub fn regions(&self) -> &TaskRegions {
        self.regions
    }

    pub fn payoffs(&self) -> &SubsetPayoffs {
        self.payoffs
    }

    /// The sub-tasks' names, in order.
    pub fn names(&self) -> &[String] {
        self.names
    }

    /// The set the robot commits to when it settles in `h` (empty: none is winnable).
    pub fn best(&self, h: u32) -> TaskSet {
        self.best[h as usize]
    }

    /// `gr(h)`.
    pub fn guarantee(&self, h: u32) -> f64 {
        self.payoffs.get(self.best(h))
    }

    /// Whether every sub-task of `set` is satisfied in `h` (final in its automaton).
    pub fn is_target(&self, set: TaskSet, h: u32) -> bool {
        set.iter().all(|i| self.game.is_final(i, h))
    }

    /// The move of the robot's rank-decreasing strategy for `Win(set)` in `h` (its first allowed
    /// edge).
    pub fn reactive_move(&self, set: TaskSet, h: u32) -> Option<(u32, u32)> {
        let win = self.regions.win(set);
        self.game
            .edges(h)
            .find(|&(_, t)| win.allows_robot_edge(h, t))
    }
}

impl GameView for SubtaskGame<'_, '_> {
    fn num_states(&self) -> u32 {
        self.game.num_states() as u32
    }
    fn initial(&self) -> u32 {
        self.game.initial()
    }
    fn is_robot(&self, h: u32) -> bool {
        self.game.owner(h) == Owner::Robot
    }
    fn edges(&self, h: u32) -> impl Iterator<Item = (u32, u32)> + '_ {
        self.game.edges(h)
    }
    fn action_name(&self, action: u32) -> &str {
        self.game.arena().action_name(action)
    }
    fn state_name(&self, h: u32) -> String {
        self.game.name(h)
    }
    fn arena(&self) -> &Arena {
        self.game.arena()
    }
    fn arena_state(&self, h: u32) -> StateId {
        self.game.arena_state(h)
    }
    fn believed_win(&self, h: u32) -> bool {
        self.regions.believed().contains(h)
    }
}

/// The general hypergame MDP. MDP state `h` is product state `h`; the stop sinks follow.
#[derive(Clone, Debug, PartialEq)]
pub struct SubtaskMdp {
    mdp: Mdp,
    /// MDP choice → arena action (`NONE` for `stop` and chance choices).
    choice_action: Vec<u32>,
    num_product_states: u32,
}

/// The sizes reported for a solved general MDP.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct SubtaskSizes {
    /// Every robot product state.
    pub robot_states: u32,
    /// Robot states where nothing better than `gr(h)` can ever come (absorbing).
    pub absorbing: u32,
    /// Other robot states of positive value.
    pub with_opportunity: u32,
    /// The remaining robot states (value 0). The three add up to `robot_states`.
    pub without_opportunity: u32,
    /// Robot states whose value exceeds their guarantee (by more than the certified error).
    pub above_guarantee: u32,
    /// Robot states without an enabled action (also counted above).
    pub stuck: u32,
    /// Adversary states that move (chance nodes).
    pub chance_nodes: u32,
    pub states: u32,
    pub choices: u32,
    pub transitions: u32,
}

impl SubtaskMdp {
    pub fn build(
        game: &SubtaskGame,
        adversary: &AdversaryModel,
        risk: Risk,
    ) -> Result<SubtaskMdp, BuildError> {
        let n = game.num_states();
        let payoffs = game.payoffs();
        let k = payoffs.num_tasks();
        let mut builder = MdpBuilder::new();
        let stop = builder.action(STOP)?;
        let chance = builder.action(CHANCE)?;
        let mut actions = Vec::with_capacity(game.arena().actions().len());
        for name in game.arena().actions() {
            if name == STOP {
                return Err(BuildError::ReservedAction);
            }
            actions.push(builder.action(name)?);
        }
        // Levels: ranks of the distinct payoffs (0 is rank 0); a stuck adversary state is worth
        // r(all), the largest.
        let mut values: Vec<f64> = std::iter::once(0.0)
            .chain(TaskSet::non_empty(k).map(|set| payoffs.get(set)))
            .collect();
        values.sort_by(f64::total_cmp);
        values.dedup();
        let rank = |value: f64| values.partition_point(|&v| v < value) as u32;
        let top = rank(payoffs.all());
        let level = |h: u32| {
            if game.is_robot(h) {
                rank(game.guarantee(h))
            } else {
                top
            }
        };
        let next = least_next_level(game, adversary, level);
        let reachable = greatest_reachable_level(game, adversary, level);
        let mut choice_action = Vec::new();
        let mut scratch = Vec::new();
        let mut outcomes = Vec::new();
        for h in 0..n {
            let stuck = game.edges(h).next().is_none();
            let state = if !game.is_robot(h) {
                if stuck {
                    builder.add_absorbing_state(payoffs.all())?
                } else {
                    let state = builder.add_decision_state()?;
                    adversary.positive_moves(game, h, &mut scratch, &mut outcomes);
                    builder.add_instant_choice(chance, &outcomes)?;
                    choice_action.push(NONE);
                    state
                }
            } else {
                let own = level(h);
                if reachable[h as usize] <= own {
                    builder.add_absorbing_state(game.guarantee(h))?
                } else {
                    let state = builder.add_decision_state()?;
                    for (a, t) in game.edges(h) {
                        let least = next[t as usize];
                        let allowed = least == UNREACHED
                            || match risk {
                                Risk::Paper => own == 0 || least > 0,
                                Risk::Strict => least >= own,
                                Risk::Neutral => true,
                            };
                        if allowed {
                            builder.add_choice(actions[a as usize], &[(t, 1.0)])?;
                            choice_action.push(a);
                        }
                    }
                    if own > 0 {
                        let sink = n + game.best(h).0 as u32 - 1;
                        builder.add_instant_choice(stop, &[(sink, 1.0)])?;
                        choice_action.push(NONE);
                    }
                    state
                }
            };
            builder.set_state_name(state, game.state_name(h))?;
        }
        for set in TaskSet::non_empty(k) {
            let sink = builder.add_absorbing_state(payoffs.get(set))?;
            builder.set_state_name(sink, format!("stop({})", set.display(game.names())))?;
        }
        builder.set_initial(game.initial());
        Ok(SubtaskMdp {
            mdp: builder.build()?,
            choice_action,
            num_product_states: n,
        })
    }

    pub fn mdp(&self) -> &Mdp {
        &self.mdp
    }

    /// The product state of MDP state `s`; `None` for the stop sinks.
    pub fn product_state(&self, s: u32) -> Option<u32> {
        (s < self.num_product_states).then_some(s)
    }

    /// The arena action of MDP choice `choice`; `None` for `stop` and chance choices.
    pub fn arena_action(&self, choice: u32) -> Option<u32> {
        Some(self.choice_action[choice as usize]).filter(|&a| a != NONE)
    }

    pub fn sizes(&self, game: &SubtaskGame, solution: &Solution) -> SubtaskSizes {
        let mut sizes = SubtaskSizes {
            robot_states: 0,
            absorbing: 0,
            with_opportunity: 0,
            without_opportunity: 0,
            above_guarantee: 0,
            stuck: 0,
            chance_nodes: 0,
            states: self.mdp.num_states(),
            choices: self.mdp.num_choices(),
            transitions: self.mdp.num_transitions(),
        };
        for h in 0..game.num_states() {
            let stuck = game.edges(h).next().is_none();
            if !game.is_robot(h) {
                sizes.chance_nodes += u32::from(!stuck);
                continue;
            }
            sizes.robot_states += 1;
            sizes.stuck += u32::from(stuck);
            let value = solution.value(h);
            sizes.above_guarantee += u32::from(value.lower > game.guarantee(h) + solution.gap());
            *if self.mdp.is_absorbing(h) {
                &mut sizes.absorbing
            } else if value.upper > 0.0 {
                &mut sizes.with_opportunity
            } else {
                &mut sizes.without_opportunity
            } += 1;
        }
        sizes
    }
}

/// What the general controller does in a robot state before it commits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SubtaskDecision {
    Move {
        action: u32,
        successor: u32,
    },
    /// Absorbing: commit to this set here.
    Commit(TaskSet),
    /// Play `stop` (instant) and commit to this set.
    Stop(TaskSet),
    /// Value 0: nothing can be gained.
    GiveUp,
}

/// The opportunistic controller of a solved general MDP: the policy until it absorbs or stops,
/// then the reactive strategy of the preferred winnable set.
pub struct SubtaskController<'a> {
    pub game: &'a SubtaskGame<'a, 'a>,
    pub mdp: &'a SubtaskMdp,
    pub solution: &'a Solution,
}

impl SubtaskController<'_> {
    pub fn value(&self, h: u32) -> Interval {
        self.solution.value(h)
    }

    pub fn decide(&self, h: u32) -> SubtaskDecision {
        let mdp = self.mdp.mdp();
        if self.value(h).upper == 0.0 {
            return SubtaskDecision::GiveUp;
        }
        if mdp.is_absorbing(h) {
            return SubtaskDecision::Commit(self.game.best(h));
        }
        let Some(choice) = self.solution.policy(h) else {
            return SubtaskDecision::GiveUp;
        };
        match self.mdp.arena_action(choice) {
            Some(action) => {
                let successor = self
                    .game
                    .edges(h)
                    .find(|&(a, _)| a == action)
                    .map(|(_, t)| t)
                    .expect("MDP choices are enabled actions");
                SubtaskDecision::Move { action, successor }
            }
            None => SubtaskDecision::Stop(self.game.best(h)),
        }
    }
}

/// Goals are task-set masks.
impl<'a> Plan for SubtaskController<'a> {
    type Game = SubtaskGame<'a, 'a>;
    fn game(&self) -> &Self::Game {
        self.game
    }
    fn num_goals(&self) -> usize {
        1 << self.game.payoffs().num_tasks()
    }
    fn is_goal_target(&self, goal: usize, h: u32) -> bool {
        self.game.is_target(TaskSet(goal as u8), h)
    }
    fn goal_move(&self, goal: usize, h: u32) -> Option<u32> {
        self.game
            .reactive_move(TaskSet(goal as u8), h)
            .map(|(_, t)| t)
    }
    fn step(&self, h: u32) -> Step {
        match self.decide(h) {
            SubtaskDecision::Move { successor, .. } => Step::Move(successor),
            SubtaskDecision::Commit(set) | SubtaskDecision::Stop(set) => Step::Commit {
                goal: set.0 as usize,
                payoff: self.game.payoffs().get(set),
            },
            SubtaskDecision::GiveUp => Step::GiveUp,
        }
    }
    fn stuck_payoff(&self) -> f64 {
        self.game.payoffs().all()
    }
    fn is_worthless(&self, h: u32) -> bool {
        self.value(h).upper == 0.0
    }
    fn discount(&self) -> f64 {
        self.solution.discount().get()
    }
}

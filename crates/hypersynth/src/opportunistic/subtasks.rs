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
use super::build::{
    BuildError, CHANCE, ChanceMoves, RobotCategory, STOP, count_sizes, node, product_state,
};
use super::controller::{Explanation, StateNames, explain};
use super::evaluate::{ControllerEvaluation, Plan, Step};
use super::levels::{greatest_reachable_level, least_next_level};
use super::view::{GameView, OverHypergame, successor};
use crate::arena::ActionId;
use crate::game::{HState, Hypergame, SubsetPayoffs, TaskRegions, TaskSet};
use crate::index::Id;
use crate::mdp::model::{ChoiceId, Mdp, MdpBuilder, MdpState};
use crate::mdp::solve::{Interval, Solution};
use crate::stage::{Meter, Stage};

/// Which arena actions a robot state that can settle for something keeps (DESIGN.md 3.8).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
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
    /// The MDP stage's view of `game`, its `regions` and `payoffs`, with the sub-tasks named
    /// `names` (in product order); computes every state's preferred winnable set once.
    pub fn new(
        game: &'g Hypergame<'a>,
        regions: &'g TaskRegions,
        payoffs: &'g SubsetPayoffs,
        names: &'g [String],
    ) -> Self {
        let best = game
            .states()
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

    /// The product the view was built on.
    pub fn game(&self) -> &Hypergame<'a> {
        self.game
    }

    /// The winning regions `Win(T)` of every non-empty set and `Win(psi)`.
    pub fn regions(&self) -> &TaskRegions {
        self.regions
    }

    /// `r(T)` for every set of sub-tasks.
    pub fn payoffs(&self) -> &SubsetPayoffs {
        self.payoffs
    }

    /// The sub-tasks' names, in order.
    pub fn names(&self) -> &[String] {
        self.names
    }

    /// The set the robot commits to when it settles in `h` (empty: none is winnable).
    pub fn best(&self, h: HState) -> TaskSet {
        self.best[h.index()]
    }

    /// `gr(h)`.
    pub fn guarantee(&self, h: HState) -> f64 {
        self.payoffs.get(self.best(h))
    }

    /// Whether every sub-task of `set` is satisfied in `h` (final in its automaton).
    pub fn is_target(&self, set: TaskSet, h: HState) -> bool {
        set.iter().all(|i| self.game.is_final(i, h))
    }

    /// The move of the robot's rank-decreasing strategy for `Win(set)` in `h` (its first allowed
    /// edge).
    pub fn reactive_move(&self, set: TaskSet, h: HState) -> Option<(ActionId, HState)> {
        let win = self.regions.win(set);
        self.game
            .edges(h)
            .find(|&(_, t)| win.allows_robot_edge(h, t))
    }
}

impl OverHypergame for SubtaskGame<'_, '_> {
    fn product(&self) -> &Hypergame<'_> {
        self.game
    }
    fn in_believed_region(&self, h: HState) -> bool {
        self.regions.believed().contains(h)
    }
}

/// The general hypergame MDP. MDP state `h` is product state `h`; the stop sinks follow.
#[derive(Clone, Debug, PartialEq)]
pub struct SubtaskMdp {
    mdp: Mdp,
    /// MDP choice → arena action (`u32::NONE` for `stop` and chance choices).
    choice_action: Vec<ActionId>,
    num_product_states: usize,
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
    /// The MDP's number of states: product states, then one stop sink per non-empty set.
    pub states: u32,
    /// The MDP's number of choices (arena actions, `stop`, and one per chance node).
    pub choices: u32,
    /// The MDP's number of transitions (successor entries over all choices).
    pub transitions: u32,
}

impl SubtaskMdp {
    /// Builds the general MDP of `game` against `adversary`, keeping the arena actions `risk`
    /// allows (see the module documentation); an arena action named `stop` is refused
    /// ([`BuildError::ReservedAction`]).
    pub fn build(
        game: &SubtaskGame,
        adversary: &AdversaryModel,
        risk: Risk,
    ) -> Result<SubtaskMdp, BuildError> {
        let meter = &mut Meter::unobserved(Stage::MdpBuild);
        SubtaskMdp::build_metered(game, adversary, risk, meter)
    }

    /// [`SubtaskMdp::build`], reporting to `meter` the product states added.
    pub fn build_metered(
        game: &SubtaskGame,
        adversary: &AdversaryModel,
        risk: Risk,
        meter: &mut Meter<'_>,
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
        let level = |h: HState| {
            if game.is_robot(h) {
                rank(game.guarantee(h))
            } else {
                top
            }
        };
        let next = least_next_level(game, adversary, level);
        let reachable = greatest_reachable_level(game, adversary, level);
        let mut choice_action = Vec::new();
        let mut chance_moves = ChanceMoves::default();
        meter.set_total(n as u64);
        for h in game.states() {
            meter.set(h.index() as u64);
            let stuck = game.edges(h).next().is_none();
            // MDP state h is product state h: states are added in product order.
            if !game.is_robot(h) {
                if stuck {
                    builder.add_absorbing_state(payoffs.all())?
                } else {
                    let state = builder.add_decision_state()?;
                    builder.add_instant_choice(chance, chance_moves.of(game, adversary, h))?;
                    choice_action.push(u32::NONE);
                    state
                }
            } else {
                let own = level(h);
                if reachable[h.index()] <= own {
                    builder.add_absorbing_state(game.guarantee(h))?
                } else {
                    let state = builder.add_decision_state()?;
                    for (a, t) in game.edges(h) {
                        let least = next[t.index()];
                        // Unreached: a closed set of chance nodes, worth 0 and never lower.
                        let allowed = least.is_none()
                            || match risk {
                                Risk::Paper => own == 0 || least > 0,
                                Risk::Strict => least >= own,
                                Risk::Neutral => true,
                            };
                        if allowed {
                            builder.add_choice(actions[a as usize], &[(node(t), 1.0)])?;
                            choice_action.push(a);
                        }
                    }
                    if own > 0 {
                        let sink = MdpState::new(n + game.best(h).0 as usize - 1);
                        builder.add_instant_choice(stop, &[(sink, 1.0)])?;
                        choice_action.push(u32::NONE);
                    }
                    state
                }
            };
        }
        for set in TaskSet::non_empty(k) {
            builder.add_absorbing_state(payoffs.get(set))?;
        }
        builder.set_initial(node(game.initial()));
        Ok(SubtaskMdp {
            mdp: builder.build()?,
            choice_action,
            num_product_states: n,
        })
    }

    /// The underlying MDP, for the solver.
    pub fn mdp(&self) -> &Mdp {
        &self.mdp
    }

    /// The MDP state of product state `h` (the same number).
    pub fn node(&self, h: HState) -> MdpState {
        node(h)
    }

    /// The product state of MDP state `s`; `None` for the stop sinks.
    pub fn product_state(&self, s: MdpState) -> Option<HState> {
        product_state(s, self.num_product_states)
    }

    /// The display name of MDP state `s`: its product state's, or `stop(SET)` for the sink of a
    /// set of sub-tasks (sinks follow the product states in set-mask order).
    pub fn state_name(&self, game: &SubtaskGame, s: MdpState) -> String {
        match self.product_state(s) {
            Some(h) => game.state_name(h),
            None => {
                let set = TaskSet((s.index() - self.num_product_states + 1) as u8);
                format!("stop({})", set.display(game.names()))
            }
        }
    }

    /// The arena action of MDP choice `choice`; `None` for `stop` and chance choices.
    pub fn arena_action(&self, choice: ChoiceId) -> Option<ActionId> {
        self.choice_action[choice.index()].to_option()
    }

    /// The sizes of the solved MDP in the paper's terms, plus the states worth more than their
    /// guarantee.
    pub fn sizes(&self, game: &SubtaskGame, solution: &Solution) -> SubtaskSizes {
        let mut above_guarantee = 0;
        let sizes = count_sizes(&self.mdp, game, |h| {
            let value = solution.value(node(h));
            above_guarantee += u32::from(value.lower > game.guarantee(h) + solution.gap());
            if self.mdp.is_absorbing(node(h)) {
                RobotCategory::Absorbing
            } else if value.upper > 0.0 {
                RobotCategory::WithOpportunity
            } else {
                RobotCategory::WithoutOpportunity
            }
        });
        SubtaskSizes {
            robot_states: sizes.robot_states,
            absorbing: sizes.absorbing,
            with_opportunity: sizes.with_opportunity,
            without_opportunity: sizes.without_opportunity,
            above_guarantee,
            stuck: sizes.stuck,
            chance_nodes: sizes.chance_nodes,
            states: sizes.states,
            choices: sizes.choices,
            transitions: sizes.transitions,
        }
    }
}

/// What the general controller does in a robot state before it commits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SubtaskDecision {
    /// One robot move: `action` to `successor`.
    Move {
        /// The arena action played.
        action: ActionId,
        /// The product state it leads to.
        successor: HState,
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
    /// The product game with its regions and payoffs.
    pub game: &'a SubtaskGame<'a, 'a>,
    /// The general MDP built from `game`.
    pub mdp: &'a SubtaskMdp,
    /// The MDP's certified solution; its policy is the controller's before committing.
    pub solution: &'a Solution,
}

impl SubtaskController<'_> {
    /// The certified bounds on the value of product state `h`.
    pub fn value(&self, h: HState) -> Interval {
        self.solution.value(node(h))
    }

    /// The decision in robot state `h` before committing: give up where the value is 0, commit
    /// where the MDP absorbs, else the policy's choice (a move, or `stop` to the preferred set).
    pub fn decide(&self, h: HState) -> SubtaskDecision {
        let mdp = self.mdp.mdp();
        if self.value(h).upper == 0.0 {
            return SubtaskDecision::GiveUp;
        }
        if mdp.is_absorbing(node(h)) {
            return SubtaskDecision::Commit(self.game.best(h));
        }
        let Some(choice) = self.solution.policy(node(h)) else {
            return SubtaskDecision::GiveUp;
        };
        match self.mdp.arena_action(choice) {
            Some(action) => {
                let successor = successor(self.game, h, action);
                SubtaskDecision::Move { action, successor }
            }
            None => SubtaskDecision::Stop(self.game.best(h)),
        }
    }
}

impl SubtaskController<'_> {
    /// The label shown for product state `h`: its generalised win-label and guarantee.
    pub fn label(&self, h: HState) -> String {
        format!(
            "{} gr {}",
            self.game.regions().label(h).display(self.game.names()),
            self.game.guarantee(h)
        )
    }

    /// The decision table of product state `h` (as [`super::controller::Controller::explain`]).
    pub fn explain(&self, h: HState, evaluation: &ControllerEvaluation) -> Explanation {
        let names = StateNames {
            product_state: &|s| self.mdp.product_state(s),
            sink_name: &|s| self.mdp.state_name(self.game, s),
        };
        explain(self, self.mdp.mdp(), self.solution, evaluation, h, &names)
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
    fn is_goal_target(&self, goal: usize, h: HState) -> bool {
        self.game.is_target(TaskSet(goal as u8), h)
    }
    fn goal_move(&self, goal: usize, h: HState) -> Option<(ActionId, HState)> {
        self.game.reactive_move(TaskSet(goal as u8), h)
    }
    fn step(&self, h: HState) -> Step {
        match self.decide(h) {
            SubtaskDecision::Move { action, successor } => Step::Move { action, successor },
            SubtaskDecision::Commit(set) => Step::Commit {
                goal: set.0 as usize,
                payoff: self.game.payoffs().get(set),
                stop: false,
            },
            SubtaskDecision::Stop(set) => Step::Commit {
                goal: set.0 as usize,
                payoff: self.game.payoffs().get(set),
                stop: true,
            },
            SubtaskDecision::GiveUp => Step::GiveUp,
        }
    }
    fn stuck_payoff(&self) -> f64 {
        self.game.payoffs().all()
    }
    fn is_worthless(&self, h: HState) -> bool {
        self.value(h).upper == 0.0
    }
    fn discount(&self) -> f64 {
        self.solution.discount().get()
    }
    fn goal_name(&self, goal: usize) -> String {
        TaskSet(goal as u8).display(self.game.names()).to_string()
    }
    fn label(&self, h: HState) -> String {
        SubtaskController::label(self, h)
    }
}

#[cfg(test)]
mod tests {
    //! Hand-solved games, one per rule: the three risk rules on one arena, a belief disjoint
    //! from every sub-task, and three sub-tasks with a bonus for all three.

    use super::*;
    use crate::arena::{Arena, ArenaBuilder, Owner, StateId};
    use crate::automata::{Dfa, Guard};
    use crate::game::{Belief, States};
    use crate::mdp::solve::{Discount, SolveOptions, solve};
    use crate::opportunistic::adversary::SigmaL;

    /// `F p`: 0 waits, 1 final.
    fn eventually(p: &str) -> Dfa {
        let p_holds = Guard::literal(0, true);
        let edges = vec![
            vec![(p_holds.not(), 0), (p_holds, 1)],
            vec![(Guard::always(), 1)],
        ];
        Dfa::new(vec![p.into()], 0, [1].into_iter().collect(), edges).unwrap()
    }

    /// An arena from `(name, robot, labels)` states (the first is initial) and edges.
    fn arena(states: &[(&str, bool, &[&str])], edges: &[(&str, &str, &str)]) -> Arena {
        let mut b = ArenaBuilder::new();
        for &(name, robot, labels) in states {
            let owner = if robot {
                Owner::Robot
            } else {
                Owner::Adversary
            };
            b.add_state(name, owner, labels.iter().copied(), None)
                .unwrap();
        }
        let id = |name: &str| StateId::new(states.iter().position(|s| s.0 == name).unwrap());
        for &(from, action, to) in edges {
            b.add_transition(id(from), action, id(to)).unwrap();
        }
        b.set_initial(StateId::new(0));
        b.build().unwrap()
    }

    struct Solved {
        value: f64,
        choices: Vec<String>,
        decision: SubtaskDecision,
        guarantee: f64,
        label: String,
    }

    /// Solves the general MDP and returns what h0 looks like; the controller's evaluation is
    /// checked against the value on the way.
    #[allow(clippy::too_many_arguments)]
    fn solve_h0(
        arena: &Arena,
        tasks: &[&Dfa],
        psi: Option<&Dfa>,
        belief: Belief,
        payoffs: &SubsetPayoffs,
        risk: Risk,
        g: f64,
    ) -> Solved {
        let names: Vec<String> = ["A", "B", "C"][..tasks.len()]
            .iter()
            .map(|s| s.to_string())
            .collect();
        let mut automata: Vec<(&str, &Dfa)> = names
            .iter()
            .map(String::as_str)
            .zip(tasks.iter().copied())
            .collect();
        automata.extend(psi.map(|psi| ("psi", psi)));
        let product = Hypergame::with_automata(arena, &automata, States::Reachable).unwrap();
        let regions = TaskRegions::compute(&product, tasks.len(), belief);
        let game = SubtaskGame::new(&product, &regions, payoffs, &names);
        let adversary = AdversaryModel::new(&game, &SigmaL::Uniform).unwrap();
        let built = SubtaskMdp::build(&game, &adversary, risk).unwrap();
        let options = SolveOptions {
            discount: Discount::new(g).unwrap(),
            ..SolveOptions::default()
        };
        let solution = solve(built.mdp(), &options).unwrap();
        let controller = SubtaskController {
            game: &game,
            mdp: &built,
            solution: &solution,
        };
        let h0 = game.initial();
        let evaluation = ControllerEvaluation::new(&controller, &adversary, 1e-9, 10_000).unwrap();
        let (value, collected) = (solution.value(built.node(h0)), evaluation.value(h0));
        assert!(
            (value.lower - collected.lower).abs() < 1e-6,
            "{value:?} {collected:?}"
        );
        let mdp = built.mdp();
        Solved {
            value: value.lower,
            choices: mdp
                .choices(built.node(h0))
                .map(|c| mdp.action_name(c).to_string())
                .collect(),
            decision: controller.decide(h0),
            guarantee: game.guarantee(h0),
            label: regions.label(h0).display(&names),
        }
    }

    /// ```text
    /// r0 (robot)  settle → ra {a}            (A for sure: guarantee r(A) = 100)
    ///             gamble → c: x, x2 → rab {a,b} (200), y → rz {} (0)
    ///             half   → d: x → rab (200), y → rb {b} (r(B) = 60)
    /// ```
    /// psi = true: the adversary believes it has lost everywhere and plays uniformly. At g = 1:
    /// settle and stop 100, gamble 2/3 · 200 = 133.3 (risks a state of guarantee 0), half
    /// 0.5 · 200 + 0.5 · 60 = 130 (risks a state of lower guarantee than 100).
    fn risky_arena() -> Arena {
        arena(
            &[
                ("r0", true, &[]),
                ("ra", true, &["a"]),
                ("c", false, &[]),
                ("d", false, &[]),
                ("rab", true, &["a", "b"]),
                ("rz", true, &[]),
                ("rb", true, &["b"]),
            ],
            &[
                ("r0", "settle", "ra"),
                ("r0", "gamble", "c"),
                ("r0", "half", "d"),
                ("c", "x", "rab"),
                ("c", "x2", "rab"),
                ("c", "y", "rz"),
                ("d", "x", "rab"),
                ("d", "y", "rb"),
            ],
        )
    }

    #[test]
    fn each_risk_rule_keeps_the_actions_it_states() {
        let arena = risky_arena();
        let (a, b) = (eventually("a"), eventually("b"));
        let truth = Dfa::new(
            vec![],
            0,
            [0].into_iter().collect(),
            vec![vec![(Guard::always(), 0)]],
        )
        .unwrap();
        let names = ["A".to_string(), "B".to_string()];
        let payoffs =
            SubsetPayoffs::new(&[100.0, 60.0], &[(TaskSet(0b11), 200.0)], &names).unwrap();
        let solved = |risk, g| {
            solve_h0(
                &arena,
                &[&a, &b],
                Some(&truth),
                Belief::Automaton,
                &payoffs,
                risk,
                g,
            )
        };
        let paper = solved(Risk::Paper, 1.0);
        assert_eq!(paper.guarantee, 100.0);
        assert_eq!(paper.label, "{A} {B} | psi W");
        assert_eq!(paper.choices, ["settle", "half", "stop"]);
        assert!((paper.value - 130.0).abs() < 1e-6);
        let half = arena.find_action("half").unwrap();
        assert!(
            matches!(paper.decision, SubtaskDecision::Move { action, .. } if action == half),
            "{:?}",
            paper.decision
        );
        let strict = solved(Risk::Strict, 1.0);
        assert_eq!(strict.choices, ["settle", "stop"]);
        assert!((strict.value - 100.0).abs() < 1e-6);
        // settle and stop tie at g = 1; stop takes no move.
        assert_eq!(strict.decision, SubtaskDecision::Stop(TaskSet(0b01)));
        let neutral = solved(Risk::Neutral, 1.0);
        assert_eq!(neutral.choices, ["settle", "gamble", "half", "stop"]);
        assert!((neutral.value - 400.0 / 3.0).abs() < 1e-6);
        // At g = 0.9 each move costs 10%: gamble 0.9 · 133.3 = 120, half 0.9 · 130 = 117,
        // settle 90, stop 100.
        let neutral = solved(Risk::Neutral, 0.9);
        assert!((neutral.value - 120.0).abs() < 1e-6);
        let strict = solved(Risk::Strict, 0.9);
        assert!((strict.value - 100.0).abs() < 1e-6);
    }

    /// ```text
    /// r0 (robot) go → c (adversary): toA → ra {a}, toZ → rz {z}, block → rx {}
    /// ```
    /// One sub-task A = F a (payoff 100). c is outside Win(A) and outside Win(psi) for either
    /// belief, so it plays sigma_W: uniform over the actions that keep the play outside Win(psi).
    /// Believing psi = F z (a decoy, disjoint from A): toA and block, so A comes with
    /// probability 1/2 (value 50). Believing psi = F a (correctly informed): toZ and block,
    /// value 0.
    #[test]
    fn a_belief_disjoint_from_the_task_is_an_opportunity() {
        let arena = arena(
            &[
                ("r0", true, &[]),
                ("c", false, &[]),
                ("ra", true, &["a"]),
                ("rz", true, &["z"]),
                ("rx", true, &[]),
            ],
            &[
                ("r0", "go", "c"),
                ("c", "toA", "ra"),
                ("c", "toZ", "rz"),
                ("c", "block", "rx"),
            ],
        );
        let (a, z) = (eventually("a"), eventually("z"));
        let payoffs = SubsetPayoffs::new(&[100.0], &[], &["A".to_string()]).unwrap();
        let decoy = solve_h0(
            &arena,
            &[&a],
            Some(&z),
            Belief::Automaton,
            &payoffs,
            Risk::Paper,
            1.0,
        );
        assert_eq!(decoy.guarantee, 0.0);
        assert_eq!(decoy.label, "{} | psi L");
        assert!((decoy.value - 50.0).abs() < 1e-6);
        let informed = solve_h0(
            &arena,
            &[&a],
            None,
            Belief::Tasks(TaskSet(0b1)),
            &payoffs,
            Risk::Paper,
            1.0,
        );
        assert_eq!(informed.value, 0.0);
        assert_eq!(informed.decision, SubtaskDecision::GiveUp);
    }

    /// ```text
    /// r0 (robot, {a}) go → d (adversary): x → rbc {b,c}, y → rb {b}
    /// ```
    /// Three sub-tasks F a, F b, F c, 100 each, 500 for all three; psi = F a. A holds from the
    /// start, so d is in Win(psi) and plays uniformly. r0 can force {A,B} (guarantee 200);
    /// `go` pays 0.5 · 500 + 0.5 · 200 = 350 under every risk rule (rb's guarantee is r0's).
    #[test]
    fn three_sub_tasks_with_a_bonus_for_all() {
        let arena = arena(
            &[
                ("r0", true, &["a"]),
                ("d", false, &[]),
                ("rbc", true, &["b", "c"]),
                ("rb", true, &["b"]),
            ],
            &[("r0", "go", "d"), ("d", "x", "rbc"), ("d", "y", "rb")],
        );
        let (a, b, c) = (eventually("a"), eventually("b"), eventually("c"));
        let names: Vec<String> = ["A", "B", "C"].iter().map(|s| s.to_string()).collect();
        let payoffs =
            SubsetPayoffs::new(&[100.0, 100.0, 100.0], &[(TaskSet(0b111), 500.0)], &names).unwrap();
        for risk in [Risk::Paper, Risk::Strict, Risk::Neutral] {
            let solved = solve_h0(
                &arena,
                &[&a, &b, &c],
                None,
                Belief::Tasks(TaskSet(0b001)),
                &payoffs,
                risk,
                1.0,
            );
            assert_eq!(solved.label, "{A,B} | psi W");
            assert_eq!(solved.guarantee, 200.0);
            assert_eq!(solved.choices, ["go", "stop"]);
            assert!((solved.value - 350.0).abs() < 1e-6, "{risk:?}");
            assert!(matches!(solved.decision, SubtaskDecision::Move { .. }));
        }
    }
}

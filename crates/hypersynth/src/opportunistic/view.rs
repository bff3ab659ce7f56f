//! What the hypergame MDP, its controller and the simulation need to know about a solved
//! hypergame: the product graph ([`GameView`]), and its winning regions, payoffs and
//! presentation ([`SolvedGame`]).
//!
//! [`SolvedHypergame`] is the real one, for both forms: a [`Hypergame`] with its
//! [`TaskRegions`]. Keeping these traits lets every rule of the MDP stage be built and tested on
//! small hand-made games, and keeps it independent of how the product and the attractors are
//! stored.

use super::presentation::Presentation;
use crate::arena::{ActionId, Arena, Owner, StateId};
use crate::game::Wins;
use crate::game::{HState, Hypergame, SubsetPayoffs, TaskRegions, TaskSet};
use crate::index::IdRange;

/// What the MDP stage needs of any product game: states `0..num_states()`, owners, edges, names,
/// the arena underneath and the region the adversary believes the robot wins.
pub trait GameView {
    /// The number of product states; their ids are `0..num_states()`.
    fn num_states(&self) -> usize;
    /// The initial product state `h0`.
    fn initial(&self) -> HState;
    /// Whether the robot moves in `h` (otherwise the adversary does).
    fn is_robot(&self, h: HState) -> bool;
    /// The enabled actions of `h` with their successors, in a fixed order.
    fn edges(&self, h: HState) -> impl Iterator<Item = (ActionId, HState)> + '_;
    /// The name of arena action `action`.
    fn action_name(&self, action: ActionId) -> &str;
    /// The display name of a product state.
    fn state_name(&self, h: HState) -> String;
    /// The arena the product is built on (what the adversary observes).
    fn arena(&self) -> &Arena;
    /// The arena state underlying product state `h`; its edges are `h`'s, in the same order.
    fn arena_state(&self, h: HState) -> StateId;
    /// Whether `h` is in `Win(psi)`, the robot's winning region for the task the adversary
    /// believes it has (`phi1` in the paper's form).
    fn believed_win(&self, h: HState) -> bool;

    /// Every product state, in order.
    fn states(&self) -> IdRange<HState> {
        HState::range(self.num_states())
    }
}

/// The successor of `h` by an MDP choice's arena action (which is enabled in `h`).
pub fn successor(game: &impl GameView, h: HState, action: ActionId) -> HState {
    game.edges(h)
        .find(|&(a, _)| a == action)
        .map(|(_, t)| t)
        .expect("MDP choices are enabled actions")
}

/// A product game whose winning regions are known: k sub-tasks (numbered in product order),
/// the payoff of every set of them, and how it is presented (which also fixes its commitment
/// rule).
pub trait SolvedGame: GameView {
    /// How the problem is named.
    fn presentation(&self) -> &Presentation;
    /// The sub-tasks' names, in order.
    fn names(&self) -> &[String] {
        self.presentation().names()
    }
    /// `r(T)` for every set of sub-tasks.
    fn payoffs(&self) -> &SubsetPayoffs;
    /// Whether `h` is in `Win(set)`.
    fn wins(&self, set: TaskSet, h: HState) -> bool;
    /// Whether `h` satisfies every sub-task of `set` already (each final in its DFA).
    fn is_target(&self, set: TaskSet, h: HState) -> bool;
    /// The move of the robot's rank-decreasing strategy for `Win(set)` in robot state `h` (the
    /// first allowed edge), `None` outside `Win(set)`.
    fn reactive_move(&self, set: TaskSet, h: HState) -> Option<(ActionId, HState)>;

    /// The set the robot commits to when it settles in `h`: the most preferred set it wins
    /// (largest payoff, then fewer sub-tasks, then earlier ones); empty when it wins none.
    fn best(&self, h: HState) -> TaskSet {
        self.payoffs()
            .best(|set| self.wins(set, h))
            .unwrap_or_default()
    }

    /// `gr(h)`: what the robot can settle for in `h` (0 when it wins no set).
    fn guarantee(&self, h: HState) -> f64 {
        self.payoffs().get(self.best(h))
    }

    /// How reports name a set of sub-tasks: `phi1`, `phi2`, `phi` in the paper's form, `A,B`
    /// in general.
    fn set_name(&self, set: TaskSet) -> String {
        self.presentation().set_name(set)
    }

    /// How reports label product state `h`: its win-label `(W, L, L)` in the paper's form, its
    /// maximal winnable sets, belief and guarantee (`{A} {B} | psi W gr 200`) in general.
    fn label(&self, h: HState) -> String;
}

/// A [`Hypergame`] with its winning regions, the payoffs of the sets of its sub-tasks and its
/// presentation.
pub struct SolvedHypergame<'g, 'a> {
    game: &'g Hypergame<'a>,
    regions: &'g TaskRegions,
    payoffs: &'g SubsetPayoffs,
    presentation: &'g Presentation,
    /// Per product state, the set it settles for (computed once: the MDP build, the controller
    /// and the evaluation ask for it per state, several times).
    best: Vec<TaskSet>,
}

impl<'g, 'a> SolvedHypergame<'g, 'a> {
    /// The view of `game` with `regions` computed on it, the payoffs of the sub-tasks and the
    /// problem's presentation (which names the sub-tasks in product order).
    pub fn new(
        game: &'g Hypergame<'a>,
        regions: &'g TaskRegions,
        payoffs: &'g SubsetPayoffs,
        presentation: &'g Presentation,
    ) -> Self {
        let best = game
            .states()
            .map(|h| regions.best(payoffs, h).unwrap_or_default())
            .collect();
        SolvedHypergame {
            game,
            regions,
            payoffs,
            presentation,
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
}

impl GameView for SolvedHypergame<'_, '_> {
    fn num_states(&self) -> usize {
        self.game.num_states()
    }
    fn initial(&self) -> HState {
        self.game.initial()
    }
    fn is_robot(&self, h: HState) -> bool {
        self.game.owner(h) == Owner::Robot
    }
    fn edges(&self, h: HState) -> impl Iterator<Item = (ActionId, HState)> + '_ {
        self.game.edges(h)
    }
    fn action_name(&self, action: ActionId) -> &str {
        self.game.arena().action_name(action)
    }
    fn state_name(&self, h: HState) -> String {
        self.game.name(h)
    }
    fn arena(&self) -> &Arena {
        self.game.arena()
    }
    fn arena_state(&self, h: HState) -> StateId {
        self.game.arena_state(h)
    }
    fn believed_win(&self, h: HState) -> bool {
        self.regions.believed().contains(h)
    }
}

impl SolvedGame for SolvedHypergame<'_, '_> {
    fn presentation(&self) -> &Presentation {
        self.presentation
    }
    fn payoffs(&self) -> &SubsetPayoffs {
        self.payoffs
    }
    fn wins(&self, set: TaskSet, h: HState) -> bool {
        self.regions.win(set).contains(h)
    }
    fn is_target(&self, set: TaskSet, h: HState) -> bool {
        self.game.is_target(set, h)
    }
    fn reactive_move(&self, set: TaskSet, h: HState) -> Option<(ActionId, HState)> {
        let win = self.regions.win(set);
        self.game
            .edges(h)
            .find(|&(_, t)| win.allows_robot_edge(h, t))
    }
    fn best(&self, h: HState) -> TaskSet {
        self.best[h.index()]
    }
    fn label(&self, h: HState) -> String {
        self.presentation.state_label(self.regions, self.payoffs, h)
    }
}

#[cfg(test)]
pub(crate) mod testing {
    //! A hand-made [`SolvedGame`] of two sub-tasks (in the paper's terms unless a test sets
    //! `presentation`): explicit edges, the three winning sets
    //! and targets given by the test, and a reactive strategy taken as "the first edge whose
    //! successor has a lower rank". Its arena is its own graph: state `h` is arena state `sH`,
    //! with the same owner and edges (built on first use, so the game must be complete by
    //! then).

    use std::sync::OnceLock;

    use super::{GameView, SolvedGame};
    use crate::arena::{ActionId, Arena, ArenaBuilder, Owner, StateId};
    use crate::game::{HState, Payoffs, SubsetPayoffs, TaskSet, WinLabel};
    use crate::opportunistic::presentation::Presentation;

    /// Product state `i`, for tests written with numbers.
    pub fn hs(i: u32) -> HState {
        HState::from_u32(i)
    }

    #[derive(Clone, Debug)]
    pub struct ToyGame {
        pub robot: Vec<bool>,
        pub edges: Vec<Vec<(ActionId, HState)>>,
        pub actions: Vec<String>,
        /// Per state: rank in Win(phi1), Win(phi2), Win(phi) (None = losing).
        pub ranks: Vec<[Option<u32>; 3]>,
        pub initial: HState,
        pub payoffs: SubsetPayoffs,
        pub presentation: Presentation,
        arena: OnceLock<Arena>,
    }

    impl ToyGame {
        pub fn new(actions: &[&str]) -> ToyGame {
            let presentation = Presentation::paper("phi");
            ToyGame {
                robot: Vec::new(),
                edges: Vec::new(),
                actions: actions.iter().map(|a| a.to_string()).collect(),
                ranks: Vec::new(),
                initial: HState::new(0),
                payoffs: Payoffs::default().subsets(presentation.names()),
                presentation,
                arena: OnceLock::new(),
            }
        }

        /// The same game with the paper's payoffs `payoffs`.
        pub fn with_payoffs(mut self, payoffs: Payoffs) -> ToyGame {
            self.payoffs = payoffs.subsets(self.presentation.names());
            self
        }

        /// Adds a state; `label` is like "WLL", ranks are 0 where the label says W and `rank`
        /// is given as the rank for every won task.
        pub fn state(&mut self, robot: bool, label: &str, rank: u32) -> HState {
            let won: Vec<Option<u32>> = label.chars().map(|c| (c == 'W').then_some(rank)).collect();
            self.robot.push(robot);
            self.edges.push(Vec::new());
            self.ranks.push([won[0], won[1], won[2]]);
            HState::new(self.robot.len() - 1)
        }

        pub fn edge(&mut self, from: HState, action: &str, to: HState) {
            let a = self.actions.iter().position(|x| x == action).unwrap() as ActionId;
            self.edges[from.index()].push((a, to));
        }

        /// The rank of `h` in `Win(set)` (`None` outside).
        fn rank(&self, set: TaskSet, h: HState) -> Option<u32> {
            assert!(set.0 >= 1 && set.0 <= 3, "a toy game has two sub-tasks");
            self.ranks[h.index()][set.0 as usize - 1]
        }

        fn build_arena(&self) -> Arena {
            let mut builder = ArenaBuilder::new();
            for action in &self.actions {
                builder.action(action);
            }
            for (h, &robot) in self.robot.iter().enumerate() {
                let owner = if robot {
                    Owner::Robot
                } else {
                    Owner::Adversary
                };
                builder
                    .add_state(&format!("s{h}"), owner, [], None)
                    .unwrap();
            }
            for (h, edges) in self.edges.iter().enumerate() {
                for &(a, t) in edges {
                    builder
                        .add_transition(
                            StateId::new(h),
                            &self.actions[a as usize],
                            StateId::new(t.index()),
                        )
                        .unwrap();
                }
            }
            builder.set_initial(StateId::new(self.initial.index()));
            builder.build().unwrap()
        }
    }

    impl GameView for ToyGame {
        fn num_states(&self) -> usize {
            self.robot.len()
        }
        fn initial(&self) -> HState {
            self.initial
        }
        fn is_robot(&self, h: HState) -> bool {
            self.robot[h.index()]
        }
        fn edges(&self, h: HState) -> impl Iterator<Item = (ActionId, HState)> + '_ {
            self.edges[h.index()].iter().copied()
        }
        fn action_name(&self, action: ActionId) -> &str {
            &self.actions[action as usize]
        }
        fn state_name(&self, h: HState) -> String {
            format!("h{h}")
        }
        fn arena(&self) -> &Arena {
            self.arena.get_or_init(|| self.build_arena())
        }
        fn arena_state(&self, h: HState) -> StateId {
            StateId::new(h.index())
        }
        fn believed_win(&self, h: HState) -> bool {
            self.wins(TaskSet(0b01), h)
        }
    }

    impl SolvedGame for ToyGame {
        fn presentation(&self) -> &Presentation {
            &self.presentation
        }
        fn payoffs(&self) -> &SubsetPayoffs {
            &self.payoffs
        }
        fn wins(&self, set: TaskSet, h: HState) -> bool {
            self.rank(set, h).is_some()
        }
        fn is_target(&self, set: TaskSet, h: HState) -> bool {
            self.rank(set, h) == Some(0)
        }
        fn reactive_move(&self, set: TaskSet, h: HState) -> Option<(ActionId, HState)> {
            let rank = self.rank(set, h)?;
            self.edges(h)
                .find(|&(_, t)| self.rank(set, t).is_some_and(|r| rank == 0 || r < rank))
        }
        fn label(&self, h: HState) -> String {
            let [phi1, phi2, phi] = [0b01, 0b10, 0b11].map(|mask| self.wins(TaskSet(mask), h));
            WinLabel { phi1, phi2, phi }.to_string()
        }
    }
}

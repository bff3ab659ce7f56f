//! What the hypergame MDP, its controller and the simulation need to know about a solved
//! hypergame: the product graph, the three winning regions with their ranks and the reactive
//! strategies.
//!
//! [`SolvedHypergame`] is the real one. Keeping this a trait lets the MDP stage be built and
//! tested on small hand-made games, and keeps it independent of how the product and the
//! attractors are stored.

use crate::arena::{ActionId, Arena, Owner, StateId};
use crate::game::{HState, Hypergame, ReactiveStrategy, Task, WinLabel, WinningRegions};
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

/// A hypergame of the paper's form whose winning regions are known.
pub trait SolvedGame: GameView {
    /// Whether `h` is in `Win(goal)`.
    fn wins(&self, goal: Task, h: HState) -> bool;
    /// Whether `h` satisfies `goal` already (a final state of its DFA, or of both for `phi`).
    fn is_target(&self, goal: Task, h: HState) -> bool;
    /// The move of the robot's reactive winning strategy for `goal` in robot state `h ∈ Win(goal)`
    /// (the first allowed action), `None` outside its domain or when it allows none.
    fn reactive_move(&self, goal: Task, h: HState) -> Option<(ActionId, HState)>;
}

/// The win-label of `h`.
pub fn win_label(game: &impl SolvedGame, h: HState) -> WinLabel {
    WinLabel::new(
        game.wins(Task::Phi1, h),
        game.wins(Task::Phi2, h),
        game.wins(Task::Phi, h),
    )
}

/// A [`Hypergame`] with its winning regions and the robot's reactive strategies.
pub struct SolvedHypergame<'g, 'a> {
    game: &'g Hypergame<'a>,
    regions: &'g WinningRegions,
    /// Indexed like [`Task::ALL`].
    strategies: [ReactiveStrategy; 3],
}

impl<'g, 'a> SolvedHypergame<'g, 'a> {
    /// The view of `game` with `regions` computed on it; builds the robot's reactive strategy of
    /// each task once.
    pub fn new(game: &'g Hypergame<'a>, regions: &'g WinningRegions) -> Self {
        let strategies =
            Task::ALL.map(|task| ReactiveStrategy::robot(game, task, regions.get(task)));
        SolvedHypergame {
            game,
            regions,
            strategies,
        }
    }

    /// The product the view was built on.
    pub fn game(&self) -> &Hypergame<'a> {
        self.game
    }
}

/// A view whose game is an explicit [`Hypergame`]: everything but `Win(psi)` comes from it.
pub trait OverHypergame {
    /// The product game the view reads everything but `Win(psi)` from.
    fn product(&self) -> &Hypergame<'_>;
    /// `Win(psi)`, see [`GameView::believed_win`].
    fn in_believed_region(&self, h: HState) -> bool;
}

impl<T: OverHypergame> GameView for T {
    fn num_states(&self) -> usize {
        self.product().num_states()
    }
    fn initial(&self) -> HState {
        self.product().initial()
    }
    fn is_robot(&self, h: HState) -> bool {
        self.product().owner(h) == Owner::Robot
    }
    fn edges(&self, h: HState) -> impl Iterator<Item = (ActionId, HState)> + '_ {
        self.product().edges(h)
    }
    fn action_name(&self, action: ActionId) -> &str {
        self.product().arena().action_name(action)
    }
    fn state_name(&self, h: HState) -> String {
        self.product().name(h)
    }
    fn arena(&self) -> &Arena {
        self.product().arena()
    }
    fn arena_state(&self, h: HState) -> StateId {
        self.product().arena_state(h)
    }
    fn believed_win(&self, h: HState) -> bool {
        self.in_believed_region(h)
    }
}

impl OverHypergame for SolvedHypergame<'_, '_> {
    fn product(&self) -> &Hypergame<'_> {
        self.game
    }
    fn in_believed_region(&self, h: HState) -> bool {
        self.wins(Task::Phi1, h)
    }
}

impl SolvedGame for SolvedHypergame<'_, '_> {
    fn wins(&self, goal: Task, h: HState) -> bool {
        self.regions.get(goal).contains(h)
    }
    fn is_target(&self, goal: Task, h: HState) -> bool {
        self.game.is_target(goal, h)
    }
    fn reactive_move(&self, goal: Task, h: HState) -> Option<(ActionId, HState)> {
        self.strategies[goal as usize].moves(self.game, h).next()
    }
}

#[cfg(test)]
pub(crate) mod testing {
    //! A hand-made [`SolvedGame`]: explicit edges, winning sets and targets given by the test,
    //! and a reactive strategy taken as "the first edge whose successor has a lower rank". Its
    //! arena is its own graph: state `h` is arena state `sH`, with the same owner and edges
    //! (built on first use, so the game must be complete by then).

    use std::sync::OnceLock;

    use super::{GameView, SolvedGame};
    use crate::arena::{ActionId, Arena, ArenaBuilder, Owner, StateId};
    use crate::game::{HState, Task};

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
        arena: OnceLock<Arena>,
    }

    impl ToyGame {
        pub fn new(actions: &[&str]) -> ToyGame {
            ToyGame {
                robot: Vec::new(),
                edges: Vec::new(),
                actions: actions.iter().map(|a| a.to_string()).collect(),
                ranks: Vec::new(),
                initial: HState::new(0),
                arena: OnceLock::new(),
            }
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
    }

    impl ToyGame {
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
            self.wins(Task::Phi1, h)
        }
    }

    impl SolvedGame for ToyGame {
        fn wins(&self, goal: Task, h: HState) -> bool {
            self.ranks[h.index()][goal as usize].is_some()
        }
        fn is_target(&self, goal: Task, h: HState) -> bool {
            self.ranks[h.index()][goal as usize] == Some(0)
        }
        fn reactive_move(&self, goal: Task, h: HState) -> Option<(ActionId, HState)> {
            let rank = self.ranks[h.index()][goal as usize]?;
            self.edges(h).find(|&(_, t)| {
                self.ranks[t.index()][goal as usize].is_some_and(|r| rank == 0 || r < rank)
            })
        }
    }
}

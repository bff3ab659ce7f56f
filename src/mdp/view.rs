//! What the hypergame MDP, its controller and the simulation need to know about a solved
//! hypergame: the product graph, the three winning regions with their ranks and the reactive
//! strategies.
//!
//! [`SolvedHypergame`] is the real one. Keeping this a trait lets the MDP stage be built and tested on small hand-made games, and
//! keeps it independent of how the product and the attractors are stored.

use crate::arena::{Arena, Owner, StateId};
use crate::game::{Hypergame, ReactiveStrategy, Task, WinLabel, WinningRegions};

/// What the MDP stage needs of any product game: states `0..num_states()`, owners, edges, names,
/// the arena underneath and the region the adversary believes the robot wins.
pub trait GameView {
    fn num_states(&self) -> u32;
    fn initial(&self) -> u32;
    fn is_robot(&self, h: u32) -> bool;
    /// The enabled actions of `h` with their successors, in a fixed order.
    fn edges(&self, h: u32) -> impl Iterator<Item = (u32, u32)> + '_;
    fn action_name(&self, action: u32) -> &str;
    /// The display name of a product state.
    fn state_name(&self, h: u32) -> String;
    /// The arena the product is built on (what the adversary observes).
    fn arena(&self) -> &Arena;
    /// The arena state underlying product state `h`; its edges are `h`'s, in the same order.
    fn arena_state(&self, h: u32) -> StateId;
    /// Whether `h` is in `Win(psi)`, the robot's winning region for the task the adversary
    /// believes it has (`phi1` in the paper's form).
    fn believed_win(&self, h: u32) -> bool;
}

/// The successor of `h` by an MDP choice's arena action (which is enabled in `h`).
pub fn successor(game: &impl GameView, h: u32, action: u32) -> u32 {
    game.edges(h)
        .find(|&(a, _)| a == action)
        .map(|(_, t)| t)
        .expect("MDP choices are enabled actions")
}

/// A hypergame of the paper's form whose winning regions are known.
pub trait SolvedGame: GameView {
    /// Whether `h` is in `Win(goal)`.
    fn wins(&self, goal: Task, h: u32) -> bool;
    /// Whether `h` satisfies `goal` already (a final state of its DFA, or of both for `phi`).
    fn is_target(&self, goal: Task, h: u32) -> bool;
    /// The move of the robot's reactive winning strategy for `goal` in robot state `h ∈ Win(goal)`
    /// (the first allowed action), `None` outside its domain or when it allows none.
    fn reactive_move(&self, goal: Task, h: u32) -> Option<(u32, u32)>;
}

/// The win-label of `h`.
pub fn win_label(game: &impl SolvedGame, h: u32) -> WinLabel {
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
    pub fn new(game: &'g Hypergame<'a>, regions: &'g WinningRegions) -> Self {
        let strategies =
            Task::ALL.map(|task| ReactiveStrategy::robot(game, task, regions.get(task)));
        SolvedHypergame {
            game,
            regions,
            strategies,
        }
    }

    pub fn game(&self) -> &Hypergame<'a> {
        self.game
    }
}

/// A view whose game is an explicit [`Hypergame`]: everything but `Win(psi)` comes from it.
pub trait OverHypergame {
    fn product(&self) -> &Hypergame<'_>;
    /// `Win(psi)`, see [`GameView::believed_win`].
    fn in_believed_region(&self, h: u32) -> bool;
}

impl<T: OverHypergame> GameView for T {
    fn num_states(&self) -> u32 {
        self.product().num_states() as u32
    }
    fn initial(&self) -> u32 {
        self.product().initial()
    }
    fn is_robot(&self, h: u32) -> bool {
        self.product().owner(h) == Owner::Robot
    }
    fn edges(&self, h: u32) -> impl Iterator<Item = (u32, u32)> + '_ {
        self.product().edges(h)
    }
    fn action_name(&self, action: u32) -> &str {
        self.product().arena().action_name(action)
    }
    fn state_name(&self, h: u32) -> String {
        self.product().name(h)
    }
    fn arena(&self) -> &Arena {
        self.product().arena()
    }
    fn arena_state(&self, h: u32) -> StateId {
        self.product().arena_state(h)
    }
    fn believed_win(&self, h: u32) -> bool {
        self.in_believed_region(h)
    }
}

impl OverHypergame for SolvedHypergame<'_, '_> {
    fn product(&self) -> &Hypergame<'_> {
        self.game
    }
    fn in_believed_region(&self, h: u32) -> bool {
        self.wins(Task::Phi1, h)
    }
}

impl SolvedGame for SolvedHypergame<'_, '_> {
    fn wins(&self, goal: Task, h: u32) -> bool {
        self.regions.get(goal).contains(h)
    }
    fn is_target(&self, goal: Task, h: u32) -> bool {
        self.game.is_target(goal, h)
    }
    fn reactive_move(&self, goal: Task, h: u32) -> Option<(u32, u32)> {
        self.strategies[goal as usize].moves(self.game, h).next()
    }
}

#[cfg(test)]
pub(crate) mod testing {
    //! A hand-made [`SolvedGame`]: explicit edges, winning sets and targets given by the test,
    //! and a reactive strategy taken as "the first edge whose successor has a lower rank". Its
    //! arena is its own graph: state `h` is arena state `sH`, with the same owner and edges
    //! (built on first use, so the game must be complete by then).

    use std::cell::OnceCell;

    use super::{GameView, SolvedGame};
    use crate::arena::{Arena, ArenaBuilder, Owner, StateId};
    use crate::game::Task;

    #[derive(Clone, Debug, Default)]
    pub struct ToyGame {
        pub robot: Vec<bool>,
        pub edges: Vec<Vec<(u32, u32)>>,
        pub actions: Vec<String>,
        /// Per state: rank in Win(phi1), Win(phi2), Win(phi) (None = losing).
        pub ranks: Vec<[Option<u32>; 3]>,
        pub initial: u32,
        arena: OnceCell<Arena>,
    }

    impl ToyGame {
        pub fn new(actions: &[&str]) -> ToyGame {
            ToyGame {
                actions: actions.iter().map(|a| a.to_string()).collect(),
                ..ToyGame::default()
            }
        }

        /// Adds a state; `label` is like "WLL", ranks are 0 where the label says W and `rank`
        /// is given as the rank for every won task.
        pub fn state(&mut self, robot: bool, label: &str, rank: u32) -> u32 {
            let won: Vec<Option<u32>> = label.chars().map(|c| (c == 'W').then_some(rank)).collect();
            self.robot.push(robot);
            self.edges.push(Vec::new());
            self.ranks.push([won[0], won[1], won[2]]);
            self.robot.len() as u32 - 1
        }

        pub fn edge(&mut self, from: u32, action: &str, to: u32) {
            let a = self.actions.iter().position(|x| x == action).unwrap() as u32;
            self.edges[from as usize].push((a, to));
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
                            StateId::from_u32(t),
                        )
                        .unwrap();
                }
            }
            builder.set_initial(StateId::from_u32(self.initial));
            builder.build().unwrap()
        }
    }

    impl GameView for ToyGame {
        fn num_states(&self) -> u32 {
            self.robot.len() as u32
        }
        fn initial(&self) -> u32 {
            self.initial
        }
        fn is_robot(&self, h: u32) -> bool {
            self.robot[h as usize]
        }
        fn edges(&self, h: u32) -> impl Iterator<Item = (u32, u32)> + '_ {
            self.edges[h as usize].iter().copied()
        }
        fn action_name(&self, action: u32) -> &str {
            &self.actions[action as usize]
        }
        fn state_name(&self, h: u32) -> String {
            format!("h{h}")
        }
        fn arena(&self) -> &Arena {
            self.arena.get_or_init(|| self.build_arena())
        }
        fn arena_state(&self, h: u32) -> StateId {
            StateId::from_u32(h)
        }
        fn believed_win(&self, h: u32) -> bool {
            self.wins(Task::Phi1, h)
        }
    }

    impl SolvedGame for ToyGame {
        fn wins(&self, goal: Task, h: u32) -> bool {
            self.ranks[h as usize][goal as usize].is_some()
        }
        fn is_target(&self, goal: Task, h: u32) -> bool {
            self.ranks[h as usize][goal as usize] == Some(0)
        }
        fn reactive_move(&self, goal: Task, h: u32) -> Option<(u32, u32)> {
            let rank = self.ranks[h as usize][goal as usize]?;
            self.edges(h).find(|&(_, t)| {
                self.ranks[t as usize][goal as usize].is_some_and(|r| rank == 0 || r < rank)
            })
        }
    }
}

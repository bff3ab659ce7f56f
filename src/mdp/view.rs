//! What the hypergame MDP, its controller and the simulation need to know about a solved
//! hypergame: the product graph, the three winning regions with their ranks and the reactive
//! strategies.
//!
//! Keeping this a trait lets the MDP stage be built and tested on small hand-made games, and
//! keeps it independent of how the product and the attractors are stored.

/// One of the three tasks: the adversary's belief `phi1`, the rest `phi2`, and `phi = phi1 & phi2`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Goal {
    Phi1,
    Phi2,
    Phi,
}

impl Goal {
    pub fn name(self) -> &'static str {
        match self {
            Goal::Phi1 => "phi1",
            Goal::Phi2 => "phi2",
            Goal::Phi => "phi",
        }
    }
}

/// A hypergame whose winning regions are known. States are `0..num_states()`.
pub trait SolvedGame {
    fn num_states(&self) -> u32;
    fn initial(&self) -> u32;
    fn is_robot(&self, h: u32) -> bool;
    /// The enabled actions of `h` with their successors, in a fixed order.
    fn edges(&self, h: u32) -> impl Iterator<Item = (u32, u32)> + '_;
    fn action_name(&self, action: u32) -> &str;
    /// The display name of a product state.
    fn state_name(&self, h: u32) -> String;
    /// The name of the arena state underlying product state `h` (the adversary file's key).
    fn arena_state_name(&self, h: u32) -> &str;
    /// Whether `h` is in `Win(goal)`.
    fn wins(&self, goal: Goal, h: u32) -> bool;
    /// Whether `h` satisfies `goal` already (a final state of its DFA, or of both for `phi`).
    fn is_target(&self, goal: Goal, h: u32) -> bool;
    /// The move of the robot's reactive winning strategy for `goal` in robot state `h ∈ Win(goal)`
    /// (the first allowed action), `None` outside its domain or when it allows none.
    fn reactive_move(&self, goal: Goal, h: u32) -> Option<(u32, u32)>;
}

/// The win-label of `h` as its three memberships, in the order (phi1, phi2, phi).
pub fn win_triple(game: &impl SolvedGame, h: u32) -> (bool, bool, bool) {
    (
        game.wins(Goal::Phi1, h),
        game.wins(Goal::Phi2, h),
        game.wins(Goal::Phi, h),
    )
}

/// The win-label as written in reports, e.g. `(W, L, L)`.
pub fn win_label_text(game: &impl SolvedGame, h: u32) -> String {
    let letter = |won: bool| if won { 'W' } else { 'L' };
    let (a, b, c) = win_triple(game, h);
    format!("({}, {}, {})", letter(a), letter(b), letter(c))
}

#[cfg(test)]
pub(crate) mod testing {
    //! A hand-made [`SolvedGame`]: explicit edges, winning sets and targets given by the test,
    //! and a reactive strategy taken as "the first edge whose successor has a lower rank".

    use super::{Goal, SolvedGame};

    #[derive(Clone, Debug, Default)]
    pub struct ToyGame {
        pub robot: Vec<bool>,
        pub edges: Vec<Vec<(u32, u32)>>,
        pub actions: Vec<String>,
        /// Per state: rank in Win(phi1), Win(phi2), Win(phi) (None = losing).
        pub ranks: Vec<[Option<u32>; 3]>,
        pub initial: u32,
    }

    fn index(goal: Goal) -> usize {
        match goal {
            Goal::Phi1 => 0,
            Goal::Phi2 => 1,
            Goal::Phi => 2,
        }
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

    impl SolvedGame for ToyGame {
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
        fn arena_state_name(&self, h: u32) -> &str {
            ["s0", "s1", "s2", "s3", "s4", "s5", "s6", "s7", "s8", "s9"][h as usize % 10]
        }
        fn wins(&self, goal: Goal, h: u32) -> bool {
            self.ranks[h as usize][index(goal)].is_some()
        }
        fn is_target(&self, goal: Goal, h: u32) -> bool {
            self.ranks[h as usize][index(goal)] == Some(0)
        }
        fn reactive_move(&self, goal: Goal, h: u32) -> Option<(u32, u32)> {
            let rank = self.ranks[h as usize][index(goal)]?;
            self.edges(h).find(|&(_, t)| {
                self.ranks[t as usize][index(goal)].is_some_and(|r| rank == 0 || r < rank)
            })
        }
    }
}

//! Backward "level" searches shared by the hypergame MDPs (docs/semantics.md §6 and §8): which robot
//! state a play can reach next, or at all, judged by a level per robot state (its win-label in
//! the paper's form, its guarantee in general).
//!
//! Both searches run on the reverse of the game graph restricted to the moves that can happen:
//! every robot edge (when the robot's own moves count) and the adversary's edges of positive
//! probability under the adversary model. Sources (robot states, and stuck adversary states,
//! which end the play) carry levels; processing the sources wave by wave in increasing order of
//! a key, each state takes the key of the first wave whose backward search reaches it:
//! - [`least_next_level`]: through adversary states only, the least level of the *next* robot
//!   state (the risk rules: is a bad next robot state possible?);
//! - [`greatest_reachable_level`]: through every move, the greatest level of any robot state
//!   reachable (the absorbing rule of 3.8: can anything better ever come?).
//!
//! Each state is entered once: O(|H| + |edges| + sources · log sources) time; the possible moves
//! are listed once (a [`Csr`]) and reversed by its transpose. Cycles of adversary states cost
//! nothing extra; a state from which no source is reachable gets `u32::NONE` (the crate's
//! sentinel, see [`crate::index`]).

use super::adversary::AdversaryModel;
use super::view::GameView;
use crate::csr::Csr;
use crate::game::HState;
use crate::game::{SubsetPayoffs, TaskSet};
use crate::index::Id;

/// The least level of the next robot state (or stuck adversary state) that the play can reach
/// from each product state through adversary moves of positive probability; a robot state's is
/// its own level; `u32::NONE` where none is reachable. `level(h)` gives the level of each robot
/// state and stuck adversary state (below `u32::NONE`).
pub fn least_next_level(
    game: &impl GameView,
    adversary: &AdversaryModel,
    level: impl Fn(HState) -> u32,
) -> Vec<u32> {
    first_wave(&reverse_moves(game, adversary, false), sources(game, level))
}

/// The greatest level of a robot state (or stuck adversary state) reachable from each product
/// state through any robot move and adversary moves of positive probability, the state itself
/// included; `u32::NONE` where none is reachable.
pub fn greatest_reachable_level(
    game: &impl GameView,
    adversary: &AdversaryModel,
    level: impl Fn(HState) -> u32,
) -> Vec<u32> {
    // Keys in decreasing order of level (below the sentinel), and back.
    let flip = |x: u32| u32::NONE - 1 - x;
    let keys = first_wave(
        &reverse_moves(game, adversary, true),
        sources(game, |h| flip(level(h))),
    );
    keys.into_iter()
        .map(|key| if key.is_none() { key } else { flip(key) })
        .collect()
}

/// The robot states and stuck adversary states with their keys, sorted by key.
fn sources(game: &impl GameView, key: impl Fn(HState) -> u32) -> Vec<(u32, HState)> {
    let mut sources: Vec<(u32, HState)> = game
        .states()
        .filter(|&h| game.is_robot(h) || game.edges(h).next().is_none())
        .map(|h| (key(h), h))
        .collect();
    sources.sort_unstable();
    sources
}

/// The reversed possible moves: row `t` lists the states with a move into `t`. The moves are
/// every robot edge (when `robot_moves`) and the adversary's edges of positive probability.
fn reverse_moves(
    game: &impl GameView,
    adversary: &AdversaryModel,
    robot_moves: bool,
) -> Csr<HState, HState> {
    // At most the moving states' edges (a product state has its arena state's): reserved once,
    // so that the list never grows by copying (the part not written is not resident).
    let moving = |h| robot_moves || !game.is_robot(h);
    let bound = game
        .states()
        .filter(|&h| moving(h))
        .map(|h| game.arena().edges(game.arena_state(h)).len())
        .sum();
    let mut forward = Csr::with_capacity(game.num_states(), bound);
    let mut scratch = Vec::new();
    let mut moves = Vec::new();
    for h in game.states() {
        if !game.is_robot(h) {
            adversary.positive_moves(game, h, &mut scratch, &mut moves);
            moves.iter().for_each(|&(t, _)| forward.push(t));
        } else if robot_moves {
            game.edges(h).for_each(|(_, t)| forward.push(t));
        }
        forward.finish_row();
    }
    forward.transpose(game.num_states())
}

/// Processes `sources` (sorted by key) one key at a time; each state gets the key of the first
/// wave that reaches it backwards over `reverse`, `u32::NONE` if none does.
fn first_wave(reverse: &Csr<HState, HState>, sources: Vec<(u32, HState)>) -> Vec<u32> {
    let mut keys = vec![u32::NONE; reverse.num_rows()];
    let mut queue = Vec::new();
    let mut start = 0;
    while start < sources.len() {
        let key = sources[start].0;
        let end = start + sources[start..].partition_point(|&(k, _)| k == key);
        for &(_, h) in &sources[start..end] {
            if keys[h.index()].is_none() {
                keys[h.index()] = key;
                queue.push(h);
            }
        }
        while let Some(t) = queue.pop() {
            for &p in reverse.row(t) {
                if keys[p.index()].is_none() {
                    keys[p.index()] = key;
                    queue.push(p);
                }
            }
        }
        start = end;
    }
    keys
}

/// The ranks of the distinct payoffs (0 for payoff 0): a robot state's level is its guarantee's
/// rank, a stuck adversary state's the top (all sub-tasks, the largest payoff by monotonicity).
#[derive(Clone, Debug)]
pub(crate) struct Levels {
    /// Indexed by the mask of the set a state settles for.
    of_set: Vec<u32>,
    top: u32,
}

impl Levels {
    /// The levels of the sets of sub-tasks under `payoffs`.
    pub(crate) fn new(payoffs: &SubsetPayoffs) -> Levels {
        let k = payoffs.num_tasks();
        let mut values: Vec<f64> = std::iter::once(0.0)
            .chain(TaskSet::non_empty(k).map(|set| payoffs.get(set)))
            .collect();
        values.sort_by(f64::total_cmp);
        values.dedup();
        let rank = |value: f64| values.partition_point(|&v| v < value) as u32;
        Levels {
            of_set: (0..1usize << k)
                .map(|mask| rank(payoffs.get(TaskSet(mask as u8))))
                .collect(),
            top: rank(payoffs.all()),
        }
    }

    /// The level of a robot state that settles for `set` (the empty set: level 0).
    pub(crate) fn of_set(&self, set: TaskSet) -> u32 {
        self.of_set[set.0 as usize]
    }

    /// The level of a stuck adversary state.
    pub(crate) fn top(&self) -> u32 {
        self.top
    }
}

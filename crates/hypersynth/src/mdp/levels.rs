//! Backward "level" searches shared by the hypergame MDPs (DESIGN.md 3.6 and 3.8): which robot
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
//! Each state is entered once: O(|H| + |edges| + sources · log sources) time, one CSR copy of
//! the reversed edges in memory. Cycles of adversary states cost nothing extra; a state from
//! which no source is reachable gets [`UNREACHED`].

use super::adversary::AdversaryModel;
use super::view::GameView;

/// The level of a state from which no source is reachable.
pub const UNREACHED: u32 = u32::MAX;

/// The least level of the next robot state (or stuck adversary state) that the play can reach
/// from each product state through adversary moves of positive probability; a robot state's is
/// its own level. `level(h)` gives the level of each robot state and stuck adversary state.
pub fn least_next_level(
    game: &impl GameView,
    adversary: &AdversaryModel,
    level: impl Fn(u32) -> u32,
) -> Vec<u32> {
    let reverse = Reverse::new(game, adversary, false);
    reverse.first_wave(sources(game, level))
}

/// The greatest level of a robot state (or stuck adversary state) reachable from each product
/// state through any robot move and adversary moves of positive probability, the state itself
/// included.
pub fn greatest_reachable_level(
    game: &impl GameView,
    adversary: &AdversaryModel,
    level: impl Fn(u32) -> u32,
) -> Vec<u32> {
    let reverse = Reverse::new(game, adversary, true);
    // Keys in decreasing order of level.
    let sources = sources(game, |h| u32::MAX - 1 - level(h));
    reverse
        .first_wave(sources)
        .into_iter()
        .map(|key| {
            if key == UNREACHED {
                UNREACHED
            } else {
                u32::MAX - 1 - key
            }
        })
        .collect()
}

/// The robot states and stuck adversary states with their keys, sorted by key.
fn sources(game: &impl GameView, key: impl Fn(u32) -> u32) -> Vec<(u32, u32)> {
    let mut sources: Vec<(u32, u32)> = (0..game.num_states())
        .filter(|&h| game.is_robot(h) || game.edges(h).next().is_none())
        .map(|h| (key(h), h))
        .collect();
    sources.sort_unstable();
    sources
}

/// The reversed possible moves in CSR form: `sources[offsets[t]..offsets[t + 1]]` are the
/// states with a move into `t`.
struct Reverse {
    offsets: Vec<u32>,
    sources: Vec<u32>,
}

impl Reverse {
    fn new(game: &impl GameView, adversary: &AdversaryModel, robot_moves: bool) -> Reverse {
        let n = game.num_states() as usize;
        let mut scratch = Vec::new();
        let mut moves = Vec::new();
        let mut targets = Vec::new();
        // The targets of the moves of `h` that count, into `targets`.
        let mut successors = |h: u32, targets: &mut Vec<u32>| {
            targets.clear();
            if game.is_robot(h) {
                if robot_moves {
                    targets.extend(game.edges(h).map(|(_, t)| t));
                }
            } else {
                adversary.positive_moves(game, h, &mut scratch, &mut moves);
                targets.extend(moves.iter().map(|&(t, _)| t));
            }
        };
        let mut offsets = vec![0u32; n + 1];
        for h in 0..n as u32 {
            successors(h, &mut targets);
            for &t in &targets {
                offsets[t as usize + 1] += 1;
            }
        }
        for i in 0..n {
            offsets[i + 1] += offsets[i];
        }
        let mut next = offsets.clone();
        let mut sources = vec![0u32; offsets[n] as usize];
        for h in 0..n as u32 {
            successors(h, &mut targets);
            for &t in &targets {
                sources[next[t as usize] as usize] = h;
                next[t as usize] += 1;
            }
        }
        Reverse { offsets, sources }
    }

    /// Processes `sources` (sorted by key) one key at a time; each state gets the key of the
    /// first wave that reaches it backwards.
    fn first_wave(&self, sources: Vec<(u32, u32)>) -> Vec<u32> {
        let n = self.offsets.len() - 1;
        let mut keys = vec![UNREACHED; n];
        let mut queue = Vec::new();
        let mut start = 0;
        while start < sources.len() {
            let key = sources[start].0;
            let end = start + sources[start..].partition_point(|&(k, _)| k == key);
            for &(_, h) in &sources[start..end] {
                if keys[h as usize] == UNREACHED {
                    keys[h as usize] = key;
                    queue.push(h);
                }
            }
            while let Some(t) = queue.pop() {
                let range =
                    self.offsets[t as usize] as usize..self.offsets[t as usize + 1] as usize;
                for &p in &self.sources[range] {
                    if keys[p as usize] == UNREACHED {
                        keys[p as usize] = key;
                        queue.push(p);
                    }
                }
            }
            start = end;
        }
        keys
    }
}

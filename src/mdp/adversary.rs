//! The adversary model: in each adversary state of the hypergame, a probability distribution
//! over its enabled actions (DESIGN.md 3.6).
//!
//! - Where the state is losing for the robot in `G(phi1)` (outside `Win(phi1)`), the adversary
//!   believes it is winning and plays `sigma_W`: uniform over its *safe* actions, those whose
//!   successor stays outside `Win(phi1)`. Such a state always has one (otherwise the attractor
//!   would contain it); should none exist, `sigma_L` is used instead.
//! - Elsewhere it plays `sigma_L` over all its enabled actions: uniform, seeded random weights,
//!   or weights read from a file.
//! - A stuck adversary state (no enabled action) has an empty distribution.
//!
//! Invariants: the distribution of a non-stuck state sums to 1, is indexed like the state's
//! edges (`SolvedGame::edges` order) and may give probability 0 to some edges (unsafe actions
//! under `sigma_W`, weight 0 in a file).
//!
//! Random weights are drawn from ChaCha8 seeded with the seed, one `u64` per edge of every
//! adversary state in increasing state order and edge order, whatever the regions: the weights
//! of a seed are therefore portable and independent of which states end up playing `sigma_W`.
//!
//! Weights file: one `STATE ACTION WEIGHT` per line (whitespace-separated; `#` starts a comment),
//! where `STATE` is an arena state name (it applies to every adversary product state over that
//! arena state), `ACTION` one of its enabled actions and `WEIGHT` a finite number ≥ 0. A listed
//! state plays its listed actions in proportion to their weights (unlisted actions get 0, and at
//! least one weight must be positive); unlisted states play uniformly.

use std::collections::HashMap;

use bit_set::BitSet;
use rand_chacha::ChaCha8Rng;
use rand_core::{RngCore, SeedableRng};
use thiserror::Error;

use super::view::SolvedGame;
use crate::game::Task;
use crate::position::Position;

/// How the adversary plays where it believes it has lost.
#[derive(Clone, Debug, PartialEq)]
pub enum SigmaL {
    Uniform,
    Random { seed: u64 },
    Weights(WeightTable),
}

/// The parsed lines of a weights file (see the module documentation).
#[derive(Clone, Debug, PartialEq, Default)]
pub struct WeightTable {
    lines: Vec<WeightLine>,
}

#[derive(Clone, Debug, PartialEq)]
struct WeightLine {
    state: String,
    action: String,
    weight: f64,
    position: Position,
}

#[derive(Debug, Error, PartialEq)]
pub enum AdversaryError {
    #[error("{position}: expected `STATE ACTION WEIGHT`")]
    Syntax { position: Position },
    #[error("{position}: invalid weight `{text}` (a finite number >= 0)")]
    Weight { position: Position, text: String },
    #[error("{position}: no adversary state is named `{state}`")]
    UnknownState { position: Position, state: String },
    #[error("{position}: action `{action}` is not enabled in adversary state `{state}`")]
    UnknownAction {
        position: Position,
        state: String,
        action: String,
    },
    #[error("{position}: weight of `{state}` `{action}` given twice")]
    Duplicate {
        position: Position,
        state: String,
        action: String,
    },
    #[error("{position}: every weight of adversary state `{state}` is 0")]
    AllZero { position: Position, state: String },
}

impl WeightTable {
    /// Parses a weights file; errors carry the position of the offending token.
    pub fn parse(text: &str) -> Result<WeightTable, AdversaryError> {
        let mut lines = Vec::new();
        let mut offset = 0;
        for line in text.split_inclusive('\n') {
            let content = line.split('#').next().unwrap_or("");
            let mut tokens = Vec::new();
            let mut start = None;
            for (i, c) in content.char_indices().chain([(content.len(), ' ')]) {
                match (c.is_whitespace(), start) {
                    (false, None) => start = Some(i),
                    (true, Some(s)) => {
                        tokens.push((offset + s, &content[s..i]));
                        start = None;
                    }
                    _ => {}
                }
            }
            let at = |o: usize| Position::of_offset(text, o);
            match tokens.as_slice() {
                [] => {}
                [(s, state), (_, action), (w, weight)] => {
                    let value: f64 = weight.parse().map_err(|_| AdversaryError::Weight {
                        position: at(*w),
                        text: weight.to_string(),
                    })?;
                    if !(value.is_finite() && value >= 0.0) {
                        return Err(AdversaryError::Weight {
                            position: at(*w),
                            text: weight.to_string(),
                        });
                    }
                    lines.push(WeightLine {
                        state: state.to_string(),
                        action: action.to_string(),
                        weight: value,
                        position: at(*s),
                    });
                }
                [(s, _), ..] => return Err(AdversaryError::Syntax { position: at(*s) }),
            }
            offset += line.len();
        }
        Ok(WeightTable { lines })
    }
}

/// The adversary's distribution in every adversary state (CSR over the game's edges).
#[derive(Clone, Debug, PartialEq)]
pub struct AdversaryModel {
    offsets: Vec<u32>,
    probabilities: Vec<f64>,
    plays_sigma_w: BitSet,
}

impl AdversaryModel {
    pub fn new(game: &impl SolvedGame, sigma_l: &SigmaL) -> Result<AdversaryModel, AdversaryError> {
        let n = game.num_states();
        let mut offsets = Vec::with_capacity(n as usize + 1);
        offsets.push(0u32);
        for h in 0..n {
            let edges = if game.is_robot(h) {
                0
            } else {
                game.edges(h).count() as u32
            };
            offsets.push(offsets[h as usize] + edges);
        }
        let mut weights = match sigma_l {
            SigmaL::Uniform => vec![1.0; offsets[n as usize] as usize],
            SigmaL::Random { seed } => {
                let mut rng = ChaCha8Rng::seed_from_u64(*seed);
                // Shifted into [1, 2^53]: positive and exactly representable.
                (0..offsets[n as usize])
                    .map(|_| ((rng.next_u64() >> 11) + 1) as f64)
                    .collect()
            }
            SigmaL::Weights(table) => file_weights(game, &offsets, table)?,
        };
        let mut plays_sigma_w = BitSet::with_capacity(n as usize);
        for h in 0..n {
            let range = offsets[h as usize] as usize..offsets[h as usize + 1] as usize;
            if range.is_empty() {
                continue;
            }
            if !game.wins(Task::Phi1, h) {
                let safe: Vec<bool> = game
                    .edges(h)
                    .map(|(_, t)| !game.wins(Task::Phi1, t))
                    .collect();
                if safe.contains(&true) {
                    plays_sigma_w.insert(h as usize);
                    for (w, safe) in weights[range.clone()].iter_mut().zip(safe) {
                        *w = if safe { 1.0 } else { 0.0 };
                    }
                }
            }
            let total: f64 = weights[range.clone()].iter().sum();
            for w in &mut weights[range] {
                *w /= total;
            }
        }
        Ok(AdversaryModel {
            offsets,
            probabilities: weights,
            plays_sigma_w,
        })
    }

    /// The probabilities of the edges of adversary state `h`, in edge order (empty for robot
    /// states and stuck adversary states).
    pub fn distribution(&self, h: u32) -> &[f64] {
        &self.probabilities
            [self.offsets[h as usize] as usize..self.offsets[h as usize + 1] as usize]
    }

    /// Whether `h` plays `sigma_W` (it is outside `Win(phi1)` and has a safe action).
    pub fn plays_sigma_w(&self, h: u32) -> bool {
        self.plays_sigma_w.contains(h as usize)
    }
}

/// Unnormalised weights per adversary edge from a weights file; unlisted states get 1 per edge.
fn file_weights(
    game: &impl SolvedGame,
    offsets: &[u32],
    table: &WeightTable,
) -> Result<Vec<f64>, AdversaryError> {
    // One representative product state per arena state name: the enabled actions are the arena's.
    let mut by_name: HashMap<&str, u32> = HashMap::new();
    for h in 0..game.num_states() {
        if !game.is_robot(h) {
            by_name.entry(game.arena_state_name(h)).or_insert(h);
        }
    }
    // Per listed arena state: weights in edge order, and the first line that mentions it.
    let mut listed: HashMap<&str, (Vec<Option<f64>>, Position)> = HashMap::new();
    for line in &table.lines {
        let Some(&h) = by_name.get(line.state.as_str()) else {
            return Err(AdversaryError::UnknownState {
                position: line.position,
                state: line.state.clone(),
            });
        };
        let Some(index) = game
            .edges(h)
            .position(|(a, _)| game.action_name(a) == line.action)
        else {
            return Err(AdversaryError::UnknownAction {
                position: line.position,
                state: line.state.clone(),
                action: line.action.clone(),
            });
        };
        let (weights, _) = listed
            .entry(line.state.as_str())
            .or_insert_with(|| (vec![None; game.edges(h).count()], line.position));
        if weights[index].replace(line.weight).is_some() {
            return Err(AdversaryError::Duplicate {
                position: line.position,
                state: line.state.clone(),
                action: line.action.clone(),
            });
        }
    }
    for (state, (weights, position)) in &listed {
        if weights.iter().all(|w| w.unwrap_or(0.0) == 0.0) {
            return Err(AdversaryError::AllZero {
                position: *position,
                state: state.to_string(),
            });
        }
    }
    let mut out = vec![1.0; *offsets.last().unwrap_or(&0) as usize];
    for h in 0..game.num_states() {
        if let Some((weights, _)) = listed.get(game.arena_state_name(h)) {
            let start = offsets[h as usize] as usize;
            for (i, w) in weights.iter().enumerate() {
                if start + i < offsets[h as usize + 1] as usize {
                    out[start + i] = w.unwrap_or(0.0);
                }
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mdp::view::testing::ToyGame;

    /// Robot r0 (losing phi1) → adversary a1 (losing phi1) with actions x → r2 (wins phi1),
    /// y → r3 (loses), z → r4 (loses); adversary a5 in Win(phi1) with x → r2, y → r3.
    fn game() -> ToyGame {
        let mut g = ToyGame::new(&["go", "x", "y", "z"]);
        let r0 = g.state(true, "LLL", 1);
        let a1 = g.state(false, "LLL", 1);
        let r2 = g.state(true, "WLL", 0);
        let r3 = g.state(true, "LLL", 0);
        let r4 = g.state(true, "LLL", 0);
        let a5 = g.state(false, "WLL", 1);
        g.edge(r0, "go", a1);
        g.edge(a1, "x", r2);
        g.edge(a1, "y", r3);
        g.edge(a1, "z", r4);
        g.edge(a5, "x", r2);
        g.edge(a5, "y", r3);
        g
    }

    #[test]
    fn sigma_w_is_uniform_over_safe_actions_and_sigma_l_over_all() {
        let model = AdversaryModel::new(&game(), &SigmaL::Uniform).unwrap();
        assert!(model.plays_sigma_w(1));
        assert_eq!(model.distribution(1), &[0.0, 0.5, 0.5]);
        assert!(!model.plays_sigma_w(5));
        assert_eq!(model.distribution(5), &[0.5, 0.5]);
        assert!(model.distribution(0).is_empty());
    }

    #[test]
    fn random_weights_are_deterministic_per_seed_and_follow_chacha8_in_state_order() {
        let g = game();
        let a = AdversaryModel::new(&g, &SigmaL::Random { seed: 7 }).unwrap();
        let b = AdversaryModel::new(&g, &SigmaL::Random { seed: 7 }).unwrap();
        assert_eq!(a, b);
        // Independent recomputation: a1's three draws come first, then a5's two.
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let draws: Vec<f64> = (0..5)
            .map(|_| ((rng.next_u64() >> 11) + 1) as f64)
            .collect();
        let total = draws[3] + draws[4];
        assert_eq!(a.distribution(5), &[draws[3] / total, draws[4] / total]);
        // sigma_W is unaffected by the seed.
        assert_eq!(a.distribution(1), &[0.0, 0.5, 0.5]);
        let c = AdversaryModel::new(&g, &SigmaL::Random { seed: 8 }).unwrap();
        assert_ne!(a.distribution(5), c.distribution(5));
    }

    #[test]
    fn weights_file_sets_listed_states_and_leaves_others_uniform() {
        let mut g = game();
        // a5 sits over arena state "s5"; a1 over "s1".
        let table = WeightTable::parse("# weights\ns5 y 3\ns5 x 1 # trailing\n").unwrap();
        let model = AdversaryModel::new(&g, &SigmaL::Weights(table)).unwrap();
        assert_eq!(model.distribution(5), &[0.25, 0.75]);
        g.ranks[1] = [Some(1), None, None];
        let table = WeightTable::parse("s5 y 2\n").unwrap();
        let model = AdversaryModel::new(&g, &SigmaL::Weights(table)).unwrap();
        assert_eq!(model.distribution(5), &[0.0, 1.0]);
        assert_eq!(model.distribution(1), &[1.0 / 3.0; 3]);
    }

    #[test]
    fn weights_file_errors_are_located() {
        let pos = |line, column| Position { line, column };
        let g = game();
        let err = |text: &str| {
            WeightTable::parse(text)
                .and_then(|t| AdversaryModel::new(&g, &SigmaL::Weights(t)))
                .unwrap_err()
        };
        assert_eq!(
            err("s5 x\n"),
            AdversaryError::Syntax {
                position: pos(1, 1)
            }
        );
        assert!(
            matches!(err("\n  s5 x -1"), AdversaryError::Weight { position, .. } if position == pos(2, 8))
        );
        assert!(matches!(err("s5 x nan"), AdversaryError::Weight { .. }));
        assert!(
            matches!(err("s0 x 1"), AdversaryError::UnknownState { position, .. } if position == pos(1, 1))
        );
        assert!(matches!(
            err("s5 z 1"),
            AdversaryError::UnknownAction { .. }
        ));
        assert!(
            matches!(err("s5 x 1\ns5 x 2"), AdversaryError::Duplicate { position, .. } if position == pos(2, 1))
        );
        assert!(matches!(err("s5 x 0"), AdversaryError::AllZero { .. }));
    }
}

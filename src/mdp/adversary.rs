//! The adversary model: in each adversary state of the hypergame, a probability distribution
//! over its enabled actions (DESIGN.md 3.6).
//!
//! - Where the state is losing for the robot in `G(psi)` (outside `Win(psi)`: `Win(phi1)` in the
//!   paper's form, [`GameView::believed_win`] in general, DESIGN.md 3.8), the adversary
//!   believes it is winning and plays `sigma_W`: uniform over its *safe* actions, those whose
//!   successor stays outside `Win(psi)`. Such a state always has one (otherwise the attractor
//!   would contain it); should none exist, `sigma_L` is used instead.
//! - Elsewhere it plays `sigma_L` over all its enabled actions: uniform, seeded random weights,
//!   or weights read from a file.
//! - A stuck adversary state (no enabled action) has an empty distribution.
//!
//! **The adversary observes the arena, not the robot's automata.** `sigma_L` is one distribution
//! per *arena* state, over the arena state's edges; every product state over that arena state
//! plays it (a product state's edges are its arena state's, in the same order). Hence the full
//! and the reachable enumeration of the product give the same model on the states they share.
//! Only the choice between `sigma_W` and `sigma_L` depends on the product state (on `Win(psi)`).
//!
//! Random weights are drawn from ChaCha8 seeded with the seed, one `u64` per edge of every
//! adversary *arena* state, in increasing arena state order and edge order: the weights of a
//! seed depend on the arena only.
//!
//! Weights file: one `STATE ACTION WEIGHT` per line, under the arena format's lexical rules
//! (names bare or double-quoted with the same escapes, `#` comments), where `STATE` is an
//! adversary arena state, `ACTION` one of its enabled actions and `WEIGHT` a finite number ≥ 0
//! (written bare, e.g. `2`, `0.5`, `1e-3`). A listed state plays its listed actions in proportion
//! to their weights (unlisted actions get 0, and at least one weight must be positive); unlisted
//! states play uniformly. Weights are divided by their maximum before they are summed, so that
//! no sum overflows. Reading is linear in the file; errors are reported in file order (the
//! syntax of every line first, then the meaning of every line), the first one winning.
//!
//! Memory: one `f64` per edge of an adversary arena state and one bit per product state; the
//! distribution of a product state is computed on demand ([`AdversaryModel::distribution`]).

use std::collections::HashMap;

use bit_set::BitSet;
use rand_chacha::ChaCha8Rng;
use rand_core::{RngCore, SeedableRng};
use thiserror::Error;

use super::view::GameView;
use crate::arena::{self, Arena, Name, Owner, StateId};
use crate::csr::Csr;
use crate::game::HState;
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
    state_position: Position,
    action_position: Position,
}

#[derive(Debug, Error, PartialEq)]
pub enum AdversaryError {
    #[error(transparent)]
    Lexical(#[from] arena::ParseError),
    #[error("{position}: expected `STATE ACTION WEIGHT`, found {found} field(s)")]
    Syntax { position: Position, found: usize },
    #[error("{position}: invalid weight `{text}` (a finite number >= 0)")]
    Weight { position: Position, text: String },
    #[error("{position}: no arena state is named `{}`", Name(.state))]
    UnknownState { position: Position, state: String },
    #[error("{position}: `{}` is a robot state; weights apply to adversary states", Name(.state))]
    RobotState { position: Position, state: String },
    #[error(
        "{position}: action `{}` is not enabled in adversary state `{}`",
        Name(.action),
        Name(.state)
    )]
    UnknownAction {
        position: Position,
        state: String,
        action: String,
    },
    #[error(
        "{position}: weight of `{}` `{}` given twice (first on line {first_line})",
        Name(.state),
        Name(.action)
    )]
    Duplicate {
        position: Position,
        state: String,
        action: String,
        first_line: usize,
    },
    #[error("{position}: every weight of adversary state `{}` is 0", Name(.state))]
    AllZero { position: Position, state: String },
}

impl AdversaryError {
    /// Where in the weights file the error is.
    pub fn position(&self) -> Position {
        match self {
            AdversaryError::Lexical(e) => e.position,
            AdversaryError::Syntax { position, .. }
            | AdversaryError::Weight { position, .. }
            | AdversaryError::UnknownState { position, .. }
            | AdversaryError::RobotState { position, .. }
            | AdversaryError::UnknownAction { position, .. }
            | AdversaryError::Duplicate { position, .. }
            | AdversaryError::AllZero { position, .. } => *position,
        }
    }
}

impl WeightTable {
    /// Parses a weights file; the first syntax error in file order is returned.
    pub fn parse(text: &str) -> Result<WeightTable, AdversaryError> {
        let mut lines = Vec::new();
        for (number, line) in arena::lines(text) {
            let names = arena::line_names(line, number)?;
            match names.as_slice() {
                [] => {}
                [
                    (state_position, state),
                    (action_position, action),
                    (at, weight),
                ] => {
                    let value = weight
                        .parse::<f64>()
                        .ok()
                        .filter(|w| w.is_finite() && *w >= 0.0)
                        .ok_or_else(|| AdversaryError::Weight {
                            position: *at,
                            text: weight.to_string(),
                        })?;
                    lines.push(WeightLine {
                        state: state.to_string(),
                        action: action.to_string(),
                        weight: value,
                        state_position: *state_position,
                        action_position: *action_position,
                    });
                }
                [(position, _), ..] => {
                    return Err(AdversaryError::Syntax {
                        position: *position,
                        found: names.len(),
                    });
                }
            }
        }
        Ok(WeightTable { lines })
    }

    /// Sets sigma_L's unnormalised weights of the listed arena states' edges in `weights`,
    /// after checking every line against `arena` (unlisted adversary states keep theirs). The
    /// first error in file order is returned.
    fn weights(
        &self,
        arena: &Arena,
        weights: &mut Csr<StateId, f64>,
    ) -> Result<(), AdversaryError> {
        // Per listed arena state: the line of each weight given, and the first line naming it.
        let mut listed: HashMap<StateId, (Vec<Option<usize>>, usize)> = HashMap::new();
        let mut errors = Vec::new();
        for (index, line) in self.lines.iter().enumerate() {
            let Some(state) = arena.find_state(&line.state) else {
                errors.push(AdversaryError::UnknownState {
                    position: line.state_position,
                    state: line.state.clone(),
                });
                continue;
            };
            if arena.owner(state) == Owner::Robot {
                errors.push(AdversaryError::RobotState {
                    position: line.state_position,
                    state: line.state.clone(),
                });
                continue;
            }
            let Some(edge) = arena
                .edges(state)
                .position(|(a, _)| arena.action_name(a) == line.action)
            else {
                errors.push(AdversaryError::UnknownAction {
                    position: line.action_position,
                    state: line.state.clone(),
                    action: line.action.clone(),
                });
                continue;
            };
            let (given, _) = listed
                .entry(state)
                .or_insert_with(|| (vec![None; arena.edges(state).len()], index));
            if let Some(first) = given[edge] {
                errors.push(AdversaryError::Duplicate {
                    position: line.state_position,
                    state: line.state.clone(),
                    action: line.action.clone(),
                    first_line: self.lines[first].state_position.line,
                });
                continue;
            }
            given[edge] = Some(index);
        }
        for (&state, (given, first)) in &listed {
            for (weight, line) in weights.row_mut(state).iter_mut().zip(given.iter()) {
                *weight = line.map_or(0.0, |i| self.lines[i].weight);
            }
            if given.iter().flatten().all(|&i| self.lines[i].weight == 0.0) {
                errors.push(AdversaryError::AllZero {
                    position: self.lines[*first].state_position,
                    state: self.lines[*first].state.clone(),
                });
            }
        }
        match errors.into_iter().min_by_key(AdversaryError::position) {
            Some(error) => Err(error),
            None => Ok(()),
        }
    }
}

/// The adversary's behaviour: sigma_L per arena state, and which product states play sigma_W.
#[derive(Clone, Debug, PartialEq)]
pub struct AdversaryModel {
    /// Per arena state, sigma_L's probability of each of its edges (none for robot states).
    sigma_l: Csr<StateId, f64>,
    plays_sigma_w: BitSet,
}

impl AdversaryModel {
    pub fn new(game: &impl GameView, sigma_l: &SigmaL) -> Result<AdversaryModel, AdversaryError> {
        let arena = game.arena();
        // Weight 1 per edge of every adversary arena state, then the chosen weights.
        let mut weights = Csr::with_capacity(arena.num_states(), arena.num_transitions());
        for s in arena.states() {
            let edges = match arena.owner(s) {
                Owner::Robot => 0,
                Owner::Adversary => arena.edges(s).len(),
            };
            weights.push_row(std::iter::repeat_n(1.0, edges));
        }
        match sigma_l {
            SigmaL::Uniform => {}
            SigmaL::Random { seed } => {
                let mut rng = ChaCha8Rng::seed_from_u64(*seed);
                for s in arena.states() {
                    for weight in weights.row_mut(s) {
                        // Shifted into [1, 2^53]: positive and exactly representable.
                        *weight = ((rng.next_u64() >> 11) + 1) as f64;
                    }
                }
            }
            SigmaL::Weights(table) => table.weights(arena, &mut weights)?,
        }
        for s in arena.states() {
            normalise(weights.row_mut(s));
        }
        let mut plays_sigma_w = BitSet::with_capacity(game.num_states());
        for h in game.states() {
            if !game.is_robot(h)
                && !game.believed_win(h)
                && game.edges(h).any(|(_, t)| !game.believed_win(t))
            {
                plays_sigma_w.insert(h.index());
            }
        }
        Ok(AdversaryModel {
            sigma_l: weights,
            plays_sigma_w,
        })
    }

    /// Fills `out` with the probabilities of the edges of adversary state `h`, in edge order
    /// (empty for robot states and stuck adversary states). Some may be 0 (unsafe actions under
    /// sigma_W, weight 0 in a file).
    pub fn distribution(&self, game: &impl GameView, h: HState, out: &mut Vec<f64>) {
        out.clear();
        if game.is_robot(h) {
            return;
        }
        if self.plays_sigma_w(h) {
            out.extend(
                game.edges(h)
                    .map(|(_, t)| f64::from(u8::from(!game.believed_win(t)))),
            );
            normalise(out);
        } else {
            out.extend_from_slice(self.sigma_l.row(game.arena_state(h)));
        }
    }

    /// Fills `out` with the successors of adversary state `h` of positive probability, with
    /// their probabilities, in edge order (`scratch` is reused for the distribution).
    pub fn positive_moves(
        &self,
        game: &impl GameView,
        h: HState,
        scratch: &mut Vec<f64>,
        out: &mut Vec<(HState, f64)>,
    ) {
        self.distribution(game, h, scratch);
        out.clear();
        out.extend(
            game.edges(h)
                .zip(scratch.iter())
                .filter(|&(_, &p)| p > 0.0)
                .map(|((_, t), &p)| (t, p)),
        );
    }

    /// Whether `h` plays `sigma_W` (it is outside `Win(psi)` and has a safe action).
    pub fn plays_sigma_w(&self, h: HState) -> bool {
        self.plays_sigma_w.contains(h.index())
    }
}

/// Divides non-negative weights by their sum, after scaling by their maximum so that the sum
/// cannot overflow. All-zero (or empty) slices are left alone.
fn normalise(weights: &mut [f64]) {
    let max = weights.iter().copied().fold(0.0, f64::max);
    if max > 0.0 {
        let total: f64 = weights.iter().map(|w| w / max).sum();
        for w in weights {
            *w = (*w / max) / total;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mdp::view::testing::{ToyGame, hs};

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

    fn distribution(model: &AdversaryModel, g: &ToyGame, h: u32) -> Vec<f64> {
        let mut out = Vec::new();
        model.distribution(g, hs(h), &mut out);
        out
    }

    #[test]
    fn sigma_w_is_uniform_over_safe_actions_and_sigma_l_over_all() {
        let g = game();
        let model = AdversaryModel::new(&g, &SigmaL::Uniform).unwrap();
        assert!(model.plays_sigma_w(hs(1)));
        assert_eq!(distribution(&model, &g, 1), [0.0, 0.5, 0.5]);
        assert!(!model.plays_sigma_w(hs(5)));
        assert_eq!(distribution(&model, &g, 5), [0.5, 0.5]);
        assert!(distribution(&model, &g, 0).is_empty());
    }

    #[test]
    fn random_weights_are_drawn_per_arena_edge_in_arena_order() {
        let g = game();
        let a = AdversaryModel::new(&g, &SigmaL::Random { seed: 7 }).unwrap();
        assert_eq!(
            a,
            AdversaryModel::new(&g, &SigmaL::Random { seed: 7 }).unwrap()
        );
        // Independent recomputation: arena state a1's three draws come first, then a5's two.
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let draws: Vec<f64> = (0..5)
            .map(|_| ((rng.next_u64() >> 11) + 1) as f64)
            .collect();
        let total = draws[3] + draws[4];
        assert_eq!(
            distribution(&a, &g, 5),
            [draws[3] / total, draws[4] / total]
        );
        // sigma_W is unaffected by the seed.
        assert_eq!(distribution(&a, &g, 1), [0.0, 0.5, 0.5]);
        let c = AdversaryModel::new(&g, &SigmaL::Random { seed: 8 }).unwrap();
        assert_ne!(distribution(&a, &g, 5), distribution(&c, &g, 5));
    }

    #[test]
    fn weights_file_sets_listed_states_and_leaves_others_uniform() {
        let mut g = game();
        // a5 is arena state "s5"; a1 is "s1".
        let table = WeightTable::parse("# weights\ns5 y 3\n\"s5\" x 1 # trailing\n").unwrap();
        let model = AdversaryModel::new(&g, &SigmaL::Weights(table)).unwrap();
        assert_eq!(distribution(&model, &g, 5), [0.25, 0.75]);
        g.ranks[1] = [Some(1), None, None];
        let table = WeightTable::parse("s5 y 2\n").unwrap();
        let model = AdversaryModel::new(&g, &SigmaL::Weights(table)).unwrap();
        assert_eq!(distribution(&model, &g, 5), [0.0, 1.0]);
        assert_eq!(distribution(&model, &g, 1), [1.0 / 3.0; 3]);
    }

    #[test]
    fn huge_weights_are_scaled_before_they_are_summed() {
        let g = game();
        let table = WeightTable::parse("s5 x 1e308\ns5 y 1e308\n").unwrap();
        let model = AdversaryModel::new(&g, &SigmaL::Weights(table)).unwrap();
        assert_eq!(distribution(&model, &g, 5), [0.5, 0.5]);
        let table = WeightTable::parse("s5 x 1.7e308\ns5 y 5e-324\n").unwrap();
        let model = AdversaryModel::new(&g, &SigmaL::Weights(table)).unwrap();
        let d = distribution(&model, &g, 5);
        assert_eq!(d[0], 1.0);
        assert!((d.iter().sum::<f64>() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn weights_file_errors_are_located_and_the_first_in_file_order_wins() {
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
                position: pos(1, 1),
                found: 2
            }
        );
        assert!(
            matches!(err("\n  s5 x -1"), AdversaryError::Weight { position, .. } if position == pos(2, 8))
        );
        assert!(matches!(err("s5 x nan"), AdversaryError::Weight { .. }));
        assert!(matches!(err("s5 x \"1\" {"), AdversaryError::Lexical(_)));
        assert!(
            matches!(err("s5 x 1\ns5 y \"2"), AdversaryError::Lexical(e) if e.position == pos(2, 6))
        );
        assert!(
            matches!(err("s9 x 1"), AdversaryError::UnknownState { position, .. } if position == pos(1, 1))
        );
        assert!(
            matches!(err("s0 x 1"), AdversaryError::RobotState { position, .. } if position == pos(1, 1))
        );
        assert!(
            matches!(err("s5 z 1"), AdversaryError::UnknownAction { position, .. } if position == pos(1, 4))
        );
        assert!(
            matches!(err("s5 x 1\ns5 x 2"), AdversaryError::Duplicate { position, first_line: 1, .. } if position == pos(2, 1))
        );
        // All-zero is located at the state's first line, and errors come in file order.
        assert!(
            matches!(err("s1 x 1\ns5 x 0\ns1 q 2\n"), AdversaryError::AllZero { position, .. } if position == pos(2, 1))
        );
        assert!(
            matches!(err("s1 q 1\ns5 x 0\n"), AdversaryError::UnknownAction { position, .. } if position == pos(1, 4))
        );
    }
}

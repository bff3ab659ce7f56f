//! The adversary model: in each adversary state of the hypergame, a probability distribution
//! over its enabled actions (docs/semantics.md §6).
//!
//! - Where the state is losing for the robot in `G(psi)` (outside `Win(psi)`: `Win(phi1)` in the
//!   paper's form, [`GameView::believed_win`] in general, docs/semantics.md §8), the adversary
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
//! no sum overflows. Reading is linear in the file. Every error is reported, in file order (the
//! first 20): reading skips a malformed line and goes on; the meaning of every well-formed line
//! is checked against the arena once the file is read (so a file with a malformed line gets its
//! other lines checked only when it is fixed).
//!
//! Memory: one `f64` per edge of an adversary arena state (exactly: no room for the robot's
//! edges) and one bit per product state; the distribution of a product state is computed on
//! demand ([`AdversaryModel::distribution`]).

use std::collections::HashMap;

use bit_set::BitSet;
use rand_chacha::ChaCha8Rng;
use rand_core::{RngCore, SeedableRng};
use thiserror::Error;

use super::view::GameView;
use crate::arena::{self, Arena, Name, Owner, StateId};
use crate::csr::Csr;
use crate::diagnostic::{Collector, DEFAULT_LIMIT, Diagnostics, brief};
use crate::game::HState;
use crate::position::Position;

/// How the adversary plays where it believes it has lost.
#[derive(Clone, Debug, PartialEq)]
pub enum SigmaL {
    /// Uniform over the enabled actions.
    Uniform,
    /// Weights drawn from ChaCha8 seeded with `seed`, one per edge of every adversary arena state
    /// (see the module documentation).
    Random {
        /// The seed of the ChaCha8 stream.
        seed: u64,
    },
    /// Weights read from a file (`--adversary`); unlisted states play uniformly.
    Weights {
        /// The file's lines.
        table: WeightTable,
        /// The file's name, as reports and pictures show it.
        file: String,
    },
}

impl SigmaL {
    /// The name reports give it: `uniform`, `random` or `file:FILE`.
    pub fn name(&self) -> String {
        match self {
            SigmaL::Uniform => "uniform".to_string(),
            SigmaL::Random { .. } => "random".to_string(),
            SigmaL::Weights { file, .. } => format!("file:{file}"),
        }
    }

    /// How a picture's title says it: `uniform`, `random (seed 7)`, `weights from FILE`.
    pub fn title(&self) -> String {
        match self {
            SigmaL::Uniform => "uniform".to_string(),
            SigmaL::Random { seed } => format!("random (seed {seed})"),
            SigmaL::Weights { file, .. } => format!("weights from {file}"),
        }
    }
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

/// What is wrong in a weights file, at a place the [`Diagnostic`](crate::diagnostic::Diagnostic)
/// gives.
#[derive(Clone, Debug, Error, PartialEq, Eq)]
pub enum WeightsError {
    /// A name that breaks the arena format's lexical rules.
    #[error(transparent)]
    Lexical(arena::ParseErrorKind),
    /// A line that does not have exactly three fields.
    #[error("expected `STATE ACTION WEIGHT`, found {found} field(s)")]
    Syntax {
        /// How many fields the line has.
        found: usize,
    },
    /// A weight that is not a finite number ≥ 0.
    #[error("invalid weight `{}` (a finite number >= 0)", brief(.text))]
    Weight {
        /// The field as written.
        text: String,
    },
    /// A name that no arena state has.
    #[error("no arena state is named `{}`", Name(.state))]
    UnknownState {
        /// The state's name as written.
        state: String,
    },
    /// A robot state: weights apply to adversary states only.
    #[error("`{}` is a robot state; weights apply to adversary states", Name(.state))]
    RobotState {
        /// The state's name.
        state: String,
    },
    #[error(
        "action `{}` is not enabled in adversary state `{}`",
        Name(.action),
        Name(.state)
    )]
    /// An action that the state does not enable.
    UnknownAction {
        /// The adversary state's name.
        state: String,
        /// The action's name as written.
        action: String,
    },
    #[error(
        "weight of `{}` `{}` given twice (first on line {first_line})",
        Name(.state),
        Name(.action)
    )]
    /// The same state and action on two lines.
    Duplicate {
        /// The state's name.
        state: String,
        /// The action's name.
        action: String,
        /// The line of the first weight (1-based).
        first_line: usize,
    },
    /// A listed state whose weights are all 0.
    #[error("every weight of adversary state `{}` is 0", Name(.state))]
    AllZero {
        /// The state's name.
        state: String,
    },
}

/// The errors of a weights file, located in it: found reading it ([`WeightTable::parse`]) or
/// resolving it against an arena ([`WeightTable::check`], [`AdversaryModel::new`]).
pub type AdversaryError = Diagnostics<WeightsError>;

impl WeightTable {
    /// Parses a weights file; on errors, the first 20 in file order.
    pub fn parse(text: &str) -> Result<WeightTable, AdversaryError> {
        WeightTable::parse_with_limit(text, DEFAULT_LIMIT)
    }

    /// Parses a weights file; on errors, the first `limit` in file order and the number of the
    /// others. Each line is checked on its own: a malformed line is reported and skipped.
    pub fn parse_with_limit(text: &str, limit: usize) -> Result<WeightTable, AdversaryError> {
        let mut lines = Vec::new();
        let mut errors = Collector::new(limit);
        for (number, line) in arena::lines(text) {
            let names = match arena::line_names(line, number) {
                Ok(names) => names,
                Err(error) => {
                    errors.push(error.map(WeightsError::Lexical));
                    continue;
                }
            };
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
                        .filter(|w| w.is_finite() && *w >= 0.0);
                    let Some(value) = value else {
                        let text = weight.to_string();
                        errors.add(*at, WeightsError::Weight { text });
                        continue;
                    };
                    lines.push(WeightLine {
                        state: state.to_string(),
                        action: action.to_string(),
                        weight: value,
                        state_position: *state_position,
                        action_position: *action_position,
                    });
                }
                [(position, _), ..] => {
                    let found = names.len();
                    errors.add(*position, WeightsError::Syntax { found });
                }
            }
        }
        errors.or_ok(WeightTable { lines })
    }

    /// The table of `entries` (state, action, weight), as data rather than a file's text:
    /// entry `i` is located as line `i + 1` of a file, its state at column 1, its action at
    /// column 2 and its weight at column 3. Every weight that is not a finite number >= 0 is an
    /// error (the first 20); the names are checked against an arena by [`WeightTable::check`].
    pub fn from_entries<'e>(
        entries: impl IntoIterator<Item = (&'e str, &'e str, f64)>,
    ) -> Result<WeightTable, AdversaryError> {
        let mut lines = Vec::new();
        let mut errors = Collector::new(DEFAULT_LIMIT);
        for (i, (state, action, weight)) in entries.into_iter().enumerate() {
            let at = |column| Position {
                line: i + 1,
                column,
            };
            if !(weight.is_finite() && weight >= 0.0) {
                let text = weight.to_string();
                errors.add(at(3), WeightsError::Weight { text });
                continue;
            }
            lines.push(WeightLine {
                state: state.to_string(),
                action: action.to_string(),
                weight,
                state_position: at(1),
                action_position: at(2),
            });
        }
        errors.or_ok(WeightTable { lines })
    }

    /// The table's weights in file order: (state, action, weight) as written.
    pub fn entries(&self) -> impl Iterator<Item = (&str, &str, f64)> {
        self.lines
            .iter()
            .map(|line| (line.state.as_str(), line.action.as_str(), line.weight))
    }

    /// Checks every line against `arena`: the errors [`AdversaryModel::new`] would give with
    /// these weights, found without a game (the command line checks a file as soon as it has
    /// the arena, where the file's text is at hand).
    pub fn check(&self, arena: &Arena) -> Result<(), AdversaryError> {
        self.weights(arena, &mut unit_weights(arena))
    }

    /// Sets sigma_L's unnormalised weights of the listed arena states' edges in `weights`,
    /// after checking every line against `arena` (unlisted adversary states keep theirs). All
    /// errors are returned, in file order (the first 20).
    fn weights(
        &self,
        arena: &Arena,
        weights: &mut Csr<StateId, f64>,
    ) -> Result<(), AdversaryError> {
        // Per listed arena state: the line of each weight given, and the first line naming it.
        let mut listed: HashMap<StateId, (Vec<Option<usize>>, usize)> = HashMap::new();
        let mut errors = Collector::new(DEFAULT_LIMIT);
        for (index, line) in self.lines.iter().enumerate() {
            let Some(state) = arena.find_state(&line.state) else {
                let state = line.state.clone();
                errors.add(line.state_position, WeightsError::UnknownState { state });
                continue;
            };
            if arena.owner(state) == Owner::Robot {
                let state = line.state.clone();
                errors.add(line.state_position, WeightsError::RobotState { state });
                continue;
            }
            let Some(edge) = arena
                .edges(state)
                .position(|(a, _)| arena.action_name(a) == line.action)
            else {
                let (state, action) = (line.state.clone(), line.action.clone());
                errors.add(
                    line.action_position,
                    WeightsError::UnknownAction { state, action },
                );
                continue;
            };
            let (given, _) = listed
                .entry(state)
                .or_insert_with(|| (vec![None; arena.edges(state).len()], index));
            if let Some(first) = given[edge] {
                let kind = WeightsError::Duplicate {
                    state: line.state.clone(),
                    action: line.action.clone(),
                    first_line: self.lines[first].state_position.line,
                };
                errors.add(line.state_position, kind);
                continue;
            }
            given[edge] = Some(index);
        }
        for (&state, (given, first)) in &listed {
            for (weight, line) in weights.row_mut(state).iter_mut().zip(given.iter()) {
                *weight = line.map_or(0.0, |i| self.lines[i].weight);
            }
            if given.iter().flatten().all(|&i| self.lines[i].weight == 0.0) {
                // One per state, at its first line: positions differ, so the hash map's order
                // does not show once the errors are sorted.
                let first = &self.lines[*first];
                let state = first.state.clone();
                errors.add(first.state_position, WeightsError::AllZero { state });
            }
        }
        errors.or_ok(())
    }
}

/// Weight 1 per edge of every adversary arena state (no row entries for robot states).
fn unit_weights(arena: &Arena) -> Csr<StateId, f64> {
    let edges = |s| match arena.owner(s) {
        Owner::Robot => 0,
        Owner::Adversary => arena.edges(s).len(),
    };
    let total = arena.states().map(edges).sum();
    let mut weights = Csr::with_capacity(arena.num_states(), total);
    for s in arena.states() {
        weights.push_row(std::iter::repeat_n(1.0, edges(s)));
    }
    weights
}

/// The adversary's behaviour: sigma_L per arena state, and which product states play sigma_W.
#[derive(Clone, Debug, PartialEq)]
pub struct AdversaryModel {
    /// Per arena state, sigma_L's probability of each of its edges (none for robot states).
    sigma_l: Csr<StateId, f64>,
    plays_sigma_w: BitSet,
}

impl AdversaryModel {
    /// The model for `game`: `sigma_l` resolved against its arena (a weights file's errors in file
    /// order), and `sigma_W` where the adversary believes it is winning (outside
    /// [`GameView::believed_win`], with a safe action).
    pub fn new(game: &impl GameView, sigma_l: &SigmaL) -> Result<AdversaryModel, AdversaryError> {
        let arena = game.arena();
        let mut weights = unit_weights(arena);
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
            SigmaL::Weights { table, .. } => table.weights(arena, &mut weights)?,
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
    use crate::opportunistic::view::testing::{ToyGame, hs};

    /// sigma_L from the weights file `text`, which must read.
    fn weights(text: &str) -> SigmaL {
        SigmaL::Weights {
            table: WeightTable::parse(text).unwrap(),
            file: "w.txt".into(),
        }
    }

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
        let model = AdversaryModel::new(&g, &weights("# weights\ns5 y 3\n\"s5\" x 1 # trailing\n"))
            .unwrap();
        assert_eq!(distribution(&model, &g, 5), [0.25, 0.75]);
        g.ranks[1] = [Some(1), None, None];
        let model = AdversaryModel::new(&g, &weights("s5 y 2\n")).unwrap();
        assert_eq!(distribution(&model, &g, 5), [0.0, 1.0]);
        assert_eq!(distribution(&model, &g, 1), [1.0 / 3.0; 3]);
    }

    #[test]
    fn huge_weights_are_scaled_before_they_are_summed() {
        let g = game();
        let model = AdversaryModel::new(&g, &weights("s5 x 1e308\ns5 y 1e308\n")).unwrap();
        assert_eq!(distribution(&model, &g, 5), [0.5, 0.5]);
        let model = AdversaryModel::new(&g, &weights("s5 x 1.7e308\ns5 y 5e-324\n")).unwrap();
        let d = distribution(&model, &g, 5);
        assert_eq!(d[0], 1.0);
        assert!((d.iter().sum::<f64>() - 1.0).abs() < 1e-15);
    }

    /// The errors of reading `text` and resolving it against `game`, as (line, column, kind).
    fn errors(g: &ToyGame, text: &str) -> Vec<(usize, usize, WeightsError)> {
        let errors = WeightTable::parse(text)
            .and_then(|table| {
                let file = "w.txt".into();
                AdversaryModel::new(g, &SigmaL::Weights { table, file })
            })
            .unwrap_err();
        errors
            .iter()
            .map(|e| (e.position.line, e.position.column, e.message.clone()))
            .collect()
    }

    #[test]
    fn weights_file_errors_are_located_and_in_file_order() {
        let g = game();
        // A text, where its first error is, and what kind it is.
        type Case = (&'static str, (usize, usize), fn(&WeightsError) -> bool);
        let cases: [Case; 11] = [
            ("s5 x\n", (1, 1), |e| {
                *e == WeightsError::Syntax { found: 2 }
            }),
            ("\n  s5 x -1", (2, 8), |e| {
                matches!(e, WeightsError::Weight { .. })
            }),
            ("s5 x nan", (1, 6), |e| {
                matches!(e, WeightsError::Weight { .. })
            }),
            ("s5 x \"1\" {", (1, 10), |e| {
                matches!(e, WeightsError::Lexical(_))
            }),
            ("s5 x 1\ns5 y \"2", (2, 6), |e| {
                matches!(e, WeightsError::Lexical(_))
            }),
            ("s9 x 1", (1, 1), |e| {
                matches!(e, WeightsError::UnknownState { .. })
            }),
            ("s0 x 1", (1, 1), |e| {
                matches!(e, WeightsError::RobotState { .. })
            }),
            ("s5 z 1", (1, 4), |e| {
                matches!(e, WeightsError::UnknownAction { .. })
            }),
            ("s5 x 1\ns5 x 2", (2, 1), |e| {
                matches!(e, WeightsError::Duplicate { first_line: 1, .. })
            }),
            // All-zero is located at the state's first line.
            ("s1 x 1\ns5 x 0\ns1 q 2\n", (2, 1), |e| {
                matches!(e, WeightsError::AllZero { .. })
            }),
            ("s1 q 1\ns5 x 0\n", (1, 4), |e| {
                matches!(e, WeightsError::UnknownAction { .. })
            }),
        ];
        for (text, at, is_expected) in cases {
            let (line, column, kind) = errors(&g, text).swap_remove(0);
            assert_eq!((line, column), at, "{text:?}");
            assert!(is_expected(&kind), "{text:?}: {kind:?}");
        }
    }

    #[test]
    fn every_error_of_a_weights_file_is_reported() {
        let g = game();
        // Reading: every malformed line, the others skipped.
        let text = "s5 x\ns5 y 2 # fine\ns1 x -1\ns1 \"y\n\ns1 z 1 extra\n";
        assert_eq!(
            errors(&g, text),
            [
                (1, 1, WeightsError::Syntax { found: 2 }),
                (3, 6, WeightsError::Weight { text: "-1".into() }),
                (
                    4,
                    4,
                    WeightsError::Lexical(arena::ParseErrorKind::UnterminatedQuote)
                ),
                (6, 1, WeightsError::Syntax { found: 4 }),
            ]
        );
        // Meaning, once the file reads: every line checked, the all-zero state at its first
        // line.
        let text = "s5 x 0\ns9 x 1\ns0 go 1\ns1 q 1\ns5 y 0\ns5 x 2\ns1 x 1\n";
        let state = |name: &str| name.to_string();
        assert_eq!(
            errors(&g, text),
            [
                (1, 1, WeightsError::AllZero { state: state("s5") }),
                (2, 1, WeightsError::UnknownState { state: state("s9") }),
                (3, 1, WeightsError::RobotState { state: state("s0") }),
                (
                    4,
                    4,
                    WeightsError::UnknownAction {
                        state: state("s1"),
                        action: state("q")
                    }
                ),
                (
                    6,
                    1,
                    WeightsError::Duplicate {
                        state: state("s5"),
                        action: state("x"),
                        first_line: 1
                    }
                ),
            ]
        );
        // The same errors without a game.
        let table = WeightTable::parse(text).unwrap();
        assert_eq!(table.check(g.arena()).unwrap_err().total(), 5);
        assert_eq!(
            table.check(g.arena()).unwrap_err().first().to_string(),
            "1:1: every weight of adversary state `s5` is 0"
        );
    }
}

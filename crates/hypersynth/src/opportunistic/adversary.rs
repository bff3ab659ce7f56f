//! The adversary model: in each adversary state of the hypergame, a probability distribution
//! over its enabled actions (docs/semantics.md §6).
//!
//! - Where the state is losing for the robot in `G(psi)` (outside `Win(psi)`: `Win(phi1)` in the
//!   paper's form, [`GameView::believed_win`] in general, docs/semantics.md §8), the adversary
//!   believes it is winning and plays `sigma_W`: uniform over its *safe* actions, those whose
//!   successor stays outside `Win(psi)`. Such a state always has one (otherwise the attractor
//!   would contain it); should none exist, `sigma_L` is used instead.
//! - Elsewhere it plays `sigma_L` over all its enabled actions: uniform, seeded random weights,
//!   or a [`WeightTable`] (given as values, or read from a weights file).
//! - A stuck adversary state (no enabled action) has an empty distribution.
//!
//! **The adversary observes the arena, not the robot's automata.** `sigma_L` is one distribution
//! per *arena* state, over the arena state's edges; every product state over that arena state
//! plays it (a product state's edges are its arena state's, in the same order). Hence the full
//! and the reachable enumeration of the product give the same model on the states they share.
//! Only the choice between `sigma_W` and `sigma_L` depends on the product state (on `Win(psi)`).
//!
//! Random weights are a pure function of the seed, the arena state and the action
//! ([`random_weight`], docs/semantics.md §6): no stream, no table, so any numbering of the
//! states, any engine and any reader of an exported controller draws the same weights. A state
//! is keyed by its name, which every engine can give without storing anything.
//!
//! Weight table: entries `(STATE, ACTION, WEIGHT)`, where `STATE` is an adversary arena state,
//! `ACTION` one of its enabled actions and `WEIGHT` a finite number ≥ 0, each pair at most once.
//! A listed state plays its listed actions in proportion to their weights (unlisted actions get
//! 0, and at least one weight must be positive); unlisted states play uniformly. Weights are
//! divided by their maximum before they are summed, so that no sum overflows. Checking a table
//! against an arena ([`WeightTable::check`]) is linear in it and gives every error, by entry
//! ([`TableError`]).
//!
//! Weights file ([`WeightsFile`]): the table's entries one `STATE ACTION WEIGHT` per line, under
//! the arena format's lexical rules (names bare or double-quoted with the same escapes, `#`
//! comments; weights written bare, e.g. `2`, `0.5`, `1e-3`). Reading is linear in the file.
//! Every error is reported, in file order (the first 20): reading skips a malformed line and
//! goes on; the meaning of every well-formed line is checked against the arena once the file is
//! read, the table's errors located at their lines (so a file with a malformed line gets its
//! other lines checked only when it is fixed).
//!
//! Memory: one `f64` per edge of an adversary arena state (exactly: no room for the robot's
//! edges) and one bit per product state; the distribution of a product state is computed on
//! demand ([`AdversaryModel::distribution`]).

use std::collections::HashMap;
use std::fmt;

use bit_set::BitSet;
use serde::{Deserialize, Serialize};
use thiserror::Error;

use super::view::GameView;
use crate::arena::{self, Arena, Name, Owner, StateId};
use crate::csr::Csr;
use crate::diagnostic::{Collector, DEFAULT_LIMIT, Diagnostics, brief};
use crate::game::HState;
use crate::index::Id;
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
    /// A weight table (see the module documentation); unlisted states play uniformly.
    Weights {
        /// The weights.
        table: WeightTable,
        /// Where they come from (a file's name), as reports and pictures show it.
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

/// sigma_L's weights as values: entries `(arena state, action, weight)`, in the order given
/// (which orders their errors). A listed adversary state plays its listed actions in proportion
/// to their weights (unlisted actions weigh 0, at least one weight must be positive); unlisted
/// states play uniformly. [`WeightTable::check`] resolves the names against an arena.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct WeightTable {
    entries: Vec<Weight>,
}

/// One entry of a [`WeightTable`] (as exported controllers write it too).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Weight {
    /// An adversary arena state's name.
    pub state: String,
    /// One of its enabled actions.
    pub action: String,
    /// A finite number ≥ 0 ([`is_weight`]).
    pub weight: f64,
}

/// Whether `weight` can be a weight: a finite number ≥ 0.
pub fn is_weight(weight: f64) -> bool {
    weight.is_finite() && weight >= 0.0
}

/// What is wrong with one entry of a [`WeightTable`] on an arena.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum EntryError {
    /// A weight that is not a finite number ≥ 0.
    #[error("invalid weight `{weight}` (a finite number >= 0)")]
    Weight {
        /// The weight given.
        weight: f64,
    },
    /// A name that no arena state has.
    #[error("no arena state is named `{}`", Name(.state))]
    UnknownState {
        /// The state's name as given.
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
        /// The action's name as given.
        action: String,
    },
    /// The same state and action in two entries.
    #[error("weight of `{}` `{}` given twice", Name(.state), Name(.action))]
    Duplicate {
        /// The state's name.
        state: String,
        /// The action's name.
        action: String,
        /// The index of the entry that gave it first.
        first: usize,
    },
    /// A listed state whose weights are all 0.
    #[error("every weight of adversary state `{}` is 0", Name(.state))]
    AllZero {
        /// The state's name.
        state: String,
    },
}

/// The part of an entry an [`EntryError`] is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum EntryPart {
    /// The state's name.
    State,
    /// The action's name.
    Action,
    /// The weight.
    Weight,
}

/// An error of the entry `entry` (its index) of a [`WeightTable`], about its `part`.
#[derive(Clone, Debug, Error, PartialEq)]
#[error("{error}")]
pub struct TableError {
    /// The entry's index.
    pub entry: usize,
    /// Which part of it.
    pub part: EntryPart,
    /// What is wrong.
    pub error: EntryError,
}

/// Every error of a [`WeightTable`] on an arena (at least one), in entry order; an entry has at
/// most one, a listed state's all-zero weights are at its first entry.
#[derive(Clone, Debug, PartialEq)]
pub struct TableErrors(Vec<TableError>);

impl TableErrors {
    /// The first error.
    pub fn first(&self) -> &TableError {
        &self.0[0]
    }

    /// The errors, in entry order.
    pub fn as_slice(&self) -> &[TableError] {
        &self.0
    }
}

/// The errors one per line, each after its entry's index.
impl fmt::Display for TableErrors {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, error) in self.0.iter().enumerate() {
            if i > 0 {
                f.write_str("\n")?;
            }
            write!(f, "weight entry {}: {}", error.entry, error.error)?;
        }
        Ok(())
    }
}

impl std::error::Error for TableErrors {}

/// The errors of resolving sigma_L against a game: its weight table's
/// ([`AdversaryModel::new`]).
pub type AdversaryError = TableErrors;

impl WeightTable {
    /// The empty table: every state plays uniformly.
    pub fn new() -> WeightTable {
        WeightTable::default()
    }

    /// Adds the entry: `weight` for `action` in adversary state `state`.
    pub fn add(&mut self, state: impl Into<String>, action: impl Into<String>, weight: f64) {
        self.entries.push(Weight {
            state: state.into(),
            action: action.into(),
            weight,
        });
    }

    /// The entries, in the order given.
    pub fn entries(&self) -> &[Weight] {
        &self.entries
    }

    /// The table of a weights file (see the module documentation); on errors, the first 20 in
    /// file order. [`WeightsFile`] keeps where each entry is, to locate its errors on an arena.
    pub fn parse(text: &str) -> Result<WeightTable, WeightsFileErrors> {
        WeightsFile::parse(text).map(|file| file.table)
    }

    /// Checks every entry against `arena`: the errors [`AdversaryModel::new`] would give with
    /// these weights, found without a game.
    pub fn check(&self, arena: &impl ArenaLookup) -> Result<(), TableErrors> {
        self.resolve(arena).map(|_| ())
    }

    /// The listed states of `arena` with sigma_L's unnormalised weights of their edges, in
    /// edge order (the table's weight, or 0 for an unlisted action), in order of their first
    /// entry, after checking every entry: all errors, in entry order. The one resolution of a
    /// table's names, whichever engine asks.
    pub(crate) fn resolve<A: ArenaLookup>(
        &self,
        arena: &A,
    ) -> Result<Resolved<A::State>, TableErrors> {
        // Per listed arena state (by its place in `given`): the entry of each weight given, and
        // the first entry naming it.
        let mut places: HashMap<A::State, usize> = HashMap::new();
        let mut given: Vec<(A::State, Vec<Option<usize>>, usize)> = Vec::new();
        let mut errors = Vec::new();
        let mut fail = |entry, part, error| errors.push(TableError { entry, part, error });
        for (index, entry) in self.entries.iter().enumerate() {
            if !is_weight(entry.weight) {
                let weight = entry.weight;
                fail(index, EntryPart::Weight, EntryError::Weight { weight });
                continue;
            }
            let Some(state) = arena.find_state(&entry.state) else {
                let state = entry.state.clone();
                fail(index, EntryPart::State, EntryError::UnknownState { state });
                continue;
            };
            if arena.owner(state) == Owner::Robot {
                let state = entry.state.clone();
                fail(index, EntryPart::State, EntryError::RobotState { state });
                continue;
            }
            let Some(edge) = arena.find_edge(state, &entry.action) else {
                let (state, action) = (entry.state.clone(), entry.action.clone());
                fail(
                    index,
                    EntryPart::Action,
                    EntryError::UnknownAction { state, action },
                );
                continue;
            };
            let place = *places.entry(state).or_insert_with(|| {
                given.push((state, vec![None; arena.degree(state)], index));
                given.len() - 1
            });
            let edges = &mut given[place].1;
            if let Some(first) = edges[edge] {
                let error = EntryError::Duplicate {
                    state: entry.state.clone(),
                    action: entry.action.clone(),
                    first,
                };
                fail(index, EntryPart::State, error);
                continue;
            }
            edges[edge] = Some(index);
        }
        let mut listed = Vec::with_capacity(given.len());
        for (state, edges, first) in given {
            let weights: Vec<f64> = edges
                .iter()
                .map(|entry| entry.map_or(0.0, |i| self.entries[i].weight))
                .collect();
            if weights.iter().all(|&w| w == 0.0) {
                let state = self.entries[first].state.clone();
                fail(first, EntryPart::State, EntryError::AllZero { state });
            }
            listed.push((state, weights));
        }
        if errors.is_empty() {
            return Ok(listed);
        }
        // Entries have one error each, but for an all-zero state's first, found last.
        errors.sort_by_key(|e| (e.entry, e.part));
        Err(TableErrors(errors))
    }
}

/// A weight table resolved against an arena ([`WeightTable::resolve`]): per listed state, its
/// edges' unnormalised weights in edge order.
pub(crate) type Resolved<S> = Vec<(S, Vec<f64>)>;

/// What resolving names (a [`WeightTable`]'s, an observations file's) asks of an arena: states
/// found by name and named, each with its owner and its edges' actions. The stored [`Arena`]
/// answers, and so does every arena of the implicit engine's rules, without a name per state.
pub trait ArenaLookup {
    /// An arena state, numbered as the stored arena numbers it.
    type State: Id;
    /// The state named `name`, if any.
    fn find_state(&self, name: &str) -> Option<Self::State>;
    /// The name of `state`.
    fn state_name(&self, state: Self::State) -> String;
    /// The name of the action of edge `edge` of `state` (in edge order; `edge` is one of its
    /// edges).
    fn edge_action(&self, state: Self::State, edge: usize) -> String;
    /// Who moves in `state`.
    fn owner(&self, state: Self::State) -> Owner;
    /// The number of edges of `state`.
    fn degree(&self, state: Self::State) -> usize;
    /// The place, among the edges of `state` in edge order, of the first whose action is named
    /// `action`.
    fn find_edge(&self, state: Self::State, action: &str) -> Option<usize>;
}

impl ArenaLookup for Arena {
    type State = StateId;

    fn find_state(&self, name: &str) -> Option<StateId> {
        Arena::find_state(self, name)
    }

    fn state_name(&self, state: StateId) -> String {
        self.name(state).to_string()
    }

    fn edge_action(&self, state: StateId, edge: usize) -> String {
        let (action, _) = self.edges(state).nth(edge).expect("an edge of the state");
        self.action_name(action).to_string()
    }

    fn owner(&self, state: StateId) -> Owner {
        Arena::owner(self, state)
    }

    fn degree(&self, state: StateId) -> usize {
        self.edges(state).len()
    }

    fn find_edge(&self, state: StateId, action: &str) -> Option<usize> {
        self.edges(state)
            .position(|(a, _)| self.action_name(a) == action)
    }
}

/// A weights file read: its table, and where each entry is in the text (to locate the table's
/// errors on an arena).
#[derive(Clone, Debug, PartialEq)]
pub struct WeightsFile {
    /// The entries, one per line that has one, in file order.
    pub table: WeightTable,
    /// Per entry, where its state, action and weight are.
    places: Vec<[Position; 3]>,
}

/// What is wrong in a weights file, at a place the [`Diagnostic`](crate::diagnostic::Diagnostic)
/// gives.
#[derive(Clone, Debug, Error, PartialEq)]
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
    /// The same state and action on two lines.
    #[error(
        "weight of `{}` `{}` given twice (first on line {first_line})",
        Name(.state),
        Name(.action)
    )]
    Duplicate {
        /// The state's name.
        state: String,
        /// The action's name.
        action: String,
        /// The line of the first weight (1-based).
        first_line: usize,
    },
    /// A line whose entry does not fit the arena.
    #[error(transparent)]
    Entry(EntryError),
}

/// The errors of a weights file, located in it: found reading it ([`WeightsFile::parse`]) or
/// resolving it against an arena ([`WeightsFile::check`]).
pub type WeightsFileErrors = Diagnostics<WeightsError>;

impl WeightsFile {
    /// Parses a weights file; on errors, the first 20 in file order.
    pub fn parse(text: &str) -> Result<WeightsFile, WeightsFileErrors> {
        WeightsFile::parse_with_limit(text, DEFAULT_LIMIT)
    }

    /// Parses a weights file; on errors, the first `limit` in file order and the number of the
    /// others. Each line is checked on its own: a malformed line is reported and skipped.
    pub fn parse_with_limit(text: &str, limit: usize) -> Result<WeightsFile, WeightsFileErrors> {
        let mut file = WeightsFile {
            table: WeightTable::new(),
            places: Vec::new(),
        };
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
                [(state_at, state), (action_at, action), (weight_at, weight)] => {
                    let Some(value) = weight.parse::<f64>().ok().filter(|&w| is_weight(w)) else {
                        let text = weight.to_string();
                        errors.add(*weight_at, WeightsError::Weight { text });
                        continue;
                    };
                    file.table.add(state.to_string(), action.to_string(), value);
                    file.places.push([*state_at, *action_at, *weight_at]);
                }
                [(position, _), ..] => {
                    let found = names.len();
                    errors.add(*position, WeightsError::Syntax { found });
                }
            }
        }
        errors.or_ok(file)
    }

    /// Checks every line against `arena` ([`WeightTable::check`]); the errors, the first 20 in
    /// file order, located at their lines.
    pub fn check(&self, arena: &impl ArenaLookup) -> Result<(), WeightsFileErrors> {
        self.table
            .check(arena)
            .map_err(|errors| self.locate(&errors))
    }

    /// The table's errors at their places in the file.
    pub fn locate(&self, errors: &TableErrors) -> WeightsFileErrors {
        let mut located = Collector::new(DEFAULT_LIMIT);
        for TableError { entry, part, error } in errors.as_slice() {
            let [state, action, weight] = self.places[*entry];
            let position = match part {
                EntryPart::State => state,
                EntryPart::Action => action,
                EntryPart::Weight => weight,
            };
            let message = match error {
                EntryError::Duplicate {
                    state,
                    action,
                    first,
                } => WeightsError::Duplicate {
                    state: state.clone(),
                    action: action.clone(),
                    first_line: self.places[*first][0].line,
                },
                other => WeightsError::Entry(other.clone()),
            };
            located.add(position, message);
        }
        located.failed()
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

/// sigma_L's weights before they are divided by their sum: per adversary arena state, one per
/// edge in arena order (1 each under `uniform` and in a table's unlisted states, the draw of
/// [`random_weight`] under `random`, the table's weight, or 0, in its listed states); no row
/// entries for robot states. The one definition of sigma_L's weights: the MDP's adversary model
/// and a certificate's checker both take them from here. A table's errors in entry order.
pub fn sigma_l_weights(arena: &Arena, sigma_l: &SigmaL) -> Result<Csr<StateId, f64>, TableErrors> {
    let mut weights = unit_weights(arena);
    match sigma_l {
        SigmaL::Uniform => {}
        SigmaL::Random { seed } => {
            for s in arena.states() {
                let actions = arena.edges(s).map(|(a, _)| arena.action_name(a));
                for (weight, action) in weights.row_mut(s).iter_mut().zip(actions) {
                    *weight = random_weight(*seed, arena.name(s), action);
                }
            }
        }
        SigmaL::Weights { table, .. } => {
            for (state, given) in table.resolve(arena)? {
                weights.row_mut(state).copy_from_slice(&given);
            }
        }
    }
    Ok(weights)
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
        let mut weights = sigma_l_weights(arena, sigma_l)?;
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

/// The weight random sigma_L gives `action` in the arena state named `state` with seed `seed`:
/// an integer in `[1, 2^53]` (positive and exact as a float), a pure function of the three
/// (docs/semantics.md §6 defines it bit for bit, so that any engine and any reader of a
/// controller file draws the same). A state is keyed by its name, so a map and the arena it
/// expands to (`hypersynth gridworld --map`) draw the same weights. With `mix` SplitMix64's
/// finaliser and `fnv` the 64-bit FNV-1a hash: `h = mix(seed ^ 0x6879706572737973)`,
/// `h = mix(h ^ fnv(state))`, `h = mix(h ^ fnv(action))`, and the weight is `(h >> 11) + 1`.
pub fn random_weight(seed: u64, state: &str, action: &str) -> f64 {
    let mut state_hash = Fnv::default();
    state_hash.bytes(state.as_bytes());
    let mut action_hash = Fnv::default();
    action_hash.bytes(action.as_bytes());
    RandomState::new(seed, state_hash).weight(action_hash)
}

/// [`random_weight`] in two steps, for a caller that draws the weights of many actions of one
/// state, or hashes a state's name as it writes it: the state's part, then each action's.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RandomState(u64);

impl RandomState {
    /// The part of [`random_weight`] of the state whose name hashes to `state`, with `seed`.
    pub(crate) fn new(seed: u64, state: Fnv) -> RandomState {
        RandomState(mix(mix(seed ^ 0x6879_7065_7273_7973) ^ state.0))
    }

    /// The weight of the action whose name hashes to `action` in this state.
    pub(crate) fn weight(self, action: Fnv) -> f64 {
        ((mix(self.0 ^ action.0) >> 11) + 1) as f64
    }
}

/// The 64-bit FNV-1a hash of the bytes written into it, in order: a name hashed as it is
/// written, without a string.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Fnv(u64);

impl Default for Fnv {
    fn default() -> Fnv {
        Fnv(0xcbf2_9ce4_8422_2325)
    }
}

impl Fnv {
    /// The hash of `text`.
    pub(crate) fn of(text: &str) -> Fnv {
        let mut hash = Fnv::default();
        hash.bytes(text.as_bytes());
        hash
    }

    fn bytes(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
}

impl std::fmt::Write for Fnv {
    fn write_str(&mut self, text: &str) -> std::fmt::Result {
        self.bytes(text.as_bytes());
        Ok(())
    }
}

/// SplitMix64's finaliser: a bijection of 64-bit words that mixes every bit into every other.
fn mix(mut x: u64) -> u64 {
    x = (x ^ (x >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    x ^ (x >> 31)
}

/// Divides non-negative weights by their sum, after scaling by their maximum so that the sum
/// cannot overflow. All-zero (or empty) slices are left alone.
pub(crate) fn normalise(weights: &mut [f64]) {
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
    fn random_weights_are_a_pure_function_of_seed_state_and_action() {
        let g = game();
        let a = AdversaryModel::new(&g, &SigmaL::Random { seed: 7 }).unwrap();
        // Arena state a5 is named "s5", its actions x then y.
        let [x, y] = ["x", "y"].map(|action| random_weight(7, "s5", action));
        let drawn = distribution(&a, &g, 5);
        for (p, q) in drawn.iter().zip([x / (x + y), y / (x + y)]) {
            assert!((p - q).abs() <= 1e-15, "{drawn:?}");
        }
        // sigma_W is unaffected by the seed.
        assert_eq!(distribution(&a, &g, 1), [0.0, 0.5, 0.5]);
        let c = AdversaryModel::new(&g, &SigmaL::Random { seed: 8 }).unwrap();
        assert_ne!(distribution(&a, &g, 5), distribution(&c, &g, 5));
        // Weights are whole numbers in [1, 2^53], and the key's parts all count.
        let weights = [
            x,
            y,
            random_weight(7, "s1", "x"),
            random_weight(8, "s5", "x"),
        ];
        for w in weights {
            assert!((1.0..=9_007_199_254_740_992.0).contains(&w) && w.fract() == 0.0);
        }
        for (i, v) in weights.iter().enumerate() {
            assert!(weights[i + 1..].iter().all(|w| w != v), "{weights:?}");
        }
        // The same state under another numbering (renamed arenas keep their draws by name).
        assert_eq!(random_weight(7, "s5", "x"), x);
    }

    /// The two functions the draws are made of, against published test vectors: SplitMix64's
    /// first output from state 0 is `mix(0x9e3779b97f4a7c15)`, and FNV-1a 64 of "a" and of "".
    #[test]
    fn the_draws_mix_and_hash_as_published() {
        assert_eq!(mix(0x9e37_79b9_7f4a_7c15), 0xe220_a839_7b1d_cdaf);
        assert_eq!(Fnv::of("").0, 0xcbf2_9ce4_8422_2325);
        assert_eq!(Fnv::of("a").0, 0xaf63_dc4c_8601_ec8c);
        // Written in pieces, the same hash.
        let mut pieces = Fnv::default();
        std::fmt::Write::write_fmt(&mut pieces, format_args!("(({},{}),", 12, 3)).unwrap();
        assert_eq!(pieces.0, Fnv::of("((12,3),").0);
        // The weight of one key, computed step by step from the definition.
        let mut h = mix(5 ^ 0x6879_7065_7273_7973);
        h = mix(h ^ Fnv::of("s").0);
        h = mix(h ^ Fnv::of("a").0);
        assert_eq!(random_weight(5, "s", "a"), ((h >> 11) + 1) as f64);
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

    /// The errors of reading `text` and resolving its table against `game`, located in the
    /// text, as (line, column, kind).
    fn errors(g: &ToyGame, text: &str) -> Vec<(usize, usize, WeightsError)> {
        let errors = WeightsFile::parse(text)
            .and_then(|file| {
                let (table, name) = (file.table.clone(), "w.txt".into());
                AdversaryModel::new(g, &SigmaL::Weights { table, file: name })
                    .map_err(|errors| file.locate(&errors))
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
                matches!(e, WeightsError::Entry(EntryError::UnknownState { .. }))
            }),
            ("s0 x 1", (1, 1), |e| {
                matches!(e, WeightsError::Entry(EntryError::RobotState { .. }))
            }),
            ("s5 z 1", (1, 4), |e| {
                matches!(e, WeightsError::Entry(EntryError::UnknownAction { .. }))
            }),
            ("s5 x 1\ns5 x 2", (2, 1), |e| {
                matches!(e, WeightsError::Duplicate { first_line: 1, .. })
            }),
            // All-zero is located at the state's first line.
            ("s1 x 1\ns5 x 0\ns1 q 2\n", (2, 1), |e| {
                matches!(e, WeightsError::Entry(EntryError::AllZero { .. }))
            }),
            ("s1 q 1\ns5 x 0\n", (1, 4), |e| {
                matches!(e, WeightsError::Entry(EntryError::UnknownAction { .. }))
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
        let entry = WeightsError::Entry;
        assert_eq!(
            errors(&g, text),
            [
                (1, 1, entry(EntryError::AllZero { state: state("s5") })),
                (2, 1, entry(EntryError::UnknownState { state: state("s9") })),
                (3, 1, entry(EntryError::RobotState { state: state("s0") })),
                (
                    4,
                    4,
                    entry(EntryError::UnknownAction {
                        state: state("s1"),
                        action: state("q")
                    })
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
        let file = WeightsFile::parse(text).unwrap();
        assert_eq!(file.check(g.arena()).unwrap_err().total(), 5);
        assert_eq!(
            file.check(g.arena()).unwrap_err().first().to_string(),
            "1:1: every weight of adversary state `s5` is 0"
        );
    }

    #[test]
    fn a_table_of_values_gives_its_errors_by_entry_and_part() {
        let g = game();
        let mut table = WeightTable::new();
        table.add("s5", "x", 0.0); // 0: s5's first entry, all of its weights 0
        table.add("s9", "x", 1.0); // 1: no such state
        table.add("s1", "x", -1.0); // 2: a negative weight
        table.add("s1", "q", 1.0); // 3: not an action of s1
        table.add("s0", "go", f64::NAN); // 4: the weight is checked first
        table.add("s5", "x", 0.0); // 5: s5's x again
        table.add("s1", "y", f64::INFINITY); // 6
        let errors = table.check(g.arena()).unwrap_err();
        let found: Vec<(usize, EntryPart)> = errors
            .as_slice()
            .iter()
            .map(|e| (e.entry, e.part))
            .collect();
        assert_eq!(
            found,
            [
                (0, EntryPart::State),
                (1, EntryPart::State),
                (2, EntryPart::Weight),
                (3, EntryPart::Action),
                (4, EntryPart::Weight),
                (5, EntryPart::State),
                (6, EntryPart::Weight),
            ]
        );
        assert_eq!(
            errors.as_slice()[5].error,
            EntryError::Duplicate {
                state: "s5".into(),
                action: "x".into(),
                first: 0
            }
        );
        assert_eq!(
            errors.first().to_string(),
            "every weight of adversary state `s5` is 0"
        );
        assert_eq!(
            errors.as_slice()[2].to_string(),
            "invalid weight `-1` (a finite number >= 0)"
        );
        // A valid table of values weighs as the same file does.
        let mut table = WeightTable::new();
        table.add("s5", "y", 3.0);
        table.add("s5", "x", 1.0);
        assert_eq!(table, WeightTable::parse("s5 y 3\n\"s5\" x 1\n").unwrap());
        let sigma_l = SigmaL::Weights {
            table,
            file: "values".into(),
        };
        let model = AdversaryModel::new(&g, &sigma_l).unwrap();
        assert_eq!(distribution(&model, &g, 5), [0.25, 0.75]);
    }
}

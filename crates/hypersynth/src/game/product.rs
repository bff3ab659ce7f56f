//! The hypergame product `H = S × Q1 × Q2` of an arena with the DFAs of `phi1` and `phi2`, as an
//! explicit graph; more generally `S × Q_1 × … × Q_m` with any number of automata
//! (docs/semantics.md §8: k sub-tasks and possibly the adversary's belief), built by [`Hypergame::with_automata`].
//! Everything below is said for two automata and holds for m of them with mixed-radix ids.
//!
//! Semantics (docs/semantics.md §4): `Δ((s,q1,q2), a) = (s', δ1(q1, L(s')), δ2(q2, L(s')))` with
//! `s' = T(s,a)`; the owner of `(s,q1,q2)` is the owner of `s`; the automata read the initial
//! label first, so `h0 = (s0, δ1(q01, L(s0)), δ2(q02, L(s0)))`.
//!
//! Enumeration:
//! - [`States::Full`]: every arena state with every pair `(q1, q2)` where `qi` is reachable in
//!   DFA i from its initial state by a sequence of letters that label some arena state. We read
//!   "reachable" as usual, including the empty sequence, so the initial DFA state is always
//!   enumerated even when no label leads back to it. This set is closed under `Δ` and contains
//!   `h0`, so strategies computed on it cover every configuration. Product state ids are
//!   `(s · |Q1| + i1) · |Q2| + i2`, where `i1`, `i2` are the positions of `q1`, `q2` among the
//!   enumerated DFA states (in breadth-first discovery order from the initial state).
//! - [`States::Reachable`]: only the states reachable from `h0`, numbered in breadth-first
//!   order from `h0` (so `h0` is state 0).
//!
//! Representation: one product edge per arena edge, in the arena's edge order, so that the
//! action of a product state's `k`-th edge is its arena state's `k`-th and is not stored. The
//! full enumeration stores no successor at all: the target of `h`'s `k`-th edge is
//! `s' · |Q1|·|Q2| + local'`, with `s'` the target of the arena edge and `local'` the automata's
//! states after reading `L(s')` from `h`'s (its slot's *local* part, `slot mod |Q1|·|Q2|`),
//! computed on demand; `local'` is looked up in a table per (local part, distinct arena label)
//! when that has at most as many entries as the arena has states (or 2^16), which is the usual
//! case, and otherwise composed from each automaton's step. Edge ids are still those of a CSR
//! layout, found from the arena's degrees. The reachable enumeration stores its successors in
//! CSR form (a [`Csr`] of targets). Predecessors are the transpose,
//! one entry per edge (an adversary state with two actions into one state is listed twice,
//! which the attractor's counters rely on), built with the product; only the attractors need
//! them: once they are computed, [`Hypergame::release_predecessors`] frees them (a later call
//! to [`Hypergame::predecessors`] builds them again). Memory, with `E` edges and `N` states:
//! nothing per state for the full enumeration (an offset per arena state and the step table),
//! `4N + 4E` for the predecessors while they are held, and for the reachable enumeration
//! `4N + 4E` of successors and 8 bytes per reachable state to convert between ids and slots (a
//! hash map while enumerating, a sorted array afterwards: nothing per state of the full space).
//! DFA steps are tabulated once per (enumerated DFA state, distinct arena label), so building
//! the product costs no guard evaluation per edge. Arena
//! propositions meet the automaton's by name; propositions an automaton mentions that no arena
//! state carries are always false and are reported by [`Hypergame::missing_propositions`]; those
//! among them the arena does not even declare ([`Hypergame::unknown_propositions`]) are worth a
//! warning.
//!
//! Indices are 32-bit ([`HState`], and `u32` slots): the full space `|S| · |Q1| · |Q2|` (whose
//! slots both enumerations use) and the number of edges must stay below `2^32 - 1`.
//!
//! Names: a product state is named `ARENA_STATE|Q1|Q2`, e.g. `((0,2),(4,2),0)|0|1`, with the
//! DFA states as their numbers in the automata. [`Hypergame::parse_state`] splits at the last two
//! `|`, so arena state names may themselves contain `|`.

use std::cell::RefCell;
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};
use std::ops::Range;
use std::sync::OnceLock;

use bit_set::BitSet;

use super::sets::TaskSet;
use crate::arena::{ActionId, Arena, LabelId, Owner, StateId};
use crate::automata::{Dfa, DfaState};
use crate::csr::Csr;
use crate::index::{Id, IdRange, id_type};
use crate::limits::MemoryLimit;
use crate::position::Position;
use crate::stage::{Meter, Stage};

id_type! {
    /// A product (hypergame) state, indexing `0..Hypergame::num_states()`.
    pub struct HState;
}

/// Which product states are enumerated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum States {
    /// Every arena state × every pair of DFA states reachable by arena labels.
    #[default]
    Full,
    /// Only the states reachable from the initial state.
    Reachable,
}

/// Which engine holds the product (docs/engines.md): the stored product and its stages, or the
/// implicit engine, which computes states and edges from the arena's rules and stores a few
/// bits and bytes per state.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Engine {
    /// Every stage stores what it computes (about 150 bytes per product state with the MDP).
    #[default]
    Explicit,
    /// Nothing is stored per product state but bits, bytes and the solver's bounds (about 20
    /// bytes per product state with the MDP).
    Implicit,
}

impl Engine {
    /// The engine's name in reports and options: `explicit` or `implicit`.
    pub fn name(self) -> &'static str {
        match self {
            Engine::Explicit => "explicit",
            Engine::Implicit => "implicit",
        }
    }
}

/// The arena state and the first two automaton states of a product state (the paper's form).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ProductState {
    /// The arena state.
    pub arena: StateId,
    /// The state of phi1's automaton (the first one).
    pub q1: DfaState,
    /// The state of phi2's automaton (the second one).
    pub q2: DfaState,
}

/// Why a product cannot be built.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum HypergameError {
    /// More states or edges than 32-bit indices allow (the count found so far).
    #[error(
        "the product is too large: {0} states or edges, more than the 4294967294 that 32-bit \
         indices allow"
    )]
    TooLarge(u64),
    /// The product, and the attractors computed on it, would need more memory than the
    /// observer allows ([`crate::stage::Observer::reserve`]).
    #[error(transparent)]
    Memory(#[from] MemoryLimit),
}

/// About the bytes that the predecessor lists of a product of `states` states and `edges`
/// edges with `automata` automata take, with the attractors computed on it at their peak:
/// `4N + 4E` of predecessors; per attractor, a rank per state and the region's bits kept
/// (`4N + N/8`), and while it runs a rank and counter pair and a queue entry per state (about
/// `16N` with the queue's spare room), for as many attractors as run at once (one per thread).
/// There are at most `2^k − 1` attractors with `k` automata (the paper's 3).
fn reserved_bytes(states: u64, edges: u64, automata: usize) -> u64 {
    let attractors = (1u64 << automata.min(16)) - 1;
    let running = attractors.min(rayon::current_num_threads().max(1) as u64);
    let predecessors = 4 * (states + 1) + 4 * edges;
    let kept = attractors * (4 * states + states / 8);
    predecessors
        .saturating_add(kept)
        .saturating_add(running * 16 * states)
}

/// The bytes the reachable enumeration adds per state discovered, beside its successors: the
/// slot (4), the hash map's entry with its spare room (about 16), the successors' offset (4).
const REACHABLE_BYTES_PER_STATE: u64 = 24;

/// How many states the reachable enumeration discovers between two memory checks.
const RESERVE_EVERY: u32 = 1 << 16;

/// Why a product state name does not denote a state of this product. Positions are 1-based
/// columns in the name (line 1).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum StateNameError {
    /// Not of the form `ARENA_STATE|Q1|Q2…`; the text is the form expected.
    #[error("{0}: expected a product state `{1}`")]
    Malformed(Position, String),
    /// The arena has no state of that name (given).
    #[error("{0}: no arena state is called `{1}`")]
    UnknownArenaState(Position, String),
    /// An automaton state that is not a number of that automaton.
    #[error("{position}: `{text}` is not a state of the automaton of {automaton}")]
    NoSuchDfaState {
        /// Where the automaton state starts in the name.
        position: Position,
        /// The automaton's name (its task).
        automaton: String,
        /// The text given for its state.
        text: String,
    },
    #[error(
        "{position}: state {state} of the automaton of {automaton} is not enumerated: no \
         sequence of arena labels leads to it"
    )]
    /// An automaton state that no sequence of arena labels reaches, so the product has no state
    /// with it.
    NotEnumerated {
        /// Where the automaton state starts in the name.
        position: Position,
        /// The automaton's name (its task).
        automaton: String,
        /// The automaton state given.
        state: DfaState,
    },
    /// A well-formed state that the product does not enumerate because it is unreachable from
    /// h0 (only with `States::Reachable`); the text is the name given.
    #[error(
        "{0}: `{1}` is not reachable from the initial state (only reachable states were enumerated)"
    )]
    Unreachable(Position, String),
}

impl StateNameError {
    /// The error of `text`, the name of a product state the reachable enumeration leaves out.
    pub(crate) fn unreachable(text: &str) -> StateNameError {
        StateNameError::Unreachable(Position::of_offset(text, 0), text.to_string())
    }
}

/// One automaton restricted to its enumerated states ("slots"), with its steps tabulated per
/// distinct arena label.
#[derive(Clone, Debug)]
pub(crate) struct Component {
    /// The enumerated DFA states, in breadth-first discovery order from the initial state.
    states: Vec<DfaState>,
    /// The slot of each DFA state, `u32::NONE` if not enumerated.
    slot_of: Vec<u32>,
    /// `step[slot * num_labels + label]`: the slot reached by reading that label.
    step: Vec<u32>,
    num_labels: usize,
    /// Final slots.
    finals: BitSet,
    /// The slot after reading the initial arena state's label.
    initial: u32,
}

impl Component {
    fn new(dfa: &Dfa, arena: &Arena) -> Component {
        let initial = arena.label_id(arena.initial());
        Component::over_labels(dfa, arena.labels(), arena.propositions(), initial)
    }

    /// The automaton restricted to the states that sequences of `labels` (sets of indices into
    /// `propositions`, numbered as [`LabelId`]s) reach, the initial state having read label
    /// `initial`: what [`Component::new`] does with an arena's labels, for an arena that is
    /// described by rules instead of stored.
    pub(crate) fn over_labels(
        dfa: &Dfa,
        labels: &[BitSet],
        propositions: &[String],
        initial: LabelId,
    ) -> Component {
        let letters: Vec<u64> = labels
            .iter()
            .map(|label| dfa.letter(label.iter().map(|p| propositions[p].as_str())))
            .collect();
        let num_labels = letters.len();
        let mut slot_of = vec![u32::NONE; dfa.num_states()];
        let mut states = vec![dfa.initial()];
        slot_of[dfa.initial() as usize] = 0;
        let mut step = Vec::with_capacity(num_labels);
        let mut next = 0;
        while next < states.len() {
            let q = states[next];
            for &letter in &letters {
                let target = dfa.step(q, letter);
                if slot_of[target as usize].is_none() {
                    slot_of[target as usize] = states.len() as u32;
                    states.push(target);
                }
                step.push(slot_of[target as usize]);
            }
            next += 1;
        }
        let finals = (0..states.len())
            .filter(|&slot| dfa.is_final(states[slot]))
            .collect();
        let initial = step[initial as usize];
        Component {
            states,
            slot_of,
            step,
            num_labels,
            finals,
            initial,
        }
    }

    pub(crate) fn len(&self) -> u64 {
        self.states.len() as u64
    }

    pub(crate) fn step(&self, slot: u32, label: LabelId) -> u32 {
        self.step[slot as usize * self.num_labels + label as usize]
    }

    /// Whether the DFA state of `slot` is final.
    pub(crate) fn is_final(&self, slot: u32) -> bool {
        self.finals.contains(slot as usize)
    }

    /// The slot reached from the initial state by reading the initial arena state's label.
    pub(crate) fn initial(&self) -> u32 {
        self.initial
    }

    /// The enumerated DFA states, by slot.
    pub(crate) fn states(&self) -> &[DfaState] {
        &self.states
    }

    /// The slot of DFA state `q`, if it is enumerated.
    pub(crate) fn slot_of(&self, q: DfaState) -> Option<u32> {
        self.slot_of
            .get(q as usize)
            .copied()
            .filter(|slot| !slot.is_none())
    }
}

/// How product state ids relate to slots `(s · |Q1| + i1) · |Q2| + i2` of the full space.
#[derive(Clone, Debug)]
enum Numbering {
    /// Ids are slots.
    Full,
    /// `slots[id]` is the slot of state `id`; `ids` the ids of the slots numbered so far,
    /// while enumerating; once done, `by_slot` lists the ids in increasing order of their
    /// slots (found by binary search) and `ids` is empty.
    Reachable {
        slots: Vec<u32>,
        ids: HashMap<u32, HState, BuildHasherDefault<SlotHasher>>,
        by_slot: Vec<HState>,
    },
}

/// A hasher for slots (`u32`): one multiplication, the high half folded into the low one so
/// that the table's bucket bits and tag bits both depend on every bit of the slot.
#[derive(Default)]
struct SlotHasher(u64);

impl Hasher for SlotHasher {
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u32(u32::from(b));
        }
    }

    fn write_u32(&mut self, slot: u32) {
        let h = (self.0 ^ u64::from(slot)).wrapping_mul(0x9e37_79b9_7f4a_7c15);
        self.0 = h ^ (h >> 32);
    }

    fn finish(&self) -> u64 {
        self.0
    }
}

/// Where the successors of the product states come from.
#[derive(Clone, Debug)]
enum Successors {
    /// Computed from the arena edges and the automata's steps (the full enumeration). Per arena
    /// state, where its edges start among the arena's (one more at the end): the product's edge
    /// ids follow from them.
    Implicit { arena_offsets: Vec<u32> },
    /// Stored, per state (the reachable enumeration).
    Explicit(Csr<HState, HState>),
}

/// The hypergame graph over an arena (borrowed, for names, owners and edges).
#[derive(Clone, Debug)]
pub struct Hypergame<'a> {
    arena: &'a Arena,
    enumeration: States,
    /// One per automaton, in the order given; the names are those of error messages.
    components: Vec<Component>,
    names: Vec<String>,
    /// `strides[i]`: the weight of automaton `i`'s slot in a product slot; `arena_stride` that
    /// of the arena state (the product of all the automata's sizes).
    strides: Vec<u32>,
    arena_stride: u32,
    /// The number of distinct arena labels.
    num_labels: usize,
    /// `local_step[local * num_labels + label]`: the local part of the slot reached from one of
    /// local part `local` into an arena state labelled `label`; empty (each automaton steps on
    /// its own) when it would have more entries than the arena has states and 2^16.
    local_step: Vec<u32>,
    numbering: Numbering,
    num_states: usize,
    num_edges: usize,
    /// The successors, one per enabled action (the arena state's, in its order).
    successors: Successors,
    /// Per state, the sources of the edges into it, one entry per edge: built with the
    /// product, released by [`Hypergame::release_predecessors`], built again if asked for.
    predecessors: OnceLock<Csr<HState, HState>>,
    initial: HState,
    missing_propositions: Vec<String>,
}

impl<'a> Hypergame<'a> {
    /// Builds the product of `arena` with `dfa1` (for `phi1`) and `dfa2` (for `phi2`).
    pub fn new(
        arena: &'a Arena,
        dfa1: &Dfa,
        dfa2: &Dfa,
        enumeration: States,
    ) -> Result<Hypergame<'a>, HypergameError> {
        Hypergame::with_automata(arena, &[("phi1", dfa1), ("phi2", dfa2)], enumeration)
    }

    /// Builds the product of `arena` with any number of named automata, in the order given
    /// (their names appear in [`StateNameError`]s). Product state ids, names and edges follow
    /// the two-automaton case with mixed-radix slots `((s · |Q_1| + i_1) · |Q_2| + i_2) · …`.
    pub fn with_automata(
        arena: &'a Arena,
        automata: &[(&str, &Dfa)],
        enumeration: States,
    ) -> Result<Hypergame<'a>, HypergameError> {
        let meter = &mut Meter::unobserved(Stage::Product);
        Hypergame::with_automata_metered(arena, automata, enumeration, meter)
    }

    /// [`Hypergame::with_automata`], reporting to `meter` the states whose predecessor lists
    /// are built (two passes over the states). The reachable enumeration before that does not
    /// know its total, and reports nothing.
    pub fn with_automata_metered(
        arena: &'a Arena,
        automata: &[(&str, &Dfa)],
        enumeration: States,
        meter: &mut Meter<'_>,
    ) -> Result<Hypergame<'a>, HypergameError> {
        let components: Vec<Component> = automata
            .iter()
            .map(|(_, dfa)| Component::new(dfa, arena))
            .collect();
        let per_arena_state = components
            .iter()
            .fold(1u64, |size, c| size.saturating_mul(c.len()));
        let full = (arena.num_states() as u64).saturating_mul(per_arena_state);
        if full >= u32::NONE as u64 {
            return Err(HypergameError::TooLarge(full));
        }
        let mut strides = vec![1u32; components.len()];
        for i in (0..components.len().saturating_sub(1)).rev() {
            strides[i] = strides[i + 1] * components[i + 1].len() as u32;
        }
        let mut numbering = match enumeration {
            States::Full => Numbering::Full,
            States::Reachable => Numbering::Reachable {
                slots: Vec::new(),
                ids: HashMap::default(),
                by_slot: Vec::new(),
            },
        };
        let dfas: Vec<&Dfa> = automata.iter().map(|(_, dfa)| *dfa).collect();
        let num_labels = arena.labels().len();
        // At most one entry per arena state (or 2^16): never one per state of the full space.
        let table_limit = (arena.num_states() as u64).max(1 << 16);
        let local_step = if per_arena_state.saturating_mul(num_labels as u64) <= table_limit {
            let mut table = Vec::with_capacity(per_arena_state as usize * num_labels);
            for local in 0..per_arena_state as u32 {
                for label in 0..num_labels as LabelId {
                    table.push(
                        components
                            .iter()
                            .zip(&strides)
                            .map(|(c, &stride)| {
                                c.step(local / stride % c.len() as u32, label) * stride
                            })
                            .sum::<u32>(),
                    );
                }
            }
            table
        } else {
            Vec::new()
        };
        let mut game = Hypergame {
            arena,
            enumeration,
            names: automata.iter().map(|(name, _)| name.to_string()).collect(),
            components,
            strides,
            arena_stride: per_arena_state as u32,
            num_labels,
            local_step,
            numbering: Numbering::Full,
            num_states: 0,
            num_edges: 0,
            successors: Successors::Explicit(Csr::new()),
            predecessors: OnceLock::new(),
            initial: HState::NONE,
            missing_propositions: missing_propositions(arena.propositions(), arena.labels(), &dfas),
        };
        if enumeration == States::Full {
            // Every arena transition appears once per tuple of DFA states.
            let edges = arena.num_transitions() as u64 * per_arena_state;
            if edges >= u32::NONE as u64 {
                return Err(HypergameError::TooLarge(edges));
            }
            (game.num_states, game.num_edges) = (full as usize, edges as usize);
            meter.reserve(reserved_bytes(full, edges, automata.len()), || {
                format!("the product ({full} states, {edges} edges) with its attractors")
            })?;
            let mut arena_offsets = Vec::with_capacity(arena.num_states() + 1);
            arena_offsets.push(0u32);
            for s in arena.states() {
                arena_offsets.push(arena_offsets[s.index()] + arena.edges(s).len() as u32);
            }
            game.successors = Successors::Implicit { arena_offsets };
            game.initial = HState::from_u32(game.initial_slot());
            game.predecessors = OnceLock::from(game.transpose(meter));
            return Ok(game);
        }
        let mut successors = Csr::new();
        game.initial = numbering.id(game.initial_slot());
        let mut state = HState::new(0);
        let degree = arena_degree(arena);
        while state.as_u32() < numbering.discovered(full as u32) {
            if state.as_u32().is_multiple_of(RESERVE_EVERY) {
                // The next states' share, and what the hash map takes when it next doubles.
                let discovered = u64::from(numbering.discovered(full as u32));
                let growth = (u64::from(RESERVE_EVERY) + discovered) * REACHABLE_BYTES_PER_STATE
                    + u64::from(RESERVE_EVERY) * 4 * degree;
                meter.reserve(growth, || {
                    format!("the reachable product ({discovered} states so far)")
                })?;
            }
            let slot = numbering.slot(state);
            let (s, local) = (slot / game.arena_stride, slot % game.arena_stride);
            for (_, successor) in arena.edges(StateId::from_u32(s)) {
                successors.push(numbering.id(game.target_slot(local, successor)));
            }
            let edges = successors.num_entries();
            if edges >= u32::NONE as usize {
                return Err(HypergameError::TooLarge(edges as u64));
            }
            successors.finish_row();
            state = HState::from_u32(state.as_u32() + 1);
        }
        numbering.finish();
        game.numbering = numbering;
        successors.shrink_to_fit();
        (game.num_states, game.num_edges) = (successors.num_rows(), successors.num_entries());
        let (states, edges) = (game.num_states as u64, game.num_edges as u64);
        meter.reserve(reserved_bytes(states, edges, automata.len()), || {
            format!("the reachable product ({states} states, {edges} edges) with its attractors")
        })?;
        game.successors = Successors::Explicit(successors);
        game.predecessors = OnceLock::from(game.transpose(meter));
        Ok(game)
    }

    /// The slot of `h0`: the arena's initial state, each automaton after reading its label.
    fn initial_slot(&self) -> u32 {
        self.arena.initial().as_u32() * self.arena_stride
            + self
                .components
                .iter()
                .zip(&self.strides)
                .map(|(c, &stride)| c.initial * stride)
                .sum::<u32>()
    }

    /// The slot reached from a slot of local part `local` by an edge into arena state
    /// `successor` (each automaton reads the successor's label).
    #[inline]
    fn target_slot(&self, local: u32, successor: StateId) -> u32 {
        let label = self.arena.label_id(successor);
        let local = if self.local_step.is_empty() {
            self.components
                .iter()
                .zip(&self.strides)
                .map(|(c, &stride)| c.step(local / stride % c.len() as u32, label) * stride)
                .sum::<u32>()
        } else {
            self.local_step[local as usize * self.num_labels + label as usize]
        };
        successor.as_u32() * self.arena_stride + local
    }

    /// The predecessor lists: the transpose of the successors, sources ascending. `meter`
    /// counts the states of both passes over the successors.
    fn transpose(&self, meter: &mut Meter<'_>) -> Csr<HState, HState> {
        meter.set_total(2 * self.num_states as u64);
        // `group_from` calls the closure once per pass (and once more for its first item).
        let meter = RefCell::new(meter);
        Csr::group_from(self.num_states, || {
            self.states()
                .inspect(|_| meter.borrow_mut().advance(1))
                .flat_map(|h| self.successors(h).map(move |target| (target, h)))
        })
    }

    /// The slot of automaton `i`'s state within the product slot `slot`.
    fn automaton_slot(&self, slot: u32, i: usize) -> u32 {
        slot / self.strides[i] % self.components[i].len() as u32
    }

    /// The arena the product was built on.
    pub fn arena(&self) -> &'a Arena {
        self.arena
    }

    /// Which product states were enumerated.
    pub fn enumeration(&self) -> States {
        self.enumeration
    }

    /// The number of product states (ids `0..num_states()`).
    pub fn num_states(&self) -> usize {
        self.num_states
    }

    /// Every product state, in order.
    pub fn states(&self) -> IdRange<HState> {
        HState::range(self.num_states())
    }

    /// The number of product edges (one per enabled arena edge of each product state).
    pub fn num_edges(&self) -> usize {
        self.num_edges
    }

    /// `h0`.
    pub fn initial(&self) -> HState {
        self.initial
    }

    /// The enumerated states of the automaton of `phi1` (`Q1` of the product), in breadth-first
    /// discovery order from its initial state.
    pub fn q1_states(&self) -> &[DfaState] {
        self.automaton_states(0)
    }

    /// The enumerated states of the automaton of `phi2` (`Q2` of the product).
    pub fn q2_states(&self) -> &[DfaState] {
        self.automaton_states(1)
    }

    /// The automata's part of `h`'s slot: `h`'s automata states as one number in
    /// `0..num_automata_slots()`, mixed radix over the positions of each automaton's state in
    /// [`Self::automaton_states`] (the first automaton most significant).
    pub fn automata_slot(&self, h: HState) -> u32 {
        self.numbering.slot(h) % self.arena_stride
    }

    /// The number of automata slots: the product of the automata's enumerated state counts.
    pub fn num_automata_slots(&self) -> u32 {
        self.arena_stride
    }

    /// The automata states of automata slot `slot` (see [`Self::automata_slot`]), one per
    /// automaton.
    pub fn automata_of_slot(&self, slot: u32) -> Vec<DfaState> {
        (0..self.num_automata())
            .map(|i| self.components[i].states[self.automaton_slot(slot, i) as usize])
            .collect()
    }

    /// The number of automata in the product.
    pub fn num_automata(&self) -> usize {
        self.components.len()
    }

    /// The enumerated states of automaton `i` (in the order given to [`Self::with_automata`]).
    pub fn automaton_states(&self, i: usize) -> &[DfaState] {
        &self.components[i].states
    }

    /// Propositions some automaton mentions but no arena state carries (always false), in the
    /// order of the automata's propositions, `phi1`'s first, without repetition.
    pub fn missing_propositions(&self) -> &[String] {
        &self.missing_propositions
    }

    /// The [missing propositions](Hypergame::missing_propositions) the arena does not declare
    /// either, in the same order: a misspelt name, most likely, and worth a warning. A declared
    /// proposition that no state carries is deliberate (docs/semantics.md §3.3: the gridworld
    /// declares the obstacles' `O`, which nobody stands on, so that `!O U A` may say "avoid
    /// obstacles"), and draws none.
    pub fn unknown_propositions(&self) -> impl Iterator<Item = &str> {
        self.missing_propositions
            .iter()
            .filter(|p| self.arena.find_proposition(p).is_none())
            .map(String::as_str)
    }

    /// The arena state of `h`.
    pub fn arena_state(&self, h: HState) -> StateId {
        StateId::from_u32(self.numbering.slot(h) / self.arena_stride)
    }

    /// The state of automaton `i` in `h`.
    pub fn automaton_state(&self, h: HState, i: usize) -> DfaState {
        let slot = self.automaton_slot(self.numbering.slot(h), i);
        self.components[i].states[slot as usize]
    }

    /// The arena state and the first two DFA states of `h`.
    pub fn state(&self, h: HState) -> ProductState {
        ProductState {
            arena: self.arena_state(h),
            q1: self.automaton_state(h, 0),
            q2: self.automaton_state(h, 1),
        }
    }

    /// The product state with these components, if it is enumerated.
    pub fn find(&self, state: ProductState) -> Option<HState> {
        self.find_tuple(state.arena, &[state.q1, state.q2])
    }

    /// The product state over arena state `arena` with these automaton states (one per
    /// automaton), if it is enumerated.
    pub fn find_tuple(&self, arena: StateId, automata: &[DfaState]) -> Option<HState> {
        if arena.index() >= self.arena.num_states() || automata.len() != self.components.len() {
            return None;
        }
        let mut slot = arena.as_u32() * self.arena_stride;
        for ((component, &q), &stride) in self.components.iter().zip(automata).zip(&self.strides) {
            slot += component.slot_of(q)? * stride;
        }
        self.numbering.find(slot)
    }

    /// Who moves in `h`: the owner of its arena state.
    pub fn owner(&self, h: HState) -> Owner {
        self.arena.owner(self.arena_state(h))
    }

    /// Whether automaton `i` is in a final state in `h`.
    pub fn is_final(&self, i: usize, h: HState) -> bool {
        let slot = self.automaton_slot(self.numbering.slot(h), i);
        self.components[i].finals.contains(slot as usize)
    }

    /// Whether every automaton of `set` is final in `h`: the target sets `F1`, `F2`, `F12` of
    /// the paper's tasks, `∩_{i∈T} F_i` in general (docs/semantics.md §4).
    pub fn is_target(&self, set: TaskSet, h: HState) -> bool {
        set.iter().all(|i| self.is_final(i, h))
    }

    /// The target set of `set` as a region.
    pub fn targets(&self, set: TaskSet) -> BitSet {
        self.states()
            .filter(|&h| self.is_target(set, h))
            .map(HState::index)
            .collect()
    }

    /// The states where automaton `i` is final.
    pub fn final_states(&self, i: usize) -> BitSet {
        self.states()
            .filter(|&h| self.is_final(i, h))
            .map(HState::index)
            .collect()
    }

    /// The edge ids of `h` (`0..num_edges()` over all states, each state's consecutive, in
    /// state order), in the order of [`Self::edges`].
    pub fn edge_range(&self, h: HState) -> Range<usize> {
        match &self.successors {
            Successors::Explicit(successors) => successors.range(h),
            Successors::Implicit { arena_offsets } => {
                // Full enumeration: id = slot. The arena states before `s` contribute all their
                // edges once per local part, then come the local parts before `h`'s.
                let (s, local) = (
                    h.index() / self.arena_stride as usize,
                    h.index() % self.arena_stride as usize,
                );
                let (start, end) = (arena_offsets[s] as usize, arena_offsets[s + 1] as usize);
                let degree = end - start;
                let first = start * self.arena_stride as usize + local * degree;
                first..first + degree
            }
        }
    }

    /// The successors of `h`, one per enabled action, in the arena's edge order.
    pub fn successors(&self, h: HState) -> impl ExactSizeIterator<Item = HState> + '_ {
        self.edges(h).map(|(_, target)| target)
    }

    /// The enabled actions of `h` with their successors, in the arena's edge order (the
    /// actions are read from the arena: the `k`-th edge of `h` is its arena state's `k`-th).
    pub fn edges(&self, h: HState) -> impl ExactSizeIterator<Item = (ActionId, HState)> + '_ {
        let slot = self.numbering.slot(h);
        let (s, local) = (slot / self.arena_stride, slot % self.arena_stride);
        let stored: &[HState] = match &self.successors {
            Successors::Explicit(successors) => successors.row(h),
            Successors::Implicit { .. } => &[],
        };
        self.arena
            .edges(StateId::from_u32(s))
            .enumerate()
            .map(move |(k, (action, successor))| {
                let target = match stored.get(k) {
                    Some(&target) => target,
                    // Implicit: the full enumeration, where ids are slots.
                    None => HState::from_u32(self.target_slot(local, successor)),
                };
                (action, target)
            })
    }

    /// The sources of the edges into `h`, one entry per edge (built again, once, if
    /// [`Self::release_predecessors`] freed them).
    pub fn predecessors(&self, h: HState) -> &[HState] {
        self.predecessors
            .get_or_init(|| self.transpose(&mut Meter::unobserved(Stage::Product)))
            .row(h)
    }

    /// Frees the predecessor lists (`4N + 4E` bytes), which only the attractors use: the
    /// stages after them call this so that the MDP and its solver do not share the memory with
    /// them. [`Self::predecessors`] still works afterwards, at the cost of building them again.
    pub fn release_predecessors(&mut self) {
        self.predecessors.take();
    }

    /// Whether the owner of `h` has no enabled action.
    pub fn is_stuck(&self, h: HState) -> bool {
        self.edges(h).len() == 0
    }

    /// The name `ARENA_STATE|Q1|Q2` of `h`.
    pub fn name(&self, h: HState) -> String {
        let mut name = self.arena.name(self.arena_state(h)).to_string();
        for i in 0..self.components.len() {
            name.push_str(&format!("|{}", self.automaton_state(h, i)));
        }
        name
    }

    /// The product state named `text` (see [`Self::name`]).
    pub fn parse_state(&self, text: &str) -> Result<HState, StateNameError> {
        let (arena, slots) = parse_state_name(text, &self.components, &self.names, |name| {
            self.arena.find_state(name).map(StateId::as_u32)
        })?;
        let local: u32 = slots.iter().zip(&self.strides).map(|(i, s)| i * s).sum();
        self.numbering
            .find(arena * self.arena_stride + local)
            .ok_or_else(|| StateNameError::unreachable(text))
    }
}

/// The arena state and the automata's slots (one per automaton of `components`, named `names`
/// in errors) of the product state named `text`, `ARENA_STATE|Q1|Q2…`, the arena state found
/// by its name with `arena_state`: how both engines read a state's name (the arena state's name
/// may itself contain `|`: the automata's states are the last fields).
pub(crate) fn parse_state_name(
    text: &str,
    components: &[Component],
    names: &[String],
    arena_state: impl FnOnce(&str) -> Option<u32>,
) -> Result<(u32, Vec<u32>), StateNameError> {
    let at = |offset: usize| Position::of_offset(text, offset);
    let m = components.len();
    let mut parts: Vec<&str> = text.rsplitn(m + 1, '|').collect();
    if parts.len() != m + 1 {
        let pattern: String = std::iter::once("ARENA_STATE".to_string())
            .chain((1..=m).map(|i| format!("|Q{i}")))
            .collect();
        return Err(StateNameError::Malformed(at(text.len()), pattern));
    }
    parts.reverse();
    let arena_name = parts[0];
    let arena = arena_state(arena_name)
        .ok_or_else(|| StateNameError::UnknownArenaState(at(0), arena_name.to_string()))?;
    let mut offset = arena_name.len() + 1;
    let mut slots = Vec::with_capacity(m);
    for ((component, name), text) in components.iter().zip(names).zip(&parts[1..]) {
        let state = text
            .parse::<DfaState>()
            .ok()
            .filter(|&q| (q as usize) < component.slot_of.len())
            .ok_or_else(|| StateNameError::NoSuchDfaState {
                position: at(offset),
                automaton: name.clone(),
                text: text.to_string(),
            })?;
        let slot = component.slot_of[state as usize];
        if slot.is_none() {
            return Err(StateNameError::NotEnumerated {
                position: at(offset),
                automaton: name.clone(),
                state,
            });
        }
        slots.push(slot);
        offset += text.len() + 1;
    }
    Ok((arena, slots))
}

impl Numbering {
    /// The id of the state in `slot`, numbering it next if it is new (while enumerating).
    fn id(&mut self, slot: u32) -> HState {
        match self {
            Numbering::Full => HState::from_u32(slot),
            Numbering::Reachable { slots, ids, .. } => *ids.entry(slot).or_insert_with(|| {
                slots.push(slot);
                HState::new(slots.len() - 1)
            }),
        }
    }

    /// Ends the enumeration: the hash map of the ids gives way to the ids sorted by slot.
    fn finish(&mut self) {
        if let Numbering::Reachable {
            slots,
            ids,
            by_slot,
        } = self
        {
            *ids = HashMap::default();
            slots.shrink_to_fit();
            *by_slot = HState::range(slots.len()).collect();
            by_slot.sort_unstable_by_key(|h| slots[h.index()]);
        }
    }

    /// The id of the state in `slot`, if it is enumerated (after [`Self::finish`]).
    fn find(&self, slot: u32) -> Option<HState> {
        match self {
            Numbering::Full => Some(HState::from_u32(slot)),
            Numbering::Reachable { slots, by_slot, .. } => by_slot
                .binary_search_by_key(&slot, |h| slots[h.index()])
                .ok()
                .map(|i| by_slot[i]),
        }
    }

    fn slot(&self, id: HState) -> u32 {
        match self {
            Numbering::Full => id.as_u32(),
            Numbering::Reachable { slots, .. } => slots[id.index()],
        }
    }

    /// How many states are numbered so far (all `full` of them for the full enumeration).
    fn discovered(&self, full: u32) -> u32 {
        match self {
            Numbering::Full => full,
            Numbering::Reachable { slots, .. } => slots.len() as u32,
        }
    }
}

/// The largest number of edges of an arena state (at least 1).
fn arena_degree(arena: &Arena) -> u64 {
    (arena.states())
        .map(|s| arena.edges(s).len() as u64)
        .max()
        .unwrap_or(0)
        .max(1)
}

/// The propositions of the automata that no arena state carries: `labels` are the arena's
/// distinct labels, sets of indices into `propositions` (both engines' arenas give them so).
pub(crate) fn missing_propositions(
    propositions: &[String],
    labels: &[BitSet],
    dfas: &[&Dfa],
) -> Vec<String> {
    let carried: BitSet = labels.iter().flat_map(|label| label.iter()).collect();
    let mut missing: Vec<String> = Vec::new();
    for ap in dfas.iter().flat_map(|dfa| dfa.aps()) {
        let is_carried = propositions
            .iter()
            .position(|p| p == ap)
            .is_some_and(|p| carried.contains(p));
        if !is_carried && !missing.contains(ap) {
            missing.push(ap.clone());
        }
    }
    missing
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::arena::gridworld::{Cell, Gridworld};
    use crate::automata::testing::avoid_until;

    fn arena() -> Arena {
        let cell = |x, y| Cell { x, y };
        let mut grid = Gridworld::new(4, 3, cell(0, 1), cell(3, 1));
        grid.obstacles = vec![cell(2, 0)];
        grid.labels = vec![("A".into(), cell(1, 0)), ("B".into(), cell(3, 2))];
        grid.build().unwrap()
    }

    /// Per slot, its state's edges as (action, target slot); then every edge id with its
    /// target slot.
    type Edges = (Vec<Vec<(ActionId, u32)>>, Vec<(usize, u32)>);

    /// The [`Edges`] of `game`.
    fn edges_by_slot(game: &Hypergame) -> Edges {
        let slot = |h: HState| game.numbering.slot(h);
        let mut by_slot = vec![Vec::new(); game.arena.num_states() * game.arena_stride as usize];
        let mut ids = Vec::new();
        for h in game.states() {
            by_slot[slot(h) as usize] = game.edges(h).map(|(a, t)| (a, slot(t))).collect();
            assert_eq!(game.edge_range(h).len(), game.edges(h).len());
            assert_eq!(game.is_stuck(h), game.edges(h).len() == 0);
            ids.extend(game.edge_range(h).zip(game.successors(h).map(slot)));
        }
        (by_slot, ids)
    }

    #[test]
    fn only_propositions_the_arena_does_not_declare_are_unknown() {
        // The gridworld declares O (its obstacles) though nobody stands on one; `Ob` is a typo.
        let arena = arena();
        assert!(arena.find_proposition("O").is_some());
        let (d1, d2) = (avoid_until("O", "A"), avoid_until("O", "Ob"));
        let game = Hypergame::new(&arena, &d1, &d2, States::Full).unwrap();
        assert_eq!(game.missing_propositions(), ["O", "Ob"]);
        assert_eq!(game.unknown_propositions().collect::<Vec<_>>(), ["Ob"]);
        let (d1, d2) = (avoid_until("O", "A"), avoid_until("O", "B"));
        let game = Hypergame::new(&arena, &d1, &d2, States::Full).unwrap();
        assert_eq!(game.missing_propositions(), ["O"]);
        assert_eq!(game.unknown_propositions().count(), 0);
    }

    #[test]
    fn implicit_successors_agree_with_stored_ones_with_or_without_the_step_table() {
        let arena = arena();
        let (d1, d2) = (avoid_until("O", "A"), avoid_until("O", "B"));
        let full = Hypergame::new(&arena, &d1, &d2, States::Full).unwrap();
        let reachable = Hypergame::new(&arena, &d1, &d2, States::Reachable).unwrap();
        assert!(matches!(full.successors, Successors::Implicit { .. }));
        assert!(matches!(reachable.successors, Successors::Explicit(_)));
        assert!(!full.local_step.is_empty());
        let (full_edges, full_ids) = edges_by_slot(&full);
        // Edge ids: 0..num_edges, each once, in state order.
        let ids: Vec<usize> = full_ids.iter().map(|&(id, _)| id).collect();
        assert_eq!(ids, (0..full.num_edges()).collect::<Vec<_>>());
        // Each reachable state has the edges of the same slot in the full product.
        let (reachable_edges, _) = edges_by_slot(&reachable);
        for (slot, edges) in reachable_edges.iter().enumerate() {
            if !edges.is_empty() {
                assert_eq!(edges, &full_edges[slot], "slot {slot}");
            }
        }
        // Without the table, each automaton steps on its own: the same edges.
        let mut composed = full.clone();
        composed.local_step.clear();
        assert_eq!(edges_by_slot(&composed), (full_edges, full_ids));
        // The predecessor lists are the transpose, released and built again on demand.
        let mut game = full.clone();
        let before: Vec<Vec<HState>> = game
            .states()
            .map(|h| game.predecessors(h).to_vec())
            .collect();
        game.release_predecessors();
        assert!(game.predecessors.get().is_none());
        let after: Vec<Vec<HState>> = game
            .states()
            .map(|h| game.predecessors(h).to_vec())
            .collect();
        assert_eq!(before, after);
        let mut count = vec![0usize; game.num_states()];
        for h in game.states() {
            for t in game.successors(h) {
                count[t.index()] += 1;
                assert!(game.predecessors(t).contains(&h));
            }
        }
        assert!(
            game.states()
                .all(|h| game.predecessors(h).len() == count[h.index()])
        );
        // Reachable lookups: by name and by tuple, through the ids sorted by slot.
        for h in reachable.states() {
            assert_eq!(reachable.parse_state(&reachable.name(h)), Ok(h));
            assert_eq!(reachable.find(reachable.state(h)), Some(h));
        }
    }
}

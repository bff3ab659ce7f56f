//! The hypergame product `H = S × Q1 × Q2` of an arena with the DFAs of `phi1` and `phi2`, as an
//! explicit graph.
//!
//! Semantics (DESIGN.md 3.4): `Δ((s,q1,q2), a) = (s', δ1(q1, L(s')), δ2(q2, L(s')))` with
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
//! Representation: successors in CSR form (`offsets`, `targets`, `actions`: one product edge per
//! arena edge, in the arena's edge order), predecessors in CSR form built once, one entry per
//! edge (an adversary state with two actions into one state is listed twice, which the
//! attractor's counters rely on). DFA steps are tabulated once per (enumerated DFA state,
//! distinct arena label), so building the product costs no guard evaluation per edge. Arena
//! propositions meet the automaton's by name; propositions an automaton mentions that no arena
//! state carries are always false and are reported by [`Hypergame::missing_propositions`].
//!
//! Indices are `u32`: the full space `|S| · |Q1| · |Q2|` (for either enumeration, which indexes
//! it densely while building) and the number of edges must stay below `2^32 - 1`.
//!
//! Names: a product state is named `ARENA_STATE|Q1|Q2`, e.g. `((0,2),(4,2),0)|0|1`, with the
//! DFA states as their numbers in the automata. [`Hypergame::parse_state`] splits at the last two
//! `|`, so arena state names may themselves contain `|`.

use std::ops::Range;

use bit_set::BitSet;

use super::Task;
use crate::arena::{ActionId, Arena, LabelId, Owner, StateId};
use crate::automata::{Dfa, DfaState};
use crate::position::Position;

/// A product state, indexing `0..Hypergame::num_states()`.
pub type HState = u32;

/// Marks "no such slot / state" in dense index tables.
const NONE: u32 = u32::MAX;

/// Which product states are enumerated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum States {
    /// Every arena state × every pair of DFA states reachable by arena labels.
    #[default]
    Full,
    /// Only the states reachable from the initial state.
    Reachable,
}

/// The three components of a product state.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ProductState {
    pub arena: StateId,
    pub q1: DfaState,
    pub q2: DfaState,
}

/// Why a product cannot be built.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum HypergameError {
    #[error(
        "the product is too large: {0} states or edges, more than the 4294967294 that 32-bit \
         indices allow"
    )]
    TooLarge(u64),
}

/// Why a product state name does not denote a state of this product. Positions are 1-based
/// columns in the name (line 1).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum StateNameError {
    #[error("{0}: expected a product state `ARENA_STATE|Q1|Q2`")]
    Malformed(Position),
    #[error("{0}: no arena state is called `{1}`")]
    UnknownArenaState(Position, String),
    #[error("{position}: `{text}` is not a state of the automaton of {task}")]
    NoSuchDfaState {
        position: Position,
        task: Task,
        text: String,
    },
    #[error(
        "{position}: state {state} of the automaton of {task} is not enumerated: no sequence of \
         arena labels leads to it"
    )]
    NotEnumerated {
        position: Position,
        task: Task,
        state: DfaState,
    },
    #[error("{0}: `{1}` is not reachable from the initial state (`--states reachable`)")]
    Unreachable(Position, String),
}

/// One automaton restricted to its enumerated states ("slots"), with its steps tabulated per
/// distinct arena label.
#[derive(Clone, Debug)]
struct Component {
    /// The enumerated DFA states, in breadth-first discovery order from the initial state.
    states: Vec<DfaState>,
    /// The slot of each DFA state, `NONE` if not enumerated.
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
        let letters: Vec<u64> = arena
            .labels()
            .iter()
            .map(|label| dfa.letter(label.iter().map(|p| arena.propositions()[p].as_str())))
            .collect();
        let num_labels = letters.len();
        let mut slot_of = vec![NONE; dfa.num_states()];
        let mut states = vec![dfa.initial()];
        slot_of[dfa.initial() as usize] = 0;
        let mut step = Vec::with_capacity(num_labels);
        let mut next = 0;
        while next < states.len() {
            let q = states[next];
            for &letter in &letters {
                let target = dfa.step(q, letter);
                if slot_of[target as usize] == NONE {
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
        let initial = step[arena.label_id(arena.initial()) as usize];
        Component {
            states,
            slot_of,
            step,
            num_labels,
            finals,
            initial,
        }
    }

    fn len(&self) -> u64 {
        self.states.len() as u64
    }

    fn step(&self, slot: u32, label: LabelId) -> u32 {
        self.step[slot as usize * self.num_labels + label as usize]
    }
}

/// How product state ids relate to slots `(s · |Q1| + i1) · |Q2| + i2` of the full space.
#[derive(Clone, Debug)]
enum Numbering {
    /// Ids are slots.
    Full,
    /// `slots[id]` is the slot of state `id`; `ids[slot]` its id or `NONE`.
    Reachable { slots: Vec<u32>, ids: Vec<u32> },
}

/// The explicit hypergame graph over an arena (borrowed, for names and owners).
#[derive(Clone, Debug)]
pub struct Hypergame<'a> {
    arena: &'a Arena,
    enumeration: States,
    components: [Component; 2],
    numbering: Numbering,
    num_states: u32,
    offsets: Vec<u32>,
    targets: Vec<HState>,
    actions: Vec<ActionId>,
    pred_offsets: Vec<u32>,
    pred_sources: Vec<HState>,
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
        let components = [Component::new(dfa1, arena), Component::new(dfa2, arena)];
        let full = arena.num_states() as u64 * components[0].len() * components[1].len();
        if full >= NONE as u64 {
            return Err(HypergameError::TooLarge(full));
        }
        let mut numbering = match enumeration {
            States::Full => Numbering::Full,
            States::Reachable => Numbering::Reachable {
                slots: Vec::new(),
                ids: vec![NONE; full as usize],
            },
        };
        let mut game = Hypergame {
            arena,
            enumeration,
            components,
            numbering: Numbering::Full,
            num_states: 0,
            offsets: vec![0],
            targets: Vec::new(),
            actions: Vec::new(),
            pred_offsets: Vec::new(),
            pred_sources: Vec::new(),
            initial: 0,
            missing_propositions: missing_propositions(arena, [dfa1, dfa2]),
        };
        if enumeration == States::Full {
            // Every arena transition appears once per pair of DFA states.
            let edges = arena.num_transitions() as u64 * (full / arena.num_states() as u64);
            if edges >= NONE as u64 {
                return Err(HypergameError::TooLarge(edges));
            }
            game.offsets.reserve_exact(full as usize);
            game.targets.reserve_exact(edges as usize);
            game.actions.reserve_exact(edges as usize);
        }
        let initial_slot = game.slot(
            arena.initial(),
            game.components[0].initial,
            game.components[1].initial,
        );
        game.initial = numbering.id(initial_slot);
        let mut state = 0u32;
        while state < numbering.discovered(full as u32) {
            let (s, i1, i2) = game.decode(numbering.slot(state));
            for (action, successor) in arena.edges(s) {
                let label = arena.label_id(successor);
                let slot = game.slot(
                    successor,
                    game.components[0].step(i1, label),
                    game.components[1].step(i2, label),
                );
                game.targets.push(numbering.id(slot));
                game.actions.push(action);
            }
            if game.targets.len() >= NONE as usize {
                return Err(HypergameError::TooLarge(game.targets.len() as u64));
            }
            game.offsets.push(game.targets.len() as u32);
            state += 1;
        }
        game.num_states = state;
        game.numbering = numbering;
        game.build_predecessors();
        Ok(game)
    }

    /// Counting sort of the edges by target: one predecessor entry per edge.
    fn build_predecessors(&mut self) {
        let n = self.num_states as usize;
        let mut offsets = vec![0u32; n + 1];
        for &target in &self.targets {
            offsets[target as usize + 1] += 1;
        }
        for i in 0..n {
            offsets[i + 1] += offsets[i];
        }
        let mut cursor = offsets.clone();
        let mut sources = vec![0; self.targets.len()];
        for source in 0..self.num_states {
            for &target in self.successors(source) {
                let slot = &mut cursor[target as usize];
                sources[*slot as usize] = source;
                *slot += 1;
            }
        }
        self.pred_offsets = offsets;
        self.pred_sources = sources;
    }

    fn slot(&self, s: StateId, i1: u32, i2: u32) -> u32 {
        (s * self.components[0].len() as u32 + i1) * self.components[1].len() as u32 + i2
    }

    fn decode(&self, slot: u32) -> (StateId, u32, u32) {
        let n1 = self.components[0].len() as u32;
        let n2 = self.components[1].len() as u32;
        (slot / n2 / n1, slot / n2 % n1, slot % n2)
    }

    pub fn arena(&self) -> &'a Arena {
        self.arena
    }

    pub fn enumeration(&self) -> States {
        self.enumeration
    }

    pub fn num_states(&self) -> usize {
        self.num_states as usize
    }

    pub fn num_edges(&self) -> usize {
        self.targets.len()
    }

    /// `h0`.
    pub fn initial(&self) -> HState {
        self.initial
    }

    /// The enumerated states of the automaton of `phi1` (`Q1` of the product), in breadth-first
    /// discovery order from its initial state.
    pub fn q1_states(&self) -> &[DfaState] {
        &self.components[0].states
    }

    /// The enumerated states of the automaton of `phi2` (`Q2` of the product).
    pub fn q2_states(&self) -> &[DfaState] {
        &self.components[1].states
    }

    /// Propositions some automaton mentions but no arena state carries (always false), in the
    /// order of the automata's propositions, `phi1`'s first, without repetition.
    pub fn missing_propositions(&self) -> &[String] {
        &self.missing_propositions
    }

    /// The arena state and DFA states of `h`.
    pub fn state(&self, h: HState) -> ProductState {
        let (arena, i1, i2) = self.decode(self.numbering.slot(h));
        ProductState {
            arena,
            q1: self.components[0].states[i1 as usize],
            q2: self.components[1].states[i2 as usize],
        }
    }

    /// The product state with these components, if it is enumerated.
    pub fn find(&self, state: ProductState) -> Option<HState> {
        let i1 = *self.components[0].slot_of.get(state.q1 as usize)?;
        let i2 = *self.components[1].slot_of.get(state.q2 as usize)?;
        if (state.arena as usize) >= self.arena.num_states() || i1 == NONE || i2 == NONE {
            return None;
        }
        let slot = self.slot(state.arena, i1, i2);
        match &self.numbering {
            Numbering::Full => Some(slot),
            Numbering::Reachable { ids, .. } => Some(ids[slot as usize]).filter(|&id| id != NONE),
        }
    }

    pub fn owner(&self, h: HState) -> Owner {
        self.arena.owner(self.state(h).arena)
    }

    /// Whether `h` belongs to `phi1`'s final states (for [`Task::Phi1`]), `phi2`'s, or both's
    /// (for [`Task::Phi`]): the sets `F1`, `F2`, `F12` of DESIGN.md 3.4.
    pub fn is_target(&self, task: Task, h: HState) -> bool {
        let (_, i1, i2) = self.decode(self.numbering.slot(h));
        let final1 = self.components[0].finals.contains(i1 as usize);
        let final2 = self.components[1].finals.contains(i2 as usize);
        match task {
            Task::Phi1 => final1,
            Task::Phi2 => final2,
            Task::Phi => final1 && final2,
        }
    }

    /// The target set of `task` as a region.
    pub fn targets(&self, task: Task) -> BitSet {
        (0..self.num_states)
            .filter(|&h| self.is_target(task, h))
            .map(|h| h as usize)
            .collect()
    }

    /// The edge ids of `h`, indexing [`Self::edge_target`] and [`Self::edge_action`].
    pub fn edge_range(&self, h: HState) -> Range<usize> {
        self.offsets[h as usize] as usize..self.offsets[h as usize + 1] as usize
    }

    pub fn edge_target(&self, edge: usize) -> HState {
        self.targets[edge]
    }

    pub fn edge_action(&self, edge: usize) -> ActionId {
        self.actions[edge]
    }

    /// The successors of `h`, one per enabled action, in the arena's edge order.
    pub fn successors(&self, h: HState) -> &[HState] {
        &self.targets[self.edge_range(h)]
    }

    /// The enabled actions of `h` with their successors.
    pub fn edges(&self, h: HState) -> impl ExactSizeIterator<Item = (ActionId, HState)> + '_ {
        let range = self.edge_range(h);
        self.actions[range.clone()]
            .iter()
            .copied()
            .zip(self.targets[range].iter().copied())
    }

    /// The sources of the edges into `h`, one entry per edge.
    pub fn predecessors(&self, h: HState) -> &[HState] {
        &self.pred_sources
            [self.pred_offsets[h as usize] as usize..self.pred_offsets[h as usize + 1] as usize]
    }

    /// Whether the owner of `h` has no enabled action.
    pub fn is_stuck(&self, h: HState) -> bool {
        self.offsets[h as usize] == self.offsets[h as usize + 1]
    }

    /// The name `ARENA_STATE|Q1|Q2` of `h`.
    pub fn name(&self, h: HState) -> String {
        let state = self.state(h);
        format!("{}|{}|{}", self.arena.name(state.arena), state.q1, state.q2)
    }

    /// The product state named `text` (see [`Self::name`]).
    pub fn parse_state(&self, text: &str) -> Result<HState, StateNameError> {
        let at = |offset: usize| Position::of_offset(text, offset);
        let mut parts = text.rsplitn(3, '|');
        let (Some(q2_text), Some(q1_text), Some(arena_name)) =
            (parts.next(), parts.next(), parts.next())
        else {
            return Err(StateNameError::Malformed(at(text.len())));
        };
        let q1_offset = arena_name.len() + 1;
        let q2_offset = q1_offset + q1_text.len() + 1;
        let arena = self
            .arena
            .find_state(arena_name)
            .ok_or_else(|| StateNameError::UnknownArenaState(at(0), arena_name.to_string()))?;
        let dfa_state = |task: Task, component: &Component, text: &str, offset: usize| {
            let state = text
                .parse::<DfaState>()
                .ok()
                .filter(|&q| (q as usize) < component.slot_of.len())
                .ok_or_else(|| StateNameError::NoSuchDfaState {
                    position: at(offset),
                    task,
                    text: text.to_string(),
                })?;
            if component.slot_of[state as usize] == NONE {
                return Err(StateNameError::NotEnumerated {
                    position: at(offset),
                    task,
                    state,
                });
            }
            Ok(state)
        };
        let q1 = dfa_state(Task::Phi1, &self.components[0], q1_text, q1_offset)?;
        let q2 = dfa_state(Task::Phi2, &self.components[1], q2_text, q2_offset)?;
        self.find(ProductState { arena, q1, q2 })
            .ok_or_else(|| StateNameError::Unreachable(at(0), text.to_string()))
    }
}

impl Numbering {
    /// The id of the state in `slot`, numbering it next if it is new.
    fn id(&mut self, slot: u32) -> HState {
        match self {
            Numbering::Full => slot,
            Numbering::Reachable { slots, ids } => {
                if ids[slot as usize] == NONE {
                    ids[slot as usize] = slots.len() as u32;
                    slots.push(slot);
                }
                ids[slot as usize]
            }
        }
    }

    fn slot(&self, id: HState) -> u32 {
        match self {
            Numbering::Full => id,
            Numbering::Reachable { slots, .. } => slots[id as usize],
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

/// The propositions of the automata that no arena state carries.
fn missing_propositions(arena: &Arena, dfas: [&Dfa; 2]) -> Vec<String> {
    let carried: BitSet = arena
        .labels()
        .iter()
        .flat_map(|label| label.iter())
        .collect();
    let mut missing: Vec<String> = Vec::new();
    for ap in dfas.iter().flat_map(|dfa| dfa.aps()) {
        let is_carried = arena
            .find_proposition(ap)
            .is_some_and(|p| carried.contains(p as usize));
        if !is_carried && !missing.contains(ap) {
            missing.push(ap.clone());
        }
    }
    missing
}

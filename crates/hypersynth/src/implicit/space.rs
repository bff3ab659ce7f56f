//! The product as an index space: states are numbers, edges are computed.
//!
//! A product state is the mixed-radix index `s · L + local` of an arena state `s` and a tuple of
//! automaton states (`local`, with the first automaton most significant), numbered exactly as
//! the explicit product's full enumeration numbers them ([`Hypergame`](crate::game::Hypergame),
//! docs/semantics.md §4.2): the same automaton states are enumerated, in the same order, so an
//! index names the same product state in both engines. Successors come from the arena's rules
//! and a table of the automata's steps per (local part, label); predecessors from the arena's
//! predecessors and the inverse of that table. Nothing is stored per product state.
//!
//! With [`States::Reachable`] ([`Space::reachable`]) only the states reachable from `h0` are
//! enumerated: the indices stay the full space's, a bit per index says which are enumerated, and
//! the product order (the explicit engine's numbering, breadth-first from `h0`) is found again
//! by a breadth-first search whenever it is needed ([`Space::for_each_state`]).
//!
//! Memory: the step table and its inverse, `8 · L · labels` bytes, and the arena's rules; with
//! the reachable enumeration, a bit per index, and while a breadth-first search runs a second
//! one and its queue (the states found and not yet expanded).

use std::collections::VecDeque;

use bit_set::BitSet;

use super::moves::Moves;
use crate::arena::{ActionId, LabelId, Owner};
use crate::automata::{Dfa, DfaState};
use crate::game::Component;
use crate::game::{HypergameError, StateNameError, States, TaskSet};
use crate::game::{missing_propositions, parse_state_name};

/// The product of an arena given by rules with a list of automata.
#[derive(Debug)]
pub struct Space<'m, M> {
    moves: &'m M,
    components: Vec<Component>,
    /// `strides[i]`: the weight of automaton `i`'s slot in the local part.
    strides: Vec<u32>,
    /// The number of local parts, `L`.
    locals: u32,
    num_labels: usize,
    /// `step[local * num_labels + label]`: the local part after entering a state so labelled.
    step: Vec<u32>,
    /// Per `(label, local')`, the local parts that step to `local'` on `label`: offsets into
    /// `inverse`, `num_labels · L + 1` of them.
    inverse_offsets: Vec<u32>,
    inverse: Vec<u32>,
    num_states: u64,
    initial: u64,
    missing_propositions: Vec<String>,
    /// The enumerated states when only those reachable from `h0` are, and their number.
    reachable: Option<(BitSet, usize)>,
}

impl<'m, M: Moves> Space<'m, M> {
    /// The product of `moves` with `automata`, in order.
    ///
    /// # Errors
    /// [`HypergameError::TooLarge`] when the product has `2^32 - 1` states or more (the
    /// explicit engine's limit: indices are 32-bit in both).
    pub fn new(moves: &'m M, automata: &[&Dfa]) -> Result<Space<'m, M>, HypergameError> {
        let initial_label = moves.label(moves.initial());
        let components: Vec<Component> = automata
            .iter()
            .map(|dfa| {
                Component::over_labels(dfa, moves.labels(), moves.propositions(), initial_label)
            })
            .collect();
        let locals = components
            .iter()
            .fold(1u64, |size, c| size.saturating_mul(c.len()));
        let num_states = (moves.num_states() as u64).saturating_mul(locals);
        if num_states >= u64::from(u32::MAX) {
            return Err(HypergameError::TooLarge(num_states));
        }
        let locals = locals as u32;
        let mut strides = vec![1u32; components.len()];
        for i in (0..components.len().saturating_sub(1)).rev() {
            strides[i] = strides[i + 1] * components[i + 1].len() as u32;
        }
        let num_labels = moves.labels().len();
        let mut step = Vec::with_capacity(locals as usize * num_labels);
        for local in 0..locals {
            for label in 0..num_labels as LabelId {
                step.push(
                    components
                        .iter()
                        .zip(&strides)
                        .map(|(c, &stride)| c.step(local / stride % c.len() as u32, label) * stride)
                        .sum::<u32>(),
                );
            }
        }
        let rows = num_labels * locals as usize;
        let mut inverse_offsets = vec![0u32; rows + 1];
        for local in 0..locals as usize {
            for label in 0..num_labels {
                let target = step[local * num_labels + label] as usize;
                inverse_offsets[label * locals as usize + target + 1] += 1;
            }
        }
        for i in 0..rows {
            inverse_offsets[i + 1] += inverse_offsets[i];
        }
        let mut inverse = vec![0u32; step.len()];
        let mut next = inverse_offsets[..rows].to_vec();
        for local in 0..locals as usize {
            for label in 0..num_labels {
                let row = label * locals as usize + step[local * num_labels + label] as usize;
                inverse[next[row] as usize] = local as u32;
                next[row] += 1;
            }
        }
        let initial_local: u32 = components
            .iter()
            .zip(&strides)
            .map(|(c, &stride)| c.initial() * stride)
            .sum();
        let initial = u64::from(moves.initial()) * u64::from(locals) + u64::from(initial_local);
        Ok(Space {
            moves,
            components,
            strides,
            locals,
            num_labels,
            step,
            inverse_offsets,
            inverse,
            num_states,
            initial,
            missing_propositions: missing_propositions(
                moves.propositions(),
                moves.labels(),
                automata,
            ),
            reachable: None,
        })
    }

    /// The same product, enumerating only the states reachable from `h0` (found by a
    /// breadth-first search).
    pub fn reachable(self) -> Space<'m, M> {
        let mut count = 0;
        let reachable = self.breadth_first(|_| count += 1);
        Space {
            reachable: Some((reachable, count)),
            ..self
        }
    }

    /// The bytes [`Space::reachable`] keeps for a product of `states` indices: a bit each.
    pub fn reachable_bytes(states: u64) -> u64 {
        states.div_ceil(8)
    }

    /// Calls `f` with each state reachable from `h0` in breadth-first order, its successors in
    /// edge order (the explicit engine's numbering of the reachable states), and returns them.
    fn breadth_first(&self, mut f: impl FnMut(u32)) -> BitSet {
        let mut found = BitSet::with_capacity(self.num_states());
        let mut queue = VecDeque::from([self.initial()]);
        found.insert(self.initial() as usize);
        while let Some(h) = queue.pop_front() {
            f(h);
            self.edges(h, |_, t| {
                if found.insert(t as usize) {
                    queue.push_back(t);
                }
            });
        }
        found
    }

    /// Which states are enumerated.
    pub fn enumeration(&self) -> States {
        match self.reachable {
            None => States::Full,
            Some(_) => States::Reachable,
        }
    }

    /// Whether `h` is enumerated (every index is with the full enumeration).
    #[inline]
    pub fn enumerated(&self, h: u32) -> bool {
        self.reachable
            .as_ref()
            .is_none_or(|(reachable, _)| reachable.contains(h as usize))
    }

    /// The number of enumerated states.
    pub fn num_enumerated(&self) -> usize {
        self.reachable
            .as_ref()
            .map_or(self.num_states(), |&(_, count)| count)
    }

    /// The enumerated states, in increasing order of index.
    pub fn states(&self) -> impl Iterator<Item = u32> + '_ {
        (0..self.num_states() as u32).filter(|&h| self.enumerated(h))
    }

    /// Calls `f` with each enumerated state in product order: the indices in increasing order,
    /// or the reachable states in the explicit engine's order (breadth-first from `h0`).
    pub fn for_each_state(&self, mut f: impl FnMut(u32)) {
        match self.reachable {
            None => (0..self.num_states() as u32).for_each(f),
            Some(_) => {
                self.breadth_first(&mut f);
            }
        }
    }

    /// The arena's rules.
    pub fn moves(&self) -> &'m M {
        self.moves
    }

    /// The number of indices, enumerated or not.
    pub fn num_states(&self) -> usize {
        self.num_states as usize
    }

    /// The initial product state `h0`.
    pub fn initial(&self) -> u32 {
        self.initial as u32
    }

    /// The number of automata.
    pub fn num_automata(&self) -> usize {
        self.components.len()
    }

    /// The number of states of automaton `i` the product enumerates (those reachable through
    /// the arena's labels).
    pub fn automaton_states(&self, i: usize) -> usize {
        self.components[i].len() as usize
    }

    /// The states of automaton `i` the product's tuples combine, in order (as the explicit
    /// product's tuples combine them).
    pub fn tuple_states_of(&self, i: usize) -> &[DfaState] {
        self.components[i].states()
    }

    /// The product state of arena state `s` with the automata in `automata` (one per
    /// automaton), if `s` is a state, each automaton's state is one the tuples combine and the
    /// product state is enumerated: the explicit product's
    /// [`find_tuple`](crate::game::Hypergame::find_tuple).
    pub fn find_tuple(&self, s: u32, automata: &[DfaState]) -> Option<u32> {
        if s as usize >= self.moves.num_states() || automata.len() != self.components.len() {
            return None;
        }
        let mut local = 0;
        for ((component, &q), &stride) in self.components.iter().zip(automata).zip(&self.strides) {
            local += component.slot_of(q)? * stride;
        }
        Some(s * self.locals + local).filter(|&h| self.enumerated(h))
    }

    /// The number of edges of the enumerated states: each has its arena state's.
    pub fn num_edges(&self) -> usize {
        match &self.reachable {
            None => {
                (0..self.moves.num_states() as u32)
                    .map(|s| self.moves.degree(s) as usize)
                    .sum::<usize>()
                    * self.locals as usize
            }
            Some((reachable, _)) => reachable
                .iter()
                .map(|h| self.degree(h as u32) as usize)
                .sum(),
        }
    }

    /// Propositions some automaton mentions but no arena state carries (always false), as
    /// [`Hypergame::missing_propositions`](crate::game::Hypergame::missing_propositions) lists
    /// them.
    pub fn missing_propositions(&self) -> &[String] {
        &self.missing_propositions
    }

    /// The arena state of `h`.
    #[inline]
    pub fn arena_state(&self, h: u32) -> u32 {
        h / self.locals
    }

    /// The number of automata tuples: every combination of the automata's enumerated states,
    /// `h`'s being [`Space::tuple`]`(h)`.
    pub fn num_tuples(&self) -> u32 {
        self.locals
    }

    /// The automata tuple of `h` (the explicit product's automata slot).
    #[inline]
    pub fn tuple(&self, h: u32) -> u32 {
        h % self.locals
    }

    /// The automata's states in tuple `tuple`, one per automaton.
    pub fn tuple_states(&self, tuple: u32) -> Vec<DfaState> {
        (0..self.components.len())
            .map(|i| self.automaton_state(tuple, i))
            .collect()
    }

    /// Automaton `i`'s state in `h`.
    pub fn automaton_state(&self, h: u32, i: usize) -> DfaState {
        let c = &self.components[i];
        c.states()[self.slot(h, i) as usize]
    }

    #[inline]
    fn slot(&self, h: u32, i: usize) -> u32 {
        h % self.locals / self.strides[i] % self.components[i].len() as u32
    }

    /// Who moves in `h`.
    #[inline]
    pub fn owner(&self, h: u32) -> Owner {
        self.moves.owner(self.arena_state(h))
    }

    /// Whether automaton `i` is in a final state in `h`.
    #[inline]
    pub fn is_final(&self, i: usize, h: u32) -> bool {
        self.components[i].is_final(self.slot(h, i))
    }

    /// Whether `h` satisfies every sub-task of `set` (automata `0..k` are the sub-tasks').
    #[inline]
    pub fn is_target(&self, set: TaskSet, h: u32) -> bool {
        set.iter().all(|i| self.is_final(i, h))
    }

    /// The number of edges of `h` (its arena state's).
    #[inline]
    pub fn degree(&self, h: u32) -> u32 {
        self.moves.degree(self.arena_state(h))
    }

    /// Calls `f(action, successor)` for each edge of `h`, in edge order.
    #[inline]
    pub fn edges(&self, h: u32, mut f: impl FnMut(ActionId, u32)) {
        let s = self.arena_state(h);
        let local = (h - s * self.locals) as usize * self.num_labels;
        self.moves.edges(s, |action, t, label| {
            f(action, t * self.locals + self.step[local + label as usize]);
        });
    }

    /// Calls `f(source)` once for each edge into `h`.
    #[inline]
    pub fn predecessors(&self, h: u32, mut f: impl FnMut(u32)) {
        let t = self.arena_state(h);
        let row = self.moves.label(t) as usize * self.locals as usize + (h % self.locals) as usize;
        let sources = &self.inverse
            [self.inverse_offsets[row] as usize..self.inverse_offsets[row + 1] as usize];
        if sources.is_empty() {
            return;
        }
        self.moves.predecessors(t, |s| {
            for &local in sources {
                f(s * self.locals + local);
            }
        });
    }

    /// The name of `h`: `ARENA_STATE|q_1|…`, as the explicit product names it.
    pub fn name(&self, h: u32) -> String {
        let mut name = self.moves.name(self.arena_state(h));
        for i in 0..self.components.len() {
            name.push('|');
            name.push_str(&self.automaton_state(h, i).to_string());
        }
        name
    }

    /// The product state named `text` ([`Space::name`]), its automata named `names` in errors
    /// (as the explicit product reads it, [`Hypergame::parse_state`](crate::game::Hypergame::parse_state);
    /// every well-formed name is a state of the full enumeration, the reachable ones of the
    /// reachable enumeration).
    pub fn parse_state(&self, text: &str, names: &[String]) -> Result<u32, StateNameError> {
        let (arena, slots) = parse_state_name(text, &self.components, names, |name| {
            self.moves.state_of(name)
        })?;
        let local: u32 = slots.iter().zip(&self.strides).map(|(i, s)| i * s).sum();
        let h = arena * self.locals + local;
        match self.enumerated(h) {
            true => Ok(h),
            false => Err(StateNameError::unreachable(text)),
        }
    }
}

//! The explicit MDP: states `0..n` ([`MdpState`]), each either a *decision state* with at least
//! one choice ([`ChoiceId`], numbered globally) or an *absorbing state* with a payoff.
//!
//! Invariants that [`MdpBuilder::build`] establishes and every consumer may rely on:
//! - a state is absorbing iff it has no choices; a decision state without choices is rejected
//!   (the hypergame construction makes such states absorbing with payoff 0 instead);
//! - payoffs are finite and ≥ 0; decision states carry no payoff;
//! - every choice names an interned action and has a non-empty distribution whose targets are
//!   distinct, in range and sorted ascending, whose probabilities are positive and were given
//!   summing to 1 within [`PROBABILITY_TOLERANCE`]; they are then divided by their sum, so the
//!   stored distribution sums to 1 up to rounding;
//! - every choice is either a *move* (one robot move: it costs one factor of the discount and
//!   counts in the expected number of moves) or *instant* (the adversary's chance move, or the
//!   robot's `stop`, which collects its payoff at once);
//! - there is exactly one initial state;
//! - action names are non-empty (any name the arena format accepts; `drn` escapes white space
//!   and control characters). States have no names: a model built from a game names them on demand from
//!   the game, so that no string is kept per state.
//!
//! Layout: compressed sparse rows, two levels. `choice_offsets[s]..choice_offsets[s + 1]` are the
//! global ids of the choices of state `s` (a range of ids, not a [`Csr`]: the choices are the
//! rows of the next level); `transitions` (a [`Csr`]) gives the targets of each choice. Choices
//! of one state are consecutive, so a state's transitions are one contiguous range too.
//!
//! Distributions are *shared*: every distinct probability vector (compared bit for bit, after
//! normalisation) is stored once, in a pool, and each choice keeps where its vector starts
//! there (its length is the choice's number of targets). The pool starts with the point
//! distribution `[1.0]`, so a choice of one target stores no probability of its own. A
//! hypergame MDP has few distinct distributions (a robot's move is certain; an adversary's
//! distribution is one per arena state, docs/semantics.md §6.2, shared by every product state
//! over it), so its probabilities cost 4 bytes per choice instead of 8 per transition. The pool
//! is deduplicated as it is written, by a hash table of its entries and a cache of the last one
//! (consecutive chance nodes usually share theirs); nothing about it is asked of the caller.
//!
//! Memory, with `N` states, `C` choices, `T` transitions and `D` pooled probabilities: `4N`
//! (choice offsets) + `2N` (payoffs: an index per state into the few distinct payoffs) + `10C`
//! (action id, 2 bytes, transition offset and distribution start) + `C/8` (instant bits) +
//! `4T` (targets) + `8D` bytes. Action and payoff ids take 2 bytes while there are at most
//! 65536 distinct ones, 4 beyond (`SmallIds`). Every array has exactly its length as
//! capacity once built ([`MdpBuilder::reserve`] lets a caller reserve an upper bound first, so
//! that no array grows by doubling on the way).
//!
//! Building: [`MdpBuilder`] state by state, or, inside the crate, from exact counts: a caller
//! that can go through its states twice counts them (`Counts`, per chunk of consecutive
//! states), lays the MDP out at its exact size (`MdpLayout`) and writes each chunk in place
//! (`ChunkWriter`, in parallel if it likes; each chunk pools its own distributions, merged in
//! chunk order at the end, so that the pool lists them in order of first use as the builder's
//! does). The second way takes the MDP's own memory and nothing more (no upper bound reserved,
//! no copy; the pool grows, but it is small), and gives the same MDP, bit for bit.

use std::collections::HashMap;
use std::hash::{BuildHasher, Hash, Hasher};

use bit_set::BitSet;

use thiserror::Error;

use crate::csr::Csr;
use crate::index::{IdRange, id_type};
use crate::limits::MemoryLimit;
use crate::stage::Meter;

id_type! {
    /// An MDP state, indexing `0..Mdp::num_states()`. A hypergame MDP numbers its states after
    /// the product's, but the two are different ids: `HypergameMdp::node` and `product_state`
    /// convert.
    ///
    /// An MDP state is not accepted where a product state is expected:
    ///
    /// ```compile_fail,E0308
    /// use hypersynth::game::Hypergame;
    /// use hypersynth::mdp::MdpState;
    ///
    /// fn owner_of(game: &Hypergame, s: MdpState) {
    ///     game.owner(s); // expected `HState`, found `MdpState`
    /// }
    /// ```
    ///
    /// The conversion is explicit:
    ///
    /// ```
    /// use hypersynth::game::{HState, Hypergame};
    /// use hypersynth::mdp::MdpState;
    /// use hypersynth::opportunistic::build::HypergameMdp;
    ///
    /// fn owner_of(game: &Hypergame, mdp: &HypergameMdp, s: MdpState) {
    ///     let h: Option<HState> = mdp.product_state(s); // `None` for the stop sinks
    ///     let _ = h.map(|h| game.owner(h));
    /// }
    /// ```
    pub struct MdpState;
}

id_type! {
    /// A choice of an MDP, numbered globally (the choices of state `s` are consecutive, see
    /// [`Mdp::choices`]).
    pub struct ChoiceId;
}

/// How far the probabilities of one choice may sum away from 1 before the builder rejects them.
pub const PROBABILITY_TOLERANCE: f64 = 1e-9;

/// Ids below 2^32, two bytes each while they are below 2^16, four once one is not: per choice
/// its action, per state its payoff, of which there are few distinct ones.
#[derive(Clone, Debug, PartialEq, Eq)]
enum SmallIds {
    Narrow(Vec<u16>),
    Wide(Vec<u32>),
}

impl Default for SmallIds {
    fn default() -> Self {
        SmallIds::Narrow(Vec::new())
    }
}

impl SmallIds {
    fn len(&self) -> usize {
        match self {
            SmallIds::Narrow(ids) => ids.len(),
            SmallIds::Wide(ids) => ids.len(),
        }
    }

    #[inline]
    fn get(&self, i: usize) -> u32 {
        match self {
            SmallIds::Narrow(ids) => u32::from(ids[i]),
            SmallIds::Wide(ids) => ids[i],
        }
    }

    fn push(&mut self, id: u32) {
        match self {
            SmallIds::Narrow(ids) => match u16::try_from(id) {
                Ok(id) => ids.push(id),
                Err(_) => {
                    let mut wide: Vec<u32> = Vec::with_capacity(ids.capacity());
                    wide.extend(ids.iter().map(|&id| u32::from(id)));
                    wide.push(id);
                    *self = SmallIds::Wide(wide);
                }
            },
            SmallIds::Wide(ids) => ids.push(id),
        }
    }

    fn reserve_exact(&mut self, more: usize) {
        match self {
            SmallIds::Narrow(ids) => ids.reserve_exact(more),
            SmallIds::Wide(ids) => ids.reserve_exact(more),
        }
    }

    fn shrink_to_fit(&mut self) {
        match self {
            SmallIds::Narrow(ids) => ids.shrink_to_fit(),
            SmallIds::Wide(ids) => ids.shrink_to_fit(),
        }
    }

    /// `len` zeros, four bytes each if `wide`.
    fn zeros(len: usize, wide: bool) -> SmallIds {
        if wide {
            SmallIds::Wide(vec![0; len])
        } else {
            SmallIds::Narrow(vec![0; len])
        }
    }

    /// Consecutive disjoint parts of the given lengths, to be written in place.
    fn split_mut(&mut self, lengths: impl Iterator<Item = usize>) -> Vec<SmallIdsMut<'_>> {
        match self {
            SmallIds::Narrow(ids) => split_mut(ids, lengths)
                .into_iter()
                .map(SmallIdsMut::Narrow)
                .collect(),
            SmallIds::Wide(ids) => split_mut(ids, lengths)
                .into_iter()
                .map(SmallIdsMut::Wide)
                .collect(),
        }
    }
}

/// A part of a [`SmallIds`], written in place (the width is chosen beforehand, so that every id
/// fits).
enum SmallIdsMut<'a> {
    Narrow(&'a mut [u16]),
    Wide(&'a mut [u32]),
}

impl SmallIdsMut<'_> {
    #[inline]
    fn set(&mut self, i: usize, id: u32) {
        match self {
            SmallIdsMut::Narrow(ids) => {
                debug_assert!(id <= u32::from(u16::MAX), "a narrow id");
                ids[i] = id as u16;
            }
            SmallIdsMut::Wide(ids) => ids[i] = id,
        }
    }
}

/// `slice` cut into consecutive parts of the given lengths (which must add up to at most its
/// length).
fn split_mut<T>(mut slice: &mut [T], lengths: impl Iterator<Item = usize>) -> Vec<&mut [T]> {
    lengths
        .map(|len| {
            let (part, rest) = std::mem::take(&mut slice).split_at_mut(len);
            slice = rest;
            part
        })
        .collect()
}

/// An explicit MDP whose absorbing states carry payoffs. Build it with [`MdpBuilder`].
#[derive(Clone, Debug, PartialEq)]
pub struct Mdp {
    action_names: Vec<String>,
    /// Per state, where its choices start (one more entry at the end).
    choice_offsets: Vec<u32>,
    /// Per choice, its interned action.
    choice_actions: SmallIds,
    /// Per choice, its targets (ascending and distinct).
    transitions: Csr<ChoiceId, MdpState>,
    /// Per choice, where its probabilities start in `pool` (one per target, beside them).
    distributions: Vec<u32>,
    /// The distinct distributions, one after the other, the point distribution `[1.0]` first.
    pool: Vec<f64>,
    /// The instant choices (all others are moves).
    instant: BitSet,
    /// Per state, its payoff's index in `payoff_values` (that of 0 for decision states).
    payoff_ids: SmallIds,
    /// The distinct payoffs (as bit patterns: -0 and 0 are kept apart), in order of first use.
    payoff_values: Vec<f64>,
    initial: MdpState,
}

impl Mdp {
    /// The number of states (ids `0..num_states()`).
    pub fn num_states(&self) -> usize {
        self.payoff_ids.len()
    }

    /// The number of choices over all states.
    pub fn num_choices(&self) -> usize {
        self.choice_actions.len()
    }

    /// The number of transitions (successors with positive probability) over all choices.
    pub fn num_transitions(&self) -> usize {
        self.transitions.num_entries()
    }

    /// Every state, in order.
    pub fn states(&self) -> IdRange<MdpState> {
        MdpState::range(self.num_states())
    }

    /// Every choice, in order.
    pub fn all_choices(&self) -> IdRange<ChoiceId> {
        ChoiceId::range(self.num_choices())
    }

    /// The initial state.
    pub fn initial(&self) -> MdpState {
        self.initial
    }

    /// The global ids of the choices of `state`; empty iff the state is absorbing.
    pub fn choices(&self, state: MdpState) -> IdRange<ChoiceId> {
        IdRange::from_raw(
            self.choice_offsets[state.index()],
            self.choice_offsets[state.index() + 1],
        )
    }

    /// Whether `state` has no choices (it pays its payoff and the run ends).
    pub fn is_absorbing(&self, state: MdpState) -> bool {
        self.choice_offsets[state.index()] == self.choice_offsets[state.index() + 1]
    }

    /// The payoff of an absorbing state; `None` for a decision state.
    pub fn payoff(&self, state: MdpState) -> Option<f64> {
        self.is_absorbing(state)
            .then(|| self.payoff_values[self.payoff_ids.get(state.index()) as usize])
    }

    /// The interned action id of `choice` (an index into [`Mdp::action_names`]).
    pub fn action(&self, choice: ChoiceId) -> u32 {
        self.choice_actions.get(choice.index())
    }

    /// The name of `choice`'s action.
    pub fn action_name(&self, choice: ChoiceId) -> &str {
        &self.action_names[self.action(choice) as usize]
    }

    /// Every interned action name, indexed by action id.
    pub fn action_names(&self) -> &[String] {
        &self.action_names
    }

    /// Whether `choice` is instant (no robot move: no discount, no time) rather than a move.
    pub fn is_instant(&self, choice: ChoiceId) -> bool {
        self.instant.contains(choice.index())
    }

    /// The factor `choice` applies to the values of its successors: `g` for a move, 1 for an
    /// instant choice.
    pub fn discount_factor(&self, choice: ChoiceId, g: f64) -> f64 {
        if self.is_instant(choice) { 1.0 } else { g }
    }

    /// The successors of `choice` with their probabilities, targets ascending and distinct.
    pub fn successors(
        &self,
        choice: ChoiceId,
    ) -> impl ExactSizeIterator<Item = (MdpState, f64)> + Clone + '_ {
        let targets = self.transitions.row(choice);
        targets
            .iter()
            .copied()
            .zip(self.probabilities(choice).iter().copied())
    }

    /// The probabilities of `choice`'s successors, beside [`Mdp::targets`].
    pub fn probabilities(&self, choice: ChoiceId) -> &[f64] {
        let start = self.distributions[choice.index()] as usize;
        &self.pool[start..start + self.transitions.row(choice).len()]
    }

    /// The successor states of `choice`, ascending and distinct.
    pub fn targets(&self, choice: ChoiceId) -> &[MdpState] {
        self.transitions.row(choice)
    }

    /// Per choice, where its probabilities start in [`Mdp::pool`].
    pub(crate) fn distribution_starts(&self) -> &[u32] {
        &self.distributions
    }

    /// The distinct distributions, one after the other ([`Mdp::probabilities`] of a choice is
    /// the run of its number of targets from its start).
    pub(crate) fn pool(&self) -> &[f64] {
        &self.pool
    }

    /// How many probabilities the pool holds (each distinct distribution once).
    pub fn num_pooled_probabilities(&self) -> usize {
        self.pool.len()
    }
}

/// Why an [`Mdp`] could not be built. States and actions are named as the builder saw them.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum MdpError {
    /// An empty action name.
    #[error("invalid action name {name:?}: action names are non-empty")]
    InvalidActionName {
        /// The name given.
        name: String,
    },
    /// An action id that was not interned.
    #[error("unknown action id {action} ({count} actions are interned)")]
    UnknownAction {
        /// The id given.
        action: u32,
        /// How many actions are interned.
        count: u32,
    },
    /// `add_choice` without an open decision state.
    #[error("a choice was added while no decision state was open")]
    NoOpenDecisionState,
    /// A choice without successors.
    #[error("state {state}: action {action} has no successors")]
    EmptyDistribution {
        /// The state being filled.
        state: MdpState,
        /// The choice's action.
        action: String,
    },
    #[error(
        "state {state}: action {action} gives state {target} probability {probability}; \
         probabilities must be positive and finite"
    )]
    /// A probability that is not positive and finite.
    InvalidProbability {
        /// The state being filled.
        state: MdpState,
        /// The choice's action.
        action: String,
        /// The successor with that probability.
        target: MdpState,
        /// The probability given.
        probability: f64,
    },
    #[error("state {state}: the probabilities of action {action} sum to {sum}, not 1")]
    /// A distribution whose probabilities do not sum to 1 (within
    /// [`PROBABILITY_TOLERANCE`]).
    ProbabilitySum {
        /// The state being filled.
        state: MdpState,
        /// The choice's action.
        action: String,
        /// The sum found.
        sum: f64,
    },
    #[error(
        "state {state}: action {action} leads to state {target}, but there are only {states} states"
    )]
    /// A successor that is not a state of the built MDP.
    TargetOutOfRange {
        /// The state whose choice names it.
        state: MdpState,
        /// The choice's action.
        action: String,
        /// The successor named.
        target: MdpState,
        /// How many states the MDP has.
        states: u32,
    },
    /// A decision state closed without any choice.
    #[error("state {state} is a decision state without choices (make it absorbing with payoff 0)")]
    NoChoices {
        /// The state.
        state: MdpState,
    },
    /// A payoff that is negative or not finite.
    #[error("state {state}: payoff {payoff} is not a finite number ≥ 0")]
    InvalidPayoff {
        /// The absorbing state.
        state: MdpState,
        /// The payoff given.
        payoff: f64,
    },
    /// The initial state named does not exist.
    #[error("state {state} does not exist ({states} states)")]
    UnknownState {
        /// The state named.
        state: MdpState,
        /// How many states the MDP has.
        states: u32,
    },
    /// `build` without an initial state.
    #[error("no initial state was set")]
    NoInitialState,
    /// More states, choices or transitions than 32-bit indices allow.
    #[error("the MDP has more than 2^32 - 1 states, choices or transitions")]
    TooLarge,
    /// Laying the MDP out would need more memory than the observer allows.
    #[error(transparent)]
    Memory(#[from] MemoryLimit),
}

/// The distinct distributions of an MDP being built (module documentation): each stored once,
/// in order of first use, found again by a hash table of (start, length) pairs over its own
/// values, compared bit for bit.
#[derive(Clone, Debug)]
struct Pool {
    values: Vec<f64>,
    table: hashbrown::HashTable<(u32, u32)>,
    hasher: foldhash::fast::RandomState,
    /// The entry found or added last: consecutive choices often share theirs.
    last: (u32, u32),
}

impl Default for Pool {
    fn default() -> Self {
        Pool {
            values: vec![1.0],
            table: hashbrown::HashTable::new(),
            hasher: foldhash::fast::RandomState::default(),
            last: (0, 1),
        }
    }
}

/// A distribution as the pool hashes and compares it: by the bits of its probabilities.
struct Bits<'a>(&'a [f64]);

impl Hash for Bits<'_> {
    fn hash<H: Hasher>(&self, state: &mut H) {
        for probability in self.0 {
            state.write_u64(probability.to_bits());
        }
    }
}

fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

impl Pool {
    /// Where `probabilities` start in the pool, added if they are not there yet.
    fn intern(&mut self, probabilities: &[f64]) -> Result<u32, MdpError> {
        let entry = |values: &[f64], (start, len): (u32, u32)| -> bool {
            same_bits(
                &values[start as usize..(start + len) as usize],
                probabilities,
            )
        };
        if probabilities.len() == 1 && probabilities[0].to_bits() == 1f64.to_bits() {
            return Ok(0);
        }
        if entry(&self.values, self.last) {
            return Ok(self.last.0);
        }
        let hash = self.hasher.hash_one(Bits(probabilities));
        if let Some(&found) = self.table.find(hash, |&e| entry(&self.values, e)) {
            self.last = found;
            return Ok(found.0);
        }
        let start = to_u32(self.values.len())?;
        let len = to_u32(probabilities.len())?;
        to_u32(self.values.len() + probabilities.len())?;
        self.values.extend_from_slice(probabilities);
        let (values, hasher) = (&self.values, &self.hasher);
        self.table.insert_unique(hash, (start, len), |&(s, l)| {
            hasher.hash_one(Bits(&values[s as usize..(s + l) as usize]))
        });
        self.last = (start, len);
        Ok(start)
    }

    /// The pooled values, without spare capacity (the table is dropped).
    fn into_values(mut self) -> Vec<f64> {
        self.values.shrink_to_fit();
        self.values
    }
}

/// Builds an [`Mdp`] state by state, in index order: `add_decision_state` opens a decision state
/// that the following `add_choice` calls fill; `add_absorbing_state` adds an absorbing one.
/// Targets may name states that are added later; they are checked by [`MdpBuilder::build`].
/// An error leaves the builder unchanged.
#[derive(Clone, Debug, Default)]
pub struct MdpBuilder {
    actions: ActionNames,
    choice_offsets: Vec<u32>,
    choice_actions: SmallIds,
    transitions: Csr<ChoiceId, MdpState>,
    distributions: Vec<u32>,
    pool: Pool,
    instant: BitSet,
    payoff_ids: SmallIds,
    payoff_values: Vec<f64>,
    /// The index of each payoff in `payoff_values`, by bit pattern.
    payoff_index: HashMap<u64, u32>,
    absorbing: BitSet,
    initial: Option<MdpState>,
    /// Reused by `add_choice` to sort and merge a distribution.
    scratch: Vec<(MdpState, f64)>,
    /// Reused by `add_choice` for the probabilities of `scratch`.
    probabilities: Vec<f64>,
}

impl MdpBuilder {
    /// An empty builder.
    pub fn new() -> Self {
        MdpBuilder {
            choice_offsets: vec![0],
            ..MdpBuilder::default()
        }
    }

    /// Reserves room for `states` more states, `choices` more choices and `transitions` more
    /// transitions. Upper bounds are fine: [`MdpBuilder::build`] gives back what is not used,
    /// and memory reserved but never written is not resident; what it saves is the arrays'
    /// growth by doubling (a copy, and up to half of each array spare).
    pub fn reserve(&mut self, states: usize, choices: usize, transitions: usize) {
        self.choice_offsets.reserve_exact(states);
        self.payoff_ids.reserve_exact(states);
        self.choice_actions.reserve_exact(choices);
        self.transitions.reserve_exact(choices, transitions);
        self.distributions.reserve_exact(choices);
    }

    /// Interns an action name and returns its id (the same id for the same name).
    pub fn action(&mut self, name: &str) -> Result<u32, MdpError> {
        self.actions.intern(name)
    }

    /// Adds a decision state; the following [`MdpBuilder::add_choice`] calls give its choices.
    pub fn add_decision_state(&mut self) -> Result<MdpState, MdpError> {
        self.add_state(0.0, false)
    }

    /// Adds an absorbing state with a finite payoff ≥ 0.
    pub fn add_absorbing_state(&mut self, payoff: f64) -> Result<MdpState, MdpError> {
        if !(payoff.is_finite() && payoff >= 0.0) {
            return Err(MdpError::InvalidPayoff {
                state: MdpState::from_u32(to_u32(self.payoff_ids.len())?),
                payoff,
            });
        }
        self.add_state(payoff, true)
    }

    /// Adds a move (a choice that takes one robot move) to the decision state added last.
    /// Duplicate targets are merged (their probabilities added); the distribution is normalised
    /// to sum to 1. Returns the choice id.
    pub fn add_choice(
        &mut self,
        action: u32,
        successors: &[(MdpState, f64)],
    ) -> Result<ChoiceId, MdpError> {
        self.add_timed_choice(action, successors, false)
    }

    /// Adds an instant choice (no robot move: not discounted, not counted as time), otherwise
    /// like [`MdpBuilder::add_choice`].
    pub fn add_instant_choice(
        &mut self,
        action: u32,
        successors: &[(MdpState, f64)],
    ) -> Result<ChoiceId, MdpError> {
        self.add_timed_choice(action, successors, true)
    }

    fn add_timed_choice(
        &mut self,
        action: u32,
        successors: &[(MdpState, f64)],
        instant: bool,
    ) -> Result<ChoiceId, MdpError> {
        let state = match self.payoff_ids.len().checked_sub(1) {
            Some(last) if !self.absorbing.contains(last) => MdpState::new(last),
            _ => return Err(MdpError::NoOpenDecisionState),
        };
        distribution(
            state,
            action,
            &self.actions.names,
            successors,
            &mut self.scratch,
        )?;
        // Check every count before mutating, so that an error leaves the builder unchanged.
        to_u32(self.transitions.num_entries() + self.scratch.len())?;
        let choice = ChoiceId::from_u32(to_u32(self.choice_actions.len())?);
        let choices_end = to_u32(self.choice_actions.len() + 1)?;
        self.probabilities.clear();
        self.probabilities
            .extend(self.scratch.iter().map(|&(_, probability)| probability));
        let start = self.pool.intern(&self.probabilities)?;
        for &(target, _) in &self.scratch {
            self.transitions.push(target);
        }
        self.transitions.finish_row();
        self.distributions.push(start);
        if instant {
            self.instant.insert(choice.index());
        }
        self.choice_actions.push(action);
        let open_state_end = self.choice_offsets.len() - 1;
        self.choice_offsets[open_state_end] = choices_end;
        Ok(choice)
    }

    /// Sets the initial state (checked by [`MdpBuilder::build`]).
    pub fn set_initial(&mut self, state: MdpState) {
        self.initial = Some(state);
    }

    /// Checks what could not be checked while adding (targets and the initial state in range,
    /// every decision state with a choice) and returns the MDP.
    pub fn build(mut self) -> Result<Mdp, MdpError> {
        let states = to_u32(self.payoff_ids.len())?;
        for state in MdpState::range(self.payoff_ids.len()) {
            let choices: IdRange<ChoiceId> = IdRange::from_raw(
                self.choice_offsets[state.index()],
                self.choice_offsets[state.index() + 1],
            );
            if choices.is_empty() && !self.absorbing.contains(state.index()) {
                return Err(MdpError::NoChoices { state });
            }
            for choice in choices {
                let row = self.transitions.row(choice);
                if let Some(&target) = row.iter().find(|&&t| t.as_u32() >= states) {
                    return Err(MdpError::TargetOutOfRange {
                        state,
                        action: self.actions.names
                            [self.choice_actions.get(choice.index()) as usize]
                            .clone(),
                        target,
                        states,
                    });
                }
            }
        }
        let initial = self.initial.ok_or(MdpError::NoInitialState)?;
        if initial.as_u32() >= states {
            return Err(MdpError::UnknownState {
                state: initial,
                states,
            });
        }
        self.choice_offsets.shrink_to_fit();
        self.choice_actions.shrink_to_fit();
        self.transitions.shrink_to_fit();
        self.distributions.shrink_to_fit();
        self.instant.shrink_to_fit();
        self.payoff_ids.shrink_to_fit();
        self.payoff_values.shrink_to_fit();
        Ok(Mdp {
            action_names: self.actions.names,
            choice_offsets: self.choice_offsets,
            choice_actions: self.choice_actions,
            transitions: self.transitions,
            distributions: self.distributions,
            pool: self.pool.into_values(),
            instant: self.instant,
            payoff_ids: self.payoff_ids,
            payoff_values: self.payoff_values,
            initial,
        })
    }

    fn add_state(&mut self, payoff: f64, absorbing: bool) -> Result<MdpState, MdpError> {
        let state = self.payoff_ids.len();
        // The state count itself must fit in a u32 (`num_states`).
        to_u32(state + 1)?;
        let next = to_u32(self.payoff_values.len())?;
        let id = *self.payoff_index.entry(payoff.to_bits()).or_insert(next);
        if id == next {
            self.payoff_values.push(payoff);
        }
        self.payoff_ids.push(id);
        if absorbing {
            self.absorbing.insert(state);
        }
        let choices_so_far = self.choice_offsets[self.choice_offsets.len() - 1];
        self.choice_offsets.push(choices_so_far);
        Ok(MdpState::new(state))
    }
}

/// Where a construction that goes state by state, in index order, adds its states: first to
/// [`Counts`], which counts them, then to the [`ChunkWriter`]s of an [`MdpLayout`] made from
/// those counts, which write them in place. Called with the same states both times, the two
/// agree, and the result is the MDP an [`MdpBuilder`] fed the same calls builds.
pub(crate) trait AddStates {
    /// Adds a decision state; the following `add_choice` calls give its choices.
    fn add_decision_state(&mut self) -> Result<(), MdpError>;
    /// Adds an absorbing state with a finite payoff ≥ 0.
    fn add_absorbing_state(&mut self, payoff: f64) -> Result<(), MdpError>;
    /// Adds a choice to the decision state added last: a move, or instant if `instant` (see
    /// [`MdpBuilder::add_choice`]).
    fn add_choice(
        &mut self,
        action: u32,
        successors: &[(MdpState, f64)],
        instant: bool,
    ) -> Result<(), MdpError>;
}

/// The exact sizes of a run of consecutive states, counted before they are written
/// ([`AddStates`]); checks nothing (the writer does).
#[derive(Clone, Debug, Default)]
pub(crate) struct Counts {
    states: usize,
    choices: usize,
    transitions: usize,
    /// The greatest action id of a choice: action ids take four bytes past 2^16.
    max_action: u32,
    /// The distinct payoffs (as bit patterns, like the builder's), in order of first use
    /// (decision states use 0). Looked up by a linear search: meant for the few payoffs of the
    /// hypergame MDPs.
    payoffs: Vec<f64>,
    /// Reused to count the distinct targets of a choice.
    targets: Vec<MdpState>,
}

impl Counts {
    fn add_state(&mut self, payoff: f64) {
        self.states += 1;
        if !self.payoffs.iter().any(|p| p.to_bits() == payoff.to_bits()) {
            self.payoffs.push(payoff);
        }
    }
}

impl AddStates for Counts {
    fn add_decision_state(&mut self) -> Result<(), MdpError> {
        self.add_state(0.0);
        Ok(())
    }

    fn add_absorbing_state(&mut self, payoff: f64) -> Result<(), MdpError> {
        self.add_state(payoff);
        Ok(())
    }

    fn add_choice(
        &mut self,
        action: u32,
        successors: &[(MdpState, f64)],
        _instant: bool,
    ) -> Result<(), MdpError> {
        self.choices += 1;
        self.max_action = self.max_action.max(action);
        // Duplicate targets are merged: count the distinct ones.
        self.transitions += if successors.len() < 2 {
            successors.len()
        } else {
            self.targets.clear();
            self.targets
                .extend(successors.iter().map(|&(target, _)| target));
            self.targets.sort_unstable();
            self.targets.dedup();
            self.targets.len()
        };
        Ok(())
    }
}

/// An [`Mdp`] laid out at its exact size from the [`Counts`] of consecutive runs of states
/// (chunks), its arrays allocated once at their final length; each chunk is then written in
/// place by its own [`ChunkWriter`], independently of the others (in parallel, say), and
/// [`MdpLayout::finish`] checks and returns the MDP. Nothing grows and nothing is copied:
/// building takes the MDP's own memory (module documentation), plus an instant bit per choice
/// while the chunks' bits are joined, and each chunk's own pool of distributions until they
/// are merged.
pub(crate) struct MdpLayout {
    action_names: Vec<String>,
    payoff_values: Vec<f64>,
    /// Per chunk: its states, choices and transitions.
    chunks: Vec<[usize; 3]>,
    choice_offsets: Vec<u32>,
    choice_actions: SmallIds,
    transition_offsets: Vec<u32>,
    targets: Vec<MdpState>,
    /// Per choice, where its distribution starts: in its chunk's pool until `finish`.
    distributions: Vec<u32>,
    payoff_ids: SmallIds,
}

/// A chunk written by its [`ChunkWriter`]: the instant bits of its choices and its own pool of
/// distributions, for [`MdpLayout::finish`].
pub(crate) struct WrittenChunk {
    instant: BitSet,
    pool: Pool,
}

impl MdpLayout {
    /// The layout of the states counted in `chunks`, in order, with the actions `names`
    /// (interned by [`ActionNames`]); its exact size is reserved through `meter` first.
    pub(crate) fn new(
        names: ActionNames,
        chunks: &[Counts],
        meter: &mut Meter<'_>,
    ) -> Result<MdpLayout, MdpError> {
        let total = |count: fn(&Counts) -> usize| chunks.iter().map(count).sum::<usize>();
        let (states, choices, transitions) = (
            total(|c| c.states),
            total(|c| c.choices),
            total(|c| c.transitions),
        );
        to_u32(states)?;
        to_u32(choices)?;
        to_u32(transitions)?;
        let mut payoff_values: Vec<f64> = Vec::new();
        for payoff in chunks.iter().flat_map(|c| &c.payoffs) {
            if !payoff_values
                .iter()
                .any(|p| p.to_bits() == payoff.to_bits())
            {
                payoff_values.push(*payoff);
            }
        }
        // The widths the builder would reach: wide once an id does not fit in two bytes.
        let max_action = chunks.iter().map(|c| c.max_action).max().unwrap_or(0);
        let wide_actions = u16::try_from(max_action).is_err();
        let wide_payoffs = u16::try_from(payoff_values.len().saturating_sub(1)).is_err();
        let id = |wide: bool| if wide { 4 } else { 2 };
        let bytes = 4 * (states + 1)
            + id(wide_actions) * choices
            + 4 * (choices + 1)
            + 12 * transitions
            + id(wide_payoffs) * states
            + choices.div_ceil(8);
        meter.reserve(bytes as u64, || {
            format!("the MDP ({states} states, {choices} choices, {transitions} transitions)")
        })?;
        Ok(MdpLayout {
            action_names: names.names,
            payoff_values,
            chunks: chunks
                .iter()
                .map(|c| [c.states, c.choices, c.transitions])
                .collect(),
            choice_offsets: vec![0; states + 1],
            choice_actions: SmallIds::zeros(choices, wide_actions),
            transition_offsets: vec![0; choices + 1],
            targets: vec![MdpState::from_u32(0); transitions],
            distributions: vec![0; choices],
            payoff_ids: SmallIds::zeros(states, wide_payoffs),
        })
    }

    /// One writer per chunk, in order, each over its own parts of the arrays.
    pub(crate) fn writers(&mut self) -> Vec<ChunkWriter<'_>> {
        let num_states = self.payoff_ids.len() as u32;
        let lengths = |i: usize| self.chunks.iter().map(move |c| c[i]);
        let choice_ends = split_mut(&mut self.choice_offsets[1..], lengths(0));
        let payoff_ids = self.payoff_ids.split_mut(lengths(0));
        let actions = self.choice_actions.split_mut(lengths(1));
        let transition_ends = split_mut(&mut self.transition_offsets[1..], lengths(1));
        let targets = split_mut(&mut self.targets, lengths(2));
        let distributions = split_mut(&mut self.distributions, lengths(1));
        let mut first = [0; 3];
        let parts = choice_ends
            .into_iter()
            .zip(payoff_ids)
            .zip(actions.into_iter().zip(transition_ends))
            .zip(targets.into_iter().zip(distributions));
        parts
            .zip(&self.chunks)
            .map(
                |(
                    (
                        ((choice_ends, payoff_ids), (actions, transition_ends)),
                        (targets, distributions),
                    ),
                    chunk,
                )| {
                    let writer = ChunkWriter {
                        names: &self.action_names,
                        payoff_values: &self.payoff_values,
                        num_states,
                        first,
                        choice_ends,
                        payoff_ids,
                        actions,
                        transition_ends,
                        targets,
                        distributions,
                        pool: Pool::default(),
                        instant: BitSet::with_capacity(chunk[1]),
                        written: [0; 3],
                        open: None,
                        merged: Vec::new(),
                        probabilities: Vec::new(),
                    };
                    for (first, len) in first.iter_mut().zip(chunk) {
                        *first += len;
                    }
                    writer
                },
            )
            .collect()
    }

    /// The MDP, once every chunk is written ([`ChunkWriter::finish`], in chunk order). The
    /// chunks' pools are merged in chunk order, each in its own order of first use, which is
    /// the order of first use over the whole MDP (the builder's); each choice's start is then
    /// moved from its chunk's pool to the merged one.
    pub(crate) fn finish(
        mut self,
        chunks: Vec<WrittenChunk>,
        initial: MdpState,
    ) -> Result<Mdp, MdpError> {
        let states = self.payoff_ids.len();
        if initial.index() >= states {
            return Err(MdpError::UnknownState {
                state: initial,
                states: states as u32,
            });
        }
        assert_eq!(chunks.len(), self.chunks.len(), "every chunk was written");
        let mut bits = BitSet::new();
        bits.get_mut().reserve(self.choice_actions.len());
        let mut pool = Pool::default();
        let mut first_choice = 0;
        for (chunk, counted) in chunks.into_iter().zip(&self.chunks) {
            let mut instant = chunk.instant;
            bits.get_mut().append(instant.get_mut());
            // Where each entry of the chunk's pool (by its start) goes in the merged one.
            let local = chunk.pool.values;
            let mut moved = vec![0u32; local.len()];
            let mut entries: Vec<(u32, u32)> = chunk.pool.table.into_iter().collect();
            entries.sort_unstable();
            for (start, len) in entries {
                let values = &local[start as usize..(start + len) as usize];
                moved[start as usize] = pool.intern(values)?;
            }
            let choices = first_choice..first_choice + counted[1];
            for start in &mut self.distributions[choices] {
                *start = moved[*start as usize];
            }
            first_choice += counted[1];
        }
        assert_eq!(
            bits.get_ref().len(),
            self.choice_actions.len(),
            "every chunk was written"
        );
        Ok(Mdp {
            action_names: self.action_names,
            choice_offsets: self.choice_offsets,
            choice_actions: self.choice_actions,
            transitions: Csr::from_parts(self.transition_offsets, self.targets),
            distributions: self.distributions,
            pool: pool.into_values(),
            instant: bits,
            payoff_ids: self.payoff_ids,
            payoff_values: self.payoff_values,
            initial,
        })
    }
}

/// Writes one chunk of an [`MdpLayout`] in place, with the checks of [`MdpBuilder`] (targets
/// are checked as they come: the number of states is known).
pub(crate) struct ChunkWriter<'a> {
    names: &'a [String],
    payoff_values: &'a [f64],
    num_states: u32,
    /// The chunk's first state, choice and transition.
    first: [usize; 3],
    /// Per state of the chunk, the end of its choices.
    choice_ends: &'a mut [u32],
    payoff_ids: SmallIdsMut<'a>,
    actions: SmallIdsMut<'a>,
    /// Per choice of the chunk, the end of its transitions.
    transition_ends: &'a mut [u32],
    targets: &'a mut [MdpState],
    /// Per choice of the chunk, where its distribution starts in `pool`.
    distributions: &'a mut [u32],
    /// The chunk's own distributions.
    pool: Pool,
    /// The instant choices of the chunk, numbered from its first.
    instant: BitSet,
    /// The states, choices and transitions written so far.
    written: [usize; 3],
    /// The decision state added last, with the choices it had then (`None` after an absorbing
    /// state).
    open: Option<(MdpState, usize)>,
    merged: Vec<(MdpState, f64)>,
    /// The probabilities of `merged`.
    probabilities: Vec<f64>,
}

impl ChunkWriter<'_> {
    /// Checks that the decision state added last has a choice, and that the chunk holds exactly
    /// what was counted; returns what [`MdpLayout::finish`] needs of it.
    pub(crate) fn finish(mut self) -> Result<WrittenChunk, MdpError> {
        self.close()?;
        assert_eq!(
            self.written,
            [
                self.choice_ends.len(),
                self.transition_ends.len(),
                self.targets.len()
            ],
            "the counts were exact"
        );
        Ok(WrittenChunk {
            instant: self.instant,
            pool: self.pool,
        })
    }

    fn close(&mut self) -> Result<(), MdpError> {
        match self.open.take() {
            Some((state, choices)) if choices == self.written[1] => {
                Err(MdpError::NoChoices { state })
            }
            _ => Ok(()),
        }
    }

    fn add_state(&mut self, payoff: f64) -> Result<MdpState, MdpError> {
        self.close()?;
        let i = self.written[0];
        let id = self
            .payoff_values
            .iter()
            .position(|p| p.to_bits() == payoff.to_bits())
            .expect("the payoff was counted");
        self.payoff_ids.set(i, id as u32);
        self.choice_ends[i] = (self.first[1] + self.written[1]) as u32;
        self.written[0] += 1;
        Ok(MdpState::new(self.first[0] + i))
    }
}

impl AddStates for ChunkWriter<'_> {
    fn add_decision_state(&mut self) -> Result<(), MdpError> {
        let choices = self.written[1];
        let state = self.add_state(0.0)?;
        self.open = Some((state, choices));
        Ok(())
    }

    fn add_absorbing_state(&mut self, payoff: f64) -> Result<(), MdpError> {
        if !(payoff.is_finite() && payoff >= 0.0) {
            return Err(MdpError::InvalidPayoff {
                state: MdpState::new(self.first[0] + self.written[0]),
                payoff,
            });
        }
        self.add_state(payoff).map(|_| ())
    }

    fn add_choice(
        &mut self,
        action: u32,
        successors: &[(MdpState, f64)],
        instant: bool,
    ) -> Result<(), MdpError> {
        let Some((state, _)) = self.open else {
            return Err(MdpError::NoOpenDecisionState);
        };
        distribution(state, action, self.names, successors, &mut self.merged)?;
        if let Some(&(target, _)) = self
            .merged
            .last()
            .filter(|t| t.0.as_u32() >= self.num_states)
        {
            return Err(MdpError::TargetOutOfRange {
                state,
                action: self.names[action as usize].clone(),
                target,
                states: self.num_states,
            });
        }
        let [_, choice, start] = self.written;
        self.probabilities.clear();
        self.probabilities
            .extend(self.merged.iter().map(|&(_, probability)| probability));
        self.distributions[choice] = self.pool.intern(&self.probabilities)?;
        for (k, &(target, _)) in self.merged.iter().enumerate() {
            self.targets[start + k] = target;
        }
        self.written[2] += self.merged.len();
        self.transition_ends[choice] = (self.first[2] + self.written[2]) as u32;
        self.actions.set(choice, action);
        if instant {
            self.instant.insert(choice);
        }
        self.written[1] += 1;
        self.choice_ends[self.written[0] - 1] = (self.first[1] + self.written[1]) as u32;
        Ok(())
    }
}

/// Interned action names: one id per distinct non-empty name, in order of first use.
#[derive(Clone, Debug, Default)]
pub(crate) struct ActionNames {
    names: Vec<String>,
    ids: HashMap<String, u32>,
}

impl ActionNames {
    /// The id of `name`, interned on first use.
    pub(crate) fn intern(&mut self, name: &str) -> Result<u32, MdpError> {
        if let Some(&id) = self.ids.get(name) {
            return Ok(id);
        }
        if name.is_empty() {
            return Err(MdpError::InvalidActionName {
                name: name.to_owned(),
            });
        }
        let id = to_u32(self.names.len())?;
        self.names.push(name.to_owned());
        self.ids.insert(name.to_owned(), id);
        Ok(id)
    }
}

/// Checks `successors` as the distribution of a choice of `state` by `action` (an id into
/// `names`) and leaves it in `merged` as an MDP stores it: targets ascending, duplicates merged
/// (their probabilities added, in the order given), each probability divided by the sum given.
/// [`MdpBuilder`] and [`ChunkWriter`] share it, so that both store the same bits.
fn distribution(
    state: MdpState,
    action: u32,
    names: &[String],
    successors: &[(MdpState, f64)],
    merged: &mut Vec<(MdpState, f64)>,
) -> Result<(), MdpError> {
    let Some(name) = names.get(action as usize) else {
        return Err(MdpError::UnknownAction {
            action,
            count: to_u32(names.len())?,
        });
    };
    if successors.is_empty() {
        return Err(MdpError::EmptyDistribution {
            state,
            action: name.clone(),
        });
    }
    if let Some(&(target, probability)) = successors
        .iter()
        .find(|(_, probability)| !(probability.is_finite() && *probability > 0.0))
    {
        return Err(MdpError::InvalidProbability {
            state,
            action: name.clone(),
            target,
            probability,
        });
    }
    let sum = merge(successors, merged);
    if (sum - 1.0).abs() > PROBABILITY_TOLERANCE {
        return Err(MdpError::ProbabilitySum {
            state,
            action: name.clone(),
            sum,
        });
    }
    Ok(())
}

/// `successors` as a choice stores them, into `merged`: targets ascending and distinct (the
/// probabilities of a repeated target added), normalised by their sum, which it returns. Any
/// engine that writes the stored MDP's numbers uses it.
pub(crate) fn merge(successors: &[(MdpState, f64)], merged: &mut Vec<(MdpState, f64)>) -> f64 {
    let sum: f64 = successors.iter().map(|(_, probability)| probability).sum();
    merged.clear();
    merged.extend_from_slice(successors);
    merged.sort_by_key(|&(target, _)| target);
    merged.dedup_by(|next, kept| {
        let same = next.0 == kept.0;
        if same {
            kept.1 += next.1;
        }
        same
    });
    for (_, probability) in merged.iter_mut() {
        *probability /= sum;
    }
    sum
}

fn to_u32(count: usize) -> Result<u32, MdpError> {
    u32::try_from(count).map_err(|_| MdpError::TooLarge)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mdp::testing::{mc, ms};
    use crate::stage::Stage;

    /// A decision state 0 with actions N and stop, an absorbing state 1 with payoff 200.
    fn two_states() -> MdpBuilder {
        let mut builder = MdpBuilder::new();
        let north = builder.action("N").unwrap();
        let stop = builder.action("stop").unwrap();
        builder.add_decision_state().unwrap();
        builder
            .add_choice(north, &[(ms(0), 0.25), (ms(1), 0.5), (ms(0), 0.25)])
            .unwrap();
        builder.add_choice(stop, &[(ms(1), 1.0)]).unwrap();
        builder.add_absorbing_state(200.0).unwrap();
        builder.set_initial(ms(0));
        builder
    }

    #[test]
    fn builder_lays_out_csr_and_merges_duplicate_targets() {
        let mdp = two_states().build().unwrap();
        assert_eq!(
            (mdp.num_states(), mdp.num_choices(), mdp.num_transitions()),
            (2, 2, 3)
        );
        assert_eq!(mdp.choices(ms(0)).collect::<Vec<_>>(), [mc(0), mc(1)]);
        assert_eq!(mdp.choices(ms(1)).start(), mc(2));
        assert!(mdp.choices(ms(1)).is_empty());
        assert!(!mdp.is_absorbing(ms(0)) && mdp.is_absorbing(ms(1)));
        assert_eq!((mdp.payoff(ms(0)), mdp.payoff(ms(1))), (None, Some(200.0)));
        assert_eq!(
            (mdp.action_name(mc(0)), mdp.action_name(mc(1))),
            ("N", "stop")
        );
        assert_eq!(mdp.action_names(), ["N", "stop"]);
        // The two entries for state 0 (0.25 + 0.25) become one, targets ascending.
        assert_eq!(
            mdp.successors(mc(0)).collect::<Vec<_>>(),
            [(ms(0), 0.5), (ms(1), 0.5)]
        );
        assert_eq!(mdp.targets(mc(1)), [ms(1)]);
        assert_eq!(mdp.initial(), ms(0));
    }

    #[test]
    fn probabilities_within_tolerance_are_normalised() {
        let mut builder = MdpBuilder::new();
        let a = builder.action("a").unwrap();
        builder.add_decision_state().unwrap();
        builder
            .add_choice(a, &[(ms(0), 0.5), (ms(1), 0.5 + 1e-10)])
            .unwrap();
        builder.add_absorbing_state(1.0).unwrap();
        builder.set_initial(ms(0));
        let mdp = builder.build().unwrap();
        let sum: f64 = mdp.successors(mc(0)).map(|(_, p)| p).sum();
        assert!((sum - 1.0).abs() <= f64::EPSILON);
    }

    #[test]
    fn ids_widen_past_two_bytes_and_arrays_keep_no_spare_capacity() {
        // 70 000 distinct payoffs and actions: ids past 2^16 switch both id arrays to 4 bytes.
        let n = 70_000u32;
        let mut builder = MdpBuilder::new();
        builder.reserve(2 * n as usize, n as usize, n as usize);
        let actions: Vec<u32> = (0..n)
            .map(|i| builder.action(&format!("a{i}")).unwrap())
            .collect();
        for i in 0..n {
            builder.add_decision_state().unwrap();
            builder
                .add_choice(actions[i as usize], &[(ms(n + i), 1.0)])
                .unwrap();
        }
        for i in 0..n {
            builder.add_absorbing_state(f64::from(i) + 0.5).unwrap();
        }
        builder.set_initial(ms(0));
        let mdp = builder.build().unwrap();
        assert!(matches!(mdp.choice_actions, SmallIds::Wide(_)));
        assert!(matches!(mdp.payoff_ids, SmallIds::Wide(_)));
        for i in [0, 1, 65_535, 65_536, n - 1] {
            assert_eq!(mdp.action_name(mc(i)), format!("a{i}"));
            assert_eq!(mdp.payoff(ms(n + i)), Some(f64::from(i) + 0.5));
            assert_eq!(mdp.payoff(ms(i)), None);
        }
        assert_eq!(mdp.payoff_values.len(), n as usize + 1);
        assert_eq!(mdp.distributions.capacity(), mdp.distributions.len());
        assert_eq!(mdp.pool.capacity(), mdp.pool.len());
        assert_eq!(mdp.choice_offsets.capacity(), mdp.choice_offsets.len());
        // A few payoffs: one id each, two bytes per state; -0 and 0 are kept apart.
        let mut builder = MdpBuilder::new();
        for payoff in [0.0, -0.0, 0.0, 1.0] {
            builder.add_absorbing_state(payoff).unwrap();
        }
        builder.set_initial(ms(0));
        let mdp = builder.build().unwrap();
        assert!(matches!(mdp.payoff_ids, SmallIds::Narrow(_)));
        assert_eq!(mdp.payoff_values.len(), 3);
        let payoffs: Vec<u64> = mdp
            .states()
            .map(|s| mdp.payoff(s).unwrap().to_bits())
            .collect();
        assert_eq!(payoffs, [0.0f64, -0.0, 0.0, 1.0].map(f64::to_bits));
    }

    #[test]
    fn interning_returns_one_id_per_name() {
        let mut builder = MdpBuilder::new();
        assert_eq!(builder.action("N"), Ok(0));
        assert_eq!(builder.action("S"), Ok(1));
        assert_eq!(builder.action("N"), Ok(0));
        assert_eq!(
            builder.action(""),
            Err(MdpError::InvalidActionName { name: "".into() })
        );
        // Every name the arena format accepts is an action name (DRN escapes what it must).
        assert_eq!(builder.action("go north"), Ok(2));
        assert_eq!(builder.action("tab\there"), Ok(3));
    }

    #[test]
    fn invalid_choices_are_rejected_without_changing_the_builder() {
        let mut builder = MdpBuilder::new();
        let a = builder.action("a").unwrap();
        assert_eq!(
            builder.add_choice(a, &[(ms(0), 1.0)]),
            Err(MdpError::NoOpenDecisionState)
        );
        builder.add_decision_state().unwrap();
        assert_eq!(
            builder.add_choice(7, &[(ms(0), 1.0)]),
            Err(MdpError::UnknownAction {
                action: 7,
                count: 1
            })
        );
        assert_eq!(
            builder.add_choice(a, &[]),
            Err(MdpError::EmptyDistribution {
                state: ms(0),
                action: "a".into()
            })
        );
        for bad in [0.0, -0.5, f64::NAN, f64::INFINITY] {
            assert!(matches!(
                builder.add_choice(a, &[(ms(0), bad), (ms(0), 1.0)]),
                Err(MdpError::InvalidProbability { state, target, .. })
                    if state == ms(0) && target == ms(0)
            ));
        }
        assert_eq!(
            builder.add_choice(a, &[(ms(0), 0.5), (ms(0), 0.4)]),
            Err(MdpError::ProbabilitySum {
                state: ms(0),
                action: "a".into(),
                sum: 0.9
            })
        );
        builder.add_choice(a, &[(ms(0), 1.0)]).unwrap();
        builder.set_initial(ms(0));
        let mdp = builder.build().unwrap();
        assert_eq!(mdp.num_choices(), 1);
        assert_eq!(mdp.num_transitions(), 1);
    }

    #[test]
    fn build_checks_targets_choices_payoffs_and_the_initial_state() {
        let mut builder = MdpBuilder::new();
        let a = builder.action("a").unwrap();
        builder.add_decision_state().unwrap();
        builder.add_choice(a, &[(ms(3), 1.0)]).unwrap();
        builder.set_initial(ms(0));
        assert_eq!(
            builder.clone().build(),
            Err(MdpError::TargetOutOfRange {
                state: ms(0),
                action: "a".into(),
                target: ms(3),
                states: 1
            })
        );

        let mut builder = MdpBuilder::new();
        builder.add_decision_state().unwrap();
        builder.set_initial(ms(0));
        assert_eq!(builder.build(), Err(MdpError::NoChoices { state: ms(0) }));

        let mut builder = MdpBuilder::new();
        for bad in [-1.0, f64::NAN, f64::INFINITY] {
            assert!(matches!(
                builder.add_absorbing_state(bad),
                Err(MdpError::InvalidPayoff { state, .. }) if state == ms(0)
            ));
        }
        builder.add_absorbing_state(0.0).unwrap();
        assert_eq!(builder.clone().build(), Err(MdpError::NoInitialState));
        builder.set_initial(ms(1));
        assert_eq!(
            builder.build(),
            Err(MdpError::UnknownState {
                state: ms(1),
                states: 1
            })
        );
    }

    /// Feeds `out` a fixed MDP over two runs of states: the first (states 0 and 1) uses the
    /// distributions [1], [0.5, 0.5] and [0.25, 0.75]; the second (states 2 to 4) first a new
    /// one, [0.1, 0.9], then [0.5, 0.5] again and [1]. States 5 and 6 are absorbing.
    fn pooled_states(out: &mut impl AddStates, run: usize) {
        // A choice of action 0 to states 5, 6, ... with the probabilities `p`.
        let add = |out: &mut dyn AddStates, p: &[f64]| {
            let successors: Vec<(MdpState, f64)> = (5..).map(ms).zip(p.iter().copied()).collect();
            out.add_choice(0, &successors, false).unwrap();
        };
        if run == 0 {
            out.add_decision_state().unwrap();
            add(out, &[1.0]);
            add(out, &[0.5, 0.5]);
            out.add_decision_state().unwrap();
            add(out, &[0.25, 0.75]);
            add(out, &[0.5, 0.5]);
        } else {
            out.add_decision_state().unwrap();
            add(out, &[0.1, 0.9]);
            out.add_decision_state().unwrap();
            add(out, &[0.5, 0.5]);
            out.add_decision_state().unwrap();
            add(out, &[1.0]);
            out.add_absorbing_state(1.0).unwrap();
            out.add_absorbing_state(2.0).unwrap();
        }
    }

    #[test]
    fn distributions_are_pooled_once_in_order_of_first_use_by_both_ways_of_building() {
        // The builder.
        struct Builder(MdpBuilder);
        impl AddStates for Builder {
            fn add_decision_state(&mut self) -> Result<(), MdpError> {
                self.0.add_decision_state().map(|_| ())
            }
            fn add_absorbing_state(&mut self, payoff: f64) -> Result<(), MdpError> {
                self.0.add_absorbing_state(payoff).map(|_| ())
            }
            fn add_choice(
                &mut self,
                action: u32,
                successors: &[(MdpState, f64)],
                instant: bool,
            ) -> Result<(), MdpError> {
                let added = if instant {
                    self.0.add_instant_choice(action, successors)
                } else {
                    self.0.add_choice(action, successors)
                };
                added.map(|_| ())
            }
        }
        let mut builder = Builder(MdpBuilder::new());
        builder.0.action("a").unwrap();
        for run in 0..2 {
            pooled_states(&mut builder, run);
        }
        builder.0.set_initial(ms(0));
        let built = builder.0.build().unwrap();
        // Each distinct distribution once, the certain one first and stored once for both of
        // its choices, in order of first use.
        assert_eq!(built.pool(), [1.0, 0.5, 0.5, 0.25, 0.75, 0.1, 0.9]);
        assert_eq!(built.distribution_starts(), [0, 1, 3, 1, 5, 1, 0]);
        assert_eq!(built.num_pooled_probabilities(), 7);
        assert_eq!(
            built.successors(mc(2)).collect::<Vec<_>>(),
            [(ms(5), 0.25), (ms(6), 0.75)]
        );
        assert_eq!(built.probabilities(mc(4)), [0.1, 0.9]);
        // From exact counts, in two chunks that each pool their own: the same MDP, bit for bit.
        let mut counts = [Counts::default(), Counts::default()];
        for (run, counts) in counts.iter_mut().enumerate() {
            pooled_states(counts, run);
        }
        let mut names = ActionNames::default();
        names.intern("a").unwrap();
        let mut layout =
            MdpLayout::new(names, &counts, &mut Meter::unobserved(Stage::MdpBuild)).unwrap();
        let chunks: Vec<WrittenChunk> = layout
            .writers()
            .into_iter()
            .enumerate()
            .map(|(run, mut writer)| {
                pooled_states(&mut writer, run);
                writer.finish().unwrap()
            })
            .collect();
        assert_eq!(layout.finish(chunks, ms(0)).unwrap(), built);
    }
}

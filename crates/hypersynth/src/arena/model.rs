//! The arena model: a two-player turn-based transition system with labelled states.
//!
//! Invariants (established by [`ArenaBuilder::build`], relied on everywhere else):
//! - states are `0..num_states()` ([`StateId`]), each with an [`Owner`], a label and a unique
//!   name;
//! - transitions are stored in CSR form (a [`Csr`] of `(action, target)` pairs), grouped by
//!   source state and kept in insertion order within a state, so that reading and writing an
//!   arena is the identity;
//! - the transition function is deterministic: at most one successor per (state, action);
//! - labels are interned: states with the same set of propositions share one [`LabelId`], so
//!   that per-label work (a DFA step, say) is done once per distinct label, not per state;
//! - exactly one initial state.

use std::hash::BuildHasher as _;

use bit_set::BitSet;

use crate::csr::Csr;
use crate::diagnostic::brief;
use crate::index::{Id, id_type};

id_type! {
    /// An arena state, indexing `0..Arena::num_states()`.
    pub struct StateId;
}

/// An action, indexing [`Arena::actions`]: actions are interned by name, shared by all states.
pub type ActionId = u32;
/// A distinct label, indexing [`Arena::labels`].
pub type LabelId = u32;
/// An atomic proposition, indexing [`Arena::propositions`].
pub type PropositionId = u32;

/// Who chooses the action in a state.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Owner {
    /// The robot (the player we synthesise for) chooses.
    Robot,
    /// The adversary chooses.
    Adversary,
}

/// A two-player turn-based arena with labelled states; see the module documentation for its
/// invariants.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Arena {
    propositions: Vec<String>,
    names: Names,
    /// The few states that have a display name, by ascending id (a slot per state would cost
    /// 24 bytes per arena state, most of them empty).
    displays: Vec<(StateId, String)>,
    owners: Vec<Owner>,
    label_of: Vec<LabelId>,
    /// Distinct labels, each a set of proposition ids.
    labels: Vec<BitSet>,
    actions: Vec<String>,
    /// Per state, its enabled actions with their successors.
    edges: Csr<StateId, (ActionId, StateId)>,
    initial: StateId,
    index: NameIndex,
}

/// The hasher of the arena's tables: foldhash, several times faster than the standard SipHash
/// on short names. The tables are only looked up, never iterated, so the hash shows in no
/// output.
type FastHash = foldhash::fast::RandomState;
type HashMap<K, V> = std::collections::HashMap<K, V, FastHash>;
pub(super) type HashSet<T> = std::collections::HashSet<T, FastHash>;

/// The states' names end to end in one buffer: no allocation per name, and a lookup reads two
/// neighbouring offsets and the bytes instead of a string header and its heap block.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
struct Names {
    text: String,
    /// Per name, the offset of its end in `text` (its start is the previous name's end).
    ends: Vec<usize>,
}

impl Names {
    fn len(&self) -> usize {
        self.ends.len()
    }

    fn get(&self, i: usize) -> &str {
        let start = if i == 0 { 0 } else { self.ends[i - 1] };
        &self.text[start..self.ends[i]]
    }

    fn push(&mut self, name: &str) {
        self.text.push_str(name);
        self.ends.push(self.text.len());
    }
}

/// State names to ids without a second copy of the names: a table of ids, hashed and compared
/// through the names they index.
#[derive(Clone, Debug, Default)]
struct NameIndex {
    hasher: FastHash,
    table: hashbrown::HashTable<StateId>,
}

impl NameIndex {
    fn find(&self, names: &Names, name: &str) -> Option<StateId> {
        let hash = self.hasher.hash_one(name);
        self.table
            .find(hash, |&id| names.get(id.index()) == name)
            .copied()
    }

    /// Adds `id`, the last of `names`, whose name is not in the table yet.
    fn insert(&mut self, names: &Names, id: StateId) {
        let hasher = &self.hasher;
        let hash = hasher.hash_one(names.get(id.index()));
        self.table
            .insert_unique(hash, id, |&id| hasher.hash_one(names.get(id.index())));
    }
}

/// The index is a function of the names, which [`Arena`]'s equality compares.
impl PartialEq for NameIndex {
    fn eq(&self, _: &NameIndex) -> bool {
        true
    }
}

impl Eq for NameIndex {}

impl Arena {
    /// The number of states; states are `0..num_states()`.
    pub fn num_states(&self) -> usize {
        self.names.len()
    }

    /// The number of transitions, over all states.
    pub fn num_transitions(&self) -> usize {
        self.edges.num_entries()
    }

    /// The initial state.
    pub fn initial(&self) -> StateId {
        self.initial
    }

    /// The propositions, indexed by [`PropositionId`], in order of declaration or first use.
    pub fn propositions(&self) -> &[String] {
        &self.propositions
    }

    /// The unique name of `state`.
    pub fn name(&self, state: StateId) -> &str {
        self.names.get(state.index())
    }

    /// The display name of `state`, a description in words, if it has one (the arena writer shows
    /// it; nothing else depends on it).
    pub fn display(&self, state: StateId) -> Option<&str> {
        let found = self.displays.binary_search_by_key(&state, |(id, _)| *id);
        found.ok().map(|i| self.displays[i].1.as_str())
    }

    /// Who chooses the action in `state`.
    pub fn owner(&self, state: StateId) -> Owner {
        self.owners[state.index()]
    }

    /// The id of the label of `state`: states with the same set of propositions share it.
    pub fn label_id(&self, state: StateId) -> LabelId {
        self.label_of[state.index()]
    }

    /// The set of propositions true in `state`.
    pub fn label(&self, state: StateId) -> &BitSet {
        &self.labels[self.label_of[state.index()] as usize]
    }

    /// The distinct labels, indexed by [`LabelId`].
    pub fn labels(&self) -> &[BitSet] {
        &self.labels
    }

    /// The interned action names, indexed by [`ActionId`].
    pub fn actions(&self) -> &[String] {
        &self.actions
    }

    /// The name of `action`.
    pub fn action_name(&self, action: ActionId) -> &str {
        &self.actions[action as usize]
    }

    /// The enabled actions of `state` with their successors, in insertion order.
    pub fn edges(&self, state: StateId) -> impl ExactSizeIterator<Item = (ActionId, StateId)> + '_ {
        self.edges.row(state).iter().copied()
    }

    /// The successor of `state` under `action`, if that action is enabled there.
    pub fn successor(&self, state: StateId, action: ActionId) -> Option<StateId> {
        self.edges(state)
            .find(|&(a, _)| a == action)
            .map(|(_, target)| target)
    }

    /// The state called `name`.
    pub fn find_state(&self, name: &str) -> Option<StateId> {
        self.index.find(&self.names, name)
    }

    /// The action called `name`, if any state enables it.
    pub fn find_action(&self, name: &str) -> Option<ActionId> {
        self.actions
            .iter()
            .position(|a| a == name)
            .map(|i| i as ActionId)
    }

    /// The proposition called `name`, if the arena has it.
    pub fn find_proposition(&self, name: &str) -> Option<PropositionId> {
        self.propositions
            .iter()
            .position(|p| p == name)
            .map(|i| i as PropositionId)
    }

    /// The states with no enabled action, in increasing order (docs/semantics.md §3: a stuck robot
    /// cannot progress, a stuck adversary is attracted).
    pub fn stuck_states(&self) -> impl Iterator<Item = StateId> + '_ {
        self.states().filter(|&s| self.edges.is_row_empty(s))
    }

    /// Every state, in order.
    pub fn states(&self) -> crate::index::IdRange<StateId> {
        StateId::range(self.num_states())
    }

    /// The states reachable from the initial state (the initial state included).
    pub fn reachable_states(&self) -> BitSet {
        let mut reached = BitSet::with_capacity(self.num_states());
        reached.insert(self.initial.index());
        let mut stack = vec![self.initial];
        while let Some(state) = stack.pop() {
            for (_, target) in self.edges(state) {
                if reached.insert(target.index()) {
                    stack.push(target);
                }
            }
        }
        reached
    }
}

/// What can go wrong when assembling an arena, independently of any text format (readers add
/// the position).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum BuildError {
    /// A state name used for two states.
    #[error("state `{}` is defined twice", brief(.0))]
    DuplicateState(String),
    /// Two transitions of one state with the same action.
    #[error(
        "state `{}` has two successors for action `{}`",
        brief(.state),
        brief(.action)
    )]
    DuplicateAction {
        /// The state's name.
        state: String,
        /// The action's name.
        action: String,
    },
    /// No state was made initial.
    #[error("no initial state")]
    MissingInitial,
}

/// Assembles an [`Arena`] state by state and transition by transition, in any order.
#[derive(Debug, Default)]
pub struct ArenaBuilder {
    propositions: Vec<String>,
    proposition_index: HashMap<String, PropositionId>,
    names: Names,
    /// By ascending id, as states are added in id order.
    displays: Vec<(StateId, String)>,
    owners: Vec<Owner>,
    label_of: Vec<LabelId>,
    labels: Vec<BitSet>,
    label_index: HashMap<Vec<u32>, LabelId>,
    actions: Vec<String>,
    action_index: HashMap<String, ActionId>,
    transitions: Vec<(StateId, ActionId, StateId)>,
    // Duplicate (state, action) detection without a hash set in the common case, where a hash
    // set costs a cache miss per transition on large arenas. Transitions from one source usually
    // come in one run (a reader of grouped text, a generator); within a source's first run,
    // `stamps[action] == run` iff the source already enables `action`. A source whose run starts
    // again later is *scattered*: its earlier transitions go into `scattered` once, and from then
    // on its transitions are checked there. Every transition enters the set at most once, so
    // any order costs linear time (edges alternating between two sources were quadratic when
    // each new run re-stamped the source's earlier transitions).
    /// Per transition, the previous transition from the same source (`NONE` for the first).
    previous: Vec<u32>,
    /// Per state, its latest transition (`NONE` if none).
    latest: Vec<u32>,
    run_source: Option<StateId>,
    run: u64,
    /// Per action, the last run in which the run's source was seen to enable it.
    stamps: Vec<u64>,
    /// Per state, whether it is scattered.
    is_scattered: Vec<bool>,
    /// The (state, action) pairs of the scattered states.
    scattered: HashSet<(StateId, ActionId)>,
    initial: Option<StateId>,
    index: NameIndex,
}

impl ArenaBuilder {
    /// An empty builder.
    pub fn new() -> Self {
        Self::default()
    }

    /// Interns a proposition; declaring it again returns the same id.
    pub fn proposition(&mut self, name: &str) -> PropositionId {
        if let Some(&id) = self.proposition_index.get(name) {
            return id;
        }
        let id = self.propositions.len() as PropositionId;
        self.propositions.push(name.to_string());
        self.proposition_index.insert(name.to_string(), id);
        id
    }

    /// Interns an action name; the same name always gives the same id.
    pub fn action(&mut self, name: &str) -> ActionId {
        if let Some(&id) = self.action_index.get(name) {
            return id;
        }
        let id = self.actions.len() as ActionId;
        self.actions.push(name.to_string());
        self.action_index.insert(name.to_string(), id);
        self.stamps.push(0);
        id
    }

    /// The state already added under `name`.
    pub fn find_state(&self, name: &str) -> Option<StateId> {
        self.index.find(&self.names, name)
    }

    /// The name of `state` if it was added, for a reader that guesses a state and checks its
    /// guess.
    pub(crate) fn state_name(&self, state: usize) -> Option<&str> {
        (state < self.names.len()).then(|| self.names.get(state))
    }

    /// The proposition already interned under `name`.
    pub fn find_proposition(&self, name: &str) -> Option<PropositionId> {
        self.proposition_index.get(name).copied()
    }

    /// The action already interned under `name`.
    pub fn find_action(&self, name: &str) -> Option<ActionId> {
        self.action_index.get(name).copied()
    }

    /// Adds a state whose label is the given propositions (interned on the way).
    pub fn add_state<'a>(
        &mut self,
        name: &str,
        owner: Owner,
        label: impl IntoIterator<Item = &'a str>,
        display: Option<String>,
    ) -> Result<StateId, BuildError> {
        if self.find_state(name).is_some() {
            return Err(BuildError::DuplicateState(name.to_string()));
        }
        let mut ids: Vec<u32> = label.into_iter().map(|p| self.proposition(p)).collect();
        ids.sort_unstable();
        ids.dedup();
        let next_label = self.labels.len() as LabelId;
        let label_id = *self.label_index.entry(ids).or_insert_with_key(|ids| {
            self.labels
                .push(ids.iter().map(|&id| id as usize).collect::<BitSet>());
            next_label
        });
        let id = StateId::new(self.names.len());
        self.names.push(name);
        if let Some(display) = display {
            self.displays.push((id, display));
        }
        self.owners.push(owner);
        self.label_of.push(label_id);
        self.latest.push(u32::NONE);
        self.is_scattered.push(false);
        self.index.insert(&self.names, id);
        Ok(id)
    }

    /// Adds `from --action--> to`; both states must already exist.
    pub fn add_transition(
        &mut self,
        from: StateId,
        action: &str,
        to: StateId,
    ) -> Result<(), BuildError> {
        let action_id = self.action(action);
        let from_index = from.index();
        if self.run_source != Some(from) {
            self.run += 1;
            self.run_source = Some(from);
            if !self.latest[from_index].is_none() && !self.is_scattered[from_index] {
                self.is_scattered[from_index] = true;
                let mut edge = self.latest[from_index];
                while !edge.is_none() {
                    self.scattered
                        .insert((from, self.transitions[edge as usize].1));
                    edge = self.previous[edge as usize];
                }
            }
        }
        let duplicate = if self.is_scattered[from_index] {
            !self.scattered.insert((from, action_id))
        } else {
            std::mem::replace(&mut self.stamps[action_id as usize], self.run) == self.run
        };
        if duplicate {
            return Err(BuildError::DuplicateAction {
                state: self.names.get(from_index).to_string(),
                action: action.to_string(),
            });
        }
        self.previous.push(self.latest[from_index]);
        self.latest[from_index] = self.transitions.len() as u32;
        self.transitions.push((from, action_id, to));
        Ok(())
    }

    /// Makes room for `additional` more transitions, when the caller knows how many will come.
    pub fn reserve_transitions(&mut self, additional: usize) {
        self.transitions.reserve(additional);
        self.previous.reserve(additional);
    }

    /// Makes `state` the initial state (the last call wins).
    pub fn set_initial(&mut self, state: StateId) {
        self.initial = Some(state);
    }

    /// The arena, its transitions grouped by source state in insertion order; an error when no
    /// state was made initial. Linear in the arena.
    pub fn build(self) -> Result<Arena, BuildError> {
        let initial = self.initial.ok_or(BuildError::MissingInitial)?;
        let edges = Csr::group(
            self.names.len(),
            self.transitions
                .iter()
                .map(|&(from, action, to)| (from, (action, to))),
        );
        Ok(Arena {
            propositions: self.propositions,
            names: self.names,
            displays: self.displays,
            owners: self.owners,
            label_of: self.label_of,
            labels: self.labels,
            actions: self.actions,
            edges,
            initial,
            index: self.index,
        })
    }
}

#[cfg(test)]
mod tests {
    use std::collections::HashSet;

    use super::*;

    #[test]
    fn builder_groups_edges_by_state_in_insertion_order_and_interns_labels() {
        let mut b = ArenaBuilder::new();
        let r = b.add_state("r", Owner::Robot, ["a"], None).unwrap();
        let e = b
            .add_state("e", Owner::Adversary, ["b", "a"], Some("E".into()))
            .unwrap();
        let s = b.add_state("s", Owner::Robot, ["a", "b"], None).unwrap();
        b.add_transition(e, "x", r).unwrap();
        b.add_transition(r, "go", e).unwrap();
        b.add_transition(r, "x", s).unwrap();
        b.set_initial(r);
        let arena = b.build().unwrap();
        assert_eq!(arena.edges(r).collect::<Vec<_>>(), vec![(1, e), (0, s)]);
        assert_eq!(arena.edges(e).collect::<Vec<_>>(), vec![(0, r)]);
        assert_eq!(arena.edges(s).count(), 0);
        assert_eq!(arena.action_name(1), "go");
        assert_eq!(arena.successor(r, 0), Some(s));
        assert_eq!(arena.successor(s, 0), None);
        // {b, a} and {a, b} are one label; {a} another.
        assert_eq!(arena.labels().len(), 2);
        assert_eq!(arena.label_id(e), arena.label_id(s));
        assert_eq!(arena.display(e), Some("E"));
        assert_eq!(arena.find_state("s"), Some(s));
        assert_eq!(arena.propositions(), ["a", "b"]);
    }

    #[test]
    fn builder_rejects_duplicates_and_a_missing_initial_state() {
        let mut b = ArenaBuilder::new();
        let r = b.add_state("r", Owner::Robot, [], None).unwrap();
        assert_eq!(
            b.add_state("r", Owner::Adversary, [], None),
            Err(BuildError::DuplicateState("r".into()))
        );
        b.add_transition(r, "a", r).unwrap();
        assert!(matches!(
            b.add_transition(r, "a", r),
            Err(BuildError::DuplicateAction { .. })
        ));
        assert_eq!(b.build(), Err(BuildError::MissingInitial));
    }

    #[test]
    fn stuck_and_reachable_states() {
        let mut b = ArenaBuilder::new();
        let r = b.add_state("r", Owner::Robot, [], None).unwrap();
        let e = b.add_state("e", Owner::Adversary, [], None).unwrap();
        let far = b.add_state("far", Owner::Robot, [], None).unwrap();
        b.add_transition(r, "go", e).unwrap();
        b.add_transition(far, "go", r).unwrap();
        b.set_initial(r);
        let arena = b.build().unwrap();
        assert_eq!(arena.stuck_states().collect::<Vec<_>>(), [e]);
        assert_eq!(arena.reachable_states().iter().collect::<Vec<_>>(), [0, 1]);
        assert_eq!(arena.states().collect::<Vec<_>>(), [r, e, far]);
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(128))]

        /// Duplicate detection, whatever the order of the transitions, agrees with a naive set.
        #[test]
        fn duplicate_actions_are_refused_in_any_order(
            transitions in proptest::collection::vec((0..4u32, 0..4u32), 0..40)
        ) {
            let mut b = ArenaBuilder::new();
            for name in ["s0", "s1", "s2", "s3"] {
                b.add_state(name, Owner::Robot, [], None).unwrap();
            }
            let mut naive = HashSet::new();
            let s0 = StateId::new(0);
            for (from, action) in transitions {
                let accepted = b.add_transition(StateId::from_u32(from), &action.to_string(), s0).is_ok();
                proptest::prop_assert_eq!(accepted, naive.insert((from, action)));
            }
            b.set_initial(s0);
            proptest::prop_assert_eq!(b.build().unwrap().num_transitions(), naive.len());
        }
    }
}

//! The deterministic finite automaton over the alphabet 2^AP.
//!
//! A [`Dfa`] is complete and deterministic: from every state, the guards of its outgoing edges
//! are pairwise disjoint and together valid, so every letter has exactly one successor. Edges are
//! stored in CSR form (a [`Csr`] of targets, the guards in a parallel array), at most one edge
//! per (state, target), so a state has as many edges as distinct successors whatever the number
//! of propositions.
//!
//! Letters are `u64` valuations of the automaton's propositions (bit `i` for `aps[i]`), see
//! [`crate::automata::guard`]. Propositions are matched by name when two automata or an automaton
//! and an arena meet.

use bit_set::BitSet;

use super::guard::{Guard, GuardUnion, MAX_PROPOSITIONS};
use crate::csr::Csr;

/// A DFA state. (Still a bare `u32`: see `crate::index` for the typed ids of the other models.)
pub type DfaState = u32;

/// A complete deterministic automaton over the valuations of its propositions (see the module
/// documentation): its propositions, initial state, final states, and edges in CSR form with one
/// guard per edge.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Dfa {
    aps: Vec<String>,
    initial: DfaState,
    finals: BitSet,
    /// Per state, the targets of its edges, with `guards` beside them.
    targets: Csr<DfaState, DfaState>,
    guards: Vec<Guard>,
}

/// Why a set of edges is not a complete DFA.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum DfaError {
    /// More propositions than [`MAX_PROPOSITIONS`]; the number given.
    #[error("{0} atomic propositions, more than the {MAX_PROPOSITIONS} an automaton may have")]
    TooManyPropositions(usize),
    /// A proposition named twice.
    #[error("atomic proposition `{0}` is listed twice")]
    DuplicateProposition(String),
    /// No states at all.
    #[error("the automaton has no states")]
    NoStates,
    /// The initial state, a final state or an edge's target (given) is not a state.
    #[error("state {0} does not exist")]
    NoSuchState(DfaState),
    /// A guard of the given state mentions a proposition whose index is not below the number
    /// declared (the second field).
    #[error("a guard of state {0} mentions a proposition beyond the {1} declared")]
    UnknownProposition(DfaState, usize),
    /// Two edges of a state have overlapping guards.
    #[error("state {state} is nondeterministic: its edges to {first} and {second} overlap")]
    Nondeterministic {
        /// The state.
        state: DfaState,
        /// The target of one of the two edges.
        first: DfaState,
        /// The target of the other.
        second: DfaState,
    },
    /// Some letters have no successor from the given state.
    #[error("state {0} is incomplete: some letters have no successor")]
    Incomplete(DfaState),
}

impl Dfa {
    /// Builds a DFA from its edges, `edges[q]` being the `(guard, target)` pairs of state `q`.
    /// Edges of one state to one target are merged; edges with unsatisfiable guards dropped.
    /// Checks determinism and completeness rather than trusting them.
    pub fn new(
        aps: Vec<String>,
        initial: DfaState,
        finals: BitSet,
        edges: Vec<Vec<(Guard, DfaState)>>,
    ) -> Result<Dfa, DfaError> {
        if aps.len() > MAX_PROPOSITIONS {
            return Err(DfaError::TooManyPropositions(aps.len()));
        }
        for (i, ap) in aps.iter().enumerate() {
            if aps[..i].contains(ap) {
                return Err(DfaError::DuplicateProposition(ap.clone()));
            }
        }
        let n = edges.len();
        if n == 0 {
            return Err(DfaError::NoStates);
        }
        let exists = |q: DfaState| (q as usize) < n;
        if !exists(initial) {
            return Err(DfaError::NoSuchState(initial));
        }
        if let Some(q) = finals.iter().find(|&q| q >= n) {
            return Err(DfaError::NoSuchState(q as DfaState));
        }
        let declared = if aps.len() == MAX_PROPOSITIONS {
            u64::MAX
        } else {
            (1u64 << aps.len()) - 1
        };
        let mut guards = Vec::new();
        let mut targets = Csr::with_capacity(n, n);
        // `merged_at[target] = (state + 1, index in merged)` when `state` has an edge to it.
        let mut merged_at: Vec<(u32, u32)> = vec![(0, 0); n];
        for (state, state_edges) in edges.into_iter().enumerate() {
            let state = state as DfaState;
            // Most states have one or two edges: valid, or complementary, guards need no
            // BDD manager (any other pair goes the general way, which finds the error).
            let trivially_fine = match state_edges.as_slice() {
                [(guard, target)] => guard.is_valid() && exists(*target),
                [(first, a), (second, b)] => {
                    a != b
                        && exists(*a)
                        && exists(*b)
                        && first.is_satisfiable()
                        && *first == second.not()
                }
                _ => false,
            };
            if trivially_fine
                && state_edges
                    .iter()
                    .all(|(g, _)| g.support() & !declared == 0)
            {
                for (guard, target) in state_edges {
                    guards.push(guard);
                    targets.push(target);
                }
                targets.finish_row();
                continue;
            }
            let mut merged: Vec<(Guard, DfaState)> = Vec::new();
            let mut union = GuardUnion::new();
            for (guard, target) in state_edges {
                if !exists(target) {
                    return Err(DfaError::NoSuchState(target));
                }
                if guard.support() & !declared != 0 {
                    return Err(DfaError::UnknownProposition(state, aps.len()));
                }
                if !guard.is_satisfiable() {
                    continue;
                }
                if !union.insert(&guard) {
                    // Only now look for the edge it overlaps.
                    let first = merged
                        .iter()
                        .find(|(other, _)| other.intersects(&guard))
                        .map_or(target, |&(_, other_target)| other_target);
                    return Err(DfaError::Nondeterministic {
                        state,
                        first,
                        second: target,
                    });
                }
                merge_edge(&mut merged, &mut merged_at, state, guard, target);
            }
            if !union.is_valid() {
                return Err(DfaError::Incomplete(state));
            }
            for (guard, target) in merged {
                guards.push(guard);
                targets.push(target);
            }
            targets.finish_row();
        }
        Ok(Dfa {
            aps,
            initial,
            finals,
            targets,
            guards,
        })
    }

    /// [`Dfa::new`] for edges known to be deterministic and complete (a construction that
    /// makes them so, such as the translation's BDD paths or a quotient of a DFA): edges of one
    /// state to one target are merged, but determinism and completeness are not checked again
    /// (in release builds), which for thousands of states with a dozen guards each is a union
    /// per edge, a noticeable uncounted pause after a translation's last counted step.
    pub(crate) fn from_disjoint(
        aps: Vec<String>,
        initial: DfaState,
        finals: BitSet,
        edges: Vec<Vec<(Guard, DfaState)>>,
    ) -> Dfa {
        debug_assert!(
            Dfa::new(aps.clone(), initial, finals.clone(), edges.clone()).is_ok(),
            "edges that are not deterministic and complete"
        );
        let n = edges.len();
        let mut guards = Vec::new();
        let mut targets = Csr::with_capacity(n, n);
        let mut merged_at: Vec<(u32, u32)> = vec![(0, 0); n];
        let mut merged: Vec<(Guard, DfaState)> = Vec::new();
        for (state, state_edges) in edges.into_iter().enumerate() {
            let state = state as DfaState;
            merged.clear();
            for (guard, target) in state_edges {
                if guard.is_satisfiable() {
                    merge_edge(&mut merged, &mut merged_at, state, guard, target);
                }
            }
            for (guard, target) in merged.drain(..) {
                guards.push(guard);
                targets.push(target);
            }
            targets.finish_row();
        }
        Dfa {
            aps,
            initial,
            finals,
            targets,
            guards,
        }
    }

    /// The number of states; states are `0..num_states()`.
    pub fn num_states(&self) -> usize {
        self.targets.num_rows()
    }

    /// The number of edges, at most one per (state, target).
    pub fn num_edges(&self) -> usize {
        self.targets.num_entries()
    }

    /// The initial state.
    pub fn initial(&self) -> DfaState {
        self.initial
    }

    /// Whether `state` is final (accepting).
    pub fn is_final(&self, state: DfaState) -> bool {
        self.finals.contains(state as usize)
    }

    /// The final states, as a set of state numbers.
    pub fn finals(&self) -> &BitSet {
        &self.finals
    }

    /// The atomic propositions; letters are valuations of these, bit `i` for `aps()[i]`.
    pub fn aps(&self) -> &[String] {
        &self.aps
    }

    /// The edges of `state`: pairwise-disjoint guards whose union is valid, one per target.
    pub fn edges(&self, state: DfaState) -> impl ExactSizeIterator<Item = (&Guard, DfaState)> {
        self.targets
            .row_with(state, &self.guards)
            .map(|(target, guard)| (guard, target))
    }

    /// The successor of `state` on `letter`.
    pub fn step(&self, state: DfaState, letter: u64) -> DfaState {
        self.edges(state)
            .find(|(guard, _)| guard.evaluate(letter))
            .map(|(_, target)| target)
            .expect("a complete DFA has a successor for every letter")
    }

    /// Whether the word (a sequence of letters over this automaton's propositions) leads from
    /// the initial state to a final state.
    pub fn accepts(&self, word: impl IntoIterator<Item = u64>) -> bool {
        let end = word
            .into_iter()
            .fold(self.initial, |state, letter| self.step(state, letter));
        self.is_final(end)
    }

    /// The letter, over this automaton's propositions, in which exactly the propositions named in
    /// `true_propositions` hold; names it does not know are ignored.
    pub fn letter<'a>(&self, true_propositions: impl IntoIterator<Item = &'a str>) -> u64 {
        true_propositions
            .into_iter()
            .filter_map(|name| self.aps.iter().position(|ap| ap == name))
            .fold(0, |letter, i| letter | (1u64 << i))
    }
}

/// Adds the edge `(guard, target)` of `state` to `merged`, the state's edges so far, or ors
/// `guard` into the edge it already has to `target`: `merged_at[target]` is `(state + 1,
/// index in merged)` once `state` has an edge to `target`.
fn merge_edge(
    merged: &mut Vec<(Guard, DfaState)>,
    merged_at: &mut [(u32, u32)],
    state: DfaState,
    guard: Guard,
    target: DfaState,
) {
    let (owner, index) = merged_at[target as usize];
    if owner == state + 1 {
        let existing = &mut merged[index as usize].0;
        *existing = existing.or(&guard);
    } else {
        merged_at[target as usize] = (state + 1, merged.len() as u32);
        merged.push((guard, target));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `a U b` over [a, b]: 0 initial, 1 final (absorbing), 2 rejecting sink.
    fn a_until_b() -> Dfa {
        let a = Guard::literal(0, true);
        let b = Guard::literal(1, true);
        let not_a_not_b = a.or(&b).not();
        let a_not_b = a.and(&b.not());
        Dfa::new(
            vec!["a".into(), "b".into()],
            0,
            [1].into_iter().collect(),
            vec![
                vec![(b.clone(), 1), (a_not_b, 0), (not_a_not_b, 2)],
                vec![(Guard::always(), 1)],
                vec![(Guard::always(), 2)],
            ],
        )
        .unwrap()
    }

    #[test]
    fn steps_follow_the_guards() {
        let dfa = a_until_b();
        assert_eq!(dfa.step(0, dfa.letter(["a"])), 0);
        assert_eq!(dfa.step(0, dfa.letter(["b"])), 1);
        assert_eq!(dfa.step(0, dfa.letter(["a", "b"])), 1);
        assert_eq!(dfa.step(0, dfa.letter([])), 2);
        assert_eq!(dfa.step(0, dfa.letter(["c"])), 2);
        assert!(dfa.is_final(1) && !dfa.is_final(0));
        assert_eq!(dfa.num_edges(), 5);
        let (a, b) = (dfa.letter(["a"]), dfa.letter(["b"]));
        assert!(dfa.accepts([a, a, b]));
        assert!(!dfa.accepts([a, a]));
        assert!(!dfa.accepts([0, b]));
        assert!(!dfa.accepts([]));
    }

    #[test]
    fn overlapping_or_missing_guards_are_rejected() {
        let a = Guard::literal(0, true);
        let aps = vec!["a".to_string()];
        assert_eq!(
            Dfa::new(
                aps.clone(),
                0,
                BitSet::new(),
                vec![vec![(a.clone(), 0), (Guard::always(), 1)], vec![]]
            ),
            Err(DfaError::Nondeterministic {
                state: 0,
                first: 0,
                second: 1
            })
        );
        assert_eq!(
            Dfa::new(aps.clone(), 0, BitSet::new(), vec![vec![(a.clone(), 0)]]),
            Err(DfaError::Incomplete(0))
        );
        assert_eq!(
            Dfa::new(
                aps,
                0,
                BitSet::new(),
                vec![vec![(Guard::literal(1, true), 0)]]
            ),
            Err(DfaError::UnknownProposition(0, 1))
        );
    }

    #[test]
    fn edges_to_one_target_are_merged() {
        let a = Guard::literal(0, true);
        let dfa = Dfa::new(
            vec!["a".into()],
            0,
            BitSet::new(),
            vec![vec![(a.clone(), 0), (a.not(), 0)]],
        )
        .unwrap();
        assert_eq!(dfa.num_edges(), 1);
        assert!(dfa.edges(0).next().unwrap().0.is_valid());
    }
}

//! From the edges read in a HOA body to the DFA of good prefixes: completion with a rejecting
//! sink, then the final states.
//!
//! A HOA automaton here is deterministic and (after completion) complete, and its acceptance is
//! `t`, `f` or Büchi, so an infinite run is accepting iff it takes accepting edges (edges of a
//! marked state, or marked edges) infinitely often. A state is final iff every edge reachable
//! from it, its own included, is accepting: from such a state every continuation is accepted,
//! so the prefix read so far is a good prefix. For a terminal automaton (the kind Spot writes
//! for co-safe formulas) these are exactly the states whose language is universal. A transient
//! state that Spot marks accepting is therefore not final when it can leave the accepting part
//! (the start state of `!b` is marked but can reach the rejecting sink). Under `t` every edge
//! read is accepting, so every state of a complete automaton is final; under `f` none is. The
//! sink added by completion rejects, under every acceptance condition.

use bit_set::BitSet;

use crate::automata::guard::GuardUnion;
use crate::automata::{Dfa, DfaError, DfaState, Guard};
use crate::csr::Csr;

/// One edge as read: a satisfiable guard, a target, and whether it is accepting.
pub(super) struct Edge {
    pub guard: Guard,
    pub target: DfaState,
    pub accepting: bool,
}

/// A deterministic automaton as read from the body.
pub(super) struct Declared {
    pub aps: Vec<String>,
    pub initial: DfaState,
    pub num_states: u32,
    /// The edges of each state, by state number; states beyond the end have none.
    pub edges: Vec<Vec<Edge>>,
}

/// The DFA of good prefixes of `declared`, and the rejecting sink if one had to be added (it is
/// the last state).
pub(super) fn to_dfa(declared: Declared) -> Result<(Dfa, Option<DfaState>), DfaError> {
    let n = declared.num_states;
    let mut edges = declared.edges;
    edges.resize_with(n as usize, Vec::new);
    let mut sink = None;
    for out in &mut edges {
        let mut covered = GuardUnion::new();
        for edge in out.iter() {
            covered.insert(&edge.guard);
        }
        let missing = covered.union().not();
        if missing.is_satisfiable() {
            out.push(Edge {
                guard: missing,
                target: *sink.get_or_insert(n),
                accepting: false,
            });
        }
    }
    if let Some(sink) = sink {
        edges.push(vec![Edge {
            guard: Guard::always(),
            target: sink,
            accepting: false,
        }]);
    }
    let finals = good_prefix_finals(&edges);
    let edges = edges
        .into_iter()
        .map(|out| out.into_iter().map(|e| (e.guard, e.target)).collect())
        .collect();
    let dfa = Dfa::new(declared.aps, declared.initial, finals, edges)?;
    Ok((dfa, sink))
}

/// The states from which no non-accepting edge is reachable. Every state has an edge (the
/// automaton is complete), so these are the states all of whose reachable edges are accepting.
/// Linear: a backward search from the states with a non-accepting edge, over predecessor lists
/// in CSR form.
fn good_prefix_finals(edges: &[Vec<Edge>]) -> BitSet {
    let n = edges.len();
    let sources: Csr<DfaState, DfaState> = Csr::group(
        n,
        edges
            .iter()
            .enumerate()
            .flat_map(|(q, out)| out.iter().map(move |edge| (edge.target, q as DfaState))),
    );
    let mut rejecting = BitSet::with_capacity(n);
    let mut stack: Vec<u32> = Vec::new();
    for (q, out) in edges.iter().enumerate() {
        if out.iter().any(|edge| !edge.accepting) {
            rejecting.insert(q);
            stack.push(q as u32);
        }
    }
    while let Some(q) = stack.pop() {
        for &p in sources.row(q) {
            if rejecting.insert(p as usize) {
                stack.push(p);
            }
        }
    }
    (0..n).filter(|&q| !rejecting.contains(q)).collect()
}

//! The HOA writer: a DFA of good prefixes written as Spot writes a terminal automaton.
//!
//! State-based Büchi acceptance (`Acceptance: 1 Inf(0)`) with the final states marked `{0}`,
//! explicit labels in HOA syntax (`!0&1 | 2`, `t` for a valid guard), states and edges in the
//! DFA's order: the output depends only on the DFA, and reading it back gives the same DFA (same
//! state numbers, same edges, equivalent guards). Infinite-word semantics agree with the DFA's
//! only when the final states are closed under successors (a good-prefix DFA's final states
//! are: once accepted, always accepted); otherwise the writer refuses, rather than write an
//! automaton with another language.

use std::fmt::Write as _;

use crate::automata::guard::quoted;
use crate::automata::{Dfa, DfaState, GuardStyle};

/// Why a DFA cannot be written as a terminal Büchi automaton.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum WriteError {
    /// A final state has a non-final successor, so the final states are not closed under
    /// successors.
    #[error(
        "final state {state} has the non-final successor {successor}: the DFA does not \
         describe good prefixes, and HOA's Büchi reading would change its language"
    )]
    FinalNotClosed {
        /// The final state.
        state: DfaState,
        /// Its non-final successor.
        successor: DfaState,
    },
}

/// The HOA text of `dfa`, with `name:` when `name` is given.
pub fn write(dfa: &Dfa, name: Option<&str>) -> Result<String, WriteError> {
    let states = dfa.num_states() as DfaState;
    for state in (0..states).filter(|&q| dfa.is_final(q)) {
        if let Some((_, successor)) = dfa.edges(state).find(|&(_, t)| !dfa.is_final(t)) {
            return Err(WriteError::FinalNotClosed { state, successor });
        }
    }
    let mut out = String::from("HOA: v1\n");
    // Writing to a String cannot fail.
    if let Some(name) = name {
        let _ = writeln!(out, "name: {}", quoted(name));
    }
    let _ = writeln!(out, "States: {states}");
    let _ = writeln!(out, "Start: {}", dfa.initial());
    let _ = write!(out, "AP: {}", dfa.aps().len());
    for ap in dfa.aps() {
        let _ = write!(out, " {}", quoted(ap));
    }
    out.push_str(concat!(
        "\nacc-name: Buchi\n",
        "Acceptance: 1 Inf(0)\n",
        "properties: trans-labels explicit-labels state-acc complete\n",
        "properties: deterministic terminal\n",
        "--BODY--\n",
    ));
    for state in 0..states {
        let mark = if dfa.is_final(state) { " {0}" } else { "" };
        let _ = writeln!(out, "State: {state}{mark}");
        for (guard, target) in dfa.edges(state) {
            let _ = writeln!(out, "[{}] {target}", guard.display(GuardStyle::Hoa));
        }
    }
    out.push_str("--END--\n");
    Ok(out)
}

//! The HOA writer: a DFA of good prefixes written as Spot writes a terminal automaton.
//!
//! State-based Büchi acceptance (`Acceptance: 1 Inf(0)`) with the final states marked `{0}`,
//! explicit labels in HOA syntax (`!0&1 | 2`, `t` for a valid guard), states and edges in the
//! DFA's order: the output depends only on the DFA, and reading it back gives the same DFA (same
//! state numbers, same edges, equivalent guards). Infinite-word semantics agree with the DFA's
//! only when the final states are closed under successors (a good-prefix DFA's final states
//! are: once accepted, always accepted); otherwise the writer refuses, rather than write an
//! automaton with another language.
//!
//! A label is an irredundant sum of products when that has at most [`MAX_LABEL_CUBES`] cubes;
//! a larger guard is written through aliases, one per node of its BDD
//! (`Alias: @a5 0&@a3 | !0&@a4`), defined once per distinct guard: the parity of 20
//! propositions has 2^19 cubes but 39 nodes. The text is therefore linear in the size of the
//! automaton and its guards' diagrams, whatever the guards.

use std::collections::HashMap;
use std::fmt::Write as _;

use crate::automata::guard::{Branch, quoted, write_cubes};
use crate::automata::{Dfa, DfaState, Guard, GuardStyle};

/// The most cubes a label is written with; a guard with more is written through aliases.
pub const MAX_LABEL_CUBES: usize = 64;

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
    ));
    let mut aliases = Aliases::default();
    let mut body = String::new();
    for state in 0..states {
        let mark = if dfa.is_final(state) { " {0}" } else { "" };
        let _ = writeln!(body, "State: {state}{mark}");
        for (guard, target) in dfa.edges(state) {
            body.push('[');
            write_label(&mut body, guard, &mut aliases);
            let _ = writeln!(body, "] {target}");
        }
    }
    out.push_str(&aliases.definitions);
    out.push_str("--BODY--\n");
    out.push_str(&body);
    out.push_str("--END--\n");
    Ok(out)
}

/// The aliases defined so far: their header lines, and the alias of each guard's root.
#[derive(Default)]
struct Aliases<'a> {
    definitions: String,
    count: usize,
    roots: HashMap<&'a Guard, usize>,
}

/// Writes the label of `guard`: its cubes, or the alias of its root (defined first if new).
fn write_label<'a>(out: &mut String, guard: &'a Guard, aliases: &mut Aliases<'a>) {
    if !guard.is_satisfiable() || guard.is_valid() {
        let _ = write!(out, "{}", guard.display(GuardStyle::Hoa));
        return;
    }
    if let Some(root) = aliases.roots.get(guard) {
        let _ = write!(out, "@a{root}");
        return;
    }
    if let Some(cubes) = guard.cubes_at_most(MAX_LABEL_CUBES) {
        let _ = write_cubes(out, &cubes, GuardStyle::Hoa);
        return;
    }
    // One alias per node: `var & high | !var & low`, constants folded.
    let first = aliases.count;
    let branch = |branch: Branch| match branch {
        Branch::Constant(value) => Err(value),
        Branch::Node(i) => Ok(format!("@a{}", first + i)),
    };
    for (var, low, high) in guard.node_definitions() {
        let definition = match (branch(low), branch(high)) {
            (Err(false), Err(true)) => format!("{var}"),
            (Err(true), Err(false)) => format!("!{var}"),
            (Err(false), Ok(high)) => format!("{var}&{high}"),
            (Ok(low), Err(false)) => format!("!{var}&{low}"),
            (Err(true), Ok(high)) => format!("!{var} | {high}"),
            (Ok(low), Err(true)) => format!("{var} | {low}"),
            (Ok(low), Ok(high)) => format!("{var}&{high} | !{var}&{low}"),
            (Err(_), Err(_)) => unreachable!("a node's branches differ"),
        };
        let _ = writeln!(
            aliases.definitions,
            "Alias: @a{} {definition}",
            aliases.count
        );
        aliases.count += 1;
    }
    let root = aliases.count - 1;
    aliases.roots.insert(guard, root);
    let _ = write!(out, "@a{root}");
}

//! DOT (Graphviz) text of a DFA: states by number, final states as double circles, an arrow
//! from an invisible point into the initial state, edges labelled by their guards written with
//! proposition names (`!a & b | c`, `true`). The output depends only on the DFA.
//!
//! A label is a sum of products, which can be exponential in the guard's diagram (the parity
//! of 20 propositions has 2^19 cubes); DOT has no way to name shared parts, so a graph whose
//! labels would have more than [`MAX_DOT_CUBES`] cubes in all is refused ([`LabelsTooLarge`]),
//! found without listing more.

use std::fmt::Write as _;

use super::guard::{quoted, write_cubes};
use super::{Dfa, DfaState, GuardStyle};

/// The most cubes the labels of one DOT graph have in all (a few megabytes of text).
pub const MAX_DOT_CUBES: usize = 1 << 16;

/// Why a DFA was not drawn: its labels would have more than [`MAX_DOT_CUBES`] cubes.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "the labels of the automaton would have more than {MAX_DOT_CUBES} cubes (reached at the edge \
     from state {state} to state {target}): DOT labels are sums of products; HOA names the \
     shared parts of large labels"
)]
pub struct LabelsTooLarge {
    /// The edge's source.
    pub state: DfaState,
    /// The edge's target.
    pub target: DfaState,
}

/// The DOT text of `dfa`; `name`, if given, names the graph and is shown as its title.
pub fn to_dot(dfa: &Dfa, name: Option<&str>) -> Result<String, LabelsTooLarge> {
    let mut out = String::new();
    // Writing to a String cannot fail.
    let _ = writeln!(out, "digraph {} {{", quoted(name.unwrap_or("dfa")));
    if let Some(name) = name {
        let _ = writeln!(out, "  label={};\n  labelloc=t;", quoted(name));
    }
    out.push_str("  rankdir=LR;\n  node [shape=circle];\n");
    let _ = writeln!(out, "  start [shape=point, label=\"\"];");
    let _ = writeln!(out, "  start -> {};", dfa.initial());
    for state in 0..dfa.num_states() as DfaState {
        if dfa.is_final(state) {
            let _ = writeln!(out, "  {state} [shape=doublecircle];");
        }
    }
    let style = GuardStyle::Names(dfa.aps());
    let mut cubes_left = MAX_DOT_CUBES;
    for state in 0..dfa.num_states() as DfaState {
        for (guard, target) in dfa.edges(state) {
            let label = if !guard.is_satisfiable() || guard.is_valid() {
                guard.display(style).to_string()
            } else {
                let cubes = guard
                    .cubes_at_most(cubes_left)
                    .ok_or(LabelsTooLarge { state, target })?;
                cubes_left -= cubes.len();
                let mut label = String::new();
                let _ = write_cubes(&mut label, &cubes, style);
                label
            };
            let _ = writeln!(out, "  {state} -> {target} [label={}];", quoted(&label));
        }
    }
    out.push_str("}\n");
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::automata::Guard;

    #[test]
    fn dot_shows_names_finals_and_the_initial_arrow() {
        // `"x y" U b`: quoted names end up escaped inside the DOT label.
        let x = Guard::literal(0, true);
        let b = Guard::literal(1, true);
        let dfa = Dfa::new(
            vec!["x y".into(), "b".into()],
            0,
            [1].into_iter().collect(),
            vec![
                vec![(b.clone(), 1), (x.and(&b.not()), 0), (x.or(&b).not(), 2)],
                vec![(Guard::always(), 1)],
                vec![(Guard::always(), 2)],
            ],
        )
        .unwrap();
        assert_eq!(
            to_dot(&dfa, Some("\"x y\" U b")).unwrap(),
            r#"digraph "\"x y\" U b" {
  label="\"x y\" U b";
  labelloc=t;
  rankdir=LR;
  node [shape=circle];
  start [shape=point, label=""];
  start -> 0;
  1 [shape=doublecircle];
  0 -> 1 [label="b"];
  0 -> 0 [label="\"x y\" & !b"];
  0 -> 2 [label="!\"x y\" & !b"];
  1 -> 1 [label="true"];
  2 -> 2 [label="true"];
}
"#
        );
    }
}

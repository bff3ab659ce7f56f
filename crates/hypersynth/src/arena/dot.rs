//! DOT (Graphviz) text of a small arena: robot states as ellipses, adversary states as boxes,
//! each with its name and label (`{A, B}`), edges named by their actions, an arrow from an
//! invisible point into the initial state. States and edges in arena order, so the output
//! depends only on the arena.
//!
//! Graphviz lays out a few hundred nodes legibly, not thousands: arenas above the limit are
//! refused rather than drawn into an unreadable (and slow) picture. Cost: linear in the arena.

use std::fmt::Write as _;

use super::model::{Arena, Owner};
use crate::automata::guard::quoted;

/// The most states [`to_dot`] draws unless told otherwise.
pub const MAX_DOT_STATES: usize = 200;

/// Why [`to_dot`] refused an arena: it has more states than the limit.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "the arena has {states} states: DOT output is limited to {limit}, beyond which Graphviz's \
     layouts are unreadable (a gridworld is better drawn with --svg from its map)"
)]
pub struct TooLarge {
    /// The number of states of the arena.
    pub states: usize,
    /// The most states the caller allowed.
    pub limit: usize,
}

/// The DOT text of `arena`, refused when it has more than `limit` states.
pub fn to_dot(arena: &Arena, limit: usize) -> Result<String, TooLarge> {
    let states = arena.num_states();
    if states > limit {
        return Err(TooLarge { states, limit });
    }
    let mut out = String::from("digraph arena {\n  node [fontname=\"Helvetica\"];\n");
    // Writing to a String cannot fail.
    let _ = writeln!(out, "  start [shape=point, label=\"\"];");
    let _ = writeln!(out, "  start -> s{};", arena.initial());
    for state in arena.states() {
        let shape = match arena.owner(state) {
            Owner::Robot => "ellipse",
            Owner::Adversary => "box",
        };
        let propositions: Vec<&str> = arena
            .label(state)
            .iter()
            .map(|p| arena.propositions()[p].as_str())
            .collect();
        // Name and label on two lines: `\n` is DOT's line break inside a label.
        let mut label = quoted(arena.name(state));
        label.pop();
        label.push_str("\\n");
        label.push_str(&quoted(&format!("{{{}}}", propositions.join(", ")))[1..]);
        let _ = writeln!(out, "  s{state} [shape={shape}, label={label}];");
    }
    for state in arena.states() {
        for (action, target) in arena.edges(state) {
            let action = quoted(arena.action_name(action));
            let _ = writeln!(out, "  s{state} -> s{target} [label={action}];");
        }
    }
    out.push_str("}\n");
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::arena::ArenaBuilder;

    fn arena() -> Arena {
        let mut b = ArenaBuilder::new();
        let r = b
            .add_state("r \"1\"", Owner::Robot, ["A", "B"], None)
            .unwrap();
        let a = b.add_state("a", Owner::Adversary, [], None).unwrap();
        b.add_transition(r, "go", a).unwrap();
        b.add_transition(a, "back", r).unwrap();
        b.add_transition(a, "stay", a).unwrap();
        b.set_initial(a);
        b.build().unwrap()
    }

    #[test]
    fn owners_are_shapes_with_names_labels_and_the_initial_arrow() {
        assert_eq!(
            to_dot(&arena(), 2).unwrap(),
            "digraph arena {\n  node [fontname=\"Helvetica\"];\n  start [shape=point, label=\"\"];\n  \
             start -> s1;\n  s0 [shape=ellipse, label=\"r \\\"1\\\"\\n{A, B}\"];\n  \
             s1 [shape=box, label=\"a\\n{}\"];\n  s0 -> s1 [label=\"go\"];\n  \
             s1 -> s0 [label=\"back\"];\n  s1 -> s1 [label=\"stay\"];\n}\n"
        );
    }

    #[test]
    fn arenas_above_the_limit_are_refused() {
        assert_eq!(
            to_dot(&arena(), 1),
            Err(TooLarge {
                states: 2,
                limit: 1
            })
        );
    }
}

//! The writer of the arena format: [`Arena`] → text, in canonical form.
//!
//! Canonical form: a header comment, the `propositions` and `actions` lines (always present, in
//! id order, so that reading the text back interns them in the same order), the `initial` line,
//! then each state in id order followed by its edges in CSR order. Names are bare exactly when
//! they are identifiers; labels list propositions in id order; display names are always quoted.
//! Hence `parse(write(a)) == a` for every arena, and `write(parse(t))` is the canonical form of
//! any readable text `t`.

use super::model::Arena;
use super::syntax::{owner_keyword, write_name, write_quoted};

/// The first line of every written arena.
pub const HEADER: &str = "# hypersynth arena v1";

/// Writes `arena` in canonical form.
pub fn write(arena: &Arena) -> String {
    write_with_comment(arena, "")
}

/// Writes `arena` in canonical form, with each line of `comment` as a comment after the header.
pub fn write_with_comment(arena: &Arena, comment: &str) -> String {
    // About 40 bytes per edge line and 60 per state line; a guess that saves most reallocations.
    let mut out = String::with_capacity(40 * arena.num_transitions() + 60 * arena.num_states());
    out.push_str(HEADER);
    out.push('\n');
    for line in comment.lines() {
        out.push_str("# ");
        out.push_str(line);
        out.push('\n');
    }
    // Writing into a String cannot fail: the fmt::Results below are always Ok.
    let _ = write_arena(&mut out, arena);
    out
}

fn write_arena(out: &mut String, arena: &Arena) -> std::fmt::Result {
    out.push_str("propositions");
    for proposition in arena.propositions() {
        out.push(' ');
        write_name(out, proposition)?;
    }
    out.push_str("\nactions");
    for action in arena.actions() {
        out.push(' ');
        write_name(out, action)?;
    }
    out.push_str("\ninitial ");
    write_name(out, arena.name(arena.initial()))?;
    out.push('\n');
    for state in arena.states() {
        out.push_str("state ");
        write_name(out, arena.name(state))?;
        out.push(' ');
        out.push_str(owner_keyword(arena.owner(state)));
        out.push_str(" {");
        for (i, proposition) in arena.label(state).iter().enumerate() {
            if i > 0 {
                out.push(' ');
            }
            write_name(out, &arena.propositions()[proposition])?;
        }
        out.push('}');
        if let Some(display) = arena.display(state) {
            out.push(' ');
            // Always quoted, so that a display name reads as text and not as a field.
            write_quoted(out, display)?;
        }
        out.push('\n');
        for (action, target) in arena.edges(state) {
            out.push_str("edge ");
            write_name(out, arena.name(state))?;
            out.push(' ');
            write_name(out, arena.action_name(action))?;
            out.push(' ');
            write_name(out, arena.name(target))?;
            out.push('\n');
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;
    use crate::arena::{ArenaBuilder, Owner, StateId, parse};

    #[test]
    fn writes_the_canonical_form() {
        let mut b = ArenaBuilder::new();
        b.proposition("O");
        let s = b.add_state("s", Owner::Robot, ["A", "O"], None).unwrap();
        let t = b
            .add_state("t 1", Owner::Adversary, [], Some("T".into()))
            .unwrap();
        b.add_transition(t, "back", s).unwrap();
        b.add_transition(s, "go", t).unwrap();
        b.add_transition(s, "back", s).unwrap();
        b.set_initial(t);
        let arena = b.build().unwrap();
        assert_eq!(
            write_with_comment(&arena, "made by hand\nfor a test"),
            "# hypersynth arena v1\n\
             # made by hand\n\
             # for a test\n\
             propositions O A\n\
             actions back go\n\
             initial \"t 1\"\n\
             state s robot {O A}\n\
             edge s go \"t 1\"\n\
             edge s back s\n\
             state \"t 1\" adversary {} \"T\"\n\
             edge \"t 1\" back s\n"
        );
    }

    /// Names with every kind of character the format must quote or escape.
    fn name() -> impl Strategy<Value = String> {
        prop_oneof![
            "[a-zA-Z0-9_.-]{1,6}",
            "[ a-z\"\\\\\n\r\t#{}é(),]{0,6}",
            any::<String>(),
        ]
    }

    /// A random arena: states, propositions and actions with arbitrary names, random labels,
    /// displays and transitions added in random order (so action ids follow first use, not the
    /// order in which the writer lists edges), some propositions and actions possibly unused.
    fn arena() -> impl Strategy<Value = Arena> {
        (
            proptest::collection::hash_set(name(), 1..10),
            proptest::collection::hash_set(name(), 0..5),
            proptest::collection::hash_set(name(), 1..5),
            any::<bool>(),
        )
            .prop_flat_map(|(states, propositions, actions, declare_first)| {
                let (n, p, a) = (states.len(), propositions.len(), actions.len());
                let state = (
                    any::<bool>(),
                    proptest::collection::vec(any::<bool>(), p),
                    proptest::option::of(name()),
                );
                (
                    Just(states.into_iter().collect::<Vec<_>>()),
                    Just(propositions.into_iter().collect::<Vec<_>>()),
                    Just(actions.into_iter().collect::<Vec<_>>()),
                    Just(declare_first),
                    proptest::collection::vec(state, n),
                    proptest::collection::vec((0..n, 0..a, 0..n), 0..3 * n),
                    0..n,
                )
            })
            .prop_map(
                |(names, propositions, actions, declare_first, states, edges, initial)| {
                    let mut b = ArenaBuilder::new();
                    if declare_first {
                        for p in &propositions {
                            b.proposition(p);
                        }
                        for a in &actions {
                            b.action(a);
                        }
                    }
                    for (name, (robot, label, display)) in names.iter().zip(states) {
                        let owner = if robot {
                            Owner::Robot
                        } else {
                            Owner::Adversary
                        };
                        let label = propositions
                            .iter()
                            .zip(&label)
                            .filter(|&(_, &on)| on)
                            .map(|(p, _)| p.as_str());
                        b.add_state(name, owner, label, display).unwrap();
                    }
                    for (from, action, to) in edges {
                        // A repeated (state, action) is refused and simply skipped.
                        let _ = b.add_transition(
                            StateId::new(from),
                            &actions[action],
                            StateId::new(to),
                        );
                    }
                    b.set_initial(StateId::new(initial));
                    b.build().unwrap()
                },
            )
    }

    /// An independent, deliberately different spelling of an arena: every name quoted, odd
    /// spacing, comments, edges of later states first, `initial` last.
    fn unusual_text(arena: &Arena) -> String {
        let q = |s: &str| {
            let mut out = String::from("\"");
            for c in s.chars() {
                match c {
                    '\\' => out.push_str("\\\\"),
                    '"' => out.push_str("\\\""),
                    '\n' => out.push_str("\\n"),
                    '\r' => out.push_str("\\r"),
                    c => out.push(c),
                }
            }
            out + "\""
        };
        let join = |names: &[String]| names.iter().map(|n| q(n)).collect::<Vec<_>>().join("\t ");
        let mut text = format!(
            "\n  actions\t{}  # the actions\r\n# the propositions:\npropositions {}\n\n",
            join(arena.actions()),
            join(arena.propositions())
        );
        let states = arena.states();
        for s in states.clone().rev() {
            for (a, t) in arena.edges(s) {
                let (from, action, to) = (arena.name(s), arena.action_name(a), arena.name(t));
                text += &format!("edge   {}\t{} {}#\n", q(from), q(action), q(to));
            }
        }
        for s in states {
            let owner = match arena.owner(s) {
                Owner::Robot => "robot",
                Owner::Adversary => "adversary",
            };
            let label: Vec<String> = arena
                .label(s)
                .iter()
                .map(|p| q(&arena.propositions()[p]))
                .collect();
            let display = arena.display(s).map(&q).unwrap_or_default();
            text += &format!(
                "state {} {owner}{{{}}} {display}\n",
                q(arena.name(s)),
                label.join(" ")
            );
        }
        text + &format!("initial {}", q(arena.name(arena.initial())))
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(128))]

        #[test]
        fn reading_what_was_written_gives_the_same_arena(arena in arena()) {
            let text = write(&arena);
            let read = parse(&text).map_err(|e| TestCaseError::fail(format!("{e}\n{text}")))?;
            prop_assert_eq!(&read.arena, &arena);
            prop_assert_eq!(write(&read.arena), text);
        }

        #[test]
        fn writing_what_was_read_gives_the_canonical_form(arena in arena()) {
            let text = unusual_text(&arena);
            let read = parse(&text).map_err(|e| TestCaseError::fail(format!("{e}\n{text}")))?;
            prop_assert_eq!(&read.arena, &arena);
            prop_assert_eq!(write(&read.arena), write(&arena));
        }
    }
}

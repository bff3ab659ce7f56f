//! The HOA writer's output for a few DFAs, pinned by hand-checked files in snapshots/,
//! and read back unchanged.

use hypersynth::automata::hoa::{self, WriteError};
use hypersynth::automata::{Dfa, DfaState, Guard};

fn snapshot(name: &str) -> String {
    let path = format!(
        "{}/tests/automata/hoa/snapshots/{name}",
        env!("CARGO_MANIFEST_DIR")
    );
    std::fs::read_to_string(path).unwrap()
}

/// The DFA accepting the words whose first letter satisfies `guard`: 0 initial, 1 final
/// (absorbing), 2 rejecting sink.
fn first_letter(aps: &[&str], guard: Guard) -> Dfa {
    Dfa::new(
        aps.iter().map(|s| s.to_string()).collect(),
        0,
        [1].into_iter().collect(),
        vec![
            vec![(guard.clone(), 1), (guard.not(), 2)],
            vec![(Guard::always(), 1)],
            vec![(Guard::always(), 2)],
        ],
    )
    .unwrap()
}

#[track_caller]
fn assert_written(dfa: &Dfa, name: Option<&str>, file: &str) {
    let text = hoa::write(dfa, name).unwrap();
    assert_eq!(text, snapshot(file));
    // Reading back gives the same DFA (guards are canonical BDDs: equal functions are equal),
    // with the same name.
    let again = hoa::parse(&text).unwrap();
    assert_eq!(again[0].dfa, *dfa);
    assert_eq!(again[0].name.as_deref(), name);
}

#[test]
fn a_until_b() {
    let a = Guard::literal(0, true);
    let b = Guard::literal(1, true);
    let dfa = Dfa::new(
        vec!["a".into(), "b".into()],
        0,
        [1].into_iter().collect(),
        vec![
            vec![(b.clone(), 1), (a.and(&b.not()), 0), (a.or(&b).not(), 2)],
            vec![(Guard::always(), 1)],
            vec![(Guard::always(), 2)],
        ],
    )
    .unwrap();
    assert_written(&dfa, Some("a U b"), "a_until_b.hoa");
}

#[test]
fn spot_transient_mark_is_dropped() {
    // Spot's `!b` marks its start state 1; the DFA (and so the output) does not.
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../tests/fixtures/spot/hoa/0004.hoa"
    ))
    .unwrap();
    let automaton = hoa::parse(&text).unwrap().pop().unwrap();
    assert_written(&automaton.dfa, Some("!b"), "not_b.hoa");
}

#[test]
fn universal_without_propositions_or_name() {
    let dfa = Dfa::new(
        Vec::new(),
        0,
        [0].into_iter().collect(),
        vec![vec![(Guard::always(), 0)]],
    )
    .unwrap();
    assert_written(&dfa, None, "universal.hoa");
}

#[test]
fn names_are_escaped_and_guards_have_several_cubes() {
    // First letter satisfies (!"x y" & "q\"") | c.
    let guard = Guard::literal(0, false)
        .and(&Guard::literal(1, true))
        .or(&Guard::literal(2, true));
    let dfa = first_letter(&["x y", "q\"", "c"], guard);
    assert_written(&dfa, Some("first \"letter\""), "quoted_names.hoa");
}

#[test]
fn a_final_state_with_a_non_final_successor_is_refused() {
    // Final 1 steps to non-final 2: not a good-prefix DFA.
    let dfa = Dfa::new(
        vec!["a".into()],
        0,
        [1].into_iter().collect(),
        vec![
            vec![(Guard::always(), 1)],
            vec![(Guard::literal(0, true), 1), (Guard::literal(0, false), 2)],
            vec![(Guard::always(), 2 as DfaState)],
        ],
    )
    .unwrap();
    assert_eq!(
        hoa::write(&dfa, None),
        Err(WriteError::FinalNotClosed {
            state: 1,
            successor: 2
        })
    );
}

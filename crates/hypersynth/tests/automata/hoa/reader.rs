//! What the HOA reader accepts, on hand-written automata whose DFAs are worked out by hand.

use hypersynth::automata::Dfa;
use hypersynth::automata::hoa::{self, HoaAutomaton};

fn read_one(text: &str) -> HoaAutomaton {
    let mut automata = hoa::parse(text).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(automata.len(), 1);
    automata.pop().unwrap()
}

fn finals(dfa: &Dfa) -> Vec<usize> {
    dfa.finals().iter().collect()
}

/// The state reached from the initial state on the letters (each a list of true propositions).
fn run(dfa: &Dfa, word: &[&[&str]]) -> u32 {
    word.iter().fold(dfa.initial(), |q, letter| {
        dfa.step(q, dfa.letter(letter.iter().copied()))
    })
}

#[test]
fn aliases_comments_and_ignored_headers() {
    let automaton = read_one(
        r#"HOA: v1.1 /* Spot's -H1.1 version */
tool: "by hand" "1.0"
name: "a U b"
States: 3
Start: 0
AP: 2 "a" "b"
Alias: @a 0
Alias: @b /* comments /* nest */ anywhere */ 1
Alias: @ab @a & !@b
acc-name: Buchi
Acceptance: 1 (Inf(0))
properties: trans-labels explicit-labels !complete
x-custom: 1 "two" three t
--BODY--
State: 0 "start"
[@b] 1
[@ab] 0
[!@a & !@b] 2
State: 1 {0}
[t] 1
State: 2
[t] 2
--END--"#,
    );
    assert_eq!(automaton.name.as_deref(), Some("a U b"));
    let dfa = &automaton.dfa;
    assert_eq!(dfa.aps(), ["a", "b"]);
    assert_eq!(finals(dfa), vec![1]);
    assert_eq!(run(dfa, &[&["a"], &["a"]]), 0);
    assert_eq!(run(dfa, &[&["a"], &["b"]]), 1);
    assert_eq!(run(dfa, &[&["a"], &[]]), 2);
    assert_eq!(automaton.sink, None);
}

#[test]
fn implicit_labels_follow_the_bits_of_the_edge_index() {
    // Edge i is the valuation with a = bit 0 and b = bit 1 of i: !a&!b, a&!b, !a&b, a&b.
    let dfa = read_one(
        r#"HOA: v1 States: 4 Start: 0 AP: 2 "a" "b" Acceptance: 1 Inf(0) --BODY--
State: 0 3 0 1 2
State: 1 {0} 1 1 1 1
State: 2 {0} 2 2 2 2
State: 3 3 3 3 3
--END--"#,
    )
    .dfa;
    assert_eq!(run(&dfa, &[&[]]), 3);
    assert_eq!(run(&dfa, &[&["a"]]), 0);
    assert_eq!(run(&dfa, &[&["b"]]), 1);
    assert_eq!(run(&dfa, &[&["a", "b"]]), 2);
    assert_eq!(finals(&dfa), vec![1, 2]);
}

#[test]
fn state_labels_apply_to_every_edge_and_incomplete_states_go_to_a_sink() {
    // From 0, letters with !a go to 1; letters with a have no edge.
    let automaton = read_one(
        r#"HOA: v1 States: 2 Start: 0 AP: 1 "a" Acceptance: 1 Inf(0) --BODY--
State: [!0] 0
1
State: 1 {0}
[t] 1
--END--"#,
    );
    let dfa = &automaton.dfa;
    assert_eq!(automaton.declared_states, 2);
    assert_eq!(automaton.sink, Some(2));
    assert_eq!(dfa.num_states(), 3);
    assert_eq!(run(dfa, &[&[]]), 1);
    assert_eq!(run(dfa, &[&["a"]]), 2);
    assert_eq!(run(dfa, &[&["a"], &[]]), 2);
    assert_eq!(finals(dfa), vec![1]);
}

#[test]
fn transition_based_marks_need_every_reachable_edge_accepting() {
    // State 0's edges are all marked but one leads to the unmarked loop of state 2; state 1's
    // only edge is a marked self-loop. Only 1 is final.
    let dfa = read_one(
        r#"HOA: v1 States: 3 Start: 0 AP: 1 "a" Acceptance: 1 Inf(0) --BODY--
State: 0
[0] 1 {0}
[!0] 2 {0}
State: 1
[t] 1 {0}
State: 2
[t] 2
--END--"#,
    )
    .dfa;
    assert_eq!(finals(&dfa), vec![1]);
    // The same with the mark on state 1 instead of its edge.
    let text = "HOA: v1 States: 2 Start: 0 AP: 1 \"a\" Acceptance: 1 Inf(0) --BODY-- \
                State: 0 [0] 1 [!0] 0 State: 1 {0} [t] 1 --END--";
    assert_eq!(finals(&read_one(text).dfa), vec![1]);
}

#[test]
fn trivial_acceptance_conditions() {
    // `t`: every run of a complete automaton is accepting, so every state is final.
    let all = "HOA: v1 States: 2 Start: 0 AP: 1 \"a\" Acceptance: 0 t --BODY-- \
               State: 0 [0] 1 [!0] 0 State: 1 [t] 0 --END--";
    assert_eq!(finals(&read_one(all).dfa), vec![0, 1]);
    // `t` on an incomplete automaton: the sink rejects, and so does every state reaching it.
    let safety = "HOA: v1 States: 2 Start: 0 AP: 1 \"a\" Acceptance: 0 t --BODY-- \
                  State: 0 [0] 0 [!0] 1 State: 1 [0] 1 --END--";
    let automaton = read_one(safety);
    assert_eq!(automaton.sink, Some(2));
    assert_eq!(finals(&automaton.dfa), Vec::<usize>::new());
    // `f`: nothing is accepted.
    let none = all.replace("0 t", "0 f");
    assert_eq!(finals(&read_one(&none).dfa), Vec::<usize>::new());
    // Büchi on the second of two sets: marks of set 0 do not count.
    let second = "HOA: v1 States: 2 Start: 0 AP: 1 \"a\" Acceptance: 2 Inf(1) --BODY-- \
                  State: 0 {0} [0] 1 [!0] 0 State: 1 {1} [t] 1 --END--";
    assert_eq!(finals(&read_one(second).dfa), vec![1]);
}

#[test]
fn false_edges_are_dropped_and_not_counted() {
    let automaton = read_one(
        "HOA: v1 States: 2 Start: 0 AP: 1 \"a\" Acceptance: 1 Inf(0) --BODY-- \
         State: 0 [f] 1 [0 & !0] 1 [t] 0 State: 1 {0} [t] 1 --END--",
    );
    assert_eq!(automaton.declared_edges, 2);
    assert_eq!(automaton.dfa.num_edges(), 2);
    assert_eq!(run(&automaton.dfa, &[&["a"]]), 0);
}

#[test]
fn without_states_header_the_largest_number_counts_and_unlisted_states_have_no_edges() {
    // State 3 is referenced but never listed: it has no edges, so it goes to the sink 4.
    let automaton = read_one(
        "HOA: v1 Start: 0 Start: 0 AP: 1 \"a\" Acceptance: 1 Inf(0) --BODY-- \
         State: 0 [0] 3 [!0] 0 --END--",
    );
    assert_eq!(automaton.declared_states, 4);
    assert_eq!(automaton.sink, Some(4));
    let dfa = &automaton.dfa;
    assert_eq!(dfa.num_states(), 5);
    assert_eq!(run(dfa, &[&["a"]]), 3);
    assert_eq!(run(dfa, &[&["a"], &[]]), 4);
    // States 1 and 2 are unreachable and edgeless: they also go to the sink.
    assert_eq!(dfa.step(1, 0), 4);
}

#[test]
fn no_propositions() {
    for aps in ["", "AP: 0"] {
        let text = format!(
            "HOA: v1 States: 1 Start: 0 {aps} Acceptance: 1 Inf(0) --BODY-- State: 0 {{0}} [t] 0 \
             --END--"
        );
        let dfa = read_one(&text).dfa;
        assert!(dfa.aps().is_empty());
        assert_eq!(finals(&dfa), vec![0]);
    }
    // Implicit labels with no propositions: one edge.
    let implicit = "HOA: v1 States: 1 Start: 0 Acceptance: 0 t --BODY-- State: 0 0 --END--";
    assert_eq!(finals(&read_one(implicit).dfa), vec![0]);
}

#[test]
fn several_automata_and_aborted_ones() {
    let one = "HOA: v1 name: \"first\" States: 1 Start: 0 Acceptance: 0 t --BODY-- \
               State: 0 [t] 0 --END--";
    let aborted = "HOA: v1 name: \"aborted\" States: 2 --ABORT--";
    let aborted_in_body = "HOA: v1 States: 1 Start: 0 Acceptance: 0 t --BODY-- State: 0 --ABORT--";
    let two = one.replace("first", "second");
    let text = format!("{one}\n{aborted}\n{two}\n{aborted_in_body}\n");
    let automata = hoa::parse(&text).unwrap();
    let names: Vec<_> = automata.iter().map(|a| a.name.as_deref()).collect();
    assert_eq!(names, vec![Some("first"), Some("second")]);
}

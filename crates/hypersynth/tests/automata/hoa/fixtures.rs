//! The 300 automata Spot 2.12.1 wrote for co-safe formulas (tests/fixtures/spot): each reads with
//! the state and edge counts of `summary.tsv`, gets as its only final state the accepting sink
//! found by a naive scan of its text, and survives writing and reading back.

use std::collections::BTreeSet;

use hypersynth::automata::compare::{equivalence_counterexample, inclusion_counterexample};
use hypersynth::automata::hoa::{self, HoaAutomaton};
use hypersynth::automata::{Dfa, DfaState};

const FIXTURES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tests/fixtures/spot");

struct Fixture {
    index: String,
    text: String,
    states: usize,
    edges: usize,
    formula: String,
}

fn fixtures() -> Vec<Fixture> {
    let summary = std::fs::read_to_string(format!("{FIXTURES}/summary.tsv")).unwrap();
    summary
        .lines()
        .skip(1)
        .map(|line| {
            let fields: Vec<&str> = line.split('\t').collect();
            let index = fields[0].to_string();
            Fixture {
                text: std::fs::read_to_string(format!("{FIXTURES}/hoa/{index}.hoa")).unwrap(),
                index,
                states: fields[1].parse().unwrap(),
                edges: fields[2].parse().unwrap(),
                formula: fields[5].to_string(),
            }
        })
        .collect()
}

fn read_one(fixture: &Fixture) -> HoaAutomaton {
    let mut automata =
        hoa::parse(&fixture.text).unwrap_or_else(|e| panic!("fixture {}: {e}", fixture.index));
    assert_eq!(automata.len(), 1, "fixture {}", fixture.index);
    automata.pop().unwrap()
}

fn fixture(index: &str) -> Dfa {
    let all = fixtures();
    read_one(all.iter().find(|f| f.index == index).unwrap()).dfa
}

/// The states the text marks `{0}` and whose only edge is `[t]` to themselves, found line by
/// line without the reader: Spot's accepting sinks.
fn accepting_sinks(text: &str) -> BTreeSet<usize> {
    let lines: Vec<&str> = text.lines().collect();
    let mut sinks = BTreeSet::new();
    for (i, line) in lines.iter().enumerate() {
        let Some(rest) = line.strip_prefix("State: ") else {
            continue;
        };
        let Some(number) = rest.strip_suffix(" {0}") else {
            continue;
        };
        let next_is_boundary = lines
            .get(i + 2)
            .is_some_and(|l| l.starts_with("State:") || *l == "--END--");
        if lines.get(i + 1) == Some(&format!("[t] {number}").as_str()) && next_is_boundary {
            sinks.insert(number.parse().unwrap());
        }
    }
    sinks
}

/// The states the text marks `{0}`.
fn marked_states(text: &str) -> BTreeSet<usize> {
    text.lines()
        .filter_map(|l| l.strip_prefix("State: ")?.strip_suffix(" {0}"))
        .map(|n| n.parse().unwrap())
        .collect()
}

#[test]
fn every_fixture_reads_with_the_summary_counts_and_one_final_sink() {
    let all = fixtures();
    assert_eq!(all.len(), 300);
    let mut with_transient_marks = 0;
    for f in &all {
        let automaton = read_one(f);
        let dfa = &automaton.dfa;
        assert_eq!(automaton.declared_states, f.states, "fixture {}", f.index);
        assert_eq!(automaton.declared_edges, f.edges, "fixture {}", f.index);
        // Complete automata: no sink added, and one DFA edge per HOA edge.
        assert_eq!(automaton.sink, None, "fixture {}", f.index);
        assert_eq!(dfa.num_states(), f.states, "fixture {}", f.index);
        assert_eq!(dfa.num_edges(), f.edges, "fixture {}", f.index);
        assert_eq!(automaton.name.as_deref(), Some(f.formula.as_str()));
        let finals: BTreeSet<usize> = dfa.finals().iter().collect();
        let sinks = accepting_sinks(&f.text);
        assert_eq!(sinks.len(), 1, "fixture {}", f.index);
        assert_eq!(finals, sinks, "fixture {}", f.index);
        if marked_states(&f.text).len() > finals.len() {
            with_transient_marks += 1;
        }
    }
    // Spot marks transient states often enough for the rule to matter.
    assert!(with_transient_marks > 10, "{with_transient_marks}");
}

#[test]
fn transient_marked_states_are_not_final() {
    // `!b` (0004): start state 1 is marked {0} but its [0] edge reaches the rejecting sink 2.
    let not_b = fixture("0004");
    assert_eq!(not_b.initial(), 1);
    assert!(!not_b.is_final(1));
    assert_eq!(not_b.finals().iter().collect::<Vec<_>>(), vec![0]);
    assert!(!not_b.accepts([]));
    assert!(not_b.accepts([not_b.letter([])]));
    assert!(!not_b.accepts([not_b.letter(["b"])]));
    // `!a & c` (0008): the same with two propositions.
    let not_a_and_c = fixture("0008");
    let text = std::fs::read_to_string(format!("{FIXTURES}/hoa/0008.hoa")).unwrap();
    let start = not_a_and_c.initial() as usize;
    assert!(marked_states(&text).contains(&start));
    assert!(!not_a_and_c.is_final(start as DfaState));
    assert!(not_a_and_c.accepts([not_a_and_c.letter(["c"])]));
    assert!(!not_a_and_c.accepts([not_a_and_c.letter(["a", "c"])]));
}

/// Same states, initial state, finals, and per state the same targets in the same order with
/// equivalent guards.
fn assert_same_structure(a: &Dfa, b: &Dfa, context: &str) {
    assert_eq!(a.aps(), b.aps(), "{context}");
    assert_eq!(a.num_states(), b.num_states(), "{context}");
    assert_eq!(a.initial(), b.initial(), "{context}");
    assert_eq!(a.finals(), b.finals(), "{context}");
    for q in 0..a.num_states() as DfaState {
        let (ea, eb): (Vec<_>, Vec<_>) = (a.edges(q).collect(), b.edges(q).collect());
        assert_eq!(ea.len(), eb.len(), "{context}: state {q}");
        for ((ga, ta), (gb, tb)) in ea.iter().zip(&eb) {
            assert_eq!(ta, tb, "{context}: state {q}");
            assert!(ga.equivalent(gb), "{context}: state {q}");
        }
    }
}

#[test]
fn every_fixture_survives_writing_and_reading_back() {
    for f in &fixtures() {
        let dfa = read_one(f).dfa;
        let text = hoa::write(&dfa, Some(&f.formula)).unwrap();
        let again =
            hoa::parse(&text).unwrap_or_else(|e| panic!("fixture {}: {e}\n{text}", f.index));
        assert_eq!(again.len(), 1);
        assert_eq!(again[0].name.as_deref(), Some(f.formula.as_str()));
        assert_same_structure(&dfa, &again[0].dfa, &f.index);
        assert_eq!(equivalence_counterexample(&dfa, &again[0].dfa), Ok(None));
    }
}

fn letters(names: &[&[&str]]) -> Vec<BTreeSet<String>> {
    names
        .iter()
        .map(|letter| letter.iter().map(|s| s.to_string()).collect())
        .collect()
}

#[test]
fn fixture_languages_compare_by_proposition_name() {
    let (f_d, x_f_d, xx_f_d) = (fixture("0010"), fixture("0084"), fixture("0001"));
    // XXFd ⊆ XFd ⊆ Fd; {d} is a good prefix of Fd only.
    assert_eq!(inclusion_counterexample(&xx_f_d, &x_f_d), Ok(None));
    assert_eq!(inclusion_counterexample(&x_f_d, &f_d), Ok(None));
    let cex = inclusion_counterexample(&f_d, &xx_f_d).unwrap().unwrap();
    assert_eq!(cex.word, letters(&[&["d"]]));
    // Fd and XFd differ first on {d} too (XFd needs a second letter).
    let cex = equivalence_counterexample(&x_f_d, &f_d).unwrap().unwrap();
    assert_eq!(cex.word, letters(&[&["d"]]));
    assert!(!cex.accepted_by_left);

    // `!a & !b` over [a, b] ⊆ `!b` over [b]; the converse fails on {a}.
    let (not_a_not_b, not_b) = (fixture("0035"), fixture("0004"));
    assert_eq!(inclusion_counterexample(&not_a_not_b, &not_b), Ok(None));
    let cex = inclusion_counterexample(&not_b, &not_a_not_b)
        .unwrap()
        .unwrap();
    assert_eq!(cex.word, letters(&[&["a"]]));
    // `!a & c` over [a, c] ⊆ `c | Fd` over [c, d].
    assert_eq!(
        inclusion_counterexample(&fixture("0008"), &fixture("0007")),
        Ok(None)
    );
}

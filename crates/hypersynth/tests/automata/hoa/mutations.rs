//! The HOA reader on mutated fixture texts: it never panics, an error points inside the text,
//! and whatever it accepts is a DFA that the writer and the reader agree on.

use std::sync::OnceLock;

use hypersynth::automata::DfaState;
use hypersynth::automata::hoa;
use proptest::prelude::*;

fn fixture_texts() -> &'static [String] {
    static TEXTS: OnceLock<Vec<String>> = OnceLock::new();
    TEXTS.get_or_init(|| {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tests/fixtures/spot/hoa");
        let mut paths: Vec<_> = std::fs::read_dir(dir)
            .unwrap()
            .map(|entry| entry.unwrap().path())
            .collect();
        paths.sort();
        paths
            .iter()
            .map(|p| std::fs::read_to_string(p).unwrap())
            .collect()
    })
}

/// Fragments that exercise the grammar's corners when spliced in anywhere.
const FRAGMENTS: &[&str] = &[
    "[",
    "]",
    "&",
    "|",
    "!",
    "(",
    ")",
    "{",
    "}",
    "{0}",
    "{1}",
    "\"",
    "/*",
    "*/",
    "@x",
    "@",
    "t",
    "f",
    "0",
    "7",
    "01",
    "2147483648",
    "State:",
    "State: 0",
    "Start: 0",
    "Start: 1&0",
    "States: 2",
    "AP: 1 \"x\"",
    "Alias: @x 0",
    "Acceptance: 1 Fin(0)",
    "Acceptance: 0 t",
    "--BODY--",
    "--END--",
    "--ABORT--",
    "HOA: v1",
    "Foo: 1",
    "\n",
    " ",
    "é",
    ":",
    "-",
];

#[derive(Clone, Debug)]
enum Mutation {
    Delete { at: usize, len: usize },
    Insert { at: usize, fragment: usize },
    DuplicateLine { line: usize },
    SwapLines { first: usize, second: usize },
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (any::<usize>(), 1..6usize).prop_map(|(at, len)| Mutation::Delete { at, len }),
        (any::<usize>(), 0..FRAGMENTS.len())
            .prop_map(|(at, fragment)| Mutation::Insert { at, fragment }),
        any::<usize>().prop_map(|line| Mutation::DuplicateLine { line }),
        (any::<usize>(), any::<usize>())
            .prop_map(|(first, second)| Mutation::SwapLines { first, second }),
    ]
}

fn apply(text: &str, mutation: &Mutation) -> String {
    let chars: Vec<char> = text.chars().collect();
    let mut lines: Vec<&str> = text.lines().collect();
    match *mutation {
        Mutation::Delete { at, len } => {
            let at = at % (chars.len() + 1);
            let end = (at + len).min(chars.len());
            chars[..at].iter().chain(&chars[end..]).collect()
        }
        Mutation::Insert { at, fragment } => {
            let at = at % (chars.len() + 1);
            let mut out: String = chars[..at].iter().collect();
            out.push_str(FRAGMENTS[fragment]);
            out.extend(&chars[at..]);
            out
        }
        Mutation::DuplicateLine { line } => {
            let line = line % lines.len();
            lines.insert(line, lines[line]);
            lines.join("\n")
        }
        Mutation::SwapLines { first, second } => {
            let n = lines.len();
            lines.swap(first % n, second % n);
            lines.join("\n")
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn mutated_fixtures_never_panic_the_reader(
        which in 0..300usize,
        mutations in proptest::collection::vec(mutation(), 1..5),
    ) {
        let text = mutations
            .iter()
            .fold(fixture_texts()[which].clone(), |text, m| apply(&text, m));
        match hoa::parse(&text) {
            Err(errors) => {
                let lines = text.split('\n').count();
                for error in &errors {
                    prop_assert!(error.position.line >= 1 && error.position.line <= lines);
                    prop_assert!(error.position.column >= 1);
                    prop_assert!(!error.message.is_empty());
                }
                prop_assert!(errors.as_slice().is_sorted_by_key(|e| e.position));
            }
            Ok(automata) => {
                for automaton in automata {
                    let dfa = &automaton.dfa;
                    // A complete DFA: every letter has a successor (step would panic otherwise).
                    for q in 0..dfa.num_states() as DfaState {
                        for letter in 0..1u64 << dfa.aps().len().min(4) {
                            prop_assert!((dfa.step(q, letter) as usize) < dfa.num_states());
                        }
                    }
                    // Writing is refused only for DFAs that are not good-prefix DFAs, which a
                    // reader's DFA always is.
                    let written = hoa::write(dfa, automaton.name.as_deref()).unwrap();
                    let again = hoa::parse(&written).unwrap();
                    prop_assert_eq!(again.len(), 1);
                    prop_assert_eq!(again[0].dfa.finals(), dfa.finals());
                    prop_assert_eq!(again[0].dfa.num_edges(), dfa.num_edges());
                }
            }
        }
    }
}

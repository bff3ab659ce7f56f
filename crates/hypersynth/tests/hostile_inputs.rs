//! Hostile inputs: short texts that once made hypersynth run for minutes or exhaust memory.
//! Each must end with an answer or a clean error, and the work is bounded by what the library
//! counts (translation limits in states, edges, BDD nodes and steps; guard sizes in BDD nodes),
//! never by a clock. The answers are checked against hand computations or naive evaluations.

use hypersynth::arena::{self, ParseErrorKind};
use hypersynth::automata::{Dfa, hoa};
use hypersynth::ltl;
use hypersynth::position::Position;
use hypersynth::testing::disjunction_of_next_steps;
use hypersynth::translate::{Builtin, Limit, Phase, TranslateError, TranslationLimits, Translator};

/// The limits of every translation here: 2^16 states (2^19 nodes) and 10^8 BDD steps.
fn limits() -> TranslationLimits {
    TranslationLimits::new(1 << 16, 100_000_000)
}

fn translate(text: &str) -> Result<Dfa, TranslateError> {
    let formula = ltl::parse(text).unwrap_or_else(|e| panic!("{text}: {e}"));
    Builtin::new(limits()).translate(&formula)
}

fn is_limit(error: &TranslateError) -> bool {
    matches!(
        error.limit(),
        Some(Limit::States(_) | Limit::Nodes(_) | Limit::Steps(_))
    )
}

/// A small deterministic generator for words (xorshift).
fn letters(seed: u64, count: usize, propositions: u32) -> Vec<u64> {
    let mut state = seed | 1;
    let mask = u64::MAX >> (64 - propositions);
    (0..count)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state & mask
        })
        .collect()
}

#[test]
fn a_window_of_22_steps_hits_the_state_limit() {
    // F(a & X^n b) must remember which of the last n letters had `a`: 2^n windows plus the
    // accepting sink. n = 10 is 1025 states; n = 22 is over four million, past the limit.
    let small = translate(&format!("F(a & {}b)", "X".repeat(10))).unwrap();
    assert_eq!(small.num_states(), 1025);
    let error = translate(&format!("F(a & {}b)", "X".repeat(22))).unwrap_err();
    assert_eq!(error.limit(), Some(Limit::States(1 << 16)), "{error}");
    assert!(error.to_string().contains("(the state limit)"), "{error}");
}

/// The 393 217-state formula.
const STRONG_RELEASE: &str = "!a M (((a & ((!c & !XXXXXXXXXXXXXXXXXX(!c & d))))) U !b)";

#[test]
fn a_strong_release_over_a_long_next_chain_hits_a_limit() {
    // Past 2^16 states.
    let error = translate(STRONG_RELEASE).unwrap_err();
    assert!(is_limit(&error), "{error}");
}

#[test]
fn a_strong_release_over_a_long_next_chain_translates_within_its_limits() {
    // 2^19 states and 4 * 10^7 units of work are enough: about 9 million steps explore the
    // 393 218 states, 26 million units minimise them (16 letter classes: the successor table
    // and Hopcroft's predecessor lists take 6.3 million entries each).
    let formula = ltl::parse(STRONG_RELEASE).unwrap();
    let dfa = Builtin::new(TranslationLimits::new(1 << 19, 40_000_000))
        .translate(&formula)
        .unwrap();
    assert_eq!(dfa.num_states(), 393_217);
    assert_eq!(dfa.num_edges(), 1_245_185);
    let letter = |names: &[&str]| dfa.letter(names.iter().copied());
    let accepts = |word: &[u64]| dfa.accepts(word.iter().copied());
    // `!a` at once releases the M, which needs the U there: `!b` at once.
    assert!(accepts(&[letter(&[])]));
    assert!(!accepts(&[letter(&["b"])]));
    assert!(!accepts(&[letter(&["b"]), letter(&[]), letter(&[])]));
    // `a & b`, then `!a & !b`: the M is released at the second letter, whose `!b` ends the U,
    // if the first letter's `!X^18(!c & d)` holds: the 19th letter decides.
    let mut word = vec![letter(&["a", "b"])];
    word.extend(std::iter::repeat_n(letter(&[]), 17));
    assert!(!accepts(&word));
    let decided = |last: &[&str]| {
        let mut word = word.clone();
        word.push(letter(last));
        word
    };
    assert!(accepts(&decided(&["c"])));
    assert!(accepts(&decided(&["c", "d"])));
    let mut lost = decided(&["d"]);
    assert!(!accepts(&lost));
    lost.extend(std::iter::repeat_n(letter(&["c"]), 5));
    assert!(!accepts(&lost));
}

#[test]
fn a_subformula_whose_unfolding_is_too_large_is_located() {
    // 2^20 sets of `q`s, past the 2^19 nodes of 2^16 states.
    let text = disjunction_of_next_steps(20);
    let error = translate(&text).unwrap_err();
    let TranslateError::Limit(limit) = &error else {
        panic!("{error:?}");
    };
    assert_eq!(limit.limit, Limit::Nodes(524288));
    assert_eq!(limit.phase, Phase::Unfolding);
    assert_eq!(
        error.to_string(),
        "unfolding this subformula over the propositions and the next step needs more than \
         524288 BDD nodes (the node limit)"
    );
    assert_eq!(
        error.position(&text),
        Some(Position {
            line: 1,
            column: 15
        })
    );
    // The same with too little work allowed: the work limit, at the same place.
    let formula = ltl::parse(&text).unwrap();
    let error = Builtin::new(TranslationLimits::new(1 << 16, 10_000))
        .translate(&formula)
        .unwrap_err();
    assert_eq!(
        error.to_string(),
        "unfolding this subformula over the propositions and the next step gave up after \
         10000 BDD steps (the work limit)"
    );
    assert_eq!(
        error.position(&text),
        Some(Position {
            line: 1,
            column: 15
        })
    );
    // A limit on the whole automaton has no place in the formula: F(a & X^22 b) unfolds in a
    // few nodes but needs 2^22 + 1 states.
    let error = translate(&format!("F(a & {}b)", "X".repeat(22))).unwrap_err();
    assert_eq!(error.limit(), Some(Limit::States(65536)), "{error:?}");
    assert_eq!(error.position("F(a & X…)"), None);
}

/// Translates `a0 U a1 U … U a4 U a0 …` (right-nested, `n` operands cycling over 5
/// propositions) within `steps` BDD steps and checks it on 400 words. A finite word is a good
/// prefix iff the chain holds on it with every `U` witnessed inside the word (positive
/// formula: extending with empty letters can witness nothing new).
fn check_until_chain(n: usize, steps: u64) {
    let text: Vec<String> = (0..n).map(|i| format!("a{}", i % 5)).collect();
    let formula = ltl::parse(&text.join(" U ")).unwrap();
    let dfa = Builtin::new(TranslationLimits::new(1 << 16, steps))
        .translate(&formula)
        .unwrap();
    assert!(dfa.num_states() < n, "{} states", dfa.num_states());
    let holds = |word: &[u64]| {
        // sat[k] for position i, computed from the end of the word backwards.
        let mut next = vec![false; n + 1];
        for letter in word.iter().rev() {
            let mut current = vec![false; n + 1];
            for k in (0..n).rev() {
                let here = letter & (1 << (k % 5)) != 0;
                current[k] = if k == n - 1 {
                    here
                } else {
                    current[k + 1] || (here && next[k])
                };
            }
            next = current;
        }
        next[0]
    };
    // The DFA's propositions are a0..a4 in that order, so letters are the same bits.
    assert_eq!(dfa.aps(), ["a0", "a1", "a2", "a3", "a4"]);
    for seed in 0..400 {
        let length = (seed % 9) as usize;
        let word = letters(seed + 1, length, 5);
        assert_eq!(dfa.accepts(word.iter().copied()), holds(&word), "{word:?}");
    }
}

#[test]
fn a_chain_of_300_untils_translates_and_means_what_it_says() {
    check_until_chain(300, 1_000_000);
}

#[test]
fn a_chain_of_1000_untils_translates_in_linear_work() {
    // About 1.1 million steps for 6386 states explored (802 after minimisation, which takes
    // 0.9 million units more): each state composes one new node. With the term variables
    // ordered from the operands up, each recomposed its whole diagram, and 1000 operands took
    // 31 s.
    check_until_chain(1000, 3_000_000);
}

#[test]
fn ten_eventualities_minimise_without_refining_3_to_the_10_guards() {
    // F p0 & … & F p9: 2^10 states, each waiting for a set of propositions, 3^10 edges with
    // as many distinct guards and 2^10 letter classes. Refining the classes by every distinct
    // guard took 100 s; the letters over ten propositions are listed instead.
    let text: Vec<String> = (0..10).map(|i| format!("F p{i}")).collect();
    let dfa = translate(&text.join(" & ")).unwrap();
    assert_eq!((dfa.num_states(), dfa.num_edges()), (1024, 59049));
    for seed in 0..200 {
        let word = letters(seed + 1, (seed % 7) as usize, 10);
        let seen = word.iter().fold(0, |acc, letter| acc | letter);
        assert_eq!(dfa.accepts(word.iter().copied()), seen == (1 << 10) - 1);
    }
    assert!(dfa.accepts((0..10).map(|i| 1 << i)));
}

#[test]
fn parity_of_forty_propositions_translates() {
    // p1 <-> (p2 <-> ... <-> X q): the guards are parities, linear as BDDs.
    let text = format!(
        "{}X q{}",
        (1..=40).map(|i| format!("(p{i} <-> ")).collect::<String>(),
        ")".repeat(40)
    );
    let dfa = translate(&text).unwrap();
    // Start, "q next", "!q next", accepting and rejecting sinks.
    assert_eq!(dfa.num_states(), 5);
}

/// A HOA automaton: state 0 goes to the accepting sink 1 on `label`.
fn one_label(propositions: usize, label: &str) -> String {
    let names: Vec<String> = (0..propositions).map(|i| format!("\"p{i}\"")).collect();
    format!(
        "HOA: v1\nStates: 2\nStart: 0\nAP: {propositions} {}\nAcceptance: 1 Inf(0)\n--BODY--\n\
         State: 0\n[{label}] 1\nState: 1 {{0}}\n[t] 1\n--END--\n",
        names.join(" ")
    )
}

#[test]
fn conjunctions_of_pairs_cost_a_node_per_proposition() {
    for pairs in [16u32, 20, 32] {
        let label: Vec<String> = (0..pairs)
            .map(|i| format!("({}|{})", 2 * i, 2 * i + 1))
            .collect();
        let text = one_label(2 * pairs as usize, &label.join("&"));
        let dfa = &hoa::parse(&text).unwrap()[0].dfa;
        // States 0, 1 and the rejecting sink that completes state 0.
        assert_eq!(dfa.num_states(), 3);
        let (guard, target) = dfa.edges(0).next().unwrap();
        assert_eq!(target, 1);
        assert_eq!(guard.size(), 2 * pairs as usize);
        for letter in letters(u64::from(pairs), 200, 2 * pairs) {
            let expected = (0..pairs).all(|i| letter & (0b11 << (2 * i)) != 0);
            assert_eq!(guard.evaluate(letter), expected);
        }
    }
}

/// A state with all 2^12 implicitly labelled edges, alternating between states 0 and 1, then
/// `extra` more lines.
fn implicit_edges(extra: &str) -> String {
    let names: Vec<String> = (0..12).map(|i| format!("\"p{i}\"")).collect();
    let edges: String = (0..4096).map(|i| format!("{}\n", i % 2)).collect();
    format!(
        "HOA: v1\nStates: 2\nStart: 0\nAP: 12 {}\nAcceptance: 1 Inf(0)\n--BODY--\nState: 0\n\
         {edges}{extra}State: 1 {{0}}\n[t] 1\n--END--\n",
        names.join(" ")
    )
}

#[test]
fn thousands_of_implicit_labels_are_read_in_linear_time() {
    let dfa = &hoa::parse(&implicit_edges("")).unwrap()[0].dfa;
    assert_eq!(dfa.num_states(), 2);
    // Letter k goes to k mod 2, so proposition 0 decides.
    for letter in letters(7, 100, 12) {
        assert_eq!(dfa.step(0, letter), (letter & 1) as u32);
    }
    // A 4097th edge is refused at its own line (line 8 is the first edge).
    let errors = hoa::parse(&implicit_edges("1\n")).unwrap_err();
    let error = errors.first();
    assert_eq!(error.position.line, 8 + 4096, "{errors}");
    assert!(error.message.contains("too many edges"), "{errors}");
}

#[test]
fn an_overlap_among_many_edges_names_both_edges() {
    // 1024 disjoint full cubes over 10 propositions, then one overlapping the 700th.
    let names: Vec<String> = (0..10).map(|i| format!("\"p{i}\"")).collect();
    let cube = |k: u32| {
        let literals: Vec<String> = (0..10)
            .map(|i| format!("{}{i}", if k & (1 << i) != 0 { "" } else { "!" }))
            .collect();
        literals.join("&")
    };
    let mut text = format!(
        "HOA: v1\nStates: 1\nStart: 0\nAP: 10 {}\nAcceptance: 1 Inf(0)\n--BODY--\nState: 0\n",
        names.join(" ")
    );
    for k in 0..1024 {
        text.push_str(&format!("[{}] 0\n", cube(k)));
    }
    text.push_str(&format!("[{}] 0\n--END--\n", cube(699)));
    let errors = hoa::parse(&text).unwrap_err();
    let error = errors.first();
    assert_eq!(error.position.line, 8 + 1024, "{errors}");
    assert!(
        error.message.contains(&format!("{}:1", 8 + 699)),
        "{errors}"
    );
}

#[test]
fn a_state_with_a_huge_label_is_read() {
    let count = 200_000;
    let propositions: Vec<String> = (0..count).map(|i| format!("p{i}")).collect();
    let text = format!("initial s\nstate s robot {{{}}}\n", propositions.join(" "));
    let parsed = arena::parse(&text).unwrap();
    assert_eq!(parsed.arena.propositions().len(), count);
    assert_eq!(
        parsed.arena.label(parsed.arena.initial()).iter().count(),
        count
    );
    // Repeating the first proposition at the end is an error at its column.
    let text = format!(
        "initial s\nstate s robot {{{} p0}}\n",
        propositions.join(" ")
    );
    let errors = arena::parse(&text).unwrap_err();
    let error = errors.first();
    assert!(
        matches!(error.message, ParseErrorKind::RepeatedInLabel(_)),
        "{error}"
    );
    assert_eq!(error.position.line, 2);
    assert_eq!(
        error.position.column,
        text.lines().nth(1).unwrap().len() - 2
    );
}

#[test]
fn edges_alternating_between_two_sources_are_read_in_linear_time() {
    let pairs = 100_000;
    let mut text = String::from("initial s0\nstate s0 robot {}\nstate s1 adversary {}\n");
    for i in 0..pairs {
        text.push_str(&format!("edge s0 x{i} s1\nedge s1 x{i} s0\n"));
    }
    let arena = arena::parse(&text).unwrap().arena;
    assert_eq!(arena.num_transitions(), 2 * pairs);
    assert_eq!(arena.edges(arena.initial()).len(), pairs);
    // One more edge of s0 with an action it already has: refused at that line.
    text.push_str("edge s0 x500 s0\n");
    let error = arena::parse(&text).unwrap_err();
    assert_eq!(error.first().position.line, 3 + 2 * pairs + 1, "{error}");
}

#[test]
fn many_errors_are_reported_in_linear_time() {
    // 100 000 repetitions of one edge: each a duplicate of line 3. Only the errors shown look
    // for the first edge, so this is one pass, not one per error.
    let mut text = String::from("initial s0\nstate s0 robot {}\n");
    text.push_str(&"edge s0 go s0\n".repeat(100_000));
    let errors = arena::parse(&text).unwrap_err();
    assert_eq!(errors.total(), 99_999);
    assert_eq!(
        errors.first().to_string(),
        "4:9: state `s0` already has a successor for action `go` (line 3)"
    );
    // 100 000 states of a HOA automaton, each repeating its first edge's label (state k on
    // line 5 + 3k).
    let mut text = String::from("HOA: v1\nStart: 0\nAcceptance: 0 t\n--BODY--\n");
    for state in 0..100_000 {
        text.push_str(&format!("State: {state}\n[t] 0\n[t] 0\n"));
    }
    text.push_str("--END--\n");
    let errors = hoa::parse(&text).unwrap_err();
    assert_eq!(errors.total(), 100_000);
    assert_eq!(
        errors.as_slice()[19].to_string(),
        "64:1: nondeterministic: this edge's label overlaps that of the edge at 63:1 (state 19)"
    );
}

#[test]
fn long_headers_are_read_in_linear_time() {
    // 100 000 proposition names: refused for being more than 64, after a linear scan.
    let names: Vec<String> = (0..100_000).map(|i| format!("\"p{i}\"")).collect();
    let text = format!(
        "HOA: v1\nStart: 0\nAP: {} {}\nAcceptance: 0 t\n--BODY--\n--END--\n",
        names.len(),
        names.join(" ")
    );
    let error = hoa::parse(&text).unwrap_err();
    assert!(
        error.first().message.contains("more than the 64"),
        "{error}"
    );
    // 20 000 aliases, each the conjunction of the previous one with a literal: the last is the
    // conjunction of all three propositions.
    let mut text = String::from("HOA: v1\nStart: 0\nAP: 3 \"a\" \"b\" \"c\"\nAlias: @x0 t\n");
    for i in 1..20_000 {
        text.push_str(&format!("Alias: @x{i} @x{} & {}\n", i - 1, i % 3));
    }
    text.push_str("Acceptance: 1 Inf(0)\n--BODY--\nState: 0\n[@x19999] 0\n--END--\n");
    let dfa = &hoa::parse(&text).unwrap()[0].dfa;
    let (guard, _) = dfa.edges(0).next().unwrap();
    for letter in 0..8 {
        assert_eq!(guard.evaluate(letter), letter == 7);
    }
}

#[test]
fn aliases_naming_every_node_of_a_large_guard_are_read_in_linear_time() {
    // A diagram of 64 levels of 256 nodes, one alias per node as the writer names them, each
    // node branching to two nodes of the next level: a node's function is the whole diagram
    // below it. Resolving each alias into a guard of its own, imported again by every alias
    // using it, cost the sum of those diagrams' sizes (about 10^8 nodes here).
    let (levels, width) = (64u32, 256u64);
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = |bound: u64| {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state % bound
    };
    // `branches[level][j]`: the (false, true) branches of node j, nodes of the next level
    // (below the last level, the constants).
    let branches: Vec<Vec<(u64, u64)>> = (0..levels)
        .map(|_| {
            (0..width)
                .map(|_| {
                    let low = next(width);
                    (low, (low + 1 + next(width - 1)) % width)
                })
                .collect()
        })
        .collect();
    let names: Vec<String> = (0..levels).map(|i| format!("\"p{i}\"")).collect();
    let mut text = format!(
        "HOA: v1\nStates: 2\nStart: 0\nAP: {levels} {}\nAcceptance: 1 Inf(0)\n",
        names.join(" ")
    );
    for level in (0..levels).rev() {
        for (j, &(low, high)) in branches[level as usize].iter().enumerate() {
            let definition = if level + 1 == levels {
                // The last level: node j is the proposition or its negation.
                if j % 2 == 0 {
                    format!("{level}")
                } else {
                    format!("!{level}")
                }
            } else {
                let below = level + 1;
                format!("{level}&@n{below}_{high} | !{level}&@n{below}_{low}")
            };
            text.push_str(&format!("Alias: @n{level}_{j} {definition}\n"));
        }
    }
    text.push_str("--BODY--\nState: 0\n[@n0_0] 1\nState: 1 {0}\n[t] 1\n--END--\n");
    let dfa = &hoa::parse(&text).unwrap()[0].dfa;
    let (guard, target) = dfa.edges(0).next().unwrap();
    assert_eq!(target, 1);
    // The diagram evaluated by hand: down the levels from node 0 of level 0.
    let naive = |letter: u64| {
        let mut node = 0;
        for level in 0..levels - 1 {
            let (low, high) = branches[level as usize][node as usize];
            node = if letter >> level & 1 == 1 { high } else { low };
        }
        (letter >> (levels - 1) & 1 == 1) == (node % 2 == 0)
    };
    for letter in letters(7, 2000, levels) {
        assert_eq!(guard.evaluate(letter), naive(letter), "{letter:#x}");
    }
}

#[test]
fn one_proposition_per_step_does_not_enumerate_letter_classes() {
    // p0 & X(p1 & X(... X q)): a chain of 61 obligations and two sinks, whose guards have 2^61
    // letter classes.
    let n = 60;
    let text = format!(
        "{}q{}",
        (0..n).map(|i| format!("p{i} & X(")).collect::<String>(),
        ")".repeat(n)
    );
    assert_eq!(translate(&text).unwrap().num_states(), n + 3);
}

#[test]
fn a_mangled_until_chain_found_by_fuzzing_ends_within_its_step_budget() {
    // Thousands of BDD-distinct states with hundreds of successors each before minimisation
    // (34 states after): the walks over their guards count as steps too.
    let text = include_str!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fuzz/seeds/ltl/slow-until-chain.ltl"
    ));
    let formula = ltl::parse(text).unwrap();
    let budget = Builtin::new(TranslationLimits::new(1 << 16, 1_000_000)).translate(&formula);
    assert!(
        matches!(&budget, Err(error) if error.limit() == Some(Limit::Steps(1_000_000))),
        "{budget:?}"
    );
}

#[test]
fn a_label_of_many_cubes_reads_back_in_linear_time() {
    // (0|1)&…&(26|27) has 2^14 cubes; reading them builds the guard in one BDD manager (a fold
    // of guard disjunctions was quadratic: 27 s for 2^16 cubes).
    let label: Vec<String> = (0..14)
        .map(|i| format!("({}|{})", 2 * i, 2 * i + 1))
        .collect();
    let cubes: Vec<String> = (0..1u32 << 14)
        .map(|choice| {
            let literals: Vec<String> = (0..14)
                .map(|i| (2 * i + (choice >> i & 1)).to_string())
                .collect();
            literals.join("&")
        })
        .collect();
    let dfa = &hoa::parse(&one_label(28, &cubes.join(" | "))).unwrap()[0].dfa;
    let (guard, _) = dfa.edges(0).next().unwrap();
    assert_eq!(guard.size(), 28);
    assert_eq!(
        dfa,
        &hoa::parse(&one_label(28, &label.join("&"))).unwrap()[0].dfa
    );
    // The writer names the diagram's 28 nodes rather than list the cubes, and the text reads
    // back as the same automaton.
    let written = hoa::write(dfa, None).unwrap();
    assert_eq!(written.matches("Alias: @").count(), 28, "{written}");
    assert!(written.len() < 2000, "{} bytes", written.len());
    let again = &hoa::parse(&written).unwrap()[0].dfa;
    assert_eq!(again, dfa);
}

#[test]
fn a_parity_guard_is_written_in_linear_size() {
    // a1 xor … xor a60: the guard into the accepting sink is the parity of 60 propositions,
    // 2^59 cubes but two nodes per proposition but the last (119).
    let text: Vec<String> = (1..=60).map(|i| format!("a{i}")).collect();
    let dfa = translate(&text.join(" xor ")).unwrap();
    assert_eq!(dfa.num_states(), 3);
    let written = hoa::write(&dfa, None).unwrap();
    // Both edges of the start state share the parity's diagram up to the root: one alias per
    // node of each guard.
    let sizes: usize = dfa.edges(0).map(|(guard, _)| guard.size()).sum();
    assert_eq!(sizes, 2 * 119);
    assert_eq!(written.matches("Alias: @").count(), 2 * 119);
    let again = &hoa::parse(&written).unwrap()[0].dfa;
    assert_eq!(again, &dfa);
    // A word with an odd number of the a_i is a good prefix, an even one is not.
    let letter = |names: &[&str]| dfa.letter(names.iter().copied());
    assert!(dfa.accepts([letter(&["a7"])]));
    assert!(!dfa.accepts([letter(&["a7", "a60"])]));
}

/// `a1 OP a2 OP … OP an`, flat (as written, the parser nests it) or explicitly nested from the
/// right, over `a1..an`.
fn chain(op: &str, n: usize, nested: bool) -> String {
    let names: Vec<String> = (1..=n).map(|i| format!("a{i}")).collect();
    if !nested {
        return names.join(&format!(" {op} "));
    }
    let mut text = names[n - 1].clone();
    for name in names[..n - 1].iter().rev() {
        text = format!("({name} {op} {text})");
    }
    text
}

/// Whether the letter (bits `a1..an` first, in that order) has an odd number of the `a_i`.
fn odd(letter: u64, n: usize) -> bool {
    (letter & (u64::MAX >> (64 - n))).count_ones() % 2 == 1
}

#[test]
fn xor_and_equivalence_chains_are_guards_inside_f_u_and_x() {
    // The family, at the sizes CI can afford to check on words: chains of 20 to 64
    // propositions, flat and nested, alone and inside F, U and X. Each is a handful of states
    // whose guards are parities (n − 1 chained `<->` is the parity with the sign of n).
    for n in [20, 33, 64] {
        for nested in [false, true] {
            let xor = chain("xor", n, nested);
            let equiv = chain("<->", n, nested);
            // a1 <-> … <-> an (n − 1 operators) holds iff the number of false a_i is even.
            let equiv_holds = |letter: u64| odd(letter, n) == (n % 2 == 1);
            let dfa = translate(&xor).unwrap();
            assert_eq!(dfa.num_states(), 3, "{xor}");
            let dfa_equiv = translate(&equiv).unwrap();
            let inside_f = translate(&format!("F({xor})")).unwrap();
            assert_eq!(inside_f.num_states(), 2);
            for word in (0..40).map(|seed| letters(seed + 1, 1 + (seed % 4) as usize, n as u32)) {
                let first = word[0];
                assert_eq!(dfa.accepts([first]), odd(first, n), "{xor} on {first:#x}");
                assert_eq!(dfa_equiv.accepts([first]), equiv_holds(first), "{equiv}");
                let some = word.iter().any(|&letter| odd(letter, n));
                assert_eq!(inside_f.accepts(word.iter().copied()), some);
            }
        }
        // Inside U and X, with one more proposition.
        if n < 64 {
            let until = translate(&format!("({}) U z", chain("xor", n, true))).unwrap();
            assert_eq!(until.num_states(), 3);
            let letter = |names: &[&str]| until.letter(names.iter().copied());
            let (odd_letter, even_letter, z) = (letter(&["a1"]), letter(&[]), letter(&["z"]));
            assert!(until.accepts([odd_letter, odd_letter, z]));
            assert!(!until.accepts([odd_letter, even_letter, z]));
            // Start, after one letter, after z, and the two sinks.
            let next = translate(&format!("X(z & X({}))", chain("<->", n, false))).unwrap();
            assert_eq!(next.num_states(), 5);
            let letter = |names: &[&str]| next.letter(names.iter().copied());
            let (z, none, one) = (letter(&["z"]), letter(&[]), letter(&["a1"]));
            assert_eq!(next.accepts([none, z, none]), n % 2 == 0);
            assert_eq!(next.accepts([none, z, one]), n % 2 == 1);
            assert!(!next.accepts([none, none, none]) && !next.accepts([none, none, one]));
        }
    }
    // Past 64 propositions: refused at once, whatever the formula's shape.
    for text in [
        chain("xor", 65, false),
        format!("F({})", chain("<->", 100, true)),
    ] {
        assert!(matches!(
            translate(&text),
            Err(TranslateError::TooManyPropositions(65 | 100))
        ));
    }
}

#[test]
fn conjunctions_of_eventualities_are_answered_or_refused_on_the_limit_that_binds() {
    // F p0 & … & F p(k−1): 2^k states (the set of propositions seen), a state missing j of
    // them has 2^j successors: 3^k edges in all.
    let eventually = |k: usize| {
        let text: Vec<String> = (0..k).map(|i| format!("F p{i}")).collect();
        text.join(" & ")
    };
    let dfa = translate(&eventually(9)).unwrap();
    assert_eq!((dfa.num_states(), dfa.num_edges()), (512, 19_683));
    // Twelve: 2^12 states, far from the 2^16 allowed, but their 3^12 = 531 441 guards need
    // more than the 2^19 BDD nodes that come with them: the node limit binds, and the message
    // says so, with what the states found would take, rather than suggest more states.
    let error = translate(&eventually(12)).unwrap_err();
    assert_eq!(error.limit(), Some(Limit::Nodes(1 << 19)), "{error}");
    let message = error.to_string();
    assert!(
        message.starts_with(
            "the built-in translation needs more than 524288 BDD nodes for its states and \
             guards (the node limit); it had explored "
        ),
        "{message}"
    );
    assert!(
        message.contains("the automaton was still growing (") && message.contains("4097 states"),
        "{message}"
    );
    // Twenty: the same limit, about as early.
    assert_eq!(
        translate(&eventually(20)).unwrap_err().limit(),
        Some(Limit::Nodes(1 << 19))
    );
}

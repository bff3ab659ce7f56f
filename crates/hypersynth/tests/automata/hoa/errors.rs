//! Malformed or unsupported HOA texts: each gives an error at a hand-checked line and column,
//! with a message naming the problem.

use hypersynth::automata::hoa::{self, MAX_NESTING, MAX_STATES};

/// A valid automaton for `a`: state 0 initial, state 1 the accepting sink, 2 the rejecting one.
/// Each test replaces one line (1-based `line`) by `replacement` (several lines allowed).
const BASE: &str = "\
HOA: v1
States: 3
Start: 0
AP: 1 \"a\"
Acceptance: 1 Inf(0)
--BODY--
State: 0
[0] 1
[!0] 2
State: 1 {0}
[t] 1
State: 2
[t] 2
--END--
";

fn with_line(line: usize, replacement: &str) -> String {
    let mut lines: Vec<&str> = BASE.lines().collect();
    lines[line - 1] = replacement;
    lines.join("\n") + "\n"
}

#[track_caller]
fn assert_error(text: &str, line: usize, column: usize, fragment: &str) {
    let errors = hoa::parse(text).expect_err("the text should be rejected");
    let error = errors.first();
    assert_eq!(
        (error.position.line, error.position.column),
        (line, column),
        "{errors}"
    );
    assert!(error.message.contains(fragment), "{errors}");
}

#[test]
fn the_base_automaton_is_valid() {
    let automata = hoa::parse(BASE).unwrap();
    assert_eq!(automata[0].dfa.num_states(), 3);
}

#[test]
fn universal_branching_is_rejected_where_the_ampersand_is() {
    assert_error(&with_line(3, "Start: 0&1"), 3, 9, "universal branching");
    assert_error(&with_line(8, "[0] 1&2"), 8, 6, "universal branching");
}

#[test]
fn acceptance_conditions_other_than_t_f_and_inf_are_rejected() {
    assert_error(
        &with_line(5, "Acceptance: 1 Fin(0)"),
        5,
        15,
        "unsupported acceptance condition `Fin(0)`",
    );
    assert_error(
        &with_line(5, "Acceptance: 2 Inf(0)&Inf(1)"),
        5,
        15,
        "unsupported acceptance condition `Inf(0)&Inf(1)`",
    );
    assert_error(
        &with_line(5, "Acceptance: 1 Inf(!0)"),
        5,
        15,
        "unsupported acceptance condition `Inf(!0)`",
    );
    assert_error(
        &with_line(5, "Acceptance: 1 Inf(0) | t"),
        5,
        15,
        "unsupported acceptance condition",
    );
    assert_error(
        &with_line(5, "Acceptance: 1 Inf(1)"),
        5,
        19,
        "acceptance set 1 does not exist (`Acceptance:` declares 1 set)",
    );
    assert_error(
        &with_line(5, "Acceptance: 1 Buchi"),
        5,
        15,
        "expected `Inf(…)`",
    );
    assert_error(&with_line(5, "Acceptance: 1 Inf(0"), 6, 1, "expected `)`");
}

#[test]
fn overlapping_guards_are_nondeterminism() {
    assert_error(
        &with_line(9, "[t] 2"),
        9,
        1,
        "nondeterministic: this edge's label overlaps that of the edge at 8:1",
    );
    // Overlap between an edge and a state label's copies.
    let text = BASE.replace("State: 0\n[0] 1\n[!0] 2", "State: [0] 0\n1\n2");
    assert_error(&text, 9, 1, "nondeterministic");
}

#[test]
fn state_numbers_must_exist() {
    assert_error(
        &with_line(8, "[0] 3"),
        8,
        5,
        "state 3 does not exist (`States: 3`)",
    );
    assert_error(&with_line(12, "State: 7"), 12, 8, "state 7 does not exist");
    assert_error(&with_line(3, "Start: 3"), 3, 8, "state 3 does not exist");
    assert_error(
        &with_line(12, "State: 0"),
        12,
        8,
        "state 0 is declared twice (first at 7:8)",
    );
    assert_error(
        &with_line(2, &format!("States: {}", MAX_STATES + 1)),
        2,
        9,
        "more than the",
    );
    // Without `States:`, numbers are bounded too.
    let text = with_line(2, "").replace("[!0] 2", &format!("[!0] {MAX_STATES}"));
    assert_error(&text, 9, 6, "beyond the");
}

#[test]
fn initial_states_must_be_exactly_one() {
    assert_error(
        &with_line(3, "Start: 0\nStart: 0\nStart: 1"),
        5,
        8,
        "several initial states (0 and 1)",
    );
    assert_error(&with_line(3, ""), 6, 1, "no `Start:` header");
}

#[test]
fn the_end_marker_is_required() {
    let text = BASE.replace("--END--\n", "");
    assert_error(&text, 14, 1, "missing `--END--`");
    // Two automata glued without `--END--` between them.
    let text = BASE.replace("--END--\n", "") + BASE;
    assert_error(&text, 14, 1, "missing `--END--` before the next `HOA:`");
    assert_error("HOA: v1\nStart: 0\n", 3, 1, "missing `--BODY--`");
}

#[test]
fn aliases_must_be_defined_before_use() {
    assert_error(&with_line(8, "[@x] 1"), 8, 2, "undefined alias `@x`");
    assert_error(
        &with_line(4, "AP: 1 \"a\"\nAlias: @b !@a\nAlias: @a 0"),
        5,
        12,
        "undefined alias `@a`",
    );
    assert_error(
        &with_line(4, "AP: 1 \"a\"\nAlias: @a 0\nAlias: @a !0"),
        6,
        8,
        "alias `@a` is defined twice",
    );
}

#[test]
fn propositions_must_be_declared_and_counted_right() {
    assert_error(
        &with_line(8, "[0 | 1] 1"),
        8,
        6,
        "atomic proposition 1 does not exist (`AP:` declares 1 proposition)",
    );
    assert_error(
        &with_line(4, "AP: 2 \"a\""),
        4,
        5,
        "`AP:` announces 2 atomic propositions but lists 1",
    );
    assert_error(
        &with_line(4, "AP: 2 \"a\" \"a\""),
        4,
        11,
        "atomic proposition \"a\" is listed twice",
    );
    let many: Vec<String> = (0..65).map(|i| format!("\"p{i}\"")).collect();
    assert_error(
        &with_line(4, &format!("AP: 65 {}", many.join(" "))),
        4,
        1,
        "more than the 64",
    );
}

#[test]
fn malformed_tokens_are_located() {
    assert_error(&with_line(4, "AP: 1 \"a"), 4, 7, "unterminated string");
    assert_error(
        &with_line(6, "/* a /* b */ --BODY--"),
        6,
        1,
        "unterminated comment",
    );
    assert_error(&with_line(6, "--BODY-"), 6, 1, "malformed token `--BODY-`");
    assert_error(&with_line(8, "[0] 01"), 8, 5, "malformed number `01`");
    assert_error(
        &with_line(8, "[0 & ] 1"),
        8,
        6,
        "expected a proposition number",
    );
    assert_error(
        &with_line(8, "[0 1"),
        8,
        4,
        "expected `]` to close the label",
    );
    assert_error(&with_line(8, "[0] 1 ; 2"), 8, 7, "unexpected character `;`");
    assert_error(
        &with_line(8, "[0]"),
        9,
        1,
        "expected a target state, found `[`",
    );
    assert_error(
        &with_line(2, "States: x"),
        2,
        9,
        "expected a number of states",
    );
    assert_error(
        &with_line(
            8,
            &format!(
                "[{}0{}] 1",
                "(".repeat(MAX_NESTING + 1),
                ")".repeat(MAX_NESTING + 1)
            ),
        ),
        8,
        MAX_NESTING + 2,
        "label nested too deeply",
    );
}

#[test]
fn headers_are_checked() {
    assert_error(&with_line(2, "Foo: 1"), 2, 1, "unknown header `Foo:`");
    assert_error(
        &with_line(1, "HOA: v2"),
        1,
        6,
        "unsupported HOA version `v2`",
    );
    assert_error(
        &with_line(5, "acc-name: Buchi"),
        6,
        1,
        "missing `Acceptance:`",
    );
    assert_error(&with_line(3, "States: 3"), 3, 1, "`States:` is given twice");
    assert_error(
        &with_line(6, "State: 0"),
        6,
        1,
        "missing `--BODY--` before `State:`",
    );
    assert_error(&with_line(1, "HOA:"), 2, 1, "expected the format version");
    assert_error(
        &with_line(1, "States: 3"),
        1,
        1,
        "expected `HOA:`, found `States:`",
    );
}

#[test]
fn edge_labels_must_be_used_consistently() {
    // Implicit labels need 2^|AP| = 2 edges.
    let one_edge = with_line(8, "1").replace("[!0] 2\n", "");
    assert_error(&one_edge, 7, 1, "implicit labels need exactly 2^1 edges");
    let three_edges = with_line(8, "1 2 1").replace("[!0] 2\n", "");
    assert_error(&three_edges, 8, 5, "too many edges");
    assert_error(&with_line(9, "2"), 9, 1, "edge without a label");
    assert_error(
        &with_line(8, "1"),
        9,
        1,
        "labelled edge in a state whose first edge",
    );
    assert_error(
        &BASE.replace("State: 0\n", "State: [t] 0\n"),
        8,
        1,
        "labelled edge in a state that has a state label",
    );
    assert_error(
        &with_line(7, "[0] 1"),
        7,
        1,
        "edge before the first `State:`",
    );
}

#[test]
fn empty_and_aborted_inputs_have_no_automaton() {
    assert_error("", 1, 1, "expected `HOA:`, found the end of the input");
    assert_error("  /* only a comment */\n", 2, 1, "expected `HOA:`");
    assert_error(
        "HOA: v1 States: 3 --ABORT--\n",
        1,
        19,
        "every automaton of the input was aborted",
    );
}

#[test]
fn errors_in_a_later_automaton_are_located_in_it() {
    let text = BASE.to_string() + &with_line(8, "[0] 9");
    assert_error(&text, 14 + 8, 5, "state 9 does not exist");
}

/// The errors of `text`, each as `LINE:COL: message`.
fn errors(text: &str) -> Vec<String> {
    let errors = hoa::parse(text).expect_err("the text should be rejected");
    errors.iter().map(ToString::to_string).collect()
}

#[test]
fn every_error_is_reported_and_reading_resumes_after_each() {
    let text = "\
HOA: v1
States: 3
Start: 0
AP: 1 \"a\"
foo: 1 2 3
Acceptance: 1 Inf(0)
--BODY--
State: 0
[0] 1
[0] 2
[!0] 2 {3}
[0 & ] 1
State: 5
[t] 1
State: 1 {0}
[t] 1
2
State: 2
[t] 2 & 1
--END--
HOA: v1
Start: 0
Start: 1
Acceptance: 1 Inf(0)
Tool: \"x\"
--BODY--
State: 0
[t] 0 $
--END--
HOA: v2
garbage
--END--
";
    assert_eq!(
        errors(text),
        [
            "10:1: nondeterministic: this edge's label overlaps that of the edge at 9:1 (state 0)",
            "11:9: acceptance set 3 does not exist (`Acceptance:` declares 1 set)",
            "12:6: expected a proposition number, an alias, `t`, `f`, `!` or `(` in the label, \
             found `]`",
            "13:8: state 5 does not exist (`States: 3`)",
            "17:1: edge without a label in a state whose first edge has one",
            "19:7: universal branching (`&` in an edge's target) is not supported: a DFA has one \
             successor per letter",
            "23:8: several initial states (0 and 1): a DFA has exactly one",
            "25:1: unknown header `Tool:` (a header starting with an upper-case letter may change \
             the automaton's meaning, so it cannot be ignored)",
            "30:6: unsupported HOA version `v2` (this reader knows v1)",
        ]
    );
    // Not reported: the edge of the nonexistent state 5 (line 14), the body of the automaton
    // whose header is wrong (the `$` on line 28), the rest of the v2 automaton.
}

#[test]
fn an_aborted_automaton_takes_its_errors_and_a_broken_header_hides_the_body() {
    let text = "\
HOA: v1
Start: 0
AP: 1 \"a\"
Acceptance: 1 Inf(0)
--BODY--
State: 0
[0] 0
[0] 0
--ABORT--
HOA: v1
States: x
Start: 0
Acceptance: 1 Inf(0)
--BODY--
State: 0
[7] 0
--END--
";
    assert_eq!(
        errors(text),
        ["11:9: expected a number of states, found `x`"]
    );
    // A malformed item is not also reported as missing.
    assert_eq!(
        errors("HOA: v1\nStart: x\nAcceptance: 1 Fin(0)\n--BODY--\n--END--\n"),
        [
            "2:8: expected an initial state, found `x`",
            "3:15: unsupported acceptance condition `Fin(0)`: a DFA can be read only from `t`, \
             `f` or Büchi `Inf(n)` acceptance",
        ]
    );
}

#[test]
fn errors_beyond_the_limit_are_counted() {
    let mut text = String::from("HOA: v1\nStates: 1\nStart: 0\nAcceptance: 0 t\n--BODY--\n");
    for _ in 0..30 {
        text.push_str("State: 0 {}\n[t] 1\n");
    }
    text.push_str("--END--\n");
    let errors = hoa::parse(&text).unwrap_err();
    // Each `State: 0` after the first is declared twice; each edge goes to state 1.
    assert_eq!(errors.total(), 30 + 29);
    assert_eq!(errors.as_slice().len(), 20);
    assert_eq!(errors.first().position.line, 7);
    let limited = hoa::parse_with_limit(&text, 3).unwrap_err();
    assert_eq!(limited.as_slice().len(), 3);
}

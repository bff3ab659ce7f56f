//! `hypersynth hoa` end to end.

use assert_cmd::Command;
use predicates::prelude::*;

const FIXTURES: &str = "tests/fixtures/spot/hoa";

fn hypersynth() -> Command {
    Command::cargo_bin("hypersynth").unwrap()
}

/// An incomplete automaton for `a` (no edge on `!a`): its DFA has 3 states (the sink added) and
/// 4 edges (0 to 1 on `a` and to the sink on `!a`, one self-loop each on 1 and the sink).
const INCOMPLETE: &str = "HOA: v1 name: \"a\" States: 2 Start: 0 AP: 1 \"a\" \
                          Acceptance: 1 Inf(0) --BODY-- State: 0 [0] 1 State: 1 {0} [t] 1 --END--\n";

#[test]
fn summary_lines_per_automaton() {
    hypersynth()
        .args([
            "hoa",
            &format!("{FIXTURES}/0001.hoa"),
            &format!("{FIXTURES}/0002.hoa"),
        ])
        .assert()
        .success()
        .stdout(format!(
            "{FIXTURES}/0001.hoa: automaton 1: 4 states, 5 edges, 1 AP, 1 final state\n\
             {FIXTURES}/0002.hoa: automaton 1: 5 states, 14 edges, 4 APs, 1 final state\n"
        ));
}

#[test]
fn standard_input_with_several_automata_and_completion() {
    let stdin = format!("{INCOMPLETE}{INCOMPLETE}");
    hypersynth()
        .args(["hoa", "-"])
        .write_stdin(stdin)
        .assert()
        .success()
        .stdout(
            "<stdin>: automaton 1: 3 states, 4 edges, 1 AP, 1 final state, completed with a \
             rejecting sink\n\
             <stdin>: automaton 2: 3 states, 4 edges, 1 AP, 1 final state, completed with a \
             rejecting sink\n",
        );
}

/// The DOT text of Spot's `!b` (0004): start state 1 is not final despite its mark.
const NOT_B_DOT: &str = r#"digraph "!b" {
  label="!b";
  labelloc=t;
  rankdir=LR;
  node [shape=circle];
  start [shape=point, label=""];
  start -> 1;
  0 [shape=doublecircle];
  0 -> 0 [label="true"];
  1 -> 0 [label="!b"];
  1 -> 2 [label="b"];
  2 -> 2 [label="true"];
}
"#;

#[test]
fn dot_to_standard_output_and_to_a_file() {
    let input = format!("{FIXTURES}/0004.hoa");
    hypersynth()
        .args(["hoa", "--dot", &input])
        .assert()
        .success()
        .stdout(NOT_B_DOT);
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("not_b.dot");
    hypersynth()
        .args(["hoa", "--dot", &input, "-o"])
        .arg(&out)
        .assert()
        .success()
        .stdout("");
    assert_eq!(std::fs::read_to_string(&out).unwrap(), NOT_B_DOT);
}

#[test]
fn errors_are_located_and_leave_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.hoa");
    std::fs::write(
        &bad,
        "HOA: v1\nStates: 1\nStart: 0\nAcceptance: 1 Fin(0)\n--BODY--\nState: 0 [t] 0\n--END--\n",
    )
    .unwrap();
    let out = dir.path().join("out.txt");
    std::fs::write(&out, "previous").unwrap();
    // The good first file's line is not printed, and the existing output is left untouched.
    hypersynth()
        .args(["hoa", &format!("{FIXTURES}/0001.hoa")])
        .arg(&bad)
        .arg("-o")
        .arg(&out)
        .assert()
        .code(1)
        .stdout("")
        .stderr(format!(
            "hypersynth: error: {}:4:15: unsupported acceptance condition `Fin(0)`: a DFA can be \
             read only from `t`, `f` or Büchi `Inf(n)` acceptance\n    Acceptance: 1 Fin(0)\n\
             \x20                 ^\n",
            bad.display()
        ));
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "previous");
}

#[test]
fn missing_files_and_missing_arguments() {
    hypersynth()
        .args(["hoa", "no-such-file.hoa"])
        .assert()
        .code(1)
        .stderr(predicate::str::starts_with(
            "hypersynth: error: no-such-file.hoa: ",
        ));
    hypersynth().arg("hoa").assert().code(2);
}

#[test]
fn hoa_output_writes_the_minimal_complete_dfa_back() {
    // The incomplete automaton for `a` comes back complete, with the sink, and reads back to
    // the same DFA; Spot's 0002 (5 states) comes back minimal.
    let output = hypersynth()
        .args([
            "hoa",
            "--output-format",
            "hoa",
            "-",
            &format!("{FIXTURES}/0002.hoa"),
        ])
        .write_stdin(INCOMPLETE)
        .output()
        .unwrap();
    assert!(output.status.success());
    let text = String::from_utf8(output.stdout).unwrap();
    let written = hypersynth::automata::hoa::parse(&text).unwrap();
    assert_eq!(written.len(), 2);
    assert_eq!(written[0].name.as_deref(), Some("a"));
    assert!(written.iter().all(|automaton| automaton.sink.is_none()));
    assert_eq!(written[0].dfa.num_states(), 3);
    let original = hypersynth::automata::hoa::parse(
        &std::fs::read_to_string(format!("{FIXTURES}/0002.hoa")).unwrap(),
    )
    .unwrap()
    .remove(0)
    .dfa;
    let minimal = hypersynth::automata::minimize(&original);
    assert_eq!(written[1].dfa.num_states(), minimal.num_states());
    assert_eq!(
        hypersynth::automata::compare::equivalence_counterexample(&written[1].dfa, &original)
            .unwrap(),
        None
    );
    // `--output-format stats` is the default summary, `dot` the same as `--dot`.
    let stats = hypersynth()
        .args([
            "hoa",
            "--output-format",
            "stats",
            &format!("{FIXTURES}/0001.hoa"),
        ])
        .output()
        .unwrap();
    let default = hypersynth()
        .args(["hoa", &format!("{FIXTURES}/0001.hoa")])
        .output()
        .unwrap();
    assert_eq!(stats.stdout, default.stdout);
    let dot = hypersynth()
        .args([
            "hoa",
            "--output-format",
            "dot",
            &format!("{FIXTURES}/0001.hoa"),
        ])
        .output()
        .unwrap();
    let legacy = hypersynth()
        .args(["hoa", "--dot", &format!("{FIXTURES}/0001.hoa")])
        .output()
        .unwrap();
    assert_eq!(dot.stdout, legacy.stdout);
    assert!(dot.stdout.starts_with(b"digraph"));
}

#[test]
fn format_is_the_option_output_format_a_hidden_alias_and_d_h_short_forms() {
    let file = format!("{FIXTURES}/0001.hoa");
    let run = |args: &[&str]| {
        let output = hypersynth()
            .arg("hoa")
            .args(args)
            .arg(&file)
            .output()
            .unwrap();
        assert!(output.status.success(), "{args:?}: {output:?}");
        output.stdout
    };
    let dot = run(&["--format", "dot"]);
    assert!(dot.starts_with(b"digraph"));
    assert_eq!(run(&["--output-format", "dot"]), dot);
    assert_eq!(run(&["-d"]), dot);
    let hoa = run(&["--format", "hoa"]);
    assert!(hoa.starts_with(b"HOA: v1"));
    assert_eq!(run(&["-H"]), hoa);
    // As in Spot, the last choice counts.
    assert_eq!(run(&["-H", "-d"]), dot);
    assert_eq!(run(&["-d", "--format", "hoa"]), hoa);
    let help = hypersynth().args(["hoa", "--help"]).output().unwrap();
    let help = String::from_utf8(help.stdout).unwrap();
    assert!(help.contains("--format <FORMAT>"), "{help}");
    assert!(!help.contains("output-format"), "{help}");
}

#[test]
fn stats_lines_follow_spots_sequences() {
    // INCOMPLETE read as a DFA: 3 states, 4 edges, 1 AP, so 3 x 2^1 = 6 transitions (letters);
    // Spot's 0001: 4 states, 5 edges, 1 AP (summary_lines_per_automaton), 8 transitions.
    hypersynth()
        .args(["hoa", "--stats", "%F|%m|%s|%e|%t|%a|%x|100%%", "-"])
        .arg(format!("{FIXTURES}/0001.hoa"))
        .write_stdin(INCOMPLETE)
        .assert()
        .success()
        .stdout(format!(
            "-|a|3|4|6|1|1|100%\n{FIXTURES}/0001.hoa|XXFd|4|5|8|1|1|100%\n"
        ));
    hypersynth()
        .args(["hoa", "--stats", "%f", "-"])
        .write_stdin(INCOMPLETE)
        .assert()
        .code(2)
        .stderr(predicate::str::contains(
            "`%f` is not supported (use %s %e %t %a %x %m %F or %%)",
        ));
}

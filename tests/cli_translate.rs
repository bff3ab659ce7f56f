//! `hypersynth translate` end to end: output formats and files, translator selection (with the
//! stand-in tests/support/fake-ltl2tgba for Spot), and errors.

#![cfg(unix)]

use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};

use assert_cmd::Command;
use hypersynth::automata::compare::equivalence_counterexample;
use hypersynth::automata::hoa;
use predicates::prelude::*;

fn stand_in() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/support/fake-ltl2tgba")
}

/// The command with no way to find a real or stand-in ltl2tgba unless a test gives one.
fn hypersynth() -> Command {
    let mut command = Command::cargo_bin("hypersynth").unwrap();
    let empty = std::env::temp_dir().join("hypersynth-no-ltl2tgba-here");
    command.env_remove("HYPERSYNTH_LTL2TGBA").env("PATH", empty);
    command
}

/// `a U b` over [a, b], worked out by hand: the start state's edges in order of their smallest
/// letter (none, {a}, {b}) go to the rejecting sink (numbered 1 by the breadth-first search),
/// back to the start, and to the accepting sink (2).
const A_UNTIL_B: &str = "HOA: v1
name: \"a U b\"
States: 3
Start: 0
AP: 2 \"a\" \"b\"
acc-name: Buchi
Acceptance: 1 Inf(0)
properties: trans-labels explicit-labels state-acc complete
properties: deterministic terminal
--BODY--
State: 0
[!0&!1] 1
[0&!1] 0
[1] 2
State: 1
[t] 1
State: 2 {0}
[t] 2
--END--
";

#[test]
fn writes_the_minimal_dfa_as_hoa_and_names_the_translator() {
    hypersynth()
        .args(["translate", "a U b"])
        .assert()
        .success()
        .stdout(A_UNTIL_B)
        .stderr("hypersynth: translated with builtin (3 states)\n");
    hypersynth()
        .args(["translate", "--quiet", "--translator", "builtin", "a U b"])
        .assert()
        .success()
        .stdout(A_UNTIL_B)
        .stderr("");
}

#[test]
fn writes_dot_and_output_files_atomically() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.dot");
    hypersynth()
        .args(["translate", "--dot", "-o"])
        .arg(&out)
        .arg("F a")
        .assert()
        .success()
        .stdout("");
    let dot = std::fs::read_to_string(&out).unwrap();
    assert!(dot.starts_with("digraph \"Fa\" {"), "{dot}");
    assert!(dot.contains("1 [shape=doublecircle]"), "{dot}");
    // An error leaves no file behind, and an existing file untouched.
    let hoa_out = dir.path().join("out.hoa");
    hypersynth()
        .args(["translate", "-o"])
        .arg(&hoa_out)
        .arg("G a")
        .assert()
        .failure();
    assert!(!hoa_out.exists());
    std::fs::write(&hoa_out, "old").unwrap();
    hypersynth()
        .args(["translate", "-o"])
        .arg(&hoa_out)
        .arg("a U")
        .assert()
        .code(1);
    assert_eq!(std::fs::read_to_string(&hoa_out).unwrap(), "old");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
}

#[test]
fn errors_in_the_formula_are_located_with_a_caret() {
    hypersynth()
        .args(["translate", "F a & G b"])
        .assert()
        .code(1)
        .stdout("")
        .stderr(
            "hypersynth: error: argument 1:1:7: `G` (globally) is not allowed in a \
             syntactically co-safe formula\n    F a & G b\n          ^\n",
        );
    hypersynth()
        .args(["translate", "a U"])
        .assert()
        .code(1)
        .stderr(predicate::str::starts_with(
            "hypersynth: error: argument 1:1:4: ",
        ));
}

#[test]
fn spot_is_used_when_given_found_on_path_or_named_by_the_variable() {
    let builtin_output = hypersynth()
        .args(["translate", "--quiet", "--translator", "builtin", "d U !b"])
        .output()
        .unwrap()
        .stdout;
    let expected_stderr = format!(
        "hypersynth: translated with spot ({}) (3 states)\n",
        stand_in().display()
    );
    let from_option = hypersynth()
        .args(["translate", "--ltl2tgba"])
        .arg(stand_in())
        .arg("d U !b")
        .assert()
        .success()
        .stderr(expected_stderr.clone())
        .get_output()
        .stdout
        .clone();
    hypersynth()
        .env("HYPERSYNTH_LTL2TGBA", stand_in())
        .args([
            "translate",
            "--translator",
            "spot",
            "--translator-timeout",
            "1e15",
        ])
        .arg("d U !b")
        .assert()
        .success()
        .stderr(expected_stderr)
        .stdout(from_option.clone());
    // Spot's automaton, minimised, is the built-in one (guards may be written differently).
    let ours = &hoa::parse(std::str::from_utf8(&builtin_output).unwrap()).unwrap()[0].dfa;
    let theirs = &hoa::parse(std::str::from_utf8(&from_option).unwrap()).unwrap()[0].dfa;
    assert_eq!(ours.num_states(), theirs.num_states());
    assert_eq!(equivalence_counterexample(ours, theirs).unwrap(), None);

    // `ltl2tgba` on PATH (a script that runs the stand-in).
    let dir = tempfile::tempdir().unwrap();
    let wrapper = dir.path().join("ltl2tgba");
    let script = format!("#!/bin/sh\nexec '{}' \"$@\"\n", stand_in().display());
    std::fs::write(&wrapper, script).unwrap();
    std::fs::set_permissions(&wrapper, std::fs::Permissions::from_mode(0o755)).unwrap();
    let path = std::env::join_paths([dir.path(), Path::new("/usr/bin"), Path::new("/bin")]);
    hypersynth()
        .env("PATH", path.unwrap())
        .args(["translate", "d U !b"])
        .assert()
        .success()
        .stderr(predicate::str::starts_with(
            "hypersynth: translated with spot (",
        ))
        .stderr(predicate::str::contains("/ltl2tgba) (3 states)"));
}

#[test]
fn spot_failures_are_errors_with_its_stderr() {
    hypersynth()
        .args(["translate", "--translator", "spot", "F a"])
        .assert()
        .code(1)
        .stderr(predicate::str::starts_with(
            "hypersynth: error: Spot's ltl2tgba was not found",
        ));
    hypersynth()
        .args(["translate", "--ltl2tgba"])
        .arg(stand_in())
        .arg("F fail")
        .assert()
        .code(1)
        .stdout("")
        .stderr(predicate::str::ends_with(
            "failed (exit status: 2)\n  ltl2tgba: simulated failure\n",
        ));
    hypersynth()
        .args(["translate", "--translator-timeout", "0.2", "--ltl2tgba"])
        .arg(stand_in())
        .arg("F sleep")
        .assert()
        .code(1)
        .stderr(predicate::str::contains(
            "did not finish within 0.200 s and was killed\n  fake-ltl2tgba: sleeping\n",
        ));
    for bad in ["0", "-1", "soon", "NaN"] {
        hypersynth()
            .args(["translate", "--translator-timeout", bad, "F a"])
            .assert()
            .code(2);
    }
}

#[test]
fn shell_syntax_in_a_formula_is_never_executed() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("victim"), "still here").unwrap();
    let formula = "\"$(touch pwned)\" U \"; rm victim; touch pwned\"";
    hypersynth()
        .current_dir(dir.path())
        .args(["translate", "--ltl2tgba"])
        .arg(stand_in())
        .arg(formula)
        .assert()
        .code(1)
        .stderr(predicate::str::contains(format!(
            "\n  unknown formula: {formula}\n"
        )));
    assert!(!dir.path().join("pwned").exists());
    assert_eq!(
        std::fs::read_to_string(dir.path().join("victim")).unwrap(),
        "still here"
    );
    // The built-in translation takes such names as they are.
    hypersynth()
        .current_dir(dir.path())
        .args(["translate", "--quiet", formula])
        .assert()
        .success()
        .stdout(predicate::str::contains(
            "AP: 2 \"$(touch pwned)\" \"; rm victim; touch pwned\"",
        ));
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

const FORMULAS: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/fixtures/spot/formulas.ltl"
);
/// `hypersynth translate -q --translator builtin`.
fn builtin_translate() -> Command {
    let mut command = hypersynth();
    command.args(["translate", "-q", "--translator", "builtin"]);
    command
}

const SPOT_HOA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/spot/hoa");

/// Spot's automaton for line `n` (from 1) of the fixtures, read as a DFA and minimised.
fn spot_fixture(n: usize) -> hypersynth::automata::Dfa {
    let text = std::fs::read_to_string(format!("{SPOT_HOA}/{n:04}.hoa")).unwrap();
    hypersynth::automata::minimize(&hoa::parse(&text).unwrap().remove(0).dfa)
}

#[test]
fn a_file_of_300_formulas_becomes_one_stream_of_300_automata() {
    let output = builtin_translate().args(["-F", FORMULAS]).output().unwrap();
    assert!(output.status.success());
    let automata = hoa::parse(std::str::from_utf8(&output.stdout).unwrap()).unwrap();
    let formulas: Vec<&str> = include_str!("fixtures/spot/formulas.ltl").lines().collect();
    assert_eq!(automata.len(), 300);
    for (i, automaton) in automata.iter().enumerate() {
        assert_eq!(
            equivalence_counterexample(&automaton.dfa, &spot_fixture(i + 1)).unwrap(),
            None,
            "line {}: {}",
            i + 1,
            formulas[i]
        );
    }
}

#[test]
fn stats_give_spots_figures_one_line_per_automaton() {
    // Sizes against Spot's automata, minimised.
    let output = builtin_translate()
        .args(["--stats", "%s", "-F", FORMULAS])
        .output()
        .unwrap();
    assert!(output.status.success());
    let lines: Vec<String> = String::from_utf8(output.stdout)
        .unwrap()
        .lines()
        .map(str::to_string)
        .collect();
    let expected: Vec<String> = (1..=300)
        .map(|n| spot_fixture(n).num_states().to_string())
        .collect();
    assert_eq!(lines, expected);
    // Every sequence on `a U b`, worked out by hand (A_UNTIL_B above): 3 states; 5 edges;
    // 3 x 2^2 = 12 transitions (letters); 1 acceptance set (Inf(0)); 2 propositions.
    hypersynth()
        .args([
            "translate",
            "--translator",
            "builtin",
            "-f",
            "a U b",
            "-f",
            "X c",
        ])
        .args(["--stats", "%s %e %t %a %x [%f] 100%%"])
        .assert()
        .success()
        .stdout("3 5 12 1 2 [a U b] 100%\n4 5 8 1 1 [Xc] 100%\n")
        .stderr("hypersynth: translated 2 formulas with builtin (7 states in all)\n");
}

#[test]
fn an_unknown_stats_sequence_is_a_usage_error() {
    hypersynth()
        .args(["translate", "-f", "a", "--stats", "%s %q"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("`%q` is not supported"));
}

#[test]
fn one_bad_formula_in_a_batch_is_located_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let formulas = dir.path().join("tasks.ltl");
    std::fs::write(&formulas, "F a\n\n# safety is not co-safe\nG b\nc U d\n").unwrap();
    let out = dir.path().join("out.hoa");
    let file = formulas.to_str().unwrap();
    hypersynth()
        .args(["translate", "--translator", "builtin", "-F", file, "-o"])
        .arg(&out)
        .assert()
        .code(1)
        .stdout("")
        .stderr(format!(
            "hypersynth: error: {file}:4:1: `G` (globally) is not allowed in a syntactically \
             co-safe formula\n    G b\n    ^\n\
             hypersynth: error: 1 of 3 formulas could not be translated; nothing was written\n"
        ));
    assert!(!out.exists());
}

#[test]
fn formulas_come_from_standard_input_with_dash_capital_f() {
    let output = builtin_translate()
        .args(["-f", "F a", "-F", "-"])
        .write_stdin("a U b\n")
        .output()
        .unwrap();
    assert!(output.status.success());
    let automata = hoa::parse(std::str::from_utf8(&output.stdout).unwrap()).unwrap();
    let names: Vec<_> = automata
        .iter()
        .map(|a| a.name.as_deref().unwrap())
        .collect();
    assert_eq!(names, ["Fa", "a U b"]);
}

/// Spot's `autfilt` reads the 300-automaton stream (skipped without Spot).
#[test]
fn autfilt_reads_the_whole_stream() {
    let Some(autfilt) = std::env::var_os("PATH").and_then(|path| {
        std::env::split_paths(&path)
            .map(|dir| dir.join("autfilt"))
            .find(|candidate| candidate.is_file())
    }) else {
        eprintln!("skipped: Spot's autfilt is not on PATH");
        return;
    };
    let output = builtin_translate().args(["-F", FORMULAS]).output().unwrap();
    let count = Command::new(autfilt)
        .arg("--count")
        .write_stdin(output.stdout)
        .output()
        .unwrap();
    assert!(count.status.success(), "{count:?}");
    assert_eq!(String::from_utf8_lossy(&count.stdout).trim(), "300");
}

/// The whole batch through the Spot translator (the stand-in replays Spot's fixtures): the
/// same figures as the built-in translation, formula by formula, in one hypersynth process.
#[test]
fn both_translators_give_the_same_batch_figures() {
    let stats = |extra: &[&str]| {
        let output = hypersynth()
            .args(["translate", "-q", "--stats", "%s %e %x %f", "-F", FORMULAS])
            .args(extra)
            .output()
            .unwrap();
        assert!(output.status.success(), "{output:?}");
        String::from_utf8(output.stdout).unwrap()
    };
    let builtin = stats(&["--translator", "builtin"]);
    let spot = stats(&[
        "--translator",
        "spot",
        "--ltl2tgba",
        stand_in().to_str().unwrap(),
    ]);
    assert_eq!(builtin.lines().count(), 300);
    assert_eq!(builtin, spot);
}

#[test]
fn limits_end_exponential_translations_with_an_error_naming_the_limit() {
    // F(a & X^22 b) needs 2^22 + 1 states (the last 22 letters' `a`s, and the accepting sink).
    let window = format!("F(a & {}b)", "X".repeat(22));
    hypersynth()
        .args(["translate", "--translator", "builtin", &window])
        .assert()
        .code(1)
        .stdout("")
        .stderr(
            predicate::str::starts_with(
                "hypersynth: error: argument 1: the automaton needs more than 1048576 states \
                 before minimisation (the state limit); it had explored ",
            )
            .and(predicate::str::ends_with("(raise it with --max-states)\n")),
        );
    // X^3: 2^3 + 1 states after minimisation, so not within 8 (the limit counts the states
    // explored, before minimisation, which are at least as many).
    let small = "F(a & XXXb)";
    hypersynth()
        .args(["translate", "-q", "--max-states", "64", small])
        .assert()
        .success();
    hypersynth()
        .args(["translate", "--max-states", "8", small])
        .assert()
        .code(1)
        .stderr(predicate::str::contains("more than 8 states"));
    // The timeout is wall-clock time: a tiny one stops the built-in translation within its
    // first few thousand steps.
    hypersynth()
        .args(["translate", "--translator-timeout", "0.00001", &window])
        .assert()
        .code(1)
        .stderr(
            predicate::str::starts_with(
                "hypersynth: error: argument 1: the built-in translation did not finish before \
                 the time limit (",
            )
            .and(predicate::str::ends_with(
                "(raise it with --translator-timeout)\n",
            )),
        );
    // Spot's output counts too: `a U b` has 3 states.
    hypersynth()
        .args(["translate", "--max-states", "2", "--ltl2tgba"])
        .arg(stand_in())
        .arg("a U b")
        .assert()
        .code(1)
        .stderr(predicate::str::contains("more than 2 states"));
}

#[test]
fn an_output_pattern_writes_one_file_per_formula_named_by_its_sequences() {
    let dir = tempfile::tempdir().unwrap();
    let formulas = dir.path().join("tasks.ltl");
    std::fs::write(&formulas, "F a\n# a comment keeps its line\nX b\n").unwrap();
    let pattern = dir.path().join("phi%L.hoa");
    builtin_translate()
        .arg("-F")
        .arg(&formulas)
        .arg("-o")
        .arg(&pattern)
        .assert()
        .success()
        .stdout("");
    // Lines 1 and 3. By hand: `F a` waits for `a` (2 states); `X b` skips a letter, then needs
    // `b` (start, after one letter, accepted, rejected: 4 states).
    let read = |name: &str| hoa::parse(&std::fs::read_to_string(dir.path().join(name)).unwrap());
    let first = read("phi1.hoa").unwrap();
    let third = read("phi3.hoa").unwrap();
    assert_eq!(first.len(), 1);
    assert_eq!(first[0].name.as_deref(), Some("Fa"));
    assert_eq!(first[0].dfa.num_states(), 2);
    assert_eq!(third[0].name.as_deref(), Some("Xb"));
    assert_eq!(third[0].dfa.num_states(), 4);
    let mut names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|entry| entry.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    assert_eq!(names, ["phi1.hoa", "phi3.hoa", "tasks.ltl"]);
    // Formulas given directly are numbered; automata naming one file share it, in order;
    // `%%` is a `%`; the stats lines go where -o says.
    builtin_translate()
        .args(["-f", "F a", "-f", "X b", "-f", "a U b", "--stats", "%L:%s"])
        .arg("-o")
        .arg(dir.path().join("%s-states-100%%.txt"))
        .assert()
        .success();
    let text = |name: &str| std::fs::read_to_string(dir.path().join(name)).unwrap();
    assert_eq!(text("2-states-100%.txt"), "1:2\n");
    // `X b` (4 states) and `a U b` (3 states, A_UNTIL_B) name different files.
    assert_eq!(text("4-states-100%.txt"), "2:4\n");
    assert_eq!(text("3-states-100%.txt"), "3:3\n");
}

#[test]
fn output_patterns_are_checked_with_the_options() {
    for (pattern, message) in [
        (
            "phi%q.hoa",
            "`%q` is not supported (use %s %e %t %a %x %f %F %L or %%)",
        ),
        ("phi%", "the format ends with a lone `%`"),
        (">>all.hoa", "`>>` (append, in Spot) is not supported"),
    ] {
        hypersynth()
            .args(["translate", "-f", "F a", "-o", pattern])
            .assert()
            .code(2)
            .stderr(predicate::str::contains(message));
    }
}

#[test]
fn dash_d_and_dash_h_choose_dot_and_hoa_and_the_last_choice_counts() {
    let dot = builtin_translate().args(["-d", "a U b"]).output().unwrap();
    assert!(dot.status.success());
    assert!(
        String::from_utf8(dot.stdout)
            .unwrap()
            .starts_with("digraph \"a U b\"")
    );
    builtin_translate()
        .args(["-d", "-H", "a U b"])
        .assert()
        .success()
        .stdout(A_UNTIL_B);
    builtin_translate()
        .args(["-d", "--stats", "%s", "a U b"])
        .assert()
        .success()
        .stdout("3\n");
    builtin_translate()
        .args(["--stats", "%s", "-H", "a U b"])
        .assert()
        .success()
        .stdout(A_UNTIL_B);
}

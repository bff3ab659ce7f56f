//! `hypersynth ltl` end to end.

use assert_cmd::Command;
use predicates::prelude::*;

fn ltl() -> Command {
    let mut command = Command::cargo_bin("hypersynth").expect("the binary is built");
    command.arg("ltl");
    command
}

#[test]
fn co_safe_formulas_print_their_normal_form_and_exit_zero() {
    ltl()
        .args(["!(a -> G b)", "(!O U A) & (!O U B)", "XXFd", "\"a b\" U c"])
        .assert()
        .success()
        .stdout("co-safe\ta & F!b\nco-safe\t!O U A & !O U B\nco-safe\tXXFd\nco-safe\t\"a b\" U c\n")
        .stderr("");
}

#[test]
fn a_formula_that_is_not_co_safe_is_classified_explained_and_fails() {
    ltl()
        .args(["a U b", "F G a"])
        .assert()
        .code(1)
        .stdout("co-safe\ta U b\nnot-co-safe\tFGa\n")
        .stderr(
            "hypersynth: error: argument 2:1:3: `G` (globally) is not allowed in a \
             syntactically co-safe formula\n    F G a\n      ^\n",
        );
}

#[test]
fn a_syntax_error_is_one_located_line_with_a_caret_and_fails() {
    ltl()
        .args(["a", "a U U b"])
        .assert()
        .code(1)
        .stdout("co-safe\ta\nerror\targument 2:1:5\n")
        .stderr(
            "hypersynth: error: argument 2:1:5: expected a formula after `U`, found binary \
             operator `U`\n    a U U b\n        ^\n",
        );
}

#[test]
fn formulas_are_read_from_files_skipping_blanks_and_comments() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let path = dir.path().join("formulas.ltl");
    std::fs::write(
        &path,
        "# tasks\n\nF a\n  # indented comment\n!O U A\r\n(b\n",
    )
    .expect("write");
    let file = path.to_str().expect("UTF-8 path");
    ltl()
        .args(["-F", file])
        .assert()
        .code(1)
        .stdout(format!("co-safe\tFa\nco-safe\t!O U A\nerror\t{file}:6:3\n"))
        .stderr(format!(
            "hypersynth: error: {file}:6:3: missing `)` to close the `(` at column 1\n    (b\n      ^\n"
        ));
}

#[test]
fn standard_input_is_read_with_a_dash() {
    ltl()
        .args(["-F", "-"])
        .write_stdin("a xor b\nG a\n")
        .assert()
        .code(1)
        .stdout("co-safe\ta & !b | !a & b\nnot-co-safe\tGa\n")
        .stderr(predicate::str::starts_with(
            "hypersynth: error: <stdin>:2:1: `G`",
        ));
}

#[test]
fn json_output_has_one_object_per_formula() {
    let output = ltl()
        .args(["--format", "json", "b U a", "!(a U b)", "(("])
        .output()
        .expect("runs");
    assert_eq!(output.status.code(), Some(1));
    let lines: Vec<serde_json::Value> = String::from_utf8(output.stdout)
        .expect("UTF-8")
        .lines()
        .map(|line| serde_json::from_str(line).expect("one JSON object per line"))
        .collect();
    assert_eq!(
        lines,
        [
            serde_json::json!({
                "source": "argument 1", "input": "b U a", "class": "co-safe",
                "formula": "b U a", "atomic_propositions": ["b", "a"],
            }),
            serde_json::json!({
                "source": "argument 2", "input": "!(a U b)", "class": "not-co-safe",
                "formula": "!a R !b", "atomic_propositions": ["a", "b"],
                "error": {"line": 1, "column": 5, "message": "`U` occurs negated (under `!`, \
                 left of `->`, or in `<->`/`xor`), so it means `R` (release), which is not \
                 allowed in a syntactically co-safe formula"},
            }),
            serde_json::json!({
                "source": "argument 3", "input": "((", "class": "error",
                "error": {"line": 1, "column": 3,
                          "message": "expected a formula after `(`, found the end of the formula"},
            }),
        ]
    );
}

#[test]
fn an_exponential_normal_form_is_refused_not_built() {
    // The k-th `<->` from the inside has a normal form of S(k) = 2 S(k − 1) + 6 nodes (both
    // polarities of each operand, an `|` and two `&`), S(1) = 9: S(k) = 15 · 2^(k−1) − 6,
    // first above a million at k = 18 (1 966 074): the 23rd `<->` from the outside, at column
    // 4 + 7 · 22 = 158, is where the error points.
    let nested = format!("{}a{}", "(a <-> ".repeat(40), ")".repeat(40));
    ltl()
        .arg(&nested)
        .assert()
        .code(1)
        .stdout("error\targument 1:1:158\n")
        .stderr(predicate::str::contains(
            "argument 1:1:158: the positive normal form of this subformula would have up to \
             1966074 nodes (more than 1000000): nested `<->` and `xor` double their operands",
        ));
}

#[test]
fn a_large_formula_whose_normal_form_is_linear_is_accepted() {
    // 1.04 million nodes, normal form of the same size: above the absolute limit, but not a
    // blow-up.
    let dir = tempfile::tempdir().expect("temporary directory");
    let path = dir.path().join("large.ltl");
    std::fs::write(&path, format!("{}a\n", "!a & ".repeat(520_000))).expect("write");
    let output = ltl()
        .args(["-F", path.to_str().expect("UTF-8 path")])
        .output()
        .expect("runs");
    assert!(output.status.success());
    assert!(output.stdout.starts_with(b"co-safe\t!a & !a & "));
}

#[test]
fn an_unreadable_file_is_an_error() {
    ltl()
        .args(["-F", "/nonexistent/formulas.ltl"])
        .assert()
        .code(1)
        .stdout("")
        .stderr(predicate::str::starts_with(
            "hypersynth: error: /nonexistent/formulas.ltl: cannot read:",
        ));
}

#[test]
fn no_formula_at_all_is_a_usage_error() {
    ltl().assert().code(2);
}

#[test]
fn dash_f_is_a_formula_and_inputs_keep_their_command_line_order() {
    // As in Spot's tools: `-f FORMULA`, `-F FILE`, processed in the order given.
    let dir = tempfile::tempdir().expect("temporary directory");
    let path = dir.path().join("formulas.ltl");
    std::fs::write(&path, "F b\n").expect("write");
    let file = path.to_str().expect("UTF-8 path");
    ltl()
        .args(["-f", "a U c", "-F", file, "--formula", "X d", "G e"])
        .assert()
        .code(1)
        .stdout("co-safe\ta U c\nco-safe\tFb\nco-safe\tXd\nnot-co-safe\tGe\n")
        .stderr(predicate::str::starts_with(
            "hypersynth: error: argument 3:1:1: `G`",
        ));
}

#[test]
fn dash_o_writes_every_line_to_the_file_and_still_fails_on_a_bad_formula() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("classes.tsv");
    ltl()
        .args(["a U b", "F G a", "-o"])
        .arg(&path)
        .assert()
        .code(1)
        .stdout("")
        .stderr(predicate::str::contains("argument 2:1:3"));
    assert_eq!(
        std::fs::read_to_string(&path).unwrap(),
        "co-safe\ta U b\nnot-co-safe\tFGa\n"
    );
}

//! The main form from HOA automata: the cases of tests/regression/ (hand-derived figures, see
//! its README), the pipeline formula -> `translate` -> HOA file -> synthesis giving the formula
//! route's report, and the errors and usage rules of `--phi1-hoa`/`--phi2-hoa`.

use std::path::{Path, PathBuf};
use std::process::Output;

use assert_cmd::Command;
use serde_json::Value;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");
const CASE_STUDY: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/specs/case-study/arena.txt");

fn hypersynth(args: &[&str]) -> Output {
    Command::cargo_bin("hypersynth")
        .unwrap()
        .args(args)
        .output()
        .unwrap()
}

/// The JSON report of a successful run.
fn report(args: &[&str]) -> Value {
    let mut all = vec!["-q", "--format", "json", "--discount", "1"];
    all.extend_from_slice(args);
    let output = hypersynth(&all);
    assert!(
        output.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    serde_json::from_slice(&output.stdout).unwrap()
}

/// The report without what names the tasks' sources (a formula, or a file and `hoa`).
fn without_source_names(mut report: Value) -> Value {
    report["phi"] = Value::Null;
    for task in ["phi1", "phi2"] {
        report["automata"][task]["formula"] = Value::Null;
        report["automata"][task]["translator"] = Value::Null;
    }
    report
}

/// Checks that every key of `expected` is in `actual` with the same value; `initial.value`
/// within the solver's certified error.
fn assert_contains(actual: &Value, expected: &Value, path: &str) {
    match (actual, expected) {
        (_, Value::Object(fields)) => {
            for (key, value) in fields {
                assert_contains(&actual[key], value, &format!("{path}.{key}"));
            }
        }
        (Value::Number(a), Value::Number(e)) if path.ends_with(".initial.value") => {
            let (a, e) = (a.as_f64().unwrap(), e.as_f64().unwrap());
            assert!((a - e).abs() <= 1e-6, "{path}: {a} instead of {e}");
        }
        _ => assert_eq!(actual, expected, "{path}"),
    }
}

fn cases() -> Vec<PathBuf> {
    let mut cases: Vec<PathBuf> = std::fs::read_dir(Path::new(ROOT).join("tests/regression"))
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .filter(|path| path.join("expected.json").exists())
        .collect();
    cases.sort();
    cases
}

#[test]
fn every_regression_case_gives_its_hand_derived_figures_and_the_formula_routes_report() {
    let cases = cases();
    assert!(cases.len() >= 3, "{cases:?}");
    for case in cases {
        let spec: Value =
            serde_json::from_str(&std::fs::read_to_string(case.join("expected.json")).unwrap())
                .unwrap();
        let file = |name: &str| case.join(name).to_str().unwrap().to_string();
        let arena = file(spec["arena"].as_str().unwrap());
        let (phi1, phi2) = (file("phi1.hoa"), file("phi2.hoa"));
        let from_files = report(&["--phi1-hoa", &phi1, "--phi2-hoa", &phi2, &arena]);
        assert_contains(&from_files, &spec["expected"], &case.display().to_string());
        assert_eq!(from_files["automata"]["phi1"]["formula"], phi1.as_str());
        assert_eq!(from_files["automata"]["phi2"]["translator"], "hoa");
        assert_eq!(from_files["phi"], format!("{phi1} & {phi2}").as_str());

        let formulas = &spec["formulas"];
        let (phi, psi) = (
            formulas["phi"].as_str().unwrap(),
            formulas["psi"].as_str().unwrap(),
        );
        let from_formulas = report(&[
            "--phi",
            phi,
            "--psi",
            psi,
            "--translator",
            "builtin",
            &arena,
        ]);
        assert_eq!(
            without_source_names(from_files),
            without_source_names(from_formulas),
            "{}",
            case.display()
        );
    }
}

/// formula -> `translate -o FILE` -> `--phi1-hoa`/`--phi2-hoa`, against the formula route.
fn round_trip_through_translate(translator: &str) {
    let dir = tempfile::tempdir().unwrap();
    let (phi1, phi2) = (dir.path().join("phi1.hoa"), dir.path().join("phi2.hoa"));
    for (formula, path) in [("!O U A", &phi1), ("!O U B", &phi2)] {
        let output = hypersynth(&[
            "translate",
            "-q",
            "--translator",
            translator,
            "-f",
            formula,
            "-o",
            path.to_str().unwrap(),
        ]);
        assert!(output.status.success(), "{output:?}");
    }
    let (phi1, phi2) = (phi1.to_str().unwrap(), phi2.to_str().unwrap());
    let tasks = ["--phi", "(!O U A) & (!O U B)", "--psi", "!O U A"];
    let from_formulas = report(&[&tasks[..], &["--translator", translator, CASE_STUDY]].concat());
    let from_files = report(&["--phi1-hoa", phi1, "--phi2-hoa", phi2, CASE_STUDY]);
    assert_eq!(from_files["automata"]["phi2"]["formula"], phi2);
    assert_eq!(
        without_source_names(from_files),
        without_source_names(from_formulas.clone())
    );
    // One task from a file, the other from a formula.
    let mixed = report(&["--psi", "!O U A", "--phi2-hoa", phi2, CASE_STUDY]);
    assert_eq!(mixed["phi"], format!("(!O U A) & {phi2}").as_str());
    assert_eq!(mixed["automata"]["phi1"]["formula"], "!O U A");
    assert_eq!(
        without_source_names(mixed),
        without_source_names(from_formulas)
    );
}

#[test]
fn the_case_study_from_translated_automata_gives_the_formula_routes_report() {
    round_trip_through_translate("builtin");
}

#[test]
fn the_same_holds_with_spot_when_it_is_installed() {
    let found = std::env::var_os("PATH")
        .is_some_and(|path| std::env::split_paths(&path).any(|dir| dir.join("ltl2tgba").is_file()));
    if !found {
        eprintln!("skipped: Spot's ltl2tgba is not on PATH");
        return;
    }
    round_trip_through_translate("spot");
}

#[test]
fn a_task_automaton_can_come_from_standard_input() {
    let phi1 =
        std::fs::read_to_string(format!("{ROOT}/tests/regression/case-study/phi1.hoa")).unwrap();
    let output = Command::cargo_bin("hypersynth")
        .unwrap()
        .args(["-q", "--games-only", "--format", "json", "--phi1-hoa", "-"])
        .args(["--phi2", "!O U B", CASE_STUDY])
        .write_stdin(phi1)
        .output()
        .unwrap();
    assert!(output.status.success(), "{output:?}");
    let json: Value = serde_json::from_slice(&output.stdout).unwrap();
    assert_eq!(json["automata"]["phi1"]["formula"], "<stdin>");
    assert_eq!(json["phi"], "<stdin> & (!O U B)");
    assert_eq!(json["initial"]["label"], "WLL");
}

/// Exit status 2 and a message naming what is wrong.
fn assert_usage_error(args: &[&str], needle: &str) {
    let output = hypersynth(args);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(2), "{args:?}: {stderr}");
    assert!(stderr.contains(needle), "{args:?}: {stderr}");
    assert!(output.stdout.is_empty());
}

#[test]
fn tasks_must_come_from_exactly_one_place_each() {
    let hoa = format!("{ROOT}/tests/regression/case-study/phi1.hoa");
    let hoa = hoa.as_str();
    // --phi splits into phi1 and phi2; it cannot be combined with a task's automaton.
    assert_usage_error(&["--phi", "F a", "--phi1-hoa", hoa, CASE_STUDY], "--phi");
    assert_usage_error(&["--psi", "F a", "--phi1-hoa", hoa, CASE_STUDY], "--psi");
    assert_usage_error(&["--phi2", "F a", "--phi2-hoa", hoa, CASE_STUDY], "--phi2");
    assert_usage_error(&["--phi1-hoa", hoa, CASE_STUDY], "--phi2-hoa");
    assert_usage_error(&["--phi2-hoa", hoa, CASE_STUDY], "--psi");
    assert_usage_error(
        &["--phi1-hoa", "-", "--phi2-hoa", "-", CASE_STUDY],
        "standard input",
    );
}

#[test]
fn a_bad_task_automaton_is_located_in_its_file() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.hoa");
    std::fs::write(
        &bad,
        "HOA: v1\nStates: 1\nStart: 0\nAcceptance: 1 Fin(0)\n--BODY--\n--END--\n",
    )
    .unwrap();
    let bad = bad.to_str().unwrap();
    let output = hypersynth(&["--phi1-hoa", bad, "--phi2", "F B", CASE_STUDY]);
    assert_eq!(output.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.starts_with(&format!("hypersynth: error: {bad}:4:")),
        "{stderr}"
    );
    assert!(output.stdout.is_empty());

    // Two automata in one file: which one is meant is not guessed.
    let two = dir.path().join("two.hoa");
    let one =
        std::fs::read_to_string(format!("{ROOT}/tests/regression/case-study/phi1.hoa")).unwrap();
    std::fs::write(&two, format!("{one}{one}")).unwrap();
    let two = two.to_str().unwrap();
    let output = hypersynth(&["--phi1-hoa", two, "--phi2", "F B", CASE_STUDY]);
    assert_eq!(output.status.code(), Some(1));
    assert_eq!(
        String::from_utf8_lossy(&output.stderr),
        format!("hypersynth: error: {two}: expected one automaton, found 2\n")
    );
}

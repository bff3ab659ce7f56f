//! Maps on the command line: `gridworld --map`, and maps wherever an arena is read.

use assert_cmd::Command;
use predicates::prelude::*;

fn hypersynth() -> Command {
    Command::cargo_bin("hypersynth").unwrap()
}

const MAP: &str = "specs/case-study/map.txt";
const ARENA: &str = "specs/case-study/arena.txt";
const TASKS: [&str; 4] = ["--phi", "(!O U A) & (!O U B)", "--psi", "!O U A"];

#[test]
fn the_case_study_map_yields_exactly_the_bundled_arena() {
    let committed = std::fs::read_to_string(ARENA).unwrap();
    hypersynth()
        .args(["gridworld", "--map", MAP])
        .assert()
        .success()
        .stdout(committed.clone());
    // From standard input too.
    hypersynth()
        .args(["gridworld", "--map", "-"])
        .write_stdin(std::fs::read_to_string(MAP).unwrap())
        .assert()
        .success()
        .stdout(committed);
}

/// The stdout of `hypersynth ARGS INPUT`, which must succeed.
fn stdout(args: &[&str], input: &str) -> String {
    let output = hypersynth().args(args).arg(input).output().unwrap();
    assert!(output.status.success(), "{args:?} {input} failed");
    String::from_utf8(output.stdout).unwrap()
}

#[test]
fn a_map_reads_like_its_arena_everywhere() {
    for args in [
        &["arena", "--format", "json"][..],
        &[&TASKS[..], &["--games-only", "--translator", "builtin"]].concat(),
        &[
            &TASKS[..],
            &["--translator", "builtin", "--discount", "0.99"],
        ]
        .concat(),
    ] {
        assert_eq!(stdout(args, MAP), stdout(args, ARENA), "{args:?}");
    }
}

#[test]
fn map_errors_name_the_file_line_and_column_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let map = dir.path().join("bad.txt");
    std::fs::write(&map, "hypersynth map v1\ngrid\n@r . .\n. ? @a\n").unwrap();
    let out = dir.path().join("arena.txt");
    let shown = map.display().to_string();
    let expected = format!(
        "hypersynth: error: {shown}:4:3: unknown cell `?`: expected `.` (free), `O` (obstacle), \
         `@r` (robot start), `@a` (adversary start), propositions, or several of the last \
         three joined by `+`\n"
    );
    hypersynth()
        .args(["gridworld", "--map"])
        .arg(&map)
        .arg("-o")
        .arg(&out)
        .assert()
        .code(1)
        .stdout("")
        .stderr(expected.clone());
    assert!(!out.exists());
    for args in [&["arena"][..], &[&TASKS[..], &["--games-only"]].concat()] {
        hypersynth()
            .args(args)
            .arg(&map)
            .assert()
            .code(1)
            .stdout("")
            .stderr(expected.clone());
    }
    // A text that is neither: the arena reader's error.
    std::fs::write(&map, "hypersynth mop v1\n").unwrap();
    hypersynth()
        .arg("arena")
        .arg(&map)
        .assert()
        .code(1)
        .stderr(predicate::str::starts_with(format!(
            "hypersynth: error: {shown}:1:1: expected `propositions`"
        )));
}

#[test]
fn map_excludes_the_generators_options() {
    hypersynth()
        .args(["gridworld", "--map", MAP, "--size", "3x3"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("cannot be used with"));
}

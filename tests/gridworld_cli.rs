//! `hypersynth gridworld`: the committed case study, `-o`, and option errors.

use std::path::Path;

use assert_cmd::Command;
use predicates::prelude::*;

fn hypersynth() -> Command {
    Command::cargo_bin("hypersynth").unwrap()
}

/// The generator's parameters for the case study, as the Makefile passes them.
fn case_study_args() -> Vec<String> {
    std::fs::read_to_string("specs/case-study/gridworld.args")
        .unwrap()
        .split_whitespace()
        .map(str::to_string)
        .collect()
}

#[test]
fn the_committed_case_study_is_what_the_generator_produces_now() {
    let committed = std::fs::read_to_string("specs/case-study/arena.txt").unwrap();
    hypersynth()
        .arg("gridworld")
        .args(case_study_args())
        .assert()
        .success()
        .stdout(committed);
}

#[test]
fn output_to_a_file_equals_standard_output() {
    let args = [
        "gridworld",
        "--width",
        "3",
        "--height",
        "2",
        "--robot",
        "0,0",
    ];
    let args = [
        &args[..],
        &[
            "--adversary",
            "2,1",
            "--label",
            "G=2,0",
            "--collision",
            "label:C",
        ],
    ]
    .concat();
    let stdout = hypersynth().args(&args).output().unwrap().stdout;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("grid.txt");
    hypersynth()
        .args(&args)
        .arg("-o")
        .arg(&path)
        .assert()
        .success()
        .stdout("");
    assert_eq!(std::fs::read(&path).unwrap(), stdout);
    // 6 free cells: 2 × 6 × 6 states; the arena subcommand reads it back.
    hypersynth()
        .args(["arena", "--format", "json"])
        .arg(&path)
        .assert()
        .success()
        .stdout(predicate::str::contains("\"states\": 72,"))
        .stdout(predicate::str::contains(
            "\"propositions\": [\n    \"G\",\n    \"O\",\n    \"C\"\n  ]",
        ));
}

/// Entries of `dir`, to check that nothing (not even a temporary file) was left behind.
fn entries(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn an_invalid_gridworld_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let existing = dir.path().join("existing.txt");
    std::fs::write(&existing, "old contents").unwrap();
    let fresh = dir.path().join("fresh.txt");
    for target in [&existing, &fresh] {
        hypersynth()
            .args([
                "gridworld",
                "--size",
                "5x5",
                "--robot",
                "0,2",
                "--adversary",
                "1,1",
            ])
            .args(["--obstacle", "1,1", "-o"])
            .arg(target)
            .assert()
            .code(1)
            .stdout("")
            .stderr("hypersynth: error: the adversary's initial cell (1,1) is an obstacle\n");
    }
    assert_eq!(std::fs::read_to_string(&existing).unwrap(), "old contents");
    assert_eq!(entries(dir.path()), ["existing.txt"]);
    // An output directory that does not exist: an error naming the file, and no output.
    let missing = dir.path().join("missing").join("out.txt");
    hypersynth()
        .args([
            "gridworld",
            "--size",
            "2x1",
            "--robot",
            "0,0",
            "--adversary",
            "1,0",
            "-o",
        ])
        .arg(&missing)
        .assert()
        .code(1)
        .stderr(predicate::str::contains(missing.display().to_string()));
    assert_eq!(entries(dir.path()), ["existing.txt"]);
}

#[test]
fn option_errors_are_clear() {
    let base = ["gridworld", "--robot", "0,0", "--adversary", "1,0"];
    let cases: [(&[&str], i32, &str); 7] = [
        (
            &["--size", "2x"],
            2,
            "`2x` is not a size: expected WIDTHxHEIGHT",
        ),
        (&["--size", "2x2", "--width", "2"], 2, "cannot be used with"),
        (&["--width", "2"], 2, "--height"),
        (
            &["--size", "2x2", "--robot-moves", "N,UP"],
            2,
            "`UP` is not a move",
        ),
        (
            &["--size", "2x2", "--label", "A"],
            2,
            "`A` is not a labelled cell",
        ),
        (
            &["--size", "2x2", "--obstacle", "1;1"],
            2,
            "`1;1` is not a cell",
        ),
        (
            &["--size", "2x2", "--label", "A=2,0"],
            1,
            "cell of label A (2,0) is off the 2x2 grid",
        ),
    ];
    for (args, code, message) in cases {
        hypersynth()
            .args(base)
            .args(args)
            .assert()
            .code(code)
            .stdout("")
            .stderr(predicate::str::contains(message));
    }
}

#[test]
fn help_shows_the_default_moves_as_they_are_given_and_they_read_back() {
    let help = hypersynth().args(["gridworld", "--help"]).output().unwrap();
    let help = String::from_utf8(help.stdout).unwrap();
    assert!(help.contains("[default: N,S,E,W,NE,NW,SE,SW]"), "{help}");
    assert!(help.contains("[default: N,S,E,W,STAY]"), "{help}");
    // The defaults, given as shown, give the default arena.
    let base = [
        "gridworld",
        "--size",
        "3x2",
        "--robot-start",
        "0,0",
        "--adversary-start",
        "2,1",
    ];
    let default = hypersynth().args(base).output().unwrap();
    assert!(default.status.success());
    let explicit = hypersynth()
        .args(base)
        .args(["--robot-moves", "N,S,E,W,NE,NW,SE,SW"])
        .args(["--adversary-moves", "N,S,E,W,STAY"])
        .output()
        .unwrap();
    assert_eq!(explicit.stdout, default.stdout);
}

#[test]
fn the_start_cells_are_robot_start_and_adversary_start_with_the_old_names_hidden() {
    let help = hypersynth().args(["gridworld", "--help"]).output().unwrap();
    let help = String::from_utf8(help.stdout).unwrap();
    assert!(help.contains("--robot-start <X,Y>"), "{help}");
    assert!(help.contains("--adversary-start <X,Y>"), "{help}");
    assert!(!help.contains("--adversary <"), "{help}");
    let new = hypersynth()
        .args(["gridworld", "--size", "3x2", "--robot-start", "0,0"])
        .args(["--adversary-start", "2,1"])
        .output()
        .unwrap();
    assert!(new.status.success());
    // The start cells are in the generated header: robot (0,0), adversary (2,1).
    let text = String::from_utf8(new.stdout.clone()).unwrap();
    assert!(text.contains("# robot: starts at (0,0)"), "{text}");
    assert!(text.contains("# adversary: starts at (2,1)"), "{text}");
    let old = hypersynth()
        .args([
            "gridworld",
            "--size",
            "3x2",
            "--robot",
            "0,0",
            "--adversary",
            "2,1",
        ])
        .output()
        .unwrap();
    assert_eq!(old.stdout, new.stdout);
    // The committed parameters use the new names.
    assert!(case_study_args().contains(&"--adversary-start".to_string()));
}

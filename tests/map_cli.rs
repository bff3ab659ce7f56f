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
         three joined by `+`\n    . ? @a\n      ^\n"
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

#[test]
fn arena_dot_draws_small_arenas_and_refuses_large_ones() {
    // Robot moves E or W on a 3x1 strip, the adversary only stays: 2 x 3 x 3 = 18 states.
    let map = "hypersynth map v1\nrobot-moves E W\nadversary-moves STAY\ngrid\n@r A @a\n";
    let output = hypersynth()
        .args(["arena", "--dot", "-"])
        .write_stdin(map)
        .output()
        .unwrap();
    assert!(output.status.success());
    let dot = String::from_utf8(output.stdout).unwrap();
    assert!(dot.starts_with("digraph arena {\n") && dot.ends_with("}\n"));
    assert_eq!(dot.matches("shape=ellipse").count(), 9);
    assert_eq!(dot.matches("shape=box").count(), 9);
    // The robot at (1,0) is on A; the initial state is the robot's turn at (0,0), (2,0).
    assert!(dot.contains("s3 [shape=ellipse, label=\"((1,0),(0,0),0)\\n{A}\"];"));
    assert!(dot.contains("start -> s2;\n"));
    // Robot moves from (0,0) with the adversary on (2,0): only E (W is off the grid).
    assert!(dot.contains("s2 -> s14 [label=\"E\"];\n"));
    // By hand: robot moves (E or W, not off the strip nor onto the adversary) 1+0+1 from
    // (0,0) with the adversary on (0,0), (1,0), (2,0); 1+2+1 from (1,0); 1+0+1 from (2,0).
    // STAY exists in the 6 adversary states where the players do not share a cell. Plus the
    // arrow into the initial state.
    assert_eq!(dot.matches("-> ").count(), 1 + 8 + 6);
    hypersynth()
        .args(["arena", "--dot", MAP])
        .assert()
        .code(1)
        .stdout("")
        .stderr(predicate::str::contains(
            "map.txt: the arena has 800 states: DOT output is limited to 200",
        ));
}

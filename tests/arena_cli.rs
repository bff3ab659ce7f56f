//! `hypersynth arena`: statistics, warnings on stderr, located errors.

use assert_cmd::Command;
use predicates::prelude::*;

const CASE_STUDY: &str = "specs/case-study/arena.txt";

fn hypersynth() -> Command {
    Command::cargo_bin("hypersynth").unwrap()
}

/// A small arena worked out by hand: `r` robot, `e` adversary (stuck), `x` unreachable.
const SMALL: &str = "propositions A B\n\
                     initial r\n\
                     state r robot {A}\n\
                     state e adversary {A B}\n\
                     state x robot {}\n\
                     edge r go e\n\
                     edge r stay r\n\
                     edge x go r\n";

#[test]
fn prints_statistics_and_warnings_for_a_small_arena_from_stdin() {
    hypersynth()
        .args(["arena", "-"])
        .write_stdin(SMALL)
        .assert()
        .success()
        .stdout(
            "states           3 (robot 2, adversary 1)\n\
             transitions      3\n\
             actions          2: go stay\n\
             propositions     2: A B\n\
             distinct labels  3\n\
             initial state    r\n\
             stuck states     1 (robot 0, adversary 1)\n\
             unreachable      1\n",
        )
        .stderr(
            "hypersynth: warning: <stdin>: 1 adversary state has no enabled action (1 reachable \
             from the initial state): the adversary is stuck there, which counts as a win for \
             the robot; the first: `e` at 4:7 (`hypersynth arena --check <stdin>` lists them)\n\
             hypersynth: warning: <stdin>: 1 state is unreachable from the initial state; the \
             first: `x` at 5:7 (`hypersynth arena --check <stdin>` lists them)\n",
        );
    // --check lists them, one per line, located.
    hypersynth()
        .args(["arena", "--check", "-"])
        .write_stdin(SMALL)
        .assert()
        .success()
        .stdout(
            "<stdin>:4:7: adversary state `e` has no enabled action: the adversary is stuck \
             there, which counts as a win for the robot whatever its task\n\
             <stdin>:5:7: state `x` is unreachable from the initial state\n",
        )
        .stderr("");
}

#[test]
fn prints_statistics_as_json() {
    let output = hypersynth()
        .args(["arena", "--format", "json", "-"])
        .write_stdin(SMALL)
        .output()
        .unwrap();
    assert!(output.status.success());
    let stats: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    assert_eq!(
        stats,
        serde_json::json!({
            "states": 3,
            "robot_states": 2,
            "adversary_states": 1,
            "transitions": 3,
            "actions": ["go", "stay"],
            "propositions": ["A", "B"],
            "distinct_labels": 3,
            "initial": "r",
            "stuck_robot_states": 0,
            "stuck_adversary_states": 1,
            "unreachable_states": 1,
        })
    );
}

#[test]
fn summarises_the_case_study_one_line_per_kind_and_lists_on_request() {
    // Stuck: the robot on (0,0) (20 states), enclosed by obstacles, or on (4,4) with the
    // adversary on (3,3) (blocking its last exit: the one stuck state a play reaches); the
    // adversary on (0,0) or (4,4) sharing the cell with the robot (it cannot even stay).
    // Unreachable: 800 - 647, counted by the statistics.
    let stats = hypersynth()
        .args(["arena", CASE_STUDY])
        .assert()
        .success()
        .stdout(predicate::str::contains(
            "states           800 (robot 400, adversary 400)\n",
        ))
        .stdout(predicate::str::contains(
            "stuck states     23 (robot 21, adversary 2)\n",
        ))
        .stdout(predicate::str::contains(
            "initial state    \"((0,2),(4,2),0)\"\n",
        ))
        .stdout(predicate::str::contains("unreachable      153\n"));
    let stderr = String::from_utf8_lossy(&stats.get_output().stderr).to_string();
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 3, "{stderr}");
    for (line, start) in lines.iter().zip([
        "21 robot states have no enabled action (1 reachable from the initial state)",
        "2 adversary states have no enabled action (0 reachable from the initial state)",
        "153 states are unreachable from the initial state",
    ]) {
        assert!(
            line.starts_with(&format!("hypersynth: warning: {CASE_STUDY}: {start}")),
            "{line}"
        );
    }
    let listing = hypersynth()
        .args(["arena", "--check", CASE_STUDY])
        .assert()
        .success()
        .stderr("");
    let listing = String::from_utf8_lossy(&listing.get_output().stdout).to_string();
    assert_eq!(listing.lines().count(), 21 + 2 + 153);
    let reachable_stuck = "specs/case-study/arena.txt:2227:7: robot state `\"((4,4),(3,3),0)\"` \
                           has no enabled action";
    assert!(
        listing
            .lines()
            .any(|line| line.starts_with(reachable_stuck))
    );
    // A map: the same states, by name (its arena has no text to point into).
    let map_listing = hypersynth()
        .args(["arena", "--check", "specs/case-study/map.txt"])
        .assert()
        .success();
    let map_listing = String::from_utf8_lossy(&map_listing.get_output().stdout).to_string();
    let unlocated: Vec<String> = listing
        .lines()
        .map(|line| {
            let (_, rest) = line.split_once(": ").unwrap();
            format!("specs/case-study/map.txt: {rest}")
        })
        .collect();
    assert_eq!(map_listing.lines().collect::<Vec<_>>(), unlocated);
}

#[test]
fn errors_name_the_file_line_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.txt");
    std::fs::write(&path, "initial s0\nstate s0 robot {A\n").unwrap();
    let shown = path.display().to_string();
    hypersynth()
        .arg("arena")
        .arg(&path)
        .assert()
        .code(1)
        .stdout("")
        .stderr(format!(
            "hypersynth: error: {shown}:2:18: expected a proposition or `}}`, found end of line\n\
             \x20   state s0 robot {{A\n\
             \x20                    ^\n"
        ));
    hypersynth()
        .args(["arena", "-"])
        .write_stdin("initial nowhere\n")
        .assert()
        .code(1)
        .stderr(
            "hypersynth: error: <stdin>:1:9: state `nowhere` is not defined\n    initial \
             nowhere\n            ^\n",
        );
}

#[test]
fn every_error_of_a_file_is_printed_in_file_order_with_its_caret() {
    // Pass one finds the label and the late `actions` line, pass two the undefined states.
    let text = "initial s0\n\
                state s0 robot {A\n\
                edge s0 go s1\n\
                state s2 adversary {}\n\
                edge s2 stay s3\n\
                actions go stay\n";
    hypersynth()
        .args(["arena", "-"])
        .write_stdin(text)
        .assert()
        .code(1)
        .stdout("")
        .stderr(
            "hypersynth: error: <stdin>:2:18: expected a proposition or `}`, found end of line\n\
             \x20   state s0 robot {A\n\
             \x20                    ^\n\
             hypersynth: error: <stdin>:3:12: state `s1` is not defined\n\
             \x20   edge s0 go s1\n\
             \x20              ^\n\
             hypersynth: error: <stdin>:5:14: state `s3` is not defined\n\
             \x20   edge s2 stay s3\n\
             \x20                ^\n\
             hypersynth: error: <stdin>:6:1: `actions` must come before the first `state` or \
             `edge` line (line 2)\n\
             \x20   actions go stay\n\
             \x20   ^\n",
        );
}

#[test]
fn beyond_twenty_errors_the_others_are_counted() {
    let text: String = std::iter::once("initial s0\nstate s0 robot {}\n".to_string())
        .chain((0..25).map(|i| format!("edge s0 go{i} t{i}\n")))
        .collect();
    let assert = hypersynth()
        .args(["arena", "-"])
        .write_stdin(text)
        .assert()
        .code(1);
    let stderr = String::from_utf8(assert.get_output().stderr.clone()).unwrap();
    let errors: Vec<&str> = stderr
        .lines()
        .filter(|line| line.starts_with("hypersynth: error: "))
        .collect();
    assert_eq!(errors.len(), 21);
    assert_eq!(
        errors[0],
        "hypersynth: error: <stdin>:3:13: state `t0` is not defined"
    );
    assert_eq!(
        errors[19],
        "hypersynth: error: <stdin>:22:14: state `t19` is not defined"
    );
    assert_eq!(
        errors[20],
        "hypersynth: error: <stdin>: 5 more errors not shown"
    );
}

#[test]
fn a_missing_file_is_an_error_naming_it() {
    hypersynth()
        .args(["arena", "no/such/arena.txt"])
        .assert()
        .code(1)
        .stderr(predicate::str::starts_with(
            "hypersynth: error: no/such/arena.txt: ",
        ));
}

#[test]
fn dash_o_writes_the_statistics_to_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("stats.json");
    hypersynth()
        .args(["arena", CASE_STUDY, "--format", "json", "-o"])
        .arg(&path)
        .assert()
        .success()
        .stdout("");
    let stats: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    // Counted in the file itself: one `state` line per state, one `edge` line per transition.
    let text = std::fs::read_to_string(CASE_STUDY).unwrap();
    let count = |keyword: &str| text.lines().filter(|l| l.starts_with(keyword)).count();
    assert_eq!(stats["states"], count("state "));
    assert_eq!(stats["transitions"], count("edge "));
}

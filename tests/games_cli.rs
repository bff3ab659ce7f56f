//! The main form with `--games-only` on the case study: the pinned text report, the JSON report
//! against the library run with hand-made DFAs, the strategy export, and formula errors.

use crate::common::{PAPER_TASKS, avoid_until};
use assert_cmd::Command;
use hypersynth::arena;
use hypersynth::game::{Hypergame, Partition, States};
use predicates::prelude::*;
use serde_json::Value;

const ARENA: &str = "specs/case-study/arena.txt";
const PHI: &str = "(!O U A) & (!O U B)";
const PSI: &str = "!O U A";

/// The case study's main form with the built-in translation (so the output does not depend on
/// whether Spot is installed), plus `extra`.
fn games(extra: &[&str]) -> Command {
    games_on(ARENA, extra)
}

/// [`games`] on another arena.
fn games_on(arena: impl AsRef<std::ffi::OsStr>, extra: &[&str]) -> Command {
    let mut command = Command::cargo_bin("hypersynth").unwrap();
    command
        .args([
            "--phi",
            PHI,
            "--psi",
            PSI,
            "--translator",
            "builtin",
            "--games-only",
        ])
        .args(extra)
        .arg(arena);
    command
}

fn json(extra: &[&str]) -> Value {
    let output = games(&[&["--format", "json"], extra].concat())
        .output()
        .unwrap();
    assert!(output.status.success());
    serde_json::from_slice(&output.stdout).unwrap()
}

#[test]
fn the_text_report_is_the_committed_snapshot() {
    let expected = std::fs::read_to_string("specs/case-study/games.txt").unwrap();
    games(&[])
        .assert()
        .success()
        .stdout(expected)
        // O is declared by the gridworld (its obstacles) though no state carries it: no warning.
        .stderr("");
}

#[test]
fn the_json_report_agrees_with_the_library_on_hand_made_automata() {
    let text = std::fs::read_to_string(ARENA).unwrap();
    let arena = arena::parse(&text).unwrap().arena;
    let (d1, d2) = (avoid_until("O", "A"), avoid_until("O", "B"));
    for (option, states) in [("full", States::Full), ("reachable", States::Reachable)] {
        let game = Hypergame::new(&arena, &d1, &d2, states).unwrap();
        let regions = crate::common::paper_regions(&game);
        let report = json(&["--states", option]);
        assert_eq!(report["states"], option);
        assert_eq!(report["product_states"], game.num_states());
        assert_eq!(report["product_edges"], game.num_edges());
        for (name, set) in PAPER_TASKS {
            assert_eq!(report["winning_region_sizes"][name], regions.win(set).len());
        }
        for (label, counts) in Partition::compute(&game, &regions).iter() {
            let entry = &report["partition"][label.code()];
            assert_eq!(entry["robot"], counts.robot);
            assert_eq!(entry["adversary"], counts.adversary);
            assert_eq!(entry["total"], counts.total);
        }
        // The built-in DFAs number their states differently: compare the label, not the name.
        assert_eq!(report["initial"]["label"], "WLL");
        assert!(
            report["initial"]["state"]
                .as_str()
                .unwrap()
                .starts_with("((0,2),(4,2),0)|")
        );
        assert_eq!(
            report["realizable"],
            serde_json::json!({"phi1": true, "phi2": false, "phi": false})
        );
    }
    assert_eq!(json(&[])["product_states"], 3200);
}

#[test]
fn the_strategy_export_moves_north_to_a_from_h0() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("strategy.json");
    games(&["--export-strategy", path.to_str().unwrap()])
        .assert()
        .success();
    let export: Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let h0 = export["initial"].as_str().unwrap();
    assert_eq!(export["states"], "full");
    // A is at (0,3), just north of the robot's (0,2): N is the only move that reaches it.
    assert_eq!(
        export["tasks"]["phi1"]["robot"][h0],
        serde_json::json!({"rank": 1, "actions": ["N"]})
    );
    assert_eq!(export["tasks"]["phi1"]["realizable"], true);
    // h0 is losing for phi: no robot strategy there.
    assert_eq!(export["tasks"]["phi"]["robot"].get(h0), None);
    assert_eq!(export["tasks"]["phi"]["realizable"], false);
    let robot_states = export["tasks"]["phi"]["robot"].as_object().unwrap().len();
    let adversary_states = export["tasks"]["phi"]["adversary"]
        .as_object()
        .unwrap()
        .len();
    // Win(phi) has 1025 robot and 872 adversary states (the snapshot's partition); the
    // adversary's strategy covers the other 400 × 4 - 872 adversary states.
    assert_eq!(robot_states, 1025);
    assert_eq!(adversary_states, 1600 - 872);
}

#[test]
fn a_psi_outside_phi_is_an_error_located_in_psi_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("strategy.json");
    Command::cargo_bin("hypersynth")
        .unwrap()
        .args(["--phi", PHI, "--psi", "!O U C", "--games-only"])
        .args(["--export-strategy", path.to_str().unwrap(), ARENA])
        .assert()
        .code(1)
        .stdout("")
        .stderr(
            "hypersynth: error: --psi:1:4: this conjunct of psi is not a conjunct of phi (psi \
             must be a part of phi's conjunction)\n    !O U C\n       ^\n",
        );
    assert!(!path.exists());
}

#[test]
fn formula_errors_name_their_option() {
    let run = |args: &[&str]| {
        Command::cargo_bin("hypersynth")
            .unwrap()
            .args(args)
            .args(["--games-only", "--translator", "builtin", ARENA])
            .assert()
            .code(1)
            .stdout("")
    };
    run(&["--phi", "(!O U A", "--psi", PSI])
        .stderr(predicate::str::starts_with("hypersynth: error: --phi:1:"));
    // A conjunct of phi that is not co-safe is reported where phi2 came from: --phi.
    run(&["--phi", "(!O U A) & G !O", "--psi", PSI]).stderr(predicate::str::starts_with(
        "hypersynth: error: --phi:1:12: `G` (globally) is not allowed",
    ));
    run(&["--phi", PHI, "--psi", PSI, "--phi2", "!O U A"]).stderr(predicate::str::starts_with(
        "hypersynth: error: --phi:1:16: this conjunct of phi is in neither psi nor phi2",
    ));
}

#[test]
fn an_explicit_phi2_gives_the_same_report() {
    let implicit = games(&[]).output().unwrap().stdout;
    let explicit = games(&["--phi2", "!O U B"]).output().unwrap().stdout;
    assert_eq!(
        String::from_utf8(explicit).unwrap(),
        String::from_utf8(implicit).unwrap()
    );
}

#[test]
fn the_implicit_engine_gives_the_committed_report_but_for_its_name() {
    let expected = std::fs::read_to_string("specs/case-study/games.txt")
        .unwrap()
        .replace("(full; explicit engine)", "(full; implicit engine)");
    games(&["--engine", "implicit"])
        .assert()
        .success()
        .stdout(expected);
    assert_eq!(json(&["--engine", "implicit"])["engine"], "implicit");
    assert_eq!(json(&["--engine", "explicit"])["engine"], "explicit");
}

/// With `--states reachable` the implicit engine gives the explicit engine's report but for
/// the engine's name, and the same strategies byte for byte: fewer states than the full
/// enumeration's 3 200, h0's entry the same (N reaches A).
#[test]
fn the_implicit_engine_gives_the_explicit_engines_reachable_report_and_strategies() {
    let dir = tempfile::tempdir().unwrap();
    let [explicit, implicit] = ["explicit", "implicit"].map(|engine| {
        let path = dir.path().join(format!("{engine}.json"));
        let output = games(&["--states", "reachable", "--engine", engine])
            .args(["--export-strategy", path.to_str().unwrap()])
            .output()
            .unwrap();
        assert!(output.status.success(), "{output:?}");
        let report = String::from_utf8(output.stdout).unwrap();
        (report, std::fs::read_to_string(&path).unwrap())
    });
    assert_eq!(
        implicit.0.replace("implicit engine", "explicit engine"),
        explicit.0
    );
    assert!(implicit.0.contains("(reachable from h0; implicit engine)"));
    assert!(implicit.1 == explicit.1, "the strategies differ");
    let export: Value = serde_json::from_str(&implicit.1).unwrap();
    assert_eq!(export["states"], "reachable");
    let h0 = export["initial"].as_str().unwrap();
    assert_eq!(
        export["tasks"]["phi1"]["robot"][h0],
        serde_json::json!({"rank": 1, "actions": ["N"]})
    );
    let reachable = json(&["--states", "reachable", "--engine", "implicit"]);
    let states = reachable["product_states"].as_u64().unwrap();
    assert!(0 < states && states < 3200, "{states}");
}

#[test]
fn a_model_that_fits_neither_engine_is_refused() {
    // A 30x30 map with A and B: 900 free cells, 2 · 900² arena states, 4 automaton pairs
    // reachable through the labels: 6 480 000 product states. The explicit engine's estimate
    // for the games is 90 bytes each, the implicit one's 4: neither fits in 20 MiB beside the
    // process itself.
    let mut map = String::from("hypersynth map v1\ngrid\n");
    for y in 0..30 {
        let row: Vec<&str> = (0..30)
            .map(|x| match (x, y) {
                (0, 0) => "@r",
                (29, 29) => "@a",
                (29, 0) => "A",
                (0, 29) => "B",
                _ => ".",
            })
            .collect();
        map.push_str(&row.join(" "));
        map.push('\n');
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("map.txt");
    std::fs::write(&path, map).unwrap();
    games_on(&path, &["--max-memory", "20M"])
        .assert()
        .code(1)
        .stdout("")
        .stderr(predicate::str::contains(
            "a product of 6480000 states (the explicit engine would need about 556 MiB) needs \
             about 24.7 MiB more",
        ));
}

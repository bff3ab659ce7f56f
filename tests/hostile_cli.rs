//! Hostile inputs through the command (the library's answers to them are the library's
//! `tests/hostile_inputs.rs`): a limit's error located in the formula on the command line, and
//! a parity of sixty propositions through `translate` and the main form.

use assert_cmd::Command;
use hypersynth::automata::hoa;
use hypersynth::ltl;
use hypersynth::testing::disjunction_of_next_steps;
use hypersynth::translate::{Builtin, TranslationLimits, Translator};

#[test]
fn the_command_line_points_at_the_subformula_whose_unfolding_is_too_large() {
    let text = format!("XX(a U b) | {}", disjunction_of_next_steps(10));
    Command::cargo_bin("hypersynth")
        .unwrap()
        .args([
            "translate",
            "--translator",
            "builtin",
            "--max-states",
            "100",
            &text,
        ])
        .assert()
        .code(1)
        .stdout("")
        .stderr(
            "hypersynth: error: argument 1:1:27: unfolding this subformula over the \
             propositions and the next step needs more than 800 BDD nodes (the node limit) (8 \
             per state of --max-states: raise that to raise it)\n    \
             XX(a U b) | F((p0 & X q0) | (p1 & X q1) | (p2 & X q2) | (p3 & X q3) | (p...\n    \
             \x20                         ^\n",
        );
    // In the main form the option names the formula.
    let phi = format!("(!O U A) & {}", disjunction_of_next_steps(10));
    Command::cargo_bin("hypersynth")
        .unwrap()
        .args(["--phi", &phi, "--psi", "!O U A", "--translator", "builtin"])
        .args(["--max-states", "100", "specs/case-study/arena.txt"])
        .assert()
        .code(1)
        .stdout("")
        .stderr(predicates::str::starts_with(
            "hypersynth: error: --phi:1:26: unfolding this subformula over the propositions and \
             the next step needs more than 800 BDD nodes",
        ));
}

/// A three-state arena carrying some of the chains' propositions.
const TINY_ARENA: &str = "initial s0\nstate s0 robot {}\nstate s1 adversary {a1 z}\n\
    state s2 robot {a2}\nedge s0 go s1\nedge s1 back s0\nedge s1 on s2\nedge s2 stay s2\n";

#[test]
fn a_parity_of_sixty_propositions_goes_through_translate_and_the_main_form() {
    let text: Vec<String> = (1..=60).map(|i| format!("a{i}")).collect();
    let formula = format!("F({})", text.join(" xor "));
    let output = Command::cargo_bin("hypersynth")
        .unwrap()
        .args(["translate", "-q", "--translator", "builtin", &formula])
        .output()
        .unwrap();
    assert!(output.status.success());
    let written = String::from_utf8(output.stdout).unwrap();
    // One alias per node of the start state's two guards, the parity and its complement (2
    // nodes per proposition but the last: 119 each).
    assert_eq!(written.matches("Alias: @").count(), 238, "{written}");
    let read = &hoa::parse(&written).unwrap()[0].dfa;
    let parsed = ltl::parse(&formula).unwrap();
    assert_eq!(
        read,
        &Builtin::new(TranslationLimits::default())
            .translate(&parsed)
            .unwrap()
    );
    // The main form: s1 carries a1 alone (odd), so the robot wins phi by going there.
    let directory = tempfile::tempdir().unwrap();
    let arena = directory.path().join("arena.txt");
    std::fs::write(&arena, TINY_ARENA).unwrap();
    let output = Command::cargo_bin("hypersynth")
        .unwrap()
        .args([
            "-q",
            "--translator",
            "builtin",
            "--games-only",
            "--phi",
            &formula,
        ])
        .args(["--psi", &formula])
        .arg(&arena)
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let report = String::from_utf8(output.stdout).unwrap();
    assert!(report.contains("realizable     phi: yes"), "{report}");
}

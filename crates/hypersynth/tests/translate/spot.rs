//! The Spot translator, exercised with a stand-in for `ltl2tgba` (tests/support/fake-ltl2tgba, a
//! shell script) so that every branch runs on machines without Spot: replayed fixture output,
//! failure, garbage, nondeterminism, extra automata or propositions, a flood of stderr, a hang,
//! and formulas that would do damage if they went through a shell. The test against the real
//! `ltl2tgba` skips (with a message) when it is not installed.

#![cfg(unix)]

use std::path::{Path, PathBuf};
use std::time::Duration;

use hypersynth::limits::Deadline;
use hypersynth::ltl;
use hypersynth::translate::spot::{self, LTL2TGBA_VARIABLE};
use hypersynth::translate::{
    Builtin, Spot, SpotError, TranslateError, TranslationLimits, Translator,
};

use crate::common::structural_difference;

const SUPPORT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tests/support");
const FIXTURES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tests/fixtures/spot");

fn stand_in() -> PathBuf {
    Path::new(SUPPORT).join("fake-ltl2tgba")
}

fn spot(timeout: Duration) -> Spot {
    Spot::new(stand_in(), timeout)
}

fn parsed(text: &str) -> ltl::Formula {
    ltl::parse(text).unwrap_or_else(|e| panic!("{text}: {e}"))
}

/// The error the stand-in's translation of `text` gives.
fn spot_error(text: &str) -> SpotError {
    match spot(Duration::from_secs(60)).translate(&parsed(text)) {
        Err(TranslateError::Spot(error)) => error,
        other => panic!("{text}: expected a Spot error, got {other:?}"),
    }
}

#[test]
fn the_stand_ins_formula_list_is_the_fixtures_as_printed() {
    let original = std::fs::read_to_string(format!("{FIXTURES}/formulas.ltl")).unwrap();
    let printed = std::fs::read_to_string(format!("{SUPPORT}/formulas-as-printed.ltl")).unwrap();
    assert_eq!(original.lines().count(), printed.lines().count());
    for (i, (text, line)) in original.lines().zip(printed.lines()).enumerate() {
        assert_eq!(
            parsed(text).to_string(),
            line,
            "line {} of tests/support/formulas-as-printed.ltl is out of date",
            i + 1
        );
    }
}

/// Every tenth fixture (a process per formula costs milliseconds; translate/fixtures.rs
/// compares all 300 in process).
#[test]
fn replayed_spot_output_gives_exactly_the_builtin_automaton() {
    let translator = spot(Duration::from_secs(60));
    assert_eq!(
        translator.name(),
        format!("spot ({})", stand_in().display())
    );
    let formulas = std::fs::read_to_string(format!("{FIXTURES}/formulas.ltl")).unwrap();
    let mut mismatches = Vec::new();
    for (i, text) in formulas.lines().enumerate().step_by(10) {
        let formula = parsed(text);
        let from_spot = translator.translate(&formula);
        let builtin = Builtin::default().translate(&formula).unwrap();
        match from_spot {
            Ok(dfa) => {
                if let Some(difference) = structural_difference(&dfa, &builtin) {
                    mismatches.push(format!("{} {text}: {difference}", i + 1));
                }
            }
            Err(error) => mismatches.push(format!("{} {text}: {error}", i + 1)),
        }
    }
    assert!(mismatches.is_empty(), "{}", mismatches.join("\n"));
}

#[test]
fn a_failing_process_is_reported_with_its_stderr() {
    let error = spot_error("F fail");
    assert!(
        matches!(&error, SpotError::Failed { status, stderr, .. }
            if status.code() == Some(2) && stderr == "ltl2tgba: simulated failure\n"),
        "{error:?}"
    );
    let message = error.to_string();
    assert!(
        message.ends_with("\n  ltl2tgba: simulated failure"),
        "{message}"
    );
    assert!(!message.lines().next().unwrap().contains("simulated"));
}

#[test]
fn output_that_is_not_one_deterministic_automaton_over_the_formulas_propositions_is_rejected() {
    for (text, expected) in [
        ("F garbage", "at 1:1 of its output"),
        ("F nondet", "nondeterministic"),
        ("F twice", "2 automata instead of one"),
        (
            "F stranger",
            "proposition `elsewhere` is not in the formula",
        ),
    ] {
        match spot_error(text) {
            SpotError::Output { reason, .. } => {
                assert!(reason.contains(expected), "{text}: {reason}")
            }
            other => panic!("{text}: {other:?}"),
        }
    }
}

#[test]
fn a_flood_on_stderr_does_not_block_the_process() {
    let dfa = spot(Duration::from_secs(60))
        .translate(&parsed("F chatty"))
        .unwrap();
    assert_eq!(dfa.aps(), ["chatty"]);
    assert_eq!(dfa.num_states(), 2);
    assert!(dfa.accepts([0, 1]) && !dfa.accepts([0, 0]));
}

#[test]
fn a_hanging_process_is_killed_at_the_timeout() {
    let error = spot(Duration::from_millis(300))
        .translate(&parsed("F sleep"))
        .unwrap_err();
    match &error {
        TranslateError::Spot(SpotError::Timeout {
            timeout, stderr, ..
        }) => {
            assert_eq!(*timeout, Duration::from_millis(300));
            assert_eq!(stderr, "fake-ltl2tgba: sleeping\n");
        }
        other => panic!("{other:?}"),
    }
    assert!(error.to_string().contains("did not finish within 0.300 s"));
}

#[test]
fn a_timeout_names_the_limit_as_set_however_much_of_it_was_left_when_spot_started() {
    // The limits' deadline of 0.3 s starts before the translator runs (as the command's does,
    // shared by all its formulas); by the time Spot starts, 0.1 s of it has gone.
    let limits =
        TranslationLimits::default().with_deadline(Deadline::after(Duration::from_millis(300)));
    let translator = spot(Duration::from_secs(60)).with_limits(limits);
    std::thread::sleep(Duration::from_millis(100));
    let error = translator.translate(&parsed("F sleep")).unwrap_err();
    match &error {
        TranslateError::Spot(SpotError::Timeout { timeout, .. }) => {
            assert_eq!(*timeout, Duration::from_millis(300));
        }
        other => panic!("{other:?}"),
    }
    assert!(error.to_string().contains("did not finish within 0.300 s"));
}

#[test]
fn a_missing_executable_cannot_start_and_non_co_safe_formulas_never_start_it() {
    let missing = Spot::new(
        PathBuf::from("/nonexistent/ltl2tgba"),
        Duration::from_secs(1),
    );
    assert!(matches!(
        missing.translate(&parsed("F a")),
        Err(TranslateError::Spot(SpotError::Start { .. }))
    ));
    assert!(matches!(
        missing.translate(&parsed("G a")),
        Err(TranslateError::NotCoSafe(_))
    ));
}

#[test]
fn shell_syntax_in_propositions_reaches_the_process_literally() {
    let dir = tempfile::tempdir().unwrap();
    let victim = dir.path().join("victim");
    std::fs::write(&victim, "still here").unwrap();
    let pwned = dir.path().join("pwned");
    let text = format!(
        "F \"$(touch {0})\" & X \"; rm -f {1}; touch {0}\" | \"`touch {0}`\"",
        pwned.display(),
        victim.display()
    );
    let formula = parsed(&text);
    let printed = formula.to_string();
    assert!(printed.contains("\"$(touch "));
    match spot_error(&text) {
        SpotError::Failed { stderr, .. } => {
            assert_eq!(stderr, format!("unknown formula: {printed}\n"))
        }
        other => panic!("{other:?}"),
    }
    assert!(!pwned.exists());
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "still here");
}

#[test]
fn spot_itself_agrees_with_the_builtin_translation() {
    let Some(ltl2tgba) = spot::locate_ltl2tgba(
        None,
        std::env::var_os(LTL2TGBA_VARIABLE).as_deref(),
        std::env::var_os("PATH").as_deref(),
    ) else {
        eprintln!("skipped: ltl2tgba not found (set {LTL2TGBA_VARIABLE} or add it to PATH)");
        return;
    };
    let translator = Spot::new(ltl2tgba, Duration::from_secs(60));
    let formulas = std::fs::read_to_string(format!("{FIXTURES}/formulas.ltl")).unwrap();
    let extra = ["!(a W b)", "Xa <-> Xb", "a -> F b", "\"x y\" U \"$(z)\""];
    let mut mismatches = Vec::new();
    for text in formulas.lines().chain(extra) {
        let formula = parsed(text);
        let builtin = Builtin::default().translate(&formula).unwrap();
        match translator.translate(&formula) {
            Ok(dfa) => {
                if let Some(difference) = structural_difference(&dfa, &builtin) {
                    mismatches.push(format!("{text}: {difference}"));
                }
            }
            Err(error) => mismatches.push(format!("{text}: {error}")),
        }
    }
    assert!(mismatches.is_empty(), "{}", mismatches.join("\n"));
}

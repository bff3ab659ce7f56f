//! The HOA regression tests of the built-in translation: for each of the 300 formulas of
//! tests/fixtures/spot, the built-in DFA accepts the same words as the DFA read from what Spot
//! 2.12.1's `ltl2tgba -D -C -S -B` printed, and has exactly as many states as that DFA once
//! minimised; when both list the propositions in the same order, the two minimal automata are
//! identical (canonical numbering). Every mismatch is reported, not only the first.

use hypersynth::automata::compare::equivalence_counterexample;
use hypersynth::automata::{hoa, minimize};
use hypersynth::ltl;
use hypersynth::translate::{Builtin, Translator};

use crate::common::structural_difference;

const FIXTURES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tests/fixtures/spot");

#[test]
fn builtin_translation_matches_spot_on_every_fixture() {
    let formulas = std::fs::read_to_string(format!("{FIXTURES}/formulas.ltl")).unwrap();
    let mut mismatches = Vec::new();
    let mut same_order = 0;
    for (i, text) in formulas.lines().enumerate() {
        let index = format!("{:04}", i + 1);
        let formula = ltl::parse(text).unwrap_or_else(|e| panic!("{index}: {e}"));
        let hoa_text = std::fs::read_to_string(format!("{FIXTURES}/hoa/{index}.hoa")).unwrap();
        let spot = hoa::parse(&hoa_text).unwrap_or_else(|e| panic!("{index}: {e}"))[0]
            .dfa
            .clone();
        let builtin = match Builtin::default().translate(&formula) {
            Ok(dfa) => dfa,
            Err(error) => {
                mismatches.push(format!("{index} {text}: not translated: {error}"));
                continue;
            }
        };
        match equivalence_counterexample(&builtin, &spot) {
            Ok(None) => {}
            Ok(Some(word)) => mismatches.push(format!(
                "{index} {text}: languages differ on {word} (built-in accepts: {})",
                word.accepted_by_left
            )),
            Err(error) => mismatches.push(format!("{index} {text}: {error}")),
        }
        let minimal_spot = minimize(&spot);
        if builtin.num_states() != minimal_spot.num_states() {
            mismatches.push(format!(
                "{index} {text}: {} states, minimised Spot automaton has {}",
                builtin.num_states(),
                minimal_spot.num_states()
            ));
        } else if builtin.aps() == spot.aps() {
            // Same propositions in the same order: the canonical numbering makes the two
            // minimal automata identical, edge by edge.
            same_order += 1;
            if let Some(difference) = structural_difference(&builtin, &minimal_spot) {
                mismatches.push(format!("{index} {text}: {difference}"));
            }
        }
    }
    assert_eq!(formulas.lines().count(), 300);
    eprintln!("{same_order} of 300 compared edge by edge (same proposition order as Spot)");
    assert!(
        mismatches.is_empty(),
        "{} mismatches:\n{}",
        mismatches.len(),
        mismatches.join("\n")
    );
}

//! LTL: parsing never panics; a parsed formula prints to text that parses back to the same
//! formula; a co-safe one translates within small limits (or reports a limit), and its DFA
//! survives the HOA writer and reader with the same language.
#![no_main]

use hypersynth::automata::{compare::equivalence_counterexample, hoa};
use hypersynth::ltl;
use hypersynth::translate::{Builtin, Translator};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some(text) = hypersynth_fuzz::text(data) else {
        return;
    };
    let Ok(formula) = ltl::parse(text) else {
        return;
    };
    let printed = formula.to_string();
    let again = ltl::parse(&printed).unwrap_or_else(|e| panic!("`{printed}` does not parse: {e}"));
    assert_eq!(again, formula, "`{text}` printed as `{printed}`");
    assert_eq!(again.to_string(), printed);
    let Ok(dfa) = Builtin::new(hypersynth_fuzz::limits()).translate(&formula) else {
        return;
    };
    let written = hoa::write(&dfa, Some(&printed)).expect("a translated DFA is terminal");
    let read = hoa::parse(&written).expect("written HOA reads back");
    assert_eq!(
        equivalence_counterexample(&read[0].dfa, &dfa).expect("same propositions"),
        None
    );
});

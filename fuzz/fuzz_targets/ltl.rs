//! LTL: parsing never panics; a parsed formula prints to text that parses back to the same
//! formula; a co-safe one translates within small limits (or reports a limit), and its DFA
//! written as HOA reads back as the same automaton. Every check is linear in the formula or
//! the automaton, so that the target runs at thousands of inputs a second: the language
//! checks of the translation live in the tests (`translate_semantics`, the naive
//! construction of `translate::builtin`, the Spot fixtures).
#![no_main]

use hypersynth::automata::hoa;
use hypersynth::ltl;
use hypersynth::translate::{Builtin, TranslateError, Translator};
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
    let dfa = match Builtin::new(hypersynth_fuzz::limits()).translate(&formula) {
        Ok(dfa) => dfa,
        Err(TranslateError::NotCoSafe(_) | TranslateError::TooManyPropositions(_)) => return,
        // A limit, with a message (formatting it must not panic either).
        Err(error) => {
            assert!(error.limit().is_some(), "{text}: {error}");
            let _ = error.to_string();
            return;
        }
    };
    let written = hoa::write(&dfa, Some(&printed)).expect("a translated DFA is terminal");
    let read = hoa::parse(&written).unwrap_or_else(|e| panic!("{written}\n{e}"));
    assert_eq!(read[0].dfa, dfa, "{written}");
});

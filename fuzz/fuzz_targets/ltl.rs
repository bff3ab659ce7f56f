//! LTL: parsing never panics; a parsed formula prints to text that parses back to the same
//! formula; a co-safe one translates within small limits (or reports a limit), and its DFA,
//! when small, written as HOA reads back as the same automaton. Every check is linear in the
//! formula or bounded by a size, so that the target runs at thousands of inputs a second: the
//! language checks of the translation live in the tests (`translate_semantics`, the naive
//! construction of `translate::builtin`, the Spot fixtures), and the reader and writer on
//! large automata are the `hoa` target's.
#![no_main]

use hypersynth::automata::hoa;
use hypersynth::ltl;
use hypersynth::translate::{Builtin, TranslateError, Translator};
use libfuzzer_sys::fuzz_target;

/// The most edges of a DFA written as HOA, and the longest text read back. A round trip costs
/// as much as the text, which grows with the edges times the cubes of their guards (up to 64
/// cubes of up to 64 literals each): a DFA of 4 states and 13 edges over 12 propositions
/// wrote 12 KB, and writing and reading it back took 15 million instructions, where the
/// whole target takes under half a million for most formulas of the Spot fixtures. Every DFA
/// of the Spot fixtures is within both bounds (the largest has 95 edges).
const ROUND_TRIP_EDGES: usize = 128;
const ROUND_TRIP_BYTES: usize = 4096;

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
    if dfa.num_edges() > ROUND_TRIP_EDGES {
        return;
    }
    let written = hoa::write(&dfa, Some(&printed)).expect("a translated DFA is terminal");
    if written.len() > ROUND_TRIP_BYTES {
        return;
    }
    let read = hoa::parse(&written).unwrap_or_else(|e| panic!("{written}\n{e}"));
    assert_eq!(read[0].dfa, dfa, "{written}");
});

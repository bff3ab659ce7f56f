//! HOA: reading never panics; every automaton read that the writer accepts (a good-prefix DFA
//! whose final states are closed) is written and read back as the same automaton, state by
//! state and edge by edge (a linear check, where a language comparison costs a product).
#![no_main]

use hypersynth::automata::hoa;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some(text) = hypersynth_fuzz::text(data) else {
        return;
    };
    let Ok(automata) = hoa::parse(text) else {
        return;
    };
    for automaton in automata {
        let dfa = automaton.dfa;
        let Ok(written) = hoa::write(&dfa, automaton.name.as_deref()) else {
            continue;
        };
        let read = hoa::parse(&written).unwrap_or_else(|e| panic!("{written}\n{e}"));
        assert_eq!(read.len(), 1);
        assert_eq!(read[0].dfa, dfa, "{written}");
    }
});

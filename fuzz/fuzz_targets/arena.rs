//! Arena: reading never panics; an arena read is written in canonical form and read back
//! equal, and writing that again gives the same text.
#![no_main]

use hypersynth::arena;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some(text) = hypersynth_fuzz::text(data) else {
        return;
    };
    let Ok(parsed) = arena::parse(text) else {
        return;
    };
    let written = arena::write(&parsed.arena);
    let again = arena::parse(&written).unwrap_or_else(|e| panic!("{written}\n{e}"));
    assert_eq!(again.arena, parsed.arena);
    assert_eq!(arena::write(&again.arena), written);
});

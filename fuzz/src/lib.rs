//! What the fuzz targets share: turning bytes into text, and the bounded translation limits.
//! Each target in `fuzz_targets/` feeds one reader and checks its round trip, except
//! `pipeline`, which runs small random problems through the whole main form.

use hypersynth::translate::Limits;

/// The input as text: readers take `&str`, so invalid UTF-8 is skipped (the CLI reports it
/// before any reader runs).
pub fn text(data: &[u8]) -> Option<&str> {
    std::str::from_utf8(data).ok()
}

/// Small counted limits, so that no input costs much more than a millisecond whatever it says
/// (at most 128 states and 10 000 units of work, minimisation included; over a corpus the
/// `ltl` target grew in 120 s, its checks took 93 µs an input on average and 1.1 ms at most,
/// uninstrumented): a formula that needs more is refused with a limit, which the targets
/// accept. Every formula of the Spot fixtures
/// translates within a quarter of them (the most work one needs is 2 665 units), and so does
/// every problem of the `pipeline` target (under 700 units).
pub fn limits() -> Limits {
    Limits::new(128, 10_000)
}

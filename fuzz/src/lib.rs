//! What the fuzz targets share: turning bytes into text, and the bounded translation limits.
//! Each target in `fuzz_targets/` feeds one reader and checks its round trip.

use hypersynth::translate::Limits;

/// The input as text: readers take `&str`, so invalid UTF-8 is skipped (the CLI reports it
/// before any reader runs).
pub fn text(data: &[u8]) -> Option<&str> {
    std::str::from_utf8(data).ok()
}

/// Small limits, so that one input costs milliseconds whatever it says.
pub fn limits() -> Limits {
    Limits::new(2_000, 200_000)
}

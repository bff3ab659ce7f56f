//! Deterministic finite automata over 2^AP with symbolic guards, minimisation, language
//! comparison, and the HOA and DOT formats.
//!
//! No algorithm here enumerates the 2^AP letters: guards are BDDs, and what must try every
//! letter tries one per letter class (the minterms of the guards, [`alphabet`]). Readers and
//! writers are bounded: the HOA reader's states and nesting, a HOA label past 64 cubes written
//! through aliases, DOT labels past 2^16 cubes refused.

pub mod alphabet;
pub mod compare;
mod dfa;
pub mod dot;
pub mod guard;
pub mod hoa;
mod minimize;
#[cfg(any(test, feature = "testing"))]
#[doc(hidden)]
pub mod testing;

pub use dfa::{Dfa, DfaError, DfaState};
pub use guard::{Cube, Guard, GuardDisplay, GuardStyle, MAX_PROPOSITIONS};
pub use minimize::minimize;
pub(crate) use minimize::minimize_within;

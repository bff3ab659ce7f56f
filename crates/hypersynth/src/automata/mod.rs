//! Deterministic finite automata over 2^AP with symbolic guards, minimisation, language
//! comparison, and the HOA and DOT formats.

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

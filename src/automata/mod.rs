//! Deterministic finite automata over 2^AP with symbolic guards, minimisation, language
//! comparison, and the HOA and DOT formats.

mod dfa;
pub mod guard;
mod minimize;

pub use dfa::{Dfa, DfaError, DfaState};
pub use guard::{Cube, Guard, MAX_PROPOSITIONS};
pub use minimize::minimize;

//! The HOA (Hanoi Omega-Automata, v1) format: reading deterministic terminal automata as DFAs of
//! good prefixes, and writing DFAs as Spot writes terminal automata.
//!
//! The subset read ([`parse()`]):
//! - every token of the format (nested comments, strings with escapes, `--ABORT--`, several
//!   automata in one text); `HOA: v1` (and `v1.x`);
//! - headers `States:` (optional), `Start:` (possibly repeated, but naming one state), `AP:`
//!   (optional), `Alias:` (defined before use), `Acceptance:` with condition `t`, `f` or
//!   `Inf(n)`, possibly parenthesised; `name:` is kept; `acc-name:`, `tool:`, `properties:` and
//!   any other header starting with a lower-case letter are ignored, an unknown header starting
//!   with an upper-case letter is an error;
//! - explicit edge labels, implicit labels (exactly 2^|AP| unlabelled edges, in the order of
//!   the valuations' bits), state labels; state-based and transition-based acceptance marks;
//!   edges labelled `f` (or any unsatisfiable label) are dropped.
//!
//! Rejected with a located error: universal branching, other acceptance conditions, several
//! initial states or none, overlapping labels in one state (nondeterminism, checked rather than
//! taken from `properties:`), references to undeclared states, propositions, aliases or
//! acceptance sets, and malformed text. An incomplete automaton is completed with a rejecting
//! sink, numbered after every HOA state. Final states: see `build`.

mod build;
mod lexer;
pub mod parse;
pub mod write;

pub use parse::{HoaAutomaton, HoaError, MAX_NESTING, MAX_STATES, parse, parse_with_limit};
pub use write::{WriteError, write};

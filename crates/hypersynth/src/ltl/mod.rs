//! Linear temporal logic: the formula tree, Spot's syntax (parser and printer), positive normal
//! form and the syntactic co-safety check.
//!
//! - [`parse`] reads Spot's LTL syntax into a [`Formula`], or gives its errors as located
//!   [`Diagnostics`](crate::diagnostic::Diagnostics) (several per formula: it recovers).
//! - `Display` for [`Formula`] prints Spot's syntax with minimal parentheses, and
//!   `parse(&f.to_string()) == f` for every well-formed formula.
//! - [`positive_normal_form`] pushes negations to the atoms; [`check_co_safe`] tells whether
//!   only `X F U M & |`, literals and constants remain, or names the offending operator.
//! - [`atomic_propositions`] lists the propositions in order of first appearance.
//!
//! Nothing in this module recurses on the depth of a formula, and the parser never panics.

mod formula;
mod normal;
mod parser;
mod printer;

pub use formula::{BinaryOp, Formula, FormulaKind, NaryOp, Span, UnaryOp};
pub use normal::{
    CoSafetyError, atomic_propositions, check_co_safe, co_safety_errors, positive_normal_form,
    positive_normal_form_blowup, positive_normal_form_size_bound,
};
pub use parser::{parse, parse_with_limit};

//! Linear temporal logic: the formula tree, Spot's syntax (parser and printer), positive normal
//! form and the syntactic co-safety check.
//!
//! - [`parse`] reads Spot's LTL syntax into a [`Formula`]; errors are [`ParseError`]s with a
//!   position and a caret context.
//! - `Display` for [`Formula`] prints Spot's syntax with minimal parentheses;
//!   `parse(&f.to_string()) == f`.

mod formula;
mod parser;
mod printer;

pub use formula::{BinaryOp, Formula, FormulaKind, NaryOp, Span, UnaryOp};
pub use parser::{ParseError, caret_context, parse};
pub use printer::is_bare_name;

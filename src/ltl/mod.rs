//! Linear temporal logic: the formula tree, Spot's syntax (parser and printer), positive normal
//! form and the syntactic co-safety check.

mod formula;

pub use formula::{BinaryOp, Formula, FormulaKind, NaryOp, Span, UnaryOp};

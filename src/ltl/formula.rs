//! The LTL abstract syntax tree.
//!
//! Conjunction and disjunction are n-ary and kept flat (an `And` never has an `And` operand),
//! because `&` and `|` are associative: long conjunctions then cost one level of nesting, and
//! printing and re-parsing gives back the same tree. Operand order is kept as written.
//! Every node remembers the span of the source text it came from, so that later checks (for
//! instance co-safety) can point at the offending operator; spans do not take part in equality
//! or hashing, so two formulas are equal when their trees are.

use std::hash::{Hash, Hasher};

/// Byte offsets `start..end` of a node in the text it was parsed from. `Span::default()` for
/// nodes built in code. For operator nodes, `start..end` covers the operator token itself.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Span {
    pub start: usize,
    pub end: usize,
}

/// Operators with one operand.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum UnaryOp {
    /// `!`, `~`
    Not,
    /// `X`
    Next,
    /// `F`, `<>`
    Finally,
    /// `G`, `[]`
    Globally,
}

/// Operators with exactly two operands.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum BinaryOp {
    /// `xor`, `^`
    Xor,
    /// `->`, `=>`
    Implies,
    /// `<->`, `<=>`
    Equiv,
    /// `U`
    Until,
    /// `R`
    Release,
    /// `W`
    WeakUntil,
    /// `M`
    StrongRelease,
}

/// Associative operators, kept flat with two or more operands.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum NaryOp {
    /// `&`, `&&`, `/\`
    And,
    /// `|`, `||`, `\/`
    Or,
}

#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum FormulaKind {
    /// `true`/`1` or `false`/`0`.
    Const(bool),
    /// An atomic proposition, by name (without quotes).
    Atom(String),
    Unary(UnaryOp, Box<Formula>),
    Binary(BinaryOp, Box<Formula>, Box<Formula>),
    /// Two or more operands, none of them itself the same `NaryOp`.
    Nary(NaryOp, Vec<Formula>),
}

/// An LTL formula: a node kind and the span of source text it was parsed from.
#[derive(Clone, Debug)]
pub struct Formula {
    pub kind: FormulaKind,
    pub span: Span,
}

impl PartialEq for Formula {
    fn eq(&self, other: &Self) -> bool {
        self.kind == other.kind
    }
}

impl Eq for Formula {}

impl Hash for Formula {
    fn hash<H: Hasher>(&self, state: &mut H) {
        self.kind.hash(state);
    }
}

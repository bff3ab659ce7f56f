//! The LTL abstract syntax tree.
//!
//! Conjunction and disjunction are n-ary and kept flat (an `And` never has an `And` operand),
//! because `&` and `|` are associative: long conjunctions then cost one level of nesting, and
//! printing and re-parsing gives back the same tree. Operand order is kept as written.
//! Every node remembers the span of the source text it came from, so that later checks (for
//! instance co-safety) can point at the offending operator; spans do not take part in equality
//! or hashing, so two formulas are equal when their trees are.
//!
//! Invariants (kept by the parser, the constructors and the normal forms; the fields are public,
//! so code that builds nodes by hand must keep them too):
//! - a [`FormulaKind::Nary`] node has at least two operands, none of them the same [`NaryOp`];
//! - nothing here recurses on the depth of the tree: `Clone`, `Drop`, `PartialEq`, `Hash`,
//!   `Debug` and every traversal use explicit stacks, so a formula nested 100000 deep (for
//!   instance 100000 `X` in a row) is as safe as a shallow one. The price is that `Formula`
//!   implements `Drop`, so its `kind` cannot be moved out by pattern matching: match on
//!   `&formula.kind`, or take it with [`Formula::into_kind`].

use std::fmt;
use std::hash::{Hash, Hasher};

/// Byte offsets `start..end` of a node in the text it was parsed from. `Span::default()` for
/// nodes built in code. For operator nodes, `start..end` covers the operator token itself (for
/// an n-ary node, the leftmost of its operator tokens); nodes made by a normal form carry the
/// span of the source operator they come from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Span {
    /// The offset of the node's first byte.
    pub start: usize,
    /// The offset just after the node's last byte.
    pub end: usize,
}

/// Operators with one operand.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum UnaryOp {
    /// `!`, `~`
    Not,
    /// `X`, `()`
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
    /// `->`, `=>`, `-->`
    Implies,
    /// `<->`, `<=>`, `<-->`
    Equiv,
    /// `U`
    Until,
    /// `R`, `V`
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
    /// `|`, `||`, `\/`, `+`
    Or,
}

impl UnaryOp {
    /// The operator as Spot prints it.
    pub fn symbol(self) -> &'static str {
        match self {
            UnaryOp::Not => "!",
            UnaryOp::Next => "X",
            UnaryOp::Finally => "F",
            UnaryOp::Globally => "G",
        }
    }
}

impl BinaryOp {
    /// The operator as Spot prints it.
    pub fn symbol(self) -> &'static str {
        match self {
            BinaryOp::Xor => "xor",
            BinaryOp::Implies => "->",
            BinaryOp::Equiv => "<->",
            BinaryOp::Until => "U",
            BinaryOp::Release => "R",
            BinaryOp::WeakUntil => "W",
            BinaryOp::StrongRelease => "M",
        }
    }
}

impl NaryOp {
    /// The operator as Spot prints it.
    pub fn symbol(self) -> &'static str {
        match self {
            NaryOp::And => "&",
            NaryOp::Or => "|",
        }
    }

    /// The value of the operator applied to no operands (its neutral element).
    pub fn identity(self) -> bool {
        self == NaryOp::And
    }
}

/// What a formula node is: a constant, an atom, or an operator with its operands.
#[derive(Debug, PartialEq, Eq, Hash)]
pub enum FormulaKind {
    /// `true`/`1` or `false`/`0`.
    Const(bool),
    /// An atomic proposition, by name (without quotes).
    Atom(String),
    /// A unary temporal or Boolean operator (`!`, `X`, `F`, `G`) and its operand.
    Unary(UnaryOp, Box<Formula>),
    /// A binary operator, its left operand, then its right operand.
    Binary(BinaryOp, Box<Formula>, Box<Formula>),
    /// Two or more operands, none of them itself the same `NaryOp`.
    Nary(NaryOp, Vec<Formula>),
}

/// An LTL formula: a node kind and the span of source text it was parsed from.
pub struct Formula {
    /// The operator (or constant, or atom) at the root, with its operands.
    pub kind: FormulaKind,
    /// Where the node's text is in the source (`Span::default()` for nodes built in code).
    pub span: Span,
}

impl Formula {
    /// The node `kind` at `span`.
    pub fn new(kind: FormulaKind, span: Span) -> Formula {
        Formula { kind, span }
    }

    /// `true` or `false`.
    pub fn constant(value: bool) -> Formula {
        Formula::new(FormulaKind::Const(value), Span::default())
    }

    /// An atomic proposition.
    pub fn atom(name: impl Into<String>) -> Formula {
        Formula::new(FormulaKind::Atom(name.into()), Span::default())
    }

    /// `op` applied to `operand`.
    pub fn unary(op: UnaryOp, operand: Formula) -> Formula {
        Formula::new(FormulaKind::Unary(op, Box::new(operand)), Span::default())
    }

    /// `X operand`.
    pub fn next(operand: Formula) -> Formula {
        Formula::unary(UnaryOp::Next, operand)
    }

    /// `F operand`.
    pub fn finally(operand: Formula) -> Formula {
        Formula::unary(UnaryOp::Finally, operand)
    }

    /// `G operand`.
    pub fn globally(operand: Formula) -> Formula {
        Formula::unary(UnaryOp::Globally, operand)
    }

    /// `left op right`.
    pub fn binary(op: BinaryOp, left: Formula, right: Formula) -> Formula {
        Formula::new(
            FormulaKind::Binary(op, Box::new(left), Box::new(right)),
            Span::default(),
        )
    }

    /// `left U right`.
    pub fn until(left: Formula, right: Formula) -> Formula {
        Formula::binary(BinaryOp::Until, left, right)
    }

    /// The n-ary `op` of `operands`, kept flat: operands that are themselves `op` are spliced
    /// in (one level: they are flat already). No operand gives the neutral constant, one
    /// operand gives that operand.
    pub fn nary(op: NaryOp, operands: Vec<Formula>) -> Formula {
        let mut flat = Vec::with_capacity(operands.len());
        for operand in operands {
            match operand.kind {
                FormulaKind::Nary(inner, _) if inner == op => {
                    if let FormulaKind::Nary(_, children) = operand.into_kind() {
                        flat.extend(children);
                    }
                }
                _ => flat.push(operand),
            }
        }
        match flat.len() {
            0 => Formula::constant(op.identity()),
            1 => flat
                .pop()
                .unwrap_or_else(|| Formula::constant(op.identity())),
            _ => Formula::new(FormulaKind::Nary(op, flat), Span::default()),
        }
    }

    /// Conjunction of `operands` (see [`Formula::nary`]).
    pub fn and(operands: Vec<Formula>) -> Formula {
        Formula::nary(NaryOp::And, operands)
    }

    /// Disjunction of `operands` (see [`Formula::nary`]).
    pub fn or(operands: Vec<Formula>) -> Formula {
        Formula::nary(NaryOp::Or, operands)
    }

    /// The same formula with its root's span replaced.
    pub fn with_span(mut self, span: Span) -> Formula {
        self.span = span;
        self
    }

    /// Takes the node kind out (`Formula` implements `Drop`, so it cannot be destructured).
    pub fn into_kind(mut self) -> FormulaKind {
        std::mem::replace(&mut self.kind, FormulaKind::Const(false))
    }

    /// The direct operands, left to right.
    pub fn children(&self) -> impl DoubleEndedIterator<Item = &Formula> {
        let (first, second, rest): (Option<&Formula>, Option<&Formula>, &[Formula]) =
            match &self.kind {
                FormulaKind::Const(_) | FormulaKind::Atom(_) => (None, None, &[]),
                FormulaKind::Unary(_, operand) => (Some(operand), None, &[]),
                FormulaKind::Binary(_, left, right) => (Some(left), Some(right), &[]),
                FormulaKind::Nary(_, operands) => (None, None, operands),
            };
        first.into_iter().chain(second).chain(rest.iter())
    }

    /// Bottom-up evaluation without recursion: `combine` receives each node and the results of
    /// its children (left to right).
    pub fn fold<'a, T>(&'a self, mut combine: impl FnMut(&'a Formula, Vec<T>) -> T) -> T {
        transform(
            self,
            (),
            |node, (), children| children.extend(node.children().map(|child| (child, ()))),
            |node, (), results| combine(node, results),
        )
    }

    /// The node with the same operator and span as `self` but with `children` as operands
    /// (as many as `self` has).
    pub(crate) fn rebuild(&self, children: Vec<Formula>) -> Formula {
        let mut children = children.into_iter();
        let mut next = || children.next().unwrap_or_else(|| Formula::constant(false));
        let kind = match &self.kind {
            FormulaKind::Const(value) => FormulaKind::Const(*value),
            FormulaKind::Atom(name) => FormulaKind::Atom(name.clone()),
            FormulaKind::Unary(op, _) => FormulaKind::Unary(*op, Box::new(next())),
            FormulaKind::Binary(op, _, _) => {
                let left = next();
                FormulaKind::Binary(*op, Box::new(left), Box::new(next()))
            }
            FormulaKind::Nary(op, operands) => {
                FormulaKind::Nary(*op, (0..operands.len()).map(|_| next()).collect())
            }
        };
        Formula::new(kind, self.span)
    }
}

/// Post-order traversal with explicit stacks. `expand` pushes the `(child, state)` pairs whose
/// results a node needs (a child may be listed several times, with different states);
/// `combine` turns the node and those results, in the same order, into the node's result.
pub(crate) fn transform<'a, S: Copy, T>(
    root: &'a Formula,
    state: S,
    mut expand: impl FnMut(&'a Formula, S, &mut Vec<(&'a Formula, S)>),
    mut combine: impl FnMut(&'a Formula, S, Vec<T>) -> T,
) -> T {
    enum Step<'a, S> {
        Enter(&'a Formula, S),
        Exit(&'a Formula, S, usize),
    }
    let mut steps = vec![Step::Enter(root, state)];
    let mut results: Vec<T> = Vec::new();
    let mut needs = Vec::new();
    while let Some(step) = steps.pop() {
        match step {
            Step::Enter(node, state) => {
                needs.clear();
                expand(node, state, &mut needs);
                steps.push(Step::Exit(node, state, needs.len()));
                steps.extend(
                    needs
                        .drain(..)
                        .rev()
                        .map(|(child, state)| Step::Enter(child, state)),
                );
            }
            Step::Exit(node, state, count) => {
                let arguments = results.split_off(results.len() - count);
                results.push(combine(node, state, arguments));
            }
        }
    }
    // Every Enter pushes exactly one result through its Exit, so exactly one remains.
    results.pop().expect("the root's result")
}

/// Splices every n-ary operand into its parent of the same operator, in linear time and
/// without recursion (formulas built bottom-up, by the parser or a normal form, may nest
/// `And` in `And`). The merged node keeps the leftmost span of the nodes merged into it.
pub(crate) fn flatten(mut root: Formula) -> Formula {
    let mut pending: Vec<&mut Formula> = vec![&mut root];
    while let Some(node) = pending.pop() {
        let mut leftmost = node.span;
        match &mut node.kind {
            FormulaKind::Const(_) | FormulaKind::Atom(_) => {}
            FormulaKind::Unary(_, operand) => pending.push(operand),
            FormulaKind::Binary(_, left, right) => {
                pending.push(left);
                pending.push(right);
            }
            FormulaKind::Nary(op, operands) => {
                let op = *op;
                let mut flat = Vec::with_capacity(operands.len());
                let mut sources = vec![std::mem::take(operands).into_iter()];
                while let Some(source) = sources.last_mut() {
                    let Some(operand) = source.next() else {
                        sources.pop();
                        continue;
                    };
                    match &operand.kind {
                        FormulaKind::Nary(inner, _) if *inner == op => {
                            if operand.span.start < leftmost.start {
                                leftmost = operand.span;
                            }
                            if let FormulaKind::Nary(_, children) = operand.into_kind() {
                                sources.push(children.into_iter());
                            }
                        }
                        _ => flat.push(operand),
                    }
                }
                *operands = flat;
                pending.extend(operands.iter_mut());
            }
        }
        node.span = leftmost;
    }
    root
}

impl std::ops::Not for Formula {
    type Output = Formula;

    /// `!self`.
    fn not(self) -> Formula {
        Formula::unary(UnaryOp::Not, self)
    }
}

impl Clone for Formula {
    fn clone(&self) -> Formula {
        self.fold(|node, children| node.rebuild(children))
    }
}

impl Drop for Formula {
    /// Dismantles the tree with an explicit stack: the default drop glue would recurse once per
    /// level and overflow the stack on deep formulas.
    fn drop(&mut self) {
        fn take_children(formula: &mut Formula, into: &mut Vec<Formula>) {
            match std::mem::replace(&mut formula.kind, FormulaKind::Const(false)) {
                FormulaKind::Const(_) | FormulaKind::Atom(_) => {}
                FormulaKind::Unary(_, operand) => into.push(*operand),
                FormulaKind::Binary(_, left, right) => {
                    into.push(*left);
                    into.push(*right);
                }
                FormulaKind::Nary(_, operands) => into.extend(operands),
            }
        }
        if matches!(self.kind, FormulaKind::Const(_) | FormulaKind::Atom(_)) {
            return;
        }
        let mut doomed = Vec::new();
        take_children(self, &mut doomed);
        while let Some(mut formula) = doomed.pop() {
            take_children(&mut formula, &mut doomed);
        }
    }
}

impl PartialEq for Formula {
    fn eq(&self, other: &Self) -> bool {
        let mut pairs = vec![(self, other)];
        while let Some((a, b)) = pairs.pop() {
            let same_node = match (&a.kind, &b.kind) {
                (FormulaKind::Const(x), FormulaKind::Const(y)) => x == y,
                (FormulaKind::Atom(x), FormulaKind::Atom(y)) => x == y,
                (FormulaKind::Unary(x, _), FormulaKind::Unary(y, _)) => x == y,
                (FormulaKind::Binary(x, _, _), FormulaKind::Binary(y, _, _)) => x == y,
                (FormulaKind::Nary(x, xs), FormulaKind::Nary(y, ys)) => {
                    x == y && xs.len() == ys.len()
                }
                _ => false,
            };
            if !same_node {
                return false;
            }
            pairs.extend(a.children().zip(b.children()));
        }
        true
    }
}

impl Eq for Formula {}

impl Hash for Formula {
    fn hash<H: Hasher>(&self, state: &mut H) {
        let mut pending = vec![self];
        while let Some(node) = pending.pop() {
            std::mem::discriminant(&node.kind).hash(state);
            match &node.kind {
                FormulaKind::Const(value) => value.hash(state),
                FormulaKind::Atom(name) => name.hash(state),
                FormulaKind::Unary(op, _) => op.hash(state),
                FormulaKind::Binary(op, _, _) => op.hash(state),
                FormulaKind::Nary(op, operands) => {
                    op.hash(state);
                    operands.len().hash(state);
                }
            }
            pending.extend(node.children().rev());
        }
    }
}

impl fmt::Debug for Formula {
    /// The formula in Spot's syntax (unambiguous, and printed without recursion).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Formula({self})")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chain(depth: usize) -> Formula {
        let mut formula = Formula::atom("a");
        for _ in 0..depth {
            formula = Formula::next(formula);
        }
        formula
    }

    #[test]
    fn deep_formulas_clone_compare_hash_and_drop_without_recursion() {
        let deep = chain(100_000);
        let copy = deep.clone();
        assert_eq!(deep, copy);
        assert_ne!(deep, chain(99_999));
        let hash = |f: &Formula| {
            let mut hasher = std::collections::hash_map::DefaultHasher::new();
            f.hash(&mut hasher);
            hasher.finish()
        };
        assert_eq!(hash(&deep), hash(&copy));
        let depth = deep.fold(|_, children: Vec<usize>| 1 + children.into_iter().sum::<usize>());
        assert_eq!(depth, 100_001);
        drop(deep);
        drop(copy);
    }

    #[test]
    fn constructors_keep_conjunctions_flat() {
        let inner = Formula::and(vec![Formula::atom("a"), Formula::atom("b")]);
        let outer = Formula::and(vec![inner, Formula::atom("c")]);
        match &outer.kind {
            FormulaKind::Nary(NaryOp::And, operands) => assert_eq!(operands.len(), 3),
            other => panic!("expected a flat conjunction, got {other:?}"),
        }
        assert_eq!(Formula::and(vec![]), Formula::constant(true));
        assert_eq!(Formula::or(vec![]), Formula::constant(false));
        assert_eq!(Formula::or(vec![Formula::atom("a")]), Formula::atom("a"));
    }

    #[test]
    fn flatten_merges_nested_operands_in_order_and_keeps_the_leftmost_span() {
        let at = |start| Span {
            start,
            end: start + 1,
        };
        let pair = |a, b, span| Formula::new(FormulaKind::Nary(NaryOp::And, vec![a, b]), span);
        // a & (b & (c | d)) & e, built as nested pairs.
        let or = Formula::new(
            FormulaKind::Nary(NaryOp::Or, vec![Formula::atom("c"), Formula::atom("d")]),
            at(9),
        );
        let inner = pair(Formula::atom("b"), or, at(6));
        let nested = pair(
            pair(Formula::atom("a"), inner, at(2)),
            Formula::atom("e"),
            at(12),
        );
        let flat = flatten(nested);
        assert_eq!(flat.span, at(2));
        let expected = Formula::and(vec![
            Formula::atom("a"),
            Formula::atom("b"),
            Formula::or(vec![Formula::atom("c"), Formula::atom("d")]),
            Formula::atom("e"),
        ]);
        assert_eq!(flat, expected);
    }
}

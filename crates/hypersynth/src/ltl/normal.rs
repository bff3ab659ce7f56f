//! Positive normal form, the syntactic co-safety check, and the atomic propositions of a
//! formula.
//!
//! Positive normal form (PNF) pushes every negation down to the atomic propositions with the
//! dualities `!X a = X !a`, `!F a = G !a`, `!G a = F !a`, `!(a U b) = !a R !b`,
//! `!(a R b) = !a U !b`, `!(a W b) = !a M !b`, `!(a M b) = !a W !b`, De Morgan for `&` and
//! `|`, `!!a = a`, `!1 = 0`, `!0 = 1`, and expands the other Boolean operators:
//! `a -> b = !a | b`, `a <-> b = (a & b) | (!a & !b)`, `a xor b = (a & !b) | (!a & b)` (and
//! their negations alike). Nothing else is simplified. The result keeps `&` and `|` flat, and
//! each node carries the span of the source operator it comes from (a negated atom, the span of
//! the operator that negated it), so errors about the PNF still point into the original text.
//! `<->` and `xor` copy both operands twice, so nested ones make the PNF exponentially larger:
//! [`positive_normal_form_size_bound`] tells in linear time how large it would be.
//!
//! A formula is syntactically co-safe when its PNF uses only `X`, `F`, `U`, `M`, `&`, `|`,
//! literals and constants. [`check_co_safe`] decides it on the original formula, tracking
//! whether each node occurs positively, negatively or both (inside `<->`/`xor`), which is
//! linear and names the operator as written: the leftmost offending one.
//!
//! Invariant: nothing here recurses on the depth of the formula.

use std::collections::HashSet;
use std::fmt;

use super::formula::{BinaryOp, Formula, FormulaKind, NaryOp, Span, UnaryOp, flatten, transform};
use crate::position::Position;

/// Whether the node being rewritten stands negated, and which operator negated it.
#[derive(Clone, Copy)]
struct Polarity {
    negated: bool,
    by: Span,
}

impl Polarity {
    fn positive(by: Span) -> Polarity {
        Polarity { negated: false, by }
    }

    fn negative(by: Span) -> Polarity {
        Polarity { negated: true, by }
    }

    fn flipped(self, by: Span) -> Polarity {
        Polarity {
            negated: !self.negated,
            by,
        }
    }
}

/// Whether the PNF of a biconditional pairs equal polarities, `(a & b) | (!a & !b)`:
/// true for a positive `<->` and a negated `xor`.
fn pairs_equal_polarities(op: BinaryOp, negated: bool) -> bool {
    (op == BinaryOp::Equiv) != negated
}

/// The positive normal form of `formula` (see the module documentation).
pub fn positive_normal_form(formula: &Formula) -> Formula {
    fn expand<'a>(node: &'a Formula, polarity: Polarity, needs: &mut Vec<(&'a Formula, Polarity)>) {
        let span = node.span;
        match &node.kind {
            FormulaKind::Const(_) | FormulaKind::Atom(_) => {}
            FormulaKind::Unary(UnaryOp::Not, operand) => {
                needs.push((operand, polarity.flipped(span)));
            }
            FormulaKind::Binary(BinaryOp::Implies, left, right) => {
                needs.push((left, polarity.flipped(span)));
                needs.push((right, polarity));
            }
            FormulaKind::Binary(op @ (BinaryOp::Equiv | BinaryOp::Xor), left, right) => {
                let (positive, negative) = (Polarity::positive(span), Polarity::negative(span));
                let (right_first, right_second) = if pairs_equal_polarities(*op, polarity.negated) {
                    (positive, negative)
                } else {
                    (negative, positive)
                };
                needs.extend([
                    (&**left, positive),
                    (&**right, right_first),
                    (&**left, negative),
                    (&**right, right_second),
                ]);
            }
            _ => needs.extend(node.children().map(|child| (child, polarity))),
        }
    }
    fn combine(node: &Formula, polarity: Polarity, mut results: Vec<Formula>) -> Formula {
        let span = node.span;
        let negated = polarity.negated;
        let kind = match &node.kind {
            FormulaKind::Const(value) => FormulaKind::Const(*value != negated),
            FormulaKind::Atom(name) if negated => FormulaKind::Unary(
                UnaryOp::Not,
                Box::new(Formula::new(FormulaKind::Atom(name.clone()), span)),
            ),
            FormulaKind::Atom(name) => FormulaKind::Atom(name.clone()),
            FormulaKind::Unary(UnaryOp::Not, _) => {
                return results.pop().unwrap_or_else(|| Formula::constant(false));
            }
            FormulaKind::Unary(op, _) => {
                let op = match (op, negated) {
                    (UnaryOp::Finally, true) => UnaryOp::Globally,
                    (UnaryOp::Globally, true) => UnaryOp::Finally,
                    (op, _) => *op,
                };
                return node.rebuild(results).with_op_unary(op);
            }
            FormulaKind::Binary(BinaryOp::Implies, _, _) => {
                let op = if negated { NaryOp::And } else { NaryOp::Or };
                FormulaKind::Nary(op, results)
            }
            FormulaKind::Binary(BinaryOp::Equiv | BinaryOp::Xor, _, _) => {
                let second = results.split_off(2);
                FormulaKind::Nary(
                    NaryOp::Or,
                    vec![
                        Formula::new(FormulaKind::Nary(NaryOp::And, results), span),
                        Formula::new(FormulaKind::Nary(NaryOp::And, second), span),
                    ],
                )
            }
            FormulaKind::Binary(op, _, _) => {
                let op = if negated { dual(*op) } else { *op };
                return node.rebuild(results).with_op_binary(op);
            }
            FormulaKind::Nary(op, _) => {
                let op = match (op, negated) {
                    (NaryOp::And, true) => NaryOp::Or,
                    (NaryOp::Or, true) => NaryOp::And,
                    (op, _) => *op,
                };
                FormulaKind::Nary(op, results)
            }
        };
        let span = match &node.kind {
            FormulaKind::Atom(_) if negated => polarity.by,
            _ => span,
        };
        Formula::new(kind, span)
    }
    flatten(transform(
        formula,
        Polarity::positive(formula.span),
        expand,
        combine,
    ))
}

/// The temporal operator that `!(a op b)` becomes on `!a` and `!b`.
fn dual(op: BinaryOp) -> BinaryOp {
    match op {
        BinaryOp::Until => BinaryOp::Release,
        BinaryOp::Release => BinaryOp::Until,
        BinaryOp::WeakUntil => BinaryOp::StrongRelease,
        BinaryOp::StrongRelease => BinaryOp::WeakUntil,
        other => other,
    }
}

impl Formula {
    /// The same unary node with another operator.
    fn with_op_unary(mut self, new: UnaryOp) -> Formula {
        if let FormulaKind::Unary(op, _) = &mut self.kind {
            *op = new;
        }
        self
    }

    /// The same binary node with another operator.
    fn with_op_binary(mut self, new: BinaryOp) -> Formula {
        if let FormulaKind::Binary(op, _, _) = &mut self.kind {
            *op = new;
        }
        self
    }
}

/// An upper bound on the number of nodes of `positive_normal_form(formula)` (exact but for the
/// merging of nested `&`/`|`), computed in linear time without building it. Saturates at
/// `u64::MAX`.
pub fn positive_normal_form_size_bound(formula: &Formula) -> u64 {
    fold_sizes(formula, |_, _, _| {})
}

/// The first subformula, in post-order (so a deepest one), whose positive normal form would
/// have more than `limit` nodes and more than twice its own nodes (which only nested `<->` and
/// `xor` cause: they duplicate their operands), with that size bound
/// ([`positive_normal_form_size_bound`]); `None` if there is none. Linear time, so callers can
/// refuse a normal form before building it and point at the operator that blows it up.
pub fn positive_normal_form_blowup(formula: &Formula, limit: u64) -> Option<(Span, u64)> {
    let mut found = None;
    fold_sizes(formula, |node, size, nodes| {
        if found.is_none() && size > limit.max(nodes.saturating_mul(2)) {
            found = Some((node.span, size));
        }
    });
    found
}

/// [`positive_normal_form_size_bound`], telling `visit` of every node (children first) the
/// bound of its normal form and its own number of nodes.
fn fold_sizes(formula: &Formula, mut visit: impl FnMut(&Formula, u64, u64)) -> u64 {
    // Each node yields the sizes of its PNF and of its negation's PNF, and its nodes.
    let sum = |sizes: &[(u64, u64, u64)], pick: fn(&(u64, u64, u64)) -> u64| {
        sizes.iter().map(pick).fold(1u64, u64::saturating_add)
    };
    let (positive, _, _) = formula.fold(|node, sizes: Vec<(u64, u64, u64)>| {
        let nodes = sum(&sizes, |s| s.2);
        let (positive, negative) = match &node.kind {
            FormulaKind::Const(_) => (1, 1),
            FormulaKind::Atom(_) => (1, 2),
            FormulaKind::Unary(UnaryOp::Not, _) => (sizes[0].1, sizes[0].0),
            FormulaKind::Binary(BinaryOp::Implies, _, _) => (
                1u64.saturating_add(sizes[0].1).saturating_add(sizes[1].0),
                1u64.saturating_add(sizes[0].0).saturating_add(sizes[1].1),
            ),
            FormulaKind::Binary(BinaryOp::Equiv | BinaryOp::Xor, _, _) => {
                // An `|` of two `&`, each of one polarity of each operand.
                let both = sum(&sizes, |s| s.0)
                    .saturating_add(sum(&sizes, |s| s.1))
                    .saturating_add(1);
                (both, both)
            }
            _ => (sum(&sizes, |s| s.0), sum(&sizes, |s| s.1)),
        };
        visit(node, positive, nodes);
        (positive, negative, nodes)
    });
    positive
}

/// Why a formula is not syntactically co-safe: the leftmost operator that is, in positive
/// normal form, one of `G`, `R`, `W`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CoSafetyError {
    /// The operator as the formula writes it (`G`, `R`, `W`, or when negated `F`, `U`, `M`).
    pub operator: &'static str,
    /// What it becomes in positive normal form when it occurs negated (`G`, `R`, `W`).
    pub negated_into: Option<&'static str>,
    /// The operator's token in the parsed text.
    pub span: Span,
}

impl CoSafetyError {
    /// Where the operator is in `source`, the text the formula was parsed from.
    pub fn position(&self, source: &str) -> Position {
        Position::of_offset(source, self.span.start)
    }
}

fn operator_name(symbol: &str) -> &'static str {
    match symbol {
        "G" => "globally",
        "R" => "release",
        _ => "weak until",
    }
}

impl fmt::Display for CoSafetyError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.negated_into {
            None => write!(
                f,
                "`{}` ({}) is not allowed in a syntactically co-safe formula",
                self.operator,
                operator_name(self.operator)
            ),
            Some(into) => write!(
                f,
                "`{}` occurs negated (under `!`, left of `->`, or in `<->`/`xor`), so it means \
                 `{into}` ({}), which is not allowed in a syntactically co-safe formula",
                self.operator,
                operator_name(into)
            ),
        }
    }
}

impl std::error::Error for CoSafetyError {}

const POSITIVE: u8 = 1;
const NEGATIVE: u8 = 2;

/// Checks that `formula` is syntactically co-safe (see the module documentation); otherwise
/// names its leftmost offending operator (leftmost by span, then first in pre-order).
pub fn check_co_safe(formula: &Formula) -> Result<(), CoSafetyError> {
    match co_safety_errors(formula).into_iter().next() {
        Some(error) => Err(error),
        None => Ok(()),
    }
}

/// Every operator that keeps `formula` from being syntactically co-safe, leftmost first (by
/// span, then in pre-order); empty when it is co-safe.
pub fn co_safety_errors(formula: &Formula) -> Vec<CoSafetyError> {
    let flip = |mask: u8| ((mask & POSITIVE) << 1) | ((mask & NEGATIVE) >> 1);
    let mut pending = vec![(formula, POSITIVE)];
    let mut errors = Vec::new();
    while let Some((node, mask)) = pending.pop() {
        let offence = match &node.kind {
            FormulaKind::Unary(UnaryOp::Globally, _) if mask & POSITIVE != 0 => Some(("G", None)),
            FormulaKind::Unary(UnaryOp::Finally, _) if mask & NEGATIVE != 0 => {
                Some(("F", Some("G")))
            }
            FormulaKind::Binary(op, _, _) => match op {
                BinaryOp::Release if mask & POSITIVE != 0 => Some(("R", None)),
                BinaryOp::WeakUntil if mask & POSITIVE != 0 => Some(("W", None)),
                BinaryOp::Until if mask & NEGATIVE != 0 => Some(("U", Some("R"))),
                BinaryOp::StrongRelease if mask & NEGATIVE != 0 => Some(("M", Some("W"))),
                _ => None,
            },
            _ => None,
        };
        if let Some((operator, negated_into)) = offence {
            errors.push(CoSafetyError {
                operator,
                negated_into,
                span: node.span,
            });
        }
        let masks: [u8; 2] = match &node.kind {
            FormulaKind::Unary(UnaryOp::Not, _) => [flip(mask), 0],
            FormulaKind::Binary(BinaryOp::Implies, _, _) => [flip(mask), mask],
            FormulaKind::Binary(BinaryOp::Equiv | BinaryOp::Xor, _, _) => [POSITIVE | NEGATIVE; 2],
            _ => [mask; 2],
        };
        let children: Vec<&Formula> = node.children().collect();
        for (index, child) in children.into_iter().enumerate().rev() {
            pending.push((child, masks[index.min(1)]));
        }
    }
    // Stable: errors at one place stay in pre-order.
    errors.sort_by_key(|error| error.span.start);
    errors
}

/// The atomic propositions of `formula`, each once, in order of first appearance in the text.
pub fn atomic_propositions(formula: &Formula) -> Vec<String> {
    let mut seen = HashSet::new();
    let mut names = Vec::new();
    let mut pending = vec![formula];
    while let Some(node) = pending.pop() {
        if let FormulaKind::Atom(name) = &node.kind
            && seen.insert(name.as_str())
        {
            names.push(name.clone());
        }
        pending.extend(node.children().rev());
    }
    names
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ltl::parse;

    fn parsed(text: &str) -> Formula {
        parse(text).unwrap_or_else(|e| panic!("{text:?}: {e}"))
    }

    /// Each `(input, expected)`: the PNF of `input` is the formula `expected`.
    fn assert_normal_forms(cases: &[(&str, &str)]) {
        for (input, expected) in cases {
            assert_eq!(
                positive_normal_form(&parsed(input)),
                parsed(expected),
                "{input}"
            );
        }
    }

    #[test]
    fn negations_are_pushed_to_the_atoms_by_duality() {
        let cases = [
            ("!X a", "X!a"),
            ("!F a", "G!a"),
            ("!G a", "F!a"),
            ("!(a U b)", "!a R !b"),
            ("!(a R b)", "!a U !b"),
            ("!(a W b)", "!a M !b"),
            ("!(a M b)", "!a W !b"),
            ("!true", "0"),
            ("!0", "1"),
            ("!!a", "a"),
            ("!(a & (b | !c))", "!a | (!b & c)"),
            ("!(a | b) & c", "!a & !b & c"),
            ("!X(F a & G !b)", "X(G!a | F b)"),
        ];
        assert_normal_forms(&cases);
    }

    #[test]
    fn implications_and_biconditionals_are_expanded() {
        let cases = [
            ("a -> b", "!a | b"),
            ("!(a -> b)", "a & !b"),
            ("(a -> b) | c", "!a | b | c"),
            ("a -> b -> c", "!a | !b | c"),
            ("a <-> b", "(a & b) | (!a & !b)"),
            ("!(a <-> b)", "(a & !b) | (!a & b)"),
            ("a xor b", "(a & !b) | (!a & b)"),
            ("!(a xor b)", "(a & b) | (!a & !b)"),
            ("X(a <-> F b)", "X((a & F b) | (!a & G!b))"),
        ];
        assert_normal_forms(&cases);
    }

    #[test]
    fn normal_form_nodes_keep_the_spans_of_their_source_operators() {
        let pnf = positive_normal_form(&parsed("!(a U b)"));
        assert_eq!(pnf.span, Span { start: 4, end: 5 });
        let FormulaKind::Binary(BinaryOp::Release, left, _) = &pnf.kind else {
            panic!("expected R, got {pnf:?}");
        };
        // The negated atom points at the `!` that negated it; the atom at itself.
        assert_eq!(left.span, Span { start: 0, end: 1 });
        assert_eq!(
            left.children().next().map(|a| a.span),
            Some(Span { start: 2, end: 3 })
        );
    }

    #[test]
    fn co_safe_formulas_pass() {
        for text in [
            "a U b",
            "F a",
            "X a",
            "a M b",
            "!a",
            "1",
            "!(a R b)",
            "!G a",
            "!(a W b)",
            "a -> F b",
            "G a -> F b",
            "(!O U A) & (!O U B)",
            "a <-> X b",
        ] {
            assert_eq!(check_co_safe(&parsed(text)), Ok(()), "{text}");
        }
    }

    #[test]
    fn the_leftmost_offending_operator_is_named_with_its_column() {
        let cases = [
            ("G a", "G", None, 1),
            ("F G a", "G", None, 3),
            ("!(a U b)", "U", Some("R"), 5),
            ("a R b", "R", None, 3),
            ("a W b", "W", None, 3),
            ("!(a M b)", "M", Some("W"), 5),
            ("!F a", "F", Some("G"), 2),
            ("F a -> b", "F", Some("G"), 1),
            ("a <-> F b", "F", Some("G"), 7),
            ("a xor (b U c)", "U", Some("R"), 10),
            ("G a & F G b", "G", None, 1),
            ("F(b R c) | G a", "R", None, 5),
            ("[] a", "G", None, 1),
            ("\"é\" U G a", "G", None, 7),
        ];
        for (text, operator, negated_into, column) in cases {
            let error = check_co_safe(&parsed(text)).expect_err(text);
            assert_eq!(
                (error.operator, error.negated_into),
                (operator, negated_into),
                "{text}"
            );
            assert_eq!(error.position(text), Position { line: 1, column }, "{text}");
        }
    }

    #[test]
    fn the_error_message_names_the_operator_and_what_it_becomes() {
        let error = check_co_safe(&parsed("!(a U b)")).expect_err("not co-safe");
        assert!(
            error
                .to_string()
                .starts_with("`U` occurs negated (under `!`, left of `->`, or in `<->`/`xor`), so it means `R` (release)"),
            "{error}"
        );
        let error = check_co_safe(&parsed("G a")).expect_err("not co-safe");
        assert!(
            error
                .to_string()
                .starts_with("`G` (globally) is not allowed"),
            "{error}"
        );
    }

    #[test]
    fn atomic_propositions_come_in_order_of_first_appearance() {
        let formula = parsed("b U (a & !b) | \"c d\" U a");
        assert_eq!(atomic_propositions(&formula), ["b", "a", "c d"]);
        assert!(atomic_propositions(&parsed("X true")).is_empty());
    }

    #[test]
    fn the_size_bound_is_exact_without_merging_and_saturates() {
        let count = |f: &Formula| f.fold(|_, children: Vec<u64>| 1 + children.iter().sum::<u64>());
        for text in ["a <-> b", "!(a xor X b)", "a -> b", "F !(a U !b)", "!1"] {
            let formula = parsed(text);
            assert_eq!(
                positive_normal_form_size_bound(&formula),
                count(&positive_normal_form(&formula)),
                "{text}"
            );
        }
        let nested = format!("{}a{}", "(a <-> ".repeat(200), ")".repeat(200));
        assert_eq!(positive_normal_form_size_bound(&parsed(&nested)), u64::MAX);
    }
}

//! Printing formulas in Spot's syntax, with as few parentheses as the grammar allows.
//!
//! Operators print as Spot prints them (`!`, `X`, `F`, `G` glued to their operand; ` & `,
//! ` | `, ` xor `, ` -> `, ` <-> `, ` U `, ` R `, ` W `, ` M ` between spaces; constants `1`
//! and `0`). A subformula is parenthesised exactly when the parser would otherwise group it
//! differently (see the precedence table in [`super::parser`]), so `parse(f.to_string()) == f`
//! for every well-formed formula, and removing any pair of parentheses from the output changes
//! its meaning or makes it invalid.
//!
//! Lexical care: an atomic proposition is printed bare only if the lexer reads the bare name
//! back as that same proposition; otherwise it is quoted (`"a b"`, `"F"`, `"U"`, `"true"`,
//! `"xor"`, `"2a"`), with `\` before `"` and `\`. A unary operator letter is separated from its
//! operand by a space where gluing them would lex differently (`X 1`, not the proposition `X1`;
//! `F alse`, not `False`).
//!
//! Ill-formed trees built by hand still print as something readable: an n-ary node nested in
//! one of the same operator is parenthesised (it re-parses flat, so it does not round-trip),
//! one operand prints alone, none prints the operator's neutral constant.
//!
//! Invariant: printing uses an explicit stack, never recursion, so deep formulas print safely.

use std::fmt;

use super::formula::{BinaryOp, Formula, FormulaKind, NaryOp, UnaryOp};
use super::parser::{
    ATOM_LEVEL, Assoc, PREFIX_LEVEL, Token, binary_binding, is_word_char, nary_level, operand_word,
};

/// The binding strength of a node's outermost operator.
fn level(formula: &Formula) -> u8 {
    match &formula.kind {
        FormulaKind::Const(_) | FormulaKind::Atom(_) => ATOM_LEVEL,
        FormulaKind::Unary(..) => PREFIX_LEVEL,
        FormulaKind::Binary(op, _, _) => binary_binding(*op).0,
        FormulaKind::Nary(_, operands) if operands.is_empty() => ATOM_LEVEL,
        FormulaKind::Nary(op, _) => nary_level(*op),
    }
}

fn binary_separator(op: BinaryOp) -> &'static str {
    match op {
        BinaryOp::Xor => " xor ",
        BinaryOp::Implies => " -> ",
        BinaryOp::Equiv => " <-> ",
        BinaryOp::Until => " U ",
        BinaryOp::Release => " R ",
        BinaryOp::WeakUntil => " W ",
        BinaryOp::StrongRelease => " M ",
    }
}

fn constant(value: bool) -> &'static str {
    if value { "1" } else { "0" }
}

/// Whether `name` reads back as the atomic proposition `name` without quotes.
fn is_bare_name(name: &str) -> bool {
    !name.is_empty()
        && name.chars().all(is_word_char)
        && matches!(operand_word(name), Ok((Token::Atom(read), length))
                    if length == name.len() && read == name)
}

fn write_atom(f: &mut fmt::Formatter<'_>, name: &str) -> fmt::Result {
    if is_bare_name(name) {
        return f.write_str(name);
    }
    f.write_str("\"")?;
    for c in name.chars() {
        if matches!(c, '"' | '\\') {
            f.write_str("\\")?;
        }
        write!(f, "{c}")?;
    }
    f.write_str("\"")
}

/// Whether the letter of `op` glued to `operand` would lex as something else than `op`
/// followed by the operand (for example `X` and `1` make the proposition `X1`).
fn needs_space(op: UnaryOp, operand: &Formula) -> bool {
    let text = match &operand.kind {
        _ if op == UnaryOp::Not => return false,
        FormulaKind::Const(value) => constant(*value),
        FormulaKind::Atom(name) if is_bare_name(name) => name,
        _ => return false,
    };
    let glued = format!("{}{text}", op.symbol());
    !matches!(operand_word(&glued), Ok((Token::Prefix(read), 1)) if read == op)
}

impl fmt::Display for Formula {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        enum Task<'a> {
            /// A subformula whose outermost operator must bind at least this strongly to go
            /// without parentheses.
            Node(&'a Formula, u8),
            Text(&'static str),
        }
        let mut tasks = vec![Task::Node(self, 0)];
        while let Some(task) = tasks.pop() {
            let (node, minimum) = match task {
                Task::Text(text) => {
                    f.write_str(text)?;
                    continue;
                }
                Task::Node(node, minimum) => (node, minimum),
            };
            if let FormulaKind::Nary(_, operands) = &node.kind
                && let [only] = operands.as_slice()
            {
                tasks.push(Task::Node(only, minimum));
                continue;
            }
            let level = level(node);
            if level < minimum {
                f.write_str("(")?;
                tasks.push(Task::Text(")"));
            }
            match &node.kind {
                FormulaKind::Const(value) => f.write_str(constant(*value))?,
                FormulaKind::Atom(name) => write_atom(f, name)?,
                FormulaKind::Unary(op, operand) => {
                    f.write_str(op.symbol())?;
                    if needs_space(*op, operand) {
                        f.write_str(" ")?;
                    }
                    tasks.push(Task::Node(operand, PREFIX_LEVEL));
                }
                FormulaKind::Binary(op, left, right) => {
                    let (left_minimum, right_minimum) = match binary_binding(*op).1 {
                        Assoc::Left => (level, level + 1),
                        Assoc::Right => (level + 1, level),
                    };
                    tasks.push(Task::Node(right, right_minimum));
                    tasks.push(Task::Text(binary_separator(*op)));
                    tasks.push(Task::Node(left, left_minimum));
                }
                FormulaKind::Nary(op, operands) => {
                    if operands.is_empty() {
                        f.write_str(constant(op.identity()))?;
                    }
                    let separator = match op {
                        NaryOp::And => " & ",
                        NaryOp::Or => " | ",
                    };
                    for (index, operand) in operands.iter().enumerate().rev() {
                        tasks.push(Task::Node(operand, level + 1));
                        if index > 0 {
                            tasks.push(Task::Text(separator));
                        }
                    }
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ltl::parse;

    fn ap(name: &str) -> Formula {
        Formula::atom(name)
    }

    fn printed(text: &str) -> String {
        let formula = parse(text).unwrap_or_else(|e| panic!("{text:?}: {e}"));
        formula.to_string()
    }

    #[test]
    fn parentheses_appear_only_where_precedence_needs_them() {
        let cases = [
            ("a U (b U c)", "a U b U c"),
            ("(a U b) U c", "(a U b) U c"),
            ("((!a & b) | c) -> (d <-> e)", "!a & b | c -> d <-> e"),
            ("(a -> b) -> c", "(a -> b) -> c"),
            ("(a xor b) xor c", "a xor b xor c"),
            ("a xor (b xor c)", "a xor (b xor c)"),
            ("a | (b xor c)", "a | b xor c"),
            ("(a | b) xor c", "(a | b) xor c"),
            ("(a U b) & c", "a U b & c"),
            ("a U (b & c)", "a U (b & c)"),
            ("!(a & b)", "!(a & b)"),
            ("X (a U b)", "X(a U b)"),
            ("(X a) U b", "Xa U b"),
            ("X(F(a))", "XFa"),
            ("F(!a)", "F!a"),
            ("G(a -> F b)", "G(a -> Fb)"),
            ("((a))", "a"),
            ("true & FALSE", "1 & 0"),
        ];
        for (input, expected) in cases {
            assert_eq!(printed(input), expected, "{input}");
        }
    }

    #[test]
    fn names_are_quoted_unless_they_read_back_bare() {
        let cases = [
            ("a", "a"),
            ("aUb", "aUb"),
            ("Ub", "Ub"),
            ("X1", "X1"),
            ("a.b", "a.b"),
            ("alse", "alse"),
            ("a b", "\"a b\""),
            ("F", "\"F\""),
            ("Fa", "\"Fa\""),
            ("U", "\"U\""),
            ("V", "\"V\""),
            ("true", "\"true\""),
            ("FALSE", "\"FALSE\""),
            ("xor", "\"xor\""),
            ("first_match", "\"first_match\""),
            ("2a", "\"2a\""),
            ("a\"b\\", "\"a\\\"b\\\\\""),
            ("é", "\"é\""),
        ];
        for (name, expected) in cases {
            assert_eq!(ap(name).to_string(), expected, "{name}");
            assert_eq!(parse(expected).ok(), Some(ap(name)), "{expected}");
        }
    }

    #[test]
    fn operator_letters_are_spaced_from_operands_they_would_merge_with() {
        let cases = [
            (Formula::next(Formula::constant(true)), "X 1"),
            (Formula::globally(Formula::constant(false)), "G 0"),
            (Formula::finally(ap("alse")), "F alse"),
            (Formula::finally(ap("ALSEx")), "F ALSEx"),
            (Formula::next(ap("alse")), "Xalse"),
            (Formula::next(ap("X1")), "XX1"),
            (!Formula::constant(true), "!1"),
            (Formula::finally(ap("1a")), "F\"1a\""),
        ];
        for (formula, expected) in cases {
            assert_eq!(formula.to_string(), expected);
            assert_eq!(parse(expected).ok(), Some(formula), "{expected}");
        }
    }

    #[test]
    fn hand_built_nested_conjunctions_are_parenthesised() {
        let nested = Formula::new(
            FormulaKind::Nary(
                NaryOp::And,
                vec![Formula::and(vec![ap("a"), ap("b")]), ap("c")],
            ),
            Default::default(),
        );
        assert_eq!(nested.to_string(), "(a & b) & c");
        let empty = Formula::new(FormulaKind::Nary(NaryOp::Or, vec![]), Default::default());
        assert_eq!(empty.to_string(), "0");
        let single = Formula::new(
            FormulaKind::Nary(NaryOp::And, vec![Formula::or(vec![ap("a"), ap("b")])]),
            Default::default(),
        );
        assert_eq!(Formula::next(single).to_string(), "X(a | b)");
    }
}

//! The LTL front end through its public API: Spot's reference formulas, random round trips,
//! the grammar's examples and deep nesting.

use hypersynth::ltl::{self, BinaryOp, Formula, FormulaKind, NaryOp, UnaryOp};
use proptest::prelude::*;

const SPOT_FORMULAS: &str = include_str!("fixtures/spot/formulas.ltl");

fn parsed(text: &str) -> Formula {
    ltl::parse(text).unwrap_or_else(|e| panic!("{text:?} should parse:\n{e}"))
}

#[test]
fn spots_reference_formulas_parse_and_round_trip() {
    let lines: Vec<&str> = SPOT_FORMULAS.lines().collect();
    assert_eq!(lines.len(), 300);
    for line in lines {
        let formula = parsed(line);
        let printed = formula.to_string();
        assert_eq!(parsed(&printed), formula, "{line} printed as {printed}");
    }
}

#[test]
fn spots_first_reference_formula_is_read_as_spot_reads_it() {
    // Line 1 of the fixture, `XXFd`, is X(X(F(d))) for Spot (its HOA has 4 states: two X
    // steps, waiting for d, accepting sink).
    let x = Formula::next;
    assert_eq!(parsed("XXFd"), x(x(Formula::finally(Formula::atom("d")))));
}

// ---------------------------------------------------------------------------------------------
// Random formulas.

/// Names chosen to exercise the lexer: operator letters, keywords, digits, spaces, quotes.
const NAMES: &[&str] = &[
    "a", "b", "c", "aUb", "X1", "F0a", "alse", "Ub", "O", "a.b", "a b", "F", "U", "V", "xor",
    "true", "False", "2", "q\"x", "é",
];
const UNARY: &[UnaryOp] = &[
    UnaryOp::Not,
    UnaryOp::Next,
    UnaryOp::Finally,
    UnaryOp::Globally,
];
const BINARY: &[BinaryOp] = &[
    BinaryOp::Xor,
    BinaryOp::Implies,
    BinaryOp::Equiv,
    BinaryOp::Until,
    BinaryOp::Release,
    BinaryOp::WeakUntil,
    BinaryOp::StrongRelease,
];

fn formulas() -> impl Strategy<Value = Formula> {
    let leaf = prop_oneof![
        1 => any::<bool>().prop_map(Formula::constant),
        4 => prop::sample::select(NAMES).prop_map(Formula::atom),
    ];
    leaf.prop_recursive(6, 40, 4, |inner| {
        prop_oneof![
            (prop::sample::select(UNARY), inner.clone())
                .prop_map(|(op, operand)| Formula::unary(op, operand)),
            (prop::sample::select(BINARY), inner.clone(), inner.clone())
                .prop_map(|(op, left, right)| Formula::binary(op, left, right)),
            (
                prop::sample::select(&[NaryOp::And, NaryOp::Or][..]),
                prop::collection::vec(inner, 2..4)
            )
                .prop_map(|(op, operands)| Formula::nary(op, operands)),
        ]
    })
}

/// Byte ranges of the `(` and `)` of every parenthesis pair outside quoted names.
fn parenthesis_pairs(text: &str) -> Vec<(usize, usize)> {
    let mut pairs = Vec::new();
    let mut open = Vec::new();
    let mut in_quotes = false;
    let mut escaped = false;
    for (index, c) in text.char_indices() {
        if in_quotes {
            match (escaped, c) {
                (true, _) => escaped = false,
                (false, '\\') => escaped = true,
                (false, '"') => in_quotes = false,
                _ => {}
            }
            continue;
        }
        match c {
            '"' => in_quotes = true,
            '(' => open.push(index),
            ')' => pairs.push((open.pop().expect("balanced output"), index)),
            _ => {}
        }
    }
    pairs
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn printing_then_parsing_gives_the_same_tree(formula in formulas()) {
        let printed = formula.to_string();
        prop_assert_eq!(ltl::parse(&printed).ok(), Some(formula), "{}", printed);
    }

    #[test]
    fn every_printed_parenthesis_pair_is_needed(formula in formulas()) {
        let printed = formula.to_string();
        for (open, close) in parenthesis_pairs(&printed) {
            let without = format!(
                "{}{}{}",
                &printed[..open],
                &printed[open + 1..close],
                &printed[close + 1..]
            );
            let reparsed = ltl::parse(&without).ok();
            prop_assert_ne!(
                reparsed.as_ref(),
                Some(&formula),
                "{} means the same without the pair at {}",
                printed,
                open
            );
        }
    }

    #[test]
    fn arbitrary_text_never_panics_the_parser(text in "[ a-zA-Z01()!&|^~<>=/\\\\\\-\"\\[\\]{}*;:+.é]{0,40}") {
        if let Ok(formula) = ltl::parse(&text) {
            prop_assert_eq!(ltl::parse(&formula.to_string()).ok(), Some(formula));
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Deep nesting: none of parse, print, clone, compare or drop may recurse on the depth.

const DEPTH: usize = 100_000;

fn round_trips(text: &str) -> Formula {
    let formula = parsed(text);
    let printed = formula.to_string();
    let reparsed = parsed(&printed);
    assert!(reparsed == formula.clone());
    formula
}

#[test]
fn a_hundred_thousand_nested_unary_operators_are_a_valid_formula() {
    for op in ["X", "!", "F", "G "] {
        let text = format!("{}a", op.repeat(DEPTH));
        let formula = round_trips(&text);
        let depth = formula.fold(|_, children: Vec<usize>| 1 + children.iter().max().unwrap_or(&0));
        assert_eq!(depth, DEPTH + 1, "{op}");
    }
}

#[test]
fn a_hundred_thousand_parentheses_around_an_atom_are_just_the_atom() {
    let text = format!("{}a{}", "(".repeat(DEPTH), ")".repeat(DEPTH));
    assert_eq!(round_trips(&text), Formula::atom("a"));
}

#[test]
fn long_right_nested_chains_parse_and_print() {
    let until = format!("{}a", "a U ".repeat(DEPTH));
    let formula = round_trips(&until);
    assert!(matches!(
        formula.kind,
        FormulaKind::Binary(BinaryOp::Until, _, _)
    ));

    let nested_and = format!("{}a{}", "(a & ".repeat(DEPTH), ")".repeat(DEPTH));
    match &round_trips(&nested_and).kind {
        FormulaKind::Nary(NaryOp::And, operands) => assert_eq!(operands.len(), DEPTH + 1),
        other => panic!("expected one flat conjunction, got {other:?}"),
    }
    let flat_or = format!("{}a", "a | ".repeat(DEPTH));
    match &round_trips(&flat_or).kind {
        FormulaKind::Nary(NaryOp::Or, operands) => assert_eq!(operands.len(), DEPTH + 1),
        other => panic!("expected one flat disjunction, got {other:?}"),
    }
}

#[test]
fn a_megabyte_of_open_parentheses_is_a_clean_error() {
    let error = ltl::parse(&"(".repeat(1 << 20)).expect_err("no formula inside");
    assert!(error.message.contains("expected a formula after `(`"));
    assert!(error.to_string().len() < 300);
}

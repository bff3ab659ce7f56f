//! The LTL front end through its public API: Spot's reference formulas, random round trips,
//! the grammar's examples and deep nesting.

use hypersynth::ltl::{self, BinaryOp, Formula, FormulaKind, NaryOp, UnaryOp};
use proptest::prelude::*;

const SPOT_FORMULAS: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../tests/fixtures/spot/formulas.ltl"
));

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
        assert_eq!(ltl::check_co_safe(&formula), Ok(()), "{line}");
        let pnf = ltl::positive_normal_form(&formula);
        assert_eq!(parsed(&pnf.to_string()), pnf, "{line}");
        assert!(only_co_safe_operators(&pnf), "{line}: {pnf}");
    }
}

#[test]
fn spots_first_reference_formula_is_read_as_spot_reads_it() {
    // Line 1 of the fixture, `XXFd`, is X(X(F(d))) for Spot (its HOA has 4 states: two X
    // steps, waiting for d, accepting sink).
    let x = Formula::next;
    assert_eq!(parsed("XXFd"), x(x(Formula::finally(Formula::atom("d")))));
}

#[test]
fn the_grammar_examples_parse_as_documented() {
    let grammar = include_str!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../grammar/ltl.ebnf"
    ));
    let (mut examples, mut rejected) = (0, 0);
    for line in grammar.lines() {
        let line = line.trim();
        if let Some(example) = line
            .strip_prefix("(* example: ")
            .and_then(|rest| rest.strip_suffix(" *)"))
        {
            examples += 1;
            match example.split_once(" == ") {
                Some((text, meaning)) => assert_eq!(parsed(text), parsed(meaning), "{line}"),
                None => {
                    parsed(example);
                }
            }
        } else if let Some(text) = line
            .strip_prefix("(* rejected: ")
            .and_then(|rest| rest.strip_suffix(" *)"))
        {
            rejected += 1;
            assert!(ltl::parse(text).is_err(), "{line}");
        }
    }
    assert!(
        examples >= 40 && rejected >= 10,
        "{examples} examples, {rejected} rejected"
    );
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
    formulas_over(NAMES)
}

/// Random formulas over the atomic propositions `names` with every operator.
fn formulas_over(names: &'static [&'static str]) -> impl Strategy<Value = Formula> {
    let leaf = prop_oneof![
        1 => any::<bool>().prop_map(Formula::constant),
        4 => prop::sample::select(names).prop_map(Formula::atom),
    ];
    leaf.prop_recursive(8, 64, 3, |inner| {
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

/// Whether a formula in positive normal form uses only `X F U M & |`, literals and constants:
/// the definition of syntactic co-safety, checked directly.
fn only_co_safe_operators(pnf: &Formula) -> bool {
    pnf.fold(|node, children: Vec<bool>| {
        let allowed = match &node.kind {
            FormulaKind::Unary(UnaryOp::Not, operand) => {
                matches!(operand.kind, FormulaKind::Atom(_))
            }
            FormulaKind::Unary(op, _) => matches!(op, UnaryOp::Next | UnaryOp::Finally),
            FormulaKind::Binary(op, _, _) => {
                matches!(op, BinaryOp::Until | BinaryOp::StrongRelease)
            }
            FormulaKind::Const(_) | FormulaKind::Atom(_) | FormulaKind::Nary(..) => true,
        };
        allowed && children.into_iter().all(|child| child)
    })
}

/// Whether a formula is in positive normal form: negations only on atoms, no `->`, `<->`,
/// `xor`.
fn is_positive_normal_form(formula: &Formula) -> bool {
    formula.fold(|node, children: Vec<bool>| {
        let allowed = match &node.kind {
            FormulaKind::Unary(UnaryOp::Not, operand) => {
                matches!(operand.kind, FormulaKind::Atom(_))
            }
            FormulaKind::Binary(op, _, _) => {
                !matches!(op, BinaryOp::Implies | BinaryOp::Equiv | BinaryOp::Xor)
            }
            _ => true,
        };
        allowed && children.into_iter().all(|child| child)
    })
}

/// An ultimately periodic word: `letters[i]` is the set of true propositions (bit `k` for
/// `NAMES[k]`) at position `i`, and the last position is followed by position `loop_start`.
#[derive(Debug, Clone)]
struct Lasso {
    letters: Vec<u32>,
    loop_start: usize,
}

fn lassos() -> impl Strategy<Value = Lasso> {
    (1..6usize)
        .prop_flat_map(|length| {
            (
                prop::collection::vec(0u32..(1 << NAMES.len()), length),
                0..length,
            )
        })
        .prop_map(|(letters, loop_start)| Lasso {
            letters,
            loop_start,
        })
}

impl Lasso {
    fn next(&self, position: usize) -> usize {
        if position + 1 < self.letters.len() {
            position + 1
        } else {
            self.loop_start
        }
    }

    /// Positions from `from` on, long enough to cover every position reachable from it.
    fn path(&self, from: usize) -> Vec<usize> {
        std::iter::successors(Some(from), |&p| Some(self.next(p)))
            .take(self.letters.len())
            .collect()
    }

    /// The LTL semantics, written out naively (recursively: the formulas here are small).
    fn holds(&self, formula: &Formula, at: usize) -> bool {
        let path = self.path(at);
        match &formula.kind {
            FormulaKind::Const(value) => *value,
            FormulaKind::Atom(name) => {
                let bit = NAMES.iter().position(|n| n == name).expect("known name");
                self.letters[at] & (1 << bit) != 0
            }
            FormulaKind::Unary(op, f) => match op {
                UnaryOp::Not => !self.holds(f, at),
                UnaryOp::Next => self.holds(f, self.next(at)),
                UnaryOp::Finally => path.iter().any(|&p| self.holds(f, p)),
                UnaryOp::Globally => path.iter().all(|&p| self.holds(f, p)),
            },
            FormulaKind::Binary(op, a, b) => {
                let (a_at, b_at) = (self.holds(a, at), self.holds(b, at));
                // The first position of the path where `stop` holds and whether `keep` held
                // everywhere before it (None: `stop` never holds).
                let until = |keep: &Formula, stop: &Formula| {
                    for &p in &path {
                        if self.holds(stop, p) {
                            return Some(true);
                        }
                        if !self.holds(keep, p) {
                            return Some(false);
                        }
                    }
                    None
                };
                // Along the path: false at the first position where `b` fails, true at the
                // first where `a` and `b` hold (None: neither happens).
                let release = || {
                    path.iter().find_map(|&p| {
                        if !self.holds(b, p) {
                            Some(false)
                        } else if self.holds(a, p) {
                            Some(true)
                        } else {
                            None
                        }
                    })
                };
                match op {
                    BinaryOp::Xor => a_at != b_at,
                    BinaryOp::Implies => !a_at || b_at,
                    BinaryOp::Equiv => a_at == b_at,
                    BinaryOp::Until => until(a, b) == Some(true),
                    BinaryOp::WeakUntil => until(a, b).unwrap_or(true),
                    BinaryOp::Release => release().unwrap_or(true),
                    BinaryOp::StrongRelease => release().unwrap_or(false),
                }
            }
            FormulaKind::Nary(NaryOp::And, operands) => operands.iter().all(|f| self.holds(f, at)),
            FormulaKind::Nary(NaryOp::Or, operands) => operands.iter().any(|f| self.holds(f, at)),
        }
    }
}

/// Every lasso of length 1 to 3 over the propositions `a` and `b`.
fn small_lassos() -> Vec<Lasso> {
    let mut words = Vec::new();
    for length in 1..=3u32 {
        for code in 0..4u32.pow(length) {
            let letters = (0..length)
                .map(|i| (code >> (2 * i)) & 3)
                .collect::<Vec<_>>();
            for loop_start in 0..letters.len() {
                words.push(Lasso {
                    letters: letters.clone(),
                    loop_start,
                });
            }
        }
    }
    words
}

#[test]
fn the_reference_semantics_agrees_with_hand_worked_cases() {
    // Position 0 has only a; position 1 has only b and repeats forever: a b b b ...
    let word = Lasso {
        letters: vec![0b01, 0b10],
        loop_start: 1,
    };
    let holds = |text: &str, at| word.holds(&parsed(text), at);
    assert!(holds("a U b", 0));
    assert!(!holds("b U a", 1));
    assert!(holds("F b & !G a & G F b & X G b", 0));
    assert!(!holds("F a", 1));
    assert!(!holds("a W 0", 0) && holds("b W 0", 1));
    assert!(!holds("b R a", 0) && holds("a R b", 1) && !holds("a M b", 1));
    assert!(!holds("b M a", 0) && holds("a M (a | b)", 0));
    assert!(holds("a xor b", 0) && !holds("a <-> b", 0) && holds("b -> a", 0));
}

#[test]
fn every_rewriting_rule_of_the_normal_form_preserves_meaning_on_small_words() {
    let mut formulas: Vec<String> = Vec::new();
    for op in ["X", "F", "G", "!"] {
        formulas.push(format!("{op}a"));
        formulas.push(format!("!{op}a"));
    }
    for op in ["U", "R", "W", "M", "&", "|", "->", "<->", "xor"] {
        formulas.push(format!("a {op} b"));
        formulas.push(format!("!(a {op} b)"));
        formulas.push(format!("!(!a {op} X b)"));
    }
    formulas.extend(["0", "!0", "1", "!1"].map(String::from));
    let words = small_lassos();
    assert_eq!(words.len(), 4 + 2 * 16 + 3 * 64);
    for text in &formulas {
        let formula = parsed(text);
        let pnf = ltl::positive_normal_form(&formula);
        assert!(is_positive_normal_form(&pnf), "{text}: {pnf}");
        for word in &words {
            for position in 0..word.letters.len() {
                assert_eq!(
                    word.holds(&pnf, position),
                    word.holds(&formula, position),
                    "{text} vs {pnf} on {word:?} at {position}"
                );
            }
        }
    }
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
    fn positive_normal_form_is_equivalent_and_printable(
        // Few propositions, so that random words often tell formulas apart.
        formula in formulas_over(&NAMES[..2]),
        words in prop::collection::vec(lassos(), 8),
    ) {
        let pnf = ltl::positive_normal_form(&formula);
        prop_assert!(is_positive_normal_form(&pnf), "{}", pnf);
        let reparsed = ltl::parse(&pnf.to_string()).ok();
        prop_assert_eq!(reparsed.as_ref(), Some(&pnf));
        for word in &words {
            for position in 0..word.letters.len() {
                prop_assert_eq!(
                    word.holds(&pnf, position),
                    word.holds(&formula, position),
                    "{} vs {} on {:?} at {}", formula, pnf, word, position
                );
            }
        }
    }

    #[test]
    fn the_co_safety_check_agrees_with_the_definition_on_the_normal_form(formula in formulas()) {
        // Parsed back so that every operator has its own span.
        let formula = ltl::parse(&formula.to_string()).expect("printed formulas parse");
        let pnf = ltl::positive_normal_form(&formula);
        let verdict = ltl::check_co_safe(&formula);
        prop_assert_eq!(verdict.is_ok(), only_co_safe_operators(&pnf), "{}", pnf);
        // On the normal form, the same operator (now in its dual form) is found.
        let on_pnf = ltl::check_co_safe(&pnf);
        prop_assert_eq!(
            verdict.map_err(|e| (e.span, e.negated_into.unwrap_or(e.operator))),
            on_pnf.map_err(|e| (e.span, e.operator))
        );
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
fn deep_formulas_normalise_and_classify_without_recursion() {
    let negations = parsed(&format!("{}a", "!".repeat(DEPTH)));
    assert_eq!(ltl::positive_normal_form(&negations), Formula::atom("a"));
    assert_eq!(ltl::check_co_safe(&negations), Ok(()));

    let alternating = format!("{}a{}", "!(b U ".repeat(DEPTH), ")".repeat(DEPTH));
    let formula = parsed(&alternating);
    let pnf = ltl::positive_normal_form(&formula);
    assert!(is_positive_normal_form(&pnf));
    let error = ltl::check_co_safe(&formula).expect_err("the outer U is negated");
    assert_eq!(error.position(&alternating).column, 5);
    assert_eq!(ltl::atomic_propositions(&formula), ["b", "a"]);

    let implications = parsed(&format!("{}c", "a -> ".repeat(DEPTH)));
    match &ltl::positive_normal_form(&implications).kind {
        FormulaKind::Nary(NaryOp::Or, operands) => assert_eq!(operands.len(), DEPTH + 1),
        other => panic!("expected one flat disjunction, got {other:?}"),
    }
    let globally = format!("{}a", "X".repeat(DEPTH) + "G");
    let error = ltl::check_co_safe(&parsed(&globally)).expect_err("G");
    assert_eq!(error.position(&globally).column, DEPTH + 1);
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
    assert!(
        error
            .first()
            .message
            .contains("expected a formula after `(`")
    );
    assert!(error.to_string().len() < 300);
}

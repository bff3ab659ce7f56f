//! The built-in translation against an independent oracle, on random co-safe formulas that use
//! every operator (the Spot fixtures are in positive normal form, so they never contain `->`,
//! `<->`, `xor`, nor `W`, `R`, `G` under a negation).
//!
//! The oracle evaluates a formula on a lasso word `u v^ω` directly, by fixpoints over the
//! lasso's positions. A co-safe formula holds on an infinite word iff some prefix is good, and
//! the DFA's final states are absorbing, so the lasso satisfies the formula iff the DFA reaches a
//! final state on `u v^k` once `k` exceeds its number of states.

use hypersynth::automata::Dfa;
use hypersynth::ltl::{self, BinaryOp, Formula, FormulaKind, NaryOp, UnaryOp};
use hypersynth::translate::{Builtin, Translator};
use proptest::prelude::*;

/// Letters are bit sets over the propositions `a` (bit 0) and `b` (bit 1).
const NAMES: [&str; 2] = ["a", "b"];

/// A lasso `prefix loop^ω`, as the letters of its positions and each position's successor.
struct Lasso {
    letters: Vec<u8>,
    next: Vec<usize>,
}

impl Lasso {
    fn new(prefix: &[u8], cycle: &[u8]) -> Lasso {
        let letters: Vec<u8> = prefix.iter().chain(cycle).copied().collect();
        let n = letters.len();
        let next = (0..n)
            .map(|i| if i + 1 < n { i + 1 } else { prefix.len() })
            .collect();
        Lasso { letters, next }
    }

    /// For each position, whether `formula` holds there.
    fn holds(&self, formula: &Formula) -> Vec<bool> {
        let n = self.letters.len();
        let operands: Vec<Vec<bool>> = formula.children().map(|f| self.holds(f)).collect();
        let pointwise = |f: &dyn Fn(usize) -> bool| (0..n).map(f).collect::<Vec<bool>>();
        // `now(i) | (stay(i) & X it)`, least (strong) or greatest (weak) fixpoint.
        let until = |now: &[bool], stay: &[bool], strong: bool| {
            let mut value = vec![!strong; n];
            loop {
                let updated: Vec<bool> = (0..n)
                    .map(|i| now[i] || (stay[i] && value[self.next[i]]))
                    .collect();
                if updated == value {
                    return value;
                }
                value = updated;
            }
        };
        let never = vec![false; n];
        let always = vec![true; n];
        let not = |v: &[bool]| v.iter().map(|x| !x).collect::<Vec<bool>>();
        let and = |x: &[bool], y: &[bool]| pointwise(&|i| x[i] && y[i]);
        match &formula.kind {
            FormulaKind::Const(value) => vec![*value; n],
            FormulaKind::Atom(name) => {
                let bit = NAMES.iter().position(|n| n == name).unwrap();
                pointwise(&|i| self.letters[i] & (1 << bit) != 0)
            }
            FormulaKind::Unary(op, _) => {
                let x = &operands[0];
                match op {
                    UnaryOp::Not => not(x),
                    UnaryOp::Next => pointwise(&|i| x[self.next[i]]),
                    UnaryOp::Finally => until(x, &always, true),
                    // G x = !F !x
                    UnaryOp::Globally => not(&until(&not(x), &always, true)),
                }
            }
            FormulaKind::Binary(op, _, _) => {
                let (x, y) = (&operands[0], &operands[1]);
                match op {
                    BinaryOp::Xor => pointwise(&|i| x[i] != y[i]),
                    BinaryOp::Implies => pointwise(&|i| !x[i] || y[i]),
                    BinaryOp::Equiv => pointwise(&|i| x[i] == y[i]),
                    BinaryOp::Until => until(y, x, true),
                    BinaryOp::WeakUntil => until(y, x, false),
                    // x M y = y U (x & y); x R y = y W (x & y)
                    BinaryOp::StrongRelease => until(&and(x, y), y, true),
                    BinaryOp::Release => until(&and(x, y), y, false),
                }
            }
            FormulaKind::Nary(op, _) => {
                operands
                    .iter()
                    .fold(
                        if *op == NaryOp::And { always } else { never },
                        |acc, v| match op {
                            NaryOp::And => and(&acc, v),
                            NaryOp::Or => pointwise(&|i| acc[i] || v[i]),
                        },
                    )
            }
        }
    }
}

/// Whether the DFA accepts some prefix of `prefix cycle^ω`.
fn dfa_accepts_lasso(dfa: &Dfa, prefix: &[u8], cycle: &[u8]) -> bool {
    let letter = |bits: u8| {
        let names = NAMES
            .iter()
            .enumerate()
            .filter(|(bit, _)| bits & (1 << bit) != 0)
            .map(|(_, name)| *name);
        dfa.letter(names)
    };
    let repeats = dfa.num_states() + 1;
    let word = prefix
        .iter()
        .chain(cycle.iter().cycle().take(cycle.len() * repeats));
    let mut state = dfa.initial();
    for &bits in word {
        if dfa.is_final(state) {
            return true;
        }
        state = dfa.step(state, letter(bits));
    }
    dfa.is_final(state)
}

fn formulas() -> impl Strategy<Value = Formula> {
    let leaf = prop_oneof![
        Just(Formula::atom("a")),
        Just(Formula::atom("b")),
        any::<bool>().prop_map(Formula::constant),
    ];
    leaf.prop_recursive(4, 24, 2, |inner| {
        let unary = prop_oneof![
            Just(UnaryOp::Not),
            Just(UnaryOp::Next),
            Just(UnaryOp::Finally),
            Just(UnaryOp::Globally),
        ];
        let binary = prop_oneof![
            Just(BinaryOp::Xor),
            Just(BinaryOp::Implies),
            Just(BinaryOp::Equiv),
            Just(BinaryOp::Until),
            Just(BinaryOp::Release),
            Just(BinaryOp::WeakUntil),
            Just(BinaryOp::StrongRelease),
        ];
        prop_oneof![
            (unary, inner.clone()).prop_map(|(op, f)| Formula::unary(op, f)),
            (binary, inner.clone(), inner.clone()).prop_map(|(op, l, r)| Formula::binary(op, l, r)),
            (inner.clone(), inner.clone()).prop_map(|(l, r)| Formula::and(vec![l, r])),
            (inner.clone(), inner).prop_map(|(l, r)| Formula::or(vec![l, r])),
        ]
    })
}

/// Every lasso with a prefix of at most 2 letters and a cycle of 1 or 2.
fn lassos() -> Vec<(Vec<u8>, Vec<u8>)> {
    let words = |lengths: std::ops::RangeInclusive<u32>| {
        lengths
            .flat_map(|len| {
                (0..4u32.pow(len))
                    .map(move |code| (0..len).map(|i| (code >> (2 * i)) as u8 & 3).collect())
            })
            .collect::<Vec<Vec<u8>>>()
    };
    let cycles = words(1..=2);
    words(0..=2)
        .into_iter()
        .flat_map(|prefix| {
            cycles
                .iter()
                .map(move |cycle| (prefix.clone(), cycle.clone()))
        })
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn the_dfa_accepts_a_lasso_iff_the_formula_holds_on_it(formula in formulas()) {
        prop_assume!(ltl::check_co_safe(&formula).is_ok());
        let dfa = Builtin::default().translate(&formula).unwrap();
        for (prefix, cycle) in lassos() {
            let expected = Lasso::new(&prefix, &cycle).holds(&formula)[0];
            prop_assert_eq!(
                dfa_accepts_lasso(&dfa, &prefix, &cycle),
                expected,
                "{} on {:?} ({:?})^ω",
                formula,
                prefix,
                cycle
            );
        }
    }
}

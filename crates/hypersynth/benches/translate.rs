//! Translates the 300 formulas of tests/fixtures/spot with the built-in translator in one
//! process and reports the total time (parsing excluded), the best of a few rounds; then the
//! `U` chain of issue 15, `a0 U a1 U … U a4 U a0 …` with 1000 operands over 5 propositions.
//! Run with `cargo bench --bench translate`. Spot's `ltl2tgba` takes about 0.15 s for the same
//! 300 formulas (one process reading them all), and more than 60 s for the chain with 300
//! operands.

use std::time::{Duration, Instant};

use hypersynth::ltl;
use hypersynth::translate::{Builtin, Translator};

const ROUNDS: usize = 5;

fn main() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../tests/fixtures/spot/formulas.ltl"
    );
    let text = std::fs::read_to_string(path).expect("the fixture formulas are readable");
    let formulas: Vec<ltl::Formula> = text
        .lines()
        .map(|line| ltl::parse(line).expect("the fixture formulas parse"))
        .collect();
    let mut best = Duration::MAX;
    let mut states = 0;
    for _ in 0..ROUNDS {
        let start = Instant::now();
        states = formulas
            .iter()
            .map(|f| {
                Builtin::default()
                    .translate(f)
                    .expect("fixtures are co-safe")
                    .num_states()
            })
            .sum::<usize>();
        best = best.min(start.elapsed());
    }
    println!(
        "translate: {} formulas ({states} DFA states in all) in {:.1} ms (best of {ROUNDS})",
        formulas.len(),
        best.as_secs_f64() * 1e3
    );

    let operands: Vec<String> = (0..1000).map(|i| format!("a{}", i % 5)).collect();
    let chain = ltl::parse(&operands.join(" U ")).expect("the chain parses");
    let mut best = Duration::MAX;
    for _ in 0..ROUNDS {
        let start = Instant::now();
        states = Builtin::default()
            .translate(&chain)
            .expect("the chain is co-safe")
            .num_states();
        best = best.min(start.elapsed());
    }
    println!(
        "translate: the 1000-operand U chain ({states} DFA states) in {:.1} ms (best of {ROUNDS})",
        best.as_secs_f64() * 1e3
    );
}

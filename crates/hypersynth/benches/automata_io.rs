//! Timing of the HOA reader and writer and of language comparison on a large generated DFA
//! (plain std::time; run with `cargo bench --bench automata_io`).

use std::time::Instant;

use hypersynth::automata::compare::equivalence_counterexample;
use hypersynth::automata::{Dfa, Guard, hoa};

/// A counter modulo `n` over 3 propositions: `a & !b` advances, `b` resets, otherwise stay;
/// the last state is final and absorbing.
fn counter(n: u32) -> Dfa {
    let a = Guard::literal(0, true);
    let b = Guard::literal(1, true);
    let advance = a.and(&b.not());
    let stay = a.or(&b).not();
    let edges = (0..n)
        .map(|q| {
            if q == n - 1 {
                vec![(Guard::always(), q)]
            } else {
                vec![(advance.clone(), q + 1), (b.clone(), 0), (stay.clone(), q)]
            }
        })
        .collect();
    let aps = ["a", "b", "c"].map(String::from).to_vec();
    Dfa::new(aps, 0, [n as usize - 1].into_iter().collect(), edges).unwrap()
}

fn main() {
    let n = 100_000;
    let start = Instant::now();
    let dfa = counter(n);
    println!("build {n}-state DFA: {:?}", start.elapsed());
    let start = Instant::now();
    let text = hoa::write(&dfa, Some("counter")).unwrap();
    println!("write HOA ({} bytes): {:?}", text.len(), start.elapsed());
    let start = Instant::now();
    let again = hoa::parse(&text).unwrap();
    println!("read HOA: {:?}", start.elapsed());
    let start = Instant::now();
    assert_eq!(equivalence_counterexample(&dfa, &again[0].dfa), Ok(None));
    println!(
        "equivalence with itself after round trip: {:?}",
        start.elapsed()
    );
}

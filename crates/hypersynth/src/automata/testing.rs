//! Automata for tests and benchmarks, written as transition tables: shared by the crate's unit
//! and integration tests, its benchmarks and the command's tests (compiled for the crate's own
//! tests, and elsewhere with the `testing` feature; not part of the API).

use bit_set::BitSet;

use super::{Cube, Dfa, Guard};

/// A DFA over `aps` whose state `q` moves to `table[q][letter]` on each of the `2^|aps|`
/// letters (bit `i` of a letter for `aps[i]`), with one minterm guard per letter.
pub fn dfa_from_table(aps: &[&str], initial: u32, finals: &[u32], table: &[Vec<u32>]) -> Dfa {
    let mask = (1u64 << aps.len()) - 1;
    let edges = table
        .iter()
        .map(|row| {
            assert_eq!(row.len() as u64, mask + 1, "one target per letter");
            row.iter()
                .enumerate()
                .map(|(letter, &target)| {
                    let letter = letter as u64;
                    let cube = Cube {
                        positive: letter,
                        negative: !letter & mask,
                    };
                    (Guard::from_cubes([cube]), target)
                })
                .collect()
        })
        .collect();
    Dfa::new(
        aps.iter().map(|ap| ap.to_string()).collect(),
        initial,
        finals.iter().map(|&q| q as usize).collect::<BitSet>(),
        edges,
    )
    .expect("a table gives a complete deterministic automaton")
}

/// `F p`: state 0 waits for `p`, state 1 is final and absorbing.
pub fn eventually(p: &str) -> Dfa {
    dfa_from_table(&[p], 0, &[1], &[vec![0, 1], vec![1, 1]])
}

/// `!o U p` over [o, p]: 0 initial, 1 final (absorbing), 2 rejecting sink (absorbing).
pub fn avoid_until(o: &str, p: &str) -> Dfa {
    // Letters: bit 0 = o, bit 1 = p; p wins over o, as `!o U p` is satisfied when p holds.
    dfa_from_table(
        &[o, p],
        0,
        &[1],
        &[vec![0, 2, 1, 1], vec![1, 1, 1, 1], vec![2, 2, 2, 2]],
    )
}

//! Language equivalence and inclusion of two DFAs, with a shortest counterexample.
//!
//! Propositions are matched by name: the two automata may list them in different orders or have
//! different sets, and a proposition one automaton lacks is unconstrained for it (its language
//! is closed under changing that proposition). Only the propositions some guard mentions are
//! considered, so the joint alphabet is 2^P with P the union of the two automata's supports; a
//! comparison fails only when P has more than [`MAX_PROPOSITIONS`] names.
//!
//! The search is a breadth-first traversal of the synchronous product: the successors of a pair
//! of states are given by the pairs of their edges whose guards (moved into the joint
//! numbering) intersect, so a pair costs `deg1 × deg2` conjunctions of guards. (A global
//! alphabet of minterms, one letter per class either automaton can tell apart, can be
//! exponential in the number of guards: `p0 & X(p1 & X(…))` has 2^n.) Reached
//! pairs are kept in a hash set: they are usually far fewer than `|Q1| * |Q2|` (about
//! `max(|Q1|, |Q2|)` for equivalent automata), which a dense bit set would have to cover.
//! Breadth-first order makes the counterexample a shortest one.

use std::collections::{BTreeSet, HashSet};
use std::fmt;

use super::dfa::{Dfa, DfaState};
use super::guard::{Guard, MAX_PROPOSITIONS};

/// A finite word on which the two automata disagree.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Counterexample {
    /// The letters, each the set of propositions (by name) that hold in it; the others are false.
    pub word: Vec<BTreeSet<String>>,
    /// Whether the left automaton accepts the word (the right one then rejects it, and vice versa).
    pub accepted_by_left: bool,
}

impl fmt::Display for Counterexample {
    /// Letters as `{a, b}` separated by spaces; the empty word is `ε`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.word.is_empty() {
            return f.write_str("ε");
        }
        for (i, letter) in self.word.iter().enumerate() {
            if i > 0 {
                f.write_str(" ")?;
            }
            let names: Vec<&str> = letter.iter().map(String::as_str).collect();
            write!(f, "{{{}}}", names.join(", "))?;
        }
        Ok(())
    }
}

/// Why two automata cannot be compared.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum CompareError {
    /// The automata together mention the given number of distinct propositions, more than
    /// [`MAX_PROPOSITIONS`].
    #[error(
        "the two automata mention {0} distinct atomic propositions, more than the {MAX_PROPOSITIONS} \
         a comparison can handle"
    )]
    TooManyPropositions(usize),
}

/// `None` when `left` and `right` accept the same words, otherwise a shortest word accepted by
/// exactly one of them.
pub fn equivalence_counterexample(
    left: &Dfa,
    right: &Dfa,
) -> Result<Option<Counterexample>, CompareError> {
    shortest_disagreement(left, right, |in_left, in_right| in_left != in_right)
}

/// `None` when every word `left` accepts is accepted by `right`, otherwise a shortest word
/// accepted by `left` and rejected by `right`.
pub fn inclusion_counterexample(
    left: &Dfa,
    right: &Dfa,
) -> Result<Option<Counterexample>, CompareError> {
    shortest_disagreement(left, right, |in_left, in_right| in_left && !in_right)
}

/// One automaton seen through the joint numbering of propositions.
struct Side<'a> {
    dfa: &'a Dfa,
    /// `(own bit, joint bit)` for each proposition its guards mention.
    bits: Vec<(u32, u32)>,
}

impl Side<'_> {
    /// Each state's edges with their guards in the joint numbering.
    fn joint_edges(&self) -> Vec<Vec<(Guard, DfaState)>> {
        let mut positions = vec![0u32; self.dfa.aps().len()];
        for &(own, joint) in &self.bits {
            positions[own as usize] = joint;
        }
        (0..self.dfa.num_states() as DfaState)
            .map(|q| {
                self.dfa
                    .edges(q)
                    .map(|(g, t)| (g.remap(&positions), t))
                    .collect()
            })
            .collect()
    }
}

/// The propositions some guard of `dfa` mentions.
fn support(dfa: &Dfa) -> u64 {
    (0..dfa.num_states() as DfaState)
        .flat_map(|q| dfa.edges(q))
        .fold(0, |acc, (g, _)| acc | g.support())
}

/// Numbers the propositions the two automata mention: `left`'s in its order, then `right`'s new
/// names in its order.
fn joint_numbering<'a>(
    left: &'a Dfa,
    right: &'a Dfa,
) -> Result<(Vec<&'a str>, Side<'a>, Side<'a>), CompareError> {
    let mut names: Vec<&str> = Vec::new();
    let mut side = |dfa: &'a Dfa| {
        let used = support(dfa);
        let mut bits = Vec::new();
        for (own, name) in dfa.aps().iter().enumerate() {
            if used & (1u64 << own) == 0 {
                continue;
            }
            let joint = match names.iter().position(|n| *n == name.as_str()) {
                Some(j) => j,
                None => {
                    names.push(name);
                    names.len() - 1
                }
            };
            bits.push((own as u32, joint as u32));
        }
        Side { dfa, bits }
    };
    let (left_side, right_side) = (side(left), side(right));
    if names.len() > MAX_PROPOSITIONS {
        return Err(CompareError::TooManyPropositions(names.len()));
    }
    Ok((names, left_side, right_side))
}

/// A reached pair of states and how it was reached: the queue index of its parent and the
/// letter read (none for the start pair).
struct Reached {
    pair: (DfaState, DfaState),
    via: Option<(usize, u64)>,
}

/// Breadth-first search of the product for a pair of states where `differs(left final, right
/// final)` holds; returns the word leading to the first one found. The successors of a pair are
/// those of its pairs of edges whose guards intersect, with the smallest letter of the
/// intersection: no alphabet of minterms, whose size can be exponential in the number of guards
/// (a chain `p0 & X(p1 & X(…))` has one guard per proposition, and 2^n minterms).
fn shortest_disagreement(
    left: &Dfa,
    right: &Dfa,
    differs: impl Fn(bool, bool) -> bool,
) -> Result<Option<Counterexample>, CompareError> {
    let (names, left_side, right_side) = joint_numbering(left, right)?;
    let (left_edges, right_edges) = (left_side.joint_edges(), right_side.joint_edges());

    let width = right.num_states();
    let key = |(p, q): (DfaState, DfaState)| p as u64 * width as u64 + q as u64;
    let mut reached = HashSet::new();
    let mut queue: Vec<Reached> = Vec::new();
    let start = (left.initial(), right.initial());
    reached.insert(key(start));
    queue.push(Reached {
        pair: start,
        via: None,
    });
    let mut head = 0;
    while head < queue.len() {
        let (p, q) = queue[head].pair;
        if differs(left.is_final(p), right.is_final(q)) {
            return Ok(Some(Counterexample {
                word: word_to(&queue, head, &names),
                accepted_by_left: left.is_final(p),
            }));
        }
        for (left_guard, left_target) in &left_edges[p as usize] {
            for (right_guard, right_target) in &right_edges[q as usize] {
                let next = (*left_target, *right_target);
                if reached.contains(&key(next)) {
                    continue;
                }
                if let Some(letter) = left_guard.and(right_guard).smallest_letter() {
                    reached.insert(key(next));
                    queue.push(Reached {
                        pair: next,
                        via: Some((head, letter)),
                    });
                }
            }
        }
        head += 1;
    }
    Ok(None)
}

/// The word along the parent links from the start pair to queue entry `index`.
fn word_to(queue: &[Reached], mut index: usize, names: &[&str]) -> Vec<BTreeSet<String>> {
    let mut word = Vec::new();
    while let Some((parent, letter)) = queue[index].via {
        word.push(
            names
                .iter()
                .enumerate()
                .filter(|&(j, _)| letter & (1u64 << j) != 0)
                .map(|(_, name)| name.to_string())
                .collect(),
        );
        index = parent;
    }
    word.reverse();
    word
}

#[cfg(test)]
mod tests {
    use super::*;

    fn aps(names: &[&str]) -> Vec<String> {
        names.iter().map(|s| s.to_string()).collect()
    }

    /// The two-state DFA accepting the words whose first letter satisfies `guard` (state 1
    /// final, 2 rejecting sink, both absorbing).
    fn first_letter(names: &[&str], guard: Guard) -> Dfa {
        Dfa::new(
            aps(names),
            0,
            [1].into_iter().collect(),
            vec![
                vec![(guard.clone(), 1), (guard.not(), 2)],
                vec![(Guard::always(), 1)],
                vec![(Guard::always(), 2)],
            ],
        )
        .unwrap()
    }

    fn set(names: &[&str]) -> BTreeSet<String> {
        names.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn propositions_are_matched_by_name_whatever_their_order() {
        // a & !b over [a, b] and over [b, a].
        let x = first_letter(
            &["a", "b"],
            Guard::literal(0, true).and(&Guard::literal(1, false)),
        );
        let y = first_letter(
            &["b", "a"],
            Guard::literal(1, true).and(&Guard::literal(0, false)),
        );
        assert_eq!(equivalence_counterexample(&x, &y), Ok(None));
        // a & b differs from a & !b first on the letter {a, b} (accepted by the right one) or
        // {a} (accepted by the left one): minterm order decides which; both are length 1.
        let z = first_letter(
            &["b", "a"],
            Guard::literal(1, true).and(&Guard::literal(0, true)),
        );
        let cex = equivalence_counterexample(&x, &z).unwrap().unwrap();
        assert_eq!(cex.word.len(), 1);
        let expected = if cex.accepted_by_left {
            set(&["a"])
        } else {
            set(&["a", "b"])
        };
        assert_eq!(cex.word[0], expected);
    }

    #[test]
    fn inclusion_with_different_proposition_sets() {
        // a & b ⊆ a, not the converse; the counterexample to a ⊆ a & b is {a}.
        let ab = first_letter(
            &["a", "b"],
            Guard::literal(0, true).and(&Guard::literal(1, true)),
        );
        let a = first_letter(&["a"], Guard::literal(0, true));
        assert_eq!(inclusion_counterexample(&ab, &a), Ok(None));
        let cex = inclusion_counterexample(&a, &ab).unwrap().unwrap();
        assert_eq!(cex.word, vec![set(&["a"])]);
        assert!(cex.accepted_by_left);
        assert_eq!(cex.to_string(), "{a}");
        // c is unconstrained for both: a over [a] equals a over [c, a] whatever c is.
        let a_with_c = first_letter(&["c", "a"], Guard::literal(1, true));
        assert_eq!(equivalence_counterexample(&a, &a_with_c), Ok(None));
    }

    #[test]
    fn counterexamples_are_shortest_and_may_be_empty() {
        let a = first_letter(&["a"], Guard::literal(0, true));
        // The universal DFA: one final state.
        let all = Dfa::new(
            aps(&[]),
            0,
            [0].into_iter().collect(),
            vec![vec![(Guard::always(), 0)]],
        )
        .unwrap();
        let cex = equivalence_counterexample(&all, &a).unwrap().unwrap();
        assert_eq!(cex.word, Vec::<BTreeSet<String>>::new());
        assert!(cex.accepted_by_left);
        assert_eq!(cex.to_string(), "ε");
        // "X a" (a in the second letter) vs "a": the shortest difference has length 1 (the
        // empty word is rejected by both), and the word is {a} (accepted by "a" only).
        let xa = Dfa::new(
            aps(&["a"]),
            0,
            [2].into_iter().collect(),
            vec![
                vec![(Guard::always(), 1)],
                vec![(Guard::literal(0, true), 2), (Guard::literal(0, false), 3)],
                vec![(Guard::always(), 2)],
                vec![(Guard::always(), 3)],
            ],
        )
        .unwrap();
        let cex = equivalence_counterexample(&xa, &a).unwrap().unwrap();
        assert_eq!(cex.word, vec![set(&["a"])]);
        assert!(!cex.accepted_by_left);
        // Xa ⊄ a: {} {a} is accepted by Xa, rejected by a.
        let cex = inclusion_counterexample(&xa, &a).unwrap().unwrap();
        assert_eq!(cex.word, vec![set(&[]), set(&["a"])]);
        assert!(xa.accepts([0, 1]) && !a.accepts([0, 1]));
    }

    /// A DFA over `names` from an explicit transition table: `table[q][letter]`.
    fn from_table(names: &[&str], table: &[Vec<u32>], finals: &[bool]) -> Dfa {
        let k = names.len() as u32;
        let letter_guard = |letter: u64| {
            Guard::from_cubes([crate::automata::Cube {
                positive: letter,
                negative: !letter & ((1u64 << k) - 1),
            }])
        };
        let edges = table
            .iter()
            .map(|row| {
                row.iter()
                    .enumerate()
                    .map(|(letter, &target)| (letter_guard(letter as u64), target))
                    .collect()
            })
            .collect();
        let finals = (0..finals.len()).filter(|&q| finals[q]).collect();
        Dfa::new(aps(names), 0, finals, edges).unwrap()
    }

    /// The length of a shortest word on which `differs` holds, by brute force over every letter
    /// of the joint alphabet (names sorted), independently of minterms.
    fn naive_shortest(left: &Dfa, right: &Dfa, differs: fn(bool, bool) -> bool) -> Option<usize> {
        let mut names: Vec<&str> = left
            .aps()
            .iter()
            .chain(right.aps())
            .map(String::as_str)
            .collect();
        names.sort();
        names.dedup();
        let own = |dfa: &Dfa, joint: u64| {
            let true_names = names
                .iter()
                .enumerate()
                .filter(|&(j, _)| joint & (1 << j) != 0);
            dfa.letter(true_names.map(|(_, n)| *n))
        };
        let mut frontier = vec![(left.initial(), right.initial())];
        let mut seen = frontier.clone();
        for length in 0.. {
            if frontier
                .iter()
                .any(|&(p, q)| differs(left.is_final(p), right.is_final(q)))
            {
                return Some(length);
            }
            let mut next = Vec::new();
            for &(p, q) in &frontier {
                for joint in 0..1u64 << names.len() {
                    let pair = (
                        left.step(p, own(left, joint)),
                        right.step(q, own(right, joint)),
                    );
                    if !seen.contains(&pair) {
                        seen.push(pair);
                        next.push(pair);
                    }
                }
            }
            if next.is_empty() {
                return None;
            }
            frontier = next;
        }
        unreachable!()
    }

    fn random_dfa() -> impl proptest::strategy::Strategy<Value = Dfa> {
        use proptest::prelude::*;
        let names = Just(vec!["a", "b", "c"])
            .prop_shuffle()
            .prop_flat_map(|all| (0..=3usize).prop_map(move |k| all[..k].to_vec()));
        (names, 1..=4usize).prop_flat_map(|(names, n)| {
            let letters = 1usize << names.len();
            let row = proptest::collection::vec(0..n as u32, letters);
            (
                Just(names),
                proptest::collection::vec(row, n),
                proptest::collection::vec(any::<bool>(), n),
            )
                .prop_map(|(names, table, finals)| from_table(&names, &table, &finals))
        })
    }

    fn word_letters(dfa: &Dfa, cex: &Counterexample) -> Vec<u64> {
        cex.word
            .iter()
            .map(|letter| dfa.letter(letter.iter().map(String::as_str)))
            .collect()
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(128))]

        #[test]
        fn comparison_agrees_with_brute_force(left in random_dfa(), right in random_dfa()) {
            let cex = equivalence_counterexample(&left, &right).unwrap();
            let naive = naive_shortest(&left, &right, |x, y| x != y);
            proptest::prop_assert_eq!(cex.as_ref().map(|c| c.word.len()), naive);
            if let Some(cex) = cex {
                proptest::prop_assert_eq!(left.accepts(word_letters(&left, &cex)), cex.accepted_by_left);
                proptest::prop_assert_eq!(right.accepts(word_letters(&right, &cex)), !cex.accepted_by_left);
            }
            let cex = inclusion_counterexample(&left, &right).unwrap();
            let naive = naive_shortest(&left, &right, |x, y| x && !y);
            proptest::prop_assert_eq!(cex.as_ref().map(|c| c.word.len()), naive);
            if let Some(cex) = cex {
                proptest::prop_assert!(cex.accepted_by_left);
                proptest::prop_assert!(left.accepts(word_letters(&left, &cex)));
                proptest::prop_assert!(!right.accepts(word_letters(&right, &cex)));
            }
        }
    }
}

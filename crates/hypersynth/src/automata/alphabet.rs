//! Letter classes: the minterms of a set of guards.
//!
//! Two letters that satisfy exactly the same guards are indistinguishable to every automaton
//! built from those guards, so algorithms that must try "every letter" (language comparison,
//! minimisation) need only one representative per class. The classes are the atoms of the
//! Boolean algebra the guards generate; they are computed symbolically, by refining the single
//! class `true` with each guard in turn (splitting every class into its parts inside and outside
//! the guard and keeping the satisfiable parts), never by enumerating 2^AP letters. Their number
//! is at most `min(2^AP, 2^guards)` and usually far smaller.

use std::collections::HashSet;

use super::guard::Guard;

/// One letter class: a satisfiable guard, disjoint from every other class, and a letter in it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Minterm {
    /// The class, as a satisfiable guard disjoint from every other class's.
    pub guard: Guard,
    /// A letter satisfying `guard` (propositions it leaves free are false).
    pub witness: u64,
}

/// The minterms of `guards`: pairwise-disjoint satisfiable guards whose union is valid, such that
/// each minterm lies entirely inside or entirely outside each given guard, each with a witness
/// letter. The order depends only on the guards and their order.
pub fn minterms<'a>(guards: impl IntoIterator<Item = &'a Guard>) -> Vec<Minterm> {
    minterms_at_most(guards, usize::MAX).expect("no bound")
}

/// [`minterms`], or `None` as soon as there are more than `bound`: `k` guards can have 2^k
/// minterms (one guard per proposition, say), so callers that can do without bound them.
pub fn minterms_at_most<'a>(
    guards: impl IntoIterator<Item = &'a Guard>,
    bound: usize,
) -> Option<Vec<Minterm>> {
    let mut classes = vec![Guard::always()];
    let mut seen: HashSet<&Guard> = HashSet::new();
    for guard in guards {
        // A guard that is trivial or already used splits nothing.
        if !guard.is_satisfiable() || !seen.insert(guard) {
            continue;
        }
        let outside = guard.not();
        if !outside.is_satisfiable() {
            continue;
        }
        classes = classes
            .iter()
            .flat_map(|class| [class.and(guard), class.and(&outside)])
            .filter(Guard::is_satisfiable)
            .collect();
        if classes.len() > bound {
            return None;
        }
    }
    Some(
        classes
            .into_iter()
            .filter_map(|guard| {
                let witness = guard.witness()?;
                Some(Minterm { guard, witness })
            })
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The number of distinct "which guards hold" signatures over all letters of `n`
    /// propositions: the number of non-empty atoms, computed by brute force.
    fn brute_force_class_count(guards: &[Guard], n: u32) -> usize {
        let mut signatures: Vec<Vec<bool>> = (0..1u64 << n)
            .map(|letter| guards.iter().map(|g| g.evaluate(letter)).collect())
            .collect();
        signatures.sort();
        signatures.dedup();
        signatures.len()
    }

    fn check_partition(guards: &[Guard], n: u32) {
        let classes = minterms(guards);
        assert_eq!(classes.len(), brute_force_class_count(guards, n));
        for letter in 0..1u64 << n {
            // Every letter lies in exactly one class...
            let owners: Vec<&Minterm> = classes
                .iter()
                .filter(|m| m.guard.evaluate(letter))
                .collect();
            assert_eq!(owners.len(), 1, "letter {letter:b}");
            // ...and agrees with its class's witness on every guard.
            let witness = owners[0].witness;
            for g in guards {
                assert_eq!(g.evaluate(letter), g.evaluate(witness));
            }
        }
        for m in &classes {
            assert!(m.guard.evaluate(m.witness));
        }
    }

    #[test]
    fn minterms_partition_the_letters_by_guard_signature() {
        let a = Guard::literal(0, true);
        let b = Guard::literal(1, true);
        let c = Guard::literal(2, true);
        check_partition(&[], 3);
        check_partition(&[Guard::always(), Guard::never()], 2);
        check_partition(std::slice::from_ref(&a), 3);
        check_partition(&[a.clone(), a.not()], 3);
        check_partition(&[a.and(&b), a.or(&c), b.not().and(&c), a.clone()], 3);
        // Guards that only pair up three propositions out of five: classes stay few.
        check_partition(&[a.and(&b), b.and(&c)], 5);
        assert_eq!(minterms([&a.and(&b), &b.and(&c)]).len(), 4);
    }
}

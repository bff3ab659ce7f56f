//! Minimisation of a complete DFA, with a canonical numbering.
//!
//! [`minimize`] returns the unique (up to guard syntax) minimal complete DFA with the language of
//! its input:
//! 1. states unreachable from the initial state are dropped;
//! 2. the alphabet is split into letter classes: when the guards mention few propositions (2^k
//!    letters over them within the table bound, k ≤ 10), by listing those letters, each edge's
//!    letters enumerated from its guard, and grouping the letters that lead every state to the
//!    same successor; otherwise the minterms of the reachable states' guards, computed
//!    symbolically with every guard imported once into one BDD manager (as
//!    [`super::alphabet`] does with guard values); one witness letter per class stands for
//!    the whole class, so no step ever enumerates 2^AP letters. Past 1024 classes (or 2^24
//!    table entries), Moore's refinement on signatures of guard unions, in the same manager,
//!    replaces step 3;
//! 3. Hopcroft's partition refinement, starting from {final, non-final}, splits blocks of
//!    states until every state of a block goes to the same block on every witness letter, in
//!    O(minterms × states × log states) with predecessor lists in CSR form and no hash map
//!    (Moore's simpler refinement needs up to one round per state, quadratic on the long
//!    chains that `X X ... X a` produces);
//! 4. the quotient is written out canonically: states are numbered in breadth-first order from
//!    the initial state, a state's edges sorted by the smallest letter of their guard (disjoint
//!    guards have distinct smallest letters, so the order depends only on the language and the
//!    order of `aps`), and the guards into one target merged. Guards are canonical BDDs, so the
//!    result is the same automaton, edge by edge, whichever member represents a class.
//!
//! Sinks: a minimal complete DFA has at most one rejecting sink (non-final, only a self-loop)
//! and at most one accepting sink. They get no special place: like every state, a sink is
//! numbered where the breadth-first search first meets it. The same language over the same
//! `aps` therefore always gets the same numbering, edge order and edge functions.

use std::cell::Cell;
use std::collections::HashMap;

use bit_set::BitSet;

use super::dfa::{Dfa, DfaState};
use super::guard::Guard;
use crate::bdd::{self, Bdd, Node};
use crate::csr::Csr;
use crate::index::Id;
use crate::limits::{Stop, Work};

/// The minimal complete DFA with the language of `dfa`, over the same propositions, numbered
/// canonically (see the module documentation).
pub fn minimize(dfa: &Dfa) -> Dfa {
    minimize_within(dfa, &mut Work::unlimited(), u64::MAX).expect("nothing limits the work")
}

/// [`minimize`], charging `work` one unit per state, edge, letter or table entry visited (and
/// its BDD steps), and refusing to allocate tables that would make the DFA and the minimiser's
/// arrays together more than `max_bytes`: the translations' limits cover minimisation too.
pub(crate) fn minimize_within(dfa: &Dfa, work: &mut Work, max_bytes: u64) -> Result<Dfa, Stop> {
    let reachable = reachable_states(dfa, work)?;
    let n = reachable.len();
    // What the DFA and the per-state arrays take, before any table.
    let held = dfa_bytes(dfa) + 24 * n as u64;
    let fits = |bytes: u64| {
        if held.saturating_add(bytes) <= max_bytes {
            Ok(())
        } else {
            Err(Stop::Bytes)
        }
    };
    // Hopcroft's tables take (letter classes × states) entries, and the classes can be
    // exponentially many (one guard per proposition: 2^n); past a bound, refine by signatures.
    let bound = (MAX_TABLE / n.max(1)).clamp(16, MAX_LETTER_CLASSES);
    let support = (reachable.iter())
        .flat_map(|&q| dfa.edges(q))
        .fold(0, |acc, (guard, _)| acc | guard.support());
    let class = if 1usize << support.count_ones().min(63) <= bound {
        fits(TABLE_ENTRY_BYTES * ((1u64 << support.count_ones()) * n as u64))?;
        let table = SuccessorTable::by_letters(dfa, &reachable, support, work)?;
        equivalence_classes(dfa, &reachable, &table, work)?
    } else {
        // Many propositions: the guards' own letter classes, symbolically, in one manager.
        fits(IMPORTED_EDGE_BYTES * dfa.num_edges() as u64)?;
        let mut edges = ImportedEdges::new(dfa, &reachable, work)?;
        match edges.minterm_witnesses(bound, work)? {
            Some(letters) => {
                fits(TABLE_ENTRY_BYTES * (letters.len() * n) as u64)?;
                let table = SuccessorTable::by_witnesses(dfa, &reachable, &letters, work)?;
                equivalence_classes(dfa, &reachable, &table, work)?
            }
            None => edges.signature_classes(dfa, &reachable, work)?,
        }
    };
    quotient(dfa, &reachable, &class, work)
}

/// The bytes of a DFA's arrays (its guards' nodes, shared with other DFAs, not counted).
fn dfa_bytes(dfa: &Dfa) -> u64 {
    (dfa.num_edges() * (size_of::<Guard>() + size_of::<DfaState>())
        + dfa.num_states() * size_of::<u32>()) as u64
}

/// The bytes of a (letter class, state) entry of Hopcroft's tables: the successor table while
/// it is built and after, the predecessor lists' entry and offset.
const TABLE_ENTRY_BYTES: u64 = 16;
/// The bytes of an edge imported into one manager: its handle and target, and about a node.
const IMPORTED_EDGE_BYTES: u64 = 32;

/// The guards of the reachable states' edges imported into one BDD manager, for the
/// symbolic computations: node handles are compared and combined there, with the manager's
/// cache, where each operation on [`Guard`] values imports its operands and exports a result.
struct ImportedEdges {
    bdd: Bdd,
    /// `edges[i]`: the (guard, target) pairs of `reachable[i]`.
    edges: Vec<Vec<(Node, DfaState)>>,
}

impl ImportedEdges {
    fn new(dfa: &Dfa, reachable: &[DfaState], work: &mut Work) -> Result<ImportedEdges, Stop> {
        let mut bdd = Bdd::new();
        bdd.set_deadline(work.deadline());
        let mut edges = Vec::with_capacity(reachable.len());
        for &q in reachable {
            let mut state_edges = Vec::with_capacity(dfa.edges(q).len());
            for (guard, target) in dfa.edges(q) {
                work.charge(1 + guard.size() as u64)?;
                state_edges.push((guard.import(&mut bdd), target));
            }
            edges.push(state_edges);
        }
        Ok(ImportedEdges { bdd, edges })
    }

    /// Charges `work` for the manager's steps since the last call (`counted` of them were
    /// charged already), and stops at its deadline.
    fn charge(&self, work: &mut Work, counted: &mut u64) -> Result<(), Stop> {
        let steps = self.bdd.steps();
        work.charge(steps - *counted)?;
        *counted = steps;
        match self.bdd.exhausted() {
            Some(_) => Err(Stop::Time),
            None => Ok(()),
        }
    }

    /// One letter of each class of letters that no guard tells apart (the minterms of the
    /// guards), or `None` as soon as there are more than `bound` classes: every class is split
    /// by each distinct guard in turn.
    fn minterm_witnesses(
        &mut self,
        bound: usize,
        work: &mut Work,
    ) -> Result<Option<Vec<u64>>, Stop> {
        let mut counted = self.bdd.steps();
        let mut classes = vec![bdd::TRUE];
        let mut seen = BitSet::new();
        for &(guard, _) in self.edges.iter().flatten() {
            if guard <= bdd::TRUE || !seen.insert(guard as usize) {
                continue;
            }
            work.charge(classes.len() as u64)?;
            self.charge(work, &mut counted)?;
            let bdd = &mut self.bdd;
            let outside = bdd.not(guard);
            let mut split = Vec::with_capacity(classes.len() + 1);
            for &class in &classes {
                let inside = bdd.and(class, guard);
                if inside == bdd::FALSE || inside == class {
                    split.push(class);
                } else {
                    split.push(inside);
                    split.push(bdd.and(class, outside));
                }
            }
            classes = split;
            if classes.len() > bound {
                return Ok(None);
            }
        }
        self.charge(work, &mut counted)?;
        let witness = |class| Guard::export(&self.bdd, class).smallest_letter();
        Ok(Some(classes.into_iter().filter_map(witness).collect()))
    }

    /// Language-equivalence classes of the `reachable` states, numbered densely, by Moore's
    /// refinement on guards: a state's signature is its block and, per block its edges reach,
    /// the union of their guards (canonical nodes, so compared by equality). One round costs
    /// one disjunction per edge; there are at most as many rounds as states. For automata
    /// whose guards have too many letter classes for [`equivalence_classes`].
    fn signature_classes(
        mut self,
        dfa: &Dfa,
        reachable: &[DfaState],
        work: &mut Work,
    ) -> Result<Vec<u32>, Stop> {
        let mut counted = self.bdd.steps();
        let mut class = vec![u32::NONE; dfa.num_states()];
        for &q in reachable {
            class[q as usize] = u32::from(dfa.is_final(q));
        }
        let mut count = 0;
        loop {
            let mut numbering: HashMap<(u32, Vec<(u32, Node)>), u32> = HashMap::new();
            let mut next = vec![u32::NONE; dfa.num_states()];
            for (&q, edges) in reachable.iter().zip(&self.edges) {
                work.charge(1 + edges.len() as u64)?;
                self.charge(work, &mut counted)?;
                let mut by_block: Vec<(u32, Node)> = Vec::new();
                for &(guard, target) in edges {
                    let block = class[target as usize];
                    match by_block.iter_mut().find(|(b, _)| *b == block) {
                        Some((_, union)) => *union = self.bdd.or(*union, guard),
                        None => by_block.push((block, guard)),
                    }
                }
                by_block.sort_unstable_by_key(|(block, _)| *block);
                let fresh = numbering.len() as u32;
                next[q as usize] = *numbering
                    .entry((class[q as usize], by_block))
                    .or_insert(fresh);
            }
            if numbering.len() == count {
                return Ok(next);
            }
            count = numbering.len();
            class = next;
        }
    }
}

/// The most letter classes Hopcroft's refinement runs with.
const MAX_LETTER_CLASSES: usize = 1 << 10;
/// The most (letter class, state) entries of Hopcroft's tables (4 bytes each).
const MAX_TABLE: usize = 1 << 24;

/// The successor of every reachable state (numbered `0..n` in `reachable` order) on one
/// letter of every letter class: `successors[class * n + state]`.
struct SuccessorTable {
    classes: usize,
    successors: Vec<u32>,
}

impl SuccessorTable {
    /// The table for one witness letter per class.
    fn by_witnesses(
        dfa: &Dfa,
        reachable: &[DfaState],
        letters: &[u64],
        work: &mut Work,
    ) -> Result<SuccessorTable, Stop> {
        let local = local_numbers(dfa, reachable);
        let mut successors = Vec::with_capacity(letters.len() * reachable.len());
        for &letter in letters {
            work.charge(reachable.len() as u64)?;
            successors.extend(
                reachable
                    .iter()
                    .map(|&q| local[dfa.step(q, letter) as usize]),
            );
        }
        Ok(SuccessorTable {
            classes: letters.len(),
            successors,
        })
    }

    /// The table when the guards mention few enough propositions (`support`) to list every
    /// letter over them: each edge's letters are enumerated (every letter once per state, as
    /// a state's guards partition them), then letters with the same column of successors are
    /// one class. O(2^|support| × states), however many distinct guards there are: computing
    /// the minterms by refinement costs a guard conjunction per class and distinct guard
    /// (`F p0 & … & F p9` has 3^10 distinct guards and 2^10 classes: 100 s).
    fn by_letters(
        dfa: &Dfa,
        reachable: &[DfaState],
        support: u64,
        work: &mut Work,
    ) -> Result<SuccessorTable, Stop> {
        let n = reachable.len();
        let local = local_numbers(dfa, reachable);
        let positions: Vec<u32> = (0..64).filter(|&p| support & (1u64 << p) != 0).collect();
        let index = |letter: u64| {
            (positions.iter().enumerate())
                .filter(|&(_, &p)| letter & (1u64 << p) != 0)
                .fold(0usize, |acc, (j, _)| acc | 1 << j)
        };
        let letters = 1usize << positions.len();
        let mut table = vec![u32::NONE; letters * n];
        for (i, &q) in reachable.iter().enumerate() {
            // Each letter once per state, as its guards partition the letters.
            work.charge(letters as u64)?;
            for (guard, target) in dfa.edges(q) {
                let target = local[target as usize];
                guard.for_each_letter(support, |letter| table[index(letter) * n + i] = target);
            }
        }
        debug_assert!(
            !table.contains(&u32::NONE),
            "every state has a successor on every letter"
        );
        // Letters with equal columns are one class; the first letter of each stands for it.
        let mut seen: HashMap<&[u32], ()> = HashMap::new();
        let mut successors = Vec::new();
        for column in table.chunks(n.max(1)) {
            work.charge(n as u64)?;
            if seen.insert(column, ()).is_none() {
                successors.extend_from_slice(column);
            }
        }
        Ok(SuccessorTable {
            classes: seen.len(),
            successors,
        })
    }
}

/// `local[q]`: the index of state `q` in `reachable` (`u32::NONE` if unreachable).
fn local_numbers(dfa: &Dfa, reachable: &[DfaState]) -> Vec<u32> {
    let mut local = vec![u32::NONE; dfa.num_states()];
    for (i, &q) in reachable.iter().enumerate() {
        local[q as usize] = i as u32;
    }
    local
}

/// The states reachable from the initial state, in breadth-first order.
fn reachable_states(dfa: &Dfa, work: &mut Work) -> Result<Vec<DfaState>, Stop> {
    let mut seen = BitSet::with_capacity(dfa.num_states());
    seen.insert(dfa.initial() as usize);
    let mut order = vec![dfa.initial()];
    let mut next = 0;
    while let Some(&state) = order.get(next) {
        next += 1;
        work.charge(1 + dfa.edges(state).len() as u64)?;
        for (_, target) in dfa.edges(state) {
            if seen.insert(target as usize) {
                order.push(target);
            }
        }
    }
    Ok(order)
}

/// Language-equivalence classes of the `reachable` states, by Hopcroft's partition refinement
/// over the letter classes of `table`: `class[q]` for each state `q` of `dfa` (unreachable
/// states keep `u32::NONE`).
///
/// States are numbered `0..n` in `reachable` order. A block is a range of `elements`; a state's
/// `location` is its index there, so marking a state is swapping it into the marked prefix of
/// its block. Splitters are whole blocks, processed for every letter; when a block splits, the
/// smaller part becomes the new block and is queued (if the old block was still queued, its
/// other part stays queued under the old number), hence O(letters × n log n).
fn equivalence_classes(
    dfa: &Dfa,
    reachable: &[DfaState],
    table: &SuccessorTable,
    work: &mut Work,
) -> Result<Vec<u32>, Stop> {
    let n = reachable.len();
    let width = table.classes;
    work.charge((width * n) as u64)?;
    // Predecessors of each (letter, state) pair, keyed by `letter * n + state`. Grouping them
    // makes two passes over `width * n` pairs with scattered writes (a third of a second for
    // 4 096 letters and states), so the deadline is read during the passes too: once it has
    // passed, the pairs end early and the partial grouping is dropped.
    let successor = |i: usize, m: usize| table.successors[m * n + i];
    let key = |m: usize, target: u32| u32::new(m * n + target as usize);
    let deadline = work.deadline();
    let (counted, late) = (Cell::new(0u32), Cell::new(false));
    let in_time = |_: &(u32, u32)| {
        counted.set(counted.get().wrapping_add(1));
        if counted.get().is_multiple_of(1 << 14) && deadline.passed() {
            late.set(true);
        }
        !late.get()
    };
    let sources: Csr<u32, u32> = Csr::group(
        width * n,
        (0..n)
            .flat_map(|i| (0..width).map(move |m| (key(m, successor(i, m)), i as u32)))
            .take_while(in_time),
    );
    if late.get() {
        return Err(Stop::Time);
    }

    // The initial partition: non-final states, then final ones.
    let is_final = |i: usize| dfa.is_final(reachable[i]);
    let mut elements: Vec<u32> = (0..n as u32).filter(|&i| !is_final(i as usize)).collect();
    let non_final = elements.len();
    elements.extend((0..n as u32).filter(|&i| is_final(i as usize)));
    let mut location = vec![0u32; n];
    for (position, &i) in elements.iter().enumerate() {
        location[i as usize] = position as u32;
    }
    let mut block_of: Vec<u32> = (0..n)
        .map(|i| u32::from(is_final(i) && non_final > 0))
        .collect();
    let mut blocks: Vec<(u32, u32)> = Vec::new();
    let mut pending: Vec<u32> = Vec::new();
    if non_final == 0 || non_final == n {
        blocks.push((0, n as u32));
    } else {
        blocks.push((0, non_final as u32));
        blocks.push((non_final as u32, n as u32));
        pending.push(if non_final <= n - non_final { 0 } else { 1 });
    }
    let mut marked = vec![0u32; blocks.len()];
    let mut touched: Vec<u32> = Vec::new();
    let mut splitter: Vec<u32> = Vec::new();
    while let Some(block) = pending.pop() {
        let (start, end) = blocks[block as usize];
        splitter.clear();
        splitter.extend_from_slice(&elements[start as usize..end as usize]);
        for m in 0..width {
            let mut visited = splitter.len();
            for &target in &splitter {
                let row = sources.row(key(m, target));
                visited += row.len();
                for &source in row {
                    let b = block_of[source as usize] as usize;
                    let boundary = blocks[b].0 + marked[b];
                    let position = location[source as usize];
                    if position < boundary {
                        continue; // already marked
                    }
                    let other = elements[boundary as usize];
                    elements.swap(position as usize, boundary as usize);
                    location[other as usize] = position;
                    location[source as usize] = boundary;
                    if marked[b] == 0 {
                        touched.push(b as u32);
                    }
                    marked[b] += 1;
                }
            }
            work.charge(visited as u64)?;
            for b in touched.drain(..) {
                let b = b as usize;
                let (start, end) = blocks[b];
                let split = start + std::mem::take(&mut marked[b]);
                if split == end {
                    continue; // the whole block goes into the splitter: no split
                }
                let new = blocks.len() as u32;
                let (kept, moved) = if split - start <= end - split {
                    ((split, end), (start, split))
                } else {
                    ((start, split), (split, end))
                };
                blocks[b] = kept;
                blocks.push(moved);
                marked.push(0);
                for &i in &elements[moved.0 as usize..moved.1 as usize] {
                    block_of[i as usize] = new;
                }
                pending.push(new);
            }
        }
    }
    let mut class = vec![u32::NONE; dfa.num_states()];
    for (i, &q) in reachable.iter().enumerate() {
        class[q as usize] = block_of[i];
    }
    Ok(class)
}

/// The quotient of `dfa` by `class`, numbered canonically.
fn quotient(
    dfa: &Dfa,
    reachable: &[DfaState],
    class: &[u32],
    work: &mut Work,
) -> Result<Dfa, Stop> {
    let classes = reachable
        .iter()
        .map(|&q| class[q as usize] + 1)
        .max()
        .unwrap_or(0) as usize;
    // The lowest-numbered member of each class stands for it.
    let mut representative = vec![DfaState::NONE; classes];
    for &q in reachable {
        let slot = &mut representative[class[q as usize] as usize];
        *slot = (*slot).min(q);
    }
    let mut number = vec![DfaState::NONE; classes];
    let mut order = vec![class[dfa.initial() as usize]];
    number[order[0] as usize] = 0;
    let mut finals = BitSet::new();
    let mut edges = Vec::with_capacity(classes);
    let mut next = 0;
    while let Some(&c) = order.get(next) {
        let state = representative[c as usize];
        if dfa.is_final(state) {
            finals.insert(next);
        }
        next += 1;
        let mut state_edges: Vec<(Guard, DfaState)> = Vec::new();
        work.charge(1 + dfa.edges(state).len() as u64)?;
        for (guard, target) in dfa.edges(state) {
            let target_class = class[target as usize];
            match state_edges.iter_mut().find(|(_, t)| *t == target_class) {
                Some((existing, _)) => *existing = existing.or(guard),
                None => state_edges.push((guard.clone(), target_class)),
            }
        }
        state_edges.sort_by_cached_key(|(guard, _)| guard.smallest_letter());
        for (_, target) in &mut state_edges {
            let slot = &mut number[*target as usize];
            if slot.is_none() {
                *slot = order.len() as DfaState;
                order.push(*target);
            }
            *target = *slot;
        }
        edges.push(state_edges);
    }
    // The quotient of a deterministic, complete DFA is one.
    Ok(Dfa::from_disjoint(dfa.aps().to_vec(), 0, finals, edges))
}

#[cfg(test)]
mod tests {
    use rand_chacha::ChaCha8Rng;
    use rand_core::{RngCore, SeedableRng};

    use super::*;
    use crate::automata::guard::Cube;

    fn aps(n: usize) -> Vec<String> {
        ["a", "b", "c"][..n].iter().map(|s| s.to_string()).collect()
    }

    /// The full cube of `letter` over `n` propositions.
    fn letter_cube(letter: u64, n: usize) -> Cube {
        Cube {
            positive: letter,
            negative: !letter & ((1 << n) - 1),
        }
    }

    /// A DFA given by its successor on every letter: `table[q][letter]`.
    fn from_table(n: usize, initial: DfaState, finals: &[usize], table: &[Vec<u32>]) -> Dfa {
        let edges = table
            .iter()
            .map(|row| {
                row.iter()
                    .enumerate()
                    .map(|(letter, &t)| (Guard::from_cubes([letter_cube(letter as u64, n)]), t))
                    .collect()
            })
            .collect();
        Dfa::new(aps(n), initial, finals.iter().copied().collect(), edges).unwrap()
    }

    /// Brute force, independent of the refinement above: two reachable states are equivalent
    /// unless a table of distinguishable pairs, filled to a fixpoint over every letter, says
    /// otherwise. Returns the number of classes among reachable states.
    fn brute_force_class_count(dfa: &Dfa) -> usize {
        let n = dfa.num_states();
        let letters = 1u64 << dfa.aps().len();
        let mut reachable = vec![false; n];
        reachable[dfa.initial() as usize] = true;
        let mut changed = true;
        while changed {
            changed = false;
            for q in 0..n {
                for letter in 0..letters {
                    let t = dfa.step(q as DfaState, letter) as usize;
                    if reachable[q] && !reachable[t] {
                        reachable[t] = true;
                        changed = true;
                    }
                }
            }
        }
        let mut distinct: Vec<Vec<bool>> = (0..n)
            .map(|p| {
                (0..n)
                    .map(|q| dfa.is_final(p as DfaState) != dfa.is_final(q as DfaState))
                    .collect()
            })
            .collect();
        changed = true;
        while changed {
            changed = false;
            for p in 0..n {
                for q in 0..n {
                    if distinct[p][q] {
                        continue;
                    }
                    if (0..letters).any(|l| {
                        distinct[dfa.step(p as DfaState, l) as usize]
                            [dfa.step(q as DfaState, l) as usize]
                    }) {
                        distinct[p][q] = true;
                        changed = true;
                    }
                }
            }
        }
        let live: Vec<usize> = (0..n).filter(|&q| reachable[q]).collect();
        live.iter()
            .filter(|&&q| live.iter().take_while(|&&p| p < q).all(|&p| distinct[p][q]))
            .count()
    }

    /// Whether the two automata over the same `aps` accept the same words: a breadth-first walk
    /// of the product over every letter finds no pair that disagrees on acceptance.
    fn same_language(x: &Dfa, y: &Dfa) -> bool {
        let letters = 1u64 << x.aps().len();
        let mut seen = vec![(x.initial(), y.initial())];
        let mut next = 0;
        while let Some(&(p, q)) = seen.get(next) {
            next += 1;
            if x.is_final(p) != y.is_final(q) {
                return false;
            }
            for l in 0..letters {
                let pair = (x.step(p, l), y.step(q, l));
                if !seen.contains(&pair) {
                    seen.push(pair);
                }
            }
        }
        true
    }

    fn random_dfa(rng: &mut ChaCha8Rng) -> Dfa {
        let n = 1 + (rng.next_u32() % 3) as usize;
        let states = 1 + rng.next_u32() % 12;
        let table: Vec<Vec<u32>> = (0..states)
            .map(|_| (0..1 << n).map(|_| rng.next_u32() % states).collect())
            .collect();
        let finals: Vec<usize> = (0..states as usize)
            .filter(|_| rng.next_u32().is_multiple_of(3))
            .collect();
        from_table(n, rng.next_u32() % states, &finals, &table)
    }

    /// The same automaton with states renumbered by `permutation`.
    fn renumbered(dfa: &Dfa, permutation: &[u32]) -> Dfa {
        let mut edges = vec![Vec::new(); dfa.num_states()];
        for q in 0..dfa.num_states() as DfaState {
            edges[permutation[q as usize] as usize] = dfa
                .edges(q)
                .map(|(g, t)| (g.clone(), permutation[t as usize]))
                .collect();
        }
        let finals = dfa
            .finals()
            .iter()
            .map(|q| permutation[q] as usize)
            .collect();
        Dfa::new(
            dfa.aps().to_vec(),
            permutation[dfa.initial() as usize],
            finals,
            edges,
        )
        .unwrap()
    }

    /// Same states, finality and targets, and equivalent guards edge by edge.
    fn assert_same_structure(x: &Dfa, y: &Dfa) {
        assert_eq!(x.num_states(), y.num_states());
        assert_eq!(x.initial(), y.initial());
        assert_eq!(x.finals(), y.finals());
        for q in 0..x.num_states() as DfaState {
            let (ex, ey): (Vec<_>, Vec<_>) = (x.edges(q).collect(), y.edges(q).collect());
            assert_eq!(ex.len(), ey.len());
            for ((gx, tx), (gy, ty)) in ex.iter().zip(&ey) {
                assert_eq!(tx, ty);
                assert!(gx.equivalent(gy));
            }
        }
    }

    #[test]
    fn redundant_states_merge_and_unreachable_ones_go() {
        // `a U b` over [a, b] with the start state duplicated (0 and 3 behave alike, 0 loops
        // through 3 on a & !b), two final states that accept everything (1 and 4), a rejecting
        // sink (2) and an unreachable state (5).
        let (a, b) = (Guard::literal(0, true), Guard::literal(1, true));
        let dfa = Dfa::new(
            aps(2),
            0,
            [1, 4, 5].into_iter().collect(),
            vec![
                vec![(b.clone(), 1), (a.and(&b.not()), 3), (a.or(&b).not(), 2)],
                vec![(a.clone(), 1), (a.not(), 4)],
                vec![(Guard::always(), 2)],
                vec![(b.clone(), 4), (a.and(&b.not()), 0), (a.or(&b).not(), 2)],
                vec![(Guard::always(), 4)],
                vec![(Guard::always(), 0)],
            ],
        )
        .unwrap();
        let minimal = minimize(&dfa);
        // Edges by smallest letter: !a&!b (0) to the sink, a&!b (1) looping, b (2) accepting.
        assert_eq!(minimal.num_states(), 3);
        assert_eq!(minimal.initial(), 0);
        let edges: Vec<(Guard, DfaState)> = minimal.edges(0).map(|(g, t)| (g.clone(), t)).collect();
        assert_eq!(edges.len(), 3);
        assert!(edges[0].0.equivalent(&a.or(&b).not()) && edges[0].1 == 1);
        assert!(edges[1].0.equivalent(&a.and(&b.not())) && edges[1].1 == 0);
        assert_eq!(edges[2], (b.clone(), 2));
        assert!(!minimal.is_final(1) && minimal.is_final(2));
        assert_eq!(
            minimal.edges(1).collect::<Vec<_>>(),
            [(&Guard::always(), 1)]
        );
        // State 1's two edges into the merged final class become one `true` edge.
        assert_eq!(
            minimal.edges(2).collect::<Vec<_>>(),
            [(&Guard::always(), 2)]
        );
        assert!(same_language(&dfa, &minimal));
    }

    #[test]
    fn a_universal_or_empty_language_has_one_state() {
        for finals in [vec![0, 1], vec![]] {
            let dfa = from_table(1, 0, &finals, &[vec![1, 0], vec![1, 1]]);
            let minimal = minimize(&dfa);
            assert_eq!(minimal.num_states(), 1);
            assert_eq!(minimal.is_final(0), !finals.is_empty());
            assert_eq!(
                minimal.edges(0).collect::<Vec<_>>(),
                [(&Guard::always(), 0)]
            );
        }
    }

    #[test]
    fn random_dfas_minimise_to_the_brute_force_class_count() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        for _ in 0..300 {
            let dfa = random_dfa(&mut rng);
            let minimal = minimize(&dfa);
            assert_eq!(minimal.num_states(), brute_force_class_count(&dfa));
            assert!(same_language(&dfa, &minimal));
            // Canonical: minimising again, or minimising a renumbered copy, changes nothing.
            assert_same_structure(&minimize(&minimal), &minimal);
            let mut permutation: Vec<u32> = (0..dfa.num_states() as u32).collect();
            for i in (1..permutation.len()).rev() {
                permutation.swap(i, rng.next_u32() as usize % (i + 1));
            }
            assert_same_structure(&minimize(&renumbered(&dfa, &permutation)), &minimal);
        }
    }

    #[test]
    fn listing_letters_and_both_minterm_refinements_give_the_same_classes() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        for _ in 0..300 {
            let dfa = random_dfa(&mut rng);
            let w = &mut Work::unlimited();
            let reachable = reachable_states(&dfa, w).unwrap();
            let guards: Vec<&Guard> = (reachable.iter())
                .flat_map(|&q| dfa.edges(q).map(|(g, _)| g))
                .collect();
            let support = guards.iter().fold(0, |acc, g| acc | g.support());
            let listed = SuccessorTable::by_letters(&dfa, &reachable, support, w).unwrap();
            let witnesses: Vec<u64> = super::super::alphabet::minterms(guards)
                .into_iter()
                .map(|m| m.witness)
                .collect();
            let mut imported = ImportedEdges::new(&dfa, &reachable, w).unwrap();
            let symbolic = imported.minterm_witnesses(usize::MAX, w).unwrap().unwrap();
            assert_eq!(symbolic.len(), witnesses.len());
            let by_symbolic = SuccessorTable::by_witnesses(&dfa, &reachable, &symbolic, w).unwrap();
            let refined = SuccessorTable::by_witnesses(&dfa, &reachable, &witnesses, w).unwrap();
            // As many classes (distinct columns are exactly the minterms that matter), and the
            // same partition of the states.
            assert!(listed.classes <= refined.classes);
            let by_listed = equivalence_classes(&dfa, &reachable, &listed, w).unwrap();
            let by_refined = equivalence_classes(&dfa, &reachable, &refined, w).unwrap();
            let quotients = (
                quotient(&dfa, &reachable, &by_listed, w).unwrap(),
                quotient(&dfa, &reachable, &by_refined, w).unwrap(),
            );
            assert_eq!(quotients.0, quotients.1);
            let by_symbolic = equivalence_classes(&dfa, &reachable, &by_symbolic, w).unwrap();
            assert_eq!(
                quotient(&dfa, &reachable, &by_symbolic, w).unwrap(),
                quotients.0
            );
            assert_eq!(quotients.0.num_states(), brute_force_class_count(&dfa));
        }
    }

    #[test]
    fn signature_refinement_finds_the_brute_force_classes() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        for _ in 0..300 {
            let dfa = random_dfa(&mut rng);
            let w = &mut Work::unlimited();
            let reachable = reachable_states(&dfa, w).unwrap();
            let class = ImportedEdges::new(&dfa, &reachable, w)
                .unwrap()
                .signature_classes(&dfa, &reachable, w)
                .unwrap();
            let quotient = quotient(&dfa, &reachable, &class, w).unwrap();
            assert_eq!(quotient.num_states(), brute_force_class_count(&dfa));
            assert!(same_language(&dfa, &quotient));
            assert_same_structure(&quotient, &minimize(&dfa));
        }
    }

    #[test]
    fn one_guard_per_proposition_does_not_enumerate_letter_classes() {
        // p0 & X(p1 & X(... & X q)) over 40 propositions: 2^40 letter classes, but a chain
        // of 41 obligations, the accepting and the rejecting sink.
        let n = 40;
        let edges = (0..=n)
            .map(|i| {
                vec![
                    (Guard::literal(i, true), i + 1),
                    (Guard::literal(i, false), n + 2),
                ]
            })
            .chain([
                vec![(Guard::always(), n + 1)],
                vec![(Guard::always(), n + 2)],
            ])
            .collect();
        let finals: BitSet = [n as usize + 1].into_iter().collect();
        let names = (0..=n).map(|i| format!("p{i}")).collect();
        let dfa = Dfa::new(names, 0, finals, edges).unwrap();
        assert_eq!(minimize(&dfa).num_states(), n as usize + 3);
    }
}

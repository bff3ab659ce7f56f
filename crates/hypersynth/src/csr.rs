//! Adjacency in compressed sparse rows: one type for every successor and predecessor list.
//!
//! A [`Csr<R, T>`] maps each row id `r` of kind `R` (`0..num_rows()`) to a slice of entries of
//! type `T`: `entries[offsets[r]..offsets[r + 1]]`. Entries are usually ids (successors of a
//! state), sometimes other values kept per edge (probabilities, `(action, target)` pairs).
//! Per-edge data stored beside a `Csr` in parallel arrays is indexed by [`Csr::range`].
//!
//! Building: row by row ([`Csr::push`] entries, then [`Csr::finish_row`]), from `(row, entry)`
//! pairs in any order ([`Csr::group`], a stable counting sort), or as the [`Csr::transpose`] of
//! a graph (predecessor lists, in one counting pass: within a row of the transpose, the entries
//! come in increasing order of their source row). Offsets are `u32`: at most `u32::MAX` entries.

use std::marker::PhantomData;
use std::ops::Range;

use crate::index::{Id, IdRange};

/// Rows of entries, in compressed sparse row form (see the module documentation).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Csr<R, T> {
    /// `num_rows() + 1` offsets into `entries`, from 0; the last one is where the open row
    /// starts.
    offsets: Vec<u32>,
    entries: Vec<T>,
    rows: PhantomData<fn(R) -> R>,
}

impl<R: Id, T> Default for Csr<R, T> {
    fn default() -> Self {
        Csr::new()
    }
}

impl<R: Id, T> Csr<R, T> {
    /// No rows.
    pub fn new() -> Self {
        Csr::with_capacity(0, 0)
    }

    /// No rows yet, with room for `rows` rows and `entries` entries.
    pub fn with_capacity(rows: usize, entries: usize) -> Self {
        let mut offsets = Vec::with_capacity(rows + 1);
        offsets.push(0);
        Csr {
            offsets,
            entries: Vec::with_capacity(entries),
            rows: PhantomData,
        }
    }

    /// The rows given by their `offsets` (from 0, non-decreasing, the last one the number of
    /// entries) into `entries`: for a `Csr` written in place at its exact size.
    ///
    /// # Panics
    /// If the offsets do not start at 0 or do not end at the number of entries.
    pub(crate) fn from_parts(offsets: Vec<u32>, entries: Vec<T>) -> Self {
        assert_eq!(offsets.first(), Some(&0));
        assert_eq!(offsets.last().map(|&end| end as usize), Some(entries.len()));
        debug_assert!(offsets.windows(2).all(|pair| pair[0] <= pair[1]));
        Csr {
            offsets,
            entries,
            rows: PhantomData,
        }
    }

    /// Adds an entry to the row being built (the next row id).
    #[inline]
    pub fn push(&mut self, entry: T) {
        self.entries.push(entry);
    }

    /// Ends the row being built: it holds the entries pushed since the last row ended.
    ///
    /// # Panics
    /// If the entries exceed `u32::MAX` in number, or the rows the ids of `R`.
    #[inline]
    pub fn finish_row(&mut self) {
        let end = u32::try_from(self.entries.len()).expect("at most u32::MAX entries");
        assert!(self.offsets.len() < u32::MAX as usize, "too many rows");
        self.offsets.push(end);
    }

    /// Adds a row with these entries.
    pub fn push_row(&mut self, entries: impl IntoIterator<Item = T>) {
        self.entries.extend(entries);
        self.finish_row();
    }

    /// Gives back the spare capacity (of a `Csr` built row by row without knowing its size).
    pub fn shrink_to_fit(&mut self) {
        self.offsets.shrink_to_fit();
        self.entries.shrink_to_fit();
    }

    /// Reserves room for `rows` more rows and `entries` more entries, exactly: with an upper
    /// bound reserved and the spare capacity given back at the end ([`Self::shrink_to_fit`]),
    /// no growth doubles the arrays on the way.
    pub fn reserve_exact(&mut self, rows: usize, entries: usize) {
        self.offsets.reserve_exact(rows);
        self.entries.reserve_exact(entries);
    }

    /// The number of (finished) rows.
    #[inline]
    pub fn num_rows(&self) -> usize {
        self.offsets.len() - 1
    }

    /// The number of entries, over all rows.
    #[inline]
    pub fn num_entries(&self) -> usize {
        self.entries.len()
    }

    /// The row ids, in order.
    #[inline]
    pub fn rows(&self) -> IdRange<R> {
        IdRange::up_to(self.num_rows())
    }

    /// Where the entries of `row` are in [`Self::entries`] (and in parallel per-entry arrays).
    #[inline]
    pub fn range(&self, row: R) -> Range<usize> {
        self.offsets[row.index()] as usize..self.offsets[row.index() + 1] as usize
    }

    /// The entries of `row`.
    #[inline]
    pub fn row(&self, row: R) -> &[T] {
        &self.entries[self.range(row)]
    }

    /// The entries of `row`, to change them in place.
    #[inline]
    pub fn row_mut(&mut self, row: R) -> &mut [T] {
        let range = self.range(row);
        &mut self.entries[range]
    }

    /// The entries of `row`, each with its value in `parallel`, an array indexed like
    /// [`Self::entries`] (per-edge data kept beside the adjacency).
    #[inline]
    pub fn row_with<'a, V>(
        &'a self,
        row: R,
        parallel: &'a [V],
    ) -> impl ExactSizeIterator<Item = (T, &'a V)> + Clone + 'a
    where
        T: Copy,
    {
        let range = self.range(row);
        self.entries[range.clone()]
            .iter()
            .copied()
            .zip(&parallel[range])
    }

    /// Whether `row` has no entry.
    #[inline]
    pub fn is_row_empty(&self, row: R) -> bool {
        self.offsets[row.index()] == self.offsets[row.index() + 1]
    }

    /// Every entry, row after row.
    #[inline]
    pub fn entries(&self) -> &[T] {
        &self.entries
    }

    /// The entries with their rows, row after row.
    pub fn iter(&self) -> impl Iterator<Item = (R, &T)> + Clone + '_ {
        self.rows()
            .flat_map(move |row| self.row(row).iter().map(move |entry| (row, entry)))
    }

    /// The rows `0..num_rows` of `(row, entry)` pairs given in any order; within a row, entries
    /// keep the order of `pairs` (a stable counting sort: `pairs` is gone through twice).
    ///
    /// # Panics
    /// If a row is not below `num_rows`.
    pub fn group<P>(num_rows: usize, pairs: P) -> Self
    where
        P: Iterator<Item = (R, T)> + Clone,
        T: Copy,
    {
        Csr::group_from(num_rows, || pairs.clone())
    }

    /// [`Self::group`] with the pairs made by `pairs()`, called twice (for pairs computed on
    /// the fly by iterators that cannot be cloned).
    pub fn group_from<P>(num_rows: usize, pairs: impl Fn() -> P) -> Self
    where
        P: Iterator<Item = (R, T)>,
        T: Copy,
    {
        let mut offsets = vec![0u32; num_rows + 1];
        for (row, _) in pairs() {
            offsets[row.index() + 1] += 1;
        }
        for i in 0..num_rows {
            offsets[i + 1] += offsets[i];
        }
        let mut entries = match pairs().next() {
            Some((_, first)) => vec![first; offsets[num_rows] as usize],
            None => Vec::new(),
        };
        let mut next = offsets[..num_rows].to_vec();
        for (row, entry) in pairs() {
            let slot = &mut next[row.index()];
            entries[*slot as usize] = entry;
            *slot += 1;
        }
        Csr {
            offsets,
            entries,
            rows: PhantomData,
        }
    }
}

impl<R: Id, T: Id> Csr<R, T> {
    /// The reverse graph over `num_targets` rows: row `t` lists the rows `r` with `t` among
    /// their entries, once per occurrence, in increasing order of `r`.
    ///
    /// # Panics
    /// If an entry is not below `num_targets`.
    pub fn transpose(&self, num_targets: usize) -> Csr<T, R> {
        Csr::group(num_targets, self.iter().map(|(row, &target)| (target, row)))
    }
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;

    /// Random graphs: a number of sources and targets, and edges as pairs.
    fn graphs() -> impl Strategy<Value = (usize, usize, Vec<(u32, u32)>)> {
        (0usize..12, 1usize..12).prop_flat_map(|(rows, targets)| {
            let edges = if rows == 0 {
                Just(Vec::new()).boxed()
            } else {
                proptest::collection::vec((0..rows as u32, 0..targets as u32), 0..60).boxed()
            };
            (Just(rows), Just(targets), edges)
        })
    }

    /// The rows as nested vectors.
    fn nested<R: Id, T: Copy>(csr: &Csr<R, T>) -> Vec<Vec<T>> {
        csr.rows().map(|row| csr.row(row).to_vec()).collect()
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]

        /// Row by row, grouped pairs and the transpose all agree with nested vectors built
        /// the obvious way.
        #[test]
        fn transpose_agrees_with_a_naive_construction((rows, targets, edges) in graphs()) {
            // Edges sorted by source, keeping their order: the rows built one by one.
            let mut forward = vec![Vec::new(); rows];
            for &(source, target) in &edges {
                forward[source as usize].push(target);
            }
            let mut csr: Csr<u32, u32> = Csr::new();
            for row in &forward {
                csr.push_row(row.iter().copied());
            }
            prop_assert_eq!(nested(&csr), forward.clone());
            prop_assert_eq!(csr.num_entries(), edges.len());
            let grouped = Csr::<u32, u32>::group(rows, edges.iter().copied());
            prop_assert_eq!(&grouped, &csr);
            // Naive predecessor lists: for each target, scan every source's row in order.
            let naive: Vec<Vec<u32>> = (0..targets as u32)
                .map(|t| {
                    let mut sources = Vec::new();
                    for (source, row) in forward.iter().enumerate() {
                        for _ in row.iter().filter(|&&x| x == t) {
                            sources.push(source as u32);
                        }
                    }
                    sources
                })
                .collect();
            let reverse = csr.transpose(targets);
            prop_assert_eq!(reverse.num_rows(), targets);
            prop_assert_eq!(nested(&reverse), naive);
            // Twice: the same rows, each sorted.
            let sorted: Vec<Vec<u32>> = forward
                .iter()
                .map(|row| {
                    let mut row = row.clone();
                    row.sort_unstable();
                    row
                })
                .collect();
            prop_assert_eq!(nested(&reverse.transpose(rows)), sorted);
        }
    }

    #[test]
    fn rows_know_their_ranges_and_can_be_changed_in_place() {
        let mut csr: Csr<u32, f64> = Csr::new();
        csr.push_row([1.0, 2.0]);
        csr.finish_row();
        csr.push(3.0);
        csr.finish_row();
        assert_eq!(csr.num_rows(), 3);
        assert_eq!(
            (csr.range(0), csr.range(1), csr.range(2)),
            (0..2, 2..2, 2..3)
        );
        assert!(csr.is_row_empty(1) && !csr.is_row_empty(2));
        csr.row_mut(0)[1] = 5.0;
        assert_eq!(csr.entries(), [1.0, 5.0, 3.0]);
        let labels = ["a", "b", "c"];
        let with: Vec<(f64, &&str)> = csr.row_with(2, &labels).collect();
        assert_eq!(with, [(3.0, &"c")]);
        let pairs: Vec<(u32, f64)> = csr.iter().map(|(r, &x)| (r, x)).collect();
        assert_eq!(pairs, [(0, 1.0), (0, 5.0), (2, 3.0)]);
        assert_eq!(Csr::<u32, u32>::group(2, std::iter::empty()).num_rows(), 2);
    }
}

//! A dense numbering of a set of product states, the *live* states of the solve and the policy
//! and the chain states of the evaluation (docs/semantics.md §13.2): a bit per product state
//! and the members before each 32-bit block of those bits, so that a member's number is one
//! count of the bits below it in its block. The blocks' bits are kept a second time beside
//! those counts, so that a look-up (is it a member, and its number) reads one place: the
//! sweeps do one for each successor they read.
//!
//! [`Numbering::update`] visits the members in runs on all threads, each run with its part of
//! a vector indexed by number: what is computed per member alone is computed in parallel.
//!
//! Memory: two bits per product state and four bytes per 32 product states.

use bit_set::BitSet;
use rayon::prelude::*;

/// The 32-bit blocks of members a thread of [`Numbering::update`] takes at a time.
const BLOCKS: usize = 1 << 12;

/// The members of a set of product states, numbered densely in increasing order.
#[derive(Clone, Debug)]
pub(crate) struct Numbering {
    set: BitSet,
    /// Per 32-bit block of `set`: its bits and the members before it, side by side, so that a
    /// look-up reads one place.
    blocks: Vec<[u32; 2]>,
}

impl Numbering {
    /// The numbering of the members of `set`.
    pub(crate) fn new(set: BitSet) -> Numbering {
        let mut blocks = Vec::with_capacity(set.get_ref().storage().len());
        let mut count = 0u32;
        for &bits in set.get_ref().storage() {
            blocks.push([bits, count]);
            count += bits.count_ones();
        }
        Numbering { set, blocks }
    }

    /// The number of members.
    pub(crate) fn len(&self) -> usize {
        self.blocks
            .last()
            .map_or(0, |&[bits, before]| (before + bits.count_ones()) as usize)
    }

    /// Whether `h` is a member.
    #[inline(always)]
    pub(crate) fn contains(&self, h: u32) -> bool {
        self.blocks
            .get((h / 32) as usize)
            .is_some_and(|&[bits, _]| bits >> (h % 32) & 1 != 0)
    }

    /// The number of member `h`.
    #[inline(always)]
    pub(crate) fn index(&self, h: u32) -> usize {
        let [bits, before] = self.blocks[(h / 32) as usize];
        before as usize + (bits & ((1u32 << (h % 32)) - 1)).count_ones() as usize
    }

    /// The number of `h`, if it is a member.
    #[inline(always)]
    pub(crate) fn get(&self, h: u32) -> Option<usize> {
        let &[bits, before] = self.blocks.get((h / 32) as usize)?;
        let bit = h % 32;
        (bits >> bit & 1 != 0)
            .then(|| before as usize + (bits & ((1u32 << bit) - 1)).count_ones() as usize)
    }

    /// The members, in increasing order.
    pub(crate) fn members(&self) -> impl Iterator<Item = u32> + '_ {
        self.set.iter().map(|h| h as u32)
    }

    /// Calls `f(h, &mut out[i], scratch)` for each member `h` of number `i`, in runs of
    /// members on rayon's threads, each with its `scratch()`: what one thread would do, since
    /// each entry depends on its member alone.
    pub(crate) fn update<T, S>(
        &self,
        out: &mut [T],
        scratch: impl Fn() -> S + Sync + Send,
        f: impl Fn(u32, &mut T, &mut S) + Sync + Send,
    ) where
        T: Send,
    {
        assert_eq!(out.len(), self.len(), "one entry per member");
        let blocks = self.set.get_ref().storage();
        // Each run's first block and its part of `out` (the runs' members are disjoint and in
        // increasing order, so are their numbers).
        let mut runs = Vec::with_capacity(blocks.len().div_ceil(BLOCKS));
        let mut rest = out;
        for (r, run) in blocks.chunks(BLOCKS).enumerate() {
            let count: usize = run.iter().map(|b| b.count_ones() as usize).sum();
            let (part, tail) = std::mem::take(&mut rest).split_at_mut(count);
            runs.push((r * BLOCKS, run, part));
            rest = tail;
        }
        runs.into_par_iter()
            .for_each_init(&scratch, |scratch, (first, run, part)| {
                let mut k = 0;
                for (b, &block) in run.iter().enumerate() {
                    let mut bits = block;
                    while bits != 0 {
                        let h = ((first + b) * 32) as u32 + bits.trailing_zeros();
                        f(h, &mut part[k], scratch);
                        k += 1;
                        bits &= bits - 1;
                    }
                }
            });
    }

    /// The members as a set.
    pub(crate) fn set(&self) -> &BitSet {
        &self.set
    }
}

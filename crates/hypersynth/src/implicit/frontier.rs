//! Backward searches one level at a time on all threads (docs/semantics.md §13.2): the
//! predecessors of a whole level are tried at once, each thread claiming the states it admits
//! in a shared set of atomic bits, so that each state is found once.
//!
//! What a search finds, level by level, is the same on any number of threads whenever whether
//! a state is admitted depends only on it and the state it was reached from (as for the
//! searches of `qualitative.rs` and the policy's ranks): the levels are sets, never lists, so
//! nothing depends on which thread found a state first.
//!
//! Memory: a bit per product state for the states claimed and one for each level held (the
//! current one and the next): no list of states, whose growth on the threads would leave the
//! allocator holding memory it does not return.

use std::sync::atomic::{AtomicU32, Ordering};

use bit_set::BitSet;
use rayon::prelude::*;

use super::moves::Moves;
use super::space::Space;

/// The 32-bit words of a [`Bits`] a thread takes at a time.
const WORDS: usize = 1 << 10;

/// A set of product states that threads may add to at once: a bit per state.
pub(crate) struct Bits {
    words: Vec<AtomicU32>,
}

impl Bits {
    /// The empty set of states below `n`.
    pub(crate) fn new(n: usize) -> Bits {
        Bits {
            words: (0..n.div_ceil(32)).map(|_| AtomicU32::new(0)).collect(),
        }
    }

    /// The states below `n` for which `f(h, scratch)` holds, decided on all threads (each
    /// with its `scratch()`).
    pub(crate) fn from_fn<S>(
        n: usize,
        scratch: impl Fn() -> S + Sync + Send,
        f: impl Fn(u32, &mut S) -> bool + Sync + Send,
    ) -> Bits {
        let bits = Bits::new(n);
        bits.words
            .par_chunks(WORDS)
            .enumerate()
            .for_each_init(&scratch, |scratch, (c, words)| {
                for (w, word) in words.iter().enumerate() {
                    let first = (c * WORDS + w) * 32;
                    let mut value = 0u32;
                    for b in 0..32.min(n.saturating_sub(first)) {
                        if f((first + b) as u32, scratch) {
                            value |= 1 << b;
                        }
                    }
                    word.store(value, Ordering::Relaxed);
                }
            });
        bits
    }

    /// The set of states below `n` as a [`BitSet`].
    pub(crate) fn into_set(self, n: usize) -> BitSet {
        let mut set = BitSet::with_capacity(n);
        for (w, word) in self.words.into_iter().enumerate() {
            let mut bits = word.into_inner();
            while bits != 0 {
                set.insert(w * 32 + bits.trailing_zeros() as usize);
                bits &= bits - 1;
            }
        }
        set
    }

    /// Whether `h` is in the set.
    #[inline]
    pub(crate) fn contains(&self, h: u32) -> bool {
        self.words[(h / 32) as usize].load(Ordering::Relaxed) & (1 << (h % 32)) != 0
    }

    /// Adds `h`: whether it was not in the set before (the thread that adds it claims it).
    #[inline]
    pub(crate) fn insert(&self, h: u32) -> bool {
        let bit = 1 << (h % 32);
        self.words[(h / 32) as usize].fetch_or(bit, Ordering::Relaxed) & bit == 0
    }

    /// Adds the states of `other` that were not in the set, and keeps only those in `other`:
    /// the states `other` newly claims.
    pub(crate) fn claim_from(&self, other: &mut Bits) {
        for (mine, theirs) in self.words.iter().zip(&mut other.words) {
            let new = *theirs.get_mut() & !mine.load(Ordering::Relaxed);
            *theirs.get_mut() = new;
            mine.fetch_or(new, Ordering::Relaxed);
        }
    }

    /// Whether the set is empty.
    pub(crate) fn is_empty(&mut self) -> bool {
        self.words.iter_mut().all(|w| *w.get_mut() == 0)
    }

    /// Empties the set.
    pub(crate) fn clear(&mut self) {
        self.words.iter_mut().for_each(|w| *w.get_mut() = 0);
    }

    /// The states in the set, in increasing order.
    pub(crate) fn iter(&mut self) -> impl Iterator<Item = u32> + '_ {
        self.words.iter_mut().enumerate().flat_map(|(w, word)| {
            let mut bits = *word.get_mut();
            std::iter::from_fn(move || {
                (bits != 0).then(|| {
                    let b = bits.trailing_zeros();
                    bits &= bits - 1;
                    (w * 32) as u32 + b
                })
            })
        })
    }
}

/// One level of a backward search: adds to `next` (empty) the predecessors `p` of the states
/// `t` of `level`, not in `claims`, that `admit(p, t, scratch)` lets in (each thread with its
/// `scratch()`), each claimed in `claims` once.
pub(crate) fn advance<M: Moves, S>(
    space: &Space<'_, M>,
    level: &Bits,
    claims: &Bits,
    next: &Bits,
    scratch: impl Fn() -> S + Sync + Send,
    admit: impl Fn(u32, u32, &mut S) -> bool + Sync + Send,
) {
    level
        .words
        .par_chunks(WORDS)
        .enumerate()
        .for_each_init(&scratch, |scratch, (c, words)| {
            for (w, word) in words.iter().enumerate() {
                let mut bits = word.load(Ordering::Relaxed);
                while bits != 0 {
                    let t = ((c * WORDS + w) * 32) as u32 + bits.trailing_zeros();
                    bits &= bits - 1;
                    space.predecessors(t, |p| {
                        if !claims.contains(p) && admit(p, t, scratch) && claims.insert(p) {
                            next.insert(p);
                        }
                    });
                }
            }
        });
}

/// A backward search from `first` (its states already in `claims`), one level at a time:
/// `visit(level, depth)` for each level in turn, `first` at depth 0, then [`advance`] to the
/// next, until a level is empty.
pub(crate) fn search<M: Moves, S>(
    space: &Space<'_, M>,
    first: Bits,
    claims: &Bits,
    scratch: impl Fn() -> S + Sync + Send,
    admit: impl Fn(u32, u32, &mut S) -> bool + Sync + Send,
    mut visit: impl FnMut(&mut Bits, u32),
) {
    let mut level = first;
    let mut next = Bits {
        words: (0..level.words.len()).map(|_| AtomicU32::new(0)).collect(),
    };
    let mut depth = 0;
    while !level.is_empty() {
        visit(&mut level, depth);
        advance(space, &level, claims, &next, &scratch, &admit);
        std::mem::swap(&mut level, &mut next);
        next.clear();
        depth += 1;
    }
}

//! Attractors over the index space: the backward fixpoint of docs/semantics.md §5.1 with one
//! counter per state, and a region of one bit per state.
//!
//! The algorithm is the explicit engine's ([`Attractor`](crate::game::Attractor)): a robot state
//! joins when one successor has, an adversary state when all its edges (parallel edges counted
//! separately) lead into the region; a stuck adversary state joins even when `F` is empty.
//! Predecessors are computed, not stored; the counters take one byte per state while the
//! attractor runs (four when some state has 255 edges or more), the queue holds the states that
//! have joined and are not yet expanded, and what remains is the region's bit per state.
//!
//! With the reachable enumeration the search stays among the enumerated states (targets,
//! stuck states and predecessors alike), as the explicit engine's product holds only those: a
//! region and its ranks are the explicit engine's.
//!
//! A region does not store ranks: the queue holds the states in order of non-decreasing rank,
//! so the search counts where each rank's states end in it and keeps only the largest rank and
//! the rank of the initial state, which is what the reports show. [`Ranks`] runs the same
//! search again for a region whose reactive strategy is played (the controller's export) and
//! keeps every state's rank, two bytes each (four past 65 534).

use std::collections::VecDeque;

use bit_set::BitSet;

use super::moves::Moves;
use super::space::Space;
use crate::arena::Owner;

/// A per-state countdown.
trait Counter: Copy {
    fn from_u32(n: u32) -> Self;
    /// Decrements and says whether the counter reached 0.
    fn hit(&mut self) -> bool;
}

impl Counter for u8 {
    fn from_u32(n: u32) -> u8 {
        n as u8
    }
    fn hit(&mut self) -> bool {
        *self = self.wrapping_sub(1);
        *self == 0
    }
}

impl Counter for u32 {
    fn from_u32(n: u32) -> u32 {
        n
    }
    fn hit(&mut self) -> bool {
        *self = self.wrapping_sub(1);
        *self == 0
    }
}

/// An attractor over the index space: its region and the two ranks the reports show.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Region {
    /// The region, a bit per state.
    pub states: BitSet,
    /// The largest rank of a state in the region (`None` when it is empty).
    pub max_rank: Option<u32>,
    /// The rank of the initial state (`None` outside the region).
    pub initial_rank: Option<u32>,
}

/// The robot's attractor of the states where `is_target` holds.
pub fn attractor<M: Moves>(space: &Space<'_, M>, is_target: impl Fn(u32) -> bool) -> Region {
    search(space, is_target, |_, _| {})
}

/// The attractor's search, calling `record(h, rank)` for each state of the region.
fn search<M: Moves>(
    space: &Space<'_, M>,
    is_target: impl Fn(u32) -> bool,
    record: impl FnMut(u32, u32),
) -> Region {
    if space.moves().max_degree() < u32::from(u8::MAX) {
        run::<M, u8>(space, is_target, record)
    } else {
        run::<M, u32>(space, is_target, record)
    }
}

/// Every state's rank in the robot's attractor of the states where `is_target` holds: what its
/// rank-decreasing strategy reads.
#[derive(Clone, Debug)]
pub enum Ranks {
    /// Ranks below [`u16::MAX`], which marks a state outside the region.
    Short(Vec<u16>),
    /// Ranks below [`u32::MAX`], which marks a state outside the region.
    Long(Vec<u32>),
}

impl Ranks {
    /// The ranks of the attractor of `is_target`, whose largest rank is `max_rank` (the
    /// [`Region`]'s, which decides the width).
    pub fn new<M: Moves>(
        space: &Space<'_, M>,
        is_target: impl Fn(u32) -> bool,
        max_rank: Option<u32>,
    ) -> Ranks {
        let n = space.num_states();
        match Ranks::width(max_rank) {
            4 => {
                let mut rank = vec![u32::MAX; n];
                search(space, is_target, |h, r| rank[h as usize] = r);
                Ranks::Long(rank)
            }
            _ => {
                let mut rank = vec![u16::MAX; n];
                search(space, is_target, |h, r| rank[h as usize] = r as u16);
                Ranks::Short(rank)
            }
        }
    }

    /// The bytes per state of the ranks of a region whose largest rank is `max_rank`.
    pub fn width(max_rank: Option<u32>) -> usize {
        match max_rank {
            Some(max) if max >= u32::from(u16::MAX) => 4,
            _ => 2,
        }
    }

    /// The rank of `h`, `None` outside the region.
    pub fn get(&self, h: u32) -> Option<u32> {
        match self {
            Ranks::Short(rank) => Some(rank[h as usize])
                .filter(|&r| r != u16::MAX)
                .map(u32::from),
            Ranks::Long(rank) => Some(rank[h as usize]).filter(|&r| r != u32::MAX),
        }
    }
}

fn run<M: Moves, C: Counter>(
    space: &Space<'_, M>,
    is_target: impl Fn(u32) -> bool,
    mut record: impl FnMut(u32, u32),
) -> Region {
    let n = space.num_states();
    let moves = space.moves();
    let locals = (n / moves.num_states().max(1)) as u32;
    let mut region = BitSet::with_capacity(n);
    let mut counters: Vec<C> = Vec::with_capacity(n);
    let mut queue: VecDeque<u32> = VecDeque::new();
    let mut stuck: Vec<u32> = Vec::new();
    for s in 0..moves.num_states() as u32 {
        let count = match moves.owner(s) {
            Owner::Robot => 1,
            Owner::Adversary => moves.degree(s),
        };
        for local in 0..locals {
            let h = s * locals + local;
            counters.push(C::from_u32(count));
            if !space.enumerated(h) {
                continue;
            }
            if is_target(h) {
                region.insert(h as usize);
                queue.push_back(h);
            } else if count == 0 {
                stuck.push(h);
            }
        }
    }
    let initial = space.initial();
    let mut initial_rank = region.contains(initial as usize).then_some(0);
    // The states of the rank being expanded still in the queue, and those of the next rank
    // already pushed (stuck adversary states are rank 1 unless targets).
    let (mut rank, mut left, mut next) = (0u32, queue.len(), stuck.len());
    for h in stuck {
        region.insert(h as usize);
        queue.push_back(h);
    }
    let mut max_rank = (!queue.is_empty()).then_some(0);
    while let Some(h) = queue.pop_front() {
        if left == 0 {
            (rank, left, next) = (rank + 1, next, 0);
        }
        left -= 1;
        max_rank = Some(rank);
        record(h, rank);
        if h == initial {
            initial_rank = Some(rank);
        }
        space.predecessors(h, |p| {
            if !region.contains(p as usize) && space.enumerated(p) && counters[p as usize].hit() {
                region.insert(p as usize);
                queue.push_back(p);
                next += 1;
            }
        });
    }
    Region {
        states: region,
        max_rank,
        initial_rank,
    }
}

//! Attractors over the index space: the backward fixpoint of docs/semantics.md §5.1 with one
//! counter per state, and a region of one bit per state.
//!
//! The algorithm is the explicit engine's ([`Attractor`](crate::game::Attractor)): a robot state
//! joins when one successor has, an adversary state when all its edges (parallel edges counted
//! separately) lead into the region; a stuck adversary state joins even when `F` is empty.
//! Predecessors are computed, not stored; the counters take one byte per state while the
//! attractor runs (four when some state has 255 edges or more), the queue holds the states that
//! have joined and are not yet expanded, and what remains is the region's bit per state.

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

/// The robot's attractor of the states where `is_target` holds: its region.
pub fn attractor<M: Moves>(space: &Space<'_, M>, is_target: impl Fn(u32) -> bool) -> BitSet {
    if space.moves().max_degree() < u32::from(u8::MAX) {
        run::<M, u8>(space, is_target)
    } else {
        run::<M, u32>(space, is_target)
    }
}

fn run<M: Moves, C: Counter>(space: &Space<'_, M>, is_target: impl Fn(u32) -> bool) -> BitSet {
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
            if is_target(h) {
                region.insert(h as usize);
                queue.push_back(h);
            } else if count == 0 {
                stuck.push(h);
            }
        }
    }
    for h in stuck {
        region.insert(h as usize);
        queue.push_back(h);
    }
    while let Some(h) = queue.pop_front() {
        space.predecessors(h, |p| {
            if !region.contains(p as usize) && counters[p as usize].hit() {
                region.insert(p as usize);
                queue.push_back(p);
            }
        });
    }
    region
}

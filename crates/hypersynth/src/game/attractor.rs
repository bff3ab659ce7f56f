//! Attractors with ranks: the robot's winning regions of reachability games on the hypergame.
//!
//! `Attr(F)` (docs/semantics.md §5) is the limit of `A_0 = F`,
//! `A_{k+1} = A_k ∪ {robot h : some successor in A_k} ∪ {adversary h : every successor in A_k}`,
//! and the rank of a state is the least `k` with `h ∈ A_k`. Consequences of the definition, which
//! the code follows literally:
//! - a stuck robot state (no action) joins only if it is a target (rank 0);
//! - a stuck adversary state joins at rank 1 unless it is a target (the `forall` over no
//!   successors holds at the first level), even when `F` is empty: the adversary cannot move, so
//!   the play cannot leave the robot's region and counts as won by the robot.
//!
//! Algorithm: backward breadth-first search from `F` over the predecessor lists, with a counter
//! per state of the edges that must still reach the region before the state joins: 1 for a robot
//! state (any one suffices), the out-degree for an adversary state (all of them, counting
//! parallel edges separately, as the predecessor lists do). A state joins when its counter hits
//! 0, so it is ranked by the last of its relevant successors to join; the queue holds states in
//! order of non-decreasing rank. Each edge is looked at once: O(|H| + |edges|).

use bit_set::BitSet;

use super::product::{HState, Hypergame};
use crate::arena::Owner;
use crate::index::Id;
use crate::stage::Tally;

/// States settled between two reports to a [`Tally`].
const BATCH: usize = 1 << 16;

/// Whether the robot's rank-decreasing strategy allows an edge from a state of rank `rank` to
/// one of rank `target` (`None`: outside the region): both in the region, and `target` lower
/// unless the source is a target (rank 0). Both engines' strategies follow it.
pub fn allows_robot_edge(rank: Option<u32>, target: Option<u32>) -> bool {
    match (rank, target) {
        (Some(rank), Some(target)) => rank == 0 || target < rank,
        _ => false,
    }
}

/// An attractor `Attr(F)`: its region and the rank of each of its states.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Attractor {
    region: BitSet,
    size: usize,
    /// Per state, its rank (`u32::NONE` outside the region).
    ranks: Vec<u32>,
    max_rank: Option<u32>,
}

impl Attractor {
    /// The robot's attractor of `targets` in `game`.
    pub fn compute(game: &Hypergame, targets: &BitSet) -> Attractor {
        Attractor::compute_tallied(game, targets, &Tally::default())
    }

    /// [`Attractor::compute`], adding to `tally` the states it has dealt with: `num_states()`
    /// in all, in batches.
    pub fn compute_tallied(game: &Hypergame, targets: &BitSet, tally: &Tally) -> Attractor {
        let n = game.num_states();
        // Rank and counter side by side: one cache miss per predecessor edge, not two.
        let mut states: Vec<(u32, u32)> = game
            .states()
            .map(|h| match game.owner(h) {
                Owner::Robot => (u32::NONE, 1),
                Owner::Adversary => (u32::NONE, game.successors(h).len() as u32),
            })
            .collect();
        let mut queue: Vec<HState> = Vec::new();
        for h in targets.iter() {
            states[h].0 = 0;
            queue.push(HState::new(h));
        }
        for (h, state) in states.iter_mut().enumerate() {
            if *state == (u32::NONE, 0) {
                state.0 = 1;
                queue.push(HState::new(h));
            }
        }
        let mut head = 0;
        while head < queue.len() {
            let h = queue[head];
            head += 1;
            if head % BATCH == 0 {
                tally.add(BATCH as u64);
            }
            let rank = states[h.index()].0 + 1;
            for &p in game.predecessors(h) {
                let (p_rank, pending) = &mut states[p.index()];
                if !p_rank.is_none() {
                    continue;
                }
                *pending -= 1;
                if *pending == 0 {
                    *p_rank = rank;
                    queue.push(p);
                }
            }
        }
        // The states left outside the region count as dealt with too.
        tally.add((n - head / BATCH * BATCH) as u64);
        // Collected from a borrowed iterator, so that the ranks get an allocation of their own
        // size: `into_iter` would reuse the pairs' one, twice as large, for the regions' life.
        let ranks: Vec<u32> = states.iter().map(|&(rank, _)| rank).collect();
        drop(states);
        let mut region = BitSet::with_capacity(n);
        for &h in &queue {
            region.insert(h.index());
        }
        Attractor {
            region,
            size: queue.len(),
            max_rank: queue.last().map(|&h| ranks[h.index()]),
            ranks,
        }
    }

    /// The region as a set of product state indices.
    pub fn region(&self) -> &BitSet {
        &self.region
    }

    /// Whether `h` is in the region.
    pub fn contains(&self, h: HState) -> bool {
        self.region.contains(h.index())
    }

    /// The number of states in the region.
    pub fn len(&self) -> usize {
        self.size
    }

    /// Whether the region is empty.
    pub fn is_empty(&self) -> bool {
        self.size == 0
    }

    /// The rank of `h`, `None` outside the region.
    pub fn rank(&self, h: HState) -> Option<u32> {
        self.ranks[h.index()].to_option()
    }

    /// Whether the robot's rank-decreasing strategy (see [`super::ReactiveStrategy::robot`])
    /// allows the edge from `h` to `target`: `h` in the region and `target` of lower rank, or
    /// anywhere in the region when `h` is a target.
    pub fn allows_robot_edge(&self, h: HState, target: HState) -> bool {
        allows_robot_edge(self.rank(h), self.rank(target))
    }

    /// The largest rank, `None` for an empty region.
    pub fn max_rank(&self) -> Option<u32> {
        self.max_rank
    }
}

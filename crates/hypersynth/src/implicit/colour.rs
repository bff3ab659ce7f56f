//! Sweeps of one player's states on all threads, for components whose turns alternate.
//!
//! When no live state has a live successor of its own player (a map's turns always
//! alternate), a backup of a robot state reads only adversary states' values and the reverse:
//! all of one player's states of a component can be updated at once, and a sweep in index
//! order of a component whose robot states come first is exactly the robot states' updates,
//! then the adversary states'. [`Split`] says whether the live numbering puts every robot state
//! before every adversary state (a map's does: the player to move is its index's leading
//! digit); then [`sweep`] hands each thread a run of one player's states with its own part
//! of the values, the other player's values shared. Each value is computed from the same
//! inputs as in the one-thread sweep, so the values are the same bit for bit whatever the
//! number of threads (the property `RAYON_NUM_THREADS` promises).
//!
//! Memory: nothing per state; a few words per run of [`RUN`] states.

use rayon::prelude::*;

use super::moves::Moves;
use super::numbering::Numbering;
use super::space::Space;
use crate::arena::Owner;

/// Components of at least this many states are swept by player on threads when they allow it:
/// below it, the threads' start costs more than they save.
pub(crate) const COLOURED: usize = 1 << 15;

/// The states of one player a thread updates at a time.
const RUN: usize = 1 << 12;

/// The live numbering split by player: every robot state's live index is below `boundary`,
/// every adversary state's at or above it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Split {
    boundary: usize,
}

impl Split {
    /// The split of `live`, if its robot states all come before its adversary states.
    pub(crate) fn of<M: Moves>(space: &Space<'_, M>, live: &Numbering) -> Option<Split> {
        let mut boundary = None;
        for (i, h) in live.members().enumerate() {
            match (space.owner(h), boundary) {
                (Owner::Adversary, None) => boundary = Some(i),
                (Owner::Robot, Some(_)) => return None,
                _ => {}
            }
        }
        Some(Split {
            boundary: boundary.unwrap_or(live.len()),
        })
    }
}

/// How the component `members` (sorted) is swept by player, if it is: with at least
/// `coloured` states, when `split` exists, its turns alternate ([`alternates`]) and its robot
/// states come first, the split and the position of its first adversary state.
pub(crate) fn by_player<M: Moves>(
    space: &Space<'_, M>,
    (split, live): (Option<Split>, &Numbering),
    members: &[u32],
    coloured: usize,
) -> Option<(Split, usize)> {
    let split = split.filter(|_| members.len() >= coloured)?;
    let first = members.partition_point(|&h| space.owner(h) == Owner::Robot);
    let sorted = members[first..]
        .iter()
        .all(|&h| space.owner(h) == Owner::Adversary);
    (sorted && alternates(space, members, live)).then_some((split, first))
}

/// The component `members` split at `first` ([`by_player`]): each player's states, in the
/// order they are swept, with the position of the first in `members`.
pub(crate) fn players(members: &[u32], first: usize) -> [((Owner, &[u32]), usize); 2] {
    let (robot, adversary) = members.split_at(first);
    [
        ((Owner::Robot, robot), 0),
        ((Owner::Adversary, adversary), first),
    ]
}

/// Whether no state of `members` has a live successor (in `live`) of its own player.
fn alternates<M: Moves>(space: &Space<'_, M>, members: &[u32], live: &Numbering) -> bool {
    members.iter().all(|&h| {
        let owner = space.owner(h);
        let mut alternate = true;
        space.edges(h, |_, t| {
            alternate &= space.owner(t) != owner || !live.contains(t);
        });
        alternate
    })
}

/// The other player's values during a [`sweep`].
pub(crate) struct Other<'a, T> {
    values: &'a [T],
    /// The live index of `values[0]`.
    offset: usize,
}

impl<T> Clone for Other<'_, T> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<T> Copy for Other<'_, T> {}

impl<T> Other<'_, T> {
    /// The value of the other player's live state of live index `j`.
    #[inline(always)]
    pub(crate) fn get(&self, j: usize) -> &T {
        &self.values[j - self.offset]
    }
}

/// One sweep of `members`, all of one player (`owner`), in increasing order, in a component
/// whose turns alternate ([`alternates`]): `update((p, h), i, value, other, scratch, found)`
/// updates live state `h` (at position `p` of `members`, live index `i`, `value` its entry of
/// `values`, by live index) from
/// the other player's values, recording what it finds in `found`; runs of states go to the
/// threads, each with its `scratch()`, and what they found is folded by `fold`.
pub(crate) fn sweep<T, S, F>(
    values: &mut [T],
    (split, live): (Split, &Numbering),
    (owner, members): (Owner, &[u32]),
    scratch: impl Fn() -> S + Sync + Send,
    update: impl Fn((usize, u32), usize, &mut T, Other<'_, T>, &mut S, &mut F) + Sync + Send,
    fold: impl Fn(F, F) -> F + Sync + Send,
) -> F
where
    T: Send + Sync,
    F: Default + Send,
{
    let (robot, adversary) = values.split_at_mut(split.boundary);
    let (own, base, other) = match owner {
        Owner::Robot => (
            robot,
            0,
            Other {
                values: &*adversary,
                offset: split.boundary,
            },
        ),
        Owner::Adversary => (
            adversary,
            split.boundary,
            Other {
                values: &*robot,
                offset: 0,
            },
        ),
    };
    // Each run's states and the part of the values its live indices span (disjoint: the
    // members are in increasing order).
    let mut runs = Vec::with_capacity(members.len().div_ceil(RUN));
    let (mut rest, mut start) = (own, base);
    for (k, run) in members.chunks(RUN).enumerate() {
        let first = live.index(run[0]);
        let end = live.index(run[run.len() - 1]) + 1;
        let (_, tail) = std::mem::take(&mut rest).split_at_mut(first - start);
        let (part, tail) = tail.split_at_mut(end - first);
        runs.push((k * RUN, run, part, first));
        (rest, start) = (tail, end);
    }
    runs.into_par_iter()
        .map_init(&scratch, |scratch, (position, run, part, first)| {
            let mut found = F::default();
            for (p, &h) in (position..).zip(run) {
                let i = live.index(h);
                update((p, h), i, &mut part[i - first], other, scratch, &mut found);
            }
            found
        })
        .reduce(F::default, &fold)
}

//! The maximal end components of a model's live states, for the undiscounted solve
//! (docs/semantics.md §6.5 step 2, §13.2).
//!
//! An end component is a set of states and, for each, a non-empty set of its choices, all of
//! whose outcomes stay in the set, and which is strongly connected under those choices: the robot
//! (with the adversary's help) can stay in it for ever, collecting nothing. The maximal ones are
//! found by the usual refinement: strongly connected components of the states still candidates,
//! under the choices that stay among them; a chance node with an outcome outside its component,
//! and a decision node without a move inside its component, leave the candidates; until nothing
//! leaves. `stop` never stays (it reaches an absorbing sink).
//!
//! Components are Tarjan's, iterative: per live state an index and a low link (eight bytes while
//! it runs), a stack of states and one of frames (state, next successor), a successor list
//! recomputed when a frame resumes (at most the arena's degree, so a state costs at most the
//! square of it).

use bit_set::BitSet;

use super::mdp::{Choice, Distribution, Model};
use super::moves::Moves;
use crate::arena::Owner;

/// Fills `out` with the successors of live state `h` within `set`: a decision node's moves
/// into `set`, a chance node's outcomes in `set`.
pub(crate) fn successors_within<M: Moves>(
    model: &Model<'_, '_, M>,
    h: u32,
    set: &BitSet,
    distribution: &mut Distribution,
    out: &mut Vec<u32>,
) {
    out.clear();
    if model.space().owner(h) == Owner::Adversary {
        model.distribution(h, distribution);
        out.extend(
            distribution
                .iter()
                .map(|(t, _)| t)
                .filter(|&t| set.contains(t as usize)),
        );
    } else {
        model.choices(h, |c| {
            if let Choice::Move { target, .. } = c
                && set.contains(target as usize)
            {
                out.push(target);
            }
        });
    }
}

/// The maximal end components among `states` (a set of live states of `model`), each as
/// its list of states; `index(h)` numbers the live states densely below `live`.
pub(crate) fn end_components<M: Moves>(
    model: &Model<'_, '_, M>,
    states: &BitSet,
    index: impl Fn(u32) -> usize,
    live: usize,
) -> Vec<Vec<u32>> {
    let mut distribution = Distribution::default();
    let chance = |h: u32| model.space().owner(h) == Owner::Adversary;
    end_components_by(states, index, live, chance, |h, out| {
        out.clear();
        if chance(h) {
            model.distribution(h, &mut distribution);
            out.extend(distribution.iter().map(|(t, _)| t));
        } else {
            model.choices(h, |c| {
                if let Choice::Move { target, .. } = c {
                    out.push(target);
                }
            });
        }
    })
}

/// The maximal end components among `states` of a graph given by its chance nodes
/// (`chance(h)`) and `outcomes`, which fills its vector with every outcome of a chance node's
/// one choice, or the targets of a decision node's moves (`stop` never stays); an outcome not
/// in `states` (any number) leaves. `index(h)` numbers the states densely below `live`.
pub(crate) fn end_components_by(
    states: &BitSet,
    index: impl Fn(u32) -> usize,
    live: usize,
    chance: impl Fn(u32) -> bool,
    mut outcomes: impl FnMut(u32, &mut Vec<u32>),
) -> Vec<Vec<u32>> {
    let mut candidates = states.clone();
    let mut all = Vec::new();
    // The successors of `h` within `set`: a decision node's moves into it, a chance node's
    // outcomes if they all are in it (its one choice stays) and none otherwise.
    let mut within = |h: u32, set: &BitSet, out: &mut Vec<u32>| {
        outcomes(h, &mut all);
        out.clear();
        let inside = |t: &u32| set.contains(*t as usize);
        if !chance(h) {
            out.extend(all.iter().copied().filter(inside));
        } else if all.iter().all(inside) {
            out.extend_from_slice(&all);
        }
    };
    let mut successors = Vec::new();
    loop {
        let found = components(&candidates, &index, live, |h, out| {
            within(h, &candidates, out)
        });
        // The component of each candidate, by live index.
        let mut component = vec![u32::MAX; live];
        for c in 0..found.len() {
            for &h in found.get(c) {
                component[index(h)] = c as u32;
            }
        }
        let mut removed = false;
        let mut kept = Vec::new();
        for c in 0..found.len() {
            let members = found.get(c);
            let inside: Vec<u32> = members
                .iter()
                .copied()
                .filter(|&h| {
                    let own = component[index(h)];
                    within(h, &candidates, &mut successors);
                    let same = |t: &u32| component[index(*t)] == own;
                    if chance(h) {
                        !successors.is_empty() && successors.iter().all(same)
                    } else {
                        successors.iter().any(same)
                    }
                })
                .collect();
            if inside.len() < members.len() {
                removed = true;
                for &h in members {
                    candidates.remove(h as usize);
                }
                for &h in &inside {
                    candidates.insert(h as usize);
                }
            }
            if !inside.is_empty() {
                kept.push(inside);
            }
        }
        if !removed {
            return kept;
        }
    }
}

/// The members of some maximal end components, each with its component's number, in a list
/// sorted by state (eight bytes per member).
#[derive(Clone, Debug, Default)]
pub(crate) struct EndMembers {
    members: Vec<(u32, u32)>,
}

impl EndMembers {
    /// The members of `ends`, component `e` numbered `e`.
    pub(crate) fn new(ends: &[Vec<u32>]) -> EndMembers {
        let mut members: Vec<(u32, u32)> = ends
            .iter()
            .enumerate()
            .flat_map(|(e, members)| members.iter().map(move |&h| (h, e as u32)))
            .collect();
        members.sort_unstable();
        EndMembers { members }
    }

    /// The component of `h`, if it is in one.
    #[inline]
    pub(crate) fn of(&self, h: u32) -> Option<u32> {
        if self.members.is_empty() {
            return None;
        }
        self.members
            .binary_search_by_key(&h, |&(state, _)| state)
            .ok()
            .map(|k| self.members[k].1)
    }
}

/// Strongly connected components, flat: the states of component `c` are
/// `states[starts[c]..starts[c + 1]]`, components in the order Tarjan's algorithm closes them
/// (every component after those it reaches: successors first).
pub(crate) struct Components {
    pub(crate) states: Vec<u32>,
    pub(crate) starts: Vec<u32>,
}

impl Components {
    /// The number of components.
    pub(crate) fn len(&self) -> usize {
        self.starts.len() - 1
    }

    /// The states of component `c`.
    pub(crate) fn get(&self, c: usize) -> &[u32] {
        &self.states[self.starts[c] as usize..self.starts[c + 1] as usize]
    }

    /// Sorts the states of each component by `key`.
    pub(crate) fn sort_each_by_key(&mut self, key: impl Fn(u32) -> u32) {
        for c in 0..self.len() {
            let range = self.starts[c] as usize..self.starts[c + 1] as usize;
            self.states[range].sort_unstable_by_key(|&h| key(h));
        }
    }
}

/// Tarjan's strongly connected components of `candidates` under the edges `successors` lists
/// (it fills its vector with the successors of a state, all of them candidates).
pub(crate) fn components(
    candidates: &BitSet,
    index: &impl Fn(u32) -> usize,
    live: usize,
    mut successors: impl FnMut(u32, &mut Vec<u32>),
) -> Components {
    const UNSEEN: u32 = u32::MAX;
    let mut order = vec![UNSEEN; live];
    let mut low = vec![0u32; live];
    let mut on_stack = BitSet::with_capacity(live);
    let mut stack: Vec<u32> = Vec::new();
    let mut frames: Vec<(u32, usize)> = Vec::new();
    let mut next = 0u32;
    let mut result = Components {
        states: Vec::new(),
        starts: vec![0],
    };
    let mut list = Vec::new();
    for root in candidates.iter().map(|h| h as u32) {
        if order[index(root)] != UNSEEN {
            continue;
        }
        frames.push((root, 0));
        while let Some(&mut (h, ref mut position)) = frames.last_mut() {
            let i = index(h);
            if *position == 0 && order[i] == UNSEEN {
                order[i] = next;
                low[i] = next;
                next += 1;
                stack.push(h);
                on_stack.insert(i);
            }
            // The successors are listed once per visit of the frame, which then takes every
            // successor already seen until one must be searched first: a state's list is
            // computed at most once more than it has children in the search.
            successors(h, &mut list);
            let mut child = None;
            while let Some(&t) = list.get(*position) {
                *position += 1;
                let j = index(t);
                if order[j] == UNSEEN {
                    child = Some(t);
                    break;
                } else if on_stack.contains(j) {
                    low[i] = low[i].min(order[j]);
                }
            }
            if let Some(t) = child {
                frames.push((t, 0));
                continue;
            }
            frames.pop();
            if let Some(&(parent, _)) = frames.last() {
                let p = index(parent);
                low[p] = low[p].min(low[i]);
            }
            if low[i] == order[i] {
                loop {
                    let t = stack
                        .pop()
                        .expect("the component's states are on the stack");
                    on_stack.remove(index(t));
                    result.states.push(t);
                    if t == h {
                        break;
                    }
                }
                result.starts.push(result.states.len() as u32);
            }
        }
    }
    result
}

//! Graph algorithms on an [`Mdp`] that the solver needs: predecessor lists, and the maximal end
//! components of a sub-MDP.
//!
//! An *end component* of a set of states `C` is a non-empty `E ⊆ C` with, for each state of `E`,
//! a non-empty set of its choices whose successors all lie in `E`, such that `E` is strongly
//! connected through those choices. A policy can keep the run inside `E` forever and visit every
//! state of it; the maximal ones (MECs) are disjoint.

use std::ops::Range;

use bit_set::BitSet;

use super::model::{ChoiceId, Mdp, MdpState};
use crate::csr::Csr;
use crate::index::Id;

/// For every state, the states with a choice (among those kept) leading to it with positive
/// probability, once per such choice, in increasing order of the choice: what the backward
/// searches need, without the choices themselves or an owner per choice (4 bytes per
/// transition and per state). Each entry carries, in its top bit, whether its choice is
/// instant (`INSTANT`), which the search for payoff levels needs per edge; a model of `2^31`
/// states or more (far beyond any memory limit) keeps no such bit, and then says it does not
/// know.
pub(super) struct Predecessors {
    lists: Csr<MdpState, u32>,
    tagged: bool,
}

/// The bit of a predecessor entry that marks an instant choice.
const INSTANT: u32 = 1 << 31;

impl Predecessors {
    /// The predecessor lists over the choices for which `keep` holds.
    pub(super) fn new(mdp: &Mdp, keep: impl Fn(ChoiceId) -> bool) -> Self {
        Predecessors::with_tags(mdp, keep, mdp.num_states() <= INSTANT as usize)
    }

    /// [`Self::new`], with the instant bits only if `tagged` (the model has fewer than `2^31`
    /// states; tests ask for lists without them).
    pub(super) fn with_tags(mdp: &Mdp, keep: impl Fn(ChoiceId) -> bool, tagged: bool) -> Self {
        // One flat pass over the choices, their owner advanced alongside (the choices of a
        // state are consecutive): nesting the choices in the states cost twice the time.
        let lists = Csr::group_from(mdp.num_states(), || {
            let mut owner = MdpState::new(0);
            mdp.all_choices()
                .filter(|&choice| keep(choice))
                .flat_map(move |choice| {
                    while mdp.choices(owner).end() <= choice {
                        owner = MdpState::new(owner.index() + 1);
                    }
                    let tag = if tagged && mdp.is_instant(choice) {
                        INSTANT
                    } else {
                        0
                    };
                    let entry = owner.index() as u32 | tag;
                    mdp.targets(choice).iter().map(move |&t| (t, entry))
                })
        });
        Predecessors { lists, tagged }
    }

    /// The number of states (rows).
    pub(super) fn num_states(&self) -> usize {
        self.lists.num_rows()
    }

    /// The owners of the kept choices with `state` among their successors, by increasing
    /// choice.
    pub(super) fn of(&self, state: MdpState) -> impl Iterator<Item = MdpState> + '_ {
        self.of_tagged(state).map(|(owner, _)| owner)
    }

    /// [`Self::of`], each owner with whether the choice that leads to `state` is instant
    /// (`None`: not recorded, see the type's documentation).
    pub(super) fn of_tagged(
        &self,
        state: MdpState,
    ) -> impl Iterator<Item = (MdpState, Option<bool>)> + '_ {
        let mask = if self.tagged { !INSTANT } else { u32::MAX };
        let tagged = self.tagged;
        self.lists.row(state).iter().map(move |&entry| {
            let instant = tagged.then_some(entry & INSTANT != 0);
            (MdpState::new((entry & mask) as usize), instant)
        })
    }
}

/// The maximal end components of the sub-MDP on the states of `candidates` (choices with a
/// successor outside `candidates` are not part of it). Returns, for every state, the index of its
/// MEC or `None`, and the number of MECs.
///
/// Method (de Alfaro's refinement): split the candidates into SCCs over the choices that stay in
/// their block; inside each SCC drop the choices that now leave it and the states left without a
/// choice, and, through the predecessor lists, the choices into a dropped state and the states
/// that this leaves without a choice, until none is left (an attractor, so that a chain of
/// states that die one after the other costs one round, not one round each: 78 rounds over the
/// whole component on a 20x20 gridworld before); re-split every SCC that lost something, until
/// none does. Whether an SCC lost a choice is decided for all SCCs of a round before any state
/// is dropped (a choice into a state dropped earlier in the round would otherwise not be seen
/// as lost, and a set that is not strongly connected through its staying choices would be
/// taken for an end component). Blocks only ever shrink, so a dropped choice never comes back.
/// The SCCs of a round are kept in one flat list (no allocation per SCC: most are single
/// states). Worst case O(n · m), in practice a few rounds.
pub(super) fn maximal_end_components(
    mdp: &Mdp,
    predecessors: &Predecessors,
    candidates: &[MdpState],
) -> (Vec<Option<u32>>, u32) {
    let n = mdp.num_states();
    // The block of each live candidate; `u32::NONE` for other states. A choice is *alive* when
    // all its successors are in its owner's block.
    let mut block = vec![u32::NONE; n];
    for &state in candidates {
        block[state.index()] = 0;
    }
    let mut next_block = 1u32;
    let mut pending = Vec::new();
    if !candidates.is_empty() {
        pending.push(candidates.to_vec());
    }
    let mut tarjan = Tarjan::new(n);
    let mut component = vec![None; n];
    let mut count = 0u32;
    let mut dropped = Vec::new();
    // The SCCs of a round: their states, one SCC after the other, and the positions where each
    // starts. Flat and reused (most SCCs are single states: a `Vec` each was most of the
    // search's time), and no offsets per SCC, so that this costs no memory beyond the old
    // per-SCC lists (4 bytes per state and a bit).
    let mut order = Vec::with_capacity(candidates.len());
    let mut starts = BitSet::with_capacity(candidates.len());
    let mut lost = BitSet::new();
    while let Some(set) = pending.pop() {
        tarjan.components(mdp, &block, &set, &mut order, &mut starts);
        // Number every SCC before checking any, so that "was alive" sees the whole old block.
        let first_new_block = next_block;
        for range in ranges(&starts, order.len()) {
            for &state in &order[range] {
                block[state.index()] = next_block;
            }
            next_block += 1;
        }
        // Which SCCs lost a choice of the old block, decided before any state is dropped: a
        // dropped state no longer shows that it was in the old block, and a choice into it
        // from a later SCC would look as if it had never been alive there.
        lost.make_empty();
        for (i, range) in ranges(&starts, order.len()).enumerate() {
            if lost_choice(mdp, &block, first_new_block, &order[range]) {
                lost.insert(i);
            }
        }
        for (i, range) in ranges(&starts, order.len()).enumerate() {
            let states = &order[range];
            let id = block[states[0].index()];
            let dropped_any = drop_dead(mdp, predecessors, &mut block, states, &mut dropped);
            if !lost.contains(i) && !dropped_any {
                for &state in states {
                    component[state.index()] = Some(count);
                }
                count += 1;
            } else if dropped_any {
                let survivors: Vec<MdpState> = states
                    .iter()
                    .copied()
                    .filter(|&state| block[state.index()] == id)
                    .collect();
                if !survivors.is_empty() {
                    pending.push(survivors);
                }
            } else {
                pending.push(states.to_vec());
            }
        }
    }
    (component, count)
}

/// The ranges of `0..len` that start at the members of `starts`.
fn ranges(starts: &BitSet, len: usize) -> impl Iterator<Item = Range<usize>> + '_ {
    let mut begin = 0;
    (1..=len).filter_map(move |end| {
        if end == len || starts.contains(end) {
            let range = begin..end;
            begin = end;
            Some(range)
        } else {
            None
        }
    })
}

/// Whether a state of the freshly numbered `scc` has a choice that was alive in the block
/// `scc` was split from (all its successors have a block ≥ `first_new_block`) but is not alive
/// in `scc`.
fn lost_choice(mdp: &Mdp, block: &[u32], first_new_block: u32, scc: &[MdpState]) -> bool {
    let id = block[scc[0].index()];
    scc.iter().any(|&state| {
        mdp.choices(state).any(|choice| {
            let targets = mdp.targets(choice);
            targets.iter().any(|&t| block[t.index()] != id)
                && targets.iter().all(|&t| {
                    let b = block[t.index()];
                    !b.is_none() && b >= first_new_block
                })
        })
    })
}

/// Drops, inside the freshly numbered `scc`, the states left without an alive choice, then
/// those that dropping them leaves without one, until none is (`dropped` is scratch space).
/// Returns whether any state was dropped.
fn drop_dead(
    mdp: &Mdp,
    predecessors: &Predecessors,
    block: &mut [u32],
    scc: &[MdpState],
    dropped: &mut Vec<MdpState>,
) -> bool {
    let id = block[scc[0].index()];
    let has_alive_choice = |block: &[u32], state: MdpState| {
        mdp.choices(state)
            .any(|choice| mdp.targets(choice).iter().all(|&t| block[t.index()] == id))
    };
    dropped.clear();
    for &state in scc {
        if !has_alive_choice(block, state) {
            block[state.index()] = u32::NONE;
            dropped.push(state);
        }
    }
    let dropped_any = !dropped.is_empty();
    while let Some(state) = dropped.pop() {
        for owner in predecessors.of(state) {
            if block[owner.index()] == id && !has_alive_choice(block, owner) {
                block[owner.index()] = u32::NONE;
                dropped.push(owner);
            }
        }
    }
    dropped_any
}

/// Iterative Tarjan over one block: vertices are the states of the block, edges the successors
/// of their alive choices. Arrays are sized once and reset per call for the block's states only.
struct Tarjan {
    /// Per state, its visiting order (`u32::NONE`: not visited).
    index: Vec<u32>,
    low: Vec<u32>,
    on_stack: BitSet,
    stack: Vec<MdpState>,
    frames: Vec<Frame>,
}

/// A suspended visit: the state, the choice being explored and the next successor's position.
struct Frame {
    state: MdpState,
    choice: ChoiceId,
    position: usize,
}

impl Tarjan {
    fn new(n: usize) -> Self {
        Tarjan {
            index: vec![u32::NONE; n],
            low: vec![u32::NONE; n],
            on_stack: BitSet::with_capacity(n),
            stack: Vec::new(),
            frames: Vec::new(),
        }
    }

    /// The SCCs of the block shared by all states of `set` (which must be the whole block).
    /// They are written to `order`, one after the other, each starting at a member of `starts`.
    fn components(
        &mut self,
        mdp: &Mdp,
        block: &[u32],
        set: &[MdpState],
        order: &mut Vec<MdpState>,
        starts: &mut BitSet,
    ) {
        let id = block[set[0].index()];
        for &state in set {
            self.index[state.index()] = u32::NONE;
        }
        let mut counter = 0u32;
        order.clear();
        starts.make_empty();
        for &root in set {
            if !self.index[root.index()].is_none() {
                continue;
            }
            self.visit(mdp, root, &mut counter);
            while let Some(frame) = self.frames.last_mut() {
                let state = frame.state;
                match next_successor(mdp, block, id, frame) {
                    Some(target) if self.index[target.index()].is_none() => {
                        self.visit(mdp, target, &mut counter);
                    }
                    Some(target) => {
                        if self.on_stack.contains(target.index()) {
                            let low = self.low[state.index()].min(self.index[target.index()]);
                            self.low[state.index()] = low;
                        }
                    }
                    None => {
                        self.frames.pop();
                        if let Some(parent) = self.frames.last() {
                            let low = self.low[parent.state.index()].min(self.low[state.index()]);
                            self.low[parent.state.index()] = low;
                        }
                        if self.low[state.index()] == self.index[state.index()] {
                            starts.insert(order.len());
                            self.pop_component(state, order);
                        }
                    }
                }
            }
        }
    }

    fn visit(&mut self, mdp: &Mdp, state: MdpState, counter: &mut u32) {
        self.index[state.index()] = *counter;
        self.low[state.index()] = *counter;
        *counter += 1;
        self.stack.push(state);
        self.on_stack.insert(state.index());
        self.frames.push(Frame {
            state,
            choice: mdp.choices(state).start(),
            position: 0,
        });
    }

    /// Moves the states of the stack down to `root` to the end of `order`.
    fn pop_component(&mut self, root: MdpState, order: &mut Vec<MdpState>) {
        loop {
            let state = self.stack.pop().expect("the root is on the stack");
            self.on_stack.remove(state.index());
            order.push(state);
            if state == root {
                return;
            }
        }
    }
}

/// The next successor of the frame's state through a choice alive in block `id`.
fn next_successor(mdp: &Mdp, block: &[u32], id: u32, frame: &mut Frame) -> Option<MdpState> {
    let end = mdp.choices(frame.state).end();
    while frame.choice < end {
        let targets = mdp.targets(frame.choice);
        let alive = frame.position > 0 || targets.iter().all(|&t| block[t.index()] == id);
        if alive && frame.position < targets.len() {
            frame.position += 1;
            return Some(targets[frame.position - 1]);
        }
        frame.choice = ChoiceId::from_u32(frame.choice.as_u32() + 1);
        frame.position = 0;
    }
    None
}

/// The strongly connected components of `graph`, in reverse topological order (every edge
/// leaving a component leads to one listed before it): row `i` of the result is component `i`'s
/// vertices. Iterative Tarjan: no recursion on the graph's depth. O(vertices + edges).
pub(crate) fn strongly_connected_components<I: Id>(graph: &Csr<I, I>) -> Csr<u32, I> {
    strongly_connected_components_by(graph.num_rows(), |v| graph.row(v).iter().copied())
}

/// [`strongly_connected_components`] of the graph on the vertices `0..n` whose successors of
/// `v` are the items of `successors(v)` below `n`, in that order (the others are skipped):
/// for a graph that is part of a larger structure, without copying it into a CSR of its own.
pub(super) fn strongly_connected_components_by<I: Id, S: Iterator<Item = I>>(
    n: usize,
    successors: impl Fn(I) -> S,
) -> Csr<u32, I> {
    // Per vertex, its visiting order (`u32::NONE`: not visited) and low link.
    let mut index = vec![u32::NONE; n];
    let mut low = vec![u32::NONE; n];
    let mut on_stack = BitSet::with_capacity(n);
    let mut stack = Vec::new();
    // Suspended visits: the vertex and its successors not yet looked at.
    let mut frames: Vec<(I, S)> = Vec::new();
    let mut components = Csr::with_capacity(n, n);
    let mut counter = 0u32;
    for root in (0..n).map(I::new) {
        if !index[root.index()].is_none() {
            continue;
        }
        // Opens the visit of `v`.
        macro_rules! visit {
            ($v:expr) => {{
                let v: I = $v;
                index[v.index()] = counter;
                low[v.index()] = counter;
                counter += 1;
                stack.push(v);
                on_stack.insert(v.index());
                frames.push((v, successors(v)));
            }};
        }
        visit!(root);
        while let Some((v, targets)) = frames.last_mut() {
            let v = *v;
            if let Some(t) = targets.next() {
                if t.index() >= n {
                    continue;
                }
                if index[t.index()].is_none() {
                    visit!(t);
                } else if on_stack.contains(t.index()) {
                    low[v.index()] = low[v.index()].min(index[t.index()]);
                }
                continue;
            }
            frames.pop();
            if let Some(&(parent, _)) = frames.last() {
                low[parent.index()] = low[parent.index()].min(low[v.index()]);
            }
            if low[v.index()] == index[v.index()] {
                loop {
                    let w = stack.pop().expect("the root is on the stack");
                    on_stack.remove(w.index());
                    components.push(w);
                    if w == v {
                        break;
                    }
                }
                components.finish_row();
            }
        }
    }
    components
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mdp::testing::{
        Spec::{Absorb, Decide},
        mc, mdp_from, ms,
    };

    #[test]
    fn components_come_in_reverse_topological_order() {
        // 0 → 1 ⇄ 2 → 3, 3 → 3, 4 isolated: {3} before {1, 2} before {0}.
        let mut graph: Csr<u32, u32> = Csr::new();
        for row in [&[1][..], &[2, 3], &[1], &[3], &[]] {
            graph.push_row(row.iter().copied());
        }
        let sccs = strongly_connected_components(&graph);
        let components: Vec<Vec<u32>> = sccs
            .rows()
            .map(|i| {
                let mut c = sccs.row(i).to_vec();
                c.sort_unstable();
                c
            })
            .collect();
        assert_eq!(components, [vec![3], vec![1, 2], vec![0], vec![4]]);
    }

    #[test]
    fn predecessors_say_which_choices_are_instant() {
        let mut rng = crate::mdp::testing::rng(5);
        for _ in 0..50 {
            let mdp = crate::mdp::testing::random_mdp_with_instant_choices(&mut rng, 30);
            // Naively: every transition, in the order of its choice, with its choice's kind.
            let mut expected = vec![Vec::new(); mdp.num_states()];
            for owner in mdp.states() {
                for choice in mdp.choices(owner) {
                    for &target in mdp.targets(choice) {
                        expected[target.index()].push((owner, Some(mdp.is_instant(choice))));
                    }
                }
            }
            let predecessors = Predecessors::new(&mdp, |_| true);
            for state in mdp.states() {
                let got: Vec<_> = predecessors.of_tagged(state).collect();
                assert_eq!(got, expected[state.index()], "{mdp:?}");
            }
        }
    }

    #[test]
    fn predecessors_list_the_owners_of_the_choices_into_each_state() {
        let mdp = mdp_from(&[
            Decide(&[("a", &[(1, 0.5), (2, 0.5)]), ("b", &[(0, 1.0)])]),
            Decide(&[("c", &[(2, 1.0)])]),
            Absorb(1.0),
        ]);
        let predecessors = Predecessors::new(&mdp, |_| true);
        assert_eq!(predecessors.of(ms(0)).collect::<Vec<_>>(), [ms(0)]);
        assert_eq!(predecessors.of(ms(1)).collect::<Vec<_>>(), [ms(0)]);
        assert_eq!(predecessors.of(ms(2)).collect::<Vec<_>>(), [ms(0), ms(1)]);
        // Only the kept choices count: without `a`, state 0 leads to 0 alone.
        let predecessors = Predecessors::new(&mdp, |c| c != mc(0));
        assert_eq!(predecessors.of(ms(0)).collect::<Vec<_>>(), [ms(0)]);
        assert_eq!(predecessors.of(ms(1)).count(), 0);
        assert_eq!(predecessors.of(ms(2)).collect::<Vec<_>>(), [ms(1)]);
    }

    #[test]
    fn choices_leaving_the_candidates_do_not_make_end_components() {
        // 0: a leaves to the absorbing 2 half the time; b is a self-loop. 1 only returns to 0.
        // {0, 1} is strongly connected only through a, which leaves: the MEC is {0} alone.
        let mdp = mdp_from(&[
            Decide(&[("a", &[(1, 0.5), (2, 0.5)]), ("b", &[(0, 1.0)])]),
            Decide(&[("c", &[(0, 1.0)])]),
            Absorb(1.0),
        ]);
        assert_eq!(
            maximal_end_components(&mdp, &Predecessors::new(&mdp, |_| true), &[ms(0), ms(1)]),
            (vec![Some(0), None, None], 1)
        );
    }

    #[test]
    fn components_are_refined_until_stable() {
        // Round 1 over {0, 1, 2}: SCCs {0, 1} (through a: 0 → 1) and {2}. a also reaches 2, so
        // it leaves {0, 1}; without it {0, 1} is no longer strongly connected. Round 2 splits it
        // into {0} (self-loop b) and {1} (whose only choice leaves): MECs {0} and {2}.
        let mdp = mdp_from(&[
            Decide(&[("a", &[(1, 0.5), (2, 0.5)]), ("b", &[(0, 1.0)])]),
            Decide(&[("c", &[(0, 1.0)])]),
            Decide(&[("d", &[(2, 1.0)])]),
        ]);
        let (component, count) = maximal_end_components(
            &mdp,
            &Predecessors::new(&mdp, |_| true),
            &[ms(0), ms(1), ms(2)],
        );
        assert_eq!(count, 2);
        assert!(component[0].is_some() && component[2].is_some());
        assert_ne!(component[0], component[2]);
        assert_eq!(component[1], None);
        // The two-state cycle 0 ⇄ 1 with choices that stay is one MEC.
        let cycle = mdp_from(&[
            Decide(&[("a", &[(1, 1.0)])]),
            Decide(&[("b", &[(0, 0.5), (1, 0.5)])]),
        ]);
        assert_eq!(
            maximal_end_components(
                &cycle,
                &Predecessors::new(&cycle, |_| true),
                &[ms(0), ms(1)]
            ),
            (vec![Some(0), Some(0)], 1)
        );
        assert_eq!(
            maximal_end_components(&cycle, &Predecessors::new(&cycle, |_| true), &[]),
            (vec![None, None], 0)
        );
    }

    #[test]
    fn a_choice_into_a_state_dropped_in_the_same_round_still_counts_as_lost() {
        // Round 1 over {0, 1, 2}: SCCs {2} (no choice stays) and {0, 1}, strongly connected
        // through b: 1 → 0, which also reaches 2 and so leaves {0, 1}. Without b, 0 → 1 has no
        // way back: the only MEC is {1} (its self-loop c). {2} is checked and dropped first;
        // b must still count as a choice {0, 1} lost.
        let mdp = mdp_from(&[
            Decide(&[("a", &[(1, 1.0)])]),
            Decide(&[("b", &[(0, 0.5), (2, 0.5)]), ("c", &[(1, 1.0)])]),
            Decide(&[("s", &[(3, 1.0)])]),
            Absorb(1.0),
        ]);
        assert_eq!(
            maximal_end_components(
                &mdp,
                &Predecessors::new(&mdp, |_| true),
                &[ms(0), ms(1), ms(2)]
            ),
            (vec![None, Some(0), None, None], 1)
        );
    }
}

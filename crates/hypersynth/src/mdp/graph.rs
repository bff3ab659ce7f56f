//! Graph algorithms on an [`Mdp`] that the solver needs: predecessor lists, and the maximal end
//! components of a sub-MDP.
//!
//! An *end component* of a set of states `C` is a non-empty `E ⊆ C` with, for each state of `E`,
//! a non-empty set of its choices whose successors all lie in `E`, such that `E` is strongly
//! connected through those choices. A policy can keep the run inside `E` forever and visit every
//! state of it; the maximal ones (MECs) are disjoint.

use bit_set::BitSet;

use super::model::Mdp;

const NONE: u32 = u32::MAX;

/// For every state, the choices (of any state) that lead to it with positive probability, in
/// CSR form, and for every choice the state that owns it.
pub(super) struct Predecessors {
    offsets: Vec<u32>,
    choices: Vec<u32>,
    owners: Vec<u32>,
}

impl Predecessors {
    pub(super) fn new(mdp: &Mdp) -> Self {
        let n = mdp.num_states() as usize;
        let mut owners = Vec::with_capacity(mdp.num_choices() as usize);
        let mut offsets = vec![0u32; n + 1];
        for state in 0..mdp.num_states() {
            for choice in mdp.choices(state) {
                owners.push(state);
                for &target in mdp.targets(choice) {
                    offsets[target as usize + 1] += 1;
                }
            }
        }
        for i in 0..n {
            offsets[i + 1] += offsets[i];
        }
        let mut next = offsets.clone();
        let mut choices = vec![0u32; mdp.num_transitions() as usize];
        for choice in 0..mdp.num_choices() {
            for &target in mdp.targets(choice) {
                choices[next[target as usize] as usize] = choice;
                next[target as usize] += 1;
            }
        }
        Predecessors {
            offsets,
            choices,
            owners,
        }
    }

    /// The choices with `state` among their successors, ascending.
    pub(super) fn of(&self, state: u32) -> &[u32] {
        &self.choices
            [self.offsets[state as usize] as usize..self.offsets[state as usize + 1] as usize]
    }

    /// The state whose choice `choice` is.
    pub(super) fn owner(&self, choice: u32) -> u32 {
        self.owners[choice as usize]
    }
}

/// The maximal end components of the sub-MDP on the states of `candidates` (choices with a
/// successor outside `candidates` are not part of it). Returns, for every state, the index of its
/// MEC or `None`, and the number of MECs.
///
/// Method (de Alfaro's refinement): split the candidates into SCCs over the choices that stay in
/// their block; inside each SCC drop the choices that now leave it and the states left without a
/// choice; re-split every SCC that lost something, until none does. Blocks only ever shrink, so a
/// dropped choice never comes back. Worst case O(n · m), in practice a few rounds.
pub(super) fn maximal_end_components(mdp: &Mdp, candidates: &[u32]) -> (Vec<Option<u32>>, u32) {
    let n = mdp.num_states() as usize;
    // The block of each live candidate; NONE for other states. A choice is *alive* when all its
    // successors are in its owner's block.
    let mut block = vec![NONE; n];
    for &state in candidates {
        block[state as usize] = 0;
    }
    let mut next_block = 1u32;
    let mut pending = Vec::new();
    if !candidates.is_empty() {
        pending.push(candidates.to_vec());
    }
    let mut tarjan = Tarjan::new(n);
    let mut component = vec![None; n];
    let mut count = 0u32;
    while let Some(set) = pending.pop() {
        let sccs = tarjan.components(mdp, &block, &set);
        // Number every SCC before checking any, so that "was alive" sees the whole old block.
        let first_new_block = next_block;
        for scc in &sccs {
            for &state in scc {
                block[state as usize] = next_block;
            }
            next_block += 1;
        }
        for scc in sccs {
            let (survivors, changed) = drop_dead(mdp, &mut block, first_new_block, &scc);
            if !changed {
                for &state in &scc {
                    component[state as usize] = Some(count);
                }
                count += 1;
            } else if !survivors.is_empty() {
                pending.push(survivors);
            }
        }
    }
    (component, count)
}

/// Drops, inside the freshly numbered `scc`, the states left without an alive choice. Returns
/// the survivors and whether anything was lost: a state, or a choice that was alive in the
/// block `scc` was split from (all its successors have a block ≥ `first_new_block`).
fn drop_dead(mdp: &Mdp, block: &mut [u32], first_new_block: u32, scc: &[u32]) -> (Vec<u32>, bool) {
    let id = block[scc[0] as usize];
    let mut changed = false;
    let mut survivors = Vec::with_capacity(scc.len());
    for &state in scc {
        let mut alive = false;
        for choice in mdp.choices(state) {
            let targets = mdp.targets(choice);
            if targets.iter().all(|&t| block[t as usize] == id) {
                alive = true;
            } else if targets
                .iter()
                .all(|&t| block[t as usize] != NONE && block[t as usize] >= first_new_block)
            {
                changed = true;
            }
        }
        if alive {
            survivors.push(state);
        } else {
            block[state as usize] = NONE;
            changed = true;
        }
    }
    (survivors, changed)
}

/// Iterative Tarjan over one block: vertices are the states of the block, edges the successors
/// of their alive choices. Arrays are sized once and reset per call for the block's states only.
struct Tarjan {
    index: Vec<u32>,
    low: Vec<u32>,
    on_stack: BitSet,
    stack: Vec<u32>,
    frames: Vec<Frame>,
}

/// A suspended visit: the state, the choice being explored and the next successor's position.
struct Frame {
    state: u32,
    choice: u32,
    position: usize,
}

impl Tarjan {
    fn new(n: usize) -> Self {
        Tarjan {
            index: vec![NONE; n],
            low: vec![NONE; n],
            on_stack: BitSet::with_capacity(n),
            stack: Vec::new(),
            frames: Vec::new(),
        }
    }

    /// The SCCs of the block shared by all states of `set` (which must be the whole block).
    fn components(&mut self, mdp: &Mdp, block: &[u32], set: &[u32]) -> Vec<Vec<u32>> {
        let id = block[set[0] as usize];
        for &state in set {
            self.index[state as usize] = NONE;
        }
        let mut counter = 0u32;
        let mut sccs = Vec::new();
        for &root in set {
            if self.index[root as usize] != NONE {
                continue;
            }
            self.visit(mdp, root, &mut counter);
            while let Some(frame) = self.frames.last_mut() {
                let state = frame.state;
                match next_successor(mdp, block, id, frame) {
                    Some(target) if self.index[target as usize] == NONE => {
                        self.visit(mdp, target, &mut counter);
                    }
                    Some(target) => {
                        if self.on_stack.contains(target as usize) {
                            let low = self.low[state as usize].min(self.index[target as usize]);
                            self.low[state as usize] = low;
                        }
                    }
                    None => {
                        self.frames.pop();
                        if let Some(parent) = self.frames.last() {
                            let low = self.low[parent.state as usize].min(self.low[state as usize]);
                            self.low[parent.state as usize] = low;
                        }
                        if self.low[state as usize] == self.index[state as usize] {
                            sccs.push(self.pop_component(state));
                        }
                    }
                }
            }
        }
        sccs
    }

    fn visit(&mut self, mdp: &Mdp, state: u32, counter: &mut u32) {
        self.index[state as usize] = *counter;
        self.low[state as usize] = *counter;
        *counter += 1;
        self.stack.push(state);
        self.on_stack.insert(state as usize);
        self.frames.push(Frame {
            state,
            choice: mdp.choices(state).start,
            position: 0,
        });
    }

    fn pop_component(&mut self, root: u32) -> Vec<u32> {
        let mut scc = Vec::new();
        loop {
            let state = self.stack.pop().expect("the root is on the stack");
            self.on_stack.remove(state as usize);
            scc.push(state);
            if state == root {
                return scc;
            }
        }
    }
}

/// The next successor of the frame's state through a choice alive in block `id`.
fn next_successor(mdp: &Mdp, block: &[u32], id: u32, frame: &mut Frame) -> Option<u32> {
    let end = mdp.choices(frame.state).end;
    while frame.choice < end {
        let targets = mdp.targets(frame.choice);
        let alive = frame.position > 0 || targets.iter().all(|&t| block[t as usize] == id);
        if alive && frame.position < targets.len() {
            frame.position += 1;
            return Some(targets[frame.position - 1]);
        }
        frame.choice += 1;
        frame.position = 0;
    }
    None
}

/// The strongly connected components of the graph with successor lists
/// `targets[offsets[v]..offsets[v + 1]]`, in reverse topological order (every edge leaving a
/// component leads to one listed before it), as one array of vertices cut by `bounds`
/// (component `i` is `vertices[bounds[i]..bounds[i + 1]]`). Iterative Tarjan: no recursion on
/// the graph's depth. O(vertices + edges).
pub(super) fn strongly_connected_components(
    offsets: &[u32],
    targets: &[u32],
) -> (Vec<u32>, Vec<u32>) {
    let n = offsets.len() - 1;
    let mut index = vec![NONE; n];
    let mut low = vec![NONE; n];
    let mut on_stack = BitSet::with_capacity(n);
    let mut stack = Vec::new();
    // Suspended visits: the vertex and the position of its next successor.
    let mut frames: Vec<(u32, u32)> = Vec::new();
    let mut vertices = Vec::with_capacity(n);
    let mut bounds = vec![0u32];
    let mut counter = 0u32;
    for root in 0..n as u32 {
        if index[root as usize] != NONE {
            continue;
        }
        // Opens the visit of `v`.
        macro_rules! visit {
            ($v:expr) => {{
                let v: u32 = $v;
                index[v as usize] = counter;
                low[v as usize] = counter;
                counter += 1;
                stack.push(v);
                on_stack.insert(v as usize);
                frames.push((v, offsets[v as usize]));
            }};
        }
        visit!(root);
        while let Some(&(v, position)) = frames.last() {
            if position < offsets[v as usize + 1] {
                let t = targets[position as usize];
                if let Some(frame) = frames.last_mut() {
                    frame.1 += 1;
                }
                if index[t as usize] == NONE {
                    visit!(t);
                } else if on_stack.contains(t as usize) {
                    low[v as usize] = low[v as usize].min(index[t as usize]);
                }
                continue;
            }
            frames.pop();
            if let Some(&(parent, _)) = frames.last() {
                low[parent as usize] = low[parent as usize].min(low[v as usize]);
            }
            if low[v as usize] == index[v as usize] {
                loop {
                    let w = stack.pop().expect("the root is on the stack");
                    on_stack.remove(w as usize);
                    vertices.push(w);
                    if w == v {
                        break;
                    }
                }
                bounds.push(vertices.len() as u32);
            }
        }
    }
    (vertices, bounds)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mdp::testing::{
        Spec::{Absorb, Decide},
        mdp_from,
    };

    #[test]
    fn components_come_in_reverse_topological_order() {
        // 0 → 1 ⇄ 2 → 3, 3 → 3, 4 isolated: {3} before {1, 2} before {0}.
        let offsets = [0, 1, 3, 4, 5, 5];
        let targets = [1, 2, 3, 1, 3];
        let (vertices, bounds) = strongly_connected_components(&offsets, &targets);
        let components: Vec<Vec<u32>> = bounds
            .windows(2)
            .map(|w| {
                let mut c = vertices[w[0] as usize..w[1] as usize].to_vec();
                c.sort_unstable();
                c
            })
            .collect();
        assert_eq!(components, [vec![3], vec![1, 2], vec![0], vec![4]]);
    }

    #[test]
    fn predecessors_list_the_choices_into_each_state() {
        let mdp = mdp_from(&[
            Decide(&[("a", &[(1, 0.5), (2, 0.5)]), ("b", &[(0, 1.0)])]),
            Decide(&[("c", &[(2, 1.0)])]),
            Absorb(1.0),
        ]);
        let predecessors = Predecessors::new(&mdp);
        assert_eq!(predecessors.of(0), [1]);
        assert_eq!(predecessors.of(1), [0]);
        assert_eq!(predecessors.of(2), [0, 2]);
        assert_eq!(
            (0..3).map(|c| predecessors.owner(c)).collect::<Vec<_>>(),
            [0, 0, 1]
        );
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
            maximal_end_components(&mdp, &[0, 1]),
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
        let (component, count) = maximal_end_components(&mdp, &[0, 1, 2]);
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
            maximal_end_components(&cycle, &[0, 1]),
            (vec![Some(0), Some(0)], 1)
        );
        assert_eq!(maximal_end_components(&cycle, &[]), (vec![None, None], 0));
    }
}

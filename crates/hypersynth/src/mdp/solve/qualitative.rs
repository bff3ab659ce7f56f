//! Qualitative preprocessing: what the graph alone says before any number is iterated.

use bit_set::BitSet;

use crate::mdp::graph::Predecessors;
use crate::mdp::model::{Mdp, MdpState};

/// The decision states that can reach an absorbing state of positive payoff under some policy,
/// in breadth-first order from those payoffs.
pub(super) fn can_reach_positive_payoff(mdp: &Mdp, predecessors: &Predecessors) -> Vec<MdpState> {
    let mut reached = BitSet::with_capacity(mdp.num_states());
    let mut queue: Vec<MdpState> = mdp
        .states()
        .filter(|&s| mdp.payoff(s).is_some_and(|payoff| payoff > 0.0))
        .collect();
    for &state in &queue {
        reached.insert(state.index());
    }
    let first_decision = queue.len();
    let mut head = 0;
    while head < queue.len() {
        let state = queue[head];
        head += 1;
        for &owner in predecessors.of(state) {
            if reached.insert(owner.index()) {
                queue.push(owner);
            }
        }
    }
    queue.drain(..first_decision);
    queue
}

/// The choices of MEC states whose successors all lie in the same MEC.
pub(super) fn internal_choices(mdp: &Mdp, component: &[Option<u32>]) -> BitSet {
    let mut internal = BitSet::new();
    for state in mdp.states() {
        if let Some(mec) = component[state.index()] {
            for choice in mdp.choices(state) {
                if mdp
                    .targets(choice)
                    .iter()
                    .all(|&t| component[t.index()] == Some(mec))
                {
                    internal.insert(choice.index());
                }
            }
        }
    }
    internal
}

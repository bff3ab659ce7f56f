//! What the graph and the intervals alone say: the states the adversary can keep away from every
//! positive payoff (worth exactly 0), and the robust attractor the policy makes progress in.
//!
//! Both are backward searches in which a choice *hits* a set when every distribution the
//! adversary may pick gives the set positive probability: an exact choice as soon as one of its
//! successors is in the set, an interval choice as soon as a successor in the set has a positive
//! lower bound or the upper bounds of its successors outside the set no longer add up to 1 (the
//! adversary must then put the rest inside). A state joins when one of its (eligible) choices
//! hits. Linear in the transitions: each choice keeps the sum of its outside upper bounds and
//! takes off a successor's when it joins.

use bit_set::BitSet;

use super::Intervals;
use crate::csr::Csr;
use crate::mdp::model::{ChoiceId, Mdp, MdpState};

/// For every state, the transitions into it: (choice, position among the choice's targets).
pub(super) struct Incoming(Csr<MdpState, (ChoiceId, u32)>);

impl Incoming {
    pub(super) fn new(mdp: &Mdp) -> Self {
        Incoming(Csr::group_from(mdp.num_states(), || {
            mdp.all_choices().flat_map(move |choice| {
                mdp.targets(choice)
                    .iter()
                    .enumerate()
                    .map(move |(i, &t)| (t, (choice, i as u32)))
            })
        }))
    }
}

/// The owner of every choice.
pub(super) fn owners(mdp: &Mdp) -> Vec<MdpState> {
    let mut owners = Vec::with_capacity(mdp.num_choices());
    for state in mdp.states() {
        owners.extend(std::iter::repeat_n(state, mdp.choices(state).len()));
    }
    owners
}

/// A backward search from `targets` over the choices `eligible` accepts (module
/// documentation). Returns, in the order they joined, the states that joined (targets first),
/// and per state the choice through which it joined (`ChoiceId::NONE` for the targets and the
/// states that did not join).
pub(super) fn attractor(
    mdp: &Mdp,
    intervals: &Intervals,
    incoming: &Incoming,
    owners: &[MdpState],
    targets: impl IntoIterator<Item = MdpState>,
    eligible: impl Fn(ChoiceId) -> bool,
) -> (Vec<MdpState>, Vec<ChoiceId>) {
    let mut joined = BitSet::with_capacity(mdp.num_states());
    let mut through = vec![ChoiceId::NONE; mdp.num_states()];
    // Per choice: the sum of the upper bounds of its successors not yet joined (interval
    // choices only), and whether it hit.
    let mut outside: Vec<f64> = vec![0.0; mdp.num_choices()];
    for choice in mdp.all_choices() {
        if let Some(bounds) = intervals.get(mdp, choice) {
            outside[choice.index()] = bounds.iter().map(|b| b[1]).sum();
        }
    }
    let mut hit = BitSet::with_capacity(mdp.num_choices());
    let mut order: Vec<MdpState> = Vec::new();
    for state in targets {
        if joined.insert(state.index()) {
            order.push(state);
        }
    }
    let mut head = 0;
    while head < order.len() {
        let state = order[head];
        head += 1;
        for &(choice, position) in incoming.0.row(state) {
            if hit.contains(choice.index()) || !eligible(choice) {
                continue;
            }
            let hits = match intervals.get(mdp, choice) {
                None => true,
                Some(bounds) => {
                    let [lower, upper] = bounds[position as usize];
                    outside[choice.index()] -= upper;
                    // A successor of upper bound 0 cannot be given mass, whatever the sums say.
                    upper > 0.0 && (lower > 0.0 || outside[choice.index()] < 1.0)
                }
            };
            if hits {
                hit.insert(choice.index());
                let owner = owners[choice.index()];
                if joined.insert(owner.index()) {
                    through[owner.index()] = choice;
                    order.push(owner);
                }
            }
        }
    }
    (order, through)
}

/// The decision states from which the robot can make a positive payoff reachable with positive
/// probability whatever the adversary does, in breadth-first order from those payoffs; every
/// other decision state is worth exactly 0 (the adversary can keep the run away from positive
/// payoffs forever).
pub(super) fn can_reach_positive_payoff(
    mdp: &Mdp,
    intervals: &Intervals,
    incoming: &Incoming,
    owners: &[MdpState],
) -> Vec<MdpState> {
    let targets = mdp
        .states()
        .filter(|&s| mdp.payoff(s).is_some_and(|payoff| payoff > 0.0));
    let (mut order, _) = attractor(mdp, intervals, incoming, owners, targets, |_| true);
    order.retain(|&s| !mdp.is_absorbing(s));
    order
}

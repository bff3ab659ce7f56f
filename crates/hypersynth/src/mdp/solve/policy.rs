//! Policy extraction from the lower bounds.
//!
//! # The policy
//! A choice is *eligible* in state `s` when its lower Q-value `f · Σ P · L` reaches `L(s)`: the
//! in-place update guarantees one always exists. If every decision state plays an eligible
//! choice and the run reaches, with probability 1, an absorbing state or a state with `L = 0`,
//! the policy's value is at least `L`, hence within ε of the optimum.
//! - g < 1: the eligible choice of largest lower Q-value, the lowest choice id among exact ties
//!   (contraction: eligibility alone suffices).
//! - g = 1: many choices tie (an opportunity that is eventually certain is worth its full
//!   payoff), and an argmax can loop forever inside an end component and collect 0. Sweeps go on
//!   after a component is certified until its lower bounds stop moving (`REFINEMENT`), and a
//!   choice is *eligible* when its lower Q-value is within a relative `TIE_TOLERANCE` (1e-12)
//!   of `L(s)`, or it is internal to the state's MEC (its exact value is the MEC's): exact ties
//!   are then recognised, and the policy loses at most that tolerance per expected move. Among
//!   the eligible choices the policy minimises the expected number of robot moves until the run
//!   is absorbed or reaches a state with `L = 0` (a stochastic shortest path restricted to the
//!   eligible choices; moves cost 1, instant choices 0). The minimal expected times are
//!   approximated from below, component by component of the eligible choices' graph (at most
//!   `max_iterations` sweeps each, until no time rises by more than `TIME_TOLERANCE`, 1e-3,
//!   relatively); each state plays the eligible choice of least expected time (within that
//!   tolerance), then largest lower Q-value, then lowest id. An approximation from below can
//!   favour a loop, so the result is checked: every state from which that policy does not reach
//!   absorption (or `L = 0`) with probability 1 plays instead its *ranked* choice: states are
//!   ranked by a backward breadth-first search from the absorbing states and those with `L = 0`
//!   (rank 0), a state gets rank k + 1 through an eligible choice that reaches rank ≤ k with
//!   positive probability, and that choice (largest lower Q-value, then lowest id) is its
//!   ranked choice.
//!   Every state with `L > 0` gets a rank (a closed unranked set would be an end component of
//!   the quotient), and from every state the resulting policy reaches absorption or `L = 0`
//!   with positive probability, hence with probability 1.

use bit_set::BitSet;

use super::expected_moves::{choice_time, eligible_components, expected_moves};
use super::{TIE_TOLERANCE, TIME_TOLERANCE, q_values};
use crate::csr::Csr;
use crate::mdp::graph::Predecessors;
use crate::mdp::model::{ChoiceId, Mdp, MdpState};
use crate::stage::{Meter, Tally};

/// The policy described in the module documentation. Progress: the states, once per phase
/// (one phase when g < 1; at g = 1 the ties, the ranking, the expected moves and the choice).
pub(super) fn choose_policy(
    mdp: &Mdp,
    g: f64,
    lower: &[f64],
    internal: &BitSet,
    max_sweeps: u32,
    meter: &mut Meter<'_>,
) -> Vec<ChoiceId> {
    let n = mdp.num_states() as u64;
    let q_lower = |choice: ChoiceId| q_values(mdp, choice, g, lower, lower).0;
    if g < 1.0 {
        meter.set_total(n);
        return mdp
            .states()
            .map(|state| {
                meter.advance(1);
                best_choice(mdp.choices(state), q_lower).unwrap_or(ChoiceId::NONE)
            })
            .collect();
    }
    meter.set_total(4 * n);
    // Whether each choice ties with its state's best. Lower Q-values are recomputed where they
    // are needed (a few products per choice, a handful of times) rather than kept: 8 bytes per
    // choice at the stage's peak.
    let mut ties = BitSet::with_capacity(mdp.num_choices());
    for state in mdp.states() {
        let value = lower[state.index()];
        for choice in mdp.choices(state) {
            if internal.contains(choice.index())
                || q_lower(choice) >= value - TIE_TOLERANCE * value.max(1.0)
            {
                ties.insert(choice.index());
            }
        }
        meter.advance(1);
    }
    let eligible = |choice: ChoiceId| ties.contains(choice.index());
    let is_goal = |state: MdpState| mdp.is_absorbing(state) || lower[state.index()] == 0.0;
    // The ranking and the expected moves' components search the same graph, the eligible
    // choices' predecessor lists: built once, searched side by side.
    let predecessors = Predecessors::new(mdp, eligible);
    let mut counted = BitSet::with_capacity(mdp.num_states());
    for state in mdp.states().filter(|&s| !is_goal(s)) {
        counted.insert(state.index());
    }
    let ((ranked, order), components) = meter.join(
        |tally| ranked_policy(mdp, &predecessors, &is_goal, &eligible, &q_lower, tally),
        |_| eligible_components(&predecessors, &counted),
    );
    drop(predecessors);
    meter.set(2 * n);
    let times = expected_moves(
        mdp, &counted, &order, components, &eligible, max_sweeps, meter,
    );
    drop(counted);
    meter.set(3 * n);
    let time_of = |choice: ChoiceId| choice_time(mdp, choice, &times);
    // The eligible choice of least time, then largest lower Q-value, then lowest id.
    let by_time = |state: MdpState| {
        let mut best: Option<(ChoiceId, f64, f64)> = None;
        for choice in mdp.choices(state).filter(|&c| eligible(c)) {
            let (time, q) = (time_of(choice), q_lower(choice));
            let better = match best {
                None => true,
                Some((_, best_time, best_q)) => {
                    let tolerance = TIME_TOLERANCE * best_time.max(1.0);
                    time < best_time - tolerance || (time <= best_time + tolerance && q > best_q)
                }
            };
            if better {
                best = Some((choice, time, q));
            }
        }
        best.map_or(ChoiceId::NONE, |(choice, _, _)| choice)
    };
    // Each state's choice is its own: chunks of the order are chosen on the pool's threads.
    let chunk = order
        .len()
        .div_ceil(4 * rayon::current_num_threads().max(1))
        .max(CHOICE_CHUNK);
    let jobs = order
        .chunks(chunk)
        .map(|states| {
            let by_time = &by_time;
            move |tally: &Tally| {
                let chosen: Vec<ChoiceId> = states.iter().map(|&s| by_time(s)).collect();
                tally.add(states.len() as u64);
                chosen
            }
        })
        .collect();
    let mut policy = vec![ChoiceId::NONE; mdp.num_states()];
    for (states, chosen) in order.chunks(chunk).zip(meter.parallel(jobs)) {
        for (&state, choice) in states.iter().zip(chosen) {
            policy[state.index()] = choice;
        }
    }
    for state in improper_states(mdp, &policy, &order, &is_goal) {
        policy[state.index()] = ranked[state.index()];
    }
    // Goal states that are decision states (value 0) play the plain argmax: nothing is at stake.
    for state in mdp.states() {
        if policy[state.index()].is_none() && !mdp.is_absorbing(state) {
            policy[state.index()] =
                best_choice(mdp.choices(state), q_lower).unwrap_or(ChoiceId::NONE);
        }
    }
    meter.set(4 * n);
    policy
}

/// The ranked choice of every non-goal state (module documentation; `ChoiceId::NONE`
/// elsewhere) and the non-goal states in increasing rank order, searched on the eligible
/// choices' predecessor lists (only eligible choices rank a state).
fn ranked_policy(
    mdp: &Mdp,
    predecessors: &Predecessors,
    is_goal: &impl Fn(MdpState) -> bool,
    eligible: &impl Fn(ChoiceId) -> bool,
    q_lower: &impl Fn(ChoiceId) -> f64,
    tally: &Tally,
) -> (Vec<ChoiceId>, Vec<MdpState>) {
    let mut policy = vec![ChoiceId::NONE; mdp.num_states()];
    let mut ranked = BitSet::with_capacity(mdp.num_states());
    let mut frontier: Vec<MdpState> = mdp.states().filter(|&s| is_goal(s)).collect();
    for &state in &frontier {
        ranked.insert(state.index());
    }
    // Every non-goal state gets a rank (module documentation): the order at its size, not
    // grown by doubling while the component search runs beside it.
    let mut order = Vec::with_capacity(mdp.num_states() - frontier.len());
    let mut candidates = Vec::new();
    let mut is_candidate = BitSet::with_capacity(mdp.num_states());
    while !frontier.is_empty() {
        candidates.clear();
        for &target in &frontier {
            for owner in predecessors.of(target) {
                if !ranked.contains(owner.index()) && is_candidate.insert(owner.index()) {
                    candidates.push(owner);
                }
            }
        }
        // Choose before ranking any candidate, so that all progress goes to ranks ≤ k.
        for &state in &candidates {
            let progressing = mdp.choices(state).filter(|&choice| {
                eligible(choice)
                    && mdp
                        .targets(choice)
                        .iter()
                        .any(|&t| ranked.contains(t.index()))
            });
            policy[state.index()] = best_choice(progressing, q_lower).unwrap_or(ChoiceId::NONE);
        }
        for &state in &candidates {
            ranked.insert(state.index());
        }
        order.extend_from_slice(&candidates);
        tally.add(candidates.len() as u64);
        std::mem::swap(&mut frontier, &mut candidates);
    }
    (policy, order)
}

/// The non-goal states from which `policy` does not reach a goal state with probability 1:
/// those that cannot reach one, and those that can reach, with positive probability, a state
/// that cannot. Usually there are none, and a cheap pass shows it: in the order of `order`
/// (the ranking's, in which most states' chosen choices lead to a state before them), a state
/// reaches a goal if a successor under the policy is a goal or was found to reach one; the
/// states this leaves (a few per hundred on gridworlds) are searched backwards among
/// themselves from those with a successor found. If every state reaches a goal, none can
/// reach a state that does not; otherwise the chain is searched as a whole
/// ([`improper_states_by_search`]).
fn improper_states(
    mdp: &Mdp,
    policy: &[ChoiceId],
    order: &[MdpState],
    is_goal: &impl Fn(MdpState) -> bool,
) -> Vec<MdpState> {
    let successors = |state: MdpState| {
        policy[state.index()]
            .to_option()
            .into_iter()
            .flat_map(|choice| mdp.targets(choice))
            .copied()
    };
    let mut reaches = BitSet::with_capacity(mdp.num_states());
    for state in mdp.states().filter(|&s| is_goal(s)) {
        reaches.insert(state.index());
    }
    for &state in order {
        if successors(state).any(|t| reaches.contains(t.index())) {
            reaches.insert(state.index());
        }
    }
    // The others, by increasing id (positions found by binary search), with their
    // successors among them reversed.
    let rest: Vec<MdpState> = mdp
        .states()
        .filter(|&s| !reaches.contains(s.index()))
        .collect();
    let place = |state: MdpState| rest.binary_search(&state).ok();
    let sources: Csr<u32, u32> = Csr::group_from(rest.len(), || {
        rest.iter().enumerate().flat_map(move |(i, &state)| {
            successors(state).filter_map(move |t| place(t).map(|j| (j as u32, i as u32)))
        })
    });
    let mut queue: Vec<u32> = Vec::new();
    for (i, &state) in rest.iter().enumerate() {
        if successors(state).any(|t| reaches.contains(t.index())) {
            reaches.insert(state.index());
            queue.push(i as u32);
        }
    }
    while let Some(i) = queue.pop() {
        for &source in sources.row(i) {
            if reaches.insert(rest[source as usize].index()) {
                queue.push(source);
            }
        }
    }
    if rest.iter().all(|s| reaches.contains(s.index())) {
        return Vec::new();
    }
    improper_states_by_search(mdp, policy, is_goal)
}

/// [`improper_states`] by two backward searches over the policy's whole chain (which ends at
/// the goals): from the goals (the states that can reach one), then from the states that
/// cannot.
fn improper_states_by_search(
    mdp: &Mdp,
    policy: &[ChoiceId],
    is_goal: &impl Fn(MdpState) -> bool,
) -> Vec<MdpState> {
    let n = mdp.num_states();
    // The policy's chain, reversed (grouped straight from the policy: no forward copy), ending
    // at the goals: a run that reaches one has reached one, whatever comes after.
    let sources: Csr<MdpState, MdpState> = Csr::group(
        n,
        mdp.states().filter(|&s| !is_goal(s)).flat_map(|state| {
            policy[state.index()]
                .to_option()
                .into_iter()
                .flat_map(|choice| mdp.targets(choice))
                .map(move |&target| (target, state))
        }),
    );
    let backward = |seeds: Vec<MdpState>, mut marked: BitSet| {
        let mut queue = seeds;
        while let Some(state) = queue.pop() {
            for &source in sources.row(state) {
                if marked.insert(source.index()) {
                    queue.push(source);
                }
            }
        }
        marked
    };
    let goals: Vec<MdpState> = mdp.states().filter(|&s| is_goal(s)).collect();
    let mut can_reach = BitSet::with_capacity(n);
    for &g in &goals {
        can_reach.insert(g.index());
    }
    let can_reach = backward(goals, can_reach);
    let stranded: Vec<MdpState> = mdp
        .states()
        .filter(|&s| !can_reach.contains(s.index()))
        .collect();
    let mut bad = BitSet::with_capacity(n);
    for &s in &stranded {
        bad.insert(s.index());
    }
    let bad = backward(stranded, bad);
    bad.iter()
        .map(MdpState::new)
        .filter(|&s| !is_goal(s))
        .collect()
}

/// The fewest states of the order a parallel job of the policy's choice takes (the jobs' tallies
/// are added once per job).
const CHOICE_CHUNK: usize = 1 << 14;

/// The choice of largest `value`, the first among exact ties (the lowest id, or position in
/// the implicit engine's `implicit/policy.rs`); `None` if there is none.
pub(crate) fn best_choice<C: Copy>(
    choices: impl Iterator<Item = C>,
    value: impl Fn(C) -> f64,
) -> Option<C> {
    let mut best: Option<(C, f64)> = None;
    for choice in choices {
        let q = value(choice);
        if best.is_none_or(|(_, best_q)| q > best_q) {
            best = Some((choice, q));
        }
    }
    best.map(|(choice, _)| choice)
}

#[cfg(test)]
mod tests {
    use rand_core::RngCore;

    use super::*;
    use crate::mdp::testing::{random_mdp_with_instant_choices, rng};

    /// The improper states by plain fixed points: the states that can reach a goal (grown until
    /// stable), then the non-goal states that cannot or can reach one that cannot (grown until
    /// stable).
    fn improper_by_fixed_points(
        mdp: &Mdp,
        policy: &[ChoiceId],
        is_goal: &impl Fn(MdpState) -> bool,
    ) -> Vec<MdpState> {
        let successors = |s: MdpState| match policy[s.index()].to_option() {
            Some(choice) => mdp.targets(choice).to_vec(),
            None => Vec::new(),
        };
        let mut reaches: Vec<bool> = mdp.states().map(is_goal).collect();
        loop {
            let grown: Vec<bool> = mdp
                .states()
                .map(|s| reaches[s.index()] || successors(s).iter().any(|t| reaches[t.index()]))
                .collect();
            if grown == reaches {
                break;
            }
            reaches = grown;
        }
        let mut bad: Vec<bool> = mdp
            .states()
            .map(|s| !is_goal(s) && !reaches[s.index()])
            .collect();
        loop {
            let grown: Vec<bool> = mdp
                .states()
                .map(|s| {
                    bad[s.index()] || (!is_goal(s) && successors(s).iter().any(|t| bad[t.index()]))
                })
                .collect();
            if grown == bad {
                break;
            }
            bad = grown;
        }
        mdp.states().filter(|s| bad[s.index()]).collect()
    }

    #[test]
    fn improper_states_match_plain_fixed_points() {
        // Random policies (a state without a choice now and then) and goals; the order lists
        // the non-goal states in a random order, some left out, so that the first pass finds
        // some, the search among the others more, and the whole chain is searched when some
        // cannot reach a goal.
        let mut rng = rng(28);
        let (mut none, mut some) = (0, 0);
        for instance in 0..400 {
            let mdp = random_mdp_with_instant_choices(&mut rng, 40);
            let goals: Vec<bool> = mdp
                .states()
                .map(|s| mdp.is_absorbing(s) || rng.next_u32().is_multiple_of(6))
                .collect();
            let is_goal = |s: MdpState| goals[s.index()];
            let policy: Vec<ChoiceId> = mdp
                .states()
                .map(|s| {
                    let choices = mdp.choices(s);
                    if choices.is_empty() || rng.next_u32().is_multiple_of(12) {
                        return ChoiceId::NONE;
                    }
                    let pick = rng.next_u32() as usize % choices.len();
                    { choices }.nth(pick).expect("a choice")
                })
                .collect();
            let mut keyed: Vec<(u32, MdpState)> = mdp
                .states()
                .filter(|&s| !is_goal(s))
                .map(|s| (rng.next_u32(), s))
                .filter(|&(key, _)| !key.is_multiple_of(10))
                .collect();
            keyed.sort_unstable();
            let order: Vec<MdpState> = keyed.into_iter().map(|(_, s)| s).collect();
            let mut found = improper_states(&mdp, &policy, &order, &is_goal);
            found.sort_unstable();
            let expected = improper_by_fixed_points(&mdp, &policy, &is_goal);
            assert_eq!(found, expected, "instance {instance}: {mdp:?}");
            if expected.is_empty() {
                none += 1;
            } else {
                some += 1;
            }
        }
        assert!(
            none > 50 && some > 50,
            "{none} without, {some} with improper states"
        );
    }
}

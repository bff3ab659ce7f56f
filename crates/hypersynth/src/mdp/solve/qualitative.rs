//! Qualitative preprocessing: what the graph alone says before any number is iterated.
//!
//! # Payoff levels
//! The distinct positive payoffs, in decreasing order, are the *levels*; the level of a state is
//! the largest payoff it can reach under some policy (an absorbing state's is its own payoff).
//! A state of no level is worth exactly 0. A backward search from the payoffs, one level after
//! the other (highest first, every state keeping the first level that reaches it), finds every
//! state's level and, counting only moves (instant choices cost nothing), the fewest robot moves
//! `d(s)` it needs to reach a payoff of its level. Hence `value(s) ≤ p · g^d(s)` for the payoff
//! `p` of its level, and `≤` the next level's payoff for anything else it can reach: the
//! iteration's initial upper bound, and the order in which the states are laid out (level by
//! level, by distance within a level: the order in which the values flow at g < 1).
//!
//! # Settled states (g = 1)
//! A state of level `p` is worth exactly `p` at g = 1 if and only if some policy reaches a
//! payoff `p` from it with probability 1: it can reach nothing higher, and anything less than
//! probability 1 loses value. Its successors under such a policy are of the same level, so these
//! states are, per level, the almost-sure reachability set of that level's payoffs inside the
//! sub-MDP of that level's states (Storm's `prob1E`), computed for all levels at once as the
//! greatest fixed point: start from every state of a level; repeatedly keep only those from
//! which a backward search from the payoffs, through choices whose successors are all kept
//! states of the same level and one of which is already found, finds them. Settled states are
//! fixed to their level's payoff before any iteration, like absorbing states.

use std::collections::VecDeque;

use bit_set::BitSet;

use crate::index::Id;
use crate::mdp::graph::Predecessors;
use crate::mdp::model::{Mdp, MdpState};

/// The payoff levels of every state (module documentation).
pub(super) struct Levels {
    /// The distinct positive payoffs, largest first.
    pub(super) payoffs: Vec<f64>,
    /// Per state, the index of its level in `payoffs`; `u32::NONE` for a state that reaches no
    /// positive payoff.
    pub(super) level: Vec<u32>,
    /// Per state of a level, the fewest moves to a payoff of its level (0 for the payoffs
    /// themselves); unspecified for the others.
    pub(super) distance: Vec<u32>,
    /// The decision states of a level, level by level, by increasing distance within a level.
    pub(super) order: Vec<MdpState>,
}

impl Levels {
    /// The levels of `mdp`'s states, found through `predecessors` (over all choices).
    pub(super) fn new(mdp: &Mdp, predecessors: &Predecessors) -> Levels {
        let n = mdp.num_states();
        let mut payoffs: Vec<f64> = mdp
            .states()
            .filter_map(|s| mdp.payoff(s))
            .filter(|&payoff| payoff > 0.0)
            .collect();
        payoffs.sort_unstable_by(|a, b| b.total_cmp(a));
        payoffs.dedup();
        let mut level = vec![u32::NONE; n];
        let mut distance = vec![u32::NONE; n];
        let mut order = Vec::new();
        let mut seeds: Vec<Vec<MdpState>> = vec![Vec::new(); payoffs.len()];
        for state in mdp.states() {
            if let Some(payoff) = mdp.payoff(state).filter(|&p| p > 0.0) {
                let index = payoffs
                    .binary_search_by(|p| payoff.total_cmp(p))
                    .expect("every positive payoff is a level");
                seeds[index].push(state);
            }
        }
        // A 0-1 breadth-first search per level: instant steps at the front of the queue, moves
        // at the back. A state is final (and placed in `order`) when it leaves the queue with
        // its distance; it may enter twice (first through a move, then through an instant
        // choice), and its stale entry is skipped.
        let mut queue: VecDeque<MdpState> = VecDeque::new();
        let mut done = BitSet::with_capacity(n);
        for (index, seeds) in seeds.into_iter().enumerate() {
            for state in seeds {
                level[state.index()] = index as u32;
                distance[state.index()] = 0;
                queue.push_back(state);
            }
            while let Some(target) = queue.pop_front() {
                if !done.insert(target.index()) {
                    continue;
                }
                if !mdp.is_absorbing(target) {
                    order.push(target);
                }
                let d = distance[target.index()];
                for (owner, instant) in predecessors.of_tagged(target) {
                    let o = owner.index();
                    if done.contains(o) || (!level[o].is_none() && level[o] != index as u32) {
                        continue;
                    }
                    let instant = instant.unwrap_or_else(|| instant_step(mdp, owner, target));
                    let cost = u32::from(!instant);
                    if level[o].is_none() || d + cost < distance[o] {
                        level[o] = index as u32;
                        distance[o] = d + cost;
                        if cost == 0 {
                            queue.push_front(owner);
                        } else {
                            queue.push_back(owner);
                        }
                    }
                }
            }
        }
        Levels {
            payoffs,
            level,
            distance,
            order,
        }
    }

    /// The payoff of `state`'s level, 0 if it has none.
    pub(super) fn payoff(&self, state: MdpState) -> f64 {
        match self.level[state.index()] {
            level if level.is_none() => 0.0,
            level => self.payoffs[level as usize],
        }
    }

    /// An upper bound on the value of `state` (module documentation): `p · g^d` for the payoff
    /// `p` of its level and its distance `d`, or the next level's payoff if that is larger.
    /// Below g = 1 the bound is raised by a relative 1e-12, so that the rounding of the iterated
    /// values can never cross it.
    pub(super) fn upper_bound(&self, state: MdpState, g: f64) -> f64 {
        let level = self.level[state.index()];
        if level.is_none() {
            return 0.0;
        }
        let payoff = self.payoffs[level as usize];
        if g == 1.0 {
            return payoff;
        }
        let next = self.payoffs.get(level as usize + 1).copied().unwrap_or(0.0);
        let distance = self.distance[state.index()].min(i32::MAX as u32) as i32;
        (payoff * g.powi(distance) * (1.0 + 1e-12)).max(next)
    }

    /// The decision states worth exactly their level's payoff at g = 1 (module documentation).
    pub(super) fn settled(&self, mdp: &Mdp, predecessors: &Predecessors) -> BitSet {
        let n = mdp.num_states();
        // The states still kept: those of a level, payoffs included.
        let mut kept = BitSet::with_capacity(n);
        let mut count = 0usize;
        for state in mdp.states() {
            if !self.level[state.index()].is_none() {
                kept.insert(state.index());
                count += 1;
            }
        }
        let seeds: Vec<MdpState> = mdp
            .states()
            .filter(|&s| mdp.is_absorbing(s) && kept.contains(s.index()))
            .collect();
        let mut staying = BitSet::with_capacity(mdp.num_choices());
        loop {
            // The choices of kept states whose successors are all kept, at their owner's level:
            // marked once per round (one pass over the transitions) instead of checked at each
            // visit of their owner (the search visits an owner once per found successor).
            staying.make_empty();
            for state in mdp.states().filter(|&s| kept.contains(s.index())) {
                let level = self.level[state.index()];
                for choice in mdp.choices(state) {
                    let stays = mdp
                        .targets(choice)
                        .iter()
                        .all(|&t| kept.contains(t.index()) && self.level[t.index()] == level);
                    if stays {
                        staying.insert(choice.index());
                    }
                }
            }
            let mut found = BitSet::with_capacity(n);
            let mut stack = seeds.clone();
            for &seed in &seeds {
                found.insert(seed.index());
            }
            let mut found_count = seeds.len();
            while let Some(target) = stack.pop() {
                for owner in predecessors.of(target) {
                    let o = owner.index();
                    if found.contains(o) || !kept.contains(o) {
                        continue;
                    }
                    // An owner progresses through a staying choice with a found successor; the
                    // search reaches it from each of them, so `target` is the one to look for.
                    let progresses = mdp.choices(owner).any(|choice| {
                        staying.contains(choice.index())
                            && mdp.targets(choice).binary_search(&target).is_ok()
                    });
                    if progresses {
                        found.insert(o);
                        found_count += 1;
                        stack.push(owner);
                    }
                }
            }
            if found_count == count {
                for &seed in &seeds {
                    found.remove(seed.index());
                }
                return found;
            }
            kept = found;
            count = found_count;
        }
    }
}

/// Whether `owner` reaches `target` through an instant choice (a step that costs no move).
fn instant_step(mdp: &Mdp, owner: MdpState, target: MdpState) -> bool {
    mdp.choices(owner)
        .any(|choice| mdp.is_instant(choice) && mdp.targets(choice).binary_search(&target).is_ok())
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mdp::testing::{
        Spec::{Absorb, Decide},
        mdp_from, ms, optimal_values_by_enumeration, random_mdp, random_mdp_with_instant_choices,
        rng,
    };

    fn levels_of(mdp: &Mdp) -> (Levels, BitSet) {
        let predecessors = Predecessors::new(mdp, |_| true);
        let levels = Levels::new(mdp, &predecessors);
        let settled = levels.settled(mdp, &predecessors);
        (levels, settled)
    }

    /// The largest payoff reachable from each state, by iterating `M(s) = max M(t)` over all
    /// successors from the payoffs until nothing changes.
    fn naive_reachable_payoff(mdp: &Mdp) -> Vec<f64> {
        let mut best: Vec<f64> = mdp.states().map(|s| mdp.payoff(s).unwrap_or(0.0)).collect();
        loop {
            let mut changed = false;
            for s in mdp.states() {
                for choice in mdp.choices(s) {
                    for &t in mdp.targets(choice) {
                        if best[t.index()] > best[s.index()] {
                            best[s.index()] = best[t.index()];
                            changed = true;
                        }
                    }
                }
            }
            if !changed {
                return best;
            }
        }
    }

    /// The fewest moves from each state to an absorbing state paying `reachable[s]`, by
    /// Bellman–Ford over the choices (a move costs 1, an instant choice 0).
    fn naive_distance(mdp: &Mdp, reachable: &[f64]) -> Vec<u32> {
        let mut distance: Vec<u32> = mdp
            .states()
            .map(|s| {
                if mdp.payoff(s).is_some_and(|p| p > 0.0) {
                    0
                } else {
                    u32::MAX
                }
            })
            .collect();
        for _ in 0..mdp.num_states() {
            for s in mdp.states() {
                for choice in mdp.choices(s) {
                    let cost = u32::from(!mdp.is_instant(choice));
                    for &t in mdp.targets(choice) {
                        if reachable[t.index()] == reachable[s.index()]
                            && distance[t.index()] != u32::MAX
                        {
                            distance[s.index()] =
                                distance[s.index()].min(distance[t.index()] + cost);
                        }
                    }
                }
            }
        }
        distance
    }

    /// Whether some policy reaches an absorbing state paying at least `payoff` with probability
    /// 1, per state: the textbook greatest fixed point, with a full scan of every state per
    /// step and no predecessor lists.
    fn naive_almost_sure(mdp: &Mdp, payoff: f64) -> Vec<bool> {
        let target = |s: MdpState| mdp.payoff(s).is_some_and(|p| p >= payoff);
        let mut kept = vec![true; mdp.num_states()];
        loop {
            let mut found: Vec<bool> = mdp.states().map(target).collect();
            loop {
                let mut changed = false;
                for s in mdp.states() {
                    if found[s.index()] || !kept[s.index()] {
                        continue;
                    }
                    if mdp.choices(s).any(|c| {
                        let targets = mdp.targets(c);
                        targets.iter().all(|t| kept[t.index()])
                            && targets.iter().any(|t| found[t.index()])
                    }) {
                        found[s.index()] = true;
                        changed = true;
                    }
                }
                if !changed {
                    break;
                }
            }
            if found == kept {
                return found;
            }
            kept = found;
        }
    }

    #[test]
    fn levels_and_distances_match_a_naive_computation() {
        let mut rng = rng(25);
        for instance in 0..400 {
            let mdp = if instance % 2 == 0 {
                random_mdp(&mut rng, 10)
            } else {
                random_mdp_with_instant_choices(&mut rng, 10)
            };
            let reachable = naive_reachable_payoff(&mdp);
            let distance = naive_distance(&mdp, &reachable);
            // With the predecessor lists' instant bits, and without them (the look-up through
            // the owner's choices that a model of 2^31 states or more falls back on).
            for tagged in [true, false] {
                let predecessors = Predecessors::with_tags(&mdp, |_| true, tagged);
                let levels = Levels::new(&mdp, &predecessors);
                check_levels(&mdp, &levels, &reachable, &distance, instance);
            }
        }
    }

    /// Asserts that `levels` has the payoff levels `reachable`, the distances `distance` and
    /// the order they imply (naive computations).
    fn check_levels(
        mdp: &Mdp,
        levels: &Levels,
        reachable: &[f64],
        distance: &[u32],
        instance: usize,
    ) {
        for s in mdp.states() {
            let context = format!("instance {instance}, state {s}: {mdp:?}");
            assert_eq!(levels.payoff(s), reachable[s.index()], "{context}");
            if reachable[s.index()] > 0.0 {
                assert_eq!(levels.distance[s.index()], distance[s.index()], "{context}");
            }
        }
        // The order: the decision states of a level, by level, then by distance.
        let mut expected: Vec<MdpState> = mdp
            .states()
            .filter(|&s| !mdp.is_absorbing(s) && reachable[s.index()] > 0.0)
            .collect();
        expected.sort_by(|a, b| {
            (reachable[b.index()].total_cmp(&reachable[a.index()]))
                .then(distance[a.index()].cmp(&distance[b.index()]))
        });
        let key = |s: &MdpState| (reachable[s.index()].to_bits(), distance[s.index()]);
        assert_eq!(
            levels.order.iter().map(key).collect::<Vec<_>>(),
            expected.iter().map(key).collect::<Vec<_>>(),
            "instance {instance}"
        );
        let mut sorted = levels.order.clone();
        sorted.sort_unstable();
        expected.sort_unstable();
        assert_eq!(sorted, expected, "instance {instance}");
    }

    #[test]
    fn settled_states_match_a_naive_almost_sure_reachability_and_the_exact_values() {
        let mut rng = rng(26);
        let mut settled_somewhere = 0;
        for instance in 0..400 {
            let mdp = if instance % 2 == 0 {
                random_mdp(&mut rng, 8)
            } else {
                random_mdp_with_instant_choices(&mut rng, 8)
            };
            let (_, settled) = levels_of(&mdp);
            let reachable = naive_reachable_payoff(&mdp);
            let optimal = optimal_values_by_enumeration(&mdp, 1.0);
            for s in mdp.states() {
                let context = format!("instance {instance}, state {s}: {mdp:?}");
                let level = reachable[s.index()];
                let naive = !mdp.is_absorbing(s)
                    && level > 0.0
                    && naive_almost_sure(&mdp, level)[s.index()];
                assert_eq!(settled.contains(s.index()), naive, "{context}");
                // Settled exactly when the optimal value is the largest payoff within reach.
                let worth_its_level = !mdp.is_absorbing(s)
                    && level > 0.0
                    && (optimal[s.index()] - level).abs() <= 1e-9 * level;
                assert_eq!(settled.contains(s.index()), worth_its_level, "{context}");
                settled_somewhere += usize::from(naive);
            }
        }
        assert!(settled_somewhere > 100, "{settled_somewhere}");
    }

    #[test]
    fn upper_bounds_hold_the_optimal_values() {
        let mut rng = rng(27);
        for instance in 0..300 {
            let mdp = random_mdp_with_instant_choices(&mut rng, 8);
            let (levels, _) = levels_of(&mdp);
            for g in [1.0, 0.9, 0.5] {
                let optimal = optimal_values_by_enumeration(&mdp, g);
                for s in mdp.states() {
                    let bound = levels.upper_bound(s, g);
                    // The enumeration's own rounding may exceed an exact bound by an ulp.
                    assert!(
                        optimal[s.index()] <= bound * (1.0 + 1e-12),
                        "instance {instance}, g = {g}, state {s}: {} > {bound}: {mdp:?}",
                        optimal[s.index()]
                    );
                }
            }
        }
    }

    #[test]
    fn a_state_settles_only_through_choices_that_stay_at_its_level() {
        // 0: `a` reaches 3 (payoff 5) or 1 half and half; 1: `b` back to 0, or `c` to 2
        // (payoff 5 too) or 4 (payoff 0). Retrying a and b reaches payoff 5 surely: 0 and 1
        // are settled at 5. 5 can only try c-like luck: half 5, half 0: not settled (2.5).
        let mdp = mdp_from(&[
            Decide(&[("a", &[(3, 0.5), (1, 0.5)])]),
            Decide(&[("b", &[(0, 1.0)]), ("c", &[(2, 0.5), (4, 0.5)])]),
            Absorb(5.0),
            Absorb(5.0),
            Absorb(0.0),
            Decide(&[("d", &[(2, 0.5), (4, 0.5)]), ("e", &[(6, 1.0)])]),
            Absorb(1.0),
        ]);
        let (levels, settled) = levels_of(&mdp);
        assert_eq!(settled.iter().collect::<Vec<_>>(), [0, 1]);
        assert_eq!(levels.payoffs, [5.0, 1.0]);
        assert_eq!(levels.payoff(ms(5)), 5.0);
        assert_eq!(levels.payoff(ms(4)), 0.0);
        // Distances count moves: 0 → 3 is one move, 1 → 0 → 3 two (or 1 → 2 one).
        assert_eq!(levels.distance[0], 1);
        assert_eq!(levels.distance[1], 1);
    }
}

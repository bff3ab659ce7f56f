//! What the graph alone says about the values, before any sweep (docs/semantics.md §6.5 step 1,
//! §13.2): the highest payoff each live state can reach, and at `g = 1` the states that reach it
//! with probability 1 under some policy, whose value is exactly that payoff.
//!
//! *Reach*: backward breadth-first searches over the MDP's moves (allowed choices, adversary
//! moves of positive probability), one wave per payoff level from the highest: a wave starts
//! from the absorbing states of its payoff and the decision nodes whose `stop` pays it, and
//! crosses only the states no higher wave has reached. A live state no wave reaches is worth 0;
//! one first reached by the wave of payoff `p` is worth at most `p` (payoffs are never negative
//! and `g ≤ 1`), its upper bound's start.
//!
//! *Settled* (`g = 1`): among the live states whose highest reachable payoff is `p`, those from
//! which some policy reaches a payoff of exactly `p` with probability 1 (Storm's `prob1E`, the
//! stored solver's `qualitative.rs`): the greatest set `X` such that every state of `X` reaches
//! a target of `X` through choices whose outcomes all stay in `X`, found by shrinking `X` to
//! the states that reach its targets so, until it no longer shrinks. Their value is `p`
//! exactly: at least `p` (the policy collects it) and at most `p` (nothing higher is
//! reachable). A state of `X` never needs a state of another level: anything it can reach
//! reaches no more than `p`, and anything that reaches a payoff above `p` is not in `X`.
//!
//! Each wave and each search of a settled set goes one level at a time, the level's
//! predecessors tried on all threads (`frontier.rs`): the same sets on any number of threads.
//!
//! Memory: a bit per state for the states reached and one for each of a wave's two levels;
//! the live states reached (a bit per state) and a level per live state (one byte);
//! while the settled states are searched, two more bits per state.

use bit_set::BitSet;

use super::frontier::{Bits, search};
use super::mdp::{Choice, Distribution, Kind, Model};
use super::moves::Moves;

/// The highest payoff each live state can reach.
pub(crate) struct Reach {
    /// The live states that can reach a positive payoff.
    pub(crate) reached: BitSet,
    /// By live index: the level of the highest payoff reachable (0: none).
    pub(crate) level: Vec<u8>,
}

/// The level `h` pays at once when it is a target (an absorbing state, or a decision node
/// with `stop`), 0 otherwise.
fn target_level<M: Moves>(model: &Model<'_, '_, M>, h: u32) -> u8 {
    match model.kind(h) {
        Kind::Absorbing(_) | Kind::Decision => model.level(h),
        Kind::Chance => 0,
    }
}

/// Whether `p` (live) can move to `t`: a decision node through an allowed move, a chance node
/// with positive probability.
fn moves_to<M: Moves>(
    model: &Model<'_, '_, M>,
    p: u32,
    t: u32,
    distribution: &mut Distribution,
) -> bool {
    if model.kind(p) == Kind::Chance {
        model.distribution(p, distribution);
        return distribution.iter().any(|(target, _)| target == t);
    }
    let mut found = false;
    model.choices(p, |c| {
        found |= matches!(c, Choice::Move { target, .. } if target == t);
    });
    found
}

/// The highest payoff every live state (of `live`, numbered by `index` below `count`) can
/// reach.
pub(crate) fn reach<M: Moves>(
    model: &Model<'_, '_, M>,
    live: &BitSet,
    index: impl Fn(u32) -> usize,
    count: usize,
) -> Reach {
    let n = model.space().num_states() as u32;
    let mut result = Reach {
        reached: BitSet::with_capacity(n as usize),
        level: vec![0; count],
    };
    // Each level's search, level by level on all threads (`frontier.rs`), passes by the states
    // a higher level reached.
    let claims = Bits::new(n as usize);
    for level in (1..model.num_levels() as u8).rev() {
        let mut first = Bits::from_fn(n as usize, || (), |h, _| target_level(model, h) == level);
        claims.claim_from(&mut first);
        search(
            model.space(),
            first,
            &claims,
            Distribution::default,
            |p, t, distribution| live.contains(p as usize) && moves_to(model, p, t, distribution),
            |found, _| {
                for t in found.iter().filter(|&t| live.contains(t as usize)) {
                    result.reached.insert(t as usize);
                    result.level[index(t)] = level;
                }
            },
        );
    }
    result
}

/// The live states whose value is exactly the highest payoff they can reach, at `g = 1`: see
/// the module documentation.
pub(crate) fn settled<M: Moves>(
    model: &Model<'_, '_, M>,
    live: &BitSet,
    index: impl Fn(u32) -> usize,
    reach: &Reach,
) -> BitSet {
    let n = model.space().num_states() as u32;
    let mut settled = BitSet::with_capacity(n as usize);
    for level in 1..model.num_levels() as u8 {
        let of_level = |h: u32| {
            if live.contains(h as usize) {
                reach.level[index(h)] == level
            } else {
                target_level(model, h) == level
            }
        };
        // The candidates, and among them the targets (which never leave).
        let mut candidates: BitSet = (0..n)
            .filter(|&h| of_level(h))
            .map(|h| h as usize)
            .collect();
        let targets: BitSet = candidates
            .iter()
            .filter(|&h| target_level(model, h as u32) == level)
            .collect();
        loop {
            // The candidates that reach the targets while staying among the candidates.
            let (claims, first) = (Bits::new(n as usize), Bits::new(n as usize));
            for h in targets.iter() {
                first.insert(h as u32);
                claims.insert(h as u32);
            }
            let mut kept = BitSet::with_capacity(n as usize);
            search(
                model.space(),
                first,
                &claims,
                Distribution::default,
                |p, t, distribution| {
                    candidates.contains(p as usize)
                        && moves_to(model, p, t, distribution)
                        // A chance node's one choice must stay among the candidates.
                        && (model.kind(p) != Kind::Chance
                            || distribution
                                .iter()
                                .all(|(u, _)| candidates.contains(u as usize)))
                },
                |found, _| {
                    for p in found.iter() {
                        kept.insert(p as usize);
                    }
                },
            );
            if kept.count() == candidates.count() {
                break;
            }
            candidates = kept;
        }
        candidates.intersect_with(live);
        settled.union_with(&candidates);
    }
    settled
}

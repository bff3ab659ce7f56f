//! Certified values over the index space (docs/semantics.md §6.4, §6.5, §13.2): interval
//! iteration on the MDP's rules, with bounds stored only for the states that can still change.
//!
//! The states are those of the explicit MDP, numbered alike: absorbing ones take their payoff,
//! and vectors of lower and upper bounds cover the others (chance and decision nodes: the
//! *live* states), found through a bit set and a count per 32-bit block of it. As in the explicit
//! solver, live states that cannot reach a positive payoff are fixed to 0 first (this includes
//! closed sets of chance nodes, where an upper bound would otherwise never come down); the rest
//! start at `[0, largest payoff]` and are solved one strongly connected component at a time,
//! successors first: Gauss–Seidel sweeps of the component (its states in the order in which the
//! backward search from the payoffs found them) apply the Bellman operator to both bounds until
//! every gap is at most `epsilon` (one backup for a state on no cycle). Starting below (above)
//! the value, a monotone operator keeps each bound on its side: the interval always contains
//! the value. A robot move multiplies by `g`, the adversary's move and `stop` are instant; every
//! cycle the iteration must contract through holds a robot move, so at `g < 1` it converges.
//! At `g = 1` the robot may circle for ever in an end component, where nothing would bring the
//! upper bounds down: the maximal end components are found once ([`end_components`]) and after
//! every sweep each of their states is lowered to the best upper bound of a choice leaving the
//! component (staying for ever pays nothing), which lets the bounds meet (the deflation of
//! interval iteration, where the stored solver collapses the components instead).
//!
//! Memory: 16 bytes per live state, four more for the components' order (eight more while
//! Tarjan's algorithm runs, four while the order is sorted), a bit per state and four bytes per
//! 32 states; at `g = 1`, while the end components are searched, eight bytes per
//! live state, then four per state of an end component.

use std::collections::VecDeque;

use bit_set::BitSet;

use super::ends::{components, end_components, successors_within};
use super::mdp::{Choice, Distribution, Kind, Model};
use super::moves::Moves;
use crate::arena::Owner;
use crate::mdp::solve::Interval;

/// Why the implicit solve stops.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SolveError {
    /// The discount is not in `(0, 1]` or epsilon not positive and finite.
    #[error("invalid discount {discount} or precision {epsilon}")]
    Invalid {
        /// The discount given.
        discount: f64,
        /// The precision given.
        epsilon: f64,
    },
    /// The sweeps did not close every gap to `epsilon`.
    #[error("no convergence within {iterations} sweeps (largest gap {gap:e})")]
    IterationLimit {
        /// The sweeps done.
        iterations: u32,
        /// The largest gap left.
        gap: f64,
    },
}

/// The certified bounds of every state of a [`Model`].
#[derive(Clone, Debug)]
pub struct Solution {
    live: BitSet,
    /// The live states before each 32-bit block of `live`.
    before: Vec<u32>,
    lower: Vec<f64>,
    upper: Vec<f64>,
    iterations: u32,
    gap: f64,
}

impl Solution {
    /// The live index of live state `h`.
    #[inline]
    fn index(&self, h: u32) -> usize {
        let blocks = self.live.get_ref().storage();
        let block = (h / 32) as usize;
        let below = blocks[block] & ((1u32 << (h % 32)) - 1);
        self.before[block] as usize + below.count_ones() as usize
    }

    /// The bounds of product state `h` of `model`.
    #[inline]
    pub fn value<M: Moves>(&self, model: &Model<'_, '_, M>, h: u32) -> Interval {
        if self.live.contains(h as usize) {
            let i = self.index(h);
            Interval {
                lower: self.lower[i],
                upper: self.upper[i],
            }
        } else {
            let payoff = model.absorbing_payoff(h);
            Interval {
                lower: payoff,
                upper: payoff,
            }
        }
    }

    /// The number of live states (those with bounds).
    pub fn num_live(&self) -> usize {
        self.lower.len()
    }

    /// The most sweeps one strongly connected component needed.
    pub fn iterations(&self) -> u32 {
        self.iterations
    }

    /// The largest gap `upper − lower`.
    pub fn gap(&self) -> f64 {
        self.gap
    }
}

/// Solves `model` at discount `g < 1` to an absolute precision `epsilon`, in at most
/// `max_iterations` sweeps.
///
/// # Errors
/// [`SolveError`].
pub fn solve<M: Moves>(
    model: &Model<'_, '_, M>,
    g: f64,
    epsilon: f64,
    max_iterations: u32,
) -> Result<Solution, SolveError> {
    if !(g > 0.0 && g <= 1.0 && epsilon > 0.0 && epsilon.is_finite()) {
        return Err(SolveError::Invalid {
            discount: g,
            epsilon,
        });
    }
    let n = model.space().num_states() as u32;
    let mut live = BitSet::with_capacity(n as usize);
    for h in 0..n {
        if matches!(model.kind(h), Kind::Chance | Kind::Decision) {
            live.insert(h as usize);
        }
    }
    let mut before = Vec::with_capacity(live.get_ref().storage().len());
    let mut count = 0u32;
    for block in live.get_ref().storage() {
        before.push(count);
        count += block.count_ones();
    }
    // The live states that can reach a positive payoff: the others are worth 0.
    let active = paying(model, &live);
    // The bounds are allocated once the searches below are done, so that their arrays and
    // the bounds are never resident together.
    let mut solution = Solution {
        lower: Vec::new(),
        upper: Vec::new(),
        live,
        before,
        iterations: 0,
        gap: 0.0,
    };
    // At g = 1 the robot may stay for ever in an end component, where the upper bounds would
    // not come down: after each sweep, every state of a maximal end component is lowered to
    // the best the component offers on leaving (staying pays nothing).
    let ends = if g == 1.0 {
        let live = count as usize;
        end_components(model, &active, |h| solution.index(h), live)
    } else {
        Vec::new()
    };
    let mut end_of = vec![u32::MAX; if ends.is_empty() { 0 } else { count as usize }];
    for (e, members) in ends.iter().enumerate() {
        for &h in members {
            end_of[solution.index(h)] = e as u32;
        }
    }
    // Solve one strongly connected component at a time, successors first (the order in which
    // Tarjan's algorithm closes them): a component without a cycle takes one backup, a cycle
    // sweeps only its own states until its gaps close.
    // Within a component, the states are swept in the order in which the backward search from
    // the payoffs found them: a value then travels as far as that search in one sweep.
    let mut distribution = Distribution::default();
    let active_set: BitSet = active.iter().map(|&h| h as usize).collect();
    let mut found = vec![u32::MAX; count as usize];
    for (position, &h) in active.iter().enumerate() {
        found[solution.index(h)] = position as u32;
    }
    drop(active);
    let mut order = components(
        &active_set,
        &|h| solution.index(h),
        count as usize,
        |h, out| successors_within(model, h, &active_set, false, &mut distribution, out),
    );
    drop(active_set);
    order.sort_each_by_key(|h| found[solution.index(h)]);
    drop(found);
    let top = model.largest_payoff();
    solution.lower = vec![0.0; count as usize];
    solution.upper = vec![0.0; count as usize];
    for &h in &order.states {
        let i = solution.index(h);
        solution.upper[i] = top;
    }
    let mut ends_of_component = Vec::new();
    for c in 0..order.len() {
        let members = order.get(c);
        ends_of_component.clear();
        if !end_of.is_empty() {
            ends_of_component.extend(
                members
                    .iter()
                    .map(|&h| end_of[solution.index(h)])
                    .filter(|&e| e != u32::MAX),
            );
            ends_of_component.sort_unstable();
            ends_of_component.dedup();
        }
        let mut sweeps = 0u32;
        loop {
            for &h in members {
                let (lower, upper) = backup(model, &solution, h, g, &mut distribution);
                let i = solution.index(h);
                // Monotone from both sides: keep the tighter bound (rounding never loosens
                // them).
                solution.lower[i] = lower.max(solution.lower[i]);
                solution.upper[i] = upper.min(solution.upper[i]);
            }
            for &e in &ends_of_component {
                let members = &ends[e as usize];
                let exit = best_exit(model, &solution, members, |t| {
                    solution.live.contains(t as usize) && end_of[solution.index(t)] == e
                });
                for &h in members {
                    let i = solution.index(h);
                    solution.upper[i] = solution.upper[i].min(exit);
                }
            }
            let gap = members
                .iter()
                .map(|&h| {
                    let i = solution.index(h);
                    solution.upper[i] - solution.lower[i]
                })
                .fold(0.0f64, f64::max);
            sweeps += 1;
            if gap <= epsilon {
                solution.iterations = solution.iterations.max(sweeps);
                solution.gap = solution.gap.max(gap);
                break;
            }
            if sweeps >= max_iterations {
                return Err(SolveError::IterationLimit {
                    iterations: sweeps,
                    gap,
                });
            }
        }
    }
    Ok(solution)
}

/// The largest upper bound of a choice leaving the end component `members` (`inside(t)` says
/// whether `t` is one of them): a decision node's `stop` or a move out of it. Chance nodes of
/// an end component have no outcome outside it.
fn best_exit<M: Moves>(
    model: &Model<'_, '_, M>,
    solution: &Solution,
    members: &[u32],
    inside: impl Fn(u32) -> bool,
) -> f64 {
    let mut exit = 0.0f64;
    for &h in members {
        if model.space().owner(h) == Owner::Adversary {
            continue;
        }
        model.choices(h, |c| match c {
            Choice::Stop { payoff } => exit = exit.max(payoff),
            Choice::Move { target, .. } if !inside(target) => {
                exit = exit.max(solution.value(model, target).upper);
            }
            Choice::Move { .. } => {}
        });
    }
    exit
}

/// The Bellman backup of live state `h` on both bounds.
#[inline]
fn backup<M: Moves>(
    model: &Model<'_, '_, M>,
    solution: &Solution,
    h: u32,
    g: f64,
    distribution: &mut Distribution,
) -> (f64, f64) {
    let bounds = |t: u32| {
        let v = solution.value(model, t);
        (v.lower, v.upper)
    };
    match model.space().owner(h) {
        Owner::Adversary => {
            model.distribution(h, distribution);
            distribution.iter().fold((0.0, 0.0), |(l, u), (t, p)| {
                let (lt, ut) = bounds(t);
                (l + p * lt, u + p * ut)
            })
        }
        _ => {
            let (mut l, mut u) = (0.0f64, 0.0f64);
            model.choices(h, |choice| {
                let (lc, uc) = match choice {
                    Choice::Move { target, .. } => {
                        let (lt, ut) = bounds(target);
                        (g * lt, g * ut)
                    }
                    Choice::Stop { payoff } => (payoff, payoff),
                };
                l = l.max(lc);
                u = u.max(uc);
            });
            (l, u)
        }
    }
}

/// The live states from which a positive payoff can be reached through the MDP's moves
/// (allowed choices, adversary moves of positive probability), in order of a backward
/// breadth-first search from the positive payoffs.
fn paying<M: Moves>(model: &Model<'_, '_, M>, live: &BitSet) -> Vec<u32> {
    let space = model.space();
    let n = space.num_states() as u32;
    let mut pays = BitSet::with_capacity(n as usize);
    let mut queue = VecDeque::new();
    for h in 0..n {
        let starts = match model.kind(h) {
            Kind::Absorbing(payoff) => payoff > 0.0,
            Kind::Decision => {
                let mut stop = false;
                model.choices(h, |c| {
                    stop |= matches!(c, Choice::Stop { payoff } if payoff > 0.0)
                });
                stop
            }
            Kind::Chance => false,
        };
        if starts {
            pays.insert(h as usize);
            queue.push_back(h);
        }
    }
    let mut distribution = Distribution::default();
    let mut order = Vec::new();
    while let Some(t) = queue.pop_front() {
        if live.contains(t as usize) {
            order.push(t);
        }
        space.predecessors(t, |p| {
            if pays.contains(p as usize) || !live.contains(p as usize) {
                return;
            }
            let moves = match model.kind(p) {
                Kind::Chance => {
                    model.distribution(p, &mut distribution);
                    distribution.iter().any(|(target, _)| target == t)
                }
                _ => {
                    let mut found = false;
                    model.choices(p, |c| {
                        found |= matches!(c, Choice::Move { target, .. } if target == t)
                    });
                    found
                }
            };
            if moves {
                pays.insert(p as usize);
                queue.push_back(p);
            }
        });
    }
    order
}

impl Solution {
    /// The live states (those with bounds), for the policy ([`super::policy`]).
    pub(crate) fn live(&self) -> &BitSet {
        &self.live
    }
}

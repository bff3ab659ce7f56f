//! Certified values over the index space, for a discount `g < 1` (docs/semantics.md §6.4,
//! §6.5): interval iteration on the MDP's rules, with bounds stored only for the states that can
//! still change.
//!
//! The states are those of the explicit MDP, numbered alike: absorbing ones take their payoff,
//! and vectors of lower and upper bounds cover the others (chance and decision nodes: the
//! *live* states), found through a bit set and a count per 32-bit block of it. As in the explicit
//! solver, live states that cannot reach a positive payoff are fixed to 0 first (this includes
//! closed sets of chance nodes, where an upper bound would otherwise never come down); the rest
//! start at `[0, largest payoff]` and Gauss–Seidel sweeps in index order apply the Bellman
//! operator to both bounds until every gap is at most `epsilon`. Starting below (above) the
//! value, a monotone operator keeps each bound on its side: the interval always contains the
//! value. A robot move multiplies by `g`, the adversary's move and `stop` are instant; every
//! cycle the iteration must contract through holds a robot move, so at `g < 1` it converges.
//! At `g = 1` end components need the explicit solver's collapse, which this engine does not do
//! yet: [`SolveError::Undiscounted`].
//!
//! Memory: 16 bytes per live state, a bit per state and four bytes per 32 states.

use std::collections::VecDeque;

use bit_set::BitSet;

use super::mdp::{Choice, Distribution, Kind, Model};
use super::moves::Moves;
use crate::arena::Owner;
use crate::mdp::solve::Interval;

/// Why the implicit solve stops.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SolveError {
    /// `g = 1`: not yet supported by this engine.
    #[error("the implicit engine solves discounted models only (g < 1) so far")]
    Undiscounted,
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

    /// The sweeps done.
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
    if g == 1.0 {
        return Err(SolveError::Undiscounted);
    }
    let n = model.space().num_states() as u32;
    let mut live = BitSet::with_capacity(n as usize);
    for h in 0..n {
        if model.kind(h) != Kind::Chance && model.kind(h) != Kind::Decision {
            continue;
        }
        live.insert(h as usize);
    }
    let mut before = Vec::with_capacity(live.get_ref().storage().len());
    let mut count = 0u32;
    for block in live.get_ref().storage() {
        before.push(count);
        count += block.count_ones();
    }
    // The live states that can reach a positive payoff, in order of discovery backwards from
    // the payoffs: sweeping in this order carries a value as far as the search went in one
    // sweep, where index order would carry it one move per sweep.
    let active = paying(model, &live);
    let top = model.largest_payoff();
    let mut solution = Solution {
        lower: vec![0.0; count as usize],
        upper: vec![0.0; count as usize],
        live,
        before,
        iterations: 0,
        gap: 0.0,
    };
    for &h in &active {
        let i = solution.index(h);
        solution.upper[i] = top;
    }
    let mut distribution = Distribution::default();
    loop {
        let mut gap = 0.0f64;
        for &h in &active {
            let (lower, upper) = backup(model, &solution, h, g, &mut distribution);
            let i = solution.index(h);
            // Monotone from both sides: keep the tighter bound (rounding never loosens them).
            let lower = lower.max(solution.lower[i]);
            let upper = upper.min(solution.upper[i]);
            solution.lower[i] = lower;
            solution.upper[i] = upper;
            gap = gap.max(upper - lower);
        }
        solution.iterations += 1;
        solution.gap = gap;
        if gap <= epsilon {
            return Ok(solution);
        }
        if solution.iterations >= max_iterations {
            return Err(SolveError::IterationLimit {
                iterations: solution.iterations,
                gap,
            });
        }
    }
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

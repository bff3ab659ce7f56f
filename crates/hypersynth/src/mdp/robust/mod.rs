//! The robust solve: maximal expected payoff at absorption when some choices' probabilities are
//! only known to lie in intervals, and an adversary picks them, at every visit anew, to minimise
//! the payoff (interval MDPs with the robust, "max–min" semantics; docs/semantics.md §10.3).
//!
//! # The problem
//! [`Intervals`] give some choices of an [`Mdp`] a probability interval `[l, u]` per successor
//! (with `Σ l ≤ 1 ≤ Σ u`); every other choice keeps the model's probabilities. The value is the
//! least solution of `value(s) = payoff(s)` for an absorbing state and
//! `value(s) = max_a f(a) · min_{p} Σ_t p(t) · value(t)` for a decision state, the minimum over
//! the distributions within the intervals (a single one for an exact choice), `f` as in
//! [`crate::mdp::solve()`]. The model's probabilities of an interval choice are ignored; its
//! targets are the successors an interval is given for.
//!
//! # Method
//! 1. *Qualitative*: the states from which every adversary can be kept from never giving a
//!    positive payoff a chance are found by a backward search (`qualitative.rs`); the others are
//!    worth exactly 0 and fixed. Here an adversary may set to 0 every probability whose lower
//!    bound is 0.
//! 2. *End components without adversary* (g = 1): a maximal end component of states whose
//!    choices are all exact is one where the robot moves freely whatever the adversary does;
//!    it is collapsed into one node, whose choices are its states' choices that leave it, as in
//!    the nominal solve. End components that contain an interval choice are not collapsed: the
//!    adversary can keep the run away from part of them.
//! 3. *Components*: the nodes' strongly connected components are solved in reverse topological
//!    order (`iteration.rs`, on the nominal solve's equation system with the robust expectation
//!    of the Bellman operator, `mdp/operator.rs`). Within one, Gauss–Seidel sweeps raise a
//!    lower vector (from 0) and lower an upper one (from the largest payoff) by the robust
//!    Bellman operator, in which the adversary's reply at an interval choice is the greedy one
//!    of `inner.rs`, computed separately for each bound. Both stay bounds after every sweep: the lower one is an iterate
//!    of value iteration from below, and every vector the operator does not raise bounds the
//!    least fixed point from above. At g = 1 the upper sequence would stall in end components
//!    the adversary can keep the run in: they are *deflated*, the adversary's replies to the
//!    lower bounds fixing an MDP whose maximal end components get the upper bound of the best
//!    choice leaving them (bounded value iteration for stochastic games). Whenever the lower
//!    bounds settle, the optimistic upper bound `min(U, L + ε/2)` is offered and kept if it is
//!    a super-fixed-point. A component is done when `max(U − L) ≤ ε` (with
//!    [`SolveOptions::relative`], when every `U − L ≤ ε · L`);
//!    `SolveOptions::max_iterations` sweeps per component give `SolveError::IterationLimit`.
//! 4. *Policy* (`policy.rs`): from the lower bounds, making progress against every adversary at
//!    g = 1; it collects at least the lower bound of every state, whatever the adversary picks
//!    within the intervals.
//!
//! Cost per sweep: one pass over the component's transitions, plus a sort of each interval
//! choice's successors per bound; a deflation builds the fixed-reply MDP of the component and
//! searches its end components (a few sweeps' worth). Memory: the nominal system's, plus the
//! transitions into every state for the qualitative searches (8 bytes per transition), the
//! fixed-reply MDP of a deflation (up to 16 per transition) and 16 bytes per interval
//! transition (the intervals themselves, [`Intervals::bytes`]). The solve asks its observer
//! for all of it but the intervals, which exist before it ([`Observer::reserve`]), and fails
//! with [`SolveError::Memory`] before allocating if refused.
//!
//! Without interval choices this computes the nominal value (tested against the nominal solve).
//! **Invariants:** the bounds are certified against every distribution within the intervals;
//! an exact choice keeps the model's probabilities; a deflation is sound for any fixed reply
//! within the intervals.

pub(crate) mod inner;
mod iteration;
mod policy;
mod qualitative;
#[cfg(test)]
mod tests;

use thiserror::Error;

use self::iteration::RobustSystem;
use self::qualitative::{Incoming, can_reach_positive_payoff, owners};
use super::graph::{Predecessors, maximal_end_components};
use super::model::{ChoiceId, Mdp, MdpState, PROBABILITY_TOLERANCE};
use super::operator::{Payoff, model_q};
use super::solve::{Discount, Precision, Solution, SolveError, SolveOptions};
use crate::index::Id;
use crate::stage::{Observer, Stage, metered};

/// Probability intervals for some choices of an [`Mdp`]: per interval choice, one `[lower,
/// upper]` per target, in the order of [`Mdp::targets`].
#[derive(Clone, Debug, PartialEq)]
pub struct Intervals {
    /// Per choice, where its bounds start in `bounds` (`u32::NONE`: an exact choice).
    first: Vec<u32>,
    bounds: Vec<[f64; 2]>,
}

/// Why [`Intervals::set`] refused a choice's intervals.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum IntervalError {
    /// Not one interval per target of the choice.
    #[error("choice {choice} has {targets} targets but {given} intervals were given")]
    Length {
        /// The choice.
        choice: ChoiceId,
        /// Its number of targets.
        targets: usize,
        /// The number of intervals given.
        given: usize,
    },
    /// An interval that is not `0 ≤ lower ≤ upper ≤ 1`.
    #[error("choice {choice}: [{lower}, {upper}] is not an interval within [0, 1]")]
    Invalid {
        /// The choice.
        choice: ChoiceId,
        /// The lower bound given.
        lower: f64,
        /// The upper bound given.
        upper: f64,
    },
    /// Intervals that admit no distribution: `Σ lower > 1` or `Σ upper < 1` (beyond
    /// [`PROBABILITY_TOLERANCE`]).
    #[error("choice {choice}: the lower bounds add up to {lower}, the upper ones to {upper}")]
    Infeasible {
        /// The choice.
        choice: ChoiceId,
        /// The sum of the lower bounds.
        lower: f64,
        /// The sum of the upper bounds.
        upper: f64,
    },
}

impl Intervals {
    /// No interval: every choice keeps the model's probabilities.
    pub fn exact(mdp: &Mdp) -> Intervals {
        Intervals {
            first: vec![u32::NONE; mdp.num_choices()],
            bounds: Vec::new(),
        }
    }

    /// Gives `choice` the intervals `bounds`, one per target of the choice in the order of
    /// [`Mdp::targets`] (replacing those it had). An error leaves the intervals unchanged.
    pub fn set(
        &mut self,
        mdp: &Mdp,
        choice: ChoiceId,
        bounds: &[[f64; 2]],
    ) -> Result<(), IntervalError> {
        let targets = mdp.targets(choice).len();
        if bounds.len() != targets {
            return Err(IntervalError::Length {
                choice,
                targets,
                given: bounds.len(),
            });
        }
        if let Some(&[lower, upper]) = bounds
            .iter()
            .find(|b| !(0.0 <= b[0] && b[0] <= b[1] && b[1] <= 1.0))
        {
            return Err(IntervalError::Invalid {
                choice,
                lower,
                upper,
            });
        }
        let lower: f64 = bounds.iter().map(|b| b[0]).sum();
        let upper: f64 = bounds.iter().map(|b| b[1]).sum();
        if lower > 1.0 + PROBABILITY_TOLERANCE || upper < 1.0 - PROBABILITY_TOLERANCE {
            return Err(IntervalError::Infeasible {
                choice,
                lower,
                upper,
            });
        }
        match self.first(choice) {
            Some(first) => {
                let first = first as usize;
                self.bounds[first..first + targets].copy_from_slice(bounds);
            }
            None => {
                self.first[choice.index()] = self.bounds.len() as u32;
                self.bounds.extend_from_slice(bounds);
            }
        }
        Ok(())
    }

    /// The intervals of `choice` of `mdp` (the model they were set for); `None` for an exact
    /// choice.
    pub fn get(&self, mdp: &Mdp, choice: ChoiceId) -> Option<&[[f64; 2]]> {
        let first = self.first(choice)? as usize;
        Some(&self.bounds[first..first + mdp.targets(choice).len()])
    }

    /// About the bytes that intervals on every choice of `mdp` take (4 per choice, 16 per
    /// transition): an upper bound for any intervals on it, for a caller to reserve before
    /// setting them.
    pub fn bytes(mdp: &Mdp) -> u64 {
        4 * mdp.num_choices() as u64 + 16 * mdp.num_transitions() as u64
    }

    /// The number of choices with intervals.
    pub fn num_uncertain(&self) -> usize {
        self.first.iter().filter(|f| !f.is_none()).count()
    }

    fn first(&self, choice: ChoiceId) -> Option<u32> {
        self.first[choice.index()].to_option()
    }
}

/// The robust value of playing `choice` once and then according to `values` (one per state):
/// `f · min_p Σ p · values`, the adversary's greedy reply for an interval choice, the model's
/// probabilities for an exact one.
pub fn choice_value(
    mdp: &Mdp,
    intervals: &Intervals,
    g: f64,
    values: &[f64],
    choice: ChoiceId,
) -> f64 {
    let bounds = intervals.get(mdp, choice);
    model_q(mdp, choice, bounds, &Payoff { g }, &|t| [values[t.index()]])[0]
}

/// The adversary's reply at `choice` to `values`: the distribution over the choice's targets
/// (in the order of [`Mdp::targets`]) that minimises the expectation within the intervals; the
/// model's probabilities for an exact choice.
pub fn worst_case(
    mdp: &Mdp,
    intervals: &Intervals,
    values: &[f64],
    choice: ChoiceId,
    out: &mut Vec<f64>,
) {
    match intervals.get(mdp, choice) {
        None => {
            out.clear();
            out.extend(mdp.successors(choice).map(|(_, p)| p));
        }
        Some(bounds) => {
            let values: Vec<f64> = mdp
                .targets(choice)
                .iter()
                .map(|t| values[t.index()])
                .collect();
            inner::distribution(&values, bounds, out);
        }
    }
}

/// About the bytes the robust solve adds to the model and its intervals at its peak: the
/// nominal solver's ([`solver_bytes`](super::solve)), plus per transition the incoming lists
/// of the qualitative searches (8) and a deflation's fixed-reply MDP (up to 16).
fn robust_solver_bytes(mdp: &Mdp) -> u64 {
    super::solve::solver_bytes(mdp) + 24 * mdp.num_transitions() as u64
}

/// Solves `mdp` with `intervals` for the robust value (see the module documentation).
pub fn solve(
    mdp: &Mdp,
    intervals: &Intervals,
    options: &SolveOptions,
) -> Result<Solution, SolveError> {
    solve_observed(mdp, intervals, options, &mut ())
}

/// [`solve`], telling `observer` about its two stages: the values ([`Stage::RobustSolve`]) and the
/// policy ([`Stage::Policy`]).
pub fn solve_observed(
    mdp: &Mdp,
    intervals: &Intervals,
    options: &SolveOptions,
    observer: &mut dyn Observer,
) -> Result<Solution, SolveError> {
    let epsilon = options.epsilon()?;
    let g = options.discount.get();
    let n = mdp.num_states();
    observer.reserve(Stage::RobustSolve, robust_solver_bytes(mdp), &|| {
        format!(
            "solving the interval MDP robustly ({n} states, {} transitions, {} of {} choices \
             with intervals)",
            mdp.num_transitions(),
            intervals.num_uncertain(),
            mdp.num_choices()
        )
    })?;
    let incoming = Incoming::new(mdp);
    let owners = owners(mdp);
    let (lower, upper, solved, end_components) = metered(observer, Stage::RobustSolve, |meter| {
        let order = can_reach_positive_payoff(mdp, intervals, &incoming, &owners);
        let (component, end_components) = if g == 1.0 {
            // Only states whose every choice is exact may be collapsed.
            let candidates: Vec<MdpState> = order
                .iter()
                .copied()
                .filter(|&s| mdp.choices(s).all(|c| intervals.first(c).is_none()))
                .collect();
            let predecessors = Predecessors::new(mdp, |_| true);
            maximal_end_components(mdp, &predecessors, &candidates)
        } else {
            (vec![None; n], 0)
        };
        let mut system = RobustSystem::with_intervals(mdp, intervals, &order, &component);
        drop(order);
        drop(component);
        let precision = Precision {
            epsilon,
            relative: options.relative,
        };
        let solved = system.solve_components(g, precision, options.max_iterations, meter)?;
        let (lower, upper) = system.expand();
        Ok::<_, SolveError>((lower, upper, solved, end_components))
    })?;
    let policy = metered(observer, Stage::Policy, |meter| {
        meter.set_total(1);
        let policy = policy::choose(mdp, intervals, g, &lower, &incoming, &owners);
        meter.set(1);
        policy
    });
    Ok(Solution::from_parts(
        Discount::new(g)?,
        lower,
        upper,
        policy,
        solved.sweeps,
        solved.gap,
        end_components,
    ))
}

//! Maximal expected payoff at absorption, by interval iteration with a certified error bound,
//! and a policy that attains it.
//!
//! # The problem
//! `value(s) = payoff(s)` for an absorbing state; for a decision state
//! `value(s) = max_a f(a) · Σ_t P(s, a, t) · value(t)`, the least solution (a run that is never
//! absorbed pays 0), where `f(a) = g` (0 < g ≤ 1) for a *move* and `f(a) = 1` for an *instant*
//! choice (an adversary's chance move, or `stop`, which collects its payoff at once): a payoff
//! collected after `t` robot moves is worth `g^t` of it.
//!
//! # Method
//! 1. *Qualitative preprocessing*: states that cannot reach an absorbing state of positive payoff
//!    under any policy (backward search over predecessor lists) have value exactly 0 and are
//!    fixed, like absorbing states.
//! 2. *End components* (g = 1 only): inside a maximal end component of the remaining decision
//!    states the robot can move freely at no cost, so all its states share one value: the best
//!    over the choices that *leave* it. Each MEC is therefore collapsed into one node whose choices
//!    are its states' leaving choices (quotient, rather than deflation: the quotient is computed
//!    once, while deflation repeats an end-component search as the iteration proceeds). The
//!    quotient has no end component of its own, so the Bellman operator has a unique fixed point
//!    on it and the upper sequence converges to it. With g < 1 no collapse is needed (nor sound:
//!    moving inside a component costs discount): an end component made of instant choices only
//!    is a closed set of chance nodes, which step 1 has fixed to 0, and every other one contains
//!    a move, so the operator contracts on it.
//! 3. *Components*: the remaining nodes (states, or collapsed MECs) are split into strongly
//!    connected components and solved one at a time in reverse topological order, so that
//!    every component sees its successors outside final. A trivial component is one exact
//!    Bellman step on both bounds. A component of at most `EXACT_LIMIT` (200) nodes that the
//!    sweeps described below have not settled within `QUICK_SWEEPS` (64) is solved by *policy
//!    iteration* with exact linear solves (subtraction-free Gaussian elimination,
//!    accurate whatever the exit probabilities: a one-state loop left with probability 1e-9
//!    takes one round where value iteration needs 10^10 sweeps): the final policy's value with
//!    the exits' lower bounds is a lower bound, its value with their upper bounds plus ε/2 is
//!    offered as the upper bound and kept only if one Bellman update does not raise it (a
//!    super-fixed-point, which bounds the value from above because no end component is left).
//!    Larger components use Gauss–Seidel sweeps of a lower (from 0) and an upper (from the
//!    largest payoff) vector in node order (breadth-first from the payoffs, which is also the
//!    memory layout), with every 16th sweep run backwards and that direction kept if it moved
//!    the lower bounds more (a cycle numbered along its edges wants it), clamped monotone, so `L ≤ value ≤ U` after every sweep (up to
//!    rounding); whenever the lower bounds settle (a sweep raises none by more than a
//!    tolerance, halved after each failure), *optimistic value iteration* offers
//!    `min(U, L + ε/2)` as the upper bound, kept if verified as above. A component is done
//!    when `max(U − L) ≤ ε` (absolute, default 1e-6); `SolveOptions::max_iterations` (per
//!    component) gives `SolveError::IterationLimit` with the gap reached. The verifications
//!    allow a relative 1e-13 of rounding. The number of iterations reported is the sum over
//!    components of sweeps and policy-iteration rounds.
//!
//! # Files
//! One file per method, behind this interface:
//! - `qualitative.rs`: the graph-only preprocessing (states that cannot reach a positive payoff,
//!   the choices internal to an end component);
//! - `system.rs`: the equation system (the quotient by the end components) and its solve, one
//!   strongly connected component at a time in reverse topological order;
//! - `optimistic.rs`: Gauss–Seidel interval iteration with optimistic upper bounds, for the
//!   components that are not trivial;
//! - `policy_iteration.rs`: exact policy iteration for small components;
//! - `policy.rs`: the policy extracted from the lower bounds;
//! - `expected_moves.rs`: the expected numbers of moves that break the policy's ties at g = 1.
//!
//! The graph algorithms (predecessor lists, strongly connected and end components) are in
//! `mdp/graph.rs`, which the evaluation of a controller shares.

mod expected_moves;
mod optimistic;
mod policy;
mod policy_iteration;
mod qualitative;
pub(in crate::mdp) mod system;
#[cfg(test)]
mod tests;

use thiserror::Error;

use self::policy::choose_policy;
use self::qualitative::{can_reach_positive_payoff, internal_choices};
use self::system::System;
use super::graph::{Predecessors, maximal_end_components};
use super::model::{ChoiceId, Mdp, MdpState};
use crate::limits::MemoryLimit;
use crate::stage::{Observer, Stage, metered};

/// Relative tolerance within which a choice's lower Q-value ties with the best one at g = 1.
/// The policy then loses at most this fraction of the value per expected robot move.
const TIE_TOLERANCE: f64 = 1e-12;

/// At g = 1, once a component is certified, its sweeps go on until no lower bound moves by more
/// than this fraction of the largest payoff in a sweep (or as many sweeps again as
/// certification took), so that choices that tie exactly are recognised as ties.
const REFINEMENT: f64 = 1e-14;

/// Components of at most this many nodes are solved by policy iteration with exact (dense)
/// linear solves; larger ones by Gauss–Seidel sweeps with optimistic upper bounds.
const EXACT_LIMIT: usize = 200;

/// Relative precision of the expected numbers of moves that break ties at g = 1: times closer
/// than this count as equal.
const TIME_TOLERANCE: f64 = 1e-6;

/// Sweeps a small component gets before it is handed to policy iteration.
const QUICK_SWEEPS: u32 = 64;

/// Relative rounding allowed when checking that an optimistic upper bound is a
/// super-fixed-point: the order of the rounding of one Bellman update.
const VERIFICATION_SLACK: f64 = 1e-13;

/// The discount `g`, 0 < g ≤ 1: a payoff collected after `t` robot moves is worth `g^t` of it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Discount(f64);

impl Discount {
    /// No discount (g = 1): the paper's definition.
    pub const NONE: Discount = Discount(1.0);

    /// The discount `g` per robot move; [`SolveError::InvalidDiscount`] unless `0 < g <= 1`.
    pub fn new(g: f64) -> Result<Self, SolveError> {
        if g > 0.0 && g <= 1.0 {
            Ok(Discount(g))
        } else {
            Err(SolveError::InvalidDiscount(g))
        }
    }

    /// `g`.
    pub fn get(self) -> f64 {
        self.0
    }
}

/// How [`solve`] iterates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolveOptions {
    /// The discount per move (instant choices are not discounted).
    pub discount: Discount,
    /// The absolute bound on `upper − lower` at which iteration stops (> 0).
    pub epsilon: f64,
    /// The number of sweeps after which [`SolveError::IterationLimit`] is returned.
    pub max_iterations: u32,
}

impl Default for SolveOptions {
    fn default() -> Self {
        SolveOptions {
            discount: Discount::NONE,
            epsilon: 1e-6,
            max_iterations: 100_000,
        }
    }
}

/// Why [`solve`] gave no solution.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum SolveError {
    /// A discount outside `(0, 1]` (the value given).
    #[error("invalid discount {0}: it must satisfy 0 < g <= 1")]
    InvalidDiscount(f64),
    /// An epsilon that is not positive and finite (the value given).
    #[error("invalid precision {0}: epsilon must be a positive finite number")]
    InvalidEpsilon(f64),
    /// The sweep limit was reached before the bounds met within epsilon.
    #[error(
        "value iteration did not reach precision {epsilon} within {iterations} iterations \
         (the gap is still {gap})"
    )]
    IterationLimit {
        /// The sweeps done.
        iterations: u32,
        /// The largest `upper − lower` left.
        gap: f64,
        /// The precision asked for.
        epsilon: f64,
    },
    /// Solving would need more memory than the observer allows.
    #[error(transparent)]
    Memory(#[from] MemoryLimit),
}

/// About the bytes the solver and the policy add to the model at their peak, and the
/// evaluation of the policy as a Markov chain after them (which keeps the solution): per
/// state the bounds, components, times, ranks and the chain's arrays (about 100), per
/// transition the equation system's copy of the target and probability (16 with offsets), per
/// choice the Q-values and offsets (24). Measured on the 20x20 gridworld (1.25 million states,
/// 4.06 million transitions): solve and policy 127 MiB, the evaluation up to 225 MiB over what
/// was resident before the solve; this gives 228 MiB.
fn solver_bytes(mdp: &Mdp) -> u64 {
    100 * mdp.num_states() as u64
        + 16 * mdp.num_transitions() as u64
        + 24 * mdp.num_choices() as u64
}

/// A certified interval around an exact value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval {
    /// A lower bound on the value (attained by the policy).
    pub lower: f64,
    /// An upper bound on the value.
    pub upper: f64,
}

impl Interval {
    /// The middle of the interval.
    pub fn midpoint(self) -> f64 {
        0.5 * (self.lower + self.upper)
    }
}

/// The result of [`solve`]: bounds on every state's value and a policy that attains the lower one.
#[derive(Clone, Debug, PartialEq)]
pub struct Solution {
    discount: Discount,
    lower: Vec<f64>,
    upper: Vec<f64>,
    /// Per state, its choice (`ChoiceId::NONE` for an absorbing state: 4 bytes, not 8).
    policy: Vec<ChoiceId>,
    iterations: u32,
    gap: f64,
    end_components: u32,
}

impl Solution {
    /// Bounds on the value of `state`, at most [`Solution::gap`] apart.
    pub fn value(&self, state: MdpState) -> Interval {
        Interval {
            lower: self.lower[state.index()],
            upper: self.upper[state.index()],
        }
    }

    /// Bounds on the value of playing `choice` once and then optimally: `f · Σ P · value`, with
    /// `f = g` for a move and 1 for an instant choice.
    pub fn choice_value(&self, mdp: &Mdp, choice: ChoiceId) -> Interval {
        let (lower, upper) = q_values(mdp, choice, self.discount.get(), &self.lower, &self.upper);
        Interval { lower, upper }
    }

    /// The policy's choice (a global choice id) in `state`; `None` for an absorbing state.
    pub fn policy(&self, state: MdpState) -> Option<ChoiceId> {
        self.policy[state.index()].to_option()
    }

    /// The lower bounds of every state, indexed by state.
    pub fn lower(&self) -> &[f64] {
        &self.lower
    }

    /// The upper bounds of every state, indexed by state.
    pub fn upper(&self) -> &[f64] {
        &self.upper
    }

    /// Gauss–Seidel sweeps and policy-iteration rounds, summed over the components (0 when every
    /// component was trivial).
    pub fn iterations(&self) -> u32 {
        self.iterations
    }

    /// `max(upper − lower)` over all states at the end: ≤ epsilon.
    pub fn gap(&self) -> f64 {
        self.gap
    }

    /// How many maximal end components were collapsed (always 0 when g < 1).
    pub fn end_components(&self) -> u32 {
        self.end_components
    }

    /// The discount the values are for.
    pub fn discount(&self) -> Discount {
        self.discount
    }

    /// A solution computed by another method of the MDP core (the robust solve): bounds and a
    /// policy per state (`ChoiceId::NONE` for absorbing states), and the method's figures.
    pub(in crate::mdp) fn from_parts(
        discount: Discount,
        lower: Vec<f64>,
        upper: Vec<f64>,
        policy: Vec<ChoiceId>,
        iterations: u32,
        gap: f64,
        end_components: u32,
    ) -> Solution {
        Solution {
            discount,
            lower,
            upper,
            policy,
            iterations,
            gap,
            end_components,
        }
    }
}

/// Solves `mdp` for the maximal expected payoff at absorption (see the module documentation).
pub fn solve(mdp: &Mdp, options: &SolveOptions) -> Result<Solution, SolveError> {
    solve_observed(mdp, options, &mut ())
}

/// [`solve`], telling `observer` about its two stages: the values ([`Stage::Solve`]) and the
/// policy ([`Stage::Policy`]).
pub fn solve_observed(
    mdp: &Mdp,
    options: &SolveOptions,
    observer: &mut dyn Observer,
) -> Result<Solution, SolveError> {
    let epsilon = options.epsilon;
    if !(epsilon.is_finite() && epsilon > 0.0) {
        return Err(SolveError::InvalidEpsilon(epsilon));
    }
    let g = options.discount.get();
    let n = mdp.num_states();
    observer.reserve(Stage::Solve, solver_bytes(mdp), &|| {
        format!(
            "solving the MDP ({n} states, {} transitions) and evaluating its policy",
            mdp.num_transitions()
        )
    })?;
    let solved = metered(observer, Stage::Solve, |meter| {
        // The phases before the sweeps report nothing; each is a point where an interrupted
        // caller stops (a second or more on large MDPs).
        let predecessors = Predecessors::new(mdp, |_| true);
        meter.checkpoint();
        let order = can_reach_positive_payoff(mdp, &predecessors);
        meter.checkpoint();
        let (component, end_components) = if g == 1.0 {
            maximal_end_components(mdp, &predecessors, &order)
        } else {
            (vec![None; n], 0)
        };
        // The policy builds its own, smaller lists (eligible choices only) when it needs them.
        drop(predecessors);
        meter.checkpoint();
        let internal = internal_choices(mdp, &component);
        let mut system = System::new(mdp, &order, &component, &internal);
        // Only the system is needed from here on: free the rest before it grows.
        drop(order);
        drop(component);
        meter.checkpoint();
        let (iterations, gap) =
            system.solve_components(g, epsilon, options.max_iterations, meter)?;
        let (lower, upper) = system.expand();
        let values = Solution {
            discount: Discount(g),
            lower,
            upper,
            policy: Vec::new(),
            iterations,
            gap,
            end_components,
        };
        Ok::<_, SolveError>((values, internal))
    });
    let (mut solution, internal) = solved?;
    solution.policy = metered(observer, Stage::Policy, |meter| {
        choose_policy(
            mdp,
            g,
            &solution.lower,
            &internal,
            options.max_iterations,
            meter,
        )
    });
    Ok(solution)
}

/// `f · Σ P · L` and `f · Σ P · U` for one choice, in one pass (`f` its discount factor).
fn q_values(mdp: &Mdp, choice: ChoiceId, g: f64, lower: &[f64], upper: &[f64]) -> (f64, f64) {
    let (mut sum_lower, mut sum_upper) = (0.0, 0.0);
    for (target, probability) in mdp.successors(choice) {
        sum_lower += probability * lower[target.index()];
        sum_upper += probability * upper[target.index()];
    }
    let f = mdp.discount_factor(choice, g);
    (f * sum_lower, f * sum_upper)
}

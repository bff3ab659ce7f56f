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
//! 1. *Qualitative preprocessing* (`qualitative.rs`): a backward search from the payoffs, level
//!    by level (the distinct positive payoffs, highest first), gives every state the largest
//!    payoff it can reach and the fewest moves it needs to reach it; a state that reaches no
//!    positive payoff is worth exactly 0. At g = 1, a state worth exactly the largest payoff
//!    it can reach is one from which some policy reaches that payoff with probability 1, found
//!    per level from the graph alone (Storm's `prob1E`): such states are *settled* at that
//!    payoff. Absorbing, zero and settled states are fixed before any iteration; the others
//!    start from `[0, p · g^d]` (their level's payoff `p`, discounted by their distance `d`, or
//!    the next level's payoff if larger) and are laid out level by level, by distance.
//! 2. *End components* (g = 1 only, `system.rs`): inside a maximal end component of the
//!    remaining decision states the robot can move freely at no cost, so all its states share
//!    one value: the best over the choices that *leave* it. Each MEC is therefore collapsed
//!    into one node whose choices are its states' leaving choices (quotient, rather than
//!    deflation: the quotient is computed once, while deflation repeats an end-component search
//!    as the iteration proceeds). The quotient has no end component of its own, so the Bellman
//!    operator has a unique fixed point on it and the upper sequence converges to it. With
//!    g < 1 no collapse is needed (nor sound: moving inside a component costs discount): an end
//!    component made of instant choices only is a closed set of chance nodes, which step 1 has
//!    fixed to 0, and every other one contains a move, so the operator contracts on it.
//! 3. *Components* (`system.rs`): the remaining nodes (states, or collapsed MECs) are split
//!    into strongly connected components and solved one at a time in reverse topological
//!    order, so that every component sees its successors outside final. A trivial component is
//!    one exact Bellman step on both bounds. A component of at most `EXACT_LIMIT` (200) nodes
//!    that `QUICK_SWEEPS` (64) sweeps have not settled is solved by *policy iteration* with
//!    exact linear solves (`policy_iteration.rs`: a one-state loop left with probability 1e-9
//!    takes one round where value iteration needs 10^10 sweeps). Larger components use
//!    Gauss–Seidel sweeps of a lower and an upper vector with *optimistic* upper bounds
//!    (`optimistic.rs`), over a compact copy of the component (`System::block`: its nodes
//!    alone, in order, then its exits as constants), each offered bound kept only if one
//!    Bellman update does not raise it
//!    (a super-fixed-point, which bounds the value from above because no end component is
//!    left). `L ≤ value ≤ U` after every step, up to a relative 1e-13 of rounding.
//! 4. *Precision*: a component is done when every state's `U − L` is at most `ε` (absolute,
//!    default 1e-6) or `ε · L` (relative, [`SolveOptions::relative`]); below g = 1 a node
//!    within half of that is no longer updated (`optimistic.rs`), so the bounds reported are
//!    as wide as the precision allows rather than as narrow as the last sweep made them;
//!    `SolveOptions::max_iterations` (per component) gives `SolveError::IterationLimit` with
//!    the gap reached. The number of iterations reported is the sum over components of sweeps
//!    and policy-iteration rounds.
//! 5. *The policy* (`policy.rs`, `expected_moves.rs`): from the lower bounds, with the ties of
//!    g = 1 broken towards the fewest expected moves (docs/semantics.md §6.6).
//!
//! # Files
//! One file per method, behind this interface:
//! - `qualitative.rs`: the graph-only preprocessing (payoff levels, distances, settled states,
//!   the choices internal to an end component);
//! - `system.rs`: the equation system (the quotient by the end components: the Bellman operator
//!   of `mdp/operator.rs` over its nodes, and their bounds), which the robust solve shares with
//!   its own expectation, and its solve, one strongly connected component at a time in reverse
//!   topological order;
//! - `optimistic.rs`: Gauss–Seidel interval iteration with optimistic upper bounds, for the
//!   components that are not trivial;
//! - `policy_iteration.rs`: exact policy iteration for small components;
//! - `policy.rs`: the policy extracted from the lower bounds;
//! - `expected_moves.rs`: the expected numbers of moves that break the policy's ties at g = 1.
//!
//! Every backup of the sweeps, of policy iteration and of the expected moves is the one Bellman
//! operator of `mdp/operator.rs` (the policy's Q-values, computed on the model, do the same
//! sums). The graph algorithms (predecessor lists, strongly connected and end components) are in
//! `mdp/graph.rs`, which the evaluation of a controller shares.
//!
//! # Invariants
//! Every reported value is certified (`upper − lower ≤ ε`, or `≤ ε · lower` relative); only
//! moves cost a factor g; the policy attains the lower bound (the controller's evaluation
//! checks it). Tested: at g = 1 a decision state is settled by `qualitative.rs` iff its exact
//! value is the largest payoff it can reach (against a naive computation); the expected moves
//! that break the policy's ties are those of plain Gauss–Seidel sweeps over the model, each
//! component in rank order, bit for bit, however `expected_moves.rs` lays its components out;
//! the states that play their ranked choice are exactly those from which the chosen policy does
//! not reach a goal with probability 1 (against plain fixed points); a component swept over its
//! compact copy gets the same bounds and sweep counts as sweeps in place, to the bit.

mod expected_moves;
mod optimistic;
mod policy;
mod policy_iteration;
mod qualitative;
pub(in crate::mdp) mod system;
#[cfg(test)]
mod tests;

use bit_set::BitSet;
use thiserror::Error;

pub(crate) use self::policy::best_choice;
use self::policy::choose_policy;
use self::qualitative::{Levels, internal_choices};
use self::system::NominalSystem;
use super::graph::{Predecessors, maximal_end_components};
use super::model::{ChoiceId, Mdp, MdpState};
use super::operator::{Payoff, model_q};
use crate::limits::MemoryLimit;
use crate::stage::{Observer, Stage, metered};

/// Relative tolerance within which a choice's lower Q-value ties with the best one at g = 1.
/// The policy then loses at most this fraction of the value per expected robot move.
pub(crate) const TIE_TOLERANCE: f64 = 1e-12;

/// At g = 1, once a component is certified, its sweeps go on until no lower bound moves by more
/// than this fraction of the largest payoff in a sweep (or as many sweeps again as
/// certification took), so that choices that tie exactly are recognised as ties.
const REFINEMENT: f64 = 1e-14;

/// Components of at most this many nodes are solved by policy iteration with exact (dense)
/// linear solves; larger ones by Gauss–Seidel sweeps with optimistic upper bounds.
const EXACT_LIMIT: usize = 200;

/// Relative precision of the expected numbers of moves that break ties at g = 1: their sweeps
/// stop when no number rises by more than this fraction of itself, and times closer than this
/// count as equal. They only order choices of optimal value, so a thousandth is enough (a
/// millionth cost sweeps that changed no decision of the bundled examples); properness is
/// checked exactly whatever the precision (`policy.rs`).
pub(crate) const TIME_TOLERANCE: f64 = 1e-3;

/// Sweeps a small component gets before it is handed to policy iteration.
const QUICK_SWEEPS: u32 = 64;

/// Relative rounding allowed when checking that an optimistic upper bound is a
/// super-fixed-point: the order of the rounding of one Bellman update.
pub(in crate::mdp) const VERIFICATION_SLACK: f64 = 1e-13;

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
    /// The bound on `upper − lower` at which iteration stops (> 0, finite): at every state,
    /// `upper − lower ≤ epsilon`, or `≤ epsilon · lower` when `relative`.
    pub epsilon: f64,
    /// Whether `epsilon` is relative to each state's value (its lower bound) rather than
    /// absolute: the precision Storm and PRISM default to, the same guarantee for a state worth
    /// 300 and one worth 0.01.
    pub relative: bool,
    /// The number of sweeps after which [`SolveError::IterationLimit`] is returned.
    pub max_iterations: u32,
}

impl Default for SolveOptions {
    fn default() -> Self {
        SolveOptions {
            discount: Discount::NONE,
            epsilon: 1e-6,
            relative: false,
            max_iterations: 100_000,
        }
    }
}

impl SolveOptions {
    /// The precision, if it is one (positive and finite).
    pub(crate) fn epsilon(&self) -> Result<f64, SolveError> {
        let epsilon = self.epsilon;
        if epsilon.is_finite() && epsilon > 0.0 {
            Ok(epsilon)
        } else {
            Err(SolveError::InvalidEpsilon(epsilon))
        }
    }
}

/// The precision a component's bounds must reach ([`SolveOptions::epsilon`] and
/// [`SolveOptions::relative`]).
#[derive(Clone, Copy, Debug)]
pub(in crate::mdp) struct Precision {
    pub(in crate::mdp) epsilon: f64,
    pub(in crate::mdp) relative: bool,
}

impl Precision {
    /// An absolute precision `epsilon`.
    pub(in crate::mdp) fn absolute(epsilon: f64) -> Self {
        Precision {
            epsilon,
            relative: false,
        }
    }

    /// The width of the interval allowed to a state whose lower bound is `lower`.
    fn allowed(self, lower: f64) -> f64 {
        if self.relative {
            self.epsilon * lower.max(0.0)
        } else {
            self.epsilon
        }
    }

    /// The width of `[lower, upper]` over the width allowed to it: at most 1 once the precision
    /// is met (infinite for an interval of positive width where no width is allowed).
    fn ratio(self, lower: f64, upper: f64) -> f64 {
        let width = upper - lower;
        if width <= 0.0 {
            0.0
        } else {
            width / self.allowed(lower)
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
pub(in crate::mdp) fn solver_bytes(mdp: &Mdp) -> u64 {
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

    /// `max(upper − lower)` over all states at the end: ≤ epsilon (absolute precision), or
    /// ≤ epsilon times the largest lower bound (relative).
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
    let epsilon = options.epsilon()?;
    let g = options.discount.get();
    let n = mdp.num_states();
    observer.reserve(Stage::Solve, solver_bytes(mdp), &|| {
        format!(
            "solving the MDP ({n} states, {} transitions) and evaluating its policy",
            mdp.num_transitions()
        )
    })?;
    let solved = metered(observer, Stage::Solve, |meter| {
        // Progress: the states once through the preprocessing (half of it once their levels
        // are known), then once more, scaled, as the iterated nodes are solved.
        let states = n as u64;
        meter.set_total(2 * states);
        // Each phase before the sweeps is a point where an interrupted caller stops.
        let predecessors = Predecessors::new(mdp, |_| true);
        meter.checkpoint();
        let mut levels = Levels::new(mdp, &predecessors);
        meter.set(states / 2);
        let settled = if g == 1.0 {
            levels.settled(mdp, &predecessors)
        } else {
            BitSet::new()
        };
        levels.order.retain(|s| !settled.contains(s.index()));
        meter.checkpoint();
        let (component, end_components) = if g == 1.0 {
            maximal_end_components(mdp, &predecessors, &levels.order)
        } else {
            (vec![None; n], 0)
        };
        // The policy builds its own, smaller lists (eligible choices only) when it needs them.
        drop(predecessors);
        meter.checkpoint();
        let internal = internal_choices(mdp, &component);
        let bounds = |state: MdpState| {
            if let Some(payoff) = mdp.payoff(state) {
                [payoff, payoff]
            } else if settled.contains(state.index()) {
                let payoff = levels.payoff(state);
                [payoff, payoff]
            } else {
                [0.0, levels.upper_bound(state, g)]
            }
        };
        let mut system = NominalSystem::new(mdp, &levels.order, &component, &internal, bounds);
        meter.set(states);
        // Only the system is needed from here on: free the rest before it grows.
        drop(levels);
        drop(settled);
        drop(component);
        meter.checkpoint();
        let precision = Precision {
            epsilon,
            relative: options.relative,
        };
        let (iterations, gap) = system.solve_components(
            g,
            precision,
            options.max_iterations,
            meter,
            (states, states),
        )?;
        let (lower, upper) = system.expand();
        meter.set(2 * states);
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
    let value = |t: MdpState| [lower[t.index()], upper[t.index()]];
    let [lower, upper] = model_q(mdp, choice, None, &Payoff { g }, &value);
    (lower, upper)
}

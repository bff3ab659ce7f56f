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
//! # Alternatives measured and not kept
//! On the 24x24 gridworld at g = 0.99 (2.6 M states; components of 56k, 217k and 318k nodes,
//! 13, 37 and 147 sweeps; the last one converges geometrically at about 0.9 per sweep once
//! the values have crossed the grid):
//! - *policy iteration on large components*, each policy evaluated through the SCCs of its own
//!   graph (trivial parts exactly in reverse topological order, small cyclic parts by the
//!   dense solve, large ones by sweeps): the policies are mostly acyclic (all but ~14k nodes of
//!   318k), but it takes 11, 20 and 23–40 rounds of about three sweeps' cost each (graph,
//!   Tarjan, evaluation, improvement), and the one large cyclic part converges at about 0.99 per
//!   sweep: no faster overall (2.5–3.9 s against 3.6–3.8 s, on a loaded machine);
//! - *sweeping in the reverse topological order of the greedy policy's graph* (recomputed after
//!   8, 16, 32 and 64 sweeps): 179 sweeps instead of 197, but two to three times slower, since
//!   that order scatters the memory accesses that the breadth-first layout keeps local;
//! - raising the optimistic upper bound of nodes with instant choices only (chance nodes) to
//!   their Bellman value before verifying: the same sweep counts (the verifications fail on
//!   move nodes, whose lower bounds are not yet within `(1 − g) · ε / 2` of a fixed point).
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
//!   `max_iterations` sweeps each, until no time rises by more than `TIME_TOLERANCE`, 1e-6,
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

use std::ops::Range;

use bit_set::BitSet;
use thiserror::Error;

use super::graph::{
    Predecessors, maximal_end_components, strongly_connected_components,
    strongly_connected_components_by,
};
use super::model::{ChoiceId, Mdp, MdpState};
use crate::csr::Csr;
use crate::index::Id;
use crate::limits::MemoryLimit;
use crate::stage::{Meter, Observer, Stage, metered};

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
        let predecessors = Predecessors::new(mdp, |_| true);
        let order = can_reach_positive_payoff(mdp, &predecessors);
        let (component, end_components) = if g == 1.0 {
            maximal_end_components(mdp, &predecessors, &order)
        } else {
            (vec![None; n], 0)
        };
        // The policy builds its own, smaller lists (eligible choices only) when it needs them.
        drop(predecessors);
        let internal = internal_choices(mdp, &component);
        let mut system = System::new(mdp, &order, &component, &internal);
        // Only the system is needed from here on: free the rest before it grows.
        drop(order);
        drop(component);
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

/// The decision states that can reach an absorbing state of positive payoff under some policy,
/// in breadth-first order from those payoffs.
fn can_reach_positive_payoff(mdp: &Mdp, predecessors: &Predecessors) -> Vec<MdpState> {
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
fn internal_choices(mdp: &Mdp, component: &[Option<u32>]) -> BitSet {
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

/// The iterated equation system. Its unknowns (*slots*) are the nodes, in the order of their
/// first state in `order`: one per MEC and one per other state of `order`. Every other state
/// gets a constant slot after them (its payoff, or 0). Each node lists the non-internal choices
/// of its states with their transitions in the model's order and targets replaced by slots, so
/// that a sweep streams through memory and a choice's Q-value is computed with exactly the
/// floating-point operations of [`q_values`] on the expanded vectors (the policy relies on it).
/// The probabilities are not copied: each choice of the system remembers where its model
/// choice's transitions start and reads them from the model (8 bytes per transition saved).
struct System<'a> {
    /// The slot of every state.
    slot: Vec<u32>,
    /// Node → range of the system's choices (rows of `transitions`).
    node_offsets: Vec<u32>,
    /// The system's instant choices (not discounted).
    instant: BitSet,
    /// Per choice of the system, its target slots.
    transitions: Csr<u32, u32>,
    /// Per choice of the system, the position of its model choice's first transition in
    /// `probabilities`, which the targets in `transitions` follow one for one.
    first_transition: Vec<u32>,
    /// The model's probabilities, per transition.
    probabilities: &'a [f64],
    /// `[lower, upper]` per slot, together so that one cache line brings both.
    values: Vec<[f64; 2]>,
    /// Per position in the component being iterated, the nodes of the component with a choice
    /// into the node there (rebuilt for each component: a reverse graph of all nodes was 4
    /// bytes per node and per edge for the whole solve).
    sources: Csr<u32, u32>,
    /// The nodes a sweep must update: some successor's bounds changed since their last
    /// update (the others would recompute the bounds they have). One byte per node rather than
    /// a bit: set and tested in the innermost loop, where `BitSet::insert` was 7% of the time.
    dirty: Vec<bool>,
}

impl<'a> System<'a> {
    fn new(mdp: &'a Mdp, order: &[MdpState], component: &[Option<u32>], internal: &BitSet) -> Self {
        let mut slot = vec![u32::NONE; mdp.num_states()];
        let mut mec_slot: Vec<u32> = Vec::new();
        let mut nodes = 0u32;
        for &state in order {
            slot[state.index()] = match component[state.index()] {
                None => {
                    nodes += 1;
                    nodes - 1
                }
                Some(mec) => {
                    let mec = mec as usize;
                    if mec_slot.len() <= mec {
                        mec_slot.resize(mec + 1, u32::NONE);
                    }
                    if mec_slot[mec].is_none() {
                        mec_slot[mec] = nodes;
                        nodes += 1;
                    }
                    mec_slot[mec]
                }
            };
        }
        // The states of each node, grouped by their slots.
        let members: Csr<u32, MdpState> = Csr::group(
            nodes as usize,
            order.iter().map(|&state| (slot[state.index()], state)),
        );

        let max_payoff = mdp
            .states()
            .filter_map(|s| mdp.payoff(s))
            .fold(0.0, f64::max);
        let mut values = vec![[0.0, max_payoff]; nodes as usize];
        for state in mdp.states() {
            if slot[state.index()].is_none() {
                slot[state.index()] = values.len() as u32;
                let payoff = mdp.payoff(state).unwrap_or(0.0);
                values.push([payoff, payoff]);
            }
        }

        let mut system = System {
            slot,
            node_offsets: vec![0],
            instant: BitSet::new(),
            transitions: Csr::new(),
            first_transition: Vec::new(),
            probabilities: mdp.probabilities(),
            values,
            sources: Csr::new(),
            dirty: Vec::new(),
        };
        for node in members.rows() {
            for &state in members.row(node) {
                for choice in mdp.choices(state) {
                    if internal.contains(choice.index()) {
                        continue;
                    }
                    if mdp.is_instant(choice) {
                        system.instant.insert(system.transitions.num_rows());
                    }
                    let first = mdp.transitions().range(choice).start;
                    system.first_transition.push(first as u32);
                    for &target in mdp.targets(choice) {
                        system.transitions.push(system.slot[target.index()]);
                    }
                    system.transitions.finish_row();
                }
            }
            system
                .node_offsets
                .push(system.transitions.num_rows() as u32);
        }
        system
    }

    /// The number of nodes (unknowns).
    fn nodes(&self) -> usize {
        self.node_offsets.len() - 1
    }

    /// The choices of `node` (rows of `transitions`).
    fn choices(&self, node: usize) -> Range<usize> {
        self.node_offsets[node] as usize..self.node_offsets[node + 1] as usize
    }

    /// The target slots and probabilities of a choice of the system (inlined: a call per choice
    /// was a tenth of a sweep).
    #[inline(always)]
    fn transitions(&self, choice: usize) -> impl Iterator<Item = (u32, f64)> + '_ {
        let first = self.first_transition[choice] as usize;
        let targets = self.transitions.row(choice as u32);
        targets
            .iter()
            .zip(&self.probabilities[first..first + targets.len()])
            .map(|(&target, &probability)| (target, probability))
    }

    /// The target slots of all choices of `node`, one choice after the other (constant slots
    /// included: they are at `nodes()` and above). The node graph, without a copy of it.
    fn successor_slots(&self, node: u32) -> std::iter::Copied<std::slice::Iter<'_, u32>> {
        let choices = self.choices(node as usize);
        if choices.is_empty() {
            return [].iter().copied();
        }
        let start = self.transitions.range(choices.start as u32).start;
        let end = self.transitions.range(choices.end as u32 - 1).end;
        self.transitions.entries()[start..end].iter().copied()
    }

    /// Solves the strongly connected components of the node graph one by one, in reverse
    /// topological order, so that each sees its successors final (module documentation).
    /// Returns the sweeps made over non-trivial components, summed, and the final gap.
    fn solve_components(
        &mut self,
        g: f64,
        epsilon: f64,
        max_iterations: u32,
        meter: &mut Meter<'_>,
    ) -> Result<(u32, f64), SolveError> {
        let mut components =
            strongly_connected_components_by(self.nodes(), |node| self.successor_slots(node));
        meter.set_total(self.nodes() as u64);
        self.dirty = vec![false; self.nodes()];
        let mut position = vec![0u32; self.nodes()];
        let scale = self.values.iter().map(|v| v[1]).fold(1.0f64, f64::max);
        let (mut sweeps, mut gap) = (0u32, 0.0f64);
        // The nodes of the components solved so far.
        let mut done = 0u64;
        for index in components.rows() {
            let component = components.row_mut(index);
            if component.len() > EXACT_LIMIT {
                // Large components are swept in node order (breadth-first from the payoffs, as
                // the nodes are laid out): the search's own order scatters memory accesses
                // (five times slower per sweep on 20x20 gridworlds).
                component.sort_unstable();
            }
            let component = &*component;
            let node = component[0];
            let trivial = component.len() == 1 && !self.successor_slots(node).any(|t| t == node);
            if trivial {
                let (_, width) = self.update(node as usize, g);
                gap = gap.max(width);
                done += 1;
                meter.set(done);
                continue;
            }
            self.sources = self.component_sources(component, &mut position);
            // Small components get a few sweeps first (most converge at once), then policy
            // iteration, which does not care how small the exits are; sweeps again if that
            // could not be verified.
            // Inside the component, the share of its nodes that the way its gap has come down
            // to epsilon represents (a large one takes many seconds).
            let size = component.len() as u64;
            let mut progress = |fraction: f64| meter.set(done + (fraction * size as f64) as u64);
            let quick = if component.len() <= EXACT_LIMIT {
                QUICK_SWEEPS.min(max_iterations)
            } else {
                max_iterations
            };
            let (used, width) =
                match self.optimistic_iteration(component, g, epsilon, scale, quick, &mut progress)
                {
                    Ok(done) => done,
                    Err(_) if quick < max_iterations => {
                        let (rounds, width) = self.policy_iteration(component, g, epsilon, scale);
                        if width <= epsilon {
                            (quick + rounds, width)
                        } else {
                            let (more, width) = self.optimistic_iteration(
                                component,
                                g,
                                epsilon,
                                scale,
                                max_iterations,
                                &mut progress,
                            )?;
                            (quick + rounds + more, width)
                        }
                    }
                    Err(error) => return Err(error),
                };
            sweeps = sweeps.saturating_add(used);
            gap = gap.max(width);
            done += size;
            meter.set(done);
        }
        Ok((sweeps, gap))
    }

    /// The reverse links of `component` (see `sources`). `position` is scratch space, one entry
    /// per node: only the component's own entries are written, and a target belongs to the
    /// component when the entry it finds there points back at it (no reset between
    /// components; a binary search per edge instead made large components' setup slow).
    fn component_sources(&self, component: &[u32], position: &mut [u32]) -> Csr<u32, u32> {
        for (i, &node) in component.iter().enumerate() {
            position[node as usize] = i as u32;
        }
        let position = &*position;
        let inside = move |target: u32| {
            let i = *position.get(target as usize)?;
            (component.get(i as usize) == Some(&target)).then_some(i)
        };
        Csr::group_from(component.len(), || {
            component.iter().flat_map(move |&node| {
                self.successor_slots(node)
                    .filter_map(move |target| inside(target).map(|i| (i, node)))
            })
        })
    }

    /// The best lower and upper Q-values of `node` under the current values.
    fn bellman(&self, node: usize, g: f64) -> [f64; 2] {
        let mut best = [0.0f64, 0.0f64];
        for choice in self.choices(node) {
            let mut sum = [0.0, 0.0];
            for (target, probability) in self.transitions(choice) {
                let [lower, upper] = self.values[target as usize];
                sum[0] += probability * lower;
                sum[1] += probability * upper;
            }
            let f = if self.instant.contains(choice) {
                1.0
            } else {
                g
            };
            best = [best[0].max(f * sum[0]), best[1].max(f * sum[1])];
        }
        best
    }

    /// One clamped in-place update of `node`; returns how far its lower bound rose and its
    /// width.
    fn update(&mut self, node: usize, g: f64) -> (f64, f64) {
        let best = self.bellman(node, g);
        let [old_lower, old_upper] = self.values[node];
        let new = [best[0].max(old_lower), best[1].min(old_upper)];
        self.values[node] = new;
        (new[0] - old_lower, new[1] - new[0])
    }

    /// Gauss–Seidel sweeps over `component` (its successors outside are final), trying after
    /// each sweep in which the lower bounds settled to within `tolerance` an optimistic upper
    /// bound `min(U, L + ε/2)`: accepted when one Bellman update does not raise it anywhere
    /// (a super-fixed-point; there are no end components left, so it bounds the value), else
    /// the tolerance halves. At g = 1 the sweeps go on after certification until the lower
    /// bounds stop moving (`REFINEMENT`), for at most as many sweeps again. A sweep skips the
    /// nodes none of whose successors' bounds changed since their last update (they would keep
    /// theirs), so converged regions of a large component cost almost nothing, with the same
    /// bounds and sweep counts as full sweeps. After each sweep, `report` is told how far the
    /// gap has come from its first value to epsilon, on a log scale (from 0 to 1). Returns the
    /// sweeps and the width.
    fn optimistic_iteration(
        &mut self,
        component: &[u32],
        g: f64,
        epsilon: f64,
        scale: f64,
        max_iterations: u32,
        report: &mut dyn FnMut(f64),
    ) -> Result<(u32, f64), SolveError> {
        let mut first_width = None;
        let mut tolerance = epsilon;
        let mut sweeps = 0u32;
        for &node in component {
            self.dirty[node as usize] = true;
        }
        let (mut forward, mut last_progress) = (true, 0.0f64);
        let mut certified = None;
        loop {
            if sweeps == max_iterations {
                return match certified {
                    Some((width, _)) => Ok((sweeps, width)),
                    None => Err(SolveError::IterationLimit {
                        iterations: sweeps,
                        gap: self.width(component),
                        epsilon,
                    }),
                };
            }
            sweeps += 1;
            let (mut rise, mut width, mut progress) = (0.0f64, 0.0f64, 0.0f64);
            // A node that is not dirty keeps its bounds (module documentation of `dirty`): its
            // width is read, not recomputed, so every sweep's figures are those of a full one.
            let mut sweep = |position: usize, node: u32| {
                let node = node as usize;
                if !std::mem::replace(&mut self.dirty[node], false) {
                    let [lower, upper] = self.values[node];
                    width = width.max(upper - lower);
                    return;
                }
                let old = self.values[node];
                let (r, w) = self.update(node, g);
                if self.values[node] != old {
                    for &source in self.sources.row(position as u32) {
                        self.dirty[source as usize] = true;
                    }
                }
                rise = rise.max(r);
                width = width.max(w);
                progress += r;
            };
            // Every 16th sweep tries the other direction and keeps it if it moved the lower
            // bounds more: forward suits components laid out from their exits (gridworlds),
            // backward a cycle whose nodes are numbered along its edges.
            let probe = sweeps.is_multiple_of(16);
            if forward != probe {
                (component.iter().enumerate()).for_each(|(i, &node)| sweep(i, node));
            } else {
                (component.iter().enumerate().rev()).for_each(|(i, &node)| sweep(i, node));
            }
            if probe && progress > last_progress {
                forward = !forward;
            }
            last_progress = progress;
            if let Some((done, budget)) = certified {
                if rise <= REFINEMENT * scale || sweeps >= budget {
                    return Ok((sweeps, width.min(done)));
                }
                certified = Some((width.min(done), budget));
                continue;
            }
            if width > epsilon && rise <= tolerance {
                if self.try_optimistic_upper(component, g, epsilon) {
                    component.iter().for_each(|&node| {
                        self.dirty[node as usize] = true;
                    });
                } else {
                    tolerance *= 0.5;
                }
                width = self.width(component);
            }
            report(gap_fraction(
                *first_width.get_or_insert(width),
                width,
                epsilon,
            ));
            if width <= epsilon {
                if g < 1.0 {
                    return Ok((sweeps, width));
                }
                // Refine at most as long again as certification took.
                certified = Some((width, sweeps.saturating_mul(2)));
            }
        }
    }

    fn width(&self, component: &[u32]) -> f64 {
        component
            .iter()
            .map(|&n| self.values[n as usize][1] - self.values[n as usize][0])
            .fold(0.0, f64::max)
    }

    /// Sets the upper bounds of `component` to `min(U, L + ε/2)` if that vector is a
    /// super-fixed-point of the Bellman operator (up to `VERIFICATION_SLACK`); leaves them
    /// unchanged otherwise. Returns whether it did.
    fn try_optimistic_upper(&mut self, component: &[u32], g: f64, epsilon: f64) -> bool {
        let saved: Vec<f64> = component
            .iter()
            .map(|&n| self.values[n as usize][1])
            .collect();
        for &node in component {
            let [lower, upper] = self.values[node as usize];
            self.values[node as usize][1] = upper.min(lower + 0.5 * epsilon);
        }
        let verified = component.iter().all(|&node| {
            let candidate = self.values[node as usize][1];
            self.bellman(node as usize, g)[1] <= candidate + VERIFICATION_SLACK * candidate.abs()
        });
        if !verified {
            for (&node, upper) in component.iter().zip(saved) {
                self.values[node as usize][1] = upper;
            }
        }
        verified
    }

    /// Policy iteration on a small component: a policy is evaluated exactly (dense Gaussian
    /// elimination, with the successors' upper bounds) and improved until stable, at most 100
    /// rounds. Its value with the successors' lower bounds is a lower bound (after the end
    /// component collapse every policy leaves the component, so that value is what it
    /// collects); its value with the upper bounds plus ε/2 is offered as the upper bound and
    /// kept only if verified as a super-fixed-point. The caller falls back to iteration if the
    /// width is not within epsilon. Returns the rounds (counted as sweeps) and the width.
    fn policy_iteration(
        &mut self,
        component: &[u32],
        g: f64,
        epsilon: f64,
        scale: f64,
    ) -> (u32, f64) {
        let size = component.len();
        let mut index = std::collections::HashMap::with_capacity(size);
        for (i, &node) in component.iter().enumerate() {
            index.insert(node, i);
        }
        // Start from the choice of largest upper Q-value, which leaves no closed loop unless
        // every choice loops (then the values solve to the loop's exits anyway).
        let mut policy: Vec<usize> = component
            .iter()
            .map(|&node| self.best_upper_choice(node as usize, g))
            .collect();
        let mut rounds = 0u32;
        let upper = loop {
            rounds += 1;
            let Some(values) = self.evaluate_policy(component, &index, &policy, g, 1) else {
                return (rounds, f64::INFINITY);
            };
            // Improve on the upper values (the two bounds differ only through the exits).
            let mut changed = false;
            for (i, &node) in component.iter().enumerate() {
                let mut best = (policy[i], self.choice_value(policy[i], g, &index, &values));
                for choice in self.choices(node as usize) {
                    let q = self.choice_value(choice, g, &index, &values);
                    if q > best.1 + 1e-12 * scale {
                        best = (choice, q);
                    }
                }
                changed |= best.0 != policy[i];
                policy[i] = best.0;
            }
            if !changed || rounds == 100 {
                break values;
            }
        };
        let Some(lower) = self.evaluate_policy(component, &index, &policy, g, 0) else {
            return (rounds, f64::INFINITY);
        };
        let saved: Vec<[f64; 2]> = component.iter().map(|&n| self.values[n as usize]).collect();
        // The policy's own value is a lower bound (every policy is proper here); the upper
        // bound is offered with a margin and verified.
        for (i, &node) in component.iter().enumerate() {
            let [old_lower, old_upper] = self.values[node as usize];
            let new_upper = old_upper.min(upper[i] + 0.5 * epsilon);
            // Rounding in the solve may put the policy's value a few ulps above a bound.
            self.values[node as usize] = [old_lower.max(lower[i]).min(new_upper), new_upper];
        }
        let verified = component.iter().all(|&node| {
            let upper = self.values[node as usize][1];
            self.bellman(node as usize, g)[1] <= upper + VERIFICATION_SLACK * upper.abs()
        });
        if !verified {
            for (&node, values) in component.iter().zip(saved) {
                self.values[node as usize] = values;
            }
            return (rounds, f64::INFINITY);
        }
        (rounds, self.width(component))
    }

    /// The choice of `node` of largest upper Q-value.
    fn best_upper_choice(&self, node: usize, g: f64) -> usize {
        let mut best = (self.node_offsets[node] as usize, f64::NEG_INFINITY);
        for choice in self.choices(node) {
            let sum: f64 = self
                .transitions(choice)
                .map(|(t, p)| p * self.values[t as usize][1])
                .sum();
            let f = if self.instant.contains(choice) {
                1.0
            } else {
                g
            };
            if f * sum > best.1 {
                best = (choice, f * sum);
            }
        }
        best.0
    }

    /// The Q-value of `choice` with the component's nodes valued by `inside` and the other
    /// targets by their upper bounds.
    fn choice_value(
        &self,
        choice: usize,
        g: f64,
        index: &std::collections::HashMap<u32, usize>,
        inside: &[f64],
    ) -> f64 {
        let sum: f64 = self
            .transitions(choice)
            .map(|(t, p)| {
                p * index
                    .get(&t)
                    .map_or(self.values[t as usize][1], |&i| inside[i])
            })
            .sum();
        let f = if self.instant.contains(choice) {
            1.0
        } else {
            g
        };
        f * sum
    }

    /// The exact values of `policy` on the component, with the targets outside valued by side
    /// `side` of their bounds: `x = f · P_inside x + f · P_outside v`. Solved by Gaussian
    /// elimination in the subtraction-free form of Grassmann, Taksar and Heyman: the matrix is
    /// `I − f · P_inside`, an M-matrix, and every diagonal entry is kept as the row's *leak*
    /// (its probability of leaving, `f · P_outside + 1 − f`, accumulated) plus its remaining
    /// off-diagonal weights, so that no difference of nearly equal numbers is ever formed and
    /// exit probabilities of 1e-12 are as accurate as any other. `None` if some row has no leak
    /// (the policy keeps the run inside forever; impossible once end components are
    /// collapsed, or with g < 1).
    fn evaluate_policy(
        &self,
        component: &[u32],
        index: &std::collections::HashMap<u32, usize>,
        policy: &[usize],
        g: f64,
        side: usize,
    ) -> Option<Vec<f64>> {
        let m = component.len();
        // weights[i * m + j]: f · P(i → j) for inside targets j ≠ i (self-loops are implicit).
        let mut weights = vec![0.0f64; m * m];
        let mut leak = vec![0.0f64; m];
        let mut rhs = vec![0.0f64; m];
        for (i, &choice) in policy.iter().enumerate() {
            let f = if self.instant.contains(choice) {
                1.0
            } else {
                g
            };
            let mut outside = 0.0;
            for (t, p) in self.transitions(choice) {
                match index.get(&t) {
                    Some(&j) if j != i => weights[i * m + j] += f * p,
                    Some(_) => {}
                    None => {
                        outside += p;
                        rhs[i] += f * p * self.values[t as usize][side];
                    }
                }
            }
            leak[i] = f * outside + (1.0 - f);
        }
        for k in 0..m {
            let pivot = leak[k] + weights[k * m + k + 1..(k + 1) * m].iter().sum::<f64>();
            if pivot <= 0.0 {
                return None;
            }
            for i in k + 1..m {
                let w_ik = weights[i * m + k];
                if w_ik == 0.0 {
                    continue;
                }
                let factor = w_ik / pivot;
                weights[i * m + k] = 0.0;
                for j in k + 1..m {
                    if j != i {
                        weights[i * m + j] += factor * weights[k * m + j];
                    }
                }
                leak[i] += factor * leak[k];
                rhs[i] += factor * rhs[k];
            }
        }
        let mut x = vec![0.0f64; m];
        for k in (0..m).rev() {
            let row = &weights[k * m + k + 1..(k + 1) * m];
            let pivot = leak[k] + row.iter().sum::<f64>();
            let sum = rhs[k] + row.iter().zip(&x[k + 1..]).map(|(w, x)| w * x).sum::<f64>();
            x[k] = sum / pivot;
        }
        Some(x)
    }

    /// The lower and upper vectors per state (the rest of the system is freed first).
    fn expand(mut self) -> (Vec<f64>, Vec<f64>) {
        let slot = std::mem::take(&mut self.slot);
        let values = std::mem::take(&mut self.values);
        drop(self);
        slot.iter()
            .map(|&slot| {
                let [lower, upper] = values[slot as usize];
                (lower, upper)
            })
            .unzip()
    }
}

/// How far a gap that was `first` has come down to `epsilon` when it is `width`, on a log scale:
/// 0 while it is still `first` (or wider), 1 once it is within `epsilon`.
fn gap_fraction(first: f64, width: f64, epsilon: f64) -> f64 {
    if width <= epsilon || first <= epsilon {
        return 1.0;
    }
    ((first / width).ln() / (first / epsilon).ln()).clamp(0.0, 1.0)
}

/// The policy described in the module documentation. Progress: the states, once per phase
/// (one phase when g < 1; at g = 1 the ties, the ranking, the expected moves and the choice).
fn choose_policy(
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
    // Each choice's lower Q-value once, and whether it ties with its state's best.
    let q: Vec<f64> = mdp.all_choices().map(q_lower).collect();
    let q_lower = |choice: ChoiceId| q[choice.index()];
    let mut ties = BitSet::with_capacity(mdp.num_choices());
    for state in mdp.states() {
        let value = lower[state.index()];
        for choice in mdp.choices(state) {
            if internal.contains(choice.index())
                || q[choice.index()] >= value - TIE_TOLERANCE * value.max(1.0)
            {
                ties.insert(choice.index());
            }
        }
        meter.advance(1);
    }
    let eligible = |choice: ChoiceId| ties.contains(choice.index());
    let is_goal = |state: MdpState| mdp.is_absorbing(state) || lower[state.index()] == 0.0;
    let (ranked, order) = ranked_policy(mdp, &is_goal, &eligible, &q_lower, meter);
    meter.set(2 * n);
    let times = expected_moves(mdp, &order, &eligible, max_sweeps, meter);
    meter.set(3 * n);
    let time_of = |choice: ChoiceId| {
        let cost = if mdp.is_instant(choice) { 0.0 } else { 1.0 };
        cost + mdp
            .successors(choice)
            .map(|(t, p)| p * times[t.index()])
            .sum::<f64>()
    };
    let mut policy = vec![ChoiceId::NONE; mdp.num_states()];
    for &state in &order {
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
        if let Some((choice, _, _)) = best {
            policy[state.index()] = choice;
        }
        meter.advance(1);
    }
    for state in improper_states(mdp, &policy, &is_goal) {
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
/// elsewhere) and the non-goal states in increasing rank order.
fn ranked_policy(
    mdp: &Mdp,
    is_goal: &impl Fn(MdpState) -> bool,
    eligible: &impl Fn(ChoiceId) -> bool,
    q_lower: &impl Fn(ChoiceId) -> f64,
    meter: &mut Meter<'_>,
) -> (Vec<ChoiceId>, Vec<MdpState>) {
    // Only eligible choices rank a state.
    let predecessors = Predecessors::new(mdp, eligible);
    let mut policy = vec![ChoiceId::NONE; mdp.num_states()];
    let mut ranked = BitSet::with_capacity(mdp.num_states());
    let mut frontier: Vec<MdpState> = mdp.states().filter(|&s| is_goal(s)).collect();
    for &state in &frontier {
        ranked.insert(state.index());
    }
    let mut order = Vec::new();
    let mut candidates = Vec::new();
    let mut is_candidate = BitSet::with_capacity(mdp.num_states());
    while !frontier.is_empty() {
        candidates.clear();
        for &target in &frontier {
            for &owner in predecessors.of(target) {
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
        meter.advance(candidates.len() as u64);
        std::mem::swap(&mut frontier, &mut candidates);
    }
    (policy, order)
}

/// Approximates from below the least expected number of moves to a goal state using eligible
/// choices only, for the states of `order` (all other states count 0). The graph of eligible
/// choices is split into strongly connected components, solved in reverse topological order:
/// a trivial component in one step, others by Gauss–Seidel sweeps until no value rises by more
/// than `TIME_TOLERANCE` of itself, or `max_sweeps` ([`TimeSweeps`]: on compact copies, skipping
/// the states none of whose successors moved; ten times faster on 20x20 gridworlds than sweeps
/// over the model, with the same times to the bit).
fn expected_moves(
    mdp: &Mdp,
    order: &[MdpState],
    eligible: &impl Fn(ChoiceId) -> bool,
    max_sweeps: u32,
    meter: &mut Meter<'_>,
) -> Vec<f64> {
    let n = mdp.num_states();
    let mut counted = BitSet::with_capacity(n);
    for &state in order {
        counted.insert(state.index());
    }
    let mut graph: Csr<MdpState, MdpState> = Csr::with_capacity(n, n);
    for state in mdp.states() {
        if counted.contains(state.index()) {
            for choice in mdp.choices(state).filter(|&c| eligible(c)) {
                for &t in mdp.targets(choice) {
                    if counted.contains(t.index()) {
                        graph.push(t);
                    }
                }
            }
        }
        graph.finish_row();
    }
    let mut components = strongly_connected_components(&graph);
    // The graph is no longer needed (a self-loop is read from the model): free it before the
    // per-state arrays below are allocated.
    drop(graph);
    let mut times = vec![0.0f64; n];
    let update = |state: MdpState, times: &mut [f64]| {
        let best = mdp
            .choices(state)
            .filter(|&c| eligible(c))
            .map(|choice| {
                let cost = if mdp.is_instant(choice) { 0.0 } else { 1.0 };
                cost + mdp
                    .successors(choice)
                    .map(|(t, p)| p * times[t.index()])
                    .sum::<f64>()
            })
            .fold(f64::INFINITY, f64::min);
        let old = times[state.index()];
        times[state.index()] = best.max(old);
        best > old + TIME_TOLERANCE * old.max(1.0)
    };
    // Position of each counted state in `order` (increasing rank): a large component is swept
    // closest-to-goal first, so that every update sees fresh successors where it can.
    let mut rank_position = vec![u32::NONE; n];
    for (i, &state) in order.iter().enumerate() {
        rank_position[state.index()] = i as u32;
    }
    let mut scratch = TimeSweeps::new(n);
    for index in components.rows() {
        let component = components.row_mut(index);
        if !counted.contains(component[0].index()) {
            continue;
        }
        if component.len() > EXACT_LIMIT {
            component.sort_unstable_by_key(|&state| rank_position[state.index()]);
        }
        let component = &*component;
        let state = component[0];
        let trivial = component.len() == 1
            && !mdp
                .choices(state)
                .filter(|&c| eligible(c))
                .any(|c| mdp.targets(c).contains(&state));
        if trivial {
            update(component[0], &mut times);
        } else {
            scratch.sweep(mdp, component, eligible, &mut times, max_sweeps);
        }
        meter.advance(component.len() as u64);
    }
    times
}

/// One non-trivial component of the eligible choices' graph, copied into compact arrays for
/// [`expected_moves`]' sweeps: its states are numbered by their position in the sweep order,
/// the targets outside it get slots after them holding their (final) times, and each choice
/// keeps its transitions in the model's order, so that every update performs exactly the
/// floating-point operations of an update on the model (the same times, bit for bit) while a
/// sweep streams through memory instead of jumping across the whole model. The buffers are
/// reused from one component to the next.
#[derive(Default)]
struct TimeSweeps {
    /// Per model state, its slot while its component is swept (`u32::NONE` otherwise).
    slot: Vec<u32>,
    /// The states given a slot, to reset `slot` afterwards.
    slotted: Vec<MdpState>,
    /// Per slot, its time.
    values: Vec<f64>,
    /// Per member, the range of its eligible choices (rows of `targets`).
    member_offsets: Vec<u32>,
    /// Per eligible choice, its cost (1 for a move, 0 for an instant choice).
    costs: Vec<f64>,
    /// Per eligible choice, its target slots, with `probabilities` beside them.
    targets: Csr<u32, u32>,
    probabilities: Vec<f64>,
    /// Per member, the members with an eligible choice into it (to mark them for the next
    /// update when its time changes).
    sources: Csr<u32, u32>,
    /// The members whose successors' times changed since their last update (a byte each, as
    /// in `System::dirty`).
    dirty: Vec<bool>,
}

impl TimeSweeps {
    fn new(n: usize) -> Self {
        TimeSweeps {
            slot: vec![u32::NONE; n],
            ..TimeSweeps::default()
        }
    }

    /// Gauss–Seidel sweeps over `component` in its order until no time rises by more than
    /// `TIME_TOLERANCE` of itself, or `max_sweeps`; writes the times back into `times`. A member
    /// none of whose successors changed since its last update is skipped: updating it would
    /// recompute the same minimum and leave its time as it is.
    fn sweep(
        &mut self,
        mdp: &Mdp,
        component: &[MdpState],
        eligible: &impl Fn(ChoiceId) -> bool,
        times: &mut [f64],
        max_sweeps: u32,
    ) {
        let members = component.len();
        self.values.clear();
        self.slotted.clear();
        for (i, &state) in component.iter().enumerate() {
            self.slot[state.index()] = i as u32;
            self.values.push(times[state.index()]);
            self.slotted.push(state);
        }
        self.member_offsets.clear();
        self.member_offsets.push(0);
        self.costs.clear();
        self.targets = Csr::with_capacity(0, 0);
        self.probabilities.clear();
        let mut edges: Vec<(u32, u32)> = Vec::new();
        for (i, &state) in component.iter().enumerate() {
            for choice in mdp.choices(state).filter(|&c| eligible(c)) {
                self.costs
                    .push(if mdp.is_instant(choice) { 0.0 } else { 1.0 });
                for (target, probability) in mdp.successors(choice) {
                    let mut slot = self.slot[target.index()];
                    if slot.is_none() {
                        slot = self.values.len() as u32;
                        self.slot[target.index()] = slot;
                        self.values.push(times[target.index()]);
                        self.slotted.push(target);
                    }
                    if (slot as usize) < members {
                        edges.push((slot, i as u32));
                    }
                    self.targets.push(slot);
                    self.probabilities.push(probability);
                }
                self.targets.finish_row();
            }
            self.member_offsets.push(self.costs.len() as u32);
        }
        self.sources = Csr::group(members, edges.into_iter());
        self.dirty.clear();
        self.dirty.resize(members, true);
        for _ in 0..max_sweeps {
            let mut changed = false;
            for i in 0..members {
                if !std::mem::replace(&mut self.dirty[i], false) {
                    continue;
                }
                let choices = self.member_offsets[i]..self.member_offsets[i + 1];
                let best = choices
                    .map(|choice| {
                        self.costs[choice as usize]
                            + self
                                .targets
                                .row_with(choice, &self.probabilities)
                                .map(|(t, &p)| p * self.values[t as usize])
                                .sum::<f64>()
                    })
                    .fold(f64::INFINITY, f64::min);
                let old = self.values[i];
                let new = best.max(old);
                if new != old {
                    self.values[i] = new;
                    for &source in self.sources.row(i as u32) {
                        self.dirty[source as usize] = true;
                    }
                }
                changed |= best > old + TIME_TOLERANCE * old.max(1.0);
            }
            if !changed {
                break;
            }
        }
        for (i, &state) in component.iter().enumerate() {
            times[state.index()] = self.values[i];
        }
        for &state in &self.slotted {
            self.slot[state.index()] = u32::NONE;
        }
    }
}

/// The non-goal states from which `policy` does not reach a goal state with probability 1:
/// those that cannot reach one, and those that can reach, with positive probability, a state
/// that cannot.
fn improper_states(
    mdp: &Mdp,
    policy: &[ChoiceId],
    is_goal: &impl Fn(MdpState) -> bool,
) -> Vec<MdpState> {
    let n = mdp.num_states();
    // The policy's chain, reversed (grouped straight from the policy: no forward copy).
    let sources: Csr<MdpState, MdpState> = Csr::group(
        n,
        mdp.states().flat_map(|state| {
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

/// The choice of largest `value`, the lowest id among exact ties; `None` if there is none.
fn best_choice(
    choices: impl Iterator<Item = ChoiceId>,
    value: impl Fn(ChoiceId) -> f64,
) -> Option<ChoiceId> {
    let mut best: Option<(ChoiceId, f64)> = None;
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
    use super::*;
    use crate::mdp::testing::{
        Spec::{Absorb, Decide},
        chain_mdp, mc, mdp_from, ms, optimal_values_by_enumeration, policy_value, random_mdp,
        random_mdp_with_weights, rng,
    };

    fn options(g: f64) -> SolveOptions {
        SolveOptions {
            discount: Discount::new(g).unwrap(),
            ..SolveOptions::default()
        }
    }

    /// Asserts that the certified interval of every state contains `expected` and is at most
    /// epsilon wide.
    fn assert_values(solution: &Solution, expected: &[f64]) {
        for (state, &value) in expected.iter().enumerate() {
            let Interval { lower, upper } = solution.value(MdpState::new(state));
            assert!(
                lower <= value + 1e-12 && value <= upper + 1e-12 && upper - lower <= 1e-6,
                "state {state}: expected {value}, got [{lower}, {upper}]"
            );
        }
    }

    #[test]
    fn stop_beats_a_risky_action_unless_the_risk_is_small() {
        // 0 --stop--> 1 (payoff 200); 0 --risky--> 2 (payoff 300) w.p. p, 3 (payoff 0) w.p. 1-p.
        let build = |p: f64| {
            mdp_from(&[
                Decide(&[("stop", &[(1, 1.0)]), ("risky", &[(2, p), (3, 1.0 - p)])]),
                Absorb(200.0),
                Absorb(300.0),
                Absorb(0.0),
            ])
        };
        // p = 0.6, g = 1: stop = 200, risky = 0.6 · 300 = 180 → stop.
        let solution = solve(&build(0.6), &options(1.0)).unwrap();
        assert_values(&solution, &[200.0, 200.0, 300.0, 0.0]);
        assert_eq!(solution.policy(ms(0)), Some(mc(0)));
        assert_eq!(solution.policy(ms(1)), None);
        // p = 0.6, g = 0.9: stop = 0.9 · 200 = 180, risky = 0.9 · 180 = 162 → stop.
        let solution = solve(&build(0.6), &options(0.9)).unwrap();
        assert_values(&solution, &[180.0]);
        assert_eq!(solution.policy(ms(0)), Some(mc(0)));
        // p = 0.7, g = 1: risky = 0.7 · 300 = 210 > 200 → risky.
        let solution = solve(&build(0.7), &options(1.0)).unwrap();
        assert_values(&solution, &[210.0]);
        assert_eq!(solution.policy(ms(0)), Some(mc(1)));
        // The decision table's Q-values: stop 200, risky 210.
        let mdp = build(0.7);
        assert!((solution.choice_value(&mdp, mc(0)).midpoint() - 200.0).abs() < 1e-9);
        assert!((solution.choice_value(&mdp, mc(1)).midpoint() - 210.0).abs() < 1e-9);
    }

    #[test]
    fn discount_prefers_near_payoffs() {
        // 0 --stop--> 4 (payoff 5); 0 --walk--> 1 --walk--> 2 --walk--> 3 (payoff 8).
        let mdp = mdp_from(&[
            Decide(&[("stop", &[(4, 1.0)]), ("walk", &[(1, 1.0)])]),
            Decide(&[("walk", &[(2, 1.0)])]),
            Decide(&[("walk", &[(3, 1.0)])]),
            Absorb(8.0),
            Absorb(5.0),
        ]);
        // g = 1: walking is worth 8 > 5.
        let solution = solve(&mdp, &options(1.0)).unwrap();
        assert_values(&solution, &[8.0, 8.0, 8.0, 8.0, 5.0]);
        assert_eq!(solution.policy(ms(0)), Some(mc(1)));
        // g = 0.9: walk = 0.9³ · 8 = 5.832 > stop = 0.9 · 5 = 4.5; V1 = 0.9² · 8, V2 = 0.9 · 8.
        let solution = solve(&mdp, &options(0.9)).unwrap();
        assert_values(&solution, &[5.832, 6.48, 7.2]);
        assert_eq!(solution.policy(ms(0)), Some(mc(1)));
        // g = 0.5: walk = 0.125 · 8 = 1 < stop = 0.5 · 5 = 2.5.
        let solution = solve(&mdp, &options(0.5)).unwrap();
        assert_values(&solution, &[2.5, 2.0, 4.0]);
        assert_eq!(solution.policy(ms(0)), Some(mc(0)));
    }

    /// 0 and 1 form an end component (go / back); `try` leaves it towards payoff 10 half the
    /// time, `cash` takes payoff 4. State 4 reaches payoff 20 elsewhere, so the upper sequence
    /// starts at 20 and only the end-component collapse lets it come down to 10.
    fn end_component_mdp() -> Mdp {
        mdp_from(&[
            Decide(&[("go", &[(1, 1.0)]), ("cash", &[(3, 1.0)])]),
            Decide(&[("back", &[(0, 1.0)]), ("try", &[(2, 0.5), (0, 0.5)])]),
            Absorb(10.0),
            Absorb(4.0),
            Decide(&[("jump", &[(5, 1.0)])]),
            Absorb(20.0),
        ])
    }

    #[test]
    fn end_component_is_left_by_the_policy_when_everything_ties() {
        let mdp = end_component_mdp();
        let solution = solve(&mdp, &options(1.0)).unwrap();
        // g = 1: from 0 or 1, retrying `try` reaches 2 with probability 1: value 10 (> cash 4).
        assert_values(&solution, &[10.0, 10.0, 10.0, 4.0, 20.0, 20.0]);
        assert_eq!(solution.end_components(), 1);
        // In 1, `back` (choice 2) and `try` (choice 3) both have Q-value 10; the lowest id would
        // loop 0 → 1 → 0 forever and collect 0. The policy must take `try`.
        assert_eq!(solution.policy(ms(0)), Some(mc(0)));
        assert_eq!(solution.policy(ms(1)), Some(mc(3)));
        let value = policy_value(
            &mdp,
            &mdp.states().map(|s| solution.policy(s)).collect::<Vec<_>>(),
            1.0,
        );
        assert_eq!(value, vec![10.0, 10.0, 10.0, 4.0, 20.0, 20.0]);
    }

    #[test]
    fn end_component_with_discount_is_not_collapsed() {
        let solution = solve(&end_component_mdp(), &options(0.9)).unwrap();
        // g = 0.9, guessing go in 0 and try in 1:
        //   V0 = 0.9 V1, V1 = 0.9 (0.5 · 10 + 0.5 V0) = 4.5 + 0.45 V0
        //   ⇒ V0 = 4.05 + 0.405 V0 ⇒ V0 = 4.05 / 0.595 = 810/119, V1 = 900/119.
        // The guess holds: cash = 0.9 · 4 = 3.6 < 810/119 ≈ 6.81 and back = 0.9 V0 = 729/119 < V1.
        assert_values(
            &solution,
            &[810.0 / 119.0, 900.0 / 119.0, 10.0, 4.0, 18.0, 20.0],
        );
        assert_eq!(solution.end_components(), 0);
        assert_eq!(solution.policy(ms(0)), Some(mc(0)));
        assert_eq!(solution.policy(ms(1)), Some(mc(3)));
    }

    #[test]
    fn states_that_cannot_reach_a_payoff_are_fixed_to_zero() {
        // 1 can only loop or drop into 4 (payoff 0); 5 can loop or go to 1: both are worth 0
        // exactly. 0: a → 1 is worth 0, b is worth 0.5 · 0 + 0.5 · 6 = 3.
        let mdp = mdp_from(&[
            Decide(&[("a", &[(1, 1.0)]), ("b", &[(2, 0.5), (3, 0.5)])]),
            Decide(&[("loop", &[(1, 1.0)]), ("drop", &[(4, 1.0)])]),
            Absorb(0.0),
            Absorb(6.0),
            Absorb(0.0),
            Decide(&[("x", &[(5, 1.0)]), ("y", &[(1, 1.0)])]),
        ]);
        let solution = solve(&mdp, &options(1.0)).unwrap();
        for state in [1, 5] {
            assert_eq!(
                solution.value(ms(state)),
                Interval {
                    lower: 0.0,
                    upper: 0.0
                }
            );
        }
        // Only state 0 is iterated, and its successors are all fixed: a trivial component, one
        // exact step and no sweep.
        assert_eq!(
            solution.value(ms(0)),
            Interval {
                lower: 3.0,
                upper: 3.0
            }
        );
        assert_eq!(solution.iterations(), 0);
        assert_eq!(solution.gap(), 0.0);
        assert_eq!(solution.end_components(), 0);
        assert_eq!(solution.policy(ms(0)), Some(mc(1)));
    }

    #[test]
    fn tiny_exits_are_solved_exactly_and_large_slow_components_hit_the_limit() {
        // try: payoff 1 w.p. 1e-9, else back to 0: value iteration would need about 1.4e10
        // sweeps; after its quick sweeps, policy iteration solves the one-state component
        // exactly in one round.
        let mdp = mdp_from(&[
            Decide(&[("try", &[(1, 1e-9), (0, 1.0 - 1e-9)])]),
            Absorb(1.0),
        ]);
        let solution = solve(&mdp, &SolveOptions::default()).unwrap();
        assert_values(&solution, &[1.0, 1.0]);
        assert_eq!(solution.iterations(), QUICK_SWEEPS + 1);
        // A ring of 300 states (more than policy iteration takes), each moving on w.p. 0.999
        // and to payoff 1 w.p. 0.001: sweeps are needed, and 10 are not enough.
        let n = 300u32;
        let states: Vec<Vec<(u32, f64)>> = (0..n)
            .map(|i| vec![((i + 1) % n, 0.999), (n, 0.001)])
            .collect();
        let ring = chain_mdp(&states, &[1.0]);
        let limited = SolveOptions {
            max_iterations: 10,
            ..SolveOptions::default()
        };
        match solve(&ring, &limited) {
            Err(SolveError::IterationLimit {
                iterations: 10,
                gap,
                epsilon,
            }) => {
                assert!(gap > 1e-3, "{gap}");
                assert_eq!(epsilon, 1e-6);
            }
            other => panic!(
                "expected the iteration limit, got {:?}",
                other.map(|s| s.gap())
            ),
        }
        let solution = solve(&ring, &SolveOptions::default()).unwrap();
        assert_values(&solution, &vec![1.0; n as usize + 1]);
    }

    #[test]
    fn tiny_exit_probabilities_and_deep_chains_agree_with_exact_evaluation() {
        let mut rng = rng(12);
        for instance in 0..200 {
            let mdp = random_mdp_with_weights(&mut rng, 8, &[1.0, 1e6]);
            let g = if instance % 2 == 0 { 1.0 } else { 0.9 };
            let solution = solve(&mdp, &options(g)).unwrap();
            let optimal = optimal_values_by_enumeration(&mdp, g);
            let policy: Vec<Option<ChoiceId>> = mdp.states().map(|s| solution.policy(s)).collect();
            let achieved = policy_value(&mdp, &policy, g);
            for s in 0..mdp.num_states() {
                let Interval { lower, upper } = solution.value(MdpState::new(s));
                let context = format!(
                    "instance {instance}, g = {g}, state {s}: [{lower}, {upper}] optimal {} achieved {}: {mdp:?}",
                    optimal[s], achieved[s]
                );
                assert!(upper - lower <= 1e-6, "{context}");
                assert!(
                    lower <= optimal[s] + 1e-7 && optimal[s] <= upper + 1e-7,
                    "{context}"
                );
                assert!(achieved[s] >= lower - 1e-6, "{context}");
            }
        }
        // A chain of 1000 states, each leaving to payoff 1 w.p. 1e-6 and otherwise moving on;
        // the last pays 5; then the same chain closed into a ring (one component larger than
        // policy iteration takes, left only through the 1e-6 exits).
        let n = 1000u32;
        let p = 1e-6;
        for ring in [false, true] {
            let choices: Vec<Vec<(u32, f64)>> = (0..n)
                .map(|i| {
                    let next = if i + 1 < n {
                        i + 1
                    } else if ring {
                        0
                    } else {
                        n + 1
                    };
                    vec![(next, 1.0 - p), (n, p)]
                })
                .collect();
            let mdp = chain_mdp(&choices, &[1.0, 5.0]);
            let solution = solve(&mdp, &options(1.0)).unwrap();
            // Backwards: V(n-1) = (1-p)·5 + p, V(i) = (1-p)·V(i+1) + p; on the ring every
            // state is worth 1 (the exits are the only payoff).
            let mut expected = vec![1.0; n as usize];
            if !ring {
                let mut next = 5.0;
                for i in (0..n as usize).rev() {
                    expected[i] = (1.0 - p) * next + p;
                    next = expected[i];
                }
            }
            assert_values(&solution, &expected);
        }
    }

    #[test]
    fn bad_epsilon_and_discount_are_typed_errors() {
        for g in [0.0, -0.5, 1.5, f64::NAN, f64::INFINITY] {
            assert!(
                matches!(Discount::new(g), Err(SolveError::InvalidDiscount(_))),
                "{g}"
            );
        }
        assert_eq!(Discount::new(1.0), Ok(Discount::NONE));
        let mdp = mdp_from(&[Absorb(1.0)]);
        for epsilon in [0.0, -1e-6, f64::NAN, f64::INFINITY] {
            let options = SolveOptions {
                epsilon,
                ..SolveOptions::default()
            };
            assert!(
                matches!(solve(&mdp, &options), Err(SolveError::InvalidEpsilon(_))),
                "{epsilon}"
            );
        }
    }

    #[test]
    fn random_mdps_are_solved_with_certified_bounds_and_an_optimal_policy() {
        let epsilon = 1e-6;
        let tolerance = 1e-9;
        let mut rng = rng(7);
        for instance in 0..200 {
            let mdp = random_mdp(&mut rng, 8);
            let g = if instance % 2 == 0 { 1.0 } else { 0.9 };
            let solution = solve(&mdp, &options(g)).unwrap();
            assert!(solution.gap() <= epsilon);
            let optimal = optimal_values_by_enumeration(&mdp, g);
            let policy: Vec<Option<ChoiceId>> = mdp.states().map(|s| solution.policy(s)).collect();
            let achieved = policy_value(&mdp, &policy, g);
            for s in mdp.states() {
                let Interval { lower, upper } = solution.value(s);
                let context = format!("instance {instance}, g = {g}, state {s}: {mdp:?}");
                assert!(upper - lower <= epsilon, "{context}");
                assert!(lower <= optimal[s.index()] + tolerance, "{context}");
                assert!(optimal[s.index()] <= upper + tolerance, "{context}");
                // The policy attains the certified lower bound, hence is epsilon-optimal.
                assert!(achieved[s.index()] >= lower - tolerance, "{context}");
                assert!(achieved[s.index()] <= upper + tolerance, "{context}");
                // Every Q-value interval contains the exact g · Σ P · V*.
                for choice in mdp.choices(s) {
                    let exact: f64 = g * mdp
                        .successors(choice)
                        .map(|(t, p)| p * optimal[t.index()])
                        .sum::<f64>();
                    let q = solution.choice_value(&mdp, choice);
                    assert!(
                        q.lower <= exact + tolerance && exact <= q.upper + tolerance,
                        "{context}"
                    );
                }
            }
            // No single deviation improves the policy's exact value by more than epsilon.
            for s in mdp.states() {
                for choice in mdp.choices(s) {
                    let mut deviation = policy.clone();
                    deviation[s.index()] = Some(choice);
                    let value = policy_value(&mdp, &deviation, g);
                    for t in 0..mdp.num_states() {
                        assert!(
                            value[t] <= achieved[t] + epsilon + tolerance,
                            "instance {instance}: playing {choice} in {s} improves state {t}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn a_false_end_component_does_not_share_its_best_exit() {
        // 0 → 1, or cash 100; 1: b reaches 0 or 2 (worth 1) half and half, c loops. {0, 1}
        // looks strongly connected through b, but b leaves it: 1 is worth 0.5 · 100 + 0.5 · 1,
        // not the 100 of 0, which a false end component {0, 1} would give it.
        let mdp = mdp_from(&[
            Decide(&[("a", &[(1, 1.0)]), ("cash", &[(4, 1.0)])]),
            Decide(&[("b", &[(0, 0.5), (2, 0.5)]), ("c", &[(1, 1.0)])]),
            Decide(&[("s", &[(3, 1.0)])]),
            Absorb(1.0),
            Absorb(100.0),
        ]);
        let solution = solve(&mdp, &options(1.0)).unwrap();
        assert_values(&solution, &[100.0, 50.5, 1.0, 1.0, 100.0]);
        assert_eq!(solution.end_components(), 1);
    }
}

//! The controller evaluated as a Markov chain: what it really collects, independently of how the
//! solver computed the values it reports (docs/semantics.md §6, "the controller's real expected payoff
//! equals the reported value").
//!
//! ```text
//! uncommitted robot state  -- Controller::decide -->  move (factor g, one robot move), or the end:
//!                             commit / stop to task T pays r(T) · P_T(h), give up pays 0
//! adversary state          -- the adversary model --> its successors (no factor, no move);
//!                             stuck: pays r; worth 0: ends (the controller gives up there)
//! committed to T           -- reactive strategy of T and the adversary model -->
//!                             P_T(h) = probability of reaching T's targets (a stuck adversary
//!                             counts as reached, as the attractor counts it won)
//! ```
//!
//! The chains (uncommitted, and one per task committed to: phi1, phi2, phi in the paper's form, a
//! set of sub-tasks in the general one, see [`Plan`]) are solved one strongly
//! connected component at a time in reverse topological order: a trivial component is one exact
//! step; inside a non-trivial one a lower sequence from 0 and an upper one from the largest
//! value its exits can give are iterated (Gauss–Seidel) until they are within epsilon. A
//! component the chain can never leave collects 0. The expected number of robot moves until the
//! controller commits, gives up or meets a stuck adversary is computed on the same components
//! (iterated from 0 until it changes by less than 1e-12 of itself, or the sweep limit; infinite
//! where the chain can reach a component it never leaves). A component of at most 200 states
//! that 64 sweeps do not settle (an exit of tiny probability) is solved exactly instead
//! (`mdp::linear`, widened by a relative 1e-12 for rounding). This shares nothing with
//! the solver but the graph's component search and that elimination.
//!
//! Cost: O(|H| + |edges|) per sweep of a non-trivial component; memory a few words per product
//! state. A chain state's lower bound, upper bound and time sit side by side (`[f64; 3]`): a
//! sweep reads all three of every successor, scattered over the product, and one cache line
//! instead of three took the evaluation stage of the 24x24 gridworld at g = 1 (random sigma_L)
//! from 1.5–2.0 s to 1.3–1.6 s, with the same values to the bit (`benches/README.md`, "Policy
//! and evaluation stages"). A component of more than 200 states is swept over a compact copy
//! (its states in sweep order, then one slot per transition leaving it), with the same sums in
//! the same order, so the same values to the bit: the sweeps read a few megabytes in order
//! instead of successors scattered over the product (the 30x30 map's 150k-state component,
//! 163 sweeps: the evaluation stage took 3.0–3.1 s instead of 5.1–5.4 on the quiet machine).
//! What is left is building the chains and the component search over each.

use thiserror::Error;

use super::adversary::AdversaryModel;
use super::controller::Decision;
use super::view::GameView;
use crate::arena::ActionId;
use crate::csr::Csr;
use crate::game::{HState, TaskSet};
use crate::mdp::graph::strongly_connected_components;
use crate::mdp::linear::Transient;
use crate::mdp::solve::Interval;
use crate::stage::{Meter, Stage};

/// Sweeps after which a small component still unsettled is solved exactly, and how small.
const EXACT_AFTER: u32 = 64;
const EXACT_LIMIT: usize = 200;

/// Chain states solved between two progress reports.
const BATCH: usize = 1 << 14;

/// Why the controller could not be evaluated.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum EvaluationError {
    #[error(
        "evaluating the controller did not reach precision {epsilon} within {iterations} \
         iterations (the gap is still {gap})"
    )]
    /// A non-trivial component's lower and upper values were still more than `epsilon` apart after
    /// the sweep limit.
    NotConverged {
        /// The sweeps made in that component (the limit).
        iterations: u32,
        /// The largest `upper − lower` in the component after the last sweep.
        gap: f64,
        /// The precision asked for.
        epsilon: f64,
    },
}

/// The value of the controller from every product state, and its expected number of robot moves.
#[derive(Clone, Debug, PartialEq)]
pub struct ControllerEvaluation {
    /// Per product state: lower and upper bounds on the value, expected moves.
    values: Vec<[f64; 3]>,
}

/// What the evaluation and the simulation need of a controller (the in-process
/// [`super::controller::Controller`], or one loaded from an exported file): its step in every
/// robot state before it commits, and, for each goal it can commit to (numbered
/// `0..num_goals()`), that goal's targets and reactive strategy.
pub trait Plan: Steps {
    /// How the controller sees the product game.
    type Game: GameView;
    /// The game the controller plays in.
    fn game(&self) -> &Self::Game;
}

/// A controller's steps, whatever game it plays in: the part of a [`Plan`] that a run reads
/// (the simulation's, over either engine's product).
pub trait Steps {
    /// The number of goal ids, `2^k`: goal `m` is the set of sub-tasks of mask `m` (0, the
    /// empty set, is never committed to).
    fn num_goals(&self) -> usize;
    /// Whether `h` satisfies `goal` already.
    fn is_goal_target(&self, goal: usize, h: HState) -> bool;
    /// The move (action, successor) of `goal`'s reactive strategy in robot state `h`, if any.
    fn goal_move(&self, goal: usize, h: HState) -> Option<(ActionId, HState)>;
    /// What the controller does in robot state `h` before committing.
    fn step(&self, h: HState) -> Step;
    /// What meeting a stuck adversary before committing pays.
    fn stuck_payoff(&self) -> f64;
    /// Whether `h` is worth exactly 0 (the controller gives up on reaching it).
    fn is_worthless(&self, h: HState) -> bool;
    /// The discount factor g.
    fn discount(&self) -> f64;
}

/// A controller's step in a robot state before it commits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Step {
    /// One robot move: `action` to `successor`.
    Move {
        /// The arena action played.
        action: ActionId,
        /// The product state it leads to.
        successor: HState,
    },
    /// Commit to `goal` here, for `payoff` once it is satisfied: where the MDP absorbs, or by
    /// playing `stop` (`stop: true`).
    Commit {
        /// The goal committed to, in `0..num_goals()`.
        goal: usize,
        /// What satisfying the goal pays (before discounting).
        payoff: f64,
        /// Whether the robot commits by playing `stop` rather than because the MDP absorbs `h`.
        stop: bool,
    },
    /// A state of value 0: the controller gives up, collecting 0.
    GiveUp,
}

impl Step {
    /// The step of a controller's `decision`, a commitment paying `payoff(set)`.
    pub fn of(decision: Decision, payoff: impl Fn(TaskSet) -> f64) -> Step {
        let commit = |set: TaskSet, stop| Step::Commit {
            goal: set.0 as usize,
            payoff: payoff(set),
            stop,
        };
        match decision {
            Decision::Move { action, successor } => Step::Move { action, successor },
            Decision::Commit(set) => commit(set, false),
            Decision::Stop(set) => commit(set, true),
            Decision::GiveUp => Step::GiveUp,
        }
    }
}

impl ControllerEvaluation {
    /// Evaluates `controller` against `adversary` with values certified to within `epsilon`,
    /// iterating at most `max_iterations` sweeps in any one component.
    pub fn new(
        controller: &impl Plan,
        adversary: &AdversaryModel,
        epsilon: f64,
        max_iterations: u32,
    ) -> Result<ControllerEvaluation, EvaluationError> {
        ControllerEvaluation::new_metered(
            controller,
            adversary,
            epsilon,
            max_iterations,
            &mut Meter::unobserved(Stage::Evaluation),
        )
    }

    /// [`ControllerEvaluation::new`], reporting to `meter` the chain states solved out of the
    /// product's times the chains.
    ///
    /// The chains of the goals committed to are independent of each other, but they are
    /// solved one after another: solved two at a time (rayon) they saved about 0.2 s of 1 s on
    /// the 24x24 gridworld and held a second chain in memory, 80 MB more at the process's peak.
    pub fn new_metered(
        controller: &impl Plan,
        adversary: &AdversaryModel,
        epsilon: f64,
        max_iterations: u32,
        meter: &mut Meter<'_>,
    ) -> Result<ControllerEvaluation, EvaluationError> {
        let game = controller.game();
        let n = game.num_states();
        let limits = SweepLimits {
            epsilon,
            max_iterations,
            compact_above: EXACT_LIMIT,
        };
        let adversary_step = |chain: &mut Chain, h: HState, distribution: &mut Vec<f64>| {
            adversary.distribution(game, h, distribution);
            let successors = game.edges(h).zip(&*distribution).map(|((_, t), &p)| (t, p));
            chain.step(1.0, 0.0, successors);
        };
        let steps: Vec<Option<Step>> = game
            .states()
            .map(|h| game.is_robot(h).then(|| controller.step(h)))
            .collect();
        // P_T for each goal committed to somewhere (empty for the others), in the order of
        // the first state committing to it.
        let mut goals: Vec<usize> = Vec::new();
        let mut seen = vec![false; controller.num_goals()];
        for step in steps.iter().flatten() {
            if let &Step::Commit { goal, .. } = step
                && !std::mem::replace(&mut seen[goal], true)
            {
                goals.push(goal);
            }
        }
        meter.set_total((goals.len() as u64 + 1) * n as u64);
        let mut reached: Vec<Option<ChainValues>> =
            (0..controller.num_goals()).map(|_| None).collect();
        let mut distribution = Vec::new();
        for &goal in &goals {
            let mut chain = Chain::with_capacity(n);
            for h in game.states() {
                if controller.is_goal_target(goal, h) {
                    chain.end(1.0, 1.0);
                } else if game.is_robot(h) {
                    match controller.goal_move(goal, h) {
                        Some((_, t)) => chain.step(1.0, 0.0, [(t, 1.0)]),
                        None => chain.end(0.0, 0.0),
                    }
                } else if game.edges(h).next().is_none() {
                    chain.end(1.0, 1.0);
                } else {
                    adversary_step(&mut chain, h, &mut distribution);
                }
            }
            reached[goal] = Some(chain.solve(limits, &mut |units| meter.advance(units))?);
        }
        let g = controller.discount();
        let r = controller.stuck_payoff();
        let mut chain = Chain::with_capacity(n);
        for h in game.states() {
            match steps[h.index()] {
                Some(Step::Move { successor, .. }) => chain.step(g, 1.0, [(successor, 1.0)]),
                Some(Step::Commit { goal, payoff, .. }) => {
                    let reached = reached[goal]
                        .as_ref()
                        .expect("computed for every goal used");
                    let [lower, upper, _] = reached.0[h.index()];
                    chain.end(payoff * lower, payoff * upper);
                }
                Some(Step::GiveUp) => chain.end(0.0, 0.0),
                None if game.edges(h).next().is_none() => chain.end(r, r),
                None if controller.is_worthless(h) => chain.end(0.0, 0.0),
                None => adversary_step(&mut chain, h, &mut distribution),
            }
        }
        let values = chain.solve(limits, &mut |units| meter.advance(units))?;
        Ok(ControllerEvaluation { values: values.0 })
    }

    /// Bounds on the controller's expected payoff from product state `h`.
    pub fn value(&self, h: HState) -> Interval {
        let [lower, upper, _] = self.values[h.index()];
        Interval { lower, upper }
    }

    /// The controller's expected number of robot moves from product state `h` until it
    /// commits, gives up or the adversary is stuck (infinite when that is not certain).
    pub fn expected_moves(&self, h: HState) -> f64 {
        self.values[h.index()][2]
    }
}

/// Per chain state: `[lower, upper, time]`, bounds on its value and its expected cost. The
/// three sit side by side because a sweep reads all three of each successor: one cache line
/// where three arrays cost three (the sweeps of the 24x24 gridworld's chains are bound by these
/// scattered reads).
struct ChainValues(Vec<[f64; 3]>);

/// When a component's sweeps stop (shared with the implicit engine's evaluation,
/// `implicit/policy.rs`).
#[derive(Clone, Copy)]
pub(crate) struct SweepLimits {
    pub(crate) epsilon: f64,
    pub(crate) max_iterations: u32,
    /// Components larger than this are swept over a compact copy ([`Compact`]).
    pub(crate) compact_above: usize,
}

impl SweepLimits {
    /// Whether a component whose last sweep left bounds `gap` apart and moved a time by
    /// `change` of itself is solved: its values within epsilon, and its times settled unless
    /// they are infinite anyway (`endless`).
    pub(crate) fn converged(self, gap: f64, change: f64, endless: bool) -> bool {
        gap <= self.epsilon && (endless || change <= 1e-12)
    }

    /// After `iterations` sweeps: nothing while sweeps are left; at the limit, done if the
    /// values are certified (the time is then a close lower estimate), else the error.
    pub(crate) fn out_of_sweeps(
        self,
        iterations: u32,
        gap: f64,
    ) -> Option<Result<(), EvaluationError>> {
        if iterations < self.max_iterations {
            return None;
        }
        Some(if gap <= self.epsilon {
            Ok(())
        } else {
            Err(EvaluationError::NotConverged {
                iterations,
                gap,
                epsilon: self.epsilon,
            })
        })
    }
}

/// One Gauss–Seidel update of a chain state from its `[factor, cost]`, its old
/// `[lower, upper, time]` and its successors' values with their probabilities, in the chain's
/// order: its new values (the bounds kept monotone), their width, and the change of its time
/// relative to it. The one update of both sweeps, over the product and over a [`Compact`] copy.
#[inline(always)]
pub(crate) fn step(
    [factor, cost]: [f64; 2],
    [old_lower, old_upper, old_time]: [f64; 3],
    successors: impl Iterator<Item = ([f64; 3], f64)>,
) -> ([f64; 3], f64, f64) {
    let (mut l, mut u, mut t) = (0.0, 0.0, cost);
    for ([target_lower, target_upper, target_time], p) in successors {
        l += p * target_lower;
        u += p * target_upper;
        t += p * target_time;
    }
    let (l, u) = ((factor * l).max(old_lower), (factor * u).min(old_upper));
    ([l, u, t], u - l, (t - old_time).abs() / t.max(1.0))
}

/// A Markov chain over the product states with a payoff interval on its ending states; each
/// other state has a factor applied to its successors' values and a cost counted in the
/// expected time.
struct Chain {
    /// Per state, its successors of positive probability, with `probabilities` beside them.
    successors: Csr<HState, HState>,
    probabilities: Vec<f64>,
    /// Per state: `[factor, cost]` of a step, or `[lower, upper]` payoff of an end.
    parameters: Vec<[f64; 2]>,
    ends: bit_set::BitSet,
}

impl Chain {
    fn with_capacity(n: usize) -> Chain {
        Chain {
            successors: Csr::with_capacity(n, n),
            probabilities: Vec::with_capacity(n),
            parameters: Vec::with_capacity(n),
            ends: bit_set::BitSet::with_capacity(n),
        }
    }

    fn end(&mut self, lower: f64, upper: f64) {
        self.ends.insert(self.parameters.len());
        self.parameters.push([lower, upper]);
        self.successors.finish_row();
    }

    /// A step to the successors of positive probability.
    fn step(
        &mut self,
        factor: f64,
        cost: f64,
        successors: impl IntoIterator<Item = (HState, f64)>,
    ) {
        for (t, p) in successors {
            if p > 0.0 {
                self.successors.push(t);
                self.probabilities.push(p);
            }
        }
        self.parameters.push([factor, cost]);
        self.successors.finish_row();
    }

    /// Lower and upper values and expected costs of every state; tells `progress` how many
    /// states are solved, in batches.
    fn solve(
        &self,
        limits: SweepLimits,
        progress: &mut dyn FnMut(u64),
    ) -> Result<ChainValues, EvaluationError> {
        let n = self.parameters.len();
        let mut values = vec![[0.0; 3]; n];
        let components = strongly_connected_components(&self.successors);
        let mut in_component = bit_set::BitSet::with_capacity(n);
        let mut solved = 0;
        for index in components.rows() {
            let component = components.row(index);
            for &v in component {
                in_component.insert(v.index());
            }
            self.solve_component(component, &in_component, limits, &mut values)?;
            for &v in component {
                in_component.remove(v.index());
            }
            solved += component.len();
            if solved >= BATCH {
                progress(solved as u64);
                solved = 0;
            }
        }
        progress(solved as u64);
        Ok(ChainValues(values))
    }

    fn transitions(&self, v: HState) -> impl Iterator<Item = (HState, f64)> + '_ {
        self.successors
            .row_with(v, &self.probabilities)
            .map(|(target, &probability)| (target, probability))
    }

    fn solve_component(
        &self,
        component: &[HState],
        inside: &bit_set::BitSet,
        limits: SweepLimits,
        values: &mut [[f64; 3]],
    ) -> Result<(), EvaluationError> {
        // One Gauss–Seidel update of `v` for the values (both bounds) and the time; returns the
        // changes. Successors outside the component are final already.
        let update = |v: HState, values: &mut [[f64; 3]]| {
            let successors = self.transitions(v).map(|(t, p)| (values[t.index()], p));
            let (new, width, change) =
                step(self.parameters[v.index()], values[v.index()], successors);
            values[v.index()] = new;
            (width, change)
        };
        if let [v] = component
            && !self.transitions(*v).any(|(t, _)| t == *v)
        {
            if self.ends.contains(v.index()) {
                let [l, u] = self.parameters[v.index()];
                values[v.index()] = [l, u, 0.0];
            } else {
                values[v.index()][1] = f64::INFINITY;
                update(*v, values);
            }
            return Ok(());
        }
        // Where the chain leaves the component: the largest value it can bring back, and whether
        // it can reach a place it never leaves (infinite time).
        let mut exits = false;
        let mut ceiling = 0.0f64;
        let mut endless = false;
        for &v in component {
            for (t, _) in self.transitions(v) {
                if !inside.contains(t.index()) {
                    exits = true;
                    let [_, upper, time] = values[t.index()];
                    ceiling = ceiling.max(upper);
                    endless |= time.is_infinite();
                }
            }
        }
        if !exits {
            for &v in component {
                values[v.index()] = [0.0, 0.0, f64::INFINITY];
            }
            return Ok(());
        }
        for &v in component {
            values[v.index()][1] = ceiling;
        }
        if component.len() > limits.compact_above {
            return Compact::new(self, component, values).solve(component, endless, limits, values);
        }
        let mut iterations = 0;
        loop {
            let (mut gap, mut change) = (0.0f64, 0.0f64);
            for &v in component {
                let (g, c) = update(v, values);
                gap = gap.max(g);
                change = change.max(c);
            }
            iterations += 1;
            if limits.converged(gap, change, endless) {
                break;
            }
            if iterations == EXACT_AFTER
                && component.len() <= EXACT_LIMIT
                && self.solve_exactly(component, inside, endless, values)
            {
                break;
            }
            if let Some(outcome) = limits.out_of_sweeps(iterations, gap) {
                outcome?;
                break;
            }
        }
        if endless {
            for &v in component {
                values[v.index()][2] = f64::INFINITY;
            }
        }
        Ok(())
    }

    /// The component's values and times solved exactly ([`Transient`]), from its exits' bounds
    /// and times, for a small component that sweeps do not settle (an exit of tiny probability
    /// takes about `1 / p` sweeps). Values: `x = f · (P_inside x + P_outside v)`, leak
    /// `f · P_outside + 1 − f`; times: `t = c + P_inside t + P_outside t'`, leak `P_outside`.
    /// Each bound is widened by a relative 1e-12 for the elimination's rounding, and kept
    /// within the bounds the sweeps reached. Returns whether the values were solved (if not,
    /// nothing changed and the sweeps go on).
    fn solve_exactly(
        &self,
        component: &[HState],
        inside: &bit_set::BitSet,
        endless: bool,
        values: &mut [[f64; 3]],
    ) -> bool {
        let position = |h: HState| component.iter().position(|&v| v == h);
        let mut bounds = Transient::<2>::new(component.len());
        let mut times = Transient::<1>::new(component.len());
        for (i, &v) in component.iter().enumerate() {
            let [factor, cost] = self.parameters[v.index()];
            let mut outside = 0.0;
            times.add_rhs(i, [cost]);
            for (t, p) in self.transitions(v) {
                if inside.contains(t.index()) {
                    let j = position(t).expect("a state of the component");
                    bounds.add_weight(i, j, factor * p);
                    times.add_weight(i, j, p);
                } else {
                    outside += p;
                    let [lower, upper, time] = values[t.index()];
                    bounds.add_rhs(i, [factor * p * lower, factor * p * upper]);
                    times.add_rhs(i, [p * time]);
                }
            }
            bounds.add_leak(i, factor * outside + (1.0 - factor));
            times.add_leak(i, outside);
        }
        // Every state of a component with an exit leaks through it, so both systems solve; a
        // pivot lost to underflow would leave the sweeps to go on.
        let Some(bounds) = bounds.solve() else {
            return false;
        };
        for (&v, [l, u]) in component.iter().zip(bounds) {
            let slack = 1e-12 * u.abs().max(l.abs());
            let [lower, upper, _] = &mut values[v.index()];
            *lower = lower.max(l - slack).min(*upper);
            *upper = upper.min(u + slack).max(*lower);
        }
        if !endless && let Some(times) = times.solve() {
            for (&v, [t]) in component.iter().zip(times) {
                values[v.index()][2] = t;
            }
        }
        true
    }
}

/// A large component of a chain copied out of the product for its sweeps: its states at
/// their positions in the component, then one slot per transition that leaves it (holding the
/// exit's final values), so that a sweep reads a few megabytes in order instead of successors
/// scattered over the product's arrays. The sums are made over the same successors in the same
/// order as [`Chain::solve_component`]'s sweeps over the product, so the values are the same to
/// the bit.
struct Compact {
    /// Per position, the slots of its successors (rows), with `probabilities` beside them.
    successors: Csr<u32, u32>,
    probabilities: Vec<f64>,
    /// Per position, `[factor, cost]`.
    parameters: Vec<[f64; 2]>,
    /// `[lower, upper, time]` per slot: the component's states, then its exits.
    values: Vec<[f64; 3]>,
}

impl Compact {
    fn new(chain: &Chain, component: &[HState], values: &[[f64; 3]]) -> Compact {
        let mut sorted: Vec<(HState, u32)> = (component.iter().enumerate())
            .map(|(i, &v)| (v, i as u32))
            .collect();
        sorted.sort_unstable();
        let position = |h: HState| {
            let i = sorted.binary_search_by_key(&h, |&(v, _)| v).ok()?;
            Some(sorted[i].1)
        };
        let transitions = (component.iter())
            .map(|&v| chain.successors.row(v).len())
            .sum();
        let mut compact = Compact {
            successors: Csr::with_capacity(component.len(), transitions),
            probabilities: Vec::with_capacity(transitions),
            parameters: Vec::with_capacity(component.len()),
            values: component.iter().map(|&v| values[v.index()]).collect(),
        };
        for &v in component {
            for (target, p) in chain.transitions(v) {
                let slot = position(target).unwrap_or_else(|| {
                    compact.values.push(values[target.index()]);
                    compact.values.len() as u32 - 1
                });
                compact.successors.push(slot);
                compact.probabilities.push(p);
            }
            compact.successors.finish_row();
            compact.parameters.push(chain.parameters[v.index()]);
        }
        compact
    }

    /// The sweeps of [`Chain::solve_component`] over the copy, then the values copied back.
    fn solve(
        mut self,
        component: &[HState],
        endless: bool,
        limits: SweepLimits,
        values: &mut [[f64; 3]],
    ) -> Result<(), EvaluationError> {
        let mut iterations = 0;
        let outcome = loop {
            let (mut gap, mut change) = (0.0f64, 0.0f64);
            for i in 0..component.len() {
                let successors = (self.successors.row_with(i as u32, &self.probabilities))
                    .map(|(target, &p)| (self.values[target as usize], p));
                let (new, width, moved) = step(self.parameters[i], self.values[i], successors);
                self.values[i] = new;
                gap = gap.max(width);
                change = change.max(moved);
            }
            iterations += 1;
            if limits.converged(gap, change, endless) {
                break Ok(());
            }
            if let Some(outcome) = limits.out_of_sweeps(iterations, gap) {
                break outcome;
            }
        };
        for (&v, &value) in component.iter().zip(&self.values) {
            values[v.index()] = value;
        }
        if endless {
            for &v in component {
                values[v.index()][2] = f64::INFINITY;
            }
        }
        outcome
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mdp::solve::{SolveOptions, solve};
    use crate::opportunistic::adversary::SigmaL;
    use crate::opportunistic::build::tests::build;
    use crate::opportunistic::controller::Controller;
    use crate::opportunistic::view::testing::{ToyGame, hs};

    /// r0 `(W,L,L)` moves to adversary a1 (in Win(phi1): uniform), which stays (x, back to
    /// itself) or moves on (y) to r2 `(W,W,W)`: a chance cycle left with probability 1/2.
    fn loop_game() -> ToyGame {
        let mut g = ToyGame::new(&["go", "x", "y"]);
        let r0 = g.state(true, "WLL", 2);
        let a1 = g.state(false, "WLL", 1);
        let r2 = g.state(true, "WWW", 0);
        g.edge(r0, "go", a1);
        g.edge(a1, "x", a1);
        g.edge(a1, "y", r2);
        g
    }

    /// A random chain of `n` states: about one in ten ends (payoffs in `[0, 10]`), the others
    /// step (factor 1 or 0.95, cost 0 or 1) to one to four random successors, so that most
    /// states fall in one large component.
    fn random_chain(seed: u64, n: usize) -> Chain {
        use rand_core::RngCore;
        let mut rng = crate::mdp::testing::rng(seed);
        let mut chain = Chain::with_capacity(n);
        for _ in 0..n {
            if rng.next_u32().is_multiple_of(10) {
                let payoff = f64::from(rng.next_u32() % 11);
                chain.end(payoff, payoff);
                continue;
            }
            let degree = 1 + rng.next_u32() % 4;
            let weights: Vec<f64> = (0..degree)
                .map(|_| f64::from(1 + rng.next_u32() % 7))
                .collect();
            let total: f64 = weights.iter().sum();
            let successors: Vec<(HState, f64)> = weights
                .iter()
                .map(|w| (HState::new(rng.next_u32() as usize % n), w / total))
                .collect();
            let factor = if rng.next_u32().is_multiple_of(2) {
                1.0
            } else {
                0.95
            };
            chain.step(factor, f64::from(rng.next_u32() % 2), successors);
        }
        chain
    }

    #[test]
    fn a_large_component_swept_over_its_compact_copy_gets_the_same_values_to_the_bit() {
        let mut failing = 0;
        for seed in 0..6 {
            let chain = random_chain(seed, 3000);
            let components = strongly_connected_components(&chain.successors);
            let largest = (components.rows())
                .map(|c| components.row(c).len())
                .max()
                .unwrap();
            // The first component solved that takes sweeps (components are solved in row order).
            let first_cyclic = (components.rows())
                .map(|c| components.row(c))
                .find(|c| c.len() > 1 || chain.transitions(c[0]).any(|(t, _)| t == c[0]))
                .map_or(0, |c| c.len());
            assert!(
                largest > EXACT_LIMIT,
                "seed {seed}: largest component {largest}"
            );
            let limits = |compact_above, max_iterations| SweepLimits {
                epsilon: 1e-9,
                max_iterations,
                compact_above,
            };
            let compact = chain.solve(limits(EXACT_LIMIT, 100_000), &mut |_| ());
            let plain = chain.solve(limits(usize::MAX, 100_000), &mut |_| ());
            let bits = |values: &ChainValues| -> Vec<[u64; 3]> {
                (values.0.iter())
                    .map(|v| [v[0].to_bits(), v[1].to_bits(), v[2].to_bits()])
                    .collect()
            };
            assert_eq!(
                bits(&compact.unwrap()),
                bits(&plain.unwrap()),
                "seed {seed}"
            );
            // Out of sweeps in the large component, where it is the first to take sweeps: the
            // same error, with the same gap.
            if first_cyclic > EXACT_LIMIT {
                failing += 1;
                let compact = chain.solve(limits(EXACT_LIMIT, 3), &mut |_| ()).err();
                let plain = chain.solve(limits(usize::MAX, 3), &mut |_| ()).err();
                assert!(
                    matches!(
                        compact,
                        Some(EvaluationError::NotConverged { iterations: 3, .. })
                    ),
                    "seed {seed}: {compact:?}"
                );
                assert_eq!(compact, plain, "seed {seed}");
            }
        }
        assert!(failing > 0);
    }

    #[test]
    fn a_cycle_the_chain_leaves_is_solved_and_a_sweep_limit_is_a_typed_error() {
        let g = loop_game();
        let built = build(&g);
        let solution = solve(built.mdp(), &SolveOptions::default()).unwrap();
        let controller = Controller {
            game: &g,
            mdp: &built,
            solution: &solution,
        };
        let adversary = AdversaryModel::new(&g, &SigmaL::Uniform).unwrap();
        // a1 reaches r2 with probability 1: r0 collects 300 after one robot move.
        let evaluation = ControllerEvaluation::new(&controller, &adversary, 1e-9, 1000).unwrap();
        let value = evaluation.value(hs(0));
        assert!((value.lower - 300.0).abs() < 1e-6 && (value.upper - 300.0).abs() < 1e-6);
        assert_eq!(evaluation.expected_moves(hs(0)), 1.0);
        // The first chain solved is the probability of reaching phi1's targets once committed:
        // one sweep over the cycle {a1} takes its bounds from [0, 1] to [1/2, 1].
        assert_eq!(
            ControllerEvaluation::new(&controller, &adversary, 1e-9, 1),
            Err(EvaluationError::NotConverged {
                iterations: 1,
                gap: 0.5,
                epsilon: 1e-9
            })
        );
    }
}

//! The Bellman operator every iterative method of the MDP core applies: the value sweeps,
//! interval iteration with optimistic bounds, policy iteration and the deflations of the nominal
//! and the robust solve, and the expected numbers of moves that break the policy's ties.
//!
//! # Layout
//! An [`Operator`] holds a system of *nodes* (the unknowns, `0..nodes()`) in compact arrays:
//! each node owns a contiguous range of *rows* (its choices, [`Operator::choices`]), each row
//! lists its *target slots* (indices into a value vector, which may be longer than the nodes:
//! the slots after them are constants the operator reads and never writes), the *start* of its
//! data in the expectation's storage, and whether it is *instant* (an adversary's chance move or
//! `stop`: not discounted, no move counted). The rows of a node, and the targets of a row, keep
//! the order they were pushed in, which the builders make the model's.
//!
//! # The backup
//! For an objective `O` ([`Objective`]) and values `v` (one `[f64; N]` per slot: `N` sides
//! iterated together, such as the lower and upper bounds, each side reading only its own side of
//! the targets), the backup of a node is
//! `O.better(… O.better(O.start(), O.q(instant(r₁), E_r₁[v])) …, O.q(instant(r_k), E_r_k[v]))`
//! over its rows `r₁ … r_k` in order: the choices' values folded from the start value, where
//! `E_r[v]` is the row's expectation, taken as the [`Expectation`] says:
//! - [`Nominal`]: `Σ p(t) · v(t)` with the row's fixed distribution (the probabilities at its
//!   start in a pool of distributions), summed from `+0.0` in the row's target order;
//! - [`Robust`]: the same for an exact row; for a row with probability intervals, the minimum
//!   over the distributions within them (the adversary's greedy reply of `robust/inner.rs`),
//!   found separately for each side.
//!
//! The objectives are [`Payoff`] (the largest `f · E` from 0, `f = g` for a move and 1 for an
//! instant row: the value of the discounted payoff at absorption) and [`Moves`] (the smallest
//! `cost + E` from infinity, the cost 1 for a move and 0 for an instant row: the expected number
//! of moves). Both are monomorphised into the sweeps, so that a backup compiles to the loops a
//! hand-written one would.
//!
//! # Invariants
//! - *Same sums, same bits*: a row's expectation does exactly the floating-point operations of
//!   the same sum over the model ([`Mdp::successors`](super::Mdp::successors) in order), so an
//!   operator built over a compact copy of part of a system (a component's block, the expected
//!   moves' components) gives the same values to the bit as one over the whole, and the policy,
//!   which recomputes Q-values on the model, sees the bounds the sweeps certified.
//! - *Sides are independent*: side `i` of a backup reads side `i` of the values only (the robust
//!   adversary replies to each side on its own), so a lower and an upper bound iterated together
//!   are each an iterate of the operator.
//! - *Monotone, up to rounding*: raising values never lowers a backup (nominal: non-negative
//!   weights; robust: a minimum of monotone sums), so any vector the backup does not raise bounds
//!   its least fixed point from above: the argument of every optimistic upper bound.
//! - The operator never writes values: the methods own the in-place (Gauss–Seidel) updates,
//!   clamping and stopping rules.

use std::cell::Cell;
use std::ops::{Deref, Range};

use bit_set::BitSet;

use super::model::{ChoiceId, Mdp, MdpState};
use super::robust::inner::{self, Entry};
use crate::csr::Csr;

/// How a row's expectation of the values is taken.
pub(in crate::mdp) trait Expectation {
    /// The expectation of `value` over the row `row`, whose targets are `targets` and whose
    /// data starts at `start`, per side.
    fn expect<const N: usize>(
        &self,
        row: usize,
        start: usize,
        targets: &[u32],
        value: &impl Fn(u32) -> [f64; N],
    ) -> [f64; N];
}

/// Fixed distributions, read from a pool of distributions (`P`: the model's pool, borrowed, or a
/// compact copy of the part a sweep reads, owned).
pub(in crate::mdp) struct Nominal<P> {
    pub(in crate::mdp) pool: P,
}

/// `Σ p · value` over `targets` and their probabilities `pool[start..]`, summed in order from
/// `+0.0`, per side.
#[inline(always)]
fn weighted_sum<T: Copy, const N: usize>(
    pool: &[f64],
    start: usize,
    targets: &[T],
    value: &impl Fn(T) -> [f64; N],
) -> [f64; N] {
    let mut sum = [0.0; N];
    for (&target, &probability) in targets.iter().zip(&pool[start..start + targets.len()]) {
        let v = value(target);
        for side in 0..N {
            sum[side] += probability * v[side];
        }
    }
    sum
}

impl<P: Deref<Target = [f64]>> Expectation for Nominal<P> {
    #[inline(always)]
    fn expect<const N: usize>(
        &self,
        _row: usize,
        start: usize,
        targets: &[u32],
        value: &impl Fn(u32) -> [f64; N],
    ) -> [f64; N] {
        weighted_sum(&self.pool, start, targets, value)
    }
}

/// Fixed distributions for the exact rows, and the worst distribution within probability
/// intervals for the others: an interval row's start is in `bounds`, one `[lower, upper]` per
/// target.
pub(in crate::mdp) struct Robust<'a> {
    pool: &'a [f64],
    bounds: &'a [[f64; 2]],
    /// The rows with intervals.
    uncertain: BitSet,
    /// The entries of the adversary's inner problem, reused from one row to the next.
    scratch: Cell<Vec<Entry>>,
}

impl<'a> Robust<'a> {
    /// No interval rows yet: the model's `pool` of distributions and the intervals' `bounds`.
    pub(in crate::mdp) fn new(pool: &'a [f64], bounds: &'a [[f64; 2]]) -> Self {
        Robust {
            pool,
            bounds,
            uncertain: BitSet::new(),
            scratch: Cell::new(Vec::new()),
        }
    }

    /// Marks `row` as one with intervals (its start is in the bounds).
    pub(in crate::mdp) fn set_uncertain(&mut self, row: usize) {
        self.uncertain.insert(row);
    }
}

impl Expectation for Robust<'_> {
    #[inline]
    fn expect<const N: usize>(
        &self,
        row: usize,
        start: usize,
        targets: &[u32],
        value: &impl Fn(u32) -> [f64; N],
    ) -> [f64; N] {
        if !self.uncertain.contains(row) {
            return weighted_sum(self.pool, start, targets, value);
        }
        let bounds = &self.bounds[start..start + targets.len()];
        let mut entries = self.scratch.take();
        let minimum = worst_sum(bounds, targets, value, &mut entries);
        self.scratch.set(entries);
        minimum
    }
}

/// `min_p Σ p · value` over the distributions within `bounds` (one interval per target), per
/// side, with `entries` as the inner problem's buffer.
#[inline]
fn worst_sum<T: Copy, const N: usize>(
    bounds: &[[f64; 2]],
    targets: &[T],
    value: &impl Fn(T) -> [f64; N],
    entries: &mut Vec<Entry>,
) -> [f64; N] {
    let mut minimum = [0.0; N];
    for (side, minimum) in minimum.iter_mut().enumerate() {
        entries.clear();
        entries.extend(targets.iter().zip(bounds).map(|(&target, b)| Entry {
            value: value(target)[side],
            lower: b[0],
            upper: b[1],
        }));
        *minimum = inner::minimum(entries);
    }
    minimum
}

/// The value of `choice` of the model itself under `objective`, the states valued by `value`:
/// with the choice's own distribution, or the worst within `bounds` (one interval per target)
/// if given. The sums of a row of an operator built over the model, for the methods that read
/// the model directly (the policies, the decision tables).
pub(in crate::mdp) fn model_q<const N: usize>(
    mdp: &Mdp,
    choice: ChoiceId,
    bounds: Option<&[[f64; 2]]>,
    objective: &impl Objective<N>,
    value: &impl Fn(MdpState) -> [f64; N],
) -> [f64; N] {
    let targets = mdp.targets(choice);
    let expectation = match bounds {
        None => {
            let start = mdp.distribution_starts()[choice.index()] as usize;
            weighted_sum(mdp.pool(), start, targets, value)
        }
        Some(bounds) => worst_sum(bounds, targets, value, &mut Vec::new()),
    };
    objective.q(mdp.is_instant(choice), expectation)
}

/// What a backup optimises: a choice's value from its expectation, and how two values compare.
pub(in crate::mdp) trait Objective<const N: usize> {
    /// The backup of a node without choices, from which the best choice is sought.
    fn start(&self) -> [f64; N];
    /// The value of a choice (instant or a move) whose expectation is `expectation`.
    fn q(&self, instant: bool, expectation: [f64; N]) -> [f64; N];
    /// The better of two values, side by side.
    fn better(&self, a: [f64; N], b: [f64; N]) -> [f64; N];
}

/// The largest discounted expectation, from 0: `max(0, max_r f(r) · E_r)`, `f` the discount `g`
/// for a move and 1 for an instant row.
#[derive(Clone, Copy, Debug)]
pub(in crate::mdp) struct Payoff {
    pub(in crate::mdp) g: f64,
}

impl<const N: usize> Objective<N> for Payoff {
    #[inline(always)]
    fn start(&self) -> [f64; N] {
        [0.0; N]
    }

    #[inline(always)]
    fn q(&self, instant: bool, expectation: [f64; N]) -> [f64; N] {
        let f = if instant { 1.0 } else { self.g };
        expectation.map(|e| f * e)
    }

    #[inline(always)]
    fn better(&self, a: [f64; N], b: [f64; N]) -> [f64; N] {
        std::array::from_fn(|side| a[side].max(b[side]))
    }
}

/// The fewest expected moves: `min_r cost(r) + E_r`, from infinity, the cost 1 for a move and 0
/// for an instant row.
#[derive(Clone, Copy, Debug)]
pub(in crate::mdp) struct Moves;

impl<const N: usize> Objective<N> for Moves {
    #[inline(always)]
    fn start(&self) -> [f64; N] {
        [f64::INFINITY; N]
    }

    #[inline(always)]
    fn q(&self, instant: bool, expectation: [f64; N]) -> [f64; N] {
        let cost = if instant { 0.0 } else { 1.0 };
        expectation.map(|e| cost + e)
    }

    #[inline(always)]
    fn better(&self, a: [f64; N], b: [f64; N]) -> [f64; N] {
        std::array::from_fn(|side| a[side].min(b[side]))
    }
}

/// The operator: the nodes' rows in compact arrays (module documentation) and the expectation
/// they are taken with.
pub(in crate::mdp) struct Operator<E> {
    /// Node → its range of rows.
    node_offsets: Vec<u32>,
    /// Per row, its target slots.
    targets: Csr<u32, u32>,
    /// Per row, where its data starts in the expectation's storage.
    starts: Vec<u32>,
    /// The instant rows (not discounted, no move counted).
    instant: BitSet,
    /// How the rows' expectations are taken.
    pub(in crate::mdp) expectation: E,
}

impl<E> Operator<E> {
    /// No nodes yet.
    pub(in crate::mdp) fn new(expectation: E) -> Self {
        Operator {
            node_offsets: vec![0],
            targets: Csr::new(),
            starts: Vec::new(),
            instant: BitSet::new(),
            expectation,
        }
    }

    /// The operator with these arrays, written in place at their exact sizes: `node_offsets`
    /// (from 0, one more than the nodes) into the rows of `targets`, one start per row.
    pub(in crate::mdp) fn from_parts(
        node_offsets: Vec<u32>,
        targets: Csr<u32, u32>,
        starts: Vec<u32>,
        instant: BitSet,
        expectation: E,
    ) -> Self {
        debug_assert_eq!(node_offsets.first(), Some(&0));
        debug_assert_eq!(node_offsets.last().map(|&r| r as usize), Some(starts.len()));
        debug_assert_eq!(targets.num_rows(), starts.len());
        Operator {
            node_offsets,
            targets,
            starts,
            instant,
            expectation,
        }
    }

    /// Adds a row to the node being built: its target slots, its start, whether it is instant.
    /// Returns the row.
    pub(in crate::mdp) fn push_row(
        &mut self,
        targets: impl IntoIterator<Item = u32>,
        start: u32,
        instant: bool,
    ) -> usize {
        let row = self.starts.len();
        if instant {
            self.instant.insert(row);
        }
        self.starts.push(start);
        self.targets.push_row(targets);
        row
    }

    /// Ends the node being built: it owns the rows pushed since the last node ended.
    pub(in crate::mdp) fn finish_node(&mut self) {
        self.node_offsets.push(self.starts.len() as u32);
    }

    /// Removes every node, keeping the expectation (and the buffers' room, but the targets').
    pub(in crate::mdp) fn clear(&mut self) {
        self.node_offsets.clear();
        self.node_offsets.push(0);
        self.targets = Csr::new();
        self.starts.clear();
        self.instant.make_empty();
    }

    /// The number of nodes.
    #[inline]
    pub(in crate::mdp) fn nodes(&self) -> usize {
        self.node_offsets.len() - 1
    }

    /// The rows of `node`.
    #[inline]
    pub(in crate::mdp) fn choices(&self, node: usize) -> Range<usize> {
        self.node_offsets[node] as usize..self.node_offsets[node + 1] as usize
    }

    /// The target slots of `row`.
    #[inline]
    pub(in crate::mdp) fn targets(&self, row: usize) -> &[u32] {
        self.targets.row(row as u32)
    }

    /// Where the data of `row` starts in the expectation's storage.
    #[inline]
    pub(in crate::mdp) fn start(&self, row: usize) -> usize {
        self.starts[row] as usize
    }

    /// Whether `row` is instant.
    #[inline]
    pub(in crate::mdp) fn is_instant(&self, row: usize) -> bool {
        self.instant.contains(row)
    }

    /// The target slots of every row of `node`, one row after the other (constant slots
    /// included): the node graph, without a copy of it.
    pub(in crate::mdp) fn successor_slots(
        &self,
        node: u32,
    ) -> std::iter::Copied<std::slice::Iter<'_, u32>> {
        let rows = self.choices(node as usize);
        if rows.is_empty() {
            return [].iter().copied();
        }
        let start = self.targets.range(rows.start as u32).start;
        let end = self.targets.range(rows.end as u32 - 1).end;
        self.targets.entries()[start..end].iter().copied()
    }
}

impl<E: Expectation> Operator<E> {
    /// The value of `row` under `objective` with the slots valued by `value`.
    #[inline(always)]
    pub(in crate::mdp) fn q<const N: usize>(
        &self,
        row: usize,
        objective: &impl Objective<N>,
        value: &impl Fn(u32) -> [f64; N],
    ) -> [f64; N] {
        let expectation = self
            .expectation
            .expect(row, self.start(row), self.targets(row), value);
        objective.q(self.is_instant(row), expectation)
    }

    /// The backup of `node` under `objective` with the slots valued by `value` (module
    /// documentation).
    #[inline(always)]
    pub(in crate::mdp) fn backup<const N: usize>(
        &self,
        node: usize,
        objective: &impl Objective<N>,
        value: &impl Fn(u32) -> [f64; N],
    ) -> [f64; N] {
        let mut best = objective.start();
        for row in self.choices(node) {
            best = objective.better(best, self.q(row, objective, value));
        }
        best
    }
}

impl<P: Deref<Target = [f64]>> Operator<Nominal<P>> {
    /// The target slots and probabilities of `row` (for the exact solves of policy iteration).
    #[inline(always)]
    pub(in crate::mdp) fn transitions(&self, row: usize) -> impl Iterator<Item = (u32, f64)> + '_ {
        let start = self.start(row);
        let targets = self.targets(row);
        targets
            .iter()
            .zip(&self.expectation.pool[start..start + targets.len()])
            .map(|(&target, &probability)| (target, probability))
    }
}

impl Operator<Robust<'_>> {
    /// Whether `row` has intervals.
    pub(in crate::mdp) fn is_uncertain(&self, row: usize) -> bool {
        self.expectation.uncertain.contains(row)
    }

    /// The distribution the expectation of `row` takes with the slots valued by `value`, one
    /// probability per target: the adversary's reply for an interval row, the row's own
    /// distribution for an exact one.
    pub(in crate::mdp) fn reply(&self, row: usize, value: impl Fn(u32) -> f64, out: &mut Vec<f64>) {
        let targets = self.targets(row);
        let start = self.start(row);
        if self.is_uncertain(row) {
            let values: Vec<f64> = targets.iter().map(|&t| value(t)).collect();
            let bounds = &self.expectation.bounds[start..start + targets.len()];
            inner::distribution(&values, bounds, out);
        } else {
            out.clear();
            out.extend_from_slice(&self.expectation.pool[start..start + targets.len()]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Node 0 of a tiny system: a move to slots 1 and 2 with probabilities 1/4 and 3/4, and an
    /// instant row to slots 2 and 3 (1/2 each); node 1 has one move to slot 3. Slots 2 and 3 are
    /// constants. The pool holds the two distributions, the move's at 0 and the other's at 2.
    fn tiny<E>(expectation: E) -> Operator<E> {
        let mut operator = Operator::new(expectation);
        operator.push_row([1, 2], 0, false);
        operator.push_row([2, 3], 2, true);
        operator.finish_node();
        operator.push_row([3], 4, false);
        operator.finish_node();
        operator
    }

    const POOL: [f64; 5] = [0.25, 0.75, 0.5, 0.5, 1.0];

    #[test]
    fn the_nominal_backup_is_the_best_discounted_expectation() {
        let operator = tiny(Nominal { pool: &POOL[..] });
        // Lower and upper values per slot.
        let values = [[0.0, 9.0], [4.0, 8.0], [2.0, 2.0], [10.0, 10.0]];
        let value = |slot: u32| values[slot as usize];
        let g = 0.5;
        // Move: 0.5 · (0.25·4 + 0.75·2) = 1.25 (lower), 0.5 · (0.25·8 + 0.75·2) = 1.75
        // (upper); instant: 0.5·2 + 0.5·10 = 6 on both sides. The best: 6, 6.
        assert_eq!(operator.q(0, &Payoff { g }, &value), [1.25, 1.75]);
        assert_eq!(operator.q(1, &Payoff { g }, &value), [6.0, 6.0]);
        assert_eq!(operator.backup(0, &Payoff { g }, &value), [6.0, 6.0]);
        // Node 1: 0.5 · 10.
        assert_eq!(operator.backup(1, &Payoff { g }, &value), [5.0, 5.0]);
        // The fewest moves, with these as times: the move costs 1 + 0.25·4 + 0.75·2 = 3.5, the
        // instant row 0 + 0.5·2 + 0.5·10 = 6 (lower side).
        assert_eq!(
            operator.backup(0, &Moves, &|s| [values[s as usize][0]]),
            [3.5]
        );
        // A node without rows keeps the start: 0 for payoffs, infinity for moves.
        let mut empty = Operator::new(Nominal { pool: &POOL[..] });
        empty.finish_node();
        assert_eq!(empty.backup(0, &Payoff { g }, &value), [0.0, 0.0]);
        assert_eq!(empty.backup(0, &Moves, &|_| [1.0]), [f64::INFINITY]);
        assert_eq!(
            operator.transitions(1).collect::<Vec<_>>(),
            [(2, 0.5), (3, 0.5)]
        );
    }

    #[test]
    fn the_robust_backup_takes_each_sides_worst_distribution_within_the_intervals() {
        // The instant row of node 0 gets intervals [0.2, 0.9] to slot 2 and [0.1, 0.8] to slot
        // 3 (bounds from 0); the move keeps its distribution.
        let bounds = [[0.2, 0.9], [0.1, 0.8]];
        let mut robust = Robust::new(&POOL[..], &bounds);
        robust.set_uncertain(1);
        let mut operator = Operator::new(robust);
        operator.push_row([1, 2], 0, false);
        operator.push_row([2, 3], 0, true);
        operator.finish_node();
        // Lower side: slot 2 worth 2, slot 3 worth 10: the adversary puts all it can (0.9) on
        // slot 2 and the rest (0.1) on slot 3: 0.9·2 + 0.1·10 = 2.8. Upper side: slot 2 worth
        // 12, slot 3 worth 10: it puts 0.8 on slot 3 and 0.2 on slot 2: 0.2·12 + 0.8·10 = 10.4.
        let values = [[0.0, 0.0], [4.0, 8.0], [2.0, 12.0], [10.0, 10.0]];
        let value = |slot: u32| values[slot as usize];
        let g = 0.5;
        let instant = operator.q(1, &Payoff { g }, &value);
        assert!((instant[0] - 2.8).abs() < 1e-15, "{instant:?}");
        assert!((instant[1] - 10.4).abs() < 1e-14, "{instant:?}");
        // Move: 0.5 · (0.25·4 + 0.75·2) = 1.25, 0.5 · (0.25·8 + 0.75·12) = 5.5.
        assert_eq!(operator.q(0, &Payoff { g }, &value), [1.25, 5.5]);
        let best = operator.backup(0, &Payoff { g }, &value);
        assert_eq!(best, instant);
        let mut reply = Vec::new();
        operator.reply(1, |slot| values[slot as usize][0], &mut reply);
        assert!((reply[0] - 0.9).abs() < 1e-15 && (reply[1] - 0.1).abs() < 1e-15);
        operator.reply(0, |slot| values[slot as usize][0], &mut reply);
        assert_eq!(reply, [0.25, 0.75]);
    }
}

//! Interval iteration with optimistic upper bounds: Gauss–Seidel sweeps of a lower and an
//! upper vector over one component, with an upper bound guessed from the lower one and kept
//! when verified.
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
//! On the 20x20 gridworld at g = 0.99 (components of 104k, 151k and 27k nodes, 31, 99 and 11
//! sweeps, 141 in all, relative ε = 1e-6; solve 1.2–1.5 s on a quiet machine): after about 20
//! sweeps in which the values cross the grid, the 151k component's gap shrinks by a steady
//! 0.857 per sweep (0.9 at 24x24: one minus about 57/n², the signature of a diffusive mode,
//! the adversary's random walk), and the optimistic upper bounds are never verified before
//! the upper sweeps meet the lower ones themselves. Tried against that, none kept:
//! - *two halves at once*: the component cut at the middle of its node order, each half swept
//!   Gauss–Seidel on its own thread, reading the other half's bounds from a snapshot taken
//!   when the sweep began (block Jacobi between the halves: sound, and the same figures on
//!   one thread or two). The layout's edges span up to 30% of a component's nodes, so many
//!   cross the cut and their information arrives a sweep late: 178 sweeps instead of 141, and
//!   1.45 s on two cores against 1.44 s for the sequential sweeps (1.99 s on one core);
//! - *extrapolating the lower bounds* along their last step, `x = L + ΔL · ρ / (1 − ρ)` with `ρ`
//!   the ratio of successive sums of rises (steady at 0.8568 from sweep 50), and offering
//!   `x − δ` and `x + δ` as bounds if one Bellman update raises the first and lowers the
//!   second: the lower bound never verified and the upper one only from sweep 93. A
//!   verification has a margin of `(1 − g) · δ` at a move node and none at a chance node, so
//!   a guess passes only once it is exact to far below the precision;
//! - *over-relaxing an estimate*, `x ← x + ω · (T x − x)` after 20 plain sweeps, to be
//!   certified as above once its residual is small: it diverges at ω = 1.3 and 1.5 (the
//!   largest relative residual goes from 3e-3 to above 1 within 30 to 50 sweeps: the
//!   operator is a maximum and not symmetric), and at ω = 1 it shrinks by the same 0.856
//!   per sweep;
//! - *reading the successors' bounds ahead* (a prefetch of the bounds the node eight positions
//!   on will read; a third of the Bellman update's samples wait on that load): medians 0.313 →
//!   0.331 s at 16x16 and 1.335 → 1.318 s at 20x20 over seven to nine alternating runs, within
//!   the noise;
//! - *alternating the direction every sweep*: 215 sweeps instead of 117 at 16x16, 262 instead
//!   of 141 at 20x20 (forward only: 112 and 134; the probe costs those few sweeps and pays on
//!   models numbered along their cycles).
//!
//! Kept: sweeping a large component over a compact copy of itself (`System::block`), the same
//! sums in the same order from memory it fills densely: 1.45 → 1.03 s at 20x20 and 4.1 →
//! 2.8 s at 24x24 (a third of the Bellman update's samples waited on a successor's bounds).
//! Tried after it, on the 20x20 gridworld at g = 0.99, none kept:
//! - *extrapolating both bounds along their last moves*, `L + s · r` and `U − t · f` (`r`, `f`
//!   the rises and falls of the last sweep), with the largest factors for which each stays a
//!   sub- or super-fixed-point found in one pass (per node and choice an affine condition in
//!   the factor) and kept if a Bellman update verifies them: in the geometric regime the ideal
//!   factor is `ρ/(1 − ρ)` ≈ 6, but the smallest over the nodes stays between 1e-4 and 0.5 (a
//!   node whose successors all come before it in the sweep has a residual of exactly 0, so it
//!   has no margin for any error in the direction); per-node factors capped at the 1%
//!   quantile fail the verification at 5 000 to 8 000 of the 151k nodes per round, in a
//!   cascade. Tried after every sweep with one factor, it cut the 151k component's sweeps
//!   from 99 to 81 at the cost of two passes per try: 2.8 s instead of 1.4 s;
//! - *the two bounds on two threads*, each sweeping its own array (the lower and upper
//!   bounds share cache lines in `values`), joined after every sweep, the same bounds to the
//!   bit: 0.90–1.07 s on two threads against 0.92–1.00 s on one. The sweep waits on the
//!   latency of its loads, which a thread sweeping one bound pays in full;
//! - *full sweeps* (no `dirty` flags read or set) after a sweep that changed three quarters
//!   of the nodes: within the noise (1.04–1.18 s against 1.10–1.28 s, 24x24 2.51–2.85 s
//!   against 2.50–2.67 s);
//! - *a block in breadth-first order* from its nodes with an exit, backwards (successors'
//!   bounds nearer in memory: half of a block's edges span 8 000 to 12 000 nodes in the node
//!   order): 199 sweeps instead of 168 at 24x24, and no faster (2.6–3.3 s against 2.6–2.7 s).
//!
//! What would address a diffusive mode is a coarse correction (aggregation or multigrid over
//! blocks of states) or a Krylov solve of the greedy policy's equations, each followed by a
//! certification whose margin is that `(1 − g) · δ`: not tried. The greedy policy of the lower
//! bounds does not settle early (in the 151k component, of its 76k nodes with several choices,
//! it differs from the final greedy choice at 828 after 30 sweeps, 108 after 65 and 0 only
//! after 97), so a policy-evaluation method would take several rounds, each a solve of the
//! whole component.

use super::system::{NominalSystem, System};
use super::{Precision, REFINEMENT, SolveError, VERIFICATION_SLACK};
use crate::mdp::operator::Expectation;

impl NominalSystem<'_> {
    /// Gauss–Seidel sweeps over `component` (its successors outside are final), trying after
    /// each sweep in which the lower bounds settled to within `tolerance` an optimistic upper
    /// bound `min(U, L + ε/2)` (`ε` the width `precision` allows at `L`): accepted when one Bellman update does not raise it anywhere
    /// (a super-fixed-point; there are no end components left, so it bounds the value), else
    /// the tolerance halves. At g = 1 the sweeps go on after certification until the lower
    /// bounds stop moving (`REFINEMENT`), for at most as many sweeps again. A sweep skips the
    /// nodes none of whose successors' bounds changed since their last update (they would keep
    /// theirs), so converged regions of a large component cost almost nothing, with the same
    /// bounds and sweep counts as full sweeps. Below g = 1 a sweep also skips the nodes whose
    /// interval is within half the precision (`SETTLED`): their bounds stay bounds (a lower one
    /// stays below its Bellman update as the successors' rise, an upper one above), and their
    /// predecessors still get within the precision, the discount bringing a gap at most that
    /// of the successors. The component is done when every interval is within the precision.
    /// After each sweep, `report` is told how far the gap has come from its first value to the
    /// precision, on a log scale (from 0 to 1). Returns the sweeps and the width.
    pub(super) fn optimistic_iteration(
        &mut self,
        component: &[u32],
        g: f64,
        precision: Precision,
        scale: f64,
        max_iterations: u32,
        report: &mut dyn FnMut(f64),
    ) -> Result<(u32, f64), SolveError> {
        let mut first_ratio = None;
        // How little the lower bounds must move before an optimistic upper bound is tried.
        let mut tolerance = if precision.relative {
            precision.allowed(scale)
        } else {
            precision.epsilon
        };
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
                        gap: self.gap(component, precision).0,
                        epsilon: precision.epsilon,
                    }),
                };
            }
            sweeps += 1;
            let (mut rise, mut width, mut progress) = (0.0f64, 0.0f64, 0.0f64);
            let mut ratio = 0.0f64;
            // A node that is not dirty keeps its bounds (module documentation of `dirty`): its
            // width is read, not recomputed, so every sweep's figures are those of a full one.
            // Below g = 1 a node within half its precision keeps its bounds too (`SETTLED`).
            let settle = g < 1.0;
            let mut sweep = |position: usize, node: u32| {
                let node = node as usize;
                let dirty = std::mem::replace(&mut self.dirty[node], false);
                if !dirty || settle {
                    let [lower, upper] = self.values[node];
                    let own = precision.ratio(lower, upper);
                    if !dirty || own <= SETTLED {
                        width = width.max(upper - lower);
                        ratio = ratio.max(own);
                        return;
                    }
                }
                let old = self.values[node];
                let (r, w) = self.update(node, g);
                if self.values[node] != old {
                    for &source in self.sources.row(position as u32) {
                        self.dirty[source as usize] = true;
                    }
                }
                let [lower, upper] = self.values[node];
                rise = rise.max(r);
                width = width.max(w);
                ratio = ratio.max(precision.ratio(lower, upper));
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
            if ratio > 1.0 && rise <= tolerance {
                if self.try_optimistic_upper(component, g, precision, 0.0) {
                    component.iter().for_each(|&node| {
                        self.dirty[node as usize] = true;
                    });
                } else {
                    tolerance *= 0.5;
                }
                (width, ratio) = self.gap(component, precision);
            }
            report(gap_fraction(*first_ratio.get_or_insert(ratio), ratio));
            if ratio <= 1.0 {
                if g < 1.0 {
                    return Ok((sweeps, width));
                }
                // Refine at most as long again as certification took.
                certified = Some((width, sweeps.saturating_mul(2)));
            }
        }
    }
}

impl<E: Expectation> System<E> {
    /// Sets the upper bounds of `component` to `min(U, L + ε/2)` (`ε` the width `precision`
    /// allows at `L`) if that vector is a super-fixed-point of the Bellman operator (up to a
    /// rounding of `VERIFICATION_SLACK` times the candidate, or times `floor` if larger); leaves
    /// them unchanged otherwise. Returns whether it did. Any super-fixed-point bounds the least
    /// fixed point, which is the value, from above.
    pub(in crate::mdp) fn try_optimistic_upper(
        &mut self,
        component: &[u32],
        g: f64,
        precision: Precision,
        floor: f64,
    ) -> bool {
        let saved: Vec<f64> = component
            .iter()
            .map(|&n| self.values[n as usize][1])
            .collect();
        for &node in component {
            let [lower, upper] = self.values[node as usize];
            self.values[node as usize][1] = upper.min(lower + 0.5 * precision.allowed(lower));
        }
        let verified = component.iter().all(|&node| {
            let candidate = self.values[node as usize][1];
            self.bellman(node as usize, g)[1]
                <= candidate + VERIFICATION_SLACK * candidate.abs().max(floor)
        });
        if !verified {
            for (&node, upper) in component.iter().zip(saved) {
                self.values[node as usize][1] = upper;
            }
        }
        verified
    }
}

/// Below g = 1, the ratio of an interval's width to its precision at which a node is no
/// longer updated: its successors then read bounds within half the precision, so its
/// predecessors get within it (20x20 and 24x24 gridworlds at g = 0.99: 7 to 12% less time, two
/// or three sweeps more; at g = 1 the lower bounds must settle for ties to be recognised).
/// 0.3 was no faster; 0.8 took more sweeps and more time.
const SETTLED: f64 = 0.5;

/// How far a gap whose ratio to the precision was `first` has come down to the precision when
/// its ratio is `ratio`, on a log scale: 0 while it is still `first` (or wider), 1 once it is
/// within the precision (ratio 1).
fn gap_fraction(first: f64, ratio: f64) -> f64 {
    if ratio <= 1.0 || first <= 1.0 {
        return 1.0;
    }
    if !first.is_finite() {
        return 0.0;
    }
    ((first / ratio).ln() / first.ln()).clamp(0.0, 1.0)
}

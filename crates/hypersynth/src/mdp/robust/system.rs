//! The robust equation system and its solve, one strongly connected component at a time in
//! reverse topological order: Gauss–Seidel interval iteration with the adversary's greedy reply
//! at every interval choice, end components deflated (g = 1) and optimistic upper bounds.

use std::ops::Range;

use bit_set::BitSet;

use super::Intervals;
use super::inner::{self, Entry};
use crate::csr::Csr;
use crate::mdp::graph::{Predecessors, maximal_end_components, strongly_connected_components_by};
use crate::mdp::model::{Mdp, MdpBuilder, MdpState};
use crate::mdp::solve::SolveError;
use crate::mdp::solve::system::{inside, place, slots};
use crate::stage::Meter;

/// Sweeps between two deflations of a component's end components at g = 1 (besides the one
/// made whenever the lower bounds settle).
const DEFLATION_PERIOD: u32 = 32;

/// Relative rounding allowed when checking that an optimistic upper bound is a
/// super-fixed-point (as the nominal solver allows).
const VERIFICATION_SLACK: f64 = 1e-13;

/// The iterated system. Its unknowns (*slots*) are the nodes: one per collapsed exact end
/// component and one per other iterated state, in the order of their first state; every other
/// state gets a constant slot after them (its payoff, or 0). Each node lists the choices of its
/// states that do not stay inside its end component, with their targets as slots; an exact
/// choice reads its probabilities from the model, an interval choice its bounds from the
/// intervals.
pub(super) struct System<'a> {
    pub(super) slot: Vec<u32>,
    node_offsets: Vec<u32>,
    targets: Csr<u32, u32>,
    /// Per choice of the system: where its probabilities (exact, in the model's pool) or bounds
    /// (interval) start.
    first: Vec<u32>,
    uncertain: BitSet,
    instant: BitSet,
    /// The model's pool of distributions.
    probabilities: &'a [f64],
    bounds: &'a [[f64; 2]],
    /// `[lower, upper]` per slot.
    pub(super) values: Vec<[f64; 2]>,
}

/// What solving the components did.
pub(super) struct Solved {
    pub(super) sweeps: u32,
    pub(super) gap: f64,
}

impl<'a> System<'a> {
    pub(super) fn new(
        mdp: &'a Mdp,
        intervals: &'a Intervals,
        order: &[MdpState],
        component: &[Option<u32>],
    ) -> Self {
        // A node lies within [0, the largest payoff]; a state outside `order` is worth its
        // payoff, or 0.
        let max_payoff = mdp
            .states()
            .filter_map(|s| mdp.payoff(s))
            .fold(0.0, f64::max);
        let mut in_order = BitSet::with_capacity(mdp.num_states());
        for state in order {
            in_order.insert(state.index());
        }
        let bounds = |state: MdpState| match mdp.payoff(state) {
            Some(payoff) => [payoff, payoff],
            None if in_order.contains(state.index()) => [0.0, max_payoff],
            None => [0.0, 0.0],
        };
        let (slot, members, values) = slots(mdp, order, component, bounds);
        let mut system = System {
            slot,
            node_offsets: vec![0],
            targets: Csr::new(),
            first: Vec::new(),
            uncertain: BitSet::new(),
            instant: BitSet::new(),
            probabilities: mdp.pool(),
            bounds: &intervals.bounds,
            values,
        };
        for node in members.rows() {
            for &state in members.row(node) {
                let mec = component[state.index()];
                for choice in mdp.choices(state) {
                    // A choice that stays inside its state's end component is not a node's.
                    if mec.is_some()
                        && mdp
                            .targets(choice)
                            .iter()
                            .all(|t| component[t.index()] == mec)
                    {
                        continue;
                    }
                    let row = system.targets.num_rows();
                    if mdp.is_instant(choice) {
                        system.instant.insert(row);
                    }
                    match intervals.first(choice) {
                        Some(first) => {
                            system.uncertain.insert(row);
                            system.first.push(first);
                        }
                        None => {
                            system.first.push(mdp.distribution_starts()[choice.index()]);
                        }
                    }
                    for &target in mdp.targets(choice) {
                        system.targets.push(system.slot[target.index()]);
                    }
                    system.targets.finish_row();
                }
            }
            system.node_offsets.push(system.targets.num_rows() as u32);
        }
        system
    }

    fn nodes(&self) -> usize {
        self.node_offsets.len() - 1
    }

    fn choices(&self, node: usize) -> Range<usize> {
        self.node_offsets[node] as usize..self.node_offsets[node + 1] as usize
    }

    /// The target slots of every choice of `node`, one choice after the other.
    fn successor_slots(&self, node: u32) -> std::iter::Copied<std::slice::Iter<'_, u32>> {
        let choices = self.choices(node as usize);
        if choices.is_empty() {
            return [].iter().copied();
        }
        let start = self.targets.range(choices.start as u32).start;
        let end = self.targets.range(choices.end as u32 - 1).end;
        self.targets.entries()[start..end].iter().copied()
    }

    /// The lower and upper Q-values of a choice of the system: each bound's own worst case for
    /// an interval choice (the adversary replies to the values it is computed from).
    fn choice_values(&self, choice: usize, g: f64, scratch: &mut Vec<Entry>) -> [f64; 2] {
        let targets = self.targets.row(choice as u32);
        let first = self.first[choice] as usize;
        let f = if self.instant.contains(choice) {
            1.0
        } else {
            g
        };
        if !self.uncertain.contains(choice) {
            let mut sum = [0.0, 0.0];
            for (&target, &p) in targets.iter().zip(&self.probabilities[first..]) {
                let [lower, upper] = self.values[target as usize];
                sum[0] += p * lower;
                sum[1] += p * upper;
            }
            return [f * sum[0], f * sum[1]];
        }
        let bounds = &self.bounds[first..first + targets.len()];
        let mut q = [0.0, 0.0];
        for (side, q) in q.iter_mut().enumerate() {
            scratch.clear();
            scratch.extend(targets.iter().zip(bounds).map(|(&target, b)| Entry {
                value: self.values[target as usize][side],
                lower: b[0],
                upper: b[1],
            }));
            *q = f * inner::minimum(scratch);
        }
        q
    }

    /// The adversary's reply at an interval choice of the system to the lower bounds, as
    /// probabilities per target; an exact choice's own probabilities.
    fn reply(&self, choice: usize, out: &mut Vec<f64>) {
        let targets = self.targets.row(choice as u32);
        let first = self.first[choice] as usize;
        if self.uncertain.contains(choice) {
            let values: Vec<f64> = targets
                .iter()
                .map(|&t| self.values[t as usize][0])
                .collect();
            inner::distribution(&values, &self.bounds[first..first + targets.len()], out);
        } else {
            out.clear();
            out.extend_from_slice(&self.probabilities[first..first + targets.len()]);
        }
    }

    fn bellman(&self, node: usize, g: f64, scratch: &mut Vec<Entry>) -> [f64; 2] {
        let mut best = [0.0f64, 0.0f64];
        for choice in self.choices(node) {
            let [lower, upper] = self.choice_values(choice, g, scratch);
            best = [best[0].max(lower), best[1].max(upper)];
        }
        best
    }

    /// One clamped in-place update of `node`: how far its lower bound rose, and its width.
    fn update(&mut self, node: usize, g: f64, scratch: &mut Vec<Entry>) -> (f64, f64) {
        let best = self.bellman(node, g, scratch);
        let [old_lower, old_upper] = self.values[node];
        let new = [best[0].max(old_lower), best[1].min(old_upper)];
        self.values[node] = new;
        (new[0] - old_lower, new[1] - new[0])
    }

    fn width(&self, component: &[u32]) -> f64 {
        component
            .iter()
            .map(|&n| self.values[n as usize][1] - self.values[n as usize][0])
            .fold(0.0, f64::max)
    }

    /// Solves the components of the node graph in reverse topological order.
    pub(super) fn solve_components(
        &mut self,
        g: f64,
        epsilon: f64,
        max_iterations: u32,
        meter: &mut Meter<'_>,
    ) -> Result<Solved, SolveError> {
        let mut components =
            strongly_connected_components_by(self.nodes(), |node| self.successor_slots(node));
        meter.set_total(self.nodes() as u64);
        let mut position = vec![0u32; self.nodes()];
        let scale = self.values.iter().map(|v| v[1]).fold(1.0f64, f64::max);
        let mut scratch = Vec::new();
        let (mut sweeps, mut gap, mut done) = (0u32, 0.0f64, 0u64);
        for index in components.rows() {
            let component = components.row_mut(index);
            component.sort_unstable();
            let component = &*component;
            let node = component[0];
            if component.len() == 1 && !self.successor_slots(node).any(|t| t == node) {
                let (_, width) = self.update(node as usize, g, &mut scratch);
                gap = gap.max(width);
            } else {
                let (used, width) = self.iterate(
                    component,
                    g,
                    epsilon,
                    scale,
                    max_iterations,
                    &mut position,
                    &mut scratch,
                )?;
                sweeps = sweeps.saturating_add(used);
                gap = gap.max(width);
            }
            done += component.len() as u64;
            meter.set(done);
        }
        Ok(Solved { sweeps, gap })
    }

    /// Gauss–Seidel sweeps of both bounds over `component` (its successors outside are final)
    /// until they are within `epsilon`. At g = 1 the end components the adversary's reply to
    /// the lower bounds leaves are deflated whenever the lower bounds settle and every
    /// `DEFLATION_PERIOD` sweeps; whenever the lower bounds settle, the optimistic upper bound
    /// `min(U, L + ε/2)` is offered and kept if one update does not raise it anywhere.
    #[allow(clippy::too_many_arguments)]
    fn iterate(
        &mut self,
        component: &[u32],
        g: f64,
        epsilon: f64,
        scale: f64,
        max_iterations: u32,
        position: &mut [u32],
        scratch: &mut Vec<Entry>,
    ) -> Result<(u32, f64), SolveError> {
        let mut tolerance = epsilon;
        let mut sweeps = 0u32;
        loop {
            if sweeps == max_iterations {
                return Err(SolveError::IterationLimit {
                    iterations: sweeps,
                    gap: self.width(component),
                    epsilon,
                });
            }
            sweeps += 1;
            let (mut rise, mut width) = (0.0f64, 0.0f64);
            for &node in component {
                let (r, w) = self.update(node as usize, g, scratch);
                rise = rise.max(r);
                width = width.max(w);
            }
            if width <= epsilon {
                return Ok((sweeps, width));
            }
            let settled = rise <= tolerance;
            if g == 1.0 && (settled || sweeps.is_multiple_of(DEFLATION_PERIOD)) {
                self.deflate(component, position, scratch);
                width = self.width(component);
                if width <= epsilon {
                    return Ok((sweeps, width));
                }
            }
            if settled {
                if self.try_optimistic_upper(component, g, epsilon, scale, scratch) {
                    return Ok((sweeps, self.width(component)));
                }
                tolerance *= 0.5;
            }
        }
    }

    /// Sets the upper bounds of `component` to `min(U, L + ε/2)` if that is a super-fixed-point
    /// of the robust Bellman operator (up to rounding); returns whether it did. Any
    /// super-fixed-point bounds the least fixed point, which is the value, from above.
    fn try_optimistic_upper(
        &mut self,
        component: &[u32],
        g: f64,
        epsilon: f64,
        scale: f64,
        scratch: &mut Vec<Entry>,
    ) -> bool {
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
            self.bellman(node as usize, g, scratch)[1] <= candidate + VERIFICATION_SLACK * scale
        });
        if !verified {
            for (&node, upper) in component.iter().zip(saved) {
                self.values[node as usize][1] = upper;
            }
        }
        verified
    }

    /// Deflation (g = 1): the adversary's replies to the lower bounds, fixed, make the component
    /// an MDP; in each of its maximal end components the adversary can keep the run forever
    /// unless the robot leaves, so no state there is worth more than the best choice leaving it
    /// (valued at the upper bounds, with the adversary's reply to them), or 0. The upper bounds
    /// of its states are lowered to that. Sound for any reply the adversary may make: the
    /// argument needs only that the reply keeps the end component's internal choices inside.
    fn deflate(&mut self, component: &[u32], position: &mut [u32], scratch: &mut Vec<Entry>) {
        place(component, position);
        let position = &*position;
        let local = |slot: u32| inside(component, position, slot);
        let outside = component.len() as u32;
        let mut builder = MdpBuilder::new();
        let action = builder.action("reply").expect("a valid name");
        let mut choices = Vec::new();
        let mut reply = Vec::new();
        let mut successors: Vec<(MdpState, f64)> = Vec::new();
        for &node in component {
            builder.add_decision_state().expect("a state");
            for choice in self.choices(node as usize) {
                self.reply(choice, &mut reply);
                successors.clear();
                for (&target, &p) in self.targets.row(choice as u32).iter().zip(&reply) {
                    if p > 0.0 {
                        let target = local(target).unwrap_or(outside);
                        successors.push((MdpState::from_u32(target), p));
                    }
                }
                // The reply sums to 1 up to rounding, which the builder accepts and normalises.
                let total: f64 = successors.iter().map(|s| s.1).sum();
                for s in successors.iter_mut() {
                    s.1 /= total;
                }
                builder
                    .add_choice(action, &successors)
                    .expect("a distribution");
                choices.push(choice);
            }
        }
        builder.add_absorbing_state(0.0).expect("a payoff");
        builder.set_initial(MdpState::new(0));
        let fixed = builder.build().expect("a valid model");
        let candidates: Vec<MdpState> = MdpState::range(component.len()).collect();
        let (mec, count) =
            maximal_end_components(&fixed, &Predecessors::new(&fixed, |_| true), &candidates);
        if count == 0 {
            return;
        }
        let mut best = vec![0.0f64; count as usize];
        for state in candidates.iter().copied() {
            let Some(m) = mec[state.index()] else {
                continue;
            };
            for choice in fixed.choices(state) {
                let leaves = fixed
                    .targets(choice)
                    .iter()
                    .any(|&t| mec[t.index()] != Some(m));
                if leaves {
                    let [_, upper] = self.choice_values(choices[choice.index()], 1.0, scratch);
                    best[m as usize] = best[m as usize].max(upper);
                }
            }
        }
        for (state, &node) in candidates.iter().zip(component) {
            if let Some(m) = mec[state.index()] {
                let [lower, upper] = self.values[node as usize];
                self.values[node as usize][1] = upper.min(best[m as usize]).max(lower);
            }
        }
    }

    /// The lower and upper vectors per state.
    pub(super) fn expand(self) -> (Vec<f64>, Vec<f64>) {
        self.slot
            .iter()
            .map(|&slot| {
                let [lower, upper] = self.values[slot as usize];
                (lower, upper)
            })
            .unzip()
    }
}

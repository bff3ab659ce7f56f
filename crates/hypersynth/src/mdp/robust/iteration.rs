//! The robust solve's methods on the equation system ([`System`] over the [`Robust`]
//! expectation), one strongly connected component at a time in reverse topological order:
//! Gauss–Seidel interval iteration with the adversary's greedy reply at every interval choice,
//! end components deflated (g = 1) and optimistic upper bounds.

use bit_set::BitSet;

use super::Intervals;
use crate::csr::Csr;
use crate::mdp::graph::{Predecessors, maximal_end_components, strongly_connected_components_by};
use crate::mdp::model::{Mdp, MdpBuilder, MdpState};
use crate::mdp::operator::{Operator, Payoff, Robust};
use crate::mdp::solve::system::{System, inside, place, slots};
use crate::mdp::solve::{Precision, SolveError};
use crate::stage::Meter;

/// Sweeps between two deflations of a component's end components at g = 1 (besides the one
/// made whenever the lower bounds settle).
const DEFLATION_PERIOD: u32 = 32;

/// The robust system, over the model's pool of distributions and the intervals' bounds.
pub(super) type RobustSystem<'a> = System<Robust<'a>>;

/// What solving the components did.
pub(super) struct Solved {
    pub(super) sweeps: u32,
    pub(super) gap: f64,
}

impl<'a> RobustSystem<'a> {
    /// The system of the robust solve. Its unknowns (*slots*) are the nodes: one per collapsed
    /// exact end component and one per other iterated state of `order`, in the order of their
    /// first state; every other state gets a constant slot after them (its payoff, or 0). Each
    /// node lists the choices of its states that do not stay inside its end component, with
    /// their targets as slots; an exact choice reads its probabilities from the model, an
    /// interval choice its bounds from the intervals.
    pub(super) fn with_intervals(
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
        let mut operator = Operator::new(Robust::new(mdp.pool(), &intervals.bounds));
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
                    let interval = intervals.first(choice);
                    let start =
                        interval.unwrap_or_else(|| mdp.distribution_starts()[choice.index()]);
                    let targets = mdp.targets(choice).iter().map(|t| slot[t.index()]);
                    let row = operator.push_row(targets, start, mdp.is_instant(choice));
                    if interval.is_some() {
                        operator.expectation.set_uncertain(row);
                    }
                }
            }
            operator.finish_node();
        }
        System {
            slot,
            operator,
            values,
            sources: Csr::new(),
            dirty: Vec::new(),
        }
    }

    /// The largest width of an interval of `component`.
    fn width(&self, component: &[u32]) -> f64 {
        self.gap(component, Precision::absolute(f64::INFINITY)).0
    }

    /// Solves the components of the node graph in reverse topological order.
    pub(super) fn solve_components(
        &mut self,
        g: f64,
        precision: Precision,
        max_iterations: u32,
        meter: &mut Meter<'_>,
    ) -> Result<Solved, SolveError> {
        let mut components =
            strongly_connected_components_by(self.nodes(), |node| self.successor_slots(node));
        meter.set_total(self.nodes() as u64);
        let mut position = vec![0u32; self.nodes()];
        let scale = self.values.iter().map(|v| v[1]).fold(1.0f64, f64::max);
        let (mut sweeps, mut gap, mut done) = (0u32, 0.0f64, 0u64);
        for index in components.rows() {
            let component = components.row_mut(index);
            component.sort_unstable();
            let component = &*component;
            let node = component[0];
            if component.len() == 1 && !self.successor_slots(node).any(|t| t == node) {
                let (_, width) = self.update(node as usize, g);
                gap = gap.max(width);
            } else {
                let (used, width) = self.iterate(
                    component,
                    g,
                    precision,
                    scale,
                    max_iterations,
                    &mut position,
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
    /// until they are within `precision` (absolute, or relative to each lower bound). At g = 1
    /// the end components the adversary's reply to the lower bounds leaves are deflated
    /// whenever the lower bounds settle and every `DEFLATION_PERIOD` sweeps; whenever the lower
    /// bounds settle, the optimistic upper bound `min(U, L + ε/2)` is offered and kept if one
    /// update does not raise it anywhere.
    fn iterate(
        &mut self,
        component: &[u32],
        g: f64,
        precision: Precision,
        scale: f64,
        max_iterations: u32,
        position: &mut [u32],
    ) -> Result<(u32, f64), SolveError> {
        let epsilon = precision.epsilon;
        // Whether the component is done: every width within what the precision allows (the
        // sweep's largest width suffices for an absolute precision).
        let met = |system: &Self, width: f64| match precision.relative {
            false => width <= epsilon,
            true => system.gap(component, precision).1 <= 1.0,
        };
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
                let (r, w) = self.update(node as usize, g);
                rise = rise.max(r);
                width = width.max(w);
            }
            if met(self, width) {
                return Ok((sweeps, width));
            }
            let settled = rise <= tolerance;
            if g == 1.0 && (settled || sweeps.is_multiple_of(DEFLATION_PERIOD)) {
                self.deflate(component, position);
                width = self.width(component);
                if met(self, width) {
                    return Ok((sweeps, width));
                }
            }
            if settled {
                if self.try_optimistic_upper(component, g, precision, scale) {
                    return Ok((sweeps, self.width(component)));
                }
                tolerance *= 0.5;
            }
        }
    }

    /// Deflation (g = 1): the adversary's replies to the lower bounds, fixed, make the component
    /// an MDP; in each of its maximal end components the adversary can keep the run forever
    /// unless the robot leaves, so no state there is worth more than the best choice leaving it
    /// (valued at the upper bounds, with the adversary's reply to them), or 0. The upper bounds
    /// of its states are lowered to that. Sound for any reply the adversary may make: the
    /// argument needs only that the reply keeps the end component's internal choices inside.
    fn deflate(&mut self, component: &[u32], position: &mut [u32]) {
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
                let values = &self.values;
                self.operator
                    .reply(choice, |slot| values[slot as usize][0], &mut reply);
                successors.clear();
                for (&target, &p) in self.operator.targets(choice).iter().zip(&reply) {
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
                    let values = &self.values;
                    let [upper] =
                        self.operator
                            .q(choices[choice.index()], &Payoff { g: 1.0 }, &|slot| {
                                [values[slot as usize][1]]
                            });
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
}

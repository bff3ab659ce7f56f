//! The least expected number of robot moves to a goal state over the eligible choices, which
//! breaks the policy's ties at g = 1.
//!
//! # Measured and not kept
//! On the 30x30 gridworld of `benches/gridworld_40.rs` (components of 527k and 945k states,
//! 34 and 109 sweeps, 17M and 59M updates; the sweeps are about 3 s of the policy stage's 5):
//! - *starting from the fewest moves* (a 0-1 breadth-first search over the eligible choices,
//!   a lower bound and a sub-fixed point, so the sweeps still rise to the same least fixed
//!   point): 98 sweeps instead of 109 for the large component, and the search cost what they
//!   saved (1.5 s unoptimised). The slow part is the adversary's random walk, not the distance;
//! - *skipping a state until its successors have risen by a share of the tolerance* (a rise
//!   bound per state instead of a dirty flag; sound for the stopping rule, since a state's
//!   update rises at most by the sum of its successors' rises): 48–51M updates instead of 59M,
//!   about 10% of the stage, at the cost of the times no longer being those of plain sweeps;
//! - *a choice of one successor computed without the sum*: 2.75 s against 2.87 (three
//!   alternating runs each), within the noise.

use bit_set::BitSet;

use super::TIME_TOLERANCE;
use crate::csr::Csr;
use crate::index::Id;
use crate::mdp::graph::{Predecessors, strongly_connected_components_by};
use crate::mdp::model::{ChoiceId, Mdp, MdpState};
use crate::mdp::operator::{Moves, Nominal, Operator, model_q};
use crate::stage::Meter;

/// The strongly connected components of the eligible choices' graph on the `counted` states
/// (edges from a counted state through an eligible choice to a counted successor), found on
/// `predecessors`, the eligible choices' predecessor lists: the same graph reversed, hence the
/// same components, listed in topological order of the graph (every edge leaving a component
/// leads to one listed after it). The policy's ranking searches the same lists, so both are
/// built from one structure and can run side by side.
pub(super) fn eligible_components(
    predecessors: &Predecessors,
    counted: &BitSet,
) -> Csr<u32, MdpState> {
    strongly_connected_components_by(predecessors.num_states(), |state: MdpState| {
        let inside = counted.contains(state.index());
        predecessors
            .of(state)
            .filter(move |owner| inside && counted.contains(owner.index()))
    })
}

/// Approximates from below the least expected number of moves to a goal state using eligible
/// choices only, for the `counted` states (all others count 0), given the eligible choices'
/// graph's `components` on them ([`eligible_components`]) and the counted states by increasing
/// rank (`order`). The components are solved from last to first (reverse topological order):
/// a trivial component in one step, others by Gauss–Seidel sweeps in rank order (closest to a
/// goal first, so that every update sees fresh successors where it can) until no value rises
/// by more than `TIME_TOLERANCE` of itself, or `max_sweeps` ([`TimeSweeps`]: on compact copies,
/// skipping the states none of whose successors moved; ten times faster on 20x20 gridworlds
/// than sweeps over the model, with the same times to the bit). A component's times depend on
/// its members' order and its successors' final times only, not on the order the components
/// were found in.
pub(super) fn expected_moves(
    mdp: &Mdp,
    counted: &BitSet,
    order: &[MdpState],
    mut components: Csr<u32, MdpState>,
    eligible: &impl Fn(ChoiceId) -> bool,
    max_sweeps: u32,
    meter: &mut Meter<'_>,
) -> Vec<f64> {
    let n = mdp.num_states();
    // Every component of several states in rank order, before the sweeps: the positions in
    // `order` (4 bytes per state) are freed before the sweeps' copies are made.
    let mut rank_position = vec![u32::NONE; n];
    for (i, &state) in order.iter().enumerate() {
        rank_position[state.index()] = i as u32;
    }
    for index in components.rows() {
        let component = components.row_mut(index);
        if component.len() > 1 {
            component.sort_unstable_by_key(|&state| rank_position[state.index()]);
        }
    }
    drop(rank_position);
    let mut times = vec![0.0f64; n];
    let mut scratch = TimeSweeps::new(n, mdp.pool().len());
    for index in components.rows().rev() {
        let component = components.row(index);
        if !counted.contains(component[0].index()) {
            continue;
        }
        let state = component[0];
        let trivial = component.len() == 1
            && !mdp
                .choices(state)
                .filter(|&c| eligible(c))
                .any(|c| mdp.targets(c).contains(&state));
        if trivial {
            update_time(mdp, eligible, state, &mut times);
        } else {
            scratch.sweep(mdp, component, eligible, &mut times, max_sweeps);
        }
        meter.advance(component.len() as u64);
    }
    times
}

/// One Gauss–Seidel update of `state`'s time over the model: the least, over its eligible
/// choices, of the choice's cost plus its successors' times, kept if it does not lower the
/// time. Returns whether the time rose by more than `TIME_TOLERANCE` of itself.
fn update_time(
    mdp: &Mdp,
    eligible: &impl Fn(ChoiceId) -> bool,
    state: MdpState,
    times: &mut [f64],
) -> bool {
    let best = mdp
        .choices(state)
        .filter(|&c| eligible(c))
        .map(|choice| choice_time(mdp, choice, times))
        .fold(f64::INFINITY, f64::min);
    let old = times[state.index()];
    times[state.index()] = best.max(old);
    best > old + TIME_TOLERANCE * old.max(1.0)
}

/// The expected moves through `choice` given its successors' `times`: its cost (1 for a move,
/// 0 for an instant choice) plus their expectation, summed in the model's order.
pub(super) fn choice_time(mdp: &Mdp, choice: ChoiceId, times: &[f64]) -> f64 {
    model_q(mdp, choice, None, &Moves, &|t| [times[t.index()]])[0]
}

/// One non-trivial component of the eligible choices' graph, copied into compact arrays for
/// [`expected_moves`]' sweeps: its states are numbered by their position in the sweep order,
/// the targets outside it get slots after them holding their (final) times, and each choice
/// keeps its transitions in the model's order, so that every update performs exactly the
/// floating-point operations of an update on the model (the same times, bit for bit) while a
/// sweep streams through memory instead of jumping across the whole model. Probabilities are
/// read from a pool of the distinct distributions the component's choices use, copied from the
/// model's pool in order of first use (a start per choice, as in the equation system): with a
/// random sigma_L the model's pool holds one distribution per adversary arena state (about 0.6
/// probabilities per product state), more than the cache holds on large maps, and reading it
/// at each choice's start was where the sweeps waited; the component's own pool is laid out in
/// sweep order and is never larger than the model's (a copy per transition would cost 8 bytes
/// per transition of the component): the policy stage of the 24x24 gridworld at g = 1 took
/// 1.8–2.0 s instead of 2.4–2.5 (`benches/README.md`, "Policy and evaluation stages"). The
/// copy is the Bellman [`Operator`] of the [`Moves`] objective over that pool, and its buffers
/// are reused from one component to the next.
struct TimeSweeps {
    /// Per model state, its slot while its component is swept (`u32::NONE` otherwise).
    slot: Vec<u32>,
    /// The states given a slot, to reset `slot` afterwards.
    slotted: Vec<MdpState>,
    /// Per slot, its time.
    values: Vec<f64>,
    /// Per member (node), its eligible choices (rows) with their target slots, where their
    /// probabilities start in the operator's pool (the distinct distributions of the
    /// component's eligible choices, in order of first use), and whether they are instant (a
    /// bit per choice, where a cost per choice took 8 bytes at the policy stage's peak).
    operator: Operator<Nominal<Vec<f64>>>,
    /// Per start in the model's pool, where that distribution starts in `pool` while the
    /// component is swept (`u32::NONE` otherwise), and the starts given one, to reset it.
    pool_slot: Vec<u32>,
    pooled: Vec<u32>,
    /// Per member, the members with an eligible choice into it (to mark them for the next
    /// update when its time changes).
    sources: Csr<u32, u32>,
    /// The members whose successors' times changed since their last update (a byte each, as
    /// in `System::dirty`).
    dirty: Vec<bool>,
}

impl TimeSweeps {
    fn new(n: usize, pool: usize) -> Self {
        TimeSweeps {
            slot: vec![u32::NONE; n],
            slotted: Vec::new(),
            values: Vec::new(),
            operator: Operator::new(Nominal { pool: Vec::new() }),
            pool_slot: vec![u32::NONE; pool],
            pooled: Vec::new(),
            sources: Csr::new(),
            dirty: Vec::new(),
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
        let operator = &mut self.operator;
        operator.clear();
        operator.expectation.pool.clear();
        let model_pool = mdp.pool();
        for &state in component {
            for choice in mdp.choices(state).filter(|&c| eligible(c)) {
                let targets = mdp.targets(choice);
                let start = mdp.distribution_starts()[choice.index()] as usize;
                if self.pool_slot[start].is_none() {
                    let pool = &mut operator.expectation.pool;
                    self.pool_slot[start] = pool.len() as u32;
                    self.pooled.push(start as u32);
                    pool.extend_from_slice(&model_pool[start..start + targets.len()]);
                }
                let slots = targets.iter().map(|&target| {
                    let mut slot = self.slot[target.index()];
                    if slot.is_none() {
                        slot = self.values.len() as u32;
                        self.slot[target.index()] = slot;
                        self.values.push(times[target.index()]);
                        self.slotted.push(target);
                    }
                    slot
                });
                operator.push_row(slots, self.pool_slot[start], mdp.is_instant(choice));
            }
            operator.finish_node();
        }
        // Grouped straight from the copied targets (no list of pairs: 8 bytes per transition
        // of the component, doubled as it grew, were the policy stage's peak).
        let operator = &self.operator;
        self.sources = Csr::group_from(members, || {
            (0..members).flat_map(move |i| {
                operator
                    .successor_slots(i as u32)
                    .filter(move |&slot| (slot as usize) < members)
                    .map(move |slot| (slot, i as u32))
            })
        });
        self.dirty.clear();
        self.dirty.resize(members, true);
        for _ in 0..max_sweeps {
            let mut changed = false;
            for i in 0..members {
                if !std::mem::replace(&mut self.dirty[i], false) {
                    continue;
                }
                let values = &self.values;
                let [best] = operator.backup(i, &Moves, &|t| [values[t as usize]]);
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
        for start in self.pooled.drain(..) {
            self.pool_slot[start as usize] = u32::NONE;
        }
    }
}

#[cfg(test)]
mod tests {
    use rand_core::RngCore;

    use super::*;
    use crate::mdp::graph::strongly_connected_components;
    use crate::mdp::solve::EXACT_LIMIT;
    use crate::mdp::testing::{random_mdp_with_instant_choices, rng};

    /// The times by plain Gauss–Seidel sweeps over the model: the components of the eligible
    /// graph built forwards (found by Tarjan's search on it, in its reverse topological order),
    /// each swept in rank order, every member updated in every sweep, its probabilities read
    /// from the model, no copy, no slots, no skipping. Counts in `large` the components beyond
    /// `EXACT_LIMIT`.
    fn swept_on_the_model(
        mdp: &Mdp,
        order: &[MdpState],
        eligible: &impl Fn(ChoiceId) -> bool,
        max_sweeps: u32,
        large: &mut usize,
    ) -> Vec<f64> {
        let n = mdp.num_states();
        let mut rank = vec![u32::NONE; n];
        for (i, &state) in order.iter().enumerate() {
            rank[state.index()] = i as u32;
        }
        let counted = |state: MdpState| !rank[state.index()].is_none();
        let mut graph: Csr<MdpState, MdpState> = Csr::with_capacity(n, n);
        for state in mdp.states() {
            if counted(state) {
                for choice in mdp.choices(state).filter(|&c| eligible(c)) {
                    for &t in mdp.targets(choice).iter().filter(|&&t| counted(t)) {
                        graph.push(t);
                    }
                }
            }
            graph.finish_row();
        }
        let mut components = strongly_connected_components(&graph);
        let mut times = vec![0.0f64; n];
        for index in components.rows() {
            let component = components.row_mut(index);
            if !counted(component[0]) {
                continue;
            }
            component.sort_unstable_by_key(|&state| rank[state.index()]);
            *large += usize::from(component.len() > EXACT_LIMIT);
            for _ in 0..max_sweeps {
                let mut changed = false;
                for &state in &*component {
                    changed |= update_time(mdp, eligible, state, &mut times);
                }
                if !changed {
                    break;
                }
            }
        }
        times
    }

    #[test]
    fn compact_sweeps_give_the_times_of_sweeps_over_the_model_bit_for_bit() {
        // Weights 1..=4 over 1..=3 targets: many choices share a distribution, so components
        // share pooled distributions and a component's pool is reused by the next. Up to 1500
        // states, components beyond `EXACT_LIMIT` occur (swept in rank order); 3 sweeps stop
        // components before they settle.
        let mut rng = rng(25);
        let mut large = 0;
        for instance in 0..300 {
            let max_states = if instance % 10 == 0 { 1500 } else { 30 };
            let mdp = random_mdp_with_instant_choices(&mut rng, max_states);
            let mut order: Vec<(u32, MdpState)> = mdp
                .states()
                .filter(|&s| !mdp.is_absorbing(s))
                .map(|s| (rng.next_u32(), s))
                .filter(|&(key, _)| !key.is_multiple_of(8))
                .collect();
            order.sort_unstable();
            let order: Vec<MdpState> = order.into_iter().map(|(_, s)| s).collect();
            let salt = rng.next_u32();
            let eligible = |c: ChoiceId| !(c.index() as u32 ^ salt).is_multiple_of(4);
            let max_sweeps = if instance % 3 == 0 { 3 } else { 1000 };
            let expected = swept_on_the_model(&mdp, &order, &eligible, max_sweeps, &mut large);
            let mut counted = BitSet::with_capacity(mdp.num_states());
            for state in &order {
                counted.insert(state.index());
            }
            let components = eligible_components(&Predecessors::new(&mdp, eligible), &counted);
            let times = expected_moves(
                &mdp,
                &counted,
                &order,
                components,
                &eligible,
                max_sweeps,
                &mut Meter::unobserved(crate::stage::Stage::Policy),
            );
            for state in mdp.states() {
                assert_eq!(
                    times[state.index()].to_bits(),
                    expected[state.index()].to_bits(),
                    "instance {instance}, state {state}: {} against {}",
                    times[state.index()],
                    expected[state.index()]
                );
            }
        }
        assert!(large > 0);
    }
}

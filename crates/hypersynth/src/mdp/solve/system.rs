//! The equation system the values are iterated on, and its solve one strongly connected
//! component at a time, in reverse topological order.

use std::ops::Range;

use bit_set::BitSet;

use super::{EXACT_LIMIT, Precision, QUICK_SWEEPS, SolveError};
use crate::csr::Csr;
use crate::index::Id;
use crate::mdp::graph::strongly_connected_components_by;
use crate::mdp::model::{ChoiceId, Mdp, MdpState};
use crate::mdp::operator::{Expectation, Nominal, Operator, Payoff};
use crate::stage::Meter;

/// The iterated equation system of the nominal and the robust solve: the [`Operator`] over its
/// nodes, with the bounds it is iterated on. Its unknowns (*slots*) are the nodes, in the order
/// of their first state in `order`: one per MEC and one per other state of `order`. Every other
/// state gets a constant slot after them (its payoff, or 0). Each node lists the non-internal
/// choices of its states with their transitions in the model's order and targets replaced by
/// slots, so that a sweep streams through memory and a choice's Q-value is computed with exactly
/// the floating-point operations of [`q_values`](super::q_values) on the expanded vectors (the
/// policy relies on it). The probabilities are not copied: each choice of the system remembers
/// where its model choice's distribution starts in the model's pool of distinct distributions,
/// which is small enough to stay in cache while the sweeps read it (reading a probability per
/// transition from the model instead, the 20x20 gridworld's solve at g = 0.99 took 1.7 times
/// the CPU time: 5.7 s against 3.3 s on a loaded machine). The nominal solve's methods are in
/// this module and its siblings, the robust solve's in `robust/iteration.rs`.
pub(in crate::mdp) struct System<E> {
    /// The slot of every state.
    pub(in crate::mdp) slot: Vec<u32>,
    /// The Bellman operator over the nodes.
    pub(in crate::mdp) operator: Operator<E>,
    /// `[lower, upper]` per slot, together so that one cache line brings both.
    pub(in crate::mdp) values: Vec<[f64; 2]>,
    /// Per position in the component being iterated, the nodes of the component with a choice
    /// into the node there (rebuilt for each component: a reverse graph of all nodes was 4
    /// bytes per node and per edge for the whole solve).
    pub(in crate::mdp) sources: Csr<u32, u32>,
    /// The nodes a sweep must update: some successor's bounds changed since their last
    /// update (the others would recompute the bounds they have). One byte per node rather than
    /// a bit: set and tested in the innermost loop, where `BitSet::insert` was 7% of the time.
    pub(in crate::mdp) dirty: Vec<bool>,
}

/// The nominal system, over the model's pool of distributions.
pub(in crate::mdp) type NominalSystem<'a> = System<Nominal<&'a [f64]>>;

/// The unknowns of an equation system over an MDP: per state its slot (one per collapsed end
/// component and one per other state of `order`, in the order of their first state, then a
/// constant slot per other state), the states of each node, and `[lower, upper]` per slot: a
/// node's lies within `bounds` of each of its states (they share its value), a constant's is
/// `bounds` of its state.
#[allow(clippy::type_complexity)]
pub(in crate::mdp) fn slots(
    mdp: &Mdp,
    order: &[MdpState],
    component: &[Option<u32>],
    bounds: impl Fn(MdpState) -> [f64; 2],
) -> (Vec<u32>, Csr<u32, MdpState>, Vec<[f64; 2]>) {
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
    let mut values = vec![[0.0, f64::INFINITY]; nodes as usize];
    for &state in order {
        let [lower, upper] = bounds(state);
        let value = &mut values[slot[state.index()] as usize];
        *value = [value[0].max(lower), value[1].min(upper)];
    }
    for state in mdp.states() {
        if slot[state.index()].is_none() {
            slot[state.index()] = values.len() as u32;
            values.push(bounds(state));
        }
    }
    (slot, members, values)
}

impl<'a> NominalSystem<'a> {
    pub(super) fn new(
        mdp: &'a Mdp,
        order: &[MdpState],
        component: &[Option<u32>],
        internal: &BitSet,
        bounds: impl Fn(MdpState) -> [f64; 2],
    ) -> Self {
        let (slot, members, values) = slots(mdp, order, component, bounds);
        let nodes = members.num_rows();
        let kept = |choice: ChoiceId| !internal.contains(choice.index());
        // Two passes, so that the choices and transitions are read in the model's order (read
        // node by node, in the layout's order, every state's rows were a cache miss: the
        // system took twice as long). First, in node order, only how many rows and entries
        // each state of a node gets, and where its rows start.
        let mut first_row = vec![0u32; mdp.num_states()];
        let mut node_offsets = Vec::with_capacity(nodes + 1);
        let mut row_offsets = vec![0u32];
        node_offsets.push(0);
        for node in members.rows() {
            for &state in members.row(node) {
                first_row[state.index()] = (row_offsets.len() - 1) as u32;
                for choice in mdp.choices(state).filter(|&c| kept(c)) {
                    let end =
                        row_offsets[row_offsets.len() - 1] as usize + mdp.targets(choice).len();
                    row_offsets.push(u32::try_from(end).expect("at most u32::MAX transitions"));
                }
            }
            node_offsets.push((row_offsets.len() - 1) as u32);
        }
        drop(members);
        // Then, in the model's order, each state's rows where they belong.
        let rows = row_offsets.len() - 1;
        let mut entries = vec![0u32; row_offsets[rows] as usize];
        let mut first_transition = vec![0u32; rows];
        let mut instant = BitSet::with_capacity(rows);
        for state in mdp.states() {
            if slot[state.index()] as usize >= nodes {
                continue;
            }
            let choices = mdp.choices(state).filter(|&c| kept(c));
            for (row, choice) in (first_row[state.index()] as usize..).zip(choices) {
                if mdp.is_instant(choice) {
                    instant.insert(row);
                }
                first_transition[row] = mdp.distribution_starts()[choice.index()];
                let start = row_offsets[row] as usize;
                for (entry, target) in entries[start..].iter_mut().zip(mdp.targets(choice)) {
                    *entry = slot[target.index()];
                }
            }
        }
        System {
            slot,
            operator: Operator::from_parts(
                node_offsets,
                Csr::from_parts(row_offsets, entries),
                first_transition,
                instant,
                Nominal { pool: mdp.pool() },
            ),
            values,
            sources: Csr::new(),
            dirty: Vec::new(),
        }
    }

    /// Solves the strongly connected components of the node graph one by one, in reverse
    /// topological order, so that each sees its successors final (module documentation).
    /// Returns the sweeps made over non-trivial components, summed, and the final gap.
    /// Progress: `meter` goes from `base` to `base + units` as the nodes are solved.
    pub(super) fn solve_components(
        &mut self,
        g: f64,
        precision: Precision,
        max_iterations: u32,
        meter: &mut Meter<'_>,
        (base, units): (u64, u64),
    ) -> Result<(u32, f64), SolveError> {
        let mut components =
            strongly_connected_components_by(self.nodes(), |node| self.successor_slots(node));
        meter.checkpoint();
        let per_node = units as f64 / self.nodes().max(1) as f64;
        let report = |nodes: f64, meter: &mut Meter<'_>| {
            meter.set(base + (nodes * per_node) as u64);
        };
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
                report(done as f64, meter);
                continue;
            }
            // Inside the component, the share of its nodes that the way its gap has come down
            // to epsilon represents (a large one takes many seconds).
            let size = component.len() as u64;
            let mut progress =
                |fraction: f64| report(done as f64 + fraction * size as f64, &mut *meter);
            place(component, &mut position);
            if component.len() > EXACT_LIMIT {
                // A large component is iterated over a compact copy of itself (`block`): the
                // same sums in the same order, from memory it fills densely (the 20x20
                // gridworld's solve at g = 0.99 took 1.45 s in place, 1.03 s over copies).
                let (mut block, local) = self.block(component, &position);
                let (used, width) = block.optimistic_iteration(
                    &local,
                    g,
                    precision,
                    scale,
                    max_iterations,
                    &mut progress,
                )?;
                for (&node, value) in component.iter().zip(&block.values) {
                    self.values[node as usize] = *value;
                }
                sweeps = sweeps.saturating_add(used);
                gap = gap.max(width);
                done += size;
                report(done as f64, meter);
                continue;
            }
            self.sources = self.component_sources(component, &position);
            // Small components get a few sweeps first (most converge at once), then policy
            // iteration, which does not care how small the exits are; sweeps again if that
            // could not be verified.
            let quick = QUICK_SWEEPS.min(max_iterations);
            let (used, width) = match self.optimistic_iteration(
                component,
                g,
                precision,
                scale,
                quick,
                &mut progress,
            ) {
                Ok(done) => done,
                Err(_) if quick < max_iterations => {
                    let (rounds, width, ratio) =
                        self.policy_iteration(component, g, precision, scale);
                    if ratio <= 1.0 {
                        (quick + rounds, width)
                    } else {
                        let (more, width) = self.optimistic_iteration(
                            component,
                            g,
                            precision,
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
            report(done as f64, meter);
        }
        Ok((sweeps, gap))
    }

    /// A system of `component`'s nodes alone, renumbered in its order (`position` maps a node
    /// to its place), followed by one constant slot per transition that leaves it, holding that
    /// target's bounds (final: components are solved after their successors). Its choices,
    /// transitions and probabilities are the component's, in the same order, so that a sweep
    /// of it does exactly the sums a sweep of the component does here. Returns it with its
    /// nodes, `0..component.len()`, ready for [`Self::optimistic_iteration`].
    pub(super) fn block(
        &self,
        component: &[u32],
        position: &[u32],
    ) -> (NominalSystem<'a>, Vec<u32>) {
        let mut operator = Operator::new(Nominal {
            pool: self.operator.expectation.pool,
        });
        let mut outside = Vec::new();
        for &node in component {
            for choice in self.choices(node as usize) {
                let targets = self.operator.targets(choice).iter().map(|&target| {
                    inside(component, position, target).unwrap_or_else(|| {
                        outside.push(target);
                        (component.len() + outside.len() - 1) as u32
                    })
                });
                operator.push_row(
                    targets,
                    self.operator.start(choice) as u32,
                    self.operator.is_instant(choice),
                );
            }
            operator.finish_node();
        }
        let mut block = System {
            slot: Vec::new(),
            operator,
            values: component.iter().map(|&n| self.values[n as usize]).collect(),
            sources: Csr::new(),
            dirty: Vec::new(),
        };
        block
            .values
            .extend(outside.iter().map(|&t| self.values[t as usize]));
        // Its nodes are their own places: the list of them is its own `position`.
        let nodes: Vec<u32> = (0..component.len() as u32).collect();
        block.sources = block.component_sources(&nodes, &nodes);
        block.dirty = vec![false; component.len()];
        (block, nodes)
    }
}

impl<E: Expectation> System<E> {
    /// The number of nodes (unknowns).
    pub(in crate::mdp) fn nodes(&self) -> usize {
        self.operator.nodes()
    }

    /// The choices of `node` (rows of the operator).
    pub(in crate::mdp) fn choices(&self, node: usize) -> Range<usize> {
        self.operator.choices(node)
    }

    /// The target slots of all choices of `node` ([`Operator::successor_slots`]).
    pub(in crate::mdp) fn successor_slots(
        &self,
        node: u32,
    ) -> std::iter::Copied<std::slice::Iter<'_, u32>> {
        self.operator.successor_slots(node)
    }

    /// The reverse links of `component` (see `sources`), whose nodes `position` maps to their
    /// places ([`place`]).
    pub(in crate::mdp) fn component_sources(
        &self,
        component: &[u32],
        position: &[u32],
    ) -> Csr<u32, u32> {
        Csr::group_from(component.len(), || {
            component.iter().flat_map(move |&node| {
                self.successor_slots(node).filter_map(move |target| {
                    inside(component, position, target).map(|i| (i, node))
                })
            })
        })
    }

    /// The Bellman backup of `node` under the current values: its best lower and upper
    /// Q-values.
    #[inline]
    pub(in crate::mdp) fn bellman(&self, node: usize, g: f64) -> [f64; 2] {
        let values = &self.values;
        self.operator
            .backup(node, &Payoff { g }, &|slot| values[slot as usize])
    }

    /// One clamped in-place update of `node`; returns how far its lower bound rose and its
    /// width.
    #[inline]
    pub(in crate::mdp) fn update(&mut self, node: usize, g: f64) -> (f64, f64) {
        let best = self.bellman(node, g);
        let [old_lower, old_upper] = self.values[node];
        let new = [best[0].max(old_lower), best[1].min(old_upper)];
        self.values[node] = new;
        (new[0] - old_lower, new[1] - new[0])
    }

    /// The largest width of an interval of `component`, and the largest ratio of a width to the
    /// width `precision` allows (at most 1 once the component is done).
    pub(in crate::mdp) fn gap(&self, component: &[u32], precision: Precision) -> (f64, f64) {
        component.iter().fold((0.0, 0.0), |(width, ratio), &n| {
            let [lower, upper] = self.values[n as usize];
            (
                width.max(upper - lower),
                ratio.max(precision.ratio(lower, upper)),
            )
        })
    }

    /// The lower and upper vectors per state (the rest of the system is freed first).
    pub(in crate::mdp) fn expand(mut self) -> (Vec<f64>, Vec<f64>) {
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

/// Writes into `position` the place of each node of `component` (only the component's own
/// entries: no reset between components).
pub(in crate::mdp) fn place(component: &[u32], position: &mut [u32]) {
    for (i, &node) in component.iter().enumerate() {
        position[node as usize] = i as u32;
    }
}

/// The place of `target` in `component` if it belongs to it: when the entry of `position` it
/// finds points back at it ([`place`]; a binary search per edge instead made large components'
/// setup slow).
pub(in crate::mdp) fn inside(component: &[u32], position: &[u32], target: u32) -> Option<u32> {
    let i = *position.get(target as usize)?;
    (component.get(i as usize) == Some(&target)).then_some(i)
}

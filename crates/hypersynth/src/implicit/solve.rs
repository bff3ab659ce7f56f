//! Certified values over the index space (docs/semantics.md §6.4, §6.5, §13.2): interval
//! iteration on the MDP's rules, with bounds stored only for the states that can still change.
//!
//! The states are those of the explicit MDP, numbered alike: absorbing ones take their payoff,
//! and pairs of lower and upper bounds cover the others (chance and decision nodes: the *live*
//! states), found through a bit set and a count per 32-bit block of it. As in the explicit
//! solver, the graph speaks first (`qualitative.rs`): live states that cannot reach a positive
//! payoff are fixed to 0 (this includes closed sets of chance nodes, where an upper bound would
//! otherwise never come down), the others start at `[0, highest payoff they can reach]`, and at
//! `g = 1` those from which some policy reaches that payoff with probability 1 are fixed to it.
//! The rest are solved one strongly connected component at a time, successors first:
//! Gauss–Seidel sweeps of the component (its states in index order; its edges compiled first
//! when it has more than one state and they fit the budget, `backup.rs`) apply the Bellman
//! operator (`backup.rs`) to both bounds until
//! every gap is at most `epsilon`, or `epsilon` times the state's lower bound with a relative
//! [`Precision`] (one backup for a state on no cycle). Starting below (above)
//! the value, a monotone operator keeps each bound on its side: the interval always contains
//! the value. A robot move multiplies by `g`, the adversary's move and `stop` are instant; every
//! cycle the iteration must contract through holds a robot move, so at `g < 1` it converges;
//! there a state whose gap is at most half of what the precision allows it is no longer backed
//! up (as in the stored solver). At `g = 1` the robot may circle for ever in an end component, where nothing would
//! bring the upper bounds down: the maximal end components of the states left are found once
//! ([`end_components`]) and after every sweep each of their states is lowered to the best upper
//! bound of a choice leaving the component (staying for ever pays nothing), which lets the
//! bounds meet (the deflation of interval iteration, where the stored solver collapses the
//! components instead).
//!
//! Invariants: every bound written is the tighter of the old one and a backup of bounds, so
//! `lower ≤ value ≤ upper` holds after every step (up to rounding); a component stops when
//! every gap in it is at most `epsilon`; fixed states (0, absorbing, settled) are never written.
//!
//! Memory: 16 bytes per live state (eight once every state's bounds meet: then each value
//! is stored once), four more for the components' order (eight more while
//! Tarjan's algorithm runs), two for the backup's masks, a bit per state and four bytes per 32
//! states, and while a component is swept its compiled edges, at most [`Tuning::compiled`]
//! bytes per live state (8 by default: at 40x40, g = 0.99, 87 MB for the largest component,
//! 12.5 M live states); before the bounds, the searches of `qualitative.rs`;
//! at `g = 1`, while the end components are searched, eight bytes per live state, then four
//! per state of an end component, and eight per such state kept in the solution for the
//! policy's ties ([`super::policy`]).
//!
//! # Why index order
//! A backup's time is mostly waiting for memory: the state's own bounds and mask, its
//! successors' places among the live states and their bounds. In index order consecutive
//! states are neighbours in the arena's numbering, their successors advance in step, and the
//! loads stream. Against the order in which the backward search from the payoffs found the
//! states (a value then travels as far as that search in one sweep, but its bounds and
//! successors are read all over the bounds), one run each of the `implicit` bench at g = 0.99
//! on the loaded 2-core machine, CPU of the whole bench: 20x20 48 sweeps in 1.16 s against 33
//! in 1.61 s; 40x40 (12.5 M live states) 230 in 94 s against 204 in 249 s; 64x64 61 in 80 s
//! against 41 in 101 s. Measured and not kept:
//! - *the search's order* (above), kept until the 40x40 runs measured its misses: at 20x20,
//!   whose bounds fit in the cache, it takes fewer sweeps and instructions;
//! - *sweeping forward and backward in turn* (index order): 459 sweeps at 40x40, twice as
//!   many;
//! - two threads sweeping the two halves of the search order: the stored solver measured that
//!   split (`mdp/solve/optimistic.rs`: more sweeps, no faster on two cores), and the halves'
//!   reads of each other's bounds race (sound with atomic loads, but not reproducible);
//! - the threads' updates of one batch of a player's states written after the batch (instead
//!   of each thread writing its own part of the bounds, `colour.rs`): on one thread a sweep
//!   took 1.7 times as long.
//!
//! # Threads
//! On a map, index order *is* the order by player (the robot's states first: the player to
//! move is the index's leading digit), and turns alternate, so a robot state's backup reads
//! only adversary states' bounds and the reverse (the red/black order of Gauss–Seidel: at
//! 20x20 48 sweeps, against the search order's 33). A component of at least 2^15 states
//! that allows it is swept by player, each player's states in runs on all of rayon's threads
//! (`colour.rs`): the same sweep, bit for bit, on any number of threads. At 40x40, g = 0.99,
//! on two cores: the solve 80.9 s on one thread, 47.9 s on two (the `implicit` bench). A text
//! arena whose players' states interleave in the numbering, or whose turns do not alternate,
//! is swept on one thread. Before the sweeps, the searches of `qualitative.rs` go one level at
//! a time on all threads (`frontier.rs`) and the backup's masks are found per state on all
//! threads ([`Numbering::update`]); Tarjan's search for the components is sequential (it lists
//! a state's successors once per visit of its frame: listing them again for each successor,
//! as it once did, made it quadratic in the degree).

use std::sync::Arc;

use bit_set::BitSet;

use super::backup::{Backup, COMPILED_PER_LIVE};
use super::colour::{self, COLOURED, Split};
use super::ends::{EndMembers, components, end_components};
use super::frontier::Bits;
use super::mdp::{Choice, Distribution, Kind, Model};
use super::moves::Moves;
use super::numbering::Numbering;
use super::qualitative::{Reach, reach, settled};
use crate::arena::Owner;
use crate::mdp::solve::Interval;

/// Why the implicit solve stops.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SolveError {
    /// The discount is not in `(0, 1]` or epsilon not positive and finite.
    #[error("invalid discount {discount} or precision {epsilon}")]
    Invalid {
        /// The discount given.
        discount: f64,
        /// The precision given.
        epsilon: f64,
    },
    /// The sweeps did not close every gap to `epsilon`.
    #[error("no convergence within {iterations} sweeps (largest gap {gap:e})")]
    IterationLimit {
        /// The sweeps done.
        iterations: u32,
        /// The largest gap left.
        gap: f64,
    },
}

/// The certified bounds of every state of a [`Model`].
#[derive(Clone, Debug)]
pub struct Solution {
    /// The live states, numbered (shared with the policy, [`super::policy`]).
    live: Arc<Numbering>,
    /// By live index: the lower and upper bound, side by side (a backup reads both); empty
    /// once the bounds are `exact`.
    bounds: Vec<[f64; 2]>,
    /// By live index, when every live state's lower and upper bounds are equal (at g = 1 the
    /// graph often settles them all): the value, stored once.
    exact: Vec<f64>,
    /// At g = 1, the maximal end components of the states swept (for the policy's ties).
    ends: EndMembers,
    iterations: u32,
    gap: f64,
}

impl Solution {
    /// The live index of live state `h`.
    #[inline(always)]
    fn index(&self, h: u32) -> usize {
        self.live.index(h)
    }

    /// The bounds of product state `h` of `model`.
    #[inline]
    pub fn value<M: Moves>(&self, model: &Model<'_, '_, M>, h: u32) -> Interval {
        let [lower, upper] = self.bounds(model, h);
        Interval { lower, upper }
    }

    /// The lower and upper bounds of product state `h` of `model`.
    #[inline(always)]
    pub(crate) fn bounds<M: Moves>(&self, model: &Model<'_, '_, M>, h: u32) -> [f64; 2] {
        if self.live.contains(h) {
            self.live_bounds(self.index(h))
        } else {
            let payoff = model.absorbing_payoff(h);
            [payoff, payoff]
        }
    }

    /// The bounds of the live state of live index `i`.
    #[inline(always)]
    pub(super) fn live_bounds(&self, i: usize) -> [f64; 2] {
        match self.exact.get(i) {
            Some(&value) => [value, value],
            None => self.bounds[i],
        }
    }

    /// Stores the bounds once if every lower bound equals its upper bound (bit for bit).
    fn compact(&mut self) {
        if !self.bounds.is_empty()
            && self
                .bounds
                .iter()
                .all(|&[lower, upper]| lower.to_bits() == upper.to_bits())
        {
            self.exact = self.bounds.iter().map(|&[lower, _]| lower).collect();
            self.bounds = Vec::new();
        }
    }

    /// The bounds stored as pairs again (for a caller that writes them).
    fn expand(&mut self) {
        if self.bounds.is_empty() && !self.exact.is_empty() {
            self.bounds = self.exact.iter().map(|&value| [value, value]).collect();
            self.exact = Vec::new();
        }
    }

    /// The number of live states (those with bounds).
    pub fn num_live(&self) -> usize {
        self.live.len()
    }

    /// The most sweeps one strongly connected component needed.
    pub fn iterations(&self) -> u32 {
        self.iterations
    }

    /// The largest gap `upper − lower`.
    pub fn gap(&self) -> f64 {
        self.gap
    }
}

/// How close a state's bounds must come: within `epsilon`, or within `epsilon` times the
/// state's lower bound when `relative` (as the explicit solver's `SolveOptions::relative`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Precision {
    /// The bound on the gaps.
    pub epsilon: f64,
    /// Whether `epsilon` is relative to each state's lower bound.
    pub relative: bool,
}

impl Precision {
    /// Gaps of at most `epsilon`.
    pub fn absolute(epsilon: f64) -> Precision {
        Precision {
            epsilon,
            relative: false,
        }
    }

    /// Gaps of at most `epsilon` times each state's lower bound.
    pub fn relative(epsilon: f64) -> Precision {
        Precision {
            epsilon,
            relative: true,
        }
    }

    /// The gap allowed to a state whose lower bound is `lower`.
    pub(super) fn allowed(self, lower: f64) -> f64 {
        match self.relative {
            true => self.epsilon * lower.max(0.0),
            false => self.epsilon,
        }
    }

    /// The gap of `[lower, upper]` over the gap the precision allows it: at most 1 once it is
    /// met (infinite for a positive gap where none is allowed).
    pub(super) fn over(self, lower: f64, upper: f64) -> f64 {
        match upper - lower {
            gap if gap <= 0.0 => 0.0,
            gap => gap / self.allowed(lower),
        }
    }
}

/// Solves `model` at discount `g` to `precision`, in at most `max_iterations` sweeps of a
/// component.
///
/// # Errors
/// [`SolveError`].
pub fn solve<M: Moves>(
    model: &Model<'_, '_, M>,
    g: f64,
    precision: Precision,
    max_iterations: u32,
) -> Result<Solution, SolveError> {
    solve_tuned(model, g, precision, max_iterations, Tuning::default())
}

/// When the solve sweeps a component by player on threads and when it compiles a component's
/// edges ([`solve`] takes the default; the tests vary it).
#[derive(Clone, Copy, Debug)]
pub struct Tuning {
    /// Components of at least this many states are swept by player, on the threads of the
    /// current pool, when they allow it (`colour.rs`; by default from 2^15 states).
    pub coloured: usize,
    /// The bytes per live state that the compiled edges of the component being swept may take
    /// (`backup.rs`; by default 8); a component whose edges would take more is backed up from
    /// the rules.
    pub compiled: usize,
}

impl Default for Tuning {
    fn default() -> Tuning {
        Tuning {
            coloured: COLOURED,
            compiled: COMPILED_PER_LIVE,
        }
    }
}

/// [`solve`] with `tuning` for its sweeps: the same bounds, bit for bit, whatever the tuning.
pub fn solve_tuned<M: Moves>(
    model: &Model<'_, '_, M>,
    g: f64,
    precision: Precision,
    max_iterations: u32,
    tuning: Tuning,
) -> Result<Solution, SolveError> {
    let live = live_states(model, g, precision)?;
    let count = live.len() as u32;
    // The bounds are allocated once the searches below are done, so that their arrays and
    // the bounds are never resident together.
    let mut solution = Solution {
        bounds: Vec::new(),
        exact: Vec::new(),
        live: Arc::new(live),
        ends: EndMembers::default(),
        iterations: 0,
        gap: 0.0,
    };
    // The highest payoff each live state can reach (0: it is worth 0) and, at g = 1, the
    // states worth exactly that: only the others are swept.
    let live = solution.live.set();
    let reach = reach(model, live, |h| solution.index(h), count as usize);
    let settled = if g == 1.0 {
        settled(model, live, |h| solution.index(h), &reach)
    } else {
        BitSet::new()
    };
    let Reach {
        reached: mut active,
        level,
    } = reach;
    active.difference_with(&settled);
    // At g = 1 the robot may stay for ever in an end component, where the upper bounds would
    // not come down: after each sweep, every state of a maximal end component is lowered to
    // the best the component offers on leaving (staying pays nothing).
    let ends = if g == 1.0 {
        let live = count as usize;
        end_components(model, &active, |h| solution.index(h), live)
    } else {
        Vec::new()
    };
    let mut end_of = vec![u32::MAX; if ends.is_empty() { 0 } else { count as usize }];
    for (e, members) in ends.iter().enumerate() {
        for &h in members {
            end_of[solution.index(h)] = e as u32;
        }
    }
    // Solve one strongly connected component at a time, successors first (the order in which
    // Tarjan's algorithm closes them): a component without a cycle takes one backup, a cycle
    // sweeps only its own states until its gaps close.
    // Within a component, the states are swept in index order: the bounds, the masks and the
    // successors of consecutive states then lie close together (module documentation).
    // The backup's masks first: the search lists a state's successors through them.
    let backup = Backup::new(model, g, &solution.live, |h| active.contains(h as usize));
    let mut distribution = Distribution::default();
    let mut order = components(&active, &|h| solution.index(h), count as usize, |h, out| {
        backup.successors_within((solution.index(h), h), &active, &mut distribution, out)
    });
    drop(active);
    order.sort_each_by_key(|h| h);
    if order.len() == 0 {
        // Nothing to sweep: every live state is settled or worth 0 (level 0), its bounds
        // equal, stored once.
        solution.exact = level.iter().map(|&l| model.payoff_of_level(l)).collect();
    } else {
        solution.bounds = level
            .iter()
            .map(|&l| [0.0, model.payoff_of_level(l)])
            .collect();
        for h in settled.iter() {
            let i = solution.index(h as u32);
            solution.bounds[i][0] = solution.bounds[i][1];
        }
    }
    drop(level);
    drop(settled);
    let split = Split::of(model.space(), &solution.live);
    // The compiled edges of the component being swept take at most this many bytes.
    let budget = tuning.compiled.saturating_mul(count as usize);
    // Below g = 1 a state whose gap is at most half the precision is no longer updated, as in
    // the stored solver: its bounds stay bounds, and the states it feeds still close their
    // gaps, since with its bounds fixed the sweeps contract towards a fixed point whose gaps are
    // at most its `epsilon / 2` (a backup's gap is at most its successors' largest). At g = 1
    // every state is updated, as the deflation's convergence requires.
    let settle = g < 1.0;
    let mut ends_of_component = Vec::new();
    for c in 0..order.len() {
        let members = order.get(c);
        ends_of_component.clear();
        if !end_of.is_empty() {
            ends_of_component.extend(
                members
                    .iter()
                    .map(|&h| end_of[solution.index(h)])
                    .filter(|&e| e != u32::MAX),
            );
            ends_of_component.sort_unstable();
            ends_of_component.dedup();
        }
        // A large component whose turns alternate, its robot states first, is swept by
        // player on threads: the same sweep as in index order (module documentation).
        let by_player = colour::by_player(
            model.space(),
            (split, &solution.live),
            members,
            tuning.coloured,
        );
        // A component of more than one state has its edges read from the rules once.
        let compiled = (members.len() > 1)
            .then(|| backup.compile(&solution.live, members, budget))
            .flatten();
        let mut sweeps = 0u32;
        loop {
            let swept = match by_player {
                Some((split, first)) => {
                    let live = Arc::clone(&solution.live);
                    let mut swept = Swept::default();
                    for (player, offset) in colour::players(members, first) {
                        let found = colour::sweep(
                            &mut solution.bounds,
                            (split, &live),
                            player,
                            Distribution::default,
                            |(p, h), i, bounds, other, distribution, swept| {
                                let backed =
                                    (!settled_gap(*bounds, precision, settle)).then(|| {
                                        let member = compiled.as_ref().map(|c| (c, offset + p));
                                        let scratch = (&*live, distribution);
                                        backup.apply_at(member, (i, h), scratch, |j| *other.get(j))
                                    });
                                tighten(bounds, backed, precision, swept);
                            },
                            Swept::max,
                        );
                        swept = swept.max(found);
                    }
                    swept
                }
                None => sweep(
                    &mut solution,
                    members,
                    precision,
                    settle,
                    |solution, (p, i, h)| {
                        let member = compiled.as_ref().map(|c| (c, p));
                        let scratch = (&*solution.live, &mut distribution);
                        backup.apply_at(member, (i, h), scratch, |j| solution.bounds[j])
                    },
                ),
            };
            let (mut gap, mut ratio) = (swept.gap, swept.ratio);
            if !ends_of_component.is_empty() {
                for &e in &ends_of_component {
                    let members = &ends[e as usize];
                    let exit = best_exit(model, &solution, members, |t| {
                        solution.live.contains(t) && end_of[solution.index(t)] == e
                    });
                    for &h in members {
                        let i = solution.index(h);
                        solution.bounds[i][1] = solution.bounds[i][1].min(exit);
                    }
                }
                (gap, ratio) = solution.gaps(members, precision);
            }
            sweeps += 1;
            if ratio <= 1.0 {
                solution.iterations = solution.iterations.max(sweeps);
                solution.gap = solution.gap.max(gap);
                break;
            }
            if sweeps >= max_iterations {
                return Err(SolveError::IterationLimit {
                    iterations: sweeps,
                    gap,
                });
            }
        }
    }
    drop(end_of);
    solution.ends = EndMembers::new(&ends);
    solution.compact();
    Ok(solution)
}

/// The live states of `model` (chance and decision nodes), numbered, once `g` and `precision`
/// are checked.
pub(super) fn live_states<M: Moves>(
    model: &Model<'_, '_, M>,
    g: f64,
    precision: Precision,
) -> Result<Numbering, SolveError> {
    let epsilon = precision.epsilon;
    if !(g > 0.0 && g <= 1.0 && epsilon > 0.0 && epsilon.is_finite()) {
        return Err(SolveError::Invalid {
            discount: g,
            epsilon,
        });
    }
    let n = model.space().num_states();
    let live = Bits::from_fn(
        n,
        || (),
        |h, _| !matches!(model.kind(h), Kind::Absorbing(_)),
    );
    Ok(Numbering::new(live.into_set(n)))
}

/// What a sweep found: the largest gap, the largest gap over what the precision allows it
/// ([`Precision::over`]) and the largest rise of a lower bound.
#[derive(Clone, Copy, Default)]
pub(super) struct Swept {
    pub(super) gap: f64,
    pub(super) ratio: f64,
    pub(super) rise: f64,
}

impl Swept {
    /// What two sweeps (or parts of one) found together.
    fn max(self, other: Swept) -> Swept {
        Swept {
            gap: self.gap.max(other.gap),
            ratio: self.ratio.max(other.ratio),
            rise: self.rise.max(other.rise),
        }
    }
}

/// Whether a sweep leaves the bounds `[lower, upper]` alone: when `settle`, a gap of at most
/// half of what `precision` allows.
#[inline(always)]
fn settled_gap([lower, upper]: [f64; 2], precision: Precision, settle: bool) -> bool {
    settle && upper - lower <= precision.allowed(lower) / 2.0
}

/// Tightens `bounds` by a `backup` (`None`: left alone, [`settled_gap`]), keeping the tighter
/// of the old and the new bound on each side, and records the result in `swept`.
#[inline(always)]
fn tighten(
    bounds: &mut [f64; 2],
    backup: Option<(f64, f64)>,
    precision: Precision,
    swept: &mut Swept,
) {
    let [old_lower, old_upper] = *bounds;
    let (lower, upper) = match backup {
        // Monotone from both sides: keep the tighter bound (rounding never loosens them).
        Some((lower, upper)) => (lower.max(old_lower), upper.min(old_upper)),
        None => (old_lower, old_upper),
    };
    *bounds = [lower, upper];
    swept.gap = swept.gap.max(upper - lower);
    swept.ratio = swept.ratio.max(precision.over(lower, upper));
    swept.rise = swept.rise.max(lower - old_lower);
}

/// One Gauss–Seidel sweep of `members` (in order) on both bounds by `backup` (given the
/// solution, a member's position in `members`, its live index and the state), except at the states whose gap is
/// already at most half of what `precision` allows when `settle`.
pub(super) fn sweep(
    solution: &mut Solution,
    members: &[u32],
    precision: Precision,
    settle: bool,
    mut backup: impl FnMut(&Solution, (usize, usize, u32)) -> (f64, f64),
) -> Swept {
    let mut swept = Swept::default();
    for (p, &h) in members.iter().enumerate() {
        let i = solution.index(h);
        let backed = (!settled_gap(solution.bounds[i], precision, settle))
            .then(|| backup(solution, (p, i, h)));
        tighten(&mut solution.bounds[i], backed, precision, &mut swept);
    }
    swept
}

/// The largest upper bound of a choice leaving the end component `members` (`inside(t)` says
/// whether `t` is one of them): a decision node's `stop` or a move out of it. Chance nodes of
/// an end component have no outcome outside it.
pub(super) fn best_exit<M: Moves>(
    model: &Model<'_, '_, M>,
    solution: &Solution,
    members: &[u32],
    inside: impl Fn(u32) -> bool,
) -> f64 {
    let mut exit = 0.0f64;
    for &h in members {
        if model.space().owner(h) == Owner::Adversary {
            continue;
        }
        model.choices(h, |c| match c {
            Choice::Stop { payoff } => exit = exit.max(payoff),
            Choice::Move { target, .. } if !inside(target) => {
                exit = exit.max(solution.value(model, target).upper);
            }
            Choice::Move { .. } => {}
        });
    }
    exit
}

impl Solution {
    /// A solution over the live states `live` with `bounds` by live index, found in at most
    /// `iterations` sweeps of a component with largest gap `gap` (no end components kept).
    pub(super) fn from_parts(
        live: Arc<Numbering>,
        bounds: Vec<[f64; 2]>,
        iterations: u32,
        gap: f64,
    ) -> Solution {
        Solution {
            live,
            bounds,
            exact: Vec::new(),
            ends: EndMembers::default(),
            iterations,
            gap,
        }
    }

    /// The largest gap of the live states `members` and the largest over what `precision`
    /// allows it ([`Precision::over`]).
    pub(super) fn gaps(&self, members: &[u32], precision: Precision) -> (f64, f64) {
        members.iter().fold((0.0f64, 0.0f64), |(gap, ratio), &h| {
            let [lower, upper] = self.live_bounds(self.index(h));
            (
                gap.max(upper - lower),
                ratio.max(precision.over(lower, upper)),
            )
        })
    }

    /// Sets the bounds of live state `h`.
    #[inline]
    pub(super) fn set_bounds(&mut self, h: u32, bounds: [f64; 2]) {
        self.expand();
        let i = self.index(h);
        self.bounds[i] = bounds;
    }

    /// The bounds by live index.
    pub(super) fn into_bounds(mut self) -> Vec<[f64; 2]> {
        self.expand();
        self.bounds
    }

    /// The live states (those with bounds), numbered as the bounds are, for the policy
    /// ([`super::policy`]).
    pub(crate) fn numbering(&self) -> &Arc<Numbering> {
        &self.live
    }

    /// At g = 1, the maximal end components of the states the solve swept (those not settled
    /// from the graph), for the policy's ties ([`super::policy`]).
    pub(crate) fn ends(&self) -> &EndMembers {
        &self.ends
    }
}

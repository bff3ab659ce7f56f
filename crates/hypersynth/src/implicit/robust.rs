//! The robust solve on the index space (docs/semantics.md §10.3, §13.2): sigma_L known only
//! to lie in probability intervals per arena state and edge, the adversary picking within them
//! at every visit to minimise the payoff; the explicit robust solve's method
//! (`mdp/robust/mod.rs`) over the model's rules.
//!
//! The model is built with sigma_L's full support (sigma_L uniform), so that its levels,
//! commitments and choices are the nominal problem's whatever was observed; the chance nodes
//! where sigma_L rules ([`Model::plays_sigma_w`] false) are *uncertain*: their backup is the
//! adversary's greedy reply within [`Intervals`] (`mdp/robust/inner.rs`), computed on each
//! bound separately. Every other node is backed up as in the nominal solve (`backup.rs`).
//!
//! 1. *Qualitative*: the live states from which the robot can give a positive payoff a
//!    positive probability whatever the adversary picks are found by a backward search in
//!    which an uncertain chance node joins when every admissible distribution puts mass on the
//!    states joined (a joined successor of positive upper bound, with a positive lower bound or
//!    the upper bounds of the successors not joined adding up to less than 1); the others are
//!    worth exactly 0. The upper bounds start at the highest payoff reachable under the full
//!    support (`qualitative.rs`), which bounds the value under any distribution.
//! 2. *Components*, successors first, each swept in index order by Gauss–Seidel on both
//!    bounds until every gap meets the precision; below g = 1 a state within half of it is no
//!    longer backed up, as in the nominal solve.
//! 3. *Deflation* (g = 1) whenever the lower bounds settle and every `DEFLATION_PERIOD` sweeps:
//!    the adversary's replies to the lower bounds, fixed, make the component an MDP; each of its
//!    maximal end components is one the adversary can keep the run in unless the robot leaves,
//!    so its states' upper bounds are lowered to the best choice leaving it (sound for any
//!    reply within the intervals).
//!
//! The policy ([`robust_policy`]) is the explicit robust policy's rule (`mdp/robust/policy.rs`):
//! below g = 1 the choice of largest lower Q-value (the lowest position among ties); at g = 1
//! the choice through which the state joins the robust attractor of the positive payoffs over
//! the *safe* choices (lower Q-value within a relative [`TIE_TOLERANCE`] of the state's lower
//! bound), which makes progress against every adversary. Ties among the attractor's choices
//! may be broken differently from the explicit engine (the searches visit states in different
//! orders); each collects at least the certified lower bound.
//!
//! Memory: the nominal solve's (16 bytes per live state for the bounds, the components' order,
//! two bytes per live state of masks) and a bit per live state for the uncertain nodes; a
//! deflation takes, per state of the component, four bytes per outcome under the reply (kept
//! until the next deflation, which reuses its end components when the graph is the same), eight
//! bytes for the end components' search and four for their numbers.

use std::collections::VecDeque;
use std::sync::Arc;

use bit_set::BitSet;

use super::backup::Backup;
use super::ends::{components, end_components_by};
use super::mdp::{Choice, Distribution, Kind, Model};
use super::moves::Moves;
use super::numbering::Numbering;
use super::policy::{Policy, PolicyError, check_discount};
use super::qualitative::{Reach, reach};
use super::solve::{Precision, Solution, SolveError, best_exit, live_states, sweep};
use crate::arena::Owner;
use crate::csr::Csr;
use crate::mdp::robust::inner::{self, Entry};
use crate::mdp::solve::TIE_TOLERANCE;
use crate::opportunistic::observations::unobserved;

/// Sweeps between two deflations of a component's end components at g = 1 (besides the one
/// made whenever the lower bounds settle).
const DEFLATION_PERIOD: u32 = 32;

/// No choice recorded (a decision node's position in the attractor's search).
const NONE: u8 = u8::MAX;

/// sigma_L's probability intervals, per arena state and edge: the listed arena states' rows
/// (one `[lower, upper]` per edge, in edge order); an arena state not listed has `[0, 1]` on
/// every edge when it has two or more, `[1, 1]` on its one edge otherwise (a learnt region's
/// unobserved states, docs/semantics.md §10.2).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Intervals {
    listed: Vec<(u32, Box<[[f64; 2]]>)>,
}

impl Intervals {
    /// The intervals of the arena states `rows` lists (each with one interval per edge; a state
    /// listed twice keeps its first row).
    pub fn new(rows: impl IntoIterator<Item = (u32, Vec<[f64; 2]>)>) -> Intervals {
        let mut listed: Vec<(u32, Box<[[f64; 2]]>)> = rows
            .into_iter()
            .map(|(s, row)| (s, row.into_boxed_slice()))
            .collect();
        listed.sort_by_key(|&(s, _)| s);
        listed.dedup_by_key(|&mut (s, _)| s);
        Intervals { listed }
    }

    /// Fills `out` with the intervals of the `degree` edges of arena state `s`.
    pub fn row(&self, s: u32, degree: usize, out: &mut Vec<[f64; 2]>) {
        out.clear();
        match self.listed.binary_search_by_key(&s, |&(state, _)| state) {
            Ok(i) => out.extend_from_slice(&self.listed[i].1),
            Err(_) => {
                let [_, lower, upper] = unobserved(degree);
                out.resize(degree, [lower, upper]);
            }
        }
    }
}

/// A deflated component (its first state), its graph under the reply (local numbers) and its
/// maximal end components.
type Deflated = (u32, Csr<u32, u32>, Vec<Vec<u32>>);

/// What the robust backups and searches share: the model, the intervals, the uncertain nodes
/// and buffers.
struct Robust<'s, 'a, 'm, M> {
    model: &'s Model<'a, 'm, M>,
    intervals: &'s Intervals,
    live: Arc<Numbering>,
    /// By live index: the chance nodes where sigma_L rules.
    uncertain: BitSet,
    row: Vec<[f64; 2]>,
    entries: [Vec<Entry>; 2],
    values: Vec<f64>,
    reply: Vec<f64>,
    distribution: Distribution,
    /// The last deflation's component (its first state), graph under the reply and end
    /// components.
    ends: Option<Deflated>,
}

impl<'s, 'a, 'm, M: Moves> Robust<'s, 'a, 'm, M> {
    fn new(model: &'s Model<'a, 'm, M>, intervals: &'s Intervals, live: Arc<Numbering>) -> Self {
        let mut uncertain = BitSet::with_capacity(live.len());
        for h in live.members() {
            if model.kind(h) == Kind::Chance && !model.plays_sigma_w(h) {
                uncertain.insert(live.index(h));
            }
        }
        Robust {
            model,
            intervals,
            live,
            uncertain,
            row: Vec::new(),
            entries: [Vec::new(), Vec::new()],
            values: Vec::new(),
            reply: Vec::new(),
            distribution: Distribution::default(),
            ends: None,
        }
    }

    /// Whether live state `h` is an uncertain chance node.
    fn is_uncertain(&self, h: u32) -> bool {
        self.live.get(h).is_some_and(|i| self.uncertain.contains(i))
    }

    /// Fills `self.row` with the intervals of uncertain node `h`'s edges.
    fn fill_row(&mut self, h: u32) {
        let space = self.model.space();
        let degree = space.degree(h) as usize;
        self.intervals
            .row(space.arena_state(h), degree, &mut self.row);
    }

    /// The backup of uncertain node `h` on both bounds: the adversary's greedy reply to each.
    fn chance(&mut self, solution: &Solution, h: u32) -> (f64, f64) {
        self.fill_row(h);
        let model = self.model;
        let [lower, upper] = &mut self.entries;
        lower.clear();
        upper.clear();
        let mut k = 0;
        model.space().edges(h, |_, t| {
            let [l, u] = solution.bounds(model, t);
            let [a, b] = self.row[k];
            lower.push(Entry {
                value: l,
                lower: a,
                upper: b,
            });
            upper.push(Entry {
                value: u,
                lower: a,
                upper: b,
            });
            k += 1;
        });
        (inner::minimum(lower), inner::minimum(upper))
    }

    /// Fills `out` with the successors of positive probability of chance node `h` under the
    /// adversary's reply to the lower bounds (its distribution where it is exact).
    fn reply_support(&mut self, solution: &Solution, h: u32, out: &mut Vec<u32>) {
        out.clear();
        let model = self.model;
        if !self.is_uncertain(h) {
            model.distribution(h, &mut self.distribution);
            out.extend(self.distribution.iter().map(|(t, _)| t));
            return;
        }
        self.fill_row(h);
        self.values.clear();
        let mut targets = Vec::with_capacity(self.row.len());
        model.space().edges(h, |_, t| {
            self.values.push(solution.bounds(model, t)[0]);
            targets.push(t);
        });
        inner::distribution(&self.values, &self.row, &mut self.reply);
        out.extend(
            targets
                .iter()
                .zip(&self.reply)
                .filter(|&(_, &p)| p > 0.0)
                .map(|(&t, _)| t),
        );
    }

    /// Whether uncertain node `h` must give the states of `joined` positive probability
    /// whatever the adversary picks within its intervals (module documentation).
    fn hits(&mut self, h: u32, joined: &BitSet) -> bool {
        self.fill_row(h);
        let (mut inside, mut forced, mut outside) = (false, false, 0.0f64);
        let mut k = 0;
        let row = &self.row;
        self.model.space().edges(h, |_, t| {
            let [lower, upper] = row[k];
            if joined.contains(t as usize) {
                inside |= upper > 0.0;
                forced |= lower > 0.0;
            } else {
                outside += upper;
            }
            k += 1;
        });
        inside && (forced || outside < 1.0)
    }

    /// The robust attractor of the positive payoffs (module documentation): the states that
    /// join it, live or not, and per live decision node the position of the choice it joined
    /// through ([`NONE`] for the others). A decision node's choices count where `eligible`
    /// (given the node, the choice's position and the choice) accepts them.
    fn attractor(&mut self, eligible: impl Fn(u32, u8, Choice) -> bool) -> (BitSet, Vec<u8>) {
        let model = self.model;
        let space = model.space();
        let n = space.num_states() as u32;
        let mut joined = BitSet::with_capacity(n as usize);
        let mut through = vec![NONE; self.live.len()];
        let mut queue = VecDeque::new();
        for h in 0..n {
            match model.kind(h) {
                Kind::Absorbing(payoff) if payoff > 0.0 => {}
                Kind::Decision if model.level(h) > 0 => {
                    let mut position = 0u8;
                    let mut stop = None;
                    model.choices(h, |c| {
                        if matches!(c, Choice::Stop { .. }) && eligible(h, position, c) {
                            stop = Some(position);
                        }
                        position = position.saturating_add(1);
                    });
                    let Some(position) = stop else { continue };
                    through[self.live.index(h)] = position;
                }
                _ => continue,
            }
            joined.insert(h as usize);
            queue.push_back(h);
        }
        let mut predecessors = Vec::new();
        while let Some(t) = queue.pop_front() {
            predecessors.clear();
            space.predecessors(t, |p| predecessors.push(p));
            for &p in &predecessors {
                if joined.contains(p as usize) || !self.live.contains(p) {
                    continue;
                }
                let hit = match model.kind(p) {
                    Kind::Decision => {
                        let (mut position, mut first) = (0u8, None);
                        model.choices(p, |c| {
                            if first.is_none()
                                && matches!(c, Choice::Move { target, .. } if target == t)
                                && eligible(p, position, c)
                            {
                                first = Some(position);
                            }
                            position = position.saturating_add(1);
                        });
                        if let Some(position) = first {
                            through[self.live.index(p)] = position;
                        }
                        first.is_some()
                    }
                    _ if self.is_uncertain(p) => self.hits(p, &joined),
                    _ => {
                        model.distribution(p, &mut self.distribution);
                        self.distribution.iter().any(|(u, _)| u == t)
                    }
                };
                if hit {
                    joined.insert(p as usize);
                    queue.push_back(p);
                }
            }
        }
        (joined, through)
    }

    /// Deflation (module documentation) of the component `members` (sorted). The component's
    /// graph under the reply (each member's outcomes, local numbers) is listed once; when it is
    /// the graph of the last deflation of the same component, its end components are reused.
    fn deflate(&mut self, solution: &mut Solution, members: &[u32]) {
        let model = self.model;
        let k = members.len();
        let local = |t: u32| members.binary_search(&t).map_or(u32::MAX, |i| i as u32);
        let chance = |i: u32| model.space().owner(members[i as usize]) == Owner::Adversary;
        let (mut graph, mut support) = (Csr::new(), Vec::new());
        for (i, &h) in members.iter().enumerate() {
            if chance(i as u32) {
                self.reply_support(solution, h, &mut support);
                graph.push_row(support.iter().map(|&t| local(t)));
            } else {
                let mut targets = Vec::new();
                model.choices(h, |c| {
                    if let Choice::Move { target, .. } = c {
                        targets.push(local(target));
                    }
                });
                graph.push_row(targets);
            }
        }
        let same = self
            .ends
            .as_ref()
            .is_some_and(|(first, last, _)| *first == members[0] && *last == graph);
        if !same {
            let states: BitSet = (0..k).collect();
            let ends = end_components_by(
                &states,
                |i| i as usize,
                k,
                chance,
                |i, out| {
                    out.clear();
                    out.extend_from_slice(graph.row(i));
                },
            );
            self.ends = Some((members[0], graph, ends));
        }
        let ends = &self.ends.as_ref().expect("just made").2;
        if ends.is_empty() {
            return;
        }
        let mut end_of = vec![u32::MAX; k];
        for (e, end) in ends.iter().enumerate() {
            for &i in end {
                end_of[i as usize] = e as u32;
            }
        }
        let mut global = Vec::new();
        for (e, end) in ends.iter().enumerate() {
            global.clear();
            global.extend(end.iter().map(|&i| members[i as usize]));
            let inside = |t: u32| {
                let i = local(t);
                i != u32::MAX && end_of[i as usize] == e as u32
            };
            let exit = best_exit(model, solution, &global, inside);
            for &h in &global {
                let [lower, upper] = solution.bounds(model, h);
                solution.set_bounds(h, [lower, upper.min(exit).max(lower)]);
            }
        }
    }
}

/// Solves `model` (built with sigma_L uniform) robustly against every sigma_L within
/// `intervals`, at discount `g` to `precision`, in at most `max_iterations` sweeps of a
/// component (module documentation).
///
/// # Errors
/// [`SolveError`].
pub fn solve_robust<M: Moves>(
    model: &Model<'_, '_, M>,
    intervals: &Intervals,
    g: f64,
    precision: Precision,
    max_iterations: u32,
) -> Result<Solution, SolveError> {
    let epsilon = precision.epsilon;
    let live = Arc::new(live_states(model, g, precision)?);
    let count = live.len();
    let mut robust = Robust::new(model, intervals, Arc::clone(&live));
    let Reach {
        reached: mut active,
        level,
    } = reach(model, live.set(), |h| live.index(h), count);
    let (joined, _) = robust.attractor(|_, _, _| true);
    active.intersect_with(&joined);
    drop(joined);
    // The backup's masks first: the search lists a state's successors through them.
    let backup = Backup::new(model, g, &live, |h| active.contains(h as usize));
    let mut distribution = Distribution::default();
    let mut order = components(&active, &|h| live.index(h), count, |h, out| {
        backup.successors_within((live.index(h), h), &active, &mut distribution, out)
    });
    order.sort_each_by_key(|h| h);
    let bounds: Vec<[f64; 2]> = live
        .members()
        .zip(&level)
        .map(|(h, &l)| match active.contains(h as usize) {
            true => [0.0, model.payoff_of_level(l)],
            false => [0.0, 0.0],
        })
        .collect();
    drop(level);
    let mut solution = Solution::from_parts(Arc::clone(&live), bounds, 0, 0.0);
    drop(active);
    let settle = g < 1.0;
    let (mut iterations, mut largest) = (0u32, 0.0f64);
    for c in 0..order.len() {
        let members = order.get(c);
        let mut tolerance = epsilon;
        let mut sweeps = 0u32;
        loop {
            let swept = sweep(
                &mut solution,
                members,
                precision,
                settle,
                |solution, (_, i, h)| match robust.uncertain.contains(i) {
                    true => robust.chance(solution, h),
                    false => backup.apply(solution, (i, h), &mut distribution),
                },
            );
            let (mut gap, mut ratio) = (swept.gap, swept.ratio);
            sweeps += 1;
            let settled = swept.rise <= tolerance;
            if ratio > 1.0 && g == 1.0 && (settled || sweeps.is_multiple_of(DEFLATION_PERIOD)) {
                robust.deflate(&mut solution, members);
                (gap, ratio) = solution.gaps(members, precision);
            }
            if settled {
                tolerance *= 0.5;
            }
            if ratio <= 1.0 {
                iterations = iterations.max(sweeps);
                largest = largest.max(gap);
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
    Ok(Solution::from_parts(
        live,
        solution.into_bounds(),
        iterations,
        largest,
    ))
}

/// The robust policy of `model` from its robust `solution` against `intervals` at discount `g`
/// (module documentation).
///
/// # Errors
/// [`PolicyError::Invalid`] for a discount outside `(0, 1]`, [`PolicyError::TooManyChoices`].
pub fn robust_policy<M: Moves>(
    model: &Model<'_, '_, M>,
    intervals: &Intervals,
    solution: &Solution,
    g: f64,
) -> Result<Policy, PolicyError> {
    check_discount(g)?;
    let live = Arc::clone(solution.numbering());
    let lower = |h: u32| solution.value(model, h).lower;
    let q = |c: Choice| match c {
        Choice::Move { target, .. } => g * lower(target),
        Choice::Stop { payoff } => payoff,
    };
    let mut choices = vec![NONE; live.len()];
    let mut worthless = BitSet::with_capacity(live.len());
    for h in live.members() {
        let i = live.index(h);
        if solution.value(model, h).upper == 0.0 {
            worthless.insert(i);
        }
        if model.kind(h) != Kind::Decision {
            continue;
        }
        let (mut best, mut best_q, mut position) = (NONE, f64::NEG_INFINITY, 0usize);
        model.choices(h, |c| {
            let value = q(c);
            if best == NONE || value > best_q {
                (best, best_q) = (position.min(usize::from(NONE) - 1) as u8, value);
            }
            position += 1;
        });
        if position > usize::from(NONE) - 1 {
            return Err(PolicyError::TooManyChoices {
                state: h,
                choices: position,
            });
        }
        choices[i] = best;
    }
    if g == 1.0 {
        let mut robust = Robust::new(model, intervals, Arc::clone(&live));
        let safe = |h: u32, _: u8, c: Choice| {
            let own = lower(h);
            q(c) >= own - TIE_TOLERANCE * own.abs()
        };
        let (_, through) = robust.attractor(safe);
        for (choice, through) in choices.iter_mut().zip(through) {
            if through != NONE {
                *choice = through;
            }
        }
    }
    let choices = live
        .members()
        .zip(choices)
        .map(|(h, c)| (model.kind(h) == Kind::Decision && c != NONE).then_some(c));
    Ok(Policy::from_parts(g, live.clone(), choices, worthless))
}

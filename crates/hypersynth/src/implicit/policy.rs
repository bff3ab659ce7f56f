//! The opportunistic policy on the index space and its evaluation as a Markov chain
//! (docs/semantics.md §6.6, §13.2).
//!
//! ```
//! use hypersynth::arena::map;
//! use hypersynth::game::{Belief, Payoffs, TaskSet};
//! use hypersynth::implicit::{Choice, MapMoves, Model, Regions, Space, evaluate, policy, solve};
//! use hypersynth::ltl;
//! use hypersynth::opportunistic::adversary::SigmaL;
//! use hypersynth::opportunistic::build::Risk;
//! use hypersynth::opportunistic::presentation::Presentation;
//! use hypersynth::translate::{Builtin, TranslationLimits, Translator};
//!
//! // A 4x2 grid: A next to the robot, B in the east, the adversary in between, in a column it
//! // cannot leave: it can block either row for ever, but steps at random (it believes it has
//! // lost: psi is F A, which the robot wins surely).
//! let text = "hypersynth map v1\nrobot-moves N S E W\nadversary-moves N S STAY\ngrid\n\
//!             .  .  .  .\n@r A  @a B\n";
//! let world = map::parse(text)?;
//! let moves = MapMoves::new(&world)?;
//! let translator = Builtin::new(TranslationLimits::default());
//! let phi1 = translator.translate(&ltl::parse("F A")?)?;
//! let phi2 = translator.translate(&ltl::parse("F B")?)?;
//! let space = Space::new(&moves, &[&phi1, &phi2])?;
//! let regions = Regions::compute(&space, 2, Belief::Tasks(TaskSet(0b01)));
//! let presentation = Presentation::paper("phi");
//! let payoffs = Payoffs::default().subsets(presentation.names());
//! let (risk, sigma_l) = (Risk::Paper, SigmaL::Uniform);
//! let model = Model::new(&space, &regions, &payoffs, &presentation, risk, &sigma_l)?;
//! let (g, epsilon) = (1.0, 1e-9);
//! let solution = solve(&model, g, epsilon, 1000)?;
//! let policy = policy(&model, &solution, g, 1000)?;
//! let h0 = space.initial();
//! // Undiscounted, getting past the adversary is eventually certain: the robot does not stop
//! // for A's 200 but moves (the choice at that position of `Model::choices(h0)`).
//! let mut choices = Vec::new();
//! model.choices(h0, |c| choices.push(c));
//! let first = choices[usize::from(policy.choice(h0).expect("h0 decides"))];
//! assert!(matches!(first, Choice::Move { .. }));
//! // What the policy collects from h0, computed on its own Markov chain, is the certified
//! // value (`evaluate` refuses it otherwise).
//! let value = solution.value(&model, h0);
//! let evaluation = evaluate(&model, &policy, value, epsilon, 1000)?;
//! assert!(value.lower > 300.0 - 1e-6 && (evaluation.value.lower - value.lower).abs() < 1e-6);
//! assert!(evaluation.expected_moves >= 1.0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! # The policy
//! The explicit engine's rule (`mdp/solve/policy.rs`), on the solution's lower bounds `L`, with
//! choices numbered by their position in [`Model::choices`] (the explicit MDP's choice order):
//! - g < 1: the choice of largest lower Q-value, the lowest position among exact ties;
//! - g = 1: a choice is eligible when its lower Q-value is within a relative `TIE_TOLERANCE`
//!   of `L` or it stays in the state's maximal end component; among the eligible choices, the
//!   one of least expected robot moves to a goal (an absorbing state or one with `L = 0`,
//!   approximated from below per strongly connected component of the eligible choices' graph,
//!   in rank order, within a relative `TIME_TOLERANCE`), then largest lower Q-value, then
//!   lowest position; the states from which that policy does not reach a goal with
//!   probability 1 play their *ranked* choice instead (ranks by a backward breadth-first search
//!   from the goals over the eligible choices).
//!
//! The lower bounds differ from the explicit engine's by up to `ε` (both solvers stop
//! anywhere inside the certified interval), so where two choices' values are within `ε` of
//! each other the engines may break the tie differently; every choice either takes is worth
//! the certified value.
//!
//! # The evaluation
//! The policy induces a Markov chain on the live states it can reach from h0: a decision node
//! moves to its chosen move's target (factor g, one robot move) or ends (its `stop`, or a state
//! worth 0 where the controller gives up), a chance node follows the adversary's distribution,
//! an absorbing state pays its payoff (a committing state its guarantee: Win(T) is won surely by
//! the attractor strategy, §5.1). The chain is solved like the explicit controller's
//! (`opportunistic/evaluate.rs`: the same update and stopping rules), one strongly connected
//! component at a time, successors first, from `[0, best exit]`, by Gauss–Seidel sweeps until
//! every gap is within `ε` (the explicit evaluation solves a small stubborn component exactly
//! after 64 sweeps; here the sweeps go on to the limit). It reads nothing of the optimising
//! solve but the policy, and [`evaluate`] refuses a policy that does not collect the certified
//! value at h0 ([`PolicyError::Mismatch`]).
//!
//! # Memory
//! The policy keeps a byte per live state (the choice's position), a bit per live state (those
//! worth 0) and the solution's numbering of the live states (a bit per state, four bytes per 32).
//! Below g = 1 nothing else is needed. At g = 1, besides the solution, at the peak (while the
//! eligible choices' strongly connected components are searched): per live state four bytes
//! for the end components, one for the ranked choices, eight for the rank order and positions,
//! twelve for Tarjan's algorithm and four for the components found, about 30 bytes; the
//! expected moves (eight) come once Tarjan's arrays and the positions are released. The
//! evaluation takes per chain state (the live states the policy reaches from h0 where the run
//! goes on) 24 bytes for the bounds and expected moves and four for its components (twelve more
//! while Tarjan's algorithm runs, before the bounds are allocated), and a bit per state; it
//! does not read the solution, which may be dropped before it.

use bit_set::BitSet;

use super::ends::{components, end_components};
use super::mdp::{Choice, Distribution, Model};
use super::moves::Moves;
use super::solve::Solution;
use crate::arena::Owner;
use crate::mdp::solve::{Interval, TIE_TOLERANCE, TIME_TOLERANCE, best_choice};
use crate::opportunistic::evaluate::{EvaluationError, SweepLimits, step};

/// Why no policy or evaluation could be given.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PolicyError {
    /// The discount is not in `(0, 1]` or epsilon not positive and finite.
    #[error("invalid discount {discount} or precision {epsilon}")]
    Invalid {
        /// The discount given.
        discount: f64,
        /// The precision given.
        epsilon: f64,
    },
    /// A decision node with more choices than a byte numbers.
    #[error("product state {state} has {choices} choices, more than the 255 the policy records")]
    TooManyChoices {
        /// The product state.
        state: u32,
        /// Its number of choices.
        choices: usize,
    },
    /// The evaluation's sweeps did not certify the chain's values.
    #[error(transparent)]
    Evaluation(#[from] EvaluationError),
    /// The policy does not collect the certified value at h0.
    #[error(
        "the policy collects [{policy_lower}, {policy_upper}] from h0, outside the certified \
         value [{lower}, {upper}]"
    )]
    Mismatch {
        /// The evaluation's lower bound.
        policy_lower: f64,
        /// The evaluation's upper bound.
        policy_upper: f64,
        /// The certified lower bound.
        lower: f64,
        /// The certified upper bound.
        upper: f64,
    },
}

/// A dense numbering of a set of product states: a bit per state and the members before each
/// 32-bit block.
#[derive(Clone, Debug)]
struct Numbering {
    set: BitSet,
    before: Vec<u32>,
}

impl Numbering {
    fn new(set: BitSet) -> Numbering {
        let mut before = Vec::with_capacity(set.get_ref().storage().len());
        let mut count = 0u32;
        for block in set.get_ref().storage() {
            before.push(count);
            count += block.count_ones();
        }
        Numbering { set, before }
    }

    /// The number of members.
    fn len(&self) -> usize {
        let blocks = self.set.get_ref().storage();
        blocks.last().map_or(0, |&b| {
            self.before[blocks.len() - 1] as usize + b.count_ones() as usize
        })
    }

    #[inline]
    fn contains(&self, h: u32) -> bool {
        self.set.contains(h as usize)
    }

    /// The number of member `h`.
    #[inline]
    fn index(&self, h: u32) -> usize {
        let blocks = self.set.get_ref().storage();
        let block = (h / 32) as usize;
        let below = blocks[block] & ((1u32 << (h % 32)) - 1);
        self.before[block] as usize + below.count_ones() as usize
    }

    /// The number of `h`, if it is a member.
    #[inline]
    fn get(&self, h: u32) -> Option<usize> {
        self.contains(h).then(|| self.index(h))
    }

    fn members(&self) -> impl Iterator<Item = u32> + '_ {
        self.set.iter().map(|h| h as u32)
    }
}

/// The code of a chance node in [`Policy::choices`].
const CHANCE: u8 = u8::MAX;

/// The target standing for the stop sink in a [`Listed`] choice.
const SINK: u32 = u32::MAX;

/// The opportunistic policy of a solved [`Model`] (module documentation).
#[derive(Clone, Debug)]
pub struct Policy {
    g: f64,
    live: Numbering,
    /// Per live state: a decision node's choice (its position in [`Model::choices`]), or
    /// [`CHANCE`].
    choices: Vec<u8>,
    /// The live states (by number) worth exactly 0: the controller gives up there.
    worthless: BitSet,
}

impl Policy {
    /// The chosen choice's position in [`Model::choices`]`(h)`'s order, for a robot state that
    /// decides: `None` for an absorbing (committing or stuck) state, an adversary state, or a
    /// state worth 0, where the controller gives up.
    pub fn choice(&self, h: u32) -> Option<u8> {
        let i = self.live.get(h)?;
        (!self.worthless.contains(i))
            .then_some(self.choices[i])
            .filter(|&c| c != CHANCE)
    }

    /// The MDP policy's choice in decision node `h`, including a state worth 0 (where every
    /// choice is worth 0 and the largest lower Q-value is played).
    pub fn mdp_choice(&self, h: u32) -> Option<u8> {
        let i = self.live.get(h)?;
        Some(self.choices[i]).filter(|&c| c != CHANCE)
    }

    /// The discount the policy was chosen for.
    pub fn discount(&self) -> f64 {
        self.g
    }

    /// The live states it records a byte for.
    pub fn num_live(&self) -> usize {
        self.choices.len()
    }
}

/// The choices of a live state as lists of outcomes (a chance node's one choice is its
/// distribution; `stop` leads to [`SINK`]), buffers reused from state to state.
#[derive(Default)]
struct Listed {
    /// Per choice, where its outcomes start, whether it is instant, and the payoff of `stop`.
    starts: Vec<usize>,
    instant: Vec<bool>,
    stop: Vec<f64>,
    outcomes: Vec<(u32, f64)>,
    distribution: Distribution,
}

impl Listed {
    fn list<M: Moves>(&mut self, model: &Model<'_, '_, M>, h: u32) {
        self.starts.clear();
        self.instant.clear();
        self.stop.clear();
        self.outcomes.clear();
        if model.space().owner(h) == Owner::Adversary {
            model.distribution(h, &mut self.distribution);
            self.starts.push(0);
            self.instant.push(true);
            self.stop.push(0.0);
            self.outcomes.extend(self.distribution.iter());
            return;
        }
        model.choices(h, |c| {
            self.starts.push(self.outcomes.len());
            match c {
                Choice::Move { target, .. } => {
                    self.instant.push(false);
                    self.stop.push(0.0);
                    self.outcomes.push((target, 1.0));
                }
                Choice::Stop { payoff } => {
                    self.instant.push(true);
                    self.stop.push(payoff);
                    self.outcomes.push((SINK, 1.0));
                }
            }
        });
    }

    fn len(&self) -> usize {
        self.starts.len()
    }

    /// Keeps the outcomes of choice `c` alone.
    fn keep(&mut self, c: usize) {
        let end = self
            .starts
            .get(c + 1)
            .copied()
            .unwrap_or(self.outcomes.len());
        self.outcomes.truncate(end);
        self.outcomes.drain(..self.starts[c]);
    }

    fn outcomes(&self, c: usize) -> &[(u32, f64)] {
        let end = self
            .starts
            .get(c + 1)
            .copied()
            .unwrap_or(self.outcomes.len());
        &self.outcomes[self.starts[c]..end]
    }

    /// `f · Σ p · value`, `f` = g for a move, 1 for an instant choice (the sink's value is the
    /// payoff of `stop`).
    fn q(&self, c: usize, g: f64, value: impl Fn(u32) -> f64) -> f64 {
        let sum: f64 = self
            .outcomes(c)
            .iter()
            .map(|&(t, p)| p * if t == SINK { self.stop[c] } else { value(t) })
            .sum();
        if self.instant[c] { sum } else { g * sum }
    }

    /// The expected moves through choice `c` given its outcomes' `time`: its cost (1 for a
    /// move, 0 for an instant choice) plus their expectation.
    fn time(&self, c: usize, time: impl Fn(u32) -> f64) -> f64 {
        let sum: f64 = self
            .outcomes(c)
            .iter()
            .map(|&(t, p)| p * if t == SINK { 0.0 } else { time(t) })
            .sum();
        sum + if self.instant[c] { 0.0 } else { 1.0 }
    }
}

/// The opportunistic policy of `model` from `solution`, solved at discount `g`
/// (module documentation); at g = 1 the expected moves take at most `max_iterations` sweeps per
/// component.
///
/// # Errors
/// [`PolicyError::Invalid`] for a discount outside `(0, 1]`, [`PolicyError::TooManyChoices`].
pub fn policy<M: Moves>(
    model: &Model<'_, '_, M>,
    solution: &Solution,
    g: f64,
    max_iterations: u32,
) -> Result<Policy, PolicyError> {
    if !(g > 0.0 && g <= 1.0) {
        return Err(PolicyError::Invalid {
            discount: g,
            epsilon: 0.0,
        });
    }
    let live = Numbering::new(solution.live().clone());
    let n_live = live.len();
    let lower = |h: u32| solution.value(model, h).lower;
    let mut choices = vec![CHANCE; n_live];
    let mut worthless = BitSet::with_capacity(n_live);
    let mut listed = Listed::default();
    for h in live.members() {
        let i = live.index(h);
        if solution.value(model, h).upper == 0.0 {
            worthless.insert(i);
        }
        if model.space().owner(h) == Owner::Robot {
            listed.list(model, h);
            if listed.len() > usize::from(u8::MAX) {
                return Err(PolicyError::TooManyChoices {
                    state: h,
                    choices: listed.len(),
                });
            }
            // The plain argmax: the policy at g < 1, and of the states worth 0 at g = 1.
            let best = best_choice(0..listed.len(), |c| listed.q(c, g, lower));
            choices[i] = best.map_or(CHANCE, |c| c as u8);
        }
    }
    let mut policy = Policy {
        g,
        live,
        choices,
        worthless,
    };
    if g == 1.0 {
        undiscounted(model, solution, &mut policy, max_iterations);
    }
    Ok(policy)
}

/// The choices of the states with `L > 0` at g = 1 (module documentation).
fn undiscounted<M: Moves>(
    model: &Model<'_, '_, M>,
    solution: &Solution,
    policy: &mut Policy,
    max_iterations: u32,
) {
    let live = &policy.live;
    let n_live = live.len();
    let lower = |h: u32| solution.value(model, h).lower;
    let is_goal = |h: u32| h == SINK || !live.contains(h) || lower(h) == 0.0;
    // The maximal end component of each live state, as the solve finds them.
    let paying: Vec<u32> = live
        .members()
        .filter(|&h| solution.value(model, h).upper > 0.0)
        .collect();
    let ends = end_components(model, &paying, |h| live.index(h), n_live);
    drop(paying);
    let mut end_of = vec![u32::MAX; if ends.is_empty() { 0 } else { n_live }];
    for (e, members) in ends.iter().enumerate() {
        for &h in members {
            end_of[live.index(h)] = e as u32;
        }
    }
    drop(ends);
    let end = |h: u32| {
        live.get(h)
            .and_then(|i| end_of.get(i).copied())
            .unwrap_or(u32::MAX)
    };
    // Whether choice `c` of `h` (listed) is eligible.
    let eligible = |listed: &Listed, h: u32, c: usize| {
        let own = end(h);
        if own != u32::MAX
            && listed
                .outcomes(c)
                .iter()
                .all(|&(t, _)| t != SINK && end(t) == own)
        {
            return true;
        }
        let value = lower(h);
        listed.q(c, 1.0, lower) >= value - TIE_TOLERANCE * value.max(1.0)
    };
    let q = |listed: &Listed, c: usize| listed.q(c, 1.0, lower);
    let mut listed = Listed::default();
    let (ranked_choice, order) = ranked(model, live, &is_goal, &eligible, &q, &mut listed);
    // The expected moves to a goal over the eligible choices, by live state.
    let times = expected_moves(model, live, &order, &is_goal, &eligible, max_iterations);
    let time = |t: u32| {
        if is_goal(t) {
            0.0
        } else {
            times[live.index(t)]
        }
    };
    for &h in &order {
        if model.space().owner(h) == Owner::Adversary {
            continue;
        }
        listed.list(model, h);
        let mut best: Option<(usize, f64, f64)> = None;
        for c in (0..listed.len()).filter(|&c| eligible(&listed, h, c)) {
            let (t, q) = (listed.time(c, time), listed.q(c, 1.0, lower));
            let better = match best {
                None => true,
                Some((_, best_time, best_q)) => {
                    let tolerance = TIME_TOLERANCE * best_time.max(1.0);
                    t < best_time - tolerance || (t <= best_time + tolerance && q > best_q)
                }
            };
            if better {
                best = Some((c, t, q));
            }
        }
        policy.choices[live.index(h)] = best.map_or(CHANCE, |(c, _, _)| c as u8);
    }
    drop(times);
    let choices = &policy.choices;
    for h in improper(model, live, choices, &order, &is_goal) {
        let i = live.index(h);
        policy.choices[i] = ranked_choice[i];
    }
}

/// The ranked choice of every live state that is not a goal (its position; [`CHANCE`] for a
/// chance node) and those states in increasing rank order: rank 1 are the states with an
/// eligible choice reaching a goal, rank k + 1 those with one reaching rank ≤ k (the choice of
/// largest lower Q-value `q` among them, the lowest position among exact ties).
fn ranked<M: Moves>(
    model: &Model<'_, '_, M>,
    live: &Numbering,
    is_goal: &impl Fn(u32) -> bool,
    eligible: &impl Fn(&Listed, u32, usize) -> bool,
    q: &impl Fn(&Listed, usize) -> f64,
    listed: &mut Listed,
) -> (Vec<u8>, Vec<u32>) {
    let n_live = live.len();
    let mut ranked_choice = vec![CHANCE; n_live];
    let mut ranked = BitSet::with_capacity(n_live);
    let mut is_candidate = BitSet::with_capacity(n_live);
    let mut order = Vec::new();
    let mut candidates: Vec<u32> = Vec::new();
    // Whether `p` is a live state, neither a goal nor ranked nor a candidate yet, with an
    // eligible choice reaching `t`; if so it becomes a candidate.
    let offer =
        |p: u32, t: u32, is_candidate: &mut BitSet, ranked: &BitSet, listed: &mut Listed| {
            let Some(i) = live.get(p) else {
                return false;
            };
            if is_goal(p) || ranked.contains(i) || is_candidate.contains(i) {
                return false;
            }
            listed.list(model, p);
            let reaches = (0..listed.len())
                .any(|c| listed.outcomes(c).iter().any(|&(s, _)| s == t) && eligible(listed, p, c));
            reaches && is_candidate.insert(i)
        };
    // Rank 1: the predecessors of the goals, product states in order, then the states with an
    // eligible `stop` (the explicit MDP numbers its stop sinks after the product states).
    let space = model.space();
    for t in (0..space.num_states() as u32).filter(|&t| is_goal(t)) {
        space.predecessors(t, |p| {
            if offer(p, t, &mut is_candidate, &ranked, listed) {
                candidates.push(p);
            }
        });
    }
    for p in live.members() {
        if space.owner(p) == Owner::Robot && offer(p, SINK, &mut is_candidate, &ranked, listed) {
            candidates.push(p);
        }
    }
    let mut frontier: Vec<u32> = Vec::new();
    while !candidates.is_empty() {
        // Choose before ranking any candidate, so that all progress goes to ranks ≤ k.
        for &h in &candidates {
            listed.list(model, h);
            let progressing = (0..listed.len()).filter(|&c| {
                eligible(listed, h, c)
                    && listed.outcomes(c).iter().any(|&(t, _)| {
                        is_goal(t) || live.get(t).is_some_and(|j| ranked.contains(j))
                    })
            });
            let best = best_choice(progressing, |c| q(listed, c));
            if space.owner(h) == Owner::Robot {
                ranked_choice[live.index(h)] = best.map_or(CHANCE, |c| c as u8);
            }
        }
        for &h in &candidates {
            ranked.insert(live.index(h));
        }
        order.extend_from_slice(&candidates);
        std::mem::swap(&mut frontier, &mut candidates);
        candidates.clear();
        for &t in &frontier {
            space.predecessors(t, |p| {
                if offer(p, t, &mut is_candidate, &ranked, listed) {
                    candidates.push(p);
                }
            });
        }
    }
    (ranked_choice, order)
}

/// The least expected number of robot moves to a goal over the eligible choices, approximated
/// from below, by live state (0 for the goals): per strongly connected component of the
/// eligible choices' graph on the states of `order`, successors first, Gauss–Seidel sweeps in
/// rank order until no time rises by more than `TIME_TOLERANCE` of itself, or `max_sweeps`.
fn expected_moves<M: Moves>(
    model: &Model<'_, '_, M>,
    live: &Numbering,
    order: &[u32],
    is_goal: &impl Fn(u32) -> bool,
    eligible: &impl Fn(&Listed, u32, usize) -> bool,
    max_sweeps: u32,
) -> Vec<f64> {
    let n_live = live.len();
    let mut rank = vec![u32::MAX; n_live];
    let mut counted = BitSet::with_capacity(model.space().num_states());
    for (position, &h) in order.iter().enumerate() {
        rank[live.index(h)] = position as u32;
        counted.insert(h as usize);
    }
    let mut listed = Listed::default();
    let mut found = components(&counted, &|h| live.index(h), n_live, |h, out| {
        out.clear();
        listed.list(model, h);
        for c in (0..listed.len()).filter(|&c| eligible(&listed, h, c)) {
            out.extend(
                listed
                    .outcomes(c)
                    .iter()
                    .map(|&(t, _)| t)
                    .filter(|&t| t != SINK && counted.contains(t as usize)),
            );
        }
    });
    drop(counted);
    found.sort_each_by_key(|h| rank[live.index(h)]);
    drop(rank);
    let mut times = vec![0.0f64; n_live];
    // One Gauss–Seidel update of `h`: whether its time rose by more than the tolerance.
    let mut update = |h: u32, times: &mut [f64]| {
        listed.list(model, h);
        let time = |t: u32| {
            if is_goal(t) {
                0.0
            } else {
                times[live.index(t)]
            }
        };
        let best = (0..listed.len())
            .filter(|&c| eligible(&listed, h, c))
            .map(|c| listed.time(c, time))
            .fold(f64::INFINITY, f64::min);
        let i = live.index(h);
        let old = times[i];
        times[i] = best.max(old);
        best > old + TIME_TOLERANCE * old.max(1.0)
    };
    for c in 0..found.len() {
        let members = found.get(c);
        let trivial = members.len() == 1 && {
            let h = members[0];
            let mut listed = Listed::default();
            listed.list(model, h);
            !(0..listed.len())
                .any(|c| eligible(&listed, h, c) && listed.outcomes(c).iter().any(|&(t, _)| t == h))
        };
        if trivial {
            update(members[0], &mut times);
            continue;
        }
        for _ in 0..max_sweeps {
            let mut changed = false;
            for &h in members {
                changed |= update(h, &mut times);
            }
            if !changed {
                break;
            }
        }
    }
    times
}

/// The states of `order` (the live states that are not goals) from which the policy `choices`
/// does not reach a goal with probability 1: those that cannot reach one, and those that can
/// reach a state that cannot (two backward searches over the policy's chain).
fn improper<M: Moves>(
    model: &Model<'_, '_, M>,
    live: &Numbering,
    choices: &[u8],
    order: &[u32],
    is_goal: &impl Fn(u32) -> bool,
) -> Vec<u32> {
    let mut listed = Listed::default();
    // The outcomes of `h`'s chosen choice.
    let mut chosen = |h: u32, out: &mut Vec<u32>| {
        out.clear();
        listed.list(model, h);
        let c = match choices[live.index(h)] {
            CHANCE => 0,
            c => usize::from(c),
        };
        if c < listed.len() {
            out.extend(listed.outcomes(c).iter().map(|&(t, _)| t));
        }
    };
    let n_live = live.len();
    let counted = |h: u32| live.get(h).is_some_and(|_| !is_goal(h));
    let mut outcomes = Vec::new();
    // Backward from `seeds` over the policy's chain among the counted states.
    let mut backward = |mut queue: Vec<u32>, marked: &mut BitSet| {
        while let Some(t) = queue.pop() {
            model.space().predecessors(t, |p| {
                if !counted(p) || marked.contains(live.index(p)) {
                    return;
                }
                chosen(p, &mut outcomes);
                if outcomes.contains(&t) {
                    marked.insert(live.index(p));
                    queue.push(p);
                }
            });
        }
    };
    let mut reaches = BitSet::with_capacity(n_live);
    let mut seeds = Vec::new();
    let mut listed_seed = Listed::default();
    for &h in order {
        listed_seed.list(model, h);
        let c = match choices[live.index(h)] {
            CHANCE => 0,
            c => usize::from(c),
        };
        if c < listed_seed.len() && listed_seed.outcomes(c).iter().any(|&(t, _)| is_goal(t)) {
            reaches.insert(live.index(h));
            seeds.push(h);
        }
    }
    backward(seeds, &mut reaches);
    let stranded: Vec<u32> = order
        .iter()
        .copied()
        .filter(|&h| !reaches.contains(live.index(h)))
        .collect();
    if stranded.is_empty() {
        return stranded;
    }
    let mut bad = BitSet::with_capacity(n_live);
    for &h in &stranded {
        bad.insert(live.index(h));
    }
    backward(stranded, &mut bad);
    order
        .iter()
        .copied()
        .filter(|&h| bad.contains(live.index(h)))
        .collect()
}

/// What a policy collects from h0 and its expected number of robot moves until the run ends
/// (it commits, stops, gives up or meets a stuck adversary; infinite when that is not certain).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Evaluation {
    /// Certified bounds on the policy's expected payoff from h0.
    pub value: Interval,
    /// The expected number of robot moves from h0.
    pub expected_moves: f64,
    /// The chain's states: the live states the policy reaches from h0 where the run goes on.
    pub states: usize,
}

/// What the chain does in a product state.
enum Node {
    /// The run ends with this payoff.
    End(f64),
    /// A step with this factor and cost.
    Step(f64, f64),
}

/// `policy` evaluated as a Markov chain from h0 (module documentation), its values certified
/// to within `epsilon` in at most `max_iterations` sweeps per component, and checked against
/// `certified`, the solve's interval at h0.
///
/// # Errors
/// [`PolicyError::Invalid`] for an epsilon that is not positive and finite,
/// [`PolicyError::Evaluation`] when the sweeps do not certify the values,
/// [`PolicyError::Mismatch`] when the policy does not collect the certified value.
pub fn evaluate<M: Moves>(
    model: &Model<'_, '_, M>,
    policy: &Policy,
    certified: Interval,
    epsilon: f64,
    max_iterations: u32,
) -> Result<Evaluation, PolicyError> {
    if !(epsilon > 0.0 && epsilon.is_finite()) {
        return Err(PolicyError::Invalid {
            discount: policy.g,
            epsilon,
        });
    }
    let space = model.space();
    let g = policy.g;
    let mut listed = Listed::default();
    // What `h` is in the chain, with its outcomes in `listed` for a step.
    let node = |h: u32, listed: &mut Listed| -> Node {
        let Some(i) = policy.live.get(h) else {
            return Node::End(model.absorbing_payoff(h));
        };
        if policy.worthless.contains(i) {
            return Node::End(0.0);
        }
        listed.list(model, h);
        match policy.choices[i] {
            _ if space.owner(h) == Owner::Adversary => Node::Step(1.0, 0.0),
            // A decision node without a choice gives up (it is worth 0).
            CHANCE => Node::End(0.0),
            c if listed.instant[usize::from(c)] => Node::End(listed.stop[usize::from(c)]),
            c => {
                listed.keep(usize::from(c));
                Node::Step(g, 1.0)
            }
        }
    };
    // The chain's states reachable from h0.
    let h0 = space.initial();
    if let Node::End(payoff) = node(h0, &mut listed) {
        return check([payoff, payoff, 0.0], 0, certified, epsilon);
    }
    let mut reached = BitSet::with_capacity(space.num_states());
    reached.insert(h0 as usize);
    let mut stack = vec![h0];
    let mut outcomes = Vec::new();
    while let Some(h) = stack.pop() {
        node(h, &mut listed);
        outcomes.clear();
        outcomes.extend(listed.outcomes.iter().map(|&(t, _)| t));
        for &t in &outcomes {
            if !reached.contains(t as usize) && matches!(node(t, &mut listed), Node::Step(..)) {
                reached.insert(t as usize);
                stack.push(t);
            }
        }
    }
    drop(stack);
    let reached = Numbering::new(reached);
    let found = components(
        &reached.set,
        &|h| reached.index(h),
        reached.len(),
        |h, out| {
            out.clear();
            node(h, &mut listed);
            out.extend(
                listed
                    .outcomes
                    .iter()
                    .map(|&(t, _)| t)
                    .filter(|&t| reached.contains(t)),
            );
        },
    );
    let limits = SweepLimits {
        epsilon,
        max_iterations,
        compact_above: usize::MAX,
    };
    let mut values = vec![[0.0f64; 3]; reached.len()];
    let mut inside = BitSet::with_capacity(reached.len());
    let mut successors: Vec<([f64; 3], f64)> = Vec::new();
    let mut probe = Listed::default();
    // One Gauss–Seidel update of chain state `h`: its width and the change of its time.
    let mut update = |h: u32, values: &mut [[f64; 3]], listed: &mut Listed, probe: &mut Listed| {
        let Node::Step(factor, cost) = node(h, listed) else {
            unreachable!("a chain state steps")
        };
        successors.clear();
        for &(t, p) in &listed.outcomes {
            let value = match reached.get(t) {
                Some(j) => values[j],
                None => end_values(node(t, probe)),
            };
            successors.push((value, p));
        }
        let i = reached.index(h);
        let (new, width, change) = step([factor, cost], values[i], successors.iter().copied());
        values[i] = new;
        (width, change)
    };
    for c in 0..found.len() {
        let members = found.get(c);
        for &h in members {
            inside.insert(reached.index(h));
        }
        let self_loop = |h: u32, listed: &mut Listed| {
            node(h, listed);
            listed.outcomes.iter().any(|&(t, _)| t == h)
        };
        if let [h] = members
            && !self_loop(*h, &mut listed)
        {
            values[reached.index(*h)][1] = f64::INFINITY;
            update(*h, &mut values, &mut listed, &mut probe);
        } else {
            // Where the chain leaves the component: the largest value it can bring back, and
            // whether it can reach a place it never leaves (infinite time).
            let (mut exits, mut ceiling, mut endless) = (false, 0.0f64, false);
            for &h in members {
                node(h, &mut listed);
                for &(t, _) in &listed.outcomes {
                    let value = match reached.get(t) {
                        Some(j) if inside.contains(j) => continue,
                        Some(j) => values[j],
                        None => end_values(node(t, &mut probe)),
                    };
                    exits = true;
                    ceiling = ceiling.max(value[1]);
                    endless |= value[2].is_infinite();
                }
            }
            if !exits {
                for &h in members {
                    values[reached.index(h)] = [0.0, 0.0, f64::INFINITY];
                }
            } else {
                for &h in members {
                    values[reached.index(h)][1] = ceiling;
                }
                let mut iterations = 0;
                loop {
                    let (mut gap, mut change) = (0.0f64, 0.0f64);
                    for &h in members {
                        let (width, moved) = update(h, &mut values, &mut listed, &mut probe);
                        gap = gap.max(width);
                        change = change.max(moved);
                    }
                    iterations += 1;
                    if limits.converged(gap, change, endless) {
                        break;
                    }
                    if let Some(outcome) = limits.out_of_sweeps(iterations, gap) {
                        outcome?;
                        break;
                    }
                }
                if endless {
                    for &h in members {
                        values[reached.index(h)][2] = f64::INFINITY;
                    }
                }
            }
        }
        for &h in members {
            inside.remove(reached.index(h));
        }
    }
    check(values[reached.index(h0)], reached.len(), certified, epsilon)
}

/// The values `[lower, upper, time]` of a state where the chain ends.
fn end_values(node: Node) -> [f64; 3] {
    match node {
        Node::End(payoff) => [payoff, payoff, 0.0],
        Node::Step(..) => unreachable!("every chain state reached is numbered"),
    }
}

/// The evaluation at h0, refused when it is not the `certified` value within `epsilon` (and a
/// relative 1e-9 of rounding), as the explicit pipeline refuses its controller.
fn check(
    [lower, upper, expected_moves]: [f64; 3],
    states: usize,
    certified: Interval,
    epsilon: f64,
) -> Result<Evaluation, PolicyError> {
    let tolerance = epsilon + 1e-9 * certified.upper.max(1.0);
    if upper < certified.lower - tolerance || lower > certified.upper + tolerance {
        return Err(PolicyError::Mismatch {
            policy_lower: lower,
            policy_upper: upper,
            lower: certified.lower,
            upper: certified.upper,
        });
    }
    Ok(Evaluation {
        value: Interval { lower, upper },
        expected_moves,
        states,
    })
}

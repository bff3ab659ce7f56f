//! The opportunistic policy on the index space and its evaluation as a Markov chain
//! (docs/semantics.md §6.6, §13.2).
//!
//! ```
//! use hypersynth::arena::map;
//! use hypersynth::game::{Belief, Payoffs, TaskSet};
//! use hypersynth::implicit::{
//!     Choice, MapMoves, Model, Precision, Regions, Space, evaluate, policy, solve,
//! };
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
//! let solution = solve(&model, g, Precision::absolute(epsilon), 1000)?;
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
//!   of `L` or it stays in the state's maximal end component (those of the solve, among the
//!   states it did not settle from the graph, as in the explicit solver: a settled state's
//!   bound is its value, so a choice staying in its end component is eligible by value); among
//!   the eligible choices, the one of least expected robot moves to a goal (an absorbing state
//!   or one with `L = 0`, approximated from below per strongly connected component of the
//!   eligible choices' graph, by Gauss–Seidel sweeps in index order, by player on threads
//!   for a large component where it can be, as the solve's (`colour.rs`), within a relative
//!   `TIME_TOLERANCE`), then largest lower Q-value, then lowest position; the states from
//!   which that policy does not reach a goal with probability 1 play their *ranked* choice
//!   instead (ranks by a backward breadth-first search from the goals over the eligible
//!   choices).
//!
//! Eligibility is decided once per live state from the bounds and kept as a mask of edges
//! ([`Ties`]), so that the searches and sweeps walk a state's eligible edges without listing
//! its choices or its adversary's distribution again. A component swept more than once has
//! its eligible edges compiled first (`Ties::compile`, as the solve's, `backup.rs`): at 40x40,
//! g = 1, the expected moves' two large components (1.7 M and 3.0 M states, 40 and 79 sweeps)
//! took about 13 s from the rules, and the policy 24.0 s against 15.4 s compiled (one run
//! each, the whole command with the controller exported).
//!
//! Measured and not kept: passing by, in a sweep of the expected moves, a state none of whose
//! successors' times rose since its last update (exact: it would compute the same time; a bit
//! per live state for the last sweep's rises and one for this sweep's). Deciding that lists the
//! state's successors, which is most of what an update costs: at 40x40, g = 1, the policy took
//! 69.5 s against 50.2 s (the `implicit` bench, `--one 40 --solve 1 --policy`, one run each).
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
//! worth 0) and shares the solution's numbering of the live states. Below g = 1 nothing else
//! is needed. At g = 1, besides the solution, per live state two bytes for the eligibility
//! masks, four for the rank positions (while they are searched, on all threads, a bit per
//! product state for the search's claims and one for each of its two levels, `frontier.rs`)
//! and, while the expected moves are computed, eight shared
//! by the component search and the times, about 15 bytes, plus the search's stacks (eight
//! bytes per state on its path, four per state of an open component) and, while a component
//! is swept, its compiled edges (four bytes per member and per eligible edge, at most
//! [`Tuning::compiled`] bytes per live state; `backup.rs`); the proof that the
//! policy is proper then takes four bytes per ranked state and a bit per live state. The
//! evaluation takes per chain state (the live states the policy reaches from h0 where the run
//! goes on) 24 bytes for the bounds and expected moves and four for its components (twelve more
//! while Tarjan's algorithm runs, before the bounds are allocated), and a bit per state; it
//! does not read the solution, which may be dropped before it.

use std::sync::Arc;

use bit_set::BitSet;

use super::backup::{
    Compiled, Inverses, MASKED, RULES, STOP, inverses, masked_edges, uniform_mask,
};
use super::colour::{self, Split};
use super::ends::components;
use super::frontier::{Bits, advance, search};
use super::mdp::{Choice, Distribution, Model};
use super::moves::Moves;
use super::numbering::Numbering;
use super::solve::{Solution, Tuning};
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

/// The code of a chance node in [`Policy::choices`].
const CHANCE: u8 = u8::MAX;

/// The target standing for the stop sink in a [`Listed`] choice.
const SINK: u32 = u32::MAX;

/// The edge position of a choice that is not a move ([`Listed`]).
const NO_EDGE: usize = usize::MAX;

/// The opportunistic policy of a solved [`Model`] (module documentation).
#[derive(Clone, Debug)]
pub struct Policy {
    g: f64,
    /// The live states, numbered as the solution numbers them.
    live: Arc<Numbering>,
    /// Per live state: a decision node's choice (its position in [`Model::choices`]), or
    /// [`CHANCE`].
    choices: Vec<u8>,
    /// The live states (by number) worth exactly 0: the controller gives up there.
    worthless: BitSet,
}

impl Policy {
    /// The policy playing, per live state of `live` (by number), the choice at position
    /// `choices[i]` of a decision node, [`None`] for a chance node; the controller gives up in
    /// the live states of `worthless`.
    pub(super) fn from_parts(
        g: f64,
        live: Arc<Numbering>,
        choices: impl Iterator<Item = Option<u8>>,
        worthless: BitSet,
    ) -> Policy {
        Policy {
            g,
            live,
            choices: choices.map(|c| c.unwrap_or(CHANCE)).collect(),
            worthless,
        }
    }

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
    /// Per choice, where its outcomes start, its move's position among the state's edges
    /// ([`NO_EDGE`] for `stop` and a chance node's distribution), whether it is instant, and
    /// the payoff of `stop`.
    starts: Vec<usize>,
    edges: Vec<usize>,
    instant: Vec<bool>,
    stop: Vec<f64>,
    outcomes: Vec<(u32, f64)>,
    distribution: Distribution,
}

impl Listed {
    fn list<M: Moves>(&mut self, model: &Model<'_, '_, M>, h: u32) {
        self.starts.clear();
        self.edges.clear();
        self.instant.clear();
        self.stop.clear();
        self.outcomes.clear();
        if model.space().owner(h) == Owner::Adversary {
            model.distribution(h, &mut self.distribution);
            self.starts.push(0);
            self.edges.push(NO_EDGE);
            self.instant.push(true);
            self.stop.push(0.0);
            self.outcomes.extend(self.distribution.iter());
            return;
        }
        model.choices_by_edge(h, |edge, c| {
            self.starts.push(self.outcomes.len());
            self.edges.push(edge.unwrap_or(NO_EDGE));
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
    policy_tuned(model, solution, g, max_iterations, Tuning::default())
}

/// [`policy`] with `tuning` for the sweeps of its expected moves at g = 1 (when a component
/// is swept by player on threads and when its edges are compiled): the same choices, whatever
/// the tuning.
pub fn policy_tuned<M: Moves>(
    model: &Model<'_, '_, M>,
    solution: &Solution,
    g: f64,
    max_iterations: u32,
    tuning: Tuning,
) -> Result<Policy, PolicyError> {
    check_discount(g)?;
    let live = Arc::clone(solution.numbering());
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
        undiscounted(model, solution, &mut policy, (max_iterations, tuning));
    }
    Ok(policy)
}

/// [`PolicyError::Invalid`] for a discount outside `(0, 1]`.
pub(super) fn check_discount(g: f64) -> Result<(), PolicyError> {
    match g > 0.0 && g <= 1.0 {
        true => Ok(()),
        false => Err(PolicyError::Invalid {
            discount: g,
            epsilon: 0.0,
        }),
    }
}

/// The choices of the states with `L > 0` at g = 1 (module documentation).
fn undiscounted<M: Moves>(
    model: &Model<'_, '_, M>,
    solution: &Solution,
    policy: &mut Policy,
    (max_iterations, tuning): (u32, Tuning),
) {
    let live = &*policy.live;
    let lower = |h: u32| solution.value(model, h).lower;
    let ties = Ties::new(model, solution, live);
    let mut listed = Listed::default();
    let ranks = Ranks::new(&ties);
    // The expected moves to a goal over the eligible choices, by live state.
    let times = expected_moves(&ties, &ranks, (max_iterations, tuning), &mut listed);
    let time = |t: u32| live.get(t).map_or(0.0, |j| times[j]);
    // Each ranked robot state chooses on its own, on all threads.
    live.update(&mut policy.choices, Listed::default, |h, choice, listed| {
        if !ranks.is_ranked(live.index(h)) || model.space().owner(h) == Owner::Adversary {
            return;
        }
        let i = live.index(h);
        listed.list(model, h);
        let mut best: Option<(usize, f64, f64)> = None;
        for c in (0..listed.len()).filter(|&c| ties.eligible(listed, h, i, c)) {
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
        *choice = best.map_or(CHANCE, |(c, _, _)| c as u8);
    });
    drop(times);
    for h in improper(&ties, &policy.choices, &ranks) {
        let i = live.index(h);
        policy.choices[i] = ranks.choice(&ties, h, &mut listed);
    }
}

/// The eligible choices of the live states at g = 1 (module documentation), found once from
/// the lower bounds and kept per live state as a mask in the backup's format
/// (`backup.rs`): a decision node's eligible moves by edge position and [`STOP`] when `stop`
/// is eligible; a chance node's edges of positive probability when its distribution is
/// uniform over them and its one choice is eligible, 0 when it is not; [`RULES`] for a state
/// whose choices are listed from the model's rules (more edges than a mask holds, or a
/// distribution that is not uniform), whose eligibility is then derived again when asked.
struct Ties<'s, 'a, 'm, M> {
    model: &'s Model<'a, 'm, M>,
    solution: &'s Solution,
    live: &'s Numbering,
    /// By live index (0 for a goal, which is never asked).
    masks: Vec<u16>,
    inverse: Inverses,
}

impl<'s, 'a, 'm, M: Moves> Ties<'s, 'a, 'm, M> {
    fn new(
        model: &'s Model<'a, 'm, M>,
        solution: &'s Solution,
        live: &'s Numbering,
    ) -> Ties<'s, 'a, 'm, M> {
        let mut ties = Ties {
            model,
            solution,
            live,
            masks: Vec::new(),
            inverse: inverses(),
        };
        let space = model.space();
        // Each state's mask on its own, on all threads.
        let mut masks = vec![0; live.len()];
        live.update(&mut masks, Listed::default, |h, mask, listed| {
            if ties.is_goal(h) {
                return;
            }
            listed.list(model, h);
            *mask = if space.owner(h) == Owner::Adversary {
                match ties.rule(listed, h, 0) {
                    true => uniform_mask(&listed.distribution, &ties.inverse),
                    false => 0,
                }
            } else if space.degree(h) as usize > MASKED {
                RULES
            } else {
                (0..listed.len())
                    .filter(|&c| ties.rule(listed, h, c))
                    .fold(0, |mask, c| {
                        mask | match listed.edges[c] {
                            NO_EDGE => STOP,
                            edge => 1 << edge,
                        }
                    })
            };
        });
        ties.masks = masks;
        ties
    }

    /// The lower bound of `h`.
    #[inline]
    fn lower(&self, h: u32) -> f64 {
        self.solution.value(self.model, h).lower
    }

    /// Whether the run's time stops at `h`: the stop sink, an absorbing state or one whose
    /// lower bound is 0.
    #[inline]
    fn is_goal(&self, h: u32) -> bool {
        h == SINK || !self.live.contains(h) || self.lower(h) == 0.0
    }

    /// Whether choice `c` of live state `h` (listed) is eligible, from the bounds: it stays in
    /// `h`'s maximal end component, or its lower Q-value is within the tie tolerance of `L(h)`.
    fn rule(&self, listed: &Listed, h: u32, c: usize) -> bool {
        let ends = self.solution.ends();
        if let Some(own) = ends.of(h)
            && listed
                .outcomes(c)
                .iter()
                .all(|&(t, _)| t != SINK && ends.of(t) == Some(own))
        {
            return true;
        }
        let value = self.lower(h);
        listed.q(c, 1.0, |t| self.lower(t)) >= value - TIE_TOLERANCE * value.max(1.0)
    }

    /// Whether choice `c` of live state `h` (listed; live index `i`) is eligible.
    fn eligible(&self, listed: &Listed, h: u32, i: usize, c: usize) -> bool {
        let mask = self.masks[i];
        if mask & RULES != 0 {
            return self.rule(listed, h, c);
        }
        match listed.edges[c] {
            _ if self.model.space().owner(h) == Owner::Adversary => mask != 0,
            NO_EDGE => mask & STOP != 0,
            edge => mask & (1 << edge) != 0,
        }
    }

    /// Calls `f` with each outcome of each eligible choice of live state `h` (live index `i`;
    /// [`SINK`] for `stop`), in the order of the choices and their outcomes.
    fn outcomes(&self, h: u32, i: usize, listed: &mut Listed, mut f: impl FnMut(u32)) {
        let mask = self.masks[i];
        if mask & RULES == 0 {
            masked_edges(self.model.space(), h, mask, &mut f);
            if mask & STOP != 0 && self.model.space().owner(h) == Owner::Robot {
                f(SINK);
            }
            return;
        }
        listed.list(self.model, h);
        for c in (0..listed.len()).filter(|&c| self.rule(listed, h, c)) {
            for &(t, _) in listed.outcomes(c) {
                f(t);
            }
        }
    }

    /// Fills `out` with the outcomes of the choice `choices` gives live state `h` (a chance
    /// node's distribution).
    fn chosen(&self, h: u32, choices: &[u8], listed: &mut Listed, out: &mut Vec<u32>) {
        out.clear();
        let i = self.live.index(h);
        let mask = self.masks[i];
        let space = self.model.space();
        if space.owner(h) == Owner::Adversary && mask != 0 && mask & RULES == 0 {
            masked_edges(space, h, mask, |t| out.push(t));
            return;
        }
        listed.list(self.model, h);
        let c = match choices[i] {
            CHANCE => 0,
            c => usize::from(c),
        };
        if c < listed.len() {
            out.extend(listed.outcomes(c).iter().map(|&(t, _)| t));
        }
    }

    /// The eligible edges of the component `members` (ranked live states, in increasing
    /// order) compiled for the sweeps of its expected moves, unless they would take more than
    /// `budget` bytes: per member, the live index of each successor its mask keeps, or
    /// [`NOT_LIVE`] for a decision node's move to a state that is not live (worth 0 moves); a
    /// chance node's successors that are not live add nothing to its sum and are left out,
    /// and a state whose choices are listed from the rules ([`RULES`]) has none. (A live
    /// index is never [`NOT_LIVE`]: a product has fewer than 2^32 − 1 states.)
    fn compile(&self, members: &[u32], budget: usize) -> Option<Compiled> {
        let (live, space) = (self.live, self.model.space());
        Compiled::new(members, budget, |h, f| {
            let mask = self.masks[live.index(h)];
            if mask & RULES != 0 {
                return;
            }
            let robot = space.owner(h) == Owner::Robot;
            masked_edges(space, h, mask, |t| match live.get(t) {
                Some(j) => f(j as u32),
                None if robot => f(NOT_LIVE),
                None => {}
            });
        })
    }

    /// The least expected moves over the eligible choices of live state `h` (live index `i`),
    /// the times of its live successors given by live index (`time`; the others count 0):
    /// through the references of the member at `position` of a compiled component
    /// (`member`), else through its mask, else from its choices listed by the rules
    /// ([`Listed::time`]). The same sums in the same order (a chance node's successor left
    /// out of its references adds `+0`), the same minima.
    #[inline(always)]
    fn time_at(
        &self,
        member: Option<(&Compiled, usize)>,
        (i, h): (usize, u32),
        listed: &mut Listed,
        time: impl Fn(usize) -> f64,
    ) -> f64 {
        let live = self.live;
        let of_state = |t: u32| live.get(t).map_or(0.0, &time);
        let mask = self.masks[i];
        if mask & RULES != 0 {
            listed.list(self.model, h);
            return (0..listed.len())
                .filter(|&c| self.rule(listed, h, c))
                .map(|c| listed.time(c, of_state))
                .fold(f64::INFINITY, f64::min);
        }
        let space = self.model.space();
        let successors = |f: &mut dyn FnMut(f64)| match member {
            Some((compiled, position)) => {
                for &r in compiled.get(position) {
                    f(match r {
                        NOT_LIVE => 0.0,
                        j => time(j as usize),
                    });
                }
            }
            None => masked_edges(space, h, mask, |t| f(of_state(t))),
        };
        if space.owner(h) == Owner::Adversary {
            if mask == 0 {
                return f64::INFINITY;
            }
            let p = self.inverse[mask.count_ones() as usize];
            let mut sum = 0.0;
            successors(&mut |t| sum += p * t);
            return sum + 0.0;
        }
        let mut best = f64::INFINITY;
        successors(&mut |t| best = best.min(t + 1.0));
        if mask & STOP != 0 {
            best = best.min(0.0);
        }
        best
    }
}

/// A compiled reference to a successor that is not live (`Ties::compile`).
const NOT_LIVE: u32 = u32::MAX;

/// The rank of a live state that is a goal or has no rank.
const UNRANKED: u32 = u32::MAX;

/// The ranks of the backward search from the goals (module documentation): rank 1 are the
/// states with an eligible choice reaching a goal, rank k + 1 those with one reaching rank ≤ k.
/// By live index, two bytes each when every rank fits in them, four otherwise; [`UNRANKED`]
/// for a goal or a state without a rank.
enum Ranks {
    Short(Vec<u16>),
    Long(Vec<u32>),
}

impl Ranks {
    fn new<M: Moves>(ties: &Ties<'_, '_, '_, M>) -> Ranks {
        let live = ties.live;
        let mut rank = vec![UNRANKED; live.len()];
        // Whether `p` is a live state, not a goal, with an eligible choice reaching `t`: the
        // search claims it (ranked or about to be) the first time (`frontier.rs`: each level
        // on all threads).
        let offer = |p: u32, t: u32, listed: &mut Listed| {
            let Some(i) = live.get(p) else {
                return false;
            };
            if ties.is_goal(p) {
                return false;
            }
            let mut reaches = false;
            ties.outcomes(p, i, listed, |s| reaches |= s == t);
            reaches
        };
        // Rank 1: the predecessors of the goals, then the states with an eligible `stop`.
        let space = ties.model.space();
        let n = space.num_states() as u32;
        let claims = Bits::new(n as usize);
        let goals = Bits::from_fn(n as usize, || (), |t, _| ties.is_goal(t));
        let first = Bits::new(n as usize);
        advance(space, &goals, &claims, &first, Listed::default, offer);
        drop(goals);
        let mut stops = Bits::from_fn(n as usize, Listed::default, |p, listed| {
            live.contains(p) && space.owner(p) == Owner::Robot && offer(p, SINK, listed)
        });
        claims.claim_from(&mut stops);
        for p in stops.iter() {
            first.insert(p);
        }
        drop(stops);
        let mut k = 0u32;
        search(
            space,
            first,
            &claims,
            Listed::default,
            offer,
            |level, depth| {
                k = depth + 1;
                for h in level.iter() {
                    rank[live.index(h)] = k;
                }
            },
        );
        if k < u32::from(u16::MAX) {
            let short = |k: u32| if k == UNRANKED { u16::MAX } else { k as u16 };
            Ranks::Short(rank.into_iter().map(short).collect())
        } else {
            Ranks::Long(rank)
        }
    }

    /// The rank of live index `i`.
    #[inline]
    fn get(&self, i: usize) -> u32 {
        match self {
            Ranks::Short(rank) if rank[i] == u16::MAX => UNRANKED,
            Ranks::Short(rank) => u32::from(rank[i]),
            Ranks::Long(rank) => rank[i],
        }
    }

    /// Whether live index `i` has a rank.
    #[inline]
    fn is_ranked(&self, i: usize) -> bool {
        self.get(i) != UNRANKED
    }

    /// The ranked choice of ranked robot state `h` (its position in [`Model::choices`]): among
    /// its eligible choices with an outcome that is a goal or of a lower rank, the one of
    /// largest lower Q-value, the lowest position among exact ties; [`CHANCE`] for a chance
    /// node.
    fn choice<M: Moves>(&self, ties: &Ties<'_, '_, '_, M>, h: u32, listed: &mut Listed) -> u8 {
        let i = ties.live.index(h);
        if ties.model.space().owner(h) == Owner::Adversary {
            return CHANCE;
        }
        let own = self.get(i);
        let lower_rank = |t: u32| ties.live.get(t).is_some_and(|j| self.get(j) < own);
        listed.list(ties.model, h);
        let progressing = (0..listed.len()).filter(|&c| {
            ties.eligible(listed, h, i, c)
                && listed
                    .outcomes(c)
                    .iter()
                    .any(|&(t, _)| ties.is_goal(t) || lower_rank(t))
        });
        let best = best_choice(progressing, |c| listed.q(c, 1.0, |t| ties.lower(t)));
        best.map_or(CHANCE, |c| c as u8)
    }
}

/// A live state's slot in [`expected_moves`]: its time (an `f64`'s bits, never negative, so the
/// top bit clear) once its component is solved, or while its component is searched its
/// number in the search (`OPEN` set), or [`UNSEEN`].
const OPEN: u64 = 1 << 63;
const UNSEEN: u64 = u64::MAX;

/// The bit of a search frame's next successor that says its state is still a root.
const ROOT: u32 = 1 << 31;

/// The least expected number of robot moves to a goal over the eligible choices, approximated
/// from below, by live state (0 for the goals and the states without a rank): per strongly
/// connected component of the eligible choices' graph on the ranked states (`ranks`),
/// successors first, Gauss–Seidel sweeps in index order until no time rises by more than
/// `TIME_TOLERANCE` of itself, or `max_sweeps`.
///
/// The components are Pearce's variant of Tarjan's algorithm (one number per state, which
/// becomes the state's time once its component is solved: the search and the times share
/// eight bytes per live state), each solved as soon as the search closes it (every component
/// it reaches is closed before it), on the search's stack.
fn expected_moves<M: Moves>(
    ties: &Ties<'_, '_, '_, M>,
    ranks: &Ranks,
    (max_sweeps, tuning): (u32, Tuning),
    listed: &mut Listed,
) -> Vec<f64> {
    let live = ties.live;
    // The compiled edges of the component being swept take at most this many bytes.
    let budget = tuning.compiled.saturating_mul(live.len());
    let space = ties.model.space();
    let split = Split::of(space, live);
    // The states without a rank count 0 from the start: the search passes them by.
    let mut slots: Vec<u64> = (0..live.len())
        .map(|i| match ranks.is_ranked(i) {
            true => UNSEEN,
            false => 0f64.to_bits(),
        })
        .collect();
    // One Gauss–Seidel update of `h` (at `member` of a compiled component, if it is): whether
    // its time rose by more than the tolerance.
    let update =
        |member: Option<(&Compiled, usize)>, h: u32, slots: &mut [u64], listed: &mut Listed| {
            let i = live.index(h);
            let best = ties.time_at(member, (i, h), listed, |j| f64::from_bits(slots[j]));
            raise(&mut slots[i], best)
        };
    // The live successors of `h` through its eligible choices.
    let successors = |h: u32, out: &mut Vec<u32>, listed: &mut Listed| {
        out.clear();
        ties.outcomes(h, live.index(h), listed, |t| {
            if t != SINK && live.contains(t) {
                out.push(t);
            }
        });
    };
    let mut next = OPEN;
    // The search's path: a state and its next successor's position (with [`ROOT`]).
    let mut frames: Vec<(u32, u32)> = Vec::new();
    // The states whose component is open.
    let mut stack: Vec<u32> = Vec::new();
    let mut list = Vec::new();
    for root in live.members() {
        if slots[live.index(root)] != UNSEEN {
            continue;
        }
        slots[live.index(root)] = next;
        next += 1;
        frames.push((root, ROOT));
        while let Some(&mut (h, ref mut at)) = frames.last_mut() {
            let i = live.index(h);
            // The successors are listed once per visit of the frame, which takes every
            // successor already seen until one must be searched first (as in `components`).
            successors(h, &mut list, listed);
            let mut child = None;
            while let Some(&t) = list.get((*at & !ROOT) as usize) {
                *at += 1;
                let j = live.index(t);
                if slots[j] == UNSEEN {
                    child = Some((t, j));
                    break;
                } else if slots[j] & OPEN != 0 && slots[j] < slots[i] {
                    slots[i] = slots[j];
                    *at &= !ROOT;
                }
            }
            if let Some((t, j)) = child {
                slots[j] = next;
                next += 1;
                frames.push((t, ROOT));
                continue;
            }
            let is_root = *at & ROOT != 0;
            frames.pop();
            if is_root {
                // The component: `h` and the states above it on the stack (numbered after it).
                let above = stack
                    .iter()
                    .rev()
                    .take_while(|&&t| slots[live.index(t)] >= slots[i])
                    .count();
                let first = stack.len() - above;
                stack.push(h);
                stack[first..].sort_unstable();
                let members = &stack[first..];
                for &t in members.iter() {
                    slots[live.index(t)] = 0f64.to_bits();
                }
                // A large component whose turns alternate, its robot states first, is swept by
                // player on threads: the same sweep as in index order (`colour.rs`).
                let by_player = colour::by_player(space, (split, live), members, tuning.coloured);
                // A component of one state without a loop takes one update.
                if members.len() == 1 && !list.contains(&h) {
                    update(None, h, &mut slots, listed);
                } else {
                    // Its edges read from the rules once, if they fit the budget (`backup.rs`).
                    let compiled = ties.compile(members, budget);
                    for _ in 0..max_sweeps {
                        let changed = match by_player {
                            Some((split, first)) => colour::players(members, first)
                                .into_iter()
                                .fold(false, |changed, (player, offset)| {
                                    let found = colour::sweep(
                                        &mut slots,
                                        (split, live),
                                        player,
                                        Listed::default,
                                        |(p, t), i, slot, other, listed, changed: &mut bool| {
                                            let member = compiled.as_ref().map(|c| (c, offset + p));
                                            let best = ties.time_at(member, (i, t), listed, |j| {
                                                f64::from_bits(*other.get(j))
                                            });
                                            *changed |= raise(slot, best);
                                        },
                                        |a, b| a || b,
                                    );
                                    changed || found
                                }),
                            None => {
                                let mut changed = false;
                                for (p, &t) in members.iter().enumerate() {
                                    let member = compiled.as_ref().map(|c| (c, p));
                                    changed |= update(member, t, &mut slots, listed);
                                }
                                changed
                            }
                        };
                        if !changed {
                            break;
                        }
                    }
                }
                stack.truncate(first);
            } else {
                stack.push(h);
            }
            if let Some((parent, parent_at)) = frames.last_mut() {
                let p = live.index(*parent);
                if slots[i] & OPEN != 0 && slots[i] < slots[p] {
                    slots[p] = slots[i];
                    *parent_at &= !ROOT;
                }
            }
        }
    }
    slots.into_iter().map(f64::from_bits).collect()
}

/// Raises the time in `slot` (an `f64`'s bits) to `best` if that is higher: whether it rose by
/// more than `TIME_TOLERANCE` of itself.
#[inline(always)]
fn raise(slot: &mut u64, best: f64) -> bool {
    let old = f64::from_bits(*slot);
    *slot = best.max(old).to_bits();
    best > old + TIME_TOLERANCE * old.max(1.0)
}

/// The ranked states (`ranks`) from which the policy `choices` does not reach a goal with
/// probability 1: those that cannot reach one, and those that can reach a state that cannot.
/// The usual case takes one pass by increasing rank: a state reaches a goal when one of its
/// chosen outcomes is a goal or a state found to reach one, and when every ranked state does,
/// none is improper. Otherwise a backward search from the states the pass left out whose
/// chosen outcomes hold a goal or a state it found, among the states left out, finds the rest
/// of those that reach a goal (at 40x40, g = 1, the pass leaves out 252k of 12.5M ranked
/// states, every one of which reaches a goal: searching among them only took the check from
/// 8.4 s to 2.1 s), and one from the others finds those that reach them.
fn improper<M: Moves>(ties: &Ties<'_, '_, '_, M>, choices: &[u8], ranks: &Ranks) -> Vec<u32> {
    let (model, live) = (ties.model, ties.live);
    let n_live = live.len();
    let mut listed = Listed::default();
    let mut outcomes = Vec::new();
    let ranked = || live.members().filter(|&h| ranks.is_ranked(live.index(h)));
    // The ranked states by increasing rank (a counting sort).
    let mut starts: Vec<u32> = Vec::new();
    for h in ranked() {
        let k = ranks.get(live.index(h)) as usize;
        if starts.len() <= k + 1 {
            starts.resize(k + 2, 0);
        }
        starts[k + 1] += 1;
    }
    for k in 1..starts.len() {
        starts[k] += starts[k - 1];
    }
    let mut order = vec![0u32; starts.last().copied().unwrap_or(0) as usize];
    for h in ranked() {
        let k = ranks.get(live.index(h)) as usize;
        order[starts[k] as usize] = h;
        starts[k] += 1;
    }
    drop(starts);
    // Whether one of `h`'s chosen outcomes is a goal or a state of `reaches`.
    let leads = |h: u32, reaches: &BitSet, listed: &mut Listed, outcomes: &mut Vec<u32>| {
        ties.chosen(h, choices, listed, outcomes);
        outcomes
            .iter()
            .any(|&t| ties.is_goal(t) || live.get(t).is_some_and(|j| reaches.contains(j)))
    };
    let mut reaches = BitSet::with_capacity(n_live);
    for &h in &order {
        if leads(h, &reaches, &mut listed, &mut outcomes) {
            reaches.insert(live.index(h));
        }
    }
    if reaches.count() == order.len() {
        return Vec::new();
    }
    drop(order);
    // The pass found states that reach a goal, maybe not all of them: the others that do have
    // a path to a goal or to one of those, searched backward from the states left out that
    // have a chosen outcome there (only the found states' predecessors among the states left
    // out are visited, not the whole chain again).
    let seeds: Vec<u32> = ranked()
        .filter(|&h| !reaches.contains(live.index(h)))
        .filter(|&h| leads(h, &reaches, &mut listed, &mut outcomes))
        .collect();
    for &h in &seeds {
        reaches.insert(live.index(h));
    }
    let counted = |h: u32| live.get(h).is_some_and(|_| !ties.is_goal(h));
    // Backward from `seeds` over the policy's chain among the counted states.
    let mut backward = |mut queue: Vec<u32>, marked: &mut BitSet| {
        while let Some(t) = queue.pop() {
            model.space().predecessors(t, |p| {
                if !counted(p) || marked.contains(live.index(p)) {
                    return;
                }
                ties.chosen(p, choices, &mut listed, &mut outcomes);
                if outcomes.contains(&t) {
                    marked.insert(live.index(p));
                    queue.push(p);
                }
            });
        }
    };
    backward(seeds, &mut reaches);
    let stranded: Vec<u32> = ranked()
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
    ranked().filter(|&h| bad.contains(live.index(h))).collect()
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
    let h0 = model.space().initial();
    let (values, chain) = chain_values(model, policy, &[h0], epsilon, max_iterations)?;
    check(values[0], chain.len(), certified, epsilon)
}

/// What `policy` collects from each state of its chain from h0 (the live states it reaches
/// where the run goes on), solved as [`evaluate`] solves it: the controller's own values, from
/// which a certificate's lower bounds are made.
///
/// Memory: a bit per product state and 24 bytes per chain state.
pub struct Chain {
    reached: Numbering,
    /// By chain state: `[lower, upper, expected moves]`.
    values: Vec<[f64; 3]>,
}

impl Chain {
    /// The bounds on what the policy collects from `h`, if `h` is a state of the chain.
    pub fn value(&self, h: u32) -> Option<Interval> {
        let [lower, upper, _] = self.values[self.reached.get(h)?];
        Some(Interval { lower, upper })
    }

    /// The number of chain states.
    pub fn len(&self) -> usize {
        self.values.len()
    }

    /// Whether the chain has no state (h0 ends the run at once).
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }
}

/// The chain of `policy` from h0, every state's values certified to within `epsilon` in at
/// most `max_iterations` sweeps per component ([`Chain`]).
///
/// # Errors
/// [`PolicyError::Invalid`], [`PolicyError::Evaluation`] as [`evaluate`].
pub fn chain<M: Moves>(
    model: &Model<'_, '_, M>,
    policy: &Policy,
    epsilon: f64,
    max_iterations: u32,
) -> Result<Chain, PolicyError> {
    let h0 = model.space().initial();
    Ok(chain_values(model, policy, &[h0], epsilon, max_iterations)?.1)
}

/// The policy's expected number of robot moves from each of `states` until the run ends (as
/// [`Evaluation::expected_moves`] from h0), its chain solved as [`evaluate`] solves it from h0.
///
/// # Errors
/// [`PolicyError::Invalid`], [`PolicyError::Evaluation`] as [`evaluate`].
pub fn expected_moves_from<M: Moves>(
    model: &Model<'_, '_, M>,
    policy: &Policy,
    states: &[u32],
    epsilon: f64,
    max_iterations: u32,
) -> Result<Vec<f64>, PolicyError> {
    let (values, _) = chain_values(model, policy, states, epsilon, max_iterations)?;
    Ok(values.into_iter().map(|[_, _, time]| time).collect())
}

/// The values `[lower, upper, time]` of the policy's chain at each of `roots`, solved on the
/// chain's states reachable from them (module documentation), and that chain.
fn chain_values<M: Moves>(
    model: &Model<'_, '_, M>,
    policy: &Policy,
    roots: &[u32],
    epsilon: f64,
    max_iterations: u32,
) -> Result<(Vec<[f64; 3]>, Chain), PolicyError> {
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
    // The chain's states reachable from the roots.
    let mut reached = BitSet::with_capacity(space.num_states());
    let mut stack = Vec::new();
    for &root in roots {
        if !reached.contains(root as usize) && matches!(node(root, &mut listed), Node::Step(..)) {
            reached.insert(root as usize);
            stack.push(root);
        }
    }
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
        reached.set(),
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
    let at_roots = roots
        .iter()
        .map(|&h| match reached.get(h) {
            Some(j) => values[j],
            None => end_values(node(h, &mut listed)),
        })
        .collect();
    Ok((at_roots, Chain { reached, values }))
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

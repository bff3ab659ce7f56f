//! The hypergame MDP over the index space, as rules (docs/semantics.md §6.2–§6.3, §8.5): what
//! kind of MDP state a product state is, the adversary's distribution at a chance node and the
//! choices of a decision node are computed when asked, from the regions and a few bytes per
//! state; no transition is stored.
//!
//! Per product state the model keeps its level (one byte: the rank of its guarantee among the
//! distinct payoffs, as [`Levels`] ranks them for the explicit build), the least level of the
//! next robot state (one byte, for the risk rules) and one bit saying whether a robot state
//! commits without moving. Both backward searches that produce them are the explicit build's
//! ([`least_next_level`](crate::opportunistic::levels::least_next_level) and
//! `greatest_reachable_level`): waves in order of level over the moves that can happen, with
//! the predecessors computed and a queue as wide as a wave's frontier.
//!
//! The adversary plays by rule: `sigma_W` uniform over its safe actions, `sigma_L` uniform,
//! with the random weights of [`random_weight`](crate::opportunistic::adversary::random_weight) (a pure function of the seed, the arena state's
//! name and the action's), or from a weight table, normalised as the explicit engine's adversary
//! model normalises them. A table is resolved as the explicit engine resolves it (the same
//! checks, the same errors) against the arena's rules, found by name without a name per state:
//! the model keeps the normalised distributions of the listed arena states only, by arena
//! state, and nothing per product state.

use std::collections::VecDeque;
use std::sync::Arc;

use bit_set::BitSet;
use rayon::prelude::*;

use super::moves::Moves;
use super::regions::Regions;
use super::robust::Intervals;
use super::solve::Solution;
use super::space::Space;
use crate::arena::{ActionId, Owner};
use crate::game::{HState, SubsetPayoffs, TaskSet};
use crate::mdp::robust::inner;
use crate::opportunistic::adversary::{Fnv, RandomState, SigmaL, TableErrors, normalise};
use crate::opportunistic::build::{Risk, STOP};
use crate::opportunistic::levels::Levels;
use crate::opportunistic::observations::RunProduct;
use crate::opportunistic::presentation::{Commitment, Presentation, Sink};

/// Why the implicit engine cannot build a model.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ModelError {
    /// A weight table for sigma_L that does not fit the arena: the explicit engine's errors.
    #[error(transparent)]
    Table(#[from] TableErrors),
    /// More distinct payoffs than a byte can rank.
    #[error("the implicit engine handles at most 254 distinct payoffs, got {0}")]
    TooManyLevels(usize),
}

/// What an MDP state is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Kind {
    /// Absorbing, with this payoff.
    Absorbing(f64),
    /// An adversary state that moves: one instant choice, the adversary's distribution.
    Chance,
    /// A robot state with choices.
    Decision,
}

/// A choice of a decision node.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Choice {
    /// An arena action to a product state: a robot move (discounted).
    Move {
        /// The arena action.
        action: ActionId,
        /// The successor.
        target: u32,
    },
    /// `stop` (instant) to the stop sink [`Model::stop_sink`] names, which pays `payoff`, the
    /// state's guarantee.
    Stop {
        /// The sink's payoff.
        payoff: f64,
    },
}

/// The adversary's moves from a chance node with their probabilities (a buffer the caller
/// reuses).
#[derive(Clone, Debug, Default)]
pub struct Distribution {
    /// Successor and action, in edge order.
    moves: Vec<(u32, ActionId)>,
    weights: Vec<f64>,
}

impl Distribution {
    /// The successors of positive probability, with their probabilities, in edge order.
    pub fn iter(&self) -> impl Iterator<Item = (u32, f64)> + '_ {
        self.moves
            .iter()
            .zip(&self.weights)
            .filter(|&(_, &p)| p > 0.0)
            .map(|(&(t, _), &p)| (t, p))
    }
}

impl Distribution {
    /// The probability of each edge of the state, in edge order (0 for an edge the adversary
    /// never takes).
    pub(crate) fn edge_weights(&self) -> &[f64] {
        &self.weights
    }
}

/// sigma_L as the model plays it.
#[derive(Clone)]
enum Rule {
    Uniform,
    Random {
        seed: u64,
        /// Each action's name hashed.
        actions: Arc<[Fnv]>,
    },
    /// The listed arena states, sorted, with sigma_L's probability of each edge; the others
    /// play uniformly.
    Table(Arc<[(u32, Box<[f64]>)]>),
    /// The adversary's greedy reply within `intervals` to the lower bounds of `solution` (the
    /// robust stage's worst case, `robust.rs`).
    Replies {
        intervals: Arc<Intervals>,
        solution: Arc<Solution>,
    },
}

impl Rule {
    /// How the model plays `sigma_l` on the arena of `moves` (a weight table resolved against
    /// its rules, as the explicit engine resolves it against its arena).
    fn of<M: Moves>(sigma_l: &SigmaL, moves: &M) -> Result<Rule, ModelError> {
        Ok(match sigma_l {
            SigmaL::Uniform => Rule::Uniform,
            SigmaL::Random { seed } => Rule::Random {
                seed: *seed,
                actions: moves.actions().iter().map(|a| Fnv::of(a)).collect(),
            },
            SigmaL::Weights { table, .. } => {
                let mut listed: Vec<(u32, Box<[f64]>)> = table
                    .resolve(moves)?
                    .into_iter()
                    .map(|(state, mut weights)| {
                        normalise(&mut weights);
                        (state, weights.into())
                    })
                    .collect();
                listed.sort_unstable_by_key(|&(state, _)| state);
                Rule::Table(listed.into())
            }
        })
    }
}

/// No level: no robot state can come next.
const NONE: u8 = u8::MAX;

/// The hypergame MDP of a product with its regions, as rules.
pub struct Model<'a, 'm, M> {
    space: &'a Space<'m, M>,
    regions: &'a Regions,
    payoffs: &'a SubsetPayoffs,
    presentation: &'a Presentation,
    risk: Risk,
    sigma_l: Rule,
    /// The distinct payoffs, by level.
    values: Vec<f64>,
    levels: Levels,
    /// Per state: its level; the least level of the next robot state ([`NONE`]: none).
    level: Arc<Vec<u8>>,
    next: Arc<Vec<u8>>,
    /// The robot states that commit without moving.
    commits: Arc<BitSet>,
    sinks: Vec<Sink>,
}

impl<'a, 'm, M: Moves> Model<'a, 'm, M> {
    /// The model of `space` with `regions`, the sub-tasks' `payoffs` and the problem's
    /// `presentation` (its commitment rule and stop sinks), the robot keeping what `risk`
    /// allows and the adversary playing `sigma_l` where it believes it has lost.
    ///
    /// # Errors
    /// [`ModelError`].
    pub fn new(
        space: &'a Space<'m, M>,
        regions: &'a Regions,
        payoffs: &'a SubsetPayoffs,
        presentation: &'a Presentation,
        risk: Risk,
        sigma_l: &SigmaL,
    ) -> Result<Model<'a, 'm, M>, ModelError> {
        let sigma_l = Rule::of(sigma_l, space.moves())?;
        let levels = Levels::new(payoffs);
        let mut values: Vec<f64> = std::iter::once(0.0)
            .chain(TaskSet::non_empty(payoffs.num_tasks()).map(|set| payoffs.get(set)))
            .collect();
        values.sort_by(f64::total_cmp);
        values.dedup();
        if values.len() >= usize::from(NONE) {
            return Err(ModelError::TooManyLevels(values.len()));
        }
        let mut model = Model {
            space,
            regions,
            payoffs,
            presentation,
            risk,
            sigma_l,
            values,
            levels,
            level: Arc::default(),
            next: Arc::default(),
            commits: Arc::default(),
            sinks: presentation.sinks(payoffs),
        };
        model.level = Arc::new(
            (0..space.num_states() as u32)
                .map(|h| model.own_level(h) as u8)
                .collect(),
        );
        model.next = Arc::new(model.waves(false, false));
        model.commits = Arc::new(model.committing());
        Ok(model)
    }

    /// This model with the adversary playing `sigma_l` where it believes it has lost: the
    /// same states, levels, commitments and choices (those of this model's sigma_L's support),
    /// only the chance nodes' distributions change; shares this model's per-state tables.
    ///
    /// # Errors
    /// [`ModelError::Table`] for a weight table that does not fit the arena.
    pub fn with_sigma_l(&self, sigma_l: &SigmaL) -> Result<Model<'a, 'm, M>, ModelError> {
        Ok(self.with_rule(Rule::of(sigma_l, self.space.moves())?))
    }

    /// This model ([`Model::with_sigma_l`]) with sigma_L playing, at the arena states `listed`
    /// (sorted), the probabilities of each edge given (zero ones included), uniformly elsewhere:
    /// a learnt region's estimate.
    pub fn with_estimate(&self, listed: Vec<(u32, Box<[f64]>)>) -> Model<'a, 'm, M> {
        self.with_rule(Rule::Table(listed.into()))
    }

    /// This model ([`Model::with_sigma_l`]) with sigma_L playing the adversary's greedy reply
    /// within `intervals` to the lower bounds of `solution` (a solution of this model): the
    /// worst case the robust policy is checked against.
    pub fn with_replies(
        &self,
        intervals: Arc<Intervals>,
        solution: Arc<Solution>,
    ) -> Model<'a, 'm, M> {
        self.with_rule(Rule::Replies {
            intervals,
            solution,
        })
    }

    fn with_rule(&self, sigma_l: Rule) -> Model<'a, 'm, M> {
        Model {
            space: self.space,
            regions: self.regions,
            payoffs: self.payoffs,
            presentation: self.presentation,
            risk: self.risk,
            sigma_l,
            values: self.values.clone(),
            levels: self.levels.clone(),
            level: Arc::clone(&self.level),
            next: Arc::clone(&self.next),
            commits: Arc::clone(&self.commits),
            sinks: self.sinks.clone(),
        }
    }

    /// The index space.
    pub fn space(&self) -> &'a Space<'m, M> {
        self.space
    }

    /// The regions it was built from.
    pub fn regions(&self) -> &'a Regions {
        self.regions
    }

    /// The payoff of every set of sub-tasks.
    pub fn payoffs(&self) -> &'a SubsetPayoffs {
        self.payoffs
    }

    /// The problem's presentation.
    pub fn presentation(&self) -> &'a Presentation {
        self.presentation
    }

    /// The stop sinks, in order.
    pub fn sinks(&self) -> &[Sink] {
        &self.sinks
    }

    /// The level of a robot state (its guarantee's rank) or of a stuck adversary state (the
    /// top), computed from the regions.
    fn own_level(&self, h: u32) -> u32 {
        match self.space.owner(h) {
            Owner::Robot => self
                .levels
                .of_set(self.regions.best(self.payoffs, h).unwrap_or_default()),
            Owner::Adversary => self.levels.top(),
        }
    }

    /// Whether the play ends or the robot decides in `h`: a robot state, or an adversary state
    /// without an action. These are the sources of the level searches.
    fn is_source(&self, h: u32) -> bool {
        self.space.owner(h) == Owner::Robot || self.space.degree(h) == 0
    }

    /// Fills `out` with the moves of positive probability of adversary state `h`, with their
    /// probabilities, in edge order (empty for a stuck state). Uniform distributions (sigma_W
    /// over the safe actions, sigma_L uniform) are `1 / count`, which is what normalising
    /// equal weights gives, bit for bit.
    pub fn distribution(&self, h: u32, out: &mut Distribution) {
        out.moves.clear();
        out.weights.clear();
        self.space.edges(h, |a, t| out.moves.push((t, a)));
        let safe = out.moves.iter().filter(|&&(t, _)| self.is_safe(t)).count();
        if self.sigma_w_rules(h, safe) {
            // sigma_W: uniform over the safe actions.
            let p = 1.0 / safe as f64;
            out.weights.extend(
                out.moves
                    .iter()
                    .map(|&(t, _)| if self.is_safe(t) { p } else { 0.0 }),
            );
        } else {
            self.sigma_l_weights(self.space.arena_state(h), out);
        }
    }

    /// Whether `h` plays sigma_W: an adversary state outside `Win(psi)` with a safe action (as
    /// [`AdversaryModel::plays_sigma_w`](crate::opportunistic::adversary::AdversaryModel::plays_sigma_w)
    /// says of the explicit product); elsewhere an adversary state plays sigma_L.
    pub fn plays_sigma_w(&self, h: u32) -> bool {
        if self.space.owner(h) == Owner::Robot {
            return false;
        }
        let mut safe = 0;
        self.space
            .edges(h, |_, t| safe += usize::from(self.is_safe(t)));
        self.sigma_w_rules(h, safe)
    }

    /// Whether `h` is in `Win(psi)`.
    #[inline]
    pub fn believed_win(&self, h: u32) -> bool {
        self.regions.believed().contains(h as usize)
    }

    /// Whether a move of the adversary to `t` is safe: `t` is outside `Win(psi)`.
    #[inline]
    fn is_safe(&self, t: u32) -> bool {
        !self.believed_win(t)
    }

    /// Whether sigma_W rules at adversary state `h` with `safe` safe actions: outside
    /// `Win(psi)` with one at least (the one statement of the rule).
    #[inline]
    fn sigma_w_rules(&self, h: u32, safe: usize) -> bool {
        !self.believed_win(h) && safe > 0
    }

    /// Fills `out`'s weights with sigma_L's probabilities of the edges of arena state `s`
    /// (its moves are in `out`).
    fn sigma_l_weights(&self, s: u32, out: &mut Distribution) {
        let uniform = |out: &mut Distribution| {
            let p = 1.0 / out.moves.len() as f64;
            out.weights.resize(out.moves.len(), p);
        };
        match &self.sigma_l {
            Rule::Uniform => uniform(out),
            Rule::Random { seed, actions } => {
                // The state's name hashed as it is written, each action's hashed once.
                let mut name = Fnv::default();
                self.space
                    .moves()
                    .write_name(s, &mut name)
                    .expect("hashing does not fail");
                let state = RandomState::new(*seed, name);
                out.weights.extend(
                    out.moves
                        .iter()
                        .map(|&(_, a)| state.weight(actions[a as usize])),
                );
                normalise(&mut out.weights);
            }
            Rule::Table(listed) => match listed.binary_search_by_key(&s, |&(state, _)| state) {
                Ok(i) => out.weights.extend_from_slice(&listed[i].1),
                Err(_) => uniform(out),
            },
            Rule::Replies {
                intervals,
                solution,
            } => {
                let values: Vec<f64> = out
                    .moves
                    .iter()
                    .map(|&(t, _)| solution.bounds(self, t)[0])
                    .collect();
                let mut row = Vec::new();
                intervals.row(s, out.moves.len(), &mut row);
                inner::distribution(&values, &row, &mut out.weights);
            }
        }
    }

    /// Whether `p` can move to `t`: a robot edge (when `robot_moves`), or an adversary edge of
    /// positive probability.
    fn moves_to(&self, p: u32, t: u32, robot_moves: bool, scratch: &mut Distribution) -> bool {
        if self.space.owner(p) == Owner::Robot {
            return robot_moves;
        }
        self.distribution(p, scratch);
        scratch.iter().any(|(target, _)| target == t)
    }

    /// Per state, the level of the first wave that reaches it backwards over the possible
    /// moves (robot moves too when `robot_moves`), the waves in increasing order of level, or
    /// decreasing when `descending`; [`NONE`] where none does.
    fn waves(&self, robot_moves: bool, descending: bool) -> Vec<u8> {
        let n = self.space.num_states();
        let mut keys = vec![NONE; n];
        let mut queue = VecDeque::new();
        let mut scratch = Distribution::default();
        let order: Vec<u8> = if descending {
            (0..self.values.len() as u8).rev().collect()
        } else {
            (0..self.values.len() as u8).collect()
        };
        for level in order {
            for h in 0..n as u32 {
                if keys[h as usize] == NONE && self.is_source(h) && self.level[h as usize] == level
                {
                    keys[h as usize] = level;
                    queue.push_back(h);
                }
            }
            while let Some(t) = queue.pop_front() {
                self.space.predecessors(t, |p| {
                    if keys[p as usize] == NONE && self.moves_to(p, t, robot_moves, &mut scratch) {
                        keys[p as usize] = level;
                        queue.push_back(p);
                    }
                });
            }
        }
        keys
    }

    /// The robot states that commit without moving, by the presentation's commitment rule.
    fn committing(&self) -> BitSet {
        let n = self.space.num_states() as u32;
        let robot = (0..n).filter(|&h| self.space.owner(h) == Owner::Robot);
        match self.presentation.commitment() {
            Commitment::Labels => {
                let all = TaskSet::all(self.payoffs.num_tasks());
                let believed = self.regions.believed();
                robot
                    .filter(|&h| {
                        self.regions.wins(all, h)
                            || (!believed.contains(h as usize)
                                && self.regions.guarantee(self.payoffs, h) > 0.0)
                    })
                    .map(|h| h as usize)
                    .collect()
            }
            Commitment::NothingBetter => {
                let reachable = self.waves(true, true);
                robot
                    .filter(|&h| {
                        // A robot state is a source of its own level: never NONE.
                        reachable[h as usize] <= self.level[h as usize]
                    })
                    .map(|h| h as usize)
                    .collect()
            }
        }
    }

    /// Whether robot state `h` commits without moving (absorbing with its guarantee).
    #[inline]
    pub fn commits(&self, h: u32) -> bool {
        self.commits.contains(h as usize)
    }

    /// The number of live states: chance nodes and decision nodes that are not absorbing
    /// (counted on all threads).
    pub fn num_live(&self) -> u64 {
        let n = self.space.num_states() as u32;
        (0..n)
            .into_par_iter()
            .filter(|&h| !matches!(self.kind(h), Kind::Absorbing(_)))
            .count() as u64
    }

    /// What MDP state `h` is. A state the product does not enumerate (not reachable from
    /// `h0`, [`Space::enumerated`]) is absorbing with payoff 0: no enumerated state leads to it,
    /// so the solve, the policy and the controller leave it alone.
    pub fn kind(&self, h: u32) -> Kind {
        if !self.space.enumerated(h) {
            return Kind::Absorbing(0.0);
        }
        let stuck = self.space.degree(h) == 0;
        let payoff = self.values[usize::from(self.level[h as usize])];
        if self.space.owner(h) == Owner::Adversary {
            return if stuck {
                Kind::Absorbing(payoff)
            } else {
                Kind::Chance
            };
        }
        if self.commits.contains(h as usize) || (stuck && payoff == 0.0) {
            Kind::Absorbing(payoff)
        } else {
            Kind::Decision
        }
    }

    /// Calls `f` with each choice of decision node `h`: the arena actions the risk rule
    /// allows, in edge order, then `stop` when the guarantee is positive.
    pub fn choices(&self, h: u32, mut f: impl FnMut(Choice)) {
        self.choices_by_edge(h, |_, c| f(c));
    }

    /// [`Model::choices`] with each move's position among the edges of `h` (in
    /// [`Space::edges`]' order; `None` for `stop`).
    #[inline]
    pub(crate) fn choices_by_edge(&self, h: u32, mut f: impl FnMut(Option<usize>, Choice)) {
        let own = u32::from(self.level[h as usize]);
        let mut position = 0;
        self.space.edges(h, |action, target| {
            let next = self.next[target as usize];
            let next = if next == NONE {
                u16::MAX
            } else {
                u16::from(next)
            };
            if self.risk.allows(own, next) {
                f(Some(position), Choice::Move { action, target });
            }
            position += 1;
        });
        if own > 0 {
            // The sink of the set the state settles for pays its guarantee, in either
            // commitment rule (the paper's `stop(phi1)` from `(W, L, L)`, `stop(best)` from
            // `(W, W, L)`): no need to find it here.
            f(
                None,
                Choice::Stop {
                    payoff: self.absorbing_payoff(h),
                },
            );
        }
    }

    /// The `c`-th choice of decision node `h` ([`Model::choices`]' order), if it has one.
    pub fn choice(&self, h: u32, c: u8) -> Option<Choice> {
        let (mut found, mut i) = (None, 0);
        self.choices(h, |choice| {
            if i == c {
                found = Some(choice);
            }
            i = i.saturating_add(1);
        });
        found
    }

    /// The name of `choice`, as the explicit MDP names it: its arena action's, or `stop`.
    pub fn choice_name(&self, choice: Choice) -> String {
        match choice {
            Choice::Move { action, .. } => self.space.moves().actions()[action as usize].clone(),
            Choice::Stop { .. } => STOP.to_string(),
        }
    }

    /// The stop sink (counted from the first, [`Model::sinks`]) of decision node `h` with a
    /// positive guarantee.
    pub fn stop_sink(&self, h: u32) -> usize {
        let best = self.regions.best(self.payoffs, h).unwrap_or_default();
        self.presentation
            .stop_sink(|set| self.regions.wins(set, h), best)
    }

    /// The payoff of `h` if it is absorbing ([`Kind::Absorbing`]).
    #[inline]
    pub fn absorbing_payoff(&self, h: u32) -> f64 {
        self.values[usize::from(self.level[h as usize])]
    }

    /// The level of `h`: the rank of its payoff (absorbing) or of its `stop`'s (a decision
    /// node, 0 for none) among the distinct payoffs, [`Model::payoff_of_level`].
    #[inline]
    pub(crate) fn level(&self, h: u32) -> u8 {
        self.level[h as usize]
    }

    /// The payoff of level `level`.
    #[inline]
    pub(crate) fn payoff_of_level(&self, level: u8) -> f64 {
        self.values[usize::from(level)]
    }

    /// The number of levels (distinct payoffs, 0 included).
    pub(crate) fn num_levels(&self) -> usize {
        self.values.len()
    }

    /// The largest payoff.
    pub fn largest_payoff(&self) -> f64 {
        self.values.last().copied().unwrap_or(0.0)
    }
}

/// Observed runs are followed in the index space as in the explicit product
/// ([`Observations::count_on`](crate::opportunistic::observations::Observations::count_on)):
/// product states are indices, the arena is the rules, sigma_W rules where
/// [`Model::plays_sigma_w`] says.
impl<M: Moves> RunProduct for Model<'_, '_, M> {
    type Arena = M;

    fn arena(&self) -> &M {
        self.space.moves()
    }
    fn initial(&self) -> HState {
        HState::from_u32(self.space.initial())
    }
    fn arena_state(&self, h: HState) -> u32 {
        self.space.arena_state(h.as_u32())
    }
    fn successor(&self, h: HState, edge: usize) -> HState {
        let (mut place, mut found) = (0, None);
        self.space.edges(h.as_u32(), |_, t| {
            if place == edge {
                found = Some(t);
            }
            place += 1;
        });
        HState::from_u32(found.expect("an edge of the state"))
    }
    fn plays_sigma_w(&self, h: HState) -> bool {
        Model::plays_sigma_w(self, h.as_u32())
    }
    fn believed_win(&self, h: HState) -> bool {
        Model::believed_win(self, h.as_u32())
    }
    fn for_each_state(&self, mut f: impl FnMut(HState)) {
        self.space.states().for_each(|h| f(HState::from_u32(h)));
    }
}

//! An adversary learnt from observed runs (docs/semantics.md §10): the observations file, the
//! attribution of each adversary step to sigma_L or sigma_W, and the confidence region of
//! sigma_L.
//!
//! **File** (`grammar/observations.ebnf`): one run per line, alternating arena states and
//! actions `s0 a0 s1 a1 ... sn`, under the arena format's lexical rules (names bare or
//! double-quoted with the same escapes, `#` comments, blank lines ignored). A run is a play of
//! the game: it starts at the arena's initial state, and every `(s_i, a_i, s_{i+1})` is an arena
//! transition. Reading checks the shape of every line (a malformed line is reported and
//! skipped); [`Observations::count`] checks the meaning of every run against the game. Every
//! error is located (line and column) and reported in file order, the first 20.
//!
//! **Attribution.** Along a run the automata start in their initial states and read the labels
//! (the run is followed in the product from `h0`), so every adversary step happens at a known
//! product state `h`. Where `h` plays sigma_L (inside `Win(psi)`, or outside with no safe action:
//! [`AdversaryModel::plays_sigma_w`]) the step is a *counted* observation of sigma_L at `h`'s
//! arena state; elsewhere it is a step of sigma_W, not counted, and an unsafe action there (one
//! whose successor is in `Win(psi)`) is a *misfit* of the model: counted and reported, not an
//! error. Cost: linear in the file times the arena's out-degree. Either engine's product is
//! followed by the same code ([`RunProduct`], [`Observations::count_on`]), names found through
//! its arena's [`ArenaLookup`], so both give the same counts and the same errors.
//!
//! **Confidence region.** For an adversary arena state `s` with `n_s > 0` counted observations
//! and `c_{s,a}` of action `a`: `p_hat = c/n_s` and the interval `[max(0, p_hat − e_s),
//! min(1, p_hat + e_s)]`, `e_s = sqrt(ln(2K/δ) / (2 n_s))`, where `K` is the number of
//! (state, action) pairs of the observed states with two actions or more (Hoeffding's bound for
//! each pair with a union bound over the `K`: the region holds with probability at least
//! `1 − δ`). An unobserved state gets `[0, 1]` for every action (nominally uniform); a state
//! with a single action gets `[1, 1]` (its probability is known).
//!
//! **Memory.** [`Counts`] and [`Region`] keep the states with a counted observation only (at
//! most one per step of the file), sorted by arena state; every other state's counts are 0 and
//! its estimate and interval those of an unobserved state, given from its number of edges. So
//! neither grows with the arena: a map's arena need not be expanded to learn sigma_L.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};
use thiserror::Error;

use super::adversary::{AdversaryModel, ArenaLookup};
use super::evaluate::{Plan, Steps};
use super::simulate::{Against, Board, TraceAction, trace_on};
use super::view::GameView;
use crate::arena::{self, ActionId, Name, Owner, Spelled, StateId};
use crate::csr::Csr;
use crate::diagnostic::{Collector, DEFAULT_LIMIT, Diagnostics};
use crate::game::HState;
use crate::index::Id;
use crate::position::Position;

/// The default confidence parameter: the region holds with probability at least 95%.
pub const DEFAULT_DELTA: f64 = 0.05;

/// The runs of an observations file, as read (names not yet resolved).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Observations {
    runs: Vec<Vec<(Position, String)>>,
}

/// What is wrong in an observations file, at the place its diagnostic gives.
#[derive(Clone, Debug, Error, PartialEq, Eq)]
pub enum ObservationsError {
    /// A name that breaks the arena format's lexical rules.
    #[error(transparent)]
    Lexical(arena::ParseErrorKind),
    /// A run that ends with an action (an even number of names).
    #[error("a run alternates states and actions and ends with a state; this one ends with action `{}`", Name(.action))]
    EndsWithAction {
        /// The last name of the line.
        action: String,
    },
    /// A name that no arena state has.
    #[error("no arena state is named `{}`", Name(.state))]
    UnknownState {
        /// The name as written.
        state: String,
    },
    /// A run that does not start at the arena's initial state.
    #[error("a run starts at the initial state `{}`, not at `{}`", Name(.initial), Name(.state))]
    NotInitial {
        /// The arena's initial state.
        initial: String,
        /// The run's first state.
        state: String,
    },
    /// An action that the state does not enable.
    #[error("action `{}` is not enabled in state `{}`", Name(.action), Name(.state))]
    UnknownAction {
        /// The state.
        state: String,
        /// The action as written.
        action: String,
    },
    /// A step that is not an arena transition.
    #[error("`{}` `{}` leads to `{}`, not to `{}`", Name(.state), Name(.action), Name(.expected), Name(.found))]
    NotATransition {
        /// The state the step leaves.
        state: String,
        /// The action.
        action: String,
        /// Where the arena's transition leads.
        expected: String,
        /// The state the run names.
        found: String,
    },
}

/// The errors of an observations file, located in it.
pub type ObservationsErrors = Diagnostics<ObservationsError>;

impl Observations {
    /// Reads an observations file (see the module documentation); on errors, the first 20 in
    /// file order.
    pub fn parse(text: &str) -> Result<Observations, ObservationsErrors> {
        let mut runs = Vec::new();
        let mut errors = Collector::new(DEFAULT_LIMIT);
        for (number, line) in arena::lines(text) {
            let names = match arena::line_names(line, number) {
                Ok(names) => names,
                Err(error) => {
                    errors.push(error.map(ObservationsError::Lexical));
                    continue;
                }
            };
            if names.is_empty() {
                continue;
            }
            if names.len().is_multiple_of(2) {
                let (at, action) = names.last().expect("a name");
                let action = action.to_string();
                errors.add(*at, ObservationsError::EndsWithAction { action });
                continue;
            }
            runs.push(
                names
                    .into_iter()
                    .map(|(at, name)| (at, name.into_owned()))
                    .collect(),
            );
        }
        errors.or_ok(Observations { runs })
    }

    /// The number of runs.
    pub fn num_runs(&self) -> usize {
        self.runs.len()
    }

    /// The first `runs` runs (all of them if there are fewer).
    pub fn prefix(&self, runs: usize) -> Observations {
        Observations {
            runs: self.runs[..runs.min(self.runs.len())].to_vec(),
        }
    }

    /// Follows every run in `game` from `h0` and counts the adversary's steps as the module
    /// documentation says; every run's errors, in file order (the first 20).
    pub fn count(
        &self,
        game: &impl GameView,
        adversary: &AdversaryModel,
    ) -> Result<Counts, ObservationsErrors> {
        self.count_on(&Against { game, adversary })
    }

    /// [`Observations::count`] in any engine's `product`: names are resolved in its arena
    /// ([`ArenaLookup`]), so the same file gives the same counts and the same errors whichever
    /// engine holds the product.
    pub fn count_on(&self, product: &impl RunProduct) -> Result<Counts, ObservationsErrors> {
        let arena = product.arena();
        let initial = product.arena_state(product.initial());
        let mut rows: BTreeMap<StateId, Box<[u32]>> = BTreeMap::new();
        let mut counts = Counts {
            runs: self.runs.len() as u32,
            ..Counts::default()
        };
        let mut errors = Collector::new(DEFAULT_LIMIT);
        'runs: for run in &self.runs {
            let mut h = product.initial();
            for i in (0..run.len()).step_by(2) {
                let (at, name) = &run[i];
                let Some(next) = arena.find_state(name) else {
                    let state = name.clone();
                    errors.add(*at, ObservationsError::UnknownState { state });
                    continue 'runs;
                };
                if i == 0 && next != initial {
                    let kind = ObservationsError::NotInitial {
                        initial: arena.state_name(initial),
                        state: name.clone(),
                    };
                    errors.add(*at, kind);
                    continue 'runs;
                }
                let Some((at, action)) = run.get(i + 1) else {
                    break;
                };
                let Some(edge) = arena.find_edge(next, action) else {
                    let kind = ObservationsError::UnknownAction {
                        state: name.clone(),
                        action: action.clone(),
                    };
                    errors.add(*at, kind);
                    continue 'runs;
                };
                // `h` is over `next`: its edges are `next`'s, in the same order.
                let successor = product.successor(h, edge);
                let target = product.arena_state(successor);
                // An unknown next state is reported as such on the next pair.
                let (after_at, after) = &run[i + 2];
                if arena.find_state(after).is_some_and(|s| s != target) {
                    let kind = ObservationsError::NotATransition {
                        state: name.clone(),
                        action: action.clone(),
                        expected: arena.state_name(target),
                        found: after.clone(),
                    };
                    errors.add(*after_at, kind);
                    continue 'runs;
                }
                if arena.owner(next) == Owner::Adversary {
                    if product.plays_sigma_w(h) {
                        counts.sigma_w_steps += 1;
                        counts.misfits += u32::from(product.believed_win(successor));
                    } else {
                        counts.counted += 1;
                        let row = rows
                            .entry(StateId::from_u32(next.as_u32()))
                            .or_insert_with(|| vec![0; arena.degree(next)].into());
                        row[edge] += 1;
                    }
                }
                h = successor;
            }
        }
        counts.set_rows(rows);
        errors.or_ok(counts)
    }
}

/// What following observed runs asks of a product, whichever engine holds it: its arena (names
/// found and given by [`ArenaLookup`]), `h0`, the arena state and the successors of each
/// product state (its arena state's edges, in the same order), and where the adversary plays
/// sigma_W and `Win(psi)`. A product state is an [`HState`] in both engines (the implicit
/// engine's index). [`Against`] (a game with its [`AdversaryModel`]) is the explicit engine's;
/// the implicit engine's model is another.
pub trait RunProduct {
    /// The arena underneath.
    type Arena: ArenaLookup;
    /// The arena underneath.
    fn arena(&self) -> &Self::Arena;
    /// The initial product state `h0`.
    fn initial(&self) -> HState;
    /// The arena state of `h`.
    fn arena_state(&self, h: HState) -> <Self::Arena as ArenaLookup>::State;
    /// The successor of `h` by its edge `edge` (in edge order; `edge` is one of its edges).
    fn successor(&self, h: HState, edge: usize) -> HState;
    /// Whether `h` plays sigma_W: an adversary state outside `Win(psi)` with a safe action
    /// ([`AdversaryModel::plays_sigma_w`]).
    fn plays_sigma_w(&self, h: HState) -> bool;
    /// Whether `h` is in `Win(psi)`.
    fn believed_win(&self, h: HState) -> bool;
    /// Calls `f` with every product state the product enumerates, in any order.
    fn for_each_state(&self, f: impl FnMut(HState));
}

impl<G: GameView> RunProduct for Against<'_, G> {
    type Arena = arena::Arena;

    fn arena(&self) -> &arena::Arena {
        self.game.arena()
    }
    fn initial(&self) -> HState {
        self.game.initial()
    }
    fn arena_state(&self, h: HState) -> StateId {
        self.game.arena_state(h)
    }
    fn successor(&self, h: HState, edge: usize) -> HState {
        let (_, t) = self.game.edges(h).nth(edge).expect("an edge of the state");
        t
    }
    fn plays_sigma_w(&self, h: HState) -> bool {
        self.adversary.plays_sigma_w(h)
    }
    fn believed_win(&self, h: HState) -> bool {
        self.game.believed_win(h)
    }
    fn for_each_state(&self, f: impl FnMut(HState)) {
        self.game.states().for_each(f);
    }
}

/// `runs` runs of `plan` against `adversary` in the observations format, one line each: run
/// `i` is [`trace`](super::simulate::trace)d with seed `seed + i` and at most `max_steps` steps; the robot's `stop` is
/// not an arena action and is left out (the run goes on from the same state). What reading
/// the text back counts is a sample of `adversary`'s sigma_L.
pub fn record<P: Plan>(
    plan: &P,
    adversary: &AdversaryModel,
    runs: u32,
    seed: u64,
    max_steps: u32,
) -> String {
    let game = plan.game();
    let arena = game.arena();
    let board = Against { game, adversary };
    let names = RunNames {
        arena_state: &|h| game.arena_state(h).as_u32(),
        state: &|s| arena.name(StateId::from_u32(s)).to_string(),
        action: &|a| arena.action_name(a).to_string(),
    };
    record_on(plan, &board, &names, (runs, seed, max_steps))
}

/// How a recorded run names what it did, whichever engine's product it ran on: the arena state
/// of a product state, and the names of arena states and actions.
pub struct RunNames<'a> {
    /// The arena state of a product state.
    pub arena_state: &'a dyn Fn(HState) -> u32,
    /// An arena state's name.
    pub state: &'a dyn Fn(u32) -> String,
    /// An arena action's name.
    pub action: &'a dyn Fn(ActionId) -> String,
}

/// [`record`] for any controller's [`Steps`] on any [`Board`], named by `names`: `(runs, seed,
/// max_steps)` as there.
pub fn record_on(
    plan: &impl Steps,
    board: &impl Board,
    names: &RunNames<'_>,
    (runs, seed, max_steps): (u32, u64, u32),
) -> String {
    let mut text = String::new();
    for i in 0..runs {
        let run = trace_on(plan, board, seed.wrapping_add(u64::from(i)), max_steps);
        let mut moves = Vec::new();
        let mut last = (names.arena_state)(board.initial());
        for step in &run.steps {
            match step.action {
                Some(TraceAction::Stop) => continue,
                Some(TraceAction::Move(action)) => {
                    moves.push(((names.arena_state)(step.state), action));
                }
                None => {
                    last = (names.arena_state)(step.state);
                    break;
                }
            }
        }
        text.push_str(&line(&moves, last, names));
        text.push('\n');
    }
    text
}

/// One run in the observations format (without its line break): each move's arena state and
/// action, then the state the run ended in, names written as the arena format spells them.
pub fn run_line(arena: &arena::Arena, moves: &[(StateId, ActionId)], last: StateId) -> String {
    let moves: Vec<_> = moves.iter().map(|&(s, a)| (s.as_u32(), a)).collect();
    let names = RunNames {
        arena_state: &|h| h.as_u32(),
        state: &|s| arena.name(StateId::from_u32(s)).to_string(),
        action: &|a| arena.action_name(a).to_string(),
    };
    line(&moves, last.as_u32(), &names)
}

fn line(moves: &[(u32, ActionId)], last: u32, names: &RunNames<'_>) -> String {
    let mut words = Vec::with_capacity(2 * moves.len() + 1);
    for &(state, action) in moves {
        words.push(Spelled(&(names.state)(state)).to_string());
        words.push(Spelled(&(names.action)(action)).to_string());
    }
    words.push(Spelled(&(names.state)(last)).to_string());
    words.join(" ")
}

/// The adversary's steps along the runs (see the module documentation). Only the arena states
/// with a counted observation are kept: every other state's counts are 0.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Counts {
    /// The adversary arena states with a counted observation, in increasing order.
    states: Vec<StateId>,
    /// Per state of `states` (by place), the counted observations of each of its edges.
    per_edge: Csr<u32, u32>,
    /// The number of runs.
    pub runs: u32,
    /// The counted observations (steps where sigma_L rules).
    pub counted: u64,
    /// The steps where sigma_W rules (not counted).
    pub sigma_w_steps: u64,
    /// The steps where sigma_W rules that took an unsafe action.
    pub misfits: u32,
}

impl Counts {
    /// The counted observations of each edge of arena state `s`, in edge order, if it has one;
    /// `None` where every count is 0 (a robot state, an adversary state never counted).
    pub fn of(&self, s: StateId) -> Option<&[u32]> {
        let place = self.states.binary_search(&s).ok()?;
        Some(self.per_edge.row(place as u32))
    }

    /// The arena states with a counted observation, in increasing order, each with the counts
    /// of its edges in edge order.
    pub fn observed(&self) -> impl ExactSizeIterator<Item = (StateId, &[u32])> + '_ {
        let rows = (0..self.states.len() as u32).map(|place| self.per_edge.row(place));
        self.states.iter().copied().zip(rows)
    }

    /// Keeps `rows`, dropping those whose counts are all 0.
    fn set_rows(&mut self, rows: BTreeMap<StateId, Box<[u32]>>) {
        self.states.clear();
        self.per_edge = Csr::new();
        for (s, row) in rows {
            if row.iter().any(|&c| c > 0) {
                self.states.push(s);
                self.per_edge.push_row(row.iter().copied());
            }
        }
    }

    /// The positive counts by name, in the arena's state and edge order (as exported
    /// controllers write them).
    pub fn entries<A: ArenaLookup>(&self, arena: &A) -> Vec<Count> {
        let mut entries = Vec::new();
        for (s, row) in self.observed() {
            let s = A::State::from_u32(s.as_u32());
            for (edge, &count) in row.iter().enumerate() {
                if count > 0 {
                    entries.push(Count {
                        state: arena.state_name(s),
                        action: arena.edge_action(s, edge),
                        count,
                    });
                }
            }
        }
        entries
    }

    /// The counts `entries` give on `arena` (0 for every edge they do not name), as a
    /// controller file carries them: the entries must name adversary states, actions they
    /// enable, and each (state, action) once (a reader checks that first); what the file
    /// does not carry (runs, sigma_W steps, misfits) is 0, and `counted` their sum.
    pub fn from_entries(arena: &impl ArenaLookup, entries: &[Count]) -> Counts {
        let mut rows: BTreeMap<StateId, Box<[u32]>> = BTreeMap::new();
        let mut counts = Counts::default();
        for entry in entries {
            let Some(s) = arena
                .find_state(&entry.state)
                .filter(|&s| arena.owner(s) == Owner::Adversary)
            else {
                continue;
            };
            if let Some(edge) = arena.find_edge(s, &entry.action) {
                let row = rows
                    .entry(StateId::from_u32(s.as_u32()))
                    .or_insert_with(|| vec![0; arena.degree(s)].into());
                row[edge] = entry.count;
                counts.counted += u64::from(entry.count);
            }
        }
        counts.set_rows(rows);
        counts
    }
}

/// One count of a learnt sigma_L, as exported controllers write it: how often the adversary
/// was observed to play `action` at `state` where sigma_L rules.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Count {
    /// An adversary arena state's name.
    pub state: String,
    /// One of its enabled actions.
    pub action: String,
    /// The observations of it (positive).
    pub count: u32,
}

/// Why a confidence region cannot be made.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum RegionError {
    /// A confidence parameter outside `(0, 1)`.
    #[error("the confidence parameter must lie strictly between 0 and 1, not {0}")]
    InvalidDelta(f64),
}

/// The confidence region of sigma_L: per adversary arena state and edge, the estimate and its
/// interval (see the module documentation). Only the states with a counted observation are
/// kept, with their estimates and intervals ([`Region::observed`]); every other state's are
/// given by the rule for an unobserved state, from its number of edges.
#[derive(Clone, Debug, PartialEq)]
pub struct Region {
    /// The confidence parameter.
    pub delta: f64,
    /// The number of (state, action) pairs the union bound is taken over.
    pub pairs: u32,
    /// The adversary arena states with a counted observation, in increasing order.
    states: Vec<StateId>,
    /// Per state of `states` (by place), `e_s` where its intervals are estimated (NaN where
    /// they are exact: a single action).
    radius: Vec<f64>,
    /// Per state of `states` (by place) and edge: `[p_hat, lower, upper]`.
    entries: Csr<u32, [f64; 3]>,
}

/// A state of a [`Region`] with a counted observation ([`Region::observed`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObservedRow<'a> {
    /// The adversary arena state.
    pub state: StateId,
    /// `e_s` where the intervals are estimated (two actions or more), `None` where they are
    /// exact (`[1, 1]`: a single action).
    pub radius: Option<f64>,
    /// Per edge, in edge order: `[p_hat, lower, upper]`.
    pub edges: &'a [[f64; 3]],
}

impl Region {
    /// The region of `counts` at confidence `1 − delta`.
    pub fn new(counts: &Counts, delta: f64) -> Result<Region, RegionError> {
        if !(delta > 0.0 && delta < 1.0) {
            return Err(RegionError::InvalidDelta(delta));
        }
        let uncertain = |row: &[u32]| row.len() >= 2;
        let pairs: u32 = counts
            .observed()
            .filter(|(_, row)| uncertain(row))
            .map(|(_, row)| row.len() as u32)
            .sum();
        let log = (2.0 * f64::from(pairs.max(1)) / delta).ln();
        let mut entries = Csr::new();
        let mut radius = Vec::with_capacity(counts.states.len());
        for (_, row) in counts.observed() {
            if !uncertain(row) {
                entries.push_row(row.iter().map(|_| unobserved(row.len())));
                radius.push(f64::NAN);
                continue;
            }
            let n: u64 = row.iter().map(|&c| u64::from(c)).sum();
            let e = (log / (2.0 * n as f64)).sqrt();
            radius.push(e);
            entries.push_row(row.iter().map(|&c| {
                let p = f64::from(c) / n as f64;
                [p, (p - e).max(0.0), (p + e).min(1.0)]
            }));
        }
        Ok(Region {
            delta,
            pairs,
            states: counts.states.clone(),
            radius,
            entries,
        })
    }

    /// The place of `s` among the observed states.
    fn place(&self, s: StateId) -> Option<u32> {
        self.states.binary_search(&s).ok().map(|place| place as u32)
    }

    /// `e_s` of arena state `s` where its intervals are estimated (an adversary state with
    /// two actions or more and a counted observation): each interval is then `[max(0, p_hat −
    /// e_s), min(1, p_hat + e_s)]`; `None` where the intervals are exact (`[0, 1]` or `[1, 1]`).
    pub fn radius(&self, s: StateId) -> Option<f64> {
        self.place(s)
            .map(|place| self.radius[place as usize])
            .filter(|e| !e.is_nan())
    }

    /// `[p_hat, lower, upper]` of edge `edge` of adversary arena state `s`, which has `degree`
    /// edges.
    fn entry(&self, s: StateId, edge: usize, degree: usize) -> [f64; 3] {
        match self.place(s) {
            Some(place) => self.entries.row(place)[edge],
            None => unobserved(degree),
        }
    }

    /// The estimate `p_hat` of edge `edge` of adversary arena state `s`, which has `degree`
    /// edges (uniform unobserved).
    pub fn estimate(&self, s: StateId, edge: usize, degree: usize) -> f64 {
        self.entry(s, edge, degree)[0]
    }

    /// The interval `[lower, upper]` of edge `edge` of adversary arena state `s`, which has
    /// `degree` edges.
    pub fn interval(&self, s: StateId, edge: usize, degree: usize) -> [f64; 2] {
        let [_, lower, upper] = self.entry(s, edge, degree);
        [lower, upper]
    }

    /// Whether adversary arena state `s` has a counted observation.
    pub fn is_observed(&self, s: StateId) -> bool {
        self.place(s).is_some()
    }

    /// The states with a counted observation, in increasing order, with their estimates and
    /// intervals; every other state's are those of an unobserved state.
    pub fn observed(&self) -> impl ExactSizeIterator<Item = ObservedRow<'_>> + '_ {
        self.states
            .iter()
            .zip(&self.radius)
            .enumerate()
            .map(|(place, (&state, &e))| ObservedRow {
                state,
                radius: Some(e).filter(|e| !e.is_nan()),
                edges: self.entries.row(place as u32),
            })
    }
}

/// `[p_hat, lower, upper]` of every edge of a state with `degree` edges and no estimated
/// interval: uniform, and `[0, 1]` with two actions or more, `[1, 1]` with one.
pub(crate) fn unobserved(degree: usize) -> [f64; 3] {
    let uniform = 1.0 / degree.max(1) as f64;
    match degree {
        0 | 1 => [uniform, 1.0, 1.0],
        _ => [uniform, 0.0, 1.0],
    }
}

/// One point of a learning curve: what the robust stage gives from the first `runs` runs of
/// the observations (the figures of the robust summary learnt from those runs alone).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CurvePoint {
    /// The runs used: the first ones of the file.
    pub runs: u32,
    /// Adversary steps among them counted as observations of sigma_L.
    pub counted: u64,
    /// sigma_L states never observed in them.
    pub never_observed: u32,
    /// Certified lower bound of the robust value of h0.
    pub value: f64,
    /// Its upper bound.
    pub value_upper: f64,
    /// Certified lower bound of the nominal value of h0.
    pub nominal_value: f64,
    /// Its upper bound.
    pub nominal_value_upper: f64,
}

#[cfg(test)]
mod tests;

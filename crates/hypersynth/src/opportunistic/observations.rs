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
//! error. Cost: linear in the file times the arena's out-degree.
//!
//! **Confidence region.** For an adversary arena state `s` with `n_s > 0` counted observations
//! and `c_{s,a}` of action `a`: `p_hat = c/n_s` and the interval `[max(0, p_hat − e_s),
//! min(1, p_hat + e_s)]`, `e_s = sqrt(ln(2K/δ) / (2 n_s))`, where `K` is the number of
//! (state, action) pairs of the observed states with two actions or more (Hoeffding's bound for
//! each pair with a union bound over the `K`: the region holds with probability at least
//! `1 − δ`). An unobserved state gets `[0, 1]` for every action (nominally uniform); a state
//! with a single action gets `[1, 1]` (its probability is known).

use bit_set::BitSet;
use serde::{Deserialize, Serialize};
use thiserror::Error;

use super::adversary::AdversaryModel;
use super::evaluate::{Plan, Steps};
use super::simulate::{Against, Board, TraceAction, trace_on};
use super::view::GameView;
use crate::arena::{self, ActionId, Name, Owner, Spelled, StateId};
use crate::csr::Csr;
use crate::diagnostic::{Collector, DEFAULT_LIMIT, Diagnostics};
use crate::game::HState;
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
        let arena = game.arena();
        let mut counts = Counts {
            per_edge: zero_counts(arena),
            runs: self.runs.len() as u32,
            counted: 0,
            sigma_w_steps: 0,
            misfits: 0,
        };
        let mut errors = Collector::new(DEFAULT_LIMIT);
        'runs: for run in &self.runs {
            let mut state = None;
            let mut h = game.initial();
            for i in (0..run.len()).step_by(2) {
                let (at, name) = &run[i];
                let Some(next) = arena.find_state(name) else {
                    let state = name.clone();
                    errors.add(*at, ObservationsError::UnknownState { state });
                    continue 'runs;
                };
                if state.is_none() && next != arena.initial() {
                    let kind = ObservationsError::NotInitial {
                        initial: arena.name(arena.initial()).to_string(),
                        state: name.clone(),
                    };
                    errors.add(*at, kind);
                    continue 'runs;
                }
                state = Some(next);
                let Some((at, action)) = run.get(i + 1) else {
                    break;
                };
                let Some(edge) = arena
                    .edges(next)
                    .position(|(a, _)| arena.action_name(a) == action)
                else {
                    let kind = ObservationsError::UnknownAction {
                        state: name.clone(),
                        action: action.clone(),
                    };
                    errors.add(*at, kind);
                    continue 'runs;
                };
                let (_, target) = arena.edges(next).nth(edge).expect("the edge found");
                // An unknown next state is reported as such on the next pair.
                let (after_at, after) = &run[i + 2];
                if arena.find_state(after).is_some_and(|s| s != target) {
                    let kind = ObservationsError::NotATransition {
                        state: name.clone(),
                        action: action.clone(),
                        expected: arena.name(target).to_string(),
                        found: after.clone(),
                    };
                    errors.add(*after_at, kind);
                    continue 'runs;
                }
                let (_, successor) = game
                    .edges(h)
                    .nth(edge)
                    .expect("a product edge per arena edge");
                if arena.owner(next) == Owner::Adversary {
                    if adversary.plays_sigma_w(h) {
                        counts.sigma_w_steps += 1;
                        counts.misfits += u32::from(game.believed_win(successor));
                    } else {
                        counts.counted += 1;
                        counts.per_edge.row_mut(next)[edge] += 1;
                    }
                }
                h = successor;
            }
        }
        errors.or_ok(counts)
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

/// The adversary's steps along the runs (see the module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct Counts {
    /// Per adversary arena state, the counted observations of each of its edges.
    per_edge: Csr<StateId, u32>,
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
    /// The counted observations of each edge of arena state `s`, in edge order (empty for a
    /// robot state).
    pub fn of(&self, s: StateId) -> &[u32] {
        self.per_edge.row(s)
    }

    /// The positive counts by name, in the arena's state and edge order (as exported
    /// controllers write them).
    pub fn entries(&self, arena: &arena::Arena) -> Vec<Count> {
        let mut entries = Vec::new();
        for s in arena.states() {
            for ((a, _), &count) in arena.edges(s).zip(self.of(s)) {
                if count > 0 {
                    entries.push(Count {
                        state: arena.name(s).to_string(),
                        action: arena.action_name(a).to_string(),
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
    pub fn from_entries(arena: &arena::Arena, entries: &[Count]) -> Counts {
        let mut counts = Counts {
            per_edge: zero_counts(arena),
            runs: 0,
            counted: 0,
            sigma_w_steps: 0,
            misfits: 0,
        };
        for entry in entries {
            let Some(s) = arena.find_state(&entry.state) else {
                continue;
            };
            let edge = arena
                .edges(s)
                .position(|(a, _)| arena.action_name(a) == entry.action);
            if let Some(slot) = edge.and_then(|e| counts.per_edge.row_mut(s).get_mut(e)) {
                *slot = entry.count;
                counts.counted += u64::from(entry.count);
            }
        }
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

/// Zero counts for every edge of every adversary arena state.
fn zero_counts(arena: &arena::Arena) -> Csr<StateId, u32> {
    let mut counts = Csr::new();
    for s in arena.states() {
        let n = match arena.owner(s) {
            Owner::Robot => 0,
            Owner::Adversary => arena.edges(s).len(),
        };
        counts.push_row(std::iter::repeat_n(0, n));
    }
    counts
}

/// Why a confidence region cannot be made.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum RegionError {
    /// A confidence parameter outside `(0, 1)`.
    #[error("the confidence parameter must lie strictly between 0 and 1, not {0}")]
    InvalidDelta(f64),
}

/// The confidence region of sigma_L: per adversary arena state and edge, the estimate and its
/// interval (see the module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct Region {
    /// The confidence parameter.
    pub delta: f64,
    /// The number of (state, action) pairs the union bound is taken over.
    pub pairs: u32,
    /// Per adversary arena state and edge: `[p_hat, lower, upper]` (uniform, 0, 1 unobserved).
    entries: Csr<StateId, [f64; 3]>,
    /// Per arena state, `e_s` where its intervals are estimated (NaN elsewhere).
    radius: Vec<f64>,
    observed: BitSet,
}

impl Region {
    /// The region of `counts` on `arena` at confidence `1 − delta`.
    pub fn new(arena: &arena::Arena, counts: &Counts, delta: f64) -> Result<Region, RegionError> {
        if !(delta > 0.0 && delta < 1.0) {
            return Err(RegionError::InvalidDelta(delta));
        }
        let total = |s: StateId| counts.of(s).iter().map(|&c| u64::from(c)).sum::<u64>();
        let uncertain = |s: StateId| counts.of(s).len() >= 2;
        let pairs: u32 = arena
            .states()
            .filter(|&s| uncertain(s) && total(s) > 0)
            .map(|s| counts.of(s).len() as u32)
            .sum();
        let log = (2.0 * f64::from(pairs.max(1)) / delta).ln();
        let mut entries = Csr::new();
        let mut radius = vec![f64::NAN; arena.num_states()];
        let mut observed = BitSet::with_capacity(arena.num_states());
        for s in arena.states() {
            let row = counts.of(s);
            let n = total(s);
            if n == 0 || !uncertain(s) {
                let uniform = 1.0 / row.len().max(1) as f64;
                let bounds = if uncertain(s) { [0.0, 1.0] } else { [1.0, 1.0] };
                entries.push_row(row.iter().map(|_| [uniform, bounds[0], bounds[1]]));
                if n > 0 {
                    observed.insert(s.index());
                }
                continue;
            }
            observed.insert(s.index());
            let e = (log / (2.0 * n as f64)).sqrt();
            radius[s.index()] = e;
            entries.push_row(row.iter().map(|&c| {
                let p = f64::from(c) / n as f64;
                [p, (p - e).max(0.0), (p + e).min(1.0)]
            }));
        }
        Ok(Region {
            delta,
            pairs,
            entries,
            radius,
            observed,
        })
    }

    /// `e_s` of arena state `s` where its intervals are estimated (an adversary state with
    /// two actions or more and a counted observation): each interval is then `[max(0, p_hat −
    /// e_s), min(1, p_hat + e_s)]`; `None` where the intervals are exact (`[0, 1]` or `[1, 1]`).
    pub fn radius(&self, s: StateId) -> Option<f64> {
        Some(self.radius[s.index()]).filter(|e| !e.is_nan())
    }

    /// The estimate `p_hat` of edge `edge` of adversary arena state `s` (uniform unobserved).
    pub fn estimate(&self, s: StateId, edge: usize) -> f64 {
        self.entries.row(s)[edge][0]
    }

    /// The interval `[lower, upper]` of edge `edge` of adversary arena state `s`.
    pub fn interval(&self, s: StateId, edge: usize) -> [f64; 2] {
        let [_, lower, upper] = self.entries.row(s)[edge];
        [lower, upper]
    }

    /// Whether adversary arena state `s` has a counted observation.
    pub fn is_observed(&self, s: StateId) -> bool {
        self.observed.contains(s.index())
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

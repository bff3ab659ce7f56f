//! The games report (`hypersynth --phi PHI --psi PSI ARENA --games-only`) and the export of the
//! reactive strategies.
//!
//! [`GamesReport`] is plain data built by a pure function from the solved hypergame, printed as a
//! text table by its `Display` and as JSON by serde; the later MDP stage embeds it in its own
//! report. JSON keys are stable (docs/guide.md lists them): maps keep a fixed order (the partition in the
//! order of [`WinLabel::ALL`], strategies in product state order), so the same inputs always give
//! byte-identical output.

use std::fmt;

use serde::Serialize;
use serde::ser::Serializer;

use crate::arena::{Arena, Owner};
use crate::automata::Dfa;
use crate::game::{Attractor, HState, Hypergame, Partition, States, Task, TaskRegions, WinLabel};

/// One value per task, serialized as `{"phi1": .., "phi2": .., "phi": ..}`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct PerTask<T> {
    /// The value for `phi1`, the sub-task the adversary believes is the robot's whole task (`psi`).
    pub phi1: T,
    /// The value for `phi2`, the sub-task the adversary does not know about.
    pub phi2: T,
    /// The value for `phi = phi1 & phi2`, the robot's whole task.
    pub phi: T,
}

impl<T> PerTask<T> {
    /// Builds the triple by calling `f` once per task, in the order `phi1`, `phi2`, `phi`.
    pub fn from_fn(mut f: impl FnMut(Task) -> T) -> PerTask<T> {
        PerTask {
            phi1: f(Task::Phi1),
            phi2: f(Task::Phi2),
            phi: f(Task::Phi),
        }
    }

    /// The value for `task`.
    pub fn get(&self, task: Task) -> &T {
        match task {
            Task::Phi1 => &self.phi1,
            Task::Phi2 => &self.phi2,
            Task::Phi => &self.phi,
        }
    }
}

/// The arena's size, serialised as `{states, robot_states, adversary_states, transitions}`.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct ArenaSummary {
    /// Number of arena states.
    pub states: usize,
    /// Number of states the robot owns.
    pub robot_states: usize,
    /// Number of states the adversary owns (`states - robot_states`).
    pub adversary_states: usize,
    /// Number of transitions (arena edges, one per enabled state and action).
    pub transitions: usize,
}

impl ArenaSummary {
    /// Counts the states by owner and the transitions of `arena`.
    pub fn new(arena: &Arena) -> ArenaSummary {
        let robot_states = arena
            .states()
            .filter(|&s| arena.owner(s) == Owner::Robot)
            .count();
        ArenaSummary {
            states: arena.num_states(),
            robot_states,
            adversary_states: arena.num_states() - robot_states,
            transitions: arena.num_transitions(),
        }
    }
}

/// A task's formula and the size and origin of its DFA.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct AutomatonSummary {
    /// The task's name: its formula as printed, or the automaton file's name.
    pub formula: String,
    /// Number of states of the minimal DFA.
    pub states: usize,
    /// Number of edges of the DFA (guarded transitions between states).
    pub edges: usize,
    /// Which translation made the DFA: the translator's name (`builtin`, `spot (PATH)`), or `hoa`
    /// for an automaton read from a file.
    pub translator: String,
    /// How many of its states the product enumerates.
    pub enumerated_states: usize,
}

/// The initial product state `h0`.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct InitialSummary {
    /// The product state's name, `ARENA_STATE|Q1|Q2`.
    pub state: String,
    /// Its win-label, serialised by its code (e.g. `WLL`).
    pub label: WinLabel,
    /// Its rank in each winning region, `null` outside.
    pub ranks: PerTask<Option<u32>>,
}

/// What the hypergame stage found.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct GamesReport {
    /// The arena's size.
    pub arena: ArenaSummary,
    /// The robot's task.
    pub phi: String,
    /// The DFAs of `phi1` (= `psi`) and `phi2`.
    pub automata: AutomataSummary,
    /// Which product states were enumerated: `full` or `reachable`.
    pub states: States,
    /// Number of product states enumerated.
    pub product_states: usize,
    /// Number of product edges (one per arena edge of each enumerated state).
    pub product_edges: usize,
    /// Number of product states in `Win(phi1)`, `Win(phi2)` and `Win(phi)`.
    pub winning_region_sizes: PerTask<usize>,
    /// The largest rank in each winning region, `null` for an empty one.
    pub max_ranks: PerTask<Option<u32>>,
    /// The number of robot, adversary and all states per win-label, in the order of
    /// [`WinLabel::ALL`].
    pub partition: Partition,
    /// The initial product state, its win-label and ranks.
    pub initial: InitialSummary,
    /// Whether the robot wins each task from `h0`.
    pub realizable: PerTask<bool>,
    /// Propositions the formulas mention that no arena state carries (always false).
    pub missing_propositions: Vec<String>,
}

/// The DFAs of the two sub-tasks, serialised as `{phi1, phi2}`.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct AutomataSummary {
    /// The DFA of `phi1` (= `psi`).
    pub phi1: AutomatonSummary,
    /// The DFA of `phi2`.
    pub phi2: AutomatonSummary,
}

/// A task's formula text with its DFA and the translator that made it.
#[derive(Clone, Copy)]
pub struct TaskAutomaton<'a> {
    /// The task's name: its formula as printed, or the automaton file's name.
    pub formula: &'a str,
    /// The minimal DFA of the task.
    pub dfa: &'a Dfa,
    /// The translator's name (`builtin`, `spot (PATH)`), or `hoa` for an automaton read from a
    /// file.
    pub translator: &'a str,
}

impl GamesReport {
    /// Summarises a solved hypergame; `phi` is the robot's task, `automata` those of `phi1` and
    /// `phi2` (the DFAs `game` was built from).
    pub fn new(
        phi: &str,
        automata: [TaskAutomaton; 2],
        game: &Hypergame,
        regions: &TaskRegions,
    ) -> GamesReport {
        let arena = game.arena();
        let [a1, a2] = automata;
        let summary = |automaton: TaskAutomaton, enumerated: &[u32]| AutomatonSummary {
            formula: automaton.formula.to_string(),
            states: automaton.dfa.num_states(),
            edges: automaton.dfa.num_edges(),
            translator: automaton.translator.to_string(),
            enumerated_states: enumerated.len(),
        };
        let h0 = game.initial();
        GamesReport {
            arena: ArenaSummary::new(arena),
            phi: phi.to_string(),
            automata: AutomataSummary {
                phi1: summary(a1, game.q1_states()),
                phi2: summary(a2, game.q2_states()),
            },
            states: game.enumeration(),
            product_states: game.num_states(),
            product_edges: game.num_edges(),
            winning_region_sizes: PerTask::from_fn(|task| regions.win(task.set()).len()),
            max_ranks: PerTask::from_fn(|task| regions.win(task.set()).max_rank()),
            partition: Partition::compute(game, regions),
            initial: InitialSummary {
                state: game.name(h0),
                label: regions.win_label(h0),
                ranks: PerTask::from_fn(|task| regions.win(task.set()).rank(h0)),
            },
            realizable: PerTask::from_fn(|task| regions.win(task.set()).contains(h0)),
            missing_propositions: game.missing_propositions().to_vec(),
        }
    }
}

/// A task's line and its DFA's line. Shared with the general form's report.
pub(super) fn write_automaton(
    f: &mut fmt::Formatter<'_>,
    title: &str,
    dfa: &AutomatonSummary,
) -> fmt::Result {
    writeln!(
        f,
        "{title:<14} {}\n               DFA: {} states, {} edges ({}); {} reachable by arena labels",
        dfa.formula, dfa.states, dfa.edges, dfa.translator, dfa.enumerated_states
    )
}

/// The product's size line. Shared with the general form's report.
pub(super) fn write_product(
    f: &mut fmt::Formatter<'_>,
    states: States,
    product_states: usize,
    product_edges: usize,
) -> fmt::Result {
    let states = match states {
        States::Full => "full",
        States::Reachable => "reachable from h0",
    };
    writeln!(
        f,
        "product        {product_states} states, {product_edges} edges ({states})"
    )
}

/// The arena's size line. Shared with the general form's report.
pub(super) fn write_arena(f: &mut fmt::Formatter<'_>, a: &ArenaSummary) -> fmt::Result {
    writeln!(
        f,
        "arena          {} states ({} robot, {} adversary), {} transitions",
        a.states, a.robot_states, a.adversary_states, a.transitions
    )
}

impl fmt::Display for GamesReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write_arena(f, &self.arena)?;
        writeln!(f, "phi            {}", self.phi)?;
        write_automaton(f, "phi1 = psi", &self.automata.phi1)?;
        write_automaton(f, "phi2", &self.automata.phi2)?;
        write_product(f, self.states, self.product_states, self.product_edges)?;
        let sizes = &self.winning_region_sizes;
        writeln!(
            f,
            "winning        |Win(phi1)| = {}, |Win(phi2)| = {}, |Win(phi)| = {}",
            sizes.phi1, sizes.phi2, sizes.phi
        )?;
        writeln!(f)?;
        let width = self.product_states.to_string().len().max("adversary".len());
        writeln!(
            f,
            "{:<10} {:>width$} {:>width$} {:>width$}",
            "win-label", "robot", "adversary", "total"
        )?;
        for (label, counts) in self.partition.iter() {
            let note = if label.is_possible() {
                ""
            } else {
                "  (impossible)"
            };
            writeln!(
                f,
                "{:<10} {:>width$} {:>width$} {:>width$}{note}",
                label.to_string(),
                counts.robot,
                counts.adversary,
                counts.total
            )?;
        }
        writeln!(f)?;
        writeln!(
            f,
            "initial state  {}  {}",
            self.initial.state, self.initial.label
        )?;
        let verdict = |task: Task| match self.initial.ranks.get(task) {
            Some(rank) => format!("{task}: yes (rank {rank})"),
            None => format!("{task}: no"),
        };
        writeln!(
            f,
            "realizable     {}, {}, {}",
            verdict(Task::Phi),
            verdict(Task::Phi1),
            verdict(Task::Phi2)
        )
    }
}

/// The reactive strategies of both players for the three tasks, keyed by product state names:
///
/// ```json
/// {"states": "full", "initial": "s|q1|q2",
///  "tasks": {"phi1": {"realizable": true,
///                     "robot": {"s|q1|q2": {"rank": 3, "actions": ["N"]}, ...},
///                     "adversary": {"s|q1|q2": ["W", "S"], ...}},
///            "phi2": {...}, "phi": {...}}}
/// ```
#[derive(Serialize)]
pub struct StrategyExport<'a> {
    states: States,
    initial: String,
    tasks: PerTask<TaskStrategies<'a>>,
}

impl<'a> StrategyExport<'a> {
    /// Reads the strategies of every task off `regions`; the export borrows `game` and `regions`
    /// and computes the allowed actions while it is serialised.
    pub fn new(game: &'a Hypergame<'a>, regions: &'a TaskRegions) -> StrategyExport<'a> {
        StrategyExport {
            states: game.enumeration(),
            initial: game.name(game.initial()),
            tasks: PerTask::from_fn(|task| TaskStrategies::new(game, regions.win(task.set()))),
        }
    }
}

/// Both players' reactive strategies for one winning region `win` (serialised as
/// `{realizable, robot, adversary}`): the robot's rank-decreasing strategy in `win` and the
/// adversary's maximally permissive one outside it, the rules of
/// [`crate::game::ReactiveStrategy`], read off the attractor as they are written, so nothing
/// but the attractor is kept.
#[derive(Serialize)]
pub(super) struct TaskStrategies<'a> {
    realizable: bool,
    robot: RobotMoves<'a>,
    adversary: AdversaryMoves<'a>,
}

impl<'a> TaskStrategies<'a> {
    pub(super) fn new(game: &'a Hypergame<'a>, win: &'a Attractor) -> TaskStrategies<'a> {
        TaskStrategies {
            realizable: win.contains(game.initial()),
            robot: RobotMoves { game, win },
            adversary: AdversaryMoves { game, win },
        }
    }
}

/// The robot's states of `Win`, each with its rank and the actions to a state of lower rank
/// (every action staying in `Win` at rank 0).
struct RobotMoves<'a> {
    game: &'a Hypergame<'a>,
    win: &'a Attractor,
}

/// The adversary's states outside `Win`, each with the actions that stay outside.
struct AdversaryMoves<'a> {
    game: &'a Hypergame<'a>,
    win: &'a Attractor,
}

#[derive(Serialize)]
struct RankedActions<'a> {
    rank: u32,
    actions: Vec<&'a str>,
}

/// The names of the actions of `h` whose successor passes `allows`.
fn allowed_actions<'a>(
    game: &'a Hypergame<'a>,
    h: HState,
    allows: impl Fn(HState) -> bool,
) -> Vec<&'a str> {
    game.edges(h)
        .filter(|&(_, target)| allows(target))
        .map(|(action, _)| game.arena().action_name(action))
        .collect()
}

/// The states of `owner` that `select` keeps, in product order, with their names.
fn states_of<'a>(
    game: &'a Hypergame<'a>,
    owner: Owner,
    select: impl Fn(HState) -> bool + 'a,
) -> impl Iterator<Item = (String, HState)> + 'a {
    game.states()
        .filter(move |&h| game.owner(h) == owner && select(h))
        .map(move |h| (game.name(h), h))
}

impl Serialize for RobotMoves<'_> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let (game, win) = (self.game, self.win);
        serializer.collect_map(states_of(game, Owner::Robot, |h| win.contains(h)).map(
            |(name, h)| {
                let entry = RankedActions {
                    rank: win.rank(h).expect("the robot's strategy lives in Win"),
                    actions: allowed_actions(game, h, |t| win.allows_robot_edge(h, t)),
                };
                (name, entry)
            },
        ))
    }
}

impl Serialize for AdversaryMoves<'_> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let (game, win) = (self.game, self.win);
        serializer.collect_map(
            states_of(game, Owner::Adversary, |h| !win.contains(h))
                .map(|(name, h)| (name, allowed_actions(game, h, |t| !win.contains(t)))),
        )
    }
}

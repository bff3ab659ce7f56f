//! The games stage's summary ([`Games`]: the arena, the tasks and the belief, the payoffs, the
//! product, the winning regions, the partition of the states by label and h0) and the export of
//! the reactive strategies ([`StrategyExport`]): plain data built by pure functions from the
//! solved hypergame, one model for both vocabularies (the report's [`Presentation`] says how they
//! are named and laid out).
//!
//! [`Presentation`]: crate::opportunistic::presentation::Presentation

use crate::game::Wins;
use serde::Serialize;
use serde::ser::{SerializeMap, Serializer};

use crate::arena::{Arena, Owner};
use crate::automata::Dfa;
use crate::game::{
    Belief, Engine, HState, Hypergame, LabelClass, ProductStrategies, States, StrategySource,
    SubsetLabel, SubsetPayoffs, TaskRegions, TaskSet, WinRegion, allows_robot_edge, label_classes,
};
use crate::opportunistic::presentation::Presentation;

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

/// A sub-task: its name and automaton summary.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct TaskSummary {
    /// The sub-task's name (`A` in `--task A=…`, `phi1` in the paper's terms).
    pub name: String,
    /// Its formula and DFA, flattened into the sub-task's object.
    #[serde(flatten)]
    pub automaton: AutomatonSummary,
}

/// The adversary's belief.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct BeliefSummary {
    /// The formula (or HOA file) of psi.
    pub formula: String,
    /// The sub-tasks psi is the conjunction of, or `null` when psi has its own automaton.
    pub tasks: Option<Vec<String>>,
    /// psi's own automaton, when it has one.
    pub automaton: Option<AutomatonSummary>,
}

/// `r(T)` of one set.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SetPayoff {
    /// The set's sub-tasks by name, in product order.
    pub set: Vec<String>,
    /// `r(T)`, non-negative and monotone in the set.
    pub payoff: f64,
}

/// `Win(T)` of one set.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct RegionSummary {
    /// The set's sub-tasks by name, in product order.
    pub set: Vec<String>,
    /// Number of product states in `Win(T)`.
    pub states: usize,
    /// Number of robot states in `Win(T)`.
    pub robot_states: usize,
    /// The largest rank in `Win(T)`, `null` when it is empty.
    pub max_rank: Option<u32>,
    /// Whether h0 is in it.
    pub realizable: bool,
    /// h0's rank in it, `None` outside.
    #[serde(skip)]
    pub initial_rank: Option<u32>,
}

/// h0 in the games stage.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct InitialSummary {
    /// h0's name, `ARENA_STATE|Q_1|…`.
    pub state: String,
    /// The inclusion-maximal winnable sets at h0.
    pub maximal: Vec<Vec<String>>,
    /// Whether h0 is in `Win(psi)`, where the adversary believes it has lost.
    pub psi: bool,
    /// `gr(h0)`: the largest `r(T)` over the sets T with h0 in `Win(T)`, 0 if there is none.
    pub guarantee: f64,
    /// The set the robot would commit to if it settled at h0 (`null`: none).
    pub settles_for: Option<Vec<String>>,
}

/// What the games stage found.
#[derive(Clone, Debug, PartialEq)]
pub struct Games {
    /// The arena's size.
    pub arena: ArenaSummary,
    /// The sub-tasks in product order.
    pub tasks: Vec<TaskSummary>,
    /// The adversary's belief psi.
    pub believed: BeliefSummary,
    /// `r(T)` for every non-empty set T, in mask order.
    pub payoffs: Vec<SetPayoff>,
    /// Which product states were enumerated: `full` or `reachable`.
    pub states: States,
    /// The engine that held the product: `explicit` or `implicit`.
    pub engine: Engine,
    /// Number of product states enumerated.
    pub product_states: usize,
    /// Number of product edges (one per arena edge of each enumerated state).
    pub product_edges: usize,
    /// `Win(T)` for every non-empty set T, in mask order.
    pub regions: Vec<RegionSummary>,
    /// Number of product states in `Win(psi)`.
    pub believed_region: usize,
    /// The states by the sets they win and `Win(psi)` (both vocabularies' partitions are read
    /// from them).
    pub classes: Vec<LabelClass>,
    /// h0's label and guarantee.
    pub initial: InitialSummary,
    /// Propositions the automata mention that no arena state carries (always false).
    pub missing_propositions: Vec<String>,
}

/// What the games report reads of a solved hypergame, whichever engine holds it: plain counts
/// and h0's facts ([`ProductFacts::of`] for the stored product, the implicit engine makes its
/// own).
#[derive(Clone, Debug, PartialEq)]
pub struct ProductFacts {
    /// The arena's size.
    pub arena: ArenaSummary,
    /// Per automaton of the product (the sub-tasks', then psi's), the states it enumerates.
    pub enumerated: Vec<usize>,
    /// Which product states are enumerated.
    pub states: States,
    /// The engine that held the product.
    pub engine: Engine,
    /// Number of product states.
    pub product_states: usize,
    /// Number of product edges.
    pub product_edges: usize,
    /// Per non-empty set of sub-tasks, in mask order: `Win(T)`'s size, robot states and ranks.
    pub regions: Vec<RegionFacts>,
    /// `|Win(psi)|`.
    pub believed_region: usize,
    /// The states by the sets they win and `Win(psi)`.
    pub classes: Vec<LabelClass>,
    /// h0's name.
    pub initial: String,
    /// The sets of sub-tasks h0 wins, in mask order.
    pub initial_wins: Vec<TaskSet>,
    /// Whether h0 is in `Win(psi)`.
    pub initial_psi: bool,
    /// The belief: a set of sub-tasks, or psi's own automaton.
    pub belief: Belief,
    /// Propositions the automata mention that no arena state carries.
    pub missing_propositions: Vec<String>,
}

/// One winning region's counts (see [`RegionSummary`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RegionFacts {
    /// Number of product states in it.
    pub states: usize,
    /// Number of robot states in it.
    pub robot_states: usize,
    /// Largest attractor rank in it.
    pub max_rank: Option<u32>,
    /// h0's rank (`None` outside it).
    pub initial_rank: Option<u32>,
}

impl ProductFacts {
    /// The facts of the stored product `game` and its `regions`.
    pub fn of(game: &Hypergame, regions: &TaskRegions) -> ProductFacts {
        let k = regions.num_tasks();
        let h0 = game.initial();
        let robot = |h: HState| game.owner(h) == Owner::Robot;
        ProductFacts {
            arena: ArenaSummary::new(game.arena()),
            enumerated: (0..game.num_automata())
                .map(|i| game.automaton_states(i).len())
                .collect(),
            states: game.enumeration(),
            engine: Engine::Explicit,
            product_states: game.num_states(),
            product_edges: game.num_edges(),
            regions: TaskSet::non_empty(k)
                .map(|set| {
                    let win = regions.win(set);
                    RegionFacts {
                        states: win.len(),
                        robot_states: win
                            .region()
                            .iter()
                            .filter(|&h| robot(HState::new(h)))
                            .count(),
                        max_rank: win.max_rank(),
                        initial_rank: win.rank(h0),
                    }
                })
                .collect(),
            believed_region: regions.believed().len(),
            classes: label_classes(game, regions),
            initial: game.name(h0),
            initial_wins: TaskSet::non_empty(k)
                .filter(|&set| regions.win(set).contains(h0))
                .collect(),
            initial_psi: regions.believed().contains(h0),
            belief: regions.belief(),
            missing_propositions: game.missing_propositions().to_vec(),
        }
    }
}

impl Games {
    /// Summarises a solved hypergame: `tasks` are the sub-tasks' automata in product order
    /// (named as `presentation` names them), `psi` psi's formula with its own automaton when it
    /// has one (the product's last).
    pub fn new(
        presentation: &Presentation,
        tasks: &[TaskAutomaton],
        psi: (&str, Option<TaskAutomaton>),
        payoffs: &SubsetPayoffs,
        game: &Hypergame,
        regions: &TaskRegions,
    ) -> Games {
        let facts = ProductFacts::of(game, regions);
        Games::from_facts(presentation, tasks, psi, payoffs, facts)
    }

    /// [`Games::new`] from the `facts` of either engine's product.
    pub fn from_facts(
        presentation: &Presentation,
        tasks: &[TaskAutomaton],
        psi: (&str, Option<TaskAutomaton>),
        payoffs: &SubsetPayoffs,
        facts: ProductFacts,
    ) -> Games {
        let names = presentation.names();
        let summary = |automaton: &TaskAutomaton, i: usize| AutomatonSummary {
            formula: automaton.formula.to_string(),
            states: automaton.dfa.num_states(),
            edges: automaton.dfa.num_edges(),
            translator: automaton.translator.to_string(),
            enumerated_states: facts.enumerated[i],
        };
        let k = tasks.len();
        let wins = |set: TaskSet| facts.initial_wins.contains(&set);
        let label = SubsetLabel::of(k, wins, facts.initial_psi);
        let best = payoffs.best(wins);
        Games {
            arena: facts.arena.clone(),
            tasks: tasks
                .iter()
                .enumerate()
                .map(|(i, automaton)| TaskSummary {
                    name: names[i].clone(),
                    automaton: summary(automaton, i),
                })
                .collect(),
            believed: BeliefSummary {
                formula: psi.0.to_string(),
                tasks: match facts.belief {
                    Belief::Tasks(set) => Some(set.names(names)),
                    Belief::Automaton => None,
                },
                automaton: psi.1.as_ref().map(|automaton| summary(automaton, k)),
            },
            payoffs: TaskSet::non_empty(k)
                .map(|set| SetPayoff {
                    set: set.names(names),
                    payoff: payoffs.get(set),
                })
                .collect(),
            states: facts.states,
            engine: facts.engine,
            product_states: facts.product_states,
            product_edges: facts.product_edges,
            regions: TaskSet::non_empty(k)
                .zip(&facts.regions)
                .map(|(set, region)| RegionSummary {
                    set: set.names(names),
                    states: region.states,
                    robot_states: region.robot_states,
                    max_rank: region.max_rank,
                    realizable: region.initial_rank.is_some(),
                    initial_rank: region.initial_rank,
                })
                .collect(),
            believed_region: facts.believed_region,
            initial: InitialSummary {
                state: facts.initial.clone(),
                maximal: label.maximal.iter().map(|set| set.names(names)).collect(),
                psi: label.psi,
                guarantee: best.map_or(0.0, |set| payoffs.get(set)),
                settles_for: best.map(|set| set.names(names)),
            },
            classes: facts.classes,
            missing_propositions: facts.missing_propositions,
        }
    }
}

/// The reactive strategies of both players for every non-empty set of sub-tasks and for psi,
/// keyed by product state names.
///
/// In the paper's terms the three tasks are keyed by name and psi is `phi1`:
///
/// ```json
/// {"states": "full", "initial": "s|q1|q2",
///  "tasks": {"phi1": {"realizable": true,
///                     "robot": {"s|q1|q2": {"rank": 3, "actions": ["N"]}, ...},
///                     "adversary": {"s|q1|q2": ["W", "S"], ...}},
///            "phi2": {...}, "phi": {...}}}
/// ```
///
/// In general each set also has its payoff, the sub-tasks are listed, and psi has its own entry:
///
/// ```json
/// {"states": "full", "initial": "s|qA|qB",
///  "subtasks": ["A", "B"],
///  "tasks": {"A": {"payoff": 200, "realizable": true, "robot": {...}, "adversary": {...}},
///            "B": {...}, "A,B": {...}},
///  "believed": {"formula": "F C", "tasks": null,
///               "realizable": false, "robot": {...}, "adversary": {...}}}
/// ```
///
/// Sets are keyed by their names, in mask order (`A`, `B`, `A,B`, `C`, `A,C`, ...). When psi
/// is the conjunction of a set (`"tasks": ["A"]`), its strategies are that set's and `believed`
/// holds only `formula`, `tasks` and `realizable`.
///
/// The states and the allowed actions are read from the [`StrategySource`] while the export is
/// serialised (nothing of it is held but the entry being written and one region's ranks), so
/// serialising into a writer streams it.
pub struct StrategyExport<'a, G = ProductStrategies<'a>> {
    source: G,
    payoffs: &'a SubsetPayoffs,
    presentation: &'a Presentation,
    psi: &'a str,
}

impl<'a> StrategyExport<'a> {
    /// The export of the product `game` with its regions and payoffs, named as `presentation`
    /// names them, psi's formula `psi`. The allowed actions are computed while it is serialised.
    pub fn new(
        game: &'a Hypergame<'a>,
        regions: &'a TaskRegions,
        payoffs: &'a SubsetPayoffs,
        presentation: &'a Presentation,
        psi: &'a str,
    ) -> StrategyExport<'a> {
        let source = ProductStrategies::new(game, regions);
        StrategyExport::of(source, payoffs, presentation, psi)
    }
}

impl<'a, G: StrategySource> StrategyExport<'a, G> {
    /// The export of what `source` reads, with the sets' `payoffs`, named as `presentation`
    /// names them, psi's formula `psi`.
    pub fn of(
        source: G,
        payoffs: &'a SubsetPayoffs,
        presentation: &'a Presentation,
        psi: &'a str,
    ) -> StrategyExport<'a, G> {
        StrategyExport {
            source,
            payoffs,
            presentation,
            psi,
        }
    }
}

impl<G: StrategySource> Serialize for StrategyExport<'_, G> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let (game, p) = (&self.source, self.presentation);
        let by_task = p.layout().keys_by_task;
        let mut map = serializer.serialize_map(None)?;
        map.serialize_entry("states", &game.enumeration())?;
        map.serialize_entry("initial", &game.name(game.initial()))?;
        if !by_task {
            map.serialize_entry("subtasks", p.names())?;
        }
        map.serialize_entry(
            "tasks",
            &SetStrategies {
                export: self,
                with_payoffs: !by_task,
            },
        )?;
        if !by_task {
            let belief = game.belief();
            map.serialize_entry(
                "believed",
                &BelievedStrategies {
                    formula: self.psi,
                    tasks: match belief {
                        Belief::Tasks(set) => Some(set.names(p.names())),
                        Belief::Automaton => None,
                    },
                    realizable: game.wins(WinRegion::Believed, game.initial()),
                    strategies: (belief == Belief::Automaton)
                        .then(|| TaskStrategies::new(game, WinRegion::Believed)),
                },
            )?;
        }
        map.end()
    }
}

/// The sets' strategies, a map in mask order keyed by the sets' names.
struct SetStrategies<'e, 'a, G> {
    export: &'e StrategyExport<'a, G>,
    with_payoffs: bool,
}

#[derive(Serialize)]
#[serde(bound = "")]
struct SetEntry<'a, G: StrategySource> {
    #[serde(skip_serializing_if = "Option::is_none")]
    payoff: Option<f64>,
    #[serde(flatten)]
    strategies: TaskStrategies<'a, G>,
}

#[derive(Serialize)]
#[serde(bound = "")]
struct BelievedStrategies<'a, G: StrategySource> {
    formula: &'a str,
    tasks: Option<Vec<String>>,
    realizable: bool,
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    strategies: Option<TaskStrategies<'a, G>>,
}

impl<G: StrategySource> Serialize for SetStrategies<'_, '_, G> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let e = self.export;
        serializer.collect_map(TaskSet::non_empty(e.payoffs.num_tasks()).map(|set| {
            let entry = SetEntry {
                payoff: self.with_payoffs.then(|| e.payoffs.get(set)),
                strategies: TaskStrategies::new(&e.source, WinRegion::Set(set)),
            };
            (e.presentation.set_name(set), entry)
        }))
    }
}

/// Both players' reactive strategies for one winning region `win` (serialised as
/// `{realizable, robot, adversary}`): the robot's rank-decreasing strategy in `win` and the
/// adversary's maximally permissive one outside it, the rules of
/// [`crate::game::ReactiveStrategy`], read off the attractor as they are written, so nothing
/// but the attractor is kept.
#[derive(Serialize)]
#[serde(bound = "")]
struct TaskStrategies<'a, G: StrategySource> {
    realizable: bool,
    robot: RobotMoves<'a, G>,
    adversary: AdversaryMoves<'a, G>,
}

impl<'a, G: StrategySource> TaskStrategies<'a, G> {
    fn new(game: &'a G, win: WinRegion) -> TaskStrategies<'a, G> {
        TaskStrategies {
            realizable: game.wins(win, game.initial()),
            robot: RobotMoves { game, win },
            adversary: AdversaryMoves { game, win },
        }
    }
}

/// The robot's states of `Win`, each with its rank and the actions to a state of lower rank
/// (every action staying in `Win` at rank 0).
struct RobotMoves<'a, G> {
    game: &'a G,
    win: WinRegion,
}

/// The adversary's states outside `Win`, each with the actions that stay outside.
struct AdversaryMoves<'a, G> {
    game: &'a G,
    win: WinRegion,
}

#[derive(Serialize)]
struct RankedActions<'a> {
    rank: u32,
    actions: Vec<&'a str>,
}

/// The names of the actions of `h` whose successor passes `allows`.
fn allowed_actions<G: StrategySource>(game: &G, h: u32, allows: impl Fn(u32) -> bool) -> Vec<&str> {
    let mut actions = Vec::new();
    game.edges(h, &mut |action, target| {
        if allows(target) {
            actions.push(action);
        }
    });
    actions.into_iter().map(|a| game.action_name(a)).collect()
}

/// Serialises as a map the entries `entry` makes of the states of `owner` that `select` keeps,
/// in product order, keyed by their names.
fn serialize_states<S: Serializer, G: StrategySource, V: Serialize>(
    serializer: S,
    game: &G,
    owner: Owner,
    select: impl Fn(u32) -> bool,
    entry: impl Fn(u32) -> V,
) -> Result<S::Ok, S::Error> {
    let mut map = serializer.serialize_map(None)?;
    let mut failed = None;
    game.for_each_state(&mut |h| {
        if failed.is_none() && game.owner(h) == owner && select(h) {
            failed = map.serialize_entry(&game.name(h), &entry(h)).err();
        }
    });
    match failed {
        Some(error) => Err(error),
        None => map.end(),
    }
}

/// The error of a source that cannot have a region's ranks.
fn no_ranks<E: serde::ser::Error>() -> E {
    E::custom("the ranks of a winning region could not be had")
}

impl<G: StrategySource> Serialize for RobotMoves<'_, G> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let game = self.game;
        let rank = game.ranks(self.win).ok_or_else(no_ranks)?;
        serialize_states(
            serializer,
            game,
            Owner::Robot,
            |h| rank(h).is_some(),
            |h| RankedActions {
                rank: rank(h).expect("the robot's strategy lives in Win"),
                actions: allowed_actions(game, h, |t| allows_robot_edge(rank(h), rank(t))),
            },
        )
    }
}

impl<G: StrategySource> Serialize for AdversaryMoves<'_, G> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let (game, win) = (self.game, self.win);
        serialize_states(
            serializer,
            game,
            Owner::Adversary,
            |h| !game.wins(win, h),
            |h| allowed_actions(game, h, |t| !game.wins(win, t)),
        )
    }
}

//! The general form of the reports (`hypersynth --task A=… --task B=… --believed … ARENA`,
//! docs/semantics.md §8): the sub-tasks and the belief, payoffs on every set, the product and its
//! regions, the generalised win-label table, then (unless games only) the MDP stage: its value
//! at h0 with the controller's own evaluation (a mismatch is refused), and optionally a decision
//! table, a simulation and a trace.
//!
//! JSON: one object with the keys `arena`, `tasks`, `believed`, `payoffs`, `states`,
//! `product_states`, `product_edges`, `regions`, `believed_region`, `partition`, `initial`,
//! `missing_propositions`, and for the MDP stage `settings`, `mdp`, `solver`, `decision` and,
//! when asked for, `explain`, `simulation`, `trace`; with the stage timings asked for,
//! `timings` last. Sets of sub-tasks are lists of names; maps
//! keep the order of the masks, so the same inputs give byte-identical output.

use std::fmt;

use serde::Serialize;

use super::games::{
    ArenaSummary, AutomatonSummary, TaskAutomaton, TaskStrategies, write_arena, write_automaton,
    write_product,
};
use super::synthesis::{
    InitialDecision, Settings, SolverSummary, Synthesis, TraceRow, ending_name, write_details,
    write_model_and_solver, write_value,
};
use crate::arena::Owner;
use crate::game::{
    Belief, HState, Hypergame, States, SubsetLabelCounts, SubsetPayoffs, TaskRegions, TaskSet,
    label_text, subset_partition,
};
use crate::opportunistic::build::MdpSizes;
use crate::opportunistic::controller::Explanation;
use crate::opportunistic::simulate::{Ending, Simulation};
use crate::stage::Timings;

/// A sub-task: its name and automaton summary.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct SubtaskSummary {
    /// The sub-task's name (`A` in `--task A=…`), used for it in every set.
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
}

/// h0 in the games stage.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SubtaskInitial {
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

/// What the games stage of the general form found.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SubtaskGamesReport {
    /// The arena's size.
    pub arena: ArenaSummary,
    /// The sub-tasks in product order.
    pub tasks: Vec<SubtaskSummary>,
    /// The adversary's belief psi.
    pub believed: BeliefSummary,
    /// `r(T)` for every non-empty set T, in mask order.
    pub payoffs: Vec<SetPayoff>,
    /// Which product states were enumerated: `full` or `reachable`.
    pub states: States,
    /// Number of product states enumerated.
    pub product_states: usize,
    /// Number of product edges.
    pub product_edges: usize,
    /// `Win(T)` for every non-empty set T, in mask order.
    pub regions: Vec<RegionSummary>,
    /// Number of product states in `Win(psi)`.
    pub believed_region: usize,
    /// The number of robot, adversary and all states per generalised win-label.
    pub partition: Vec<SubsetLabelCounts>,
    /// h0's win-label and guarantee.
    pub initial: SubtaskInitial,
    /// Propositions the automata mention that no arena state carries (always false).
    pub missing_propositions: Vec<String>,
}

impl SubtaskGamesReport {
    /// `tasks` are the sub-tasks' automata in product order; `psi` is psi's formula with its
    /// own automaton when it has one (the product's last).
    pub fn new(
        tasks: &[(String, TaskAutomaton)],
        psi: (&str, Option<TaskAutomaton>),
        payoffs: &SubsetPayoffs,
        game: &Hypergame,
        regions: &TaskRegions,
    ) -> SubtaskGamesReport {
        let arena = game.arena();
        let names: Vec<String> = tasks.iter().map(|(name, _)| name.clone()).collect();
        let summary = |automaton: &TaskAutomaton, i: usize| AutomatonSummary {
            formula: automaton.formula.to_string(),
            states: automaton.dfa.num_states(),
            edges: automaton.dfa.num_edges(),
            translator: automaton.translator.to_string(),
            enumerated_states: game.automaton_states(i).len(),
        };
        let k = tasks.len();
        let h0 = game.initial();
        let robot = |h: HState| game.owner(h) == Owner::Robot;
        let label = regions.label(h0);
        SubtaskGamesReport {
            arena: ArenaSummary::new(arena),
            tasks: tasks
                .iter()
                .enumerate()
                .map(|(i, (name, automaton))| SubtaskSummary {
                    name: name.clone(),
                    automaton: summary(automaton, i),
                })
                .collect(),
            believed: BeliefSummary {
                formula: psi.0.to_string(),
                tasks: match regions.belief() {
                    Belief::Tasks(set) => Some(set.names(&names)),
                    Belief::Automaton => None,
                },
                automaton: psi.1.as_ref().map(|automaton| summary(automaton, k)),
            },
            payoffs: TaskSet::non_empty(k)
                .map(|set| SetPayoff {
                    set: set.names(&names),
                    payoff: payoffs.get(set),
                })
                .collect(),
            states: game.enumeration(),
            product_states: game.num_states(),
            product_edges: game.num_edges(),
            regions: TaskSet::non_empty(k)
                .map(|set| {
                    let win = regions.win(set);
                    RegionSummary {
                        set: set.names(&names),
                        states: win.len(),
                        robot_states: win
                            .region()
                            .iter()
                            .filter(|&h| robot(HState::new(h)))
                            .count(),
                        max_rank: win.max_rank(),
                        realizable: win.contains(h0),
                    }
                })
                .collect(),
            believed_region: regions.believed().len(),
            partition: subset_partition(game, regions, &names),
            initial: SubtaskInitial {
                state: game.name(h0),
                maximal: label.maximal.iter().map(|set| set.names(&names)).collect(),
                psi: label.psi,
                guarantee: regions.guarantee(payoffs, h0),
                settles_for: regions.best(payoffs, h0).map(|set| set.names(&names)),
            },
            missing_propositions: game.missing_propositions().to_vec(),
        }
    }
}

/// The reactive strategies of both players for every non-empty set of sub-tasks and for psi,
/// keyed by product state names: the paper's export ([`super::StrategyExport`]) with its tasks
/// keyed by sets.
///
/// ```json
/// {"states": "full", "initial": "s|qA|qB",
///  "subtasks": ["A", "B"],
///  "tasks": {"A": {"payoff": 200, "realizable": true,
///                  "robot": {"s|qA|qB": {"rank": 3, "actions": ["N"]}, ...},
///                  "adversary": {"s|qA|qB": ["W", "S"], ...}},
///            "B": {...}, "A,B": {...}},
///  "believed": {"formula": "F C", "tasks": null,
///               "realizable": false, "robot": {...}, "adversary": {...}}}
/// ```
///
/// Sets are keyed by their sub-tasks' names joined by `,`, in mask order (`A`, `B`, `A,B`, `C`,
/// `A,C`, ...). When psi is the conjunction of a set (`"tasks": ["A"]`), its strategies are that
/// set's and `believed` holds only `formula`, `tasks` and `realizable`.
#[derive(Serialize)]
pub struct SubtaskStrategyExport<'a> {
    states: States,
    initial: String,
    subtasks: &'a [String],
    tasks: SetStrategies<'a>,
    believed: BelievedStrategies<'a>,
}

/// The sets' strategies, a map in mask order.
struct SetStrategies<'a> {
    game: &'a Hypergame<'a>,
    regions: &'a TaskRegions,
    payoffs: &'a SubsetPayoffs,
    names: &'a [String],
}

#[derive(Serialize)]
struct SetEntry<'a> {
    payoff: f64,
    #[serde(flatten)]
    strategies: TaskStrategies<'a>,
}

#[derive(Serialize)]
struct BelievedStrategies<'a> {
    formula: &'a str,
    tasks: Option<Vec<String>>,
    realizable: bool,
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    strategies: Option<TaskStrategies<'a>>,
}

impl<'a> SubtaskStrategyExport<'a> {
    /// The export of the product `game` of the sub-tasks named `names` (and psi, written
    /// `psi`), with its regions and payoffs.
    pub fn new(
        game: &'a Hypergame<'a>,
        regions: &'a TaskRegions,
        payoffs: &'a SubsetPayoffs,
        names: &'a [String],
        psi: &'a str,
    ) -> SubtaskStrategyExport<'a> {
        let believed = regions.believed();
        SubtaskStrategyExport {
            states: game.enumeration(),
            initial: game.name(game.initial()),
            subtasks: names,
            tasks: SetStrategies {
                game,
                regions,
                payoffs,
                names,
            },
            believed: BelievedStrategies {
                formula: psi,
                tasks: match regions.belief() {
                    Belief::Tasks(set) => Some(set.names(names)),
                    Belief::Automaton => None,
                },
                realizable: believed.contains(game.initial()),
                strategies: (regions.belief() == Belief::Automaton)
                    .then(|| TaskStrategies::new(game, believed)),
            },
        }
    }
}

impl Serialize for SetStrategies<'_> {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_map(TaskSet::non_empty(self.payoffs.num_tasks()).map(|set| {
            let entry = SetEntry {
                payoff: self.payoffs.get(set),
                strategies: TaskStrategies::new(self.game, self.regions.win(set)),
            };
            (set.display(self.names).to_string(), entry)
        }))
    }
}

fn set_text(set: &[String]) -> String {
    format!("{{{}}}", set.join(","))
}

impl fmt::Display for SubtaskGamesReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write_arena(f, &self.arena)?;
        let automaton = write_automaton;
        for task in &self.tasks {
            automaton(f, &format!("task {}", task.name), &task.automaton)?;
        }
        match (&self.believed.tasks, &self.believed.automaton) {
            (Some(tasks), _) => writeln!(
                f,
                "believed psi   {}\n               the conjunction of {}: Win(psi) = Win({})",
                self.believed.formula,
                set_text(tasks),
                set_text(tasks)
            )?,
            (None, Some(dfa)) => automaton(f, "believed psi", dfa)?,
            (None, None) => writeln!(f, "believed psi   {}", self.believed.formula)?,
        }
        let payoffs: Vec<String> = self
            .payoffs
            .iter()
            .map(|p| format!("r{} = {}", set_text(&p.set), p.payoff))
            .collect();
        writeln!(f, "payoffs        {}", payoffs.join(", "))?;
        write_product(f, self.states, self.product_states, self.product_edges)?;
        let regions: Vec<String> = self
            .regions
            .iter()
            .map(|r| format!("|Win{}| = {}", set_text(&r.set), r.states))
            .collect();
        writeln!(f, "winning        {}", regions.join(", "))?;
        writeln!(f, "               |Win(psi)| = {}", self.believed_region)?;
        writeln!(f)?;
        let labels: Vec<String> = self
            .partition
            .iter()
            .map(|row| label_text(&row.maximal, row.psi))
            .collect();
        let label_width = labels
            .iter()
            .map(|l| l.chars().count())
            .chain(["maximal winnable sets".len()])
            .max()
            .unwrap_or(0);
        let width = self.product_states.to_string().len().max("adversary".len());
        writeln!(
            f,
            "{:<label_width$} {:>width$} {:>width$} {:>width$}",
            "maximal winnable sets", "robot", "adversary", "total"
        )?;
        for (row, label) in self.partition.iter().zip(&labels) {
            writeln!(
                f,
                "{label:<label_width$} {:>width$} {:>width$} {:>width$}",
                row.robot, row.adversary, row.total
            )?;
        }
        writeln!(f)?;
        let i = &self.initial;
        let settles = i
            .settles_for
            .as_ref()
            .map_or("nothing".to_string(), |set| set_text(set));
        writeln!(
            f,
            "initial state  {}  {}\n               guarantee {} (settles for {settles})",
            i.state,
            label_text(&i.maximal, i.psi),
            i.guarantee
        )?;
        if !self.missing_propositions.is_empty() {
            writeln!(
                f,
                "always false   {} (carried by no arena state)",
                self.missing_propositions.join(", ")
            )?;
        }
        Ok(())
    }
}

/// The MDP stage's part of the general form's text report, after the games report.
pub(super) fn write(f: &mut fmt::Formatter<'_>, s: &Synthesis) -> fmt::Result {
    let settings = &s.settings;
    writeln!(f)?;
    writeln!(
        f,
        "adversary      sigma_W uniform over the actions that keep it outside Win(psi); \
         sigma_L {} (seed {})",
        settings.sigma_l, settings.seed
    )?;
    writeln!(
        f,
        "settings       risk {}; discount {}",
        serde_json::to_value(settings.risk)
            .ok()
            .and_then(|v| v.as_str().map(str::to_string))
            .unwrap_or_default(),
        settings.discount
    )?;
    let m = &s.mdp;
    writeln!(
        f,
        "MDP            {} decision nodes (robot states): {} absorbing, {} with an opportunity, {} without ({} stuck); {} worth more than their guarantee",
        m.robot_states,
        m.absorbing,
        m.with_opportunity,
        m.without_opportunity,
        m.stuck,
        m.above_guarantee.unwrap_or_default()
    )?;
    write_model_and_solver(f, m, &s.solver, settings.epsilon)?;
    let d = &s.decision;
    let action = match (&d.action, &d.commits_to, d.adversary_first) {
        (Some(action), Some(set), _) => format!("{action}, committing to {}", set_text(set)),
        (Some(action), None, _) => action.clone(),
        (None, Some(set), _) => format!("none (absorbing: commits to {})", set_text(set)),
        (None, None, true) => "none (the adversary moves first)".to_string(),
        (None, None, false) => "none (nothing to gain)".to_string(),
    };
    write_value(f, d, &action)?;
    let outcomes: Vec<(String, u32)> = s
        .simulation
        .as_ref()
        .map_or(Vec::new(), |sim| outcome_counts(s, sim));
    let trace_outcome = s
        .trace
        .as_ref()
        .map_or(String::new(), |t| outcome(s, t.ending));
    write_details(f, s, &outcomes, &trace_outcome)
}

/// How the general form names a run's ending: `A,B satisfied`, `adversary stuck`...
fn outcome(s: &Synthesis, ending: Ending) -> String {
    match ending {
        Ending::Satisfied(set) => format!("{} satisfied", s.set_name(set)),
        other => ending_name(other).to_string(),
    }
}

/// The outcome counts: the sets some run satisfied, in mask order, then `adversary stuck`,
/// `none` and `step bound hit`.
fn outcome_counts(s: &Synthesis, sim: &Simulation) -> Vec<(String, u32)> {
    let satisfied = sim
        .satisfied
        .iter()
        .enumerate()
        .filter(|&(_, &count)| count > 0)
        .map(|(mask, &count)| (outcome(s, Ending::Satisfied(TaskSet(mask as u8))), count));
    let others = [
        (Ending::AdversaryStuck, sim.adversary_stuck),
        (Ending::None, sim.none),
        (Ending::StepBound, sim.step_bound),
    ]
    .map(|(ending, count)| (ending_name(ending).to_string(), count));
    satisfied.chain(others).collect()
}

/// The general form's JSON report: the games stage's keys at the top level, then those of the
/// MDP stage, then `timings` when given; in this order (struct order, not sorted).
#[derive(Serialize)]
pub(super) struct Json<'a> {
    #[serde(flatten)]
    games: &'a SubtaskGamesReport,
    #[serde(skip_serializing_if = "Option::is_none")]
    settings: Option<&'a Settings>,
    #[serde(skip_serializing_if = "Option::is_none")]
    mdp: Option<&'a MdpSizes>,
    #[serde(skip_serializing_if = "Option::is_none")]
    solver: Option<&'a SolverSummary>,
    #[serde(skip_serializing_if = "Option::is_none")]
    decision: Option<&'a InitialDecision>,
    #[serde(skip_serializing_if = "Option::is_none")]
    explain: Option<&'a Explanation>,
    #[serde(skip_serializing_if = "Option::is_none")]
    simulation: Option<SimulationJson>,
    #[serde(skip_serializing_if = "Option::is_none")]
    trace: Option<TraceJson<'a>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    timings: Option<&'a Timings>,
}

/// A simulation as the general form's JSON shows it.
#[derive(Serialize)]
struct SimulationJson {
    runs: u32,
    seed: u64,
    max_steps: u32,
    outcomes: Vec<OutcomeCount>,
    mean_payoff: f64,
    ci_low: f64,
    ci_high: f64,
}

/// How many runs ended one way.
#[derive(Serialize)]
struct OutcomeCount {
    outcome: String,
    count: u32,
}

/// A traced run as the general form's JSON shows it.
#[derive(Serialize)]
struct TraceJson<'a> {
    outcome: String,
    payoff: f64,
    steps: &'a [TraceRow],
}

impl<'a> Json<'a> {
    pub(super) fn new(
        games: &'a SubtaskGamesReport,
        s: Option<&'a Synthesis>,
        timings: Option<&'a Timings>,
    ) -> Json<'a> {
        Json {
            games,
            settings: s.map(|s| &s.settings),
            mdp: s.map(|s| &s.mdp),
            solver: s.map(|s| &s.solver),
            decision: s.map(|s| &s.decision),
            explain: s.and_then(|s| s.explanation.as_ref()),
            simulation: s.and_then(|s| {
                let sim = s.simulation.as_ref()?;
                Some(SimulationJson {
                    runs: sim.options.runs,
                    seed: sim.options.seed,
                    max_steps: sim.options.max_steps,
                    outcomes: outcome_counts(s, sim)
                        .into_iter()
                        .map(|(outcome, count)| OutcomeCount { outcome, count })
                        .collect(),
                    mean_payoff: sim.mean_payoff,
                    ci_low: sim.ci_low,
                    ci_high: sim.ci_high,
                })
            }),
            trace: s.and_then(|s| {
                let trace = s.trace.as_ref()?;
                Some(TraceJson {
                    outcome: outcome(s, trace.ending),
                    payoff: trace.payoff,
                    steps: &trace.steps,
                })
            }),
            timings,
        }
    }
}

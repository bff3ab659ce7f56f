//! The report of the general form (`hypersynth --task A=… --task B=… --believed … ARENA`,
//! DESIGN.md 3.8): the sub-tasks and the belief, payoffs on every set, the product and its
//! regions, the generalised win-label table, then (unless games only) the general MDP, its value
//! at h0 with the controller's own evaluation (a mismatch is refused), and optionally a decision
//! table.
//!
//! JSON: one object with the keys `arena`, `tasks`, `believed`, `payoffs`, `states`,
//! `product_states`, `product_edges`, `regions`, `believed_region`, `partition`, `initial`,
//! `missing_propositions`, and for the MDP stage `settings`, `mdp`, `solver`, `decision` and,
//! when asked for, `explain`, `simulation`, `trace`. Sets of sub-tasks are lists of names; maps
//! keep the order of the masks, so the same inputs give byte-identical output.

use std::fmt;

use serde::Serialize;

use super::games::{
    ArenaSummary, AutomatonSummary, TaskAutomaton, TaskStrategies, write_automaton, write_product,
};
use super::opportunistic::{
    SolverSummary, moves, write_explanation, write_mean, write_simulation, write_trace,
};
use crate::arena::Owner;
use crate::game::{
    Belief, HState, Hypergame, States, SubsetLabelCounts, SubsetPayoffs, TaskRegions, TaskSet,
    label_text, subset_partition,
};
use crate::opportunistic::controller::Explanation;
use crate::opportunistic::simulate::{GoalSimulationReport, TraceStep};
use crate::opportunistic::subtasks::{Risk, SubtaskSizes};

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

/// The inputs of the general form's MDP stage, echoed in the report.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SubtaskSettings {
    /// `uniform`, `random` or `file:PATH`.
    pub sigma_l: String,
    /// The seed of random weights (`random`) and of the simulations.
    pub seed: u64,
    /// Which arena actions a robot state that can settle keeps: `paper`, `strict` or `neutral`.
    pub risk: Risk,
    /// The discount factor `g` (0 < g ≤ 1).
    pub discount: f64,
    /// The solver's bound on `upper − lower` at every state.
    pub epsilon: f64,
}

/// The value of h0 and what the controller does there.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SubtaskDecisionSummary {
    /// Certified lower bound of the value of h0.
    pub value: f64,
    /// Certified upper bound of the value of h0.
    pub value_upper: f64,
    /// The first action (`stop` included); `null` when h0 is absorbing, worthless or the
    /// adversary's.
    pub action: Option<String>,
    /// The set the controller commits to at h0 (absorbing or `stop`), if it does there.
    pub commits_to: Option<Vec<String>>,
    /// Whether the adversary moves first (the value is then the expectation over its move).
    pub adversary_first: bool,
    /// The controller's expected number of robot moves before it commits (infinite if it may
    /// never).
    pub expected_moves: f64,
    /// Lower bound of the controller's own expected payoff, evaluated as a Markov chain.
    pub policy_value: f64,
    /// Upper bound of the controller's own expected payoff.
    pub policy_value_upper: f64,
}

/// The whole report of the general form: the games stage's keys at the top level, then those of the
/// MDP stage.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SubtaskReport {
    /// The games stage, flattened into the report's object.
    #[serde(flatten)]
    pub games: SubtaskGamesReport,
    /// The MDP stage's inputs (`settings`).
    pub settings: SubtaskSettings,
    /// The general MDP's sizes (`mdp`).
    pub mdp: SubtaskSizes,
    /// What value iteration did (`solver`).
    pub solver: SolverSummary,
    /// The value of h0 and the controller's first decision (`decision`).
    pub decision: SubtaskDecisionSummary,
    /// The decision table at the requested states (`explain`), when asked for.
    #[serde(rename = "explain", skip_serializing_if = "Option::is_none")]
    pub explanation: Option<Explanation>,
    /// Outcome counts per satisfied set and the mean payoff (`simulation`), when asked for.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub simulation: Option<GoalSimulationReport>,
    /// One traced run (`trace`), when asked for.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub trace: Option<GoalTrace>,
}

/// A traced run of the general controller.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GoalTrace {
    /// How the run ended: `A,B satisfied`, `adversary stuck`, `none` or `step bound hit`.
    pub outcome: String,
    /// The payoff the run collected: the committed set's `r(T)` times `g^k` after k robot moves.
    pub payoff: f64,
    /// The run's steps from h0, one per move.
    pub steps: Vec<TraceStep>,
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
        let a = &self.arena;
        writeln!(
            f,
            "arena          {} states ({} robot, {} adversary), {} transitions",
            a.states, a.robot_states, a.adversary_states, a.transitions
        )?;
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

impl fmt::Display for SubtaskReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.games)?;
        let s = &self.settings;
        writeln!(f)?;
        writeln!(
            f,
            "adversary      sigma_W uniform over the actions that keep it outside Win(psi); \
             sigma_L {} (seed {})",
            s.sigma_l, s.seed
        )?;
        writeln!(
            f,
            "settings       risk {}; discount {}",
            serde_json::to_value(s.risk)
                .ok()
                .and_then(|v| v.as_str().map(str::to_string))
                .unwrap_or_default(),
            s.discount
        )?;
        let m = &self.mdp;
        writeln!(
            f,
            "MDP            {} decision nodes (robot states): {} absorbing, {} with an opportunity, {} without ({} stuck); {} worth more than their guarantee",
            m.robot_states,
            m.absorbing,
            m.with_opportunity,
            m.without_opportunity,
            m.stuck,
            m.above_guarantee
        )?;
        super::opportunistic::write_model_and_solver(
            f,
            [m.chance_nodes, m.states, m.choices, m.transitions],
            &self.solver,
            s.epsilon,
        )?;
        let d = &self.decision;
        let action = match (&d.action, &d.commits_to, d.adversary_first) {
            (Some(action), Some(set), _) => format!("{action}, committing to {}", set_text(set)),
            (Some(action), None, _) => action.clone(),
            (None, Some(set), _) => format!("none (absorbing: commits to {})", set_text(set)),
            (None, None, true) => "none (the adversary moves first)".to_string(),
            (None, None, false) => "none (nothing to gain)".to_string(),
        };
        writeln!(
            f,
            "value of h0    {:.6} (upper bound {:.6}), expected {} robot moves; action {action}",
            d.value,
            d.value_upper,
            moves(d.expected_moves)
        )?;
        writeln!(
            f,
            "controller     collects {:.6} (upper bound {:.6}), evaluated as a Markov chain",
            d.policy_value, d.policy_value_upper
        )?;
        if let Some(table) = &self.explanation {
            write_explanation(f, table)?;
        }
        if let Some(sim) = &self.simulation {
            let outcomes = sim.outcomes.iter().map(|o| (o.outcome.clone(), o.count));
            write_simulation(f, sim.runs, sim.seed, sim.max_steps, outcomes)?;
            write_mean(f, sim.mean_payoff, sim.ci_low, sim.ci_high, d.value)?;
        }
        if let Some(trace) = &self.trace {
            write_trace(f, &trace.steps)?;
            writeln!(f, "  outcome {}, payoff {}", trace.outcome, trace.payoff)?;
        }
        Ok(())
    }
}

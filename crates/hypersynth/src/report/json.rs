//! The JSON report: one serialiser for both vocabularies, reading the report's data and its
//! [`Layout`]. **Key order:** every object's keys come in the order this file writes them (the
//! order of the text report), never sorted, so the same inputs give byte-identical output.
//!
//! With per-task keys (the paper's terms), the games are `arena`, `phi`, `automata` (by task),
//! `states`, `engine`, `product_states`, `product_edges`, `winning_region_sizes`, `max_ranks` (by task),
//! `partition` (by win-label code), `initial` (h0's state, win-label code and ranks, then the MDP
//! stage's `value`, `value_upper`, `action`, `adversary_first`, `expected_moves`,
//! `policy_value`, `policy_value_upper`), `realizable` (by task) and `missing_propositions`.
//! Otherwise they are `arena`, `tasks`, `believed`, `payoffs`, `states`, `engine`,
//! `product_states`, `product_edges`, `regions`, `believed_region`, `partition` (a list of labels), `initial` and
//! `missing_propositions`, and the MDP stage's decision at h0 is `decision`. The MDP stage
//! adds `settings`, `mdp`, `solver`, (`decision`,) then `robust`, `explain`, `simulation` and
//! `trace` when present, and `timings` comes last when asked for.

use serde::Serialize;
use serde::ser::{SerializeMap, Serializer};

use super::games::Games;
use super::synthesis::{InitialDecision, Settings, Synthesis, TraceRow};
use crate::game::{TaskSet, WinLabel};
use crate::opportunistic::presentation::{Layout, Presentation};
use crate::opportunistic::simulate::Simulation;
use crate::stage::Timings;

/// A report's parts with its timings, serialised as the module documentation says.
pub(super) struct Json<'a> {
    pub(super) presentation: &'a Presentation,
    pub(super) games: &'a Games,
    pub(super) synthesis: Option<&'a Synthesis>,
    pub(super) timings: Option<&'a Timings>,
}

impl Serialize for Json<'_> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let (p, g) = (self.presentation, self.games);
        let layout = p.layout();
        let s = self.synthesis;
        let k = g.tasks.len();
        let sets = || TaskSet::non_empty(k);
        let by_task = |value: &dyn Fn(TaskSet) -> serde_json::Value| ByName {
            entries: sets().map(|set| (p.set_name(set), value(set))).collect(),
        };
        let mut map = serializer.serialize_map(None)?;
        map.serialize_entry("arena", &g.arena)?;
        if layout.keys_by_task {
            map.serialize_entry("phi", p.whole_task().unwrap_or_default())?;
            let automata = ByName {
                entries: g
                    .tasks
                    .iter()
                    .map(|task| (task.name.clone(), &task.automaton))
                    .collect(),
            };
            map.serialize_entry("automata", &automata)?;
        } else {
            map.serialize_entry("tasks", &g.tasks)?;
            map.serialize_entry("believed", &g.believed)?;
            map.serialize_entry("payoffs", &g.payoffs)?;
        }
        map.serialize_entry("states", &g.states)?;
        map.serialize_entry("engine", &g.engine)?;
        map.serialize_entry("product_states", &g.product_states)?;
        map.serialize_entry("product_edges", &g.product_edges)?;
        let region = |set: TaskSet| &g.regions[set.0 as usize - 1];
        if layout.keys_by_task {
            let sizes = by_task(&|set| region(set).states.into());
            map.serialize_entry("winning_region_sizes", &sizes)?;
            let ranks = by_task(&|set| region(set).max_rank.into());
            map.serialize_entry("max_ranks", &ranks)?;
            map.serialize_entry("partition", &crate::game::Partition::of(&g.classes))?;
            let initial = PaperInitial {
                state: &g.initial.state,
                label: WinLabel::new(
                    region(TaskSet(0b01)).realizable,
                    region(TaskSet(0b10)).realizable,
                    region(TaskSet(0b11)).realizable,
                ),
                ranks: by_task(&|set| region(set).initial_rank.into()),
                decision: s.map(|s| PaperDecision(&s.decision)),
            };
            map.serialize_entry("initial", &initial)?;
            let realizable = by_task(&|set| region(set).realizable.into());
            map.serialize_entry("realizable", &realizable)?;
        } else {
            map.serialize_entry("regions", &g.regions)?;
            map.serialize_entry("believed_region", &g.believed_region)?;
            let partition: Vec<PartitionJson> = p
                .partition(&g.classes)
                .into_iter()
                .map(|row| PartitionJson {
                    maximal: row.maximal,
                    psi: row.psi,
                    robot: row.counts.robot,
                    adversary: row.counts.adversary,
                    total: row.counts.total,
                })
                .collect();
            map.serialize_entry("partition", &partition)?;
            map.serialize_entry("initial", &g.initial)?;
        }
        map.serialize_entry("missing_propositions", &g.missing_propositions)?;
        if let Some(s) = s {
            synthesis_entries(&mut map, p, g, s)?;
        }
        if let Some(timings) = self.timings {
            map.serialize_entry("timings", timings)?;
        }
        map.end()
    }
}

/// The MDP stage's keys.
fn synthesis_entries<M: SerializeMap>(
    map: &mut M,
    p: &Presentation,
    g: &Games,
    s: &Synthesis,
) -> Result<(), M::Error> {
    let layout: &Layout = p.layout();
    map.serialize_entry(
        "settings",
        &SettingsJson {
            settings: &s.settings,
            payoffs: (!layout.states_guarantees).then(|| ByName {
                entries: TaskSet::non_empty(g.tasks.len())
                    .zip(&g.payoffs)
                    .map(|(set, payoff)| (p.payoff_name(set), payoff.payoff))
                    .collect(),
            }),
            risk: layout.states_guarantees,
        },
    )?;
    map.serialize_entry("mdp", &s.mdp)?;
    map.serialize_entry("solver", &s.solver)?;
    if !layout.keys_by_task {
        map.serialize_entry("decision", &s.decision)?;
    }
    if let Some(robust) = &s.robust {
        map.serialize_entry("robust", robust)?;
    }
    if let Some(explanation) = &s.explanation {
        map.serialize_entry("explain", explanation)?;
    }
    if let Some(simulation) = &s.simulation {
        map.serialize_entry(
            "simulation",
            &SimulationJson {
                simulation,
                presentation: p,
            },
        )?;
    }
    if let Some(trace) = &s.trace {
        map.serialize_entry(
            "trace",
            &TraceJson {
                outcome: p.ending_key(trace.ending),
                payoff: trace.payoff,
                steps: &trace.steps,
            },
        )?;
    }
    Ok(())
}

/// A map from names to values, in the order given.
struct ByName<T> {
    entries: Vec<(String, T)>,
}

impl<T: Serialize> Serialize for ByName<T> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_map(self.entries.iter().map(|(name, value)| (name, value)))
    }
}

/// h0 in the paper's terms: the games' state, win-label and ranks, then the MDP stage's value
/// and decision.
#[derive(Serialize)]
struct PaperInitial<'a> {
    state: &'a str,
    label: WinLabel,
    ranks: ByName<serde_json::Value>,
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    decision: Option<PaperDecision<'a>>,
}

/// The decision at h0 without the set committed to (the paper's reports name none).
struct PaperDecision<'a>(&'a InitialDecision);

impl Serialize for PaperDecision<'_> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let d = self.0;
        let mut map = serializer.serialize_map(None)?;
        map.serialize_entry("value", &d.value)?;
        map.serialize_entry("value_upper", &d.value_upper)?;
        map.serialize_entry("action", &d.action)?;
        map.serialize_entry("adversary_first", &d.adversary_first)?;
        map.serialize_entry("expected_moves", &d.expected_moves)?;
        map.serialize_entry("policy_value", &d.policy_value)?;
        map.serialize_entry("policy_value_upper", &d.policy_value_upper)?;
        map.end()
    }
}

/// One label of the general partition.
#[derive(Serialize)]
struct PartitionJson {
    maximal: Vec<Vec<String>>,
    psi: bool,
    robot: usize,
    adversary: usize,
    total: usize,
}

/// The settings: the paper's payoffs by name, or the risk rule.
struct SettingsJson<'a> {
    settings: &'a Settings,
    payoffs: Option<ByName<f64>>,
    risk: bool,
}

impl Serialize for SettingsJson<'_> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let s = self.settings;
        let mut map = serializer.serialize_map(None)?;
        map.serialize_entry("sigma_l", &s.sigma_l)?;
        map.serialize_entry("seed", &s.seed)?;
        if let Some(payoffs) = &self.payoffs {
            map.serialize_entry("payoffs", payoffs)?;
        }
        if self.risk {
            map.serialize_entry("risk", &s.risk)?;
        }
        map.serialize_entry("discount", &s.discount)?;
        map.serialize_entry("epsilon", &s.epsilon)?;
        map.end()
    }
}

/// A simulation: its options, the counts per ending (keyed by the paper's names, or a list of
/// `{outcome, count}`), the mean payoff and its interval.
struct SimulationJson<'a> {
    simulation: &'a Simulation,
    presentation: &'a Presentation,
}

#[derive(Serialize)]
struct OutcomeCount {
    outcome: String,
    count: u32,
}

impl Serialize for SimulationJson<'_> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let (sim, p) = (self.simulation, self.presentation);
        let endings = sim.endings(p);
        let mut map = serializer.serialize_map(None)?;
        map.serialize_entry("runs", &sim.options.runs)?;
        map.serialize_entry("seed", &sim.options.seed)?;
        map.serialize_entry("max_steps", &sim.options.max_steps)?;
        if p.layout().keys_by_task {
            let outcomes = ByName {
                entries: endings
                    .into_iter()
                    .map(|(ending, count)| (p.ending_key(ending), count))
                    .collect(),
            };
            map.serialize_entry("outcomes", &outcomes)?;
        } else {
            let outcomes: Vec<OutcomeCount> = endings
                .into_iter()
                .map(|(ending, count)| OutcomeCount {
                    outcome: p.ending(ending),
                    count,
                })
                .collect();
            map.serialize_entry("outcomes", &outcomes)?;
        }
        map.serialize_entry("mean_payoff", &sim.mean_payoff)?;
        map.serialize_entry("ci_low", &sim.ci_low)?;
        map.serialize_entry("ci_high", &sim.ci_high)?;
        map.end()
    }
}

/// A traced run: how it ended, what it collected, its steps.
#[derive(Serialize)]
struct TraceJson<'a> {
    outcome: String,
    payoff: f64,
    steps: &'a [TraceRow],
}

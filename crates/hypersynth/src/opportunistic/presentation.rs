//! How a problem names what it computes, and the two rules the paper fixes beyond the values
//! (docs/semantics.md §6, §8).
//!
//! A problem is one general problem (k named sub-tasks, payoffs on their sets, a believed task,
//! a risk rule); when its tasks are the paper's preset (two sub-tasks, one of them believed, the
//! paper's risk rule, payoffs with `r >= r1 + r2`), `pipeline::Tasks` recognises it once and
//! presents it in the paper's terms. Everything downstream reads this [`Presentation`]: the MDP
//! build (which robot states commit, the stop sinks and their names), the controller's labels,
//! the executor's answers, the reports, the pictures and the explorer. This file is the only one
//! that knows both vocabularies; nothing else asks which form a problem has.
//!
//! ```
//! use hypersynth::game::TaskSet;
//! use hypersynth::opportunistic::presentation::Presentation;
//!
//! let paper = Presentation::paper("F a & F b");
//! assert_eq!(paper.set_name(TaskSet(0b11)), "phi");
//! assert_eq!(paper.region_name(TaskSet(0b01)), "(phi1)");
//! let general = Presentation::general(vec!["A".into(), "B".into()]);
//! assert_eq!(general.set_name(TaskSet(0b11)), "A,B");
//! assert_eq!(general.region_name(TaskSet(0b01)), "{A}");
//! ```

use crate::game::Wins;
use serde::{Deserialize, Serialize};

use super::ending::Ending;
use crate::game::{
    HState, LabelClass, LabelCounts, Partition, SubsetPayoffs, TaskRegions, TaskSet, WinLabel,
    label_rows,
};

/// The vocabulary a problem is presented in: the paper's (two sub-tasks `phi1`, `phi2`, the
/// adversary believing `psi = phi1`, win-labels `(W, L, L)`) or the general one (named
/// sub-tasks, sets `A,B`, labels by maximal winnable sets). Controller files record it by name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Form {
    /// The paper's terms.
    Paper,
    /// Named sub-tasks.
    General,
}

impl Form {
    /// `paper` or `general`, as controller files and the Python package name it.
    pub fn name(self) -> &'static str {
        match self {
            Form::Paper => "paper",
            Form::General => "general",
        }
    }

    /// How many sub-tasks a problem of this form has, when the form fixes it (the paper's:
    /// two).
    pub fn fixed_tasks(self) -> Option<usize> {
        match self {
            Form::Paper => Some(2),
            Form::General => None,
        }
    }
}

/// Which robot states the hypergame MDP absorbs without a move, and where `stop` leads: the
/// general rule (§8.5) or the paper's (§6.3). Both give every state the same value; the paper's
/// keeps the MDP the paper describes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Commitment {
    /// A robot state commits where no robot state of a larger guarantee can be reached; `stop`
    /// leads to the sink of the set it settles for, one sink per non-empty set in mask order.
    NothingBetter,
    /// A robot state commits in `Win(all)` and outside `Win(psi)` with a positive guarantee;
    /// `stop` leads to `stop(phi1)` (r1) from states that win `phi2` on its own nowhere, to
    /// `stop(best)` (max(r1, r2)) from those that win it too.
    Labels,
}

/// A stop sink of the MDP: its name in reports and decision tables, and its payoff.
#[derive(Clone, Debug, PartialEq)]
pub struct Sink {
    /// `stop(phi1)`, `stop(best)`, `stop(A,B)`.
    pub name: String,
    /// What it pays.
    pub payoff: f64,
}

/// What a vocabulary's reports show, and where: the data the text and JSON reports read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    /// JSON keys per-task figures by task name (`"realizable": {"phi1": true, …}`) and runs'
    /// outcomes by the paper's keys (`phi1_only`); otherwise it lists sets (`"regions": [{"set":
    /// ["A"], …}]`) and outcomes by their text.
    pub keys_by_task: bool,
    /// The belief has its own lines (with `|Win(psi)|`), the payoffs are listed with the games,
    /// and the propositions no arena state carries are listed; otherwise the belief is `phi1`
    /// (the task's title says so) and the payoffs are given with the MDP's settings.
    pub states_belief: bool,
    /// Reports state guarantees: the risk rule, the robot states worth more than their
    /// guarantee, the set the controller commits to at h0 (and that nothing can be gained where
    /// it gives up); otherwise they name the policy's first action wherever the robot moves.
    pub states_guarantees: bool,
    /// States are labelled by the paper's win-labels `(W, L, L)` (and h0's realizability is
    /// listed per task); otherwise by their maximal winnable sets and belief, and h0 by its
    /// guarantee.
    pub win_labels: bool,
    /// The heading of the partition table's label column, and its least width.
    pub partition_heading: (&'static str, usize),
    /// What sigma_W plays, in reports' words.
    pub sigma_w: &'static str,
}

/// The paper's reports.
const PAPER_LAYOUT: Layout = Layout {
    keys_by_task: true,
    states_belief: false,
    states_guarantees: false,
    win_labels: true,
    partition_heading: ("win-label", 10),
    sigma_w: "uniform over safe actions",
};

/// The general form's reports.
const GENERAL_LAYOUT: Layout = Layout {
    keys_by_task: false,
    states_belief: true,
    states_guarantees: true,
    win_labels: false,
    partition_heading: ("maximal winnable sets", 0),
    sigma_w: "uniform over the actions that keep it outside Win(psi)",
};

/// One row of the partition table: the states of one label.
#[derive(Clone, Debug, PartialEq)]
pub struct PartitionRow {
    /// The label as the text report writes it: `(W, L, L)`, `{A} {B} | psi W`.
    pub text: String,
    /// The paper's code of the label (`WLL`; empty in general).
    pub code: &'static str,
    /// The inclusion-maximal winnable sets, each by its sub-tasks' names.
    pub maximal: Vec<Vec<String>>,
    /// Whether the states are in `Win(psi)`.
    pub psi: bool,
    /// How many robot, adversary and all states have the label.
    pub counts: LabelCounts,
    /// Whether the label can occur (the paper lists its impossible win-labels too: a non-zero
    /// count there is a bug).
    pub possible: bool,
}

/// How a problem is named (see the module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct Presentation {
    form: Form,
    /// The sub-tasks' names in product order (`phi1`, `phi2` in the paper's terms).
    names: Vec<String>,
    /// The robot's whole task as the paper's reports name it (empty in general).
    phi: String,
}

/// The paper's names of its two sub-tasks.
const PAPER_NAMES: [&str; 2] = ["phi1", "phi2"];

/// The paper's tasks in the order of its win-label triple, with their sets.
const PAPER_TASKS: [(&str, TaskSet); 3] = [
    ("phi1", TaskSet(0b01)),
    ("phi2", TaskSet(0b10)),
    ("phi", TaskSet(0b11)),
];

impl Presentation {
    /// The paper's terms, the robot's whole task named `phi`.
    pub fn paper(phi: impl Into<String>) -> Presentation {
        Presentation {
            form: Form::Paper,
            names: PAPER_NAMES.map(str::to_string).to_vec(),
            phi: phi.into(),
        }
    }

    /// Named sub-tasks, in product order.
    pub fn general(names: Vec<String>) -> Presentation {
        Presentation {
            form: Form::General,
            names,
            phi: String::new(),
        }
    }

    /// The presentation a controller file records: its form and its sub-tasks' names (the
    /// paper's are always `phi1`, `phi2`).
    pub fn of_form(form: Form, names: Vec<String>) -> Presentation {
        match form {
            Form::Paper => Presentation::paper(""),
            Form::General => Presentation::general(names),
        }
    }

    /// The vocabulary, as controller files record it.
    pub fn form(&self) -> Form {
        self.form
    }

    /// Whether the problem is presented in the paper's terms.
    fn is_paper(&self) -> bool {
        self.form == Form::Paper
    }

    /// The sub-tasks' names in product order.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The robot's whole task `phi`, when it is named on its own (the paper's terms).
    pub fn whole_task(&self) -> Option<&str> {
        self.is_paper().then_some(self.phi.as_str())
    }

    /// How a set of sub-tasks is named: `phi1`, `phi2`, `phi` in the paper's terms, `A,B` in
    /// general.
    pub fn set_name(&self, set: TaskSet) -> String {
        match self.paper_task(set) {
            Some(name) => name.to_string(),
            None => set.display(&self.names).to_string(),
        }
    }

    /// Every set's name, indexed by its mask (the empty set's is empty).
    pub fn set_names(&self) -> Vec<String> {
        (0..1usize << self.names.len())
            .map(|mask| match mask {
                0 => String::new(),
                mask => self.set_name(TaskSet(mask as u8)),
            })
            .collect()
    }

    /// The paper's name of a set, in its terms.
    fn paper_task(&self, set: TaskSet) -> Option<&'static str> {
        PAPER_TASKS
            .iter()
            .find(|&&(_, s)| self.is_paper() && s == set)
            .map(|&(name, _)| name)
    }

    /// The winning region of a set as reports write it: `(phi1)` in the paper's terms, `{A,B}`
    /// in general (so `|Win(phi1)|`, `|Win{A,B}|`).
    pub fn region_name(&self, set: TaskSet) -> String {
        match self.paper_task(set) {
            Some(name) => format!("({name})"),
            None => format!("{{{}}}", set.display(&self.names)),
        }
    }

    /// How reports name the payoff of a set: `r1`, `r2`, `r` in the paper's terms, `r{A,B}` in
    /// general.
    pub fn payoff_name(&self, set: TaskSet) -> String {
        match set.0 {
            0b01 | 0b10 if self.is_paper() => format!("r{}", set.0.trailing_zeros() + 1),
            _ if self.is_paper() => "r".to_string(),
            _ => format!("r{{{}}}", set.display(&self.names)),
        }
    }

    /// How reports title sub-task `i`: `phi1 = psi`, `phi2` in the paper's terms (its belief is
    /// `phi1`), `task A` in general.
    pub fn task_title(&self, i: usize) -> String {
        match (self.is_paper(), i) {
            (true, 0) => "phi1 = psi".to_string(),
            (true, _) => self.names[i].clone(),
            (false, _) => format!("task {}", self.names[i]),
        }
    }

    /// Whether reports state the belief on its own line (in the paper's terms it is `phi1`, as
    /// the task's title says) and the size of `Win(psi)`.
    pub fn states_belief(&self) -> bool {
        !self.is_paper()
    }

    /// The paper's win-label of a state, when the problem is in its terms.
    pub fn win_label(&self, regions: &TaskRegions, h: HState) -> Option<WinLabel> {
        self.is_paper().then(|| regions.win_label(h))
    }

    /// How a product state is labelled in decision tables and traces: its win-label `(W, L, L)`
    /// in the paper's terms, its maximal winnable sets, belief and guarantee (`{A} {B} | psi W
    /// gr 200`) in general.
    pub fn state_label(
        &self,
        regions: &(impl Wins + ?Sized),
        payoffs: &SubsetPayoffs,
        h: HState,
    ) -> String {
        match self.is_paper() {
            true => Wins::win_label(regions, h).to_string(),
            false => format!(
                "{} gr {}",
                Wins::label(regions, h).display(&self.names),
                Wins::guarantee(regions, payoffs, h)
            ),
        }
    }

    /// The label of a state in the games report (without its guarantee).
    pub fn games_label(&self, regions: &TaskRegions, h: HState) -> String {
        match self.win_label(regions, h) {
            Some(label) => label.to_string(),
            None => regions.label(h).display(&self.names),
        }
    }

    /// The commitment rule of the hypergame MDP.
    pub fn commitment(&self) -> Commitment {
        match self.form {
            Form::Paper => Commitment::Labels,
            Form::General => Commitment::NothingBetter,
        }
    }

    /// The MDP's stop sinks, in order (see [`Commitment`]).
    pub fn sinks(&self, payoffs: &SubsetPayoffs) -> Vec<Sink> {
        match self.commitment() {
            Commitment::Labels => {
                let [r1, r2] = [0b01, 0b10].map(|mask| payoffs.get(TaskSet(mask)));
                vec![
                    Sink {
                        name: "stop(phi1)".to_string(),
                        payoff: r1,
                    },
                    Sink {
                        name: "stop(best)".to_string(),
                        payoff: r1.max(r2),
                    },
                ]
            }
            Commitment::NothingBetter => TaskSet::non_empty(payoffs.num_tasks())
                .map(|set| Sink {
                    name: format!("stop({})", self.set_name(set)),
                    payoff: payoffs.get(set),
                })
                .collect(),
        }
    }

    /// The sink (an index into [`Presentation::sinks`]) that `stop` leads to from a robot state
    /// that settles for `best` and wins the sets `wins` says.
    pub fn stop_sink(&self, wins: impl Fn(TaskSet) -> bool, best: TaskSet) -> usize {
        match self.commitment() {
            Commitment::Labels => usize::from(wins(TaskSet(0b10))),
            Commitment::NothingBetter => best.0 as usize - 1,
        }
    }

    /// What the reports show, and where.
    pub fn layout(&self) -> &'static Layout {
        match self.form {
            Form::Paper => &PAPER_LAYOUT,
            Form::General => &GENERAL_LAYOUT,
        }
    }

    /// The partition table's rows: the paper's eight win-labels in the order of
    /// [`WinLabel::ALL`] (its three impossible ones last), or in general the labels that occur,
    /// sorted by their maximal sets, then psi.
    pub fn partition(&self, classes: &[LabelClass]) -> Vec<PartitionRow> {
        if !self.is_paper() {
            return label_rows(classes, &self.names)
                .into_iter()
                .map(|row| PartitionRow {
                    text: crate::game::label_text(&row.maximal, row.psi),
                    code: "",
                    maximal: row.maximal,
                    psi: row.psi,
                    counts: row.counts,
                    possible: true,
                })
                .collect();
        }
        Partition::of(classes)
            .iter()
            .map(|(label, counts)| PartitionRow {
                text: label.to_string(),
                code: label.code(),
                maximal: Vec::new(),
                psi: label.phi1,
                counts,
                possible: label.is_possible(),
            })
            .collect()
    }

    /// How a run's ending is named: the paper's `phi satisfied`, `phi1 only`, `phi2 only`, or
    /// `A,B satisfied`; `adversary stuck`, `none`, `step bound hit` in both.
    pub fn ending(&self, ending: Ending) -> String {
        match ending {
            Ending::Satisfied(set) => match (self.is_paper(), set.0) {
                (true, 0b01) => "phi1 only".to_string(),
                (true, 0b10) => "phi2 only".to_string(),
                (true, _) => "phi satisfied".to_string(),
                (false, _) => format!("{} satisfied", self.set_name(set)),
            },
            Ending::AdversaryStuck => "adversary stuck".to_string(),
            Ending::None => "none".to_string(),
            Ending::StepBound => "step bound hit".to_string(),
        }
    }

    /// How the JSON of the paper's reports keys a run's ending: `phi`, `phi1_only`,
    /// `phi2_only`, `adversary_stuck`, `none`, `step_bound`; in general its text.
    pub fn ending_key(&self, ending: Ending) -> String {
        if !self.is_paper() {
            return self.ending(ending);
        }
        match ending {
            Ending::Satisfied(set) => match set.0 {
                0b01 => "phi1_only",
                0b10 => "phi2_only",
                _ => "phi",
            },
            Ending::AdversaryStuck => "adversary_stuck",
            Ending::None => "none",
            Ending::StepBound => "step_bound",
        }
        .to_string()
    }

    /// The sets whose runs a simulation's table lists, given how many runs satisfied each set
    /// (by mask): the paper's `phi`, `phi1`, `phi2` always, in that order; in general the sets
    /// some run satisfied, in mask order.
    pub fn outcome_sets(&self, satisfied: &[u32]) -> Vec<TaskSet> {
        if self.is_paper() {
            return [0b11, 0b01, 0b10].map(TaskSet).to_vec();
        }
        (1..satisfied.len())
            .filter(|&mask| satisfied[mask] > 0)
            .map(|mask| TaskSet(mask as u8))
            .collect()
    }

    /// The automata of the product as errors and titles name them: the sub-tasks', then `psi`
    /// when it has its own automaton (`with_psi`).
    pub fn automata(&self, with_psi: bool) -> Vec<String> {
        let mut automata = self.names.clone();
        if with_psi {
            automata.push("psi".to_string());
        }
        automata
    }

    /// How titles name the states of the product's automata: `q1`, `q2` in the paper's terms,
    /// `q_A`, `q_psi` in general.
    pub fn automaton_states(&self, with_psi: bool) -> Vec<String> {
        if self.is_paper() {
            return vec!["q1".to_string(), "q2".to_string()];
        }
        self.automata(with_psi)
            .iter()
            .map(|name| format!("q_{name}"))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn general(k: usize) -> Presentation {
        Presentation::general(["A", "B", "C"][..k].iter().map(|s| s.to_string()).collect())
    }

    #[test]
    fn sets_are_named_in_each_vocabulary() {
        let paper = Presentation::paper("phi");
        assert_eq!(paper.set_names(), ["", "phi1", "phi2", "phi"]);
        assert_eq!(general(2).set_names(), ["", "A", "B", "A,B"]);
        assert_eq!(general(3).set_name(TaskSet(0b101)), "A,C");
        assert_eq!(paper.task_title(0), "phi1 = psi");
        assert_eq!(general(2).task_title(1), "task B");
        assert_eq!(
            Presentation::of_form(Form::Paper, vec!["x".into()]).names(),
            ["phi1", "phi2"]
        );
    }

    #[test]
    fn the_paper_stops_to_two_sinks_and_the_general_form_to_one_per_set() {
        let names: Vec<String> = vec!["A".into(), "B".into()];
        let payoffs = SubsetPayoffs::new(&[100.0, 250.0], &[], &names).unwrap();
        let paper = Presentation::paper("phi").sinks(&payoffs);
        let payoff = |sinks: &[Sink]| sinks.iter().map(|s| s.payoff).collect::<Vec<_>>();
        assert_eq!(payoff(&paper), [100.0, 250.0]);
        assert_eq!(paper[1].name, "stop(best)");
        let sinks = general(2).sinks(&payoffs);
        assert_eq!(payoff(&sinks), [100.0, 250.0, 350.0]);
        assert_eq!(sinks[2].name, "stop(A,B)");
        // A state winning both singletons settles for {B}: the paper's `stop(best)`, the
        // general form's sink of {B}.
        let wins = |set: TaskSet| set.0 != 0b11;
        assert_eq!(Presentation::paper("phi").stop_sink(wins, TaskSet(0b10)), 1);
        assert_eq!(general(2).stop_sink(wins, TaskSet(0b10)), 1);
        let only_a = |set: TaskSet| set.0 == 0b01;
        assert_eq!(
            Presentation::paper("phi").stop_sink(only_a, TaskSet(0b01)),
            0
        );
        assert_eq!(general(2).stop_sink(only_a, TaskSet(0b01)), 0);
    }
}

//! The hypergame: the product of an arena with two DFAs, attractors with ranks, win-labels and
//! the reactive strategies.
//!
//! The robot has k named sub-tasks and the adversary believes its task is psi (docs/semantics.md
//! §4, §5, §8); in the paper's form the task is `phi = phi1 & phi2` and `psi = phi1`
//! ([`split_task`] finds `phi1` and `phi2` in the formulas). [`Hypergame::with_automata`] builds
//! the explicit product graph once, with the sub-tasks' automata (and psi's when it needs one);
//! [`TaskRegions::compute`] runs an attractor per set of sub-tasks; [`WinLabel`], [`SubsetLabel`]
//! and [`Partition`] summarise them; [`ReactiveStrategy`] turns them into the players'
//! strategies. Every function is pure: nothing here prints or touches files.
//!
//! **Invariants** (tested on random arenas and DFAs against naive constructions): the product
//! equals stepping each DFA per edge; attractors equal the naive fixpoint, sets and ranks;
//! `Win(T) ⊆ Win(T')` for `T' ⊆ T`, so impossible win-labels never occur; in the full product a
//! region is a union of blocks over the automata that do not matter to it; the strategies win
//! within the rank against every adversary behaviour.

mod attractor;
mod labels;
mod partition;
mod product;
mod regions;
mod sets;
mod strategy;
mod task;

pub use attractor::Attractor;
pub use labels::{LabelCounts, WinLabel};
pub use partition::Partition;
pub use product::{HState, Hypergame, HypergameError, ProductState, StateNameError, States};
pub use regions::{
    Belief, PayoffError, Payoffs, SubsetLabel, SubsetLabelCounts, SubsetPayoffs, TaskRegions,
    label_text, subset_partition,
};
pub use sets::{MAX_TASKS, TaskSet};
pub use strategy::ReactiveStrategy;
pub use task::{Operand, SplitError, TaskSplit, match_belief, split_task};

/// How a problem is committed to and reported: the paper's form (two sub-tasks `phi1`, `phi2`,
/// the adversary believing `psi = phi1`, payoffs `r1`, `r2`, `r` with `r >= r1 + r2`, the paper's
/// risk rule) or the general form of k named sub-tasks (docs/semantics.md §6 and §8).
///
/// Both forms are one problem (the paper's is a preset of the general one) and their values
/// agree; the form decides only what the paper fixes beyond the values: which robot states the
/// MDP treats as absorbing, its stop sinks, and how reports name tasks and labels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Form {
    /// The paper's: win-labels `(W, L, L)`, tasks `phi1`, `phi2`, `phi`.
    Paper,
    /// k named sub-tasks, payoffs on their sets, any believed task.
    General,
}

/// The three tasks of a hypergame: the adversary's belief `phi1`, the rest `phi2`, and the
/// robot's actual task `phi = phi1 & phi2`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Task {
    /// `phi1`: the part of the robot's task that the adversary believes is all of it (`psi`).
    Phi1,
    /// `phi2`: the conjuncts of `phi` that the adversary does not know about.
    Phi2,
    /// `phi = phi1 & phi2`: the robot's whole task.
    Phi,
}

impl Task {
    /// In the order of the win-label triple.
    pub const ALL: [Task; 3] = [Task::Phi1, Task::Phi2, Task::Phi];

    /// The set of sub-tasks the task is: `{1}`, `{2}` or `{1,2}` (phi1 is sub-task 0).
    pub fn set(self) -> TaskSet {
        match self {
            Task::Phi1 => TaskSet(0b01),
            Task::Phi2 => TaskSet(0b10),
            Task::Phi => TaskSet(0b11),
        }
    }

    /// The paper's task of a set of its two sub-tasks (`None` for the empty set or a larger one).
    pub fn of_set(set: TaskSet) -> Option<Task> {
        Task::ALL.into_iter().find(|task| task.set() == set)
    }

    /// `phi1`, `phi2` or `phi`, as in reports and JSON keys.
    pub fn name(self) -> &'static str {
        match self {
            Task::Phi1 => "phi1",
            Task::Phi2 => "phi2",
            Task::Phi => "phi",
        }
    }
}

impl std::fmt::Display for Task {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    /// The files of this module depend on each other one way only (`use super::FILE`): the
    /// product, then attractors, regions and labels, then what is built on them. A cycle (as
    /// there was between the attractors and the win-labels) fails here.
    #[test]
    fn files_depend_on_each_other_without_cycles() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src/game");
        let mut sources = BTreeMap::new();
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            let stem = path.file_stem().unwrap().to_str().unwrap().to_string();
            if stem != "mod" {
                sources.insert(stem, std::fs::read_to_string(&path).unwrap());
            }
        }
        let depends: BTreeMap<&str, Vec<&str>> = sources
            .iter()
            .map(|(file, text)| {
                let uses = sources
                    .keys()
                    .filter(|other| *other != file && text.contains(&format!("super::{other}")))
                    .map(String::as_str)
                    .collect();
                (file.as_str(), uses)
            })
            .collect();
        // Depth-first search: a file met again while it is on the path closes a cycle.
        fn visit<'a>(
            file: &'a str,
            depends: &BTreeMap<&'a str, Vec<&'a str>>,
            path: &mut Vec<&'a str>,
            done: &mut Vec<&'a str>,
        ) {
            if done.contains(&file) {
                return;
            }
            assert!(!path.contains(&file), "cycle: {path:?} -> {file}");
            path.push(file);
            for &next in &depends[file] {
                visit(next, depends, path, done);
            }
            path.pop();
            done.push(file);
        }
        let mut done = Vec::new();
        for &file in depends.keys() {
            visit(file, &depends, &mut Vec::new(), &mut done);
        }
        assert!(depends["attractor"].iter().all(|&d| d == "product"));
        assert!(depends["labels"].is_empty());
    }
}

//! The hypergame: the product of an arena with two DFAs, attractors with ranks, win-labels and
//! the reactive strategies.
//!
//! The robot's task is `phi = phi1 & phi2`, the adversary believes it is `psi = phi1`
//! ([`split_task`] finds `phi1` and `phi2` in the formulas). [`Hypergame::new`] builds the
//! explicit product graph once; [`WinningRegions::compute`] runs the three attractors on it;
//! [`WinLabel`] and [`Partition`] summarise them; [`ReactiveStrategy`] turns them into the
//! players' strategies. Beyond the paper (DESIGN.md 3.8), [`Hypergame::with_automata`] builds the
//! product with k sub-task automata (and psi's), and [`TaskRegions`] computes `Win(T)` for every
//! set of sub-tasks. Every function is pure: nothing here prints or touches files.

mod attractor;
mod labels;
mod partition;
mod product;
mod regions;
mod strategy;
mod subtasks;
mod task;

pub use attractor::Attractor;
pub use labels::{LabelCounts, WinLabel};
pub use partition::Partition;
pub use product::{HState, Hypergame, HypergameError, ProductState, StateNameError, States};
pub use regions::WinningRegions;
pub use strategy::ReactiveStrategy;
pub use subtasks::{
    Belief, MAX_TASKS, PayoffError, SubsetLabel, SubsetLabelCounts, SubsetPayoffs, TaskRegions,
    TaskSet, label_text, subset_partition, task_targets,
};
pub use task::{Operand, SplitError, TaskSplit, match_belief, split_task};

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

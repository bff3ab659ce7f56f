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
mod product;
mod strategy;
mod subtasks;
mod task;

pub use attractor::{Attractor, WinningRegions};
pub use labels::{LabelCounts, Partition, WinLabel};
pub use product::{HState, Hypergame, HypergameError, ProductState, StateNameError, States};
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
    Phi1,
    Phi2,
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

//! The hypergame: the product of an arena with two DFAs, attractors with ranks, win-labels and
//! the reactive strategies.
//!
//! The robot has k named sub-tasks and the adversary believes its task is psi (docs/semantics.md
//! §4, §5, §8); in the paper's terms the task is `phi = phi1 & phi2` and `psi = phi1`
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

pub use attractor::{Attractor, allows_robot_edge};
pub use labels::{LabelCounts, WinLabel};
pub use partition::{LabelClass, LabelRow, Partition, label_classes, label_rows};
pub(crate) use partition::{classes_of, won_bits};
pub(crate) use product::{Component, missing_propositions, parse_state_name};
pub use product::{
    Engine, HState, Hypergame, HypergameError, ProductState, StateNameError, States,
};
pub use regions::{
    Belief, PayoffError, Payoffs, SubsetLabel, SubsetPayoffs, TaskRegions, Wins, is_payoff,
    label_text,
};
pub use sets::{MAX_TASKS, TaskSet};
pub use strategy::{ProductStrategies, ReactiveStrategy, StrategySource, WinRegion};
pub use task::{Operand, SplitError, TaskSplit, match_belief, split_task};

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

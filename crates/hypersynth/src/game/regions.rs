//! The robot's winning regions: `Win(T)` for every non-empty set T of sub-tasks and `Win(psi)`
//! (docs/semantics.md §5 and §8), with the payoffs of the sets and the labels they give.
//!
//! The paper's form is the case of two sub-tasks `phi1`, `phi2` with `psi = phi1`: its three
//! regions `Win(phi1)`, `Win(phi2)`, `Win(phi)` are those of the sets `{1}`, `{2}` and `{1,2}`
//! and its win-label is [`TaskRegions::win_label`].
//!
//! The product is a [`Hypergame`] built with [`Hypergame::with_automata`] over the k sub-tasks'
//! DFAs in order, followed by psi's DFA when psi is not a conjunction of sub-tasks
//! ([`Belief::Automaton`]). [`TaskRegions::compute`] runs one attractor per non-empty set T of
//! sub-tasks (`Win(T) = Attr(∩_{i∈T} F_i)`, 2^k − 1 of them) and one for psi when it has its own
//! automaton, spread over the available cores (rayon, see [`Meter::parallel`]; the product and its
//! predecessor lists are shared read-only). Each attractor costs O(|H| + |edges|) time and
//! `|H|` words of ranks plus `|H|` bits: for k = 8 that is 255 rank vectors, the memory bound of
//! this stage.
//!
//! Sets of sub-tasks are bit masks ([`TaskSet`], bit i = sub-task i). [`SubsetPayoffs`] holds
//! `r(T)` for every T, checked monotone; `gr(h)`, the guarantee, is the largest `r(T)` with
//! `h ∈ Win(T)`; the set the robot commits to when it settles is the one of largest payoff
//! (ties: fewer sub-tasks, then the sub-tasks' order).

use crate::stage::{Meter, Stage, Tally};
use serde::Serialize;

use super::attractor::Attractor;
use super::labels::WinLabel;
use super::product::{HState, Hypergame};
use super::sets::{MAX_TASKS, TaskSet};

/// Why payoffs are rejected. Sets are given as masks; the CLI names them.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PayoffError {
    /// The paper's payoffs must be positive and finite with `r >= r1 + r2`.
    #[error("payoffs must be positive with r >= r1 + r2 (got r1 = {r1}, r2 = {r2}, r = {r})")]
    Paper {
        /// The payoff of phi1 given.
        r1: f64,
        /// The payoff of phi2 given.
        r2: f64,
        /// The payoff of phi given.
        r: f64,
    },
    /// More than [`MAX_TASKS`] sub-tasks (the count given).
    #[error("at most {MAX_TASKS} sub-tasks are supported, got {0}")]
    TooManyTasks(usize),
    /// A payoff that is negative, infinite or NaN.
    #[error("a payoff must be a finite number >= 0, got {value}")]
    Invalid {
        /// The set it was given for.
        set: TaskSet,
        /// The rejected payoff.
        value: f64,
    },
    #[error(
        "payoffs must be monotone: a set of sub-tasks pays at least as much as each of its \
         subsets, but r({smaller_name}) = {smaller_value} > r({larger_name}) = {larger_value}"
    )]
    /// A set pays more than one of its supersets (`r(smaller) > r(larger)` with `smaller ⊆
    /// larger`).
    NotMonotone {
        /// The subset.
        smaller: TaskSet,
        /// The subset's sub-tasks by name, `A,B`.
        smaller_name: String,
        /// `r(smaller)`.
        smaller_value: f64,
        /// The superset.
        larger: TaskSet,
        /// The superset's sub-tasks by name, `A,B`.
        larger_name: String,
        /// `r(larger)`.
        larger_value: f64,
    },
}

/// Whether `value` can be the payoff of a set of sub-tasks: a finite number ≥ 0.
pub fn is_payoff(value: f64) -> bool {
    value.is_finite() && value >= 0.0
}

/// `r(T)` for every non-empty set T of k sub-tasks: monotone, finite, ≥ 0.
#[derive(Clone, Debug, PartialEq)]
pub struct SubsetPayoffs {
    k: usize,
    /// Indexed by mask; entry 0 (the empty set) is 0.
    values: Vec<f64>,
    /// The non-empty sets in the order in which the robot prefers to commit to them.
    preference: Vec<TaskSet>,
}

impl SubsetPayoffs {
    /// `r(T) = Σ_{i∈T} per_task[i]`, except for the sets in `overrides`; `names` (one per
    /// sub-task) only serve the error messages.
    pub fn new(
        per_task: &[f64],
        overrides: &[(TaskSet, f64)],
        names: &[String],
    ) -> Result<SubsetPayoffs, PayoffError> {
        let k = per_task.len();
        if k > MAX_TASKS {
            return Err(PayoffError::TooManyTasks(k));
        }
        let valid = |set: TaskSet, value: f64| {
            if is_payoff(value) {
                Ok(value)
            } else {
                Err(PayoffError::Invalid { set, value })
            }
        };
        for (i, &value) in per_task.iter().enumerate() {
            valid(TaskSet(1 << i), value)?;
        }
        // Folded from +0.0: an empty `sum()` of floats is -0.0, which would print as `-0`.
        let mut values: Vec<f64> = (0..1usize << k)
            .map(|mask| {
                TaskSet(mask as u8)
                    .iter()
                    .fold(0.0, |sum, i| sum + per_task[i])
            })
            .collect();
        for &(set, value) in overrides {
            values[set.0 as usize] = valid(set, value)?;
        }
        for set in TaskSet::non_empty(k) {
            for i in (0..k).filter(|&i| !set.contains(i)) {
                let larger = TaskSet(set.0 | 1 << i);
                let (a, b) = (values[set.0 as usize], values[larger.0 as usize]);
                if a > b {
                    return Err(PayoffError::NotMonotone {
                        smaller: set,
                        smaller_name: set.display(names).to_string(),
                        smaller_value: a,
                        larger,
                        larger_name: larger.display(names).to_string(),
                        larger_value: b,
                    });
                }
            }
        }
        let mut preference: Vec<TaskSet> = TaskSet::non_empty(k).collect();
        let members = |set: TaskSet| set.iter().collect::<Vec<usize>>();
        preference.sort_by(|&a, &b| {
            values[b.0 as usize]
                .total_cmp(&values[a.0 as usize])
                .then(a.len().cmp(&b.len()))
                .then_with(|| members(a).cmp(&members(b)))
        });
        Ok(SubsetPayoffs {
            k,
            values,
            preference,
        })
    }

    /// The number of sub-tasks.
    pub fn num_tasks(&self) -> usize {
        self.k
    }

    /// `r(T)` (0 for the empty set).
    pub fn get(&self, set: TaskSet) -> f64 {
        self.values[set.0 as usize]
    }

    /// The payoff of all sub-tasks together, the largest one.
    pub fn all(&self) -> f64 {
        self.get(TaskSet::all(self.k))
    }

    /// The non-empty sets, most preferred first: largest payoff, then fewer sub-tasks, then
    /// earlier sub-tasks.
    pub fn preference(&self) -> &[TaskSet] {
        &self.preference
    }

    /// The most preferred of the sets that `wins` accepts, `None` when it accepts none.
    pub fn best(&self, wins: impl Fn(TaskSet) -> bool) -> Option<TaskSet> {
        self.preference.iter().copied().find(|&set| wins(set))
    }
}

/// The paper's payoffs of `phi1`, `phi2` and `phi`: positive and finite with `r >= r1 + r2`
/// (docs/semantics.md §6.1). As payoffs on sets they are `r({1}) = r1`, `r({2}) = r2`,
/// `r({1,2}) = r` ([`Payoffs::subsets`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Payoffs {
    r1: f64,
    r2: f64,
    r: f64,
}

impl Payoffs {
    /// The payoffs of phi1, phi2 and phi; all positive and finite, with `r >= r1 + r2`, else
    /// [`PayoffError::Paper`].
    pub fn new(r1: f64, r2: f64, r: f64) -> Result<Payoffs, PayoffError> {
        let positive = |x: f64| x.is_finite() && x > 0.0;
        if !(positive(r1) && positive(r2) && positive(r) && r >= r1 + r2) {
            return Err(PayoffError::Paper { r1, r2, r });
        }
        Ok(Payoffs { r1, r2, r })
    }

    /// The payoff of `phi1`.
    pub fn r1(self) -> f64 {
        self.r1
    }

    /// The payoff of `phi2`.
    pub fn r2(self) -> f64 {
        self.r2
    }

    /// The payoff of `phi = phi1 & phi2`.
    pub fn r(self) -> f64 {
        self.r
    }

    /// The same payoffs on the sets of the two sub-tasks, named `names` in messages.
    pub fn subsets(self, names: &[String]) -> SubsetPayoffs {
        SubsetPayoffs::new(&[self.r1, self.r2], &[(TaskSet(0b11), self.r)], names)
            .expect("positive payoffs with r >= r1 + r2 are monotone")
    }

    /// The paper's payoffs of sets of two sub-tasks, if they are the paper's: positive with
    /// `r({1,2}) >= r({1}) + r({2})`.
    pub fn of_subsets(payoffs: &SubsetPayoffs) -> Option<Payoffs> {
        if payoffs.num_tasks() != 2 {
            return None;
        }
        let [r1, r2, r] = [0b01, 0b10, 0b11].map(|mask| payoffs.get(TaskSet(mask)));
        Payoffs::new(r1, r2, r).ok()
    }
}

impl Default for Payoffs {
    /// The case study's payoffs.
    fn default() -> Self {
        Payoffs {
            r1: 200.0,
            r2: 100.0,
            r: 300.0,
        }
    }
}

/// Where `Win(psi)` comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Belief {
    /// psi is the conjunction of these sub-tasks: `Win(psi) = Win(T_psi)`.
    Tasks(TaskSet),
    /// psi has its own automaton, the last one of the product.
    Automaton,
}

/// `Win(T)` for every non-empty set of sub-tasks, and `Win(psi)`.
#[derive(Clone, Debug, PartialEq)]
pub struct TaskRegions {
    k: usize,
    belief: Belief,
    /// Indexed by mask − 1.
    attractors: Vec<Attractor>,
    /// `Win(psi)` when psi has its own automaton.
    believed: Option<Attractor>,
}

impl TaskRegions {
    /// The attractors of a product of `k` sub-task automata (and psi's last, for
    /// [`Belief::Automaton`]).
    pub fn compute(game: &Hypergame, k: usize, belief: Belief) -> TaskRegions {
        TaskRegions::compute_metered(game, k, belief, &mut Meter::unobserved(Stage::Attractors))
    }

    /// [`Self::compute`] on a rayon pool of `threads` threads (1: in this thread's order, one
    /// by one).
    pub fn compute_on(game: &Hypergame, k: usize, belief: Belief, threads: usize) -> TaskRegions {
        match rayon::ThreadPoolBuilder::new()
            .num_threads(threads.max(1))
            .build()
        {
            Ok(pool) => pool.install(|| TaskRegions::compute(game, k, belief)),
            Err(_) => TaskRegions::compute(game, k, belief),
        }
    }

    /// [`Self::compute`] on the current rayon pool, the attractors in parallel (independent
    /// computations on the shared product: the result does not depend on their schedule),
    /// reporting to `meter` the states dealt with out of the product's times the attractors.
    pub fn compute_metered(
        game: &Hypergame,
        k: usize,
        belief: Belief,
        meter: &mut Meter<'_>,
    ) -> TaskRegions {
        let mut jobs: Vec<Option<TaskSet>> = TaskSet::non_empty(k).map(Some).collect();
        if belief == Belief::Automaton {
            jobs.push(None);
        }
        meter.set_total(jobs.len() as u64 * game.num_states() as u64);
        let jobs: Vec<_> = jobs
            .into_iter()
            .map(|job| {
                move |tally: &Tally| {
                    let targets = match job {
                        Some(set) => game.targets(set),
                        None => game.final_states(k),
                    };
                    Attractor::compute_tallied(game, &targets, tally)
                }
            })
            .collect();
        let mut results = meter.parallel(jobs);
        let believed = (belief == Belief::Automaton).then(|| results.pop().expect("psi's job"));
        TaskRegions {
            k,
            belief,
            attractors: results,
            believed,
        }
    }

    /// What psi is: a set of sub-tasks, or an automaton of its own in the product.
    pub fn belief(&self) -> Belief {
        self.belief
    }

    /// `Win(T)` for a non-empty `set`.
    pub fn win(&self, set: TaskSet) -> &Attractor {
        &self.attractors[set.0 as usize - 1]
    }

    /// `Win(psi)`.
    pub fn believed(&self) -> &Attractor {
        match (self.belief, &self.believed) {
            (Belief::Tasks(set), _) => self.win(set),
            (Belief::Automaton, Some(win)) => win,
            (Belief::Automaton, None) => unreachable!("computed with psi's automaton"),
        }
    }
}

/// Membership in either engine's winning regions, and what it gives a state: its set, its
/// guarantee and its labels ([`TaskRegions`], or the implicit engine's regions over the same
/// indices).
pub trait Wins {
    /// The number k of sub-tasks.
    fn num_tasks(&self) -> usize;

    /// Whether `h ∈ Win(T)` for a non-empty `set`.
    fn wins(&self, set: TaskSet, h: HState) -> bool;

    /// Whether `h ∈ Win(psi)`.
    fn believed_wins(&self, h: HState) -> bool;

    /// `gr(h)`: the largest `r(T)` with `h ∈ Win(T)`, 0 if there is none.
    fn guarantee(&self, payoffs: &SubsetPayoffs, h: HState) -> f64 {
        self.best(payoffs, h).map_or(0.0, |set| payoffs.get(set))
    }

    /// The set the robot commits to when it settles in `h`: the most preferred T with
    /// `h ∈ Win(T)`.
    fn best(&self, payoffs: &SubsetPayoffs, h: HState) -> Option<TaskSet> {
        payoffs.best(|set| self.wins(set, h))
    }

    /// The paper's win-label of `h`: its membership in `Win(phi1)`, `Win(phi2)` and `Win(phi)`,
    /// the regions of the sets `{1}`, `{2}` and `{1,2}` (two sub-tasks).
    fn win_label(&self, h: HState) -> WinLabel {
        WinLabel::of(|set| self.wins(set, h))
    }

    /// The label of `h`: the inclusion-maximal sets T with `h ∈ Win(T)`, and whether
    /// `h ∈ Win(psi)`.
    fn label(&self, h: HState) -> SubsetLabel {
        SubsetLabel::of(
            self.num_tasks(),
            |set| self.wins(set, h),
            self.believed_wins(h),
        )
    }
}

impl Wins for TaskRegions {
    fn num_tasks(&self) -> usize {
        self.k
    }

    fn wins(&self, set: TaskSet, h: HState) -> bool {
        self.win(set).contains(h)
    }

    fn believed_wins(&self, h: HState) -> bool {
        self.believed().contains(h)
    }
}

impl WinLabel {
    /// The paper's win-label of a state, from whether it is in `Win(T)` for the sets `{1}`,
    /// `{2}` and `{1,2}`.
    pub fn of(wins: impl Fn(TaskSet) -> bool) -> WinLabel {
        let [phi1, phi2, phi] = [0b01, 0b10, 0b11].map(|mask| wins(TaskSet(mask)));
        WinLabel { phi1, phi2, phi }
    }
}

/// The generalised win-label: the inclusion-maximal winnable sets of sub-tasks (in increasing
/// mask order) and whether psi is winnable.
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct SubsetLabel {
    /// The inclusion-maximal sets T with the state in `Win(T)`, in increasing mask order.
    pub maximal: Vec<TaskSet>,
    /// Whether the state is in `Win(psi)`.
    pub psi: bool,
}

impl SubsetLabel {
    /// The label of a state of a product of `k` sub-tasks, from whether it is in `Win(T)` for
    /// each non-empty `T` and in `Win(psi)`.
    pub fn of(k: usize, wins: impl Fn(TaskSet) -> bool, psi: bool) -> SubsetLabel {
        let won: Vec<TaskSet> = TaskSet::non_empty(k).filter(|&set| wins(set)).collect();
        let maximal = won
            .iter()
            .copied()
            .filter(|&set| {
                !won.iter()
                    .any(|&other| other != set && set.is_subset(other))
            })
            .collect();
        SubsetLabel { maximal, psi }
    }

    /// `{A,B} {C} | psi W`, or `{} | psi L` when no sub-task is winnable.
    pub fn display(&self, names: &[String]) -> String {
        let sets: Vec<Vec<String>> = self.maximal.iter().map(|set| set.names(names)).collect();
        label_text(&sets, self.psi)
    }
}

/// A generalised win-label from its maximal sets (as names): `{A,B} {C} | psi W`.
pub fn label_text(maximal: &[Vec<String>], psi: bool) -> String {
    let sets: Vec<String> = maximal
        .iter()
        .map(|set| format!("{{{}}}", set.join(",")))
        .collect();
    let sets = if sets.is_empty() {
        "{}".to_string()
    } else {
        sets.join(" ")
    };
    format!("{sets} | psi {}", if psi { 'W' } else { 'L' })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(k: usize) -> Vec<String> {
        ["A", "B", "C"][..k].iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn payoffs_default_to_sums_and_must_be_monotone() {
        let payoffs = SubsetPayoffs::new(&[200.0, 100.0, 50.0], &[], &names(3)).unwrap();
        assert_eq!(payoffs.get(TaskSet(0b011)), 300.0);
        assert_eq!(payoffs.all(), 350.0);
        // The example: A,B = 350 keeps {A,B,C} at its default 350.
        let payoffs =
            SubsetPayoffs::new(&[200.0, 100.0, 50.0], &[(TaskSet(0b011), 350.0)], &names(3))
                .unwrap();
        assert_eq!(payoffs.get(TaskSet(0b011)), 350.0);
        assert_eq!(payoffs.all(), 350.0);
        // {A,B} = 400 > {A,B,C} = 350: not monotone.
        let error =
            SubsetPayoffs::new(&[200.0, 100.0, 50.0], &[(TaskSet(0b011), 400.0)], &names(3))
                .unwrap_err();
        assert_eq!(
            error.to_string(),
            "payoffs must be monotone: a set of sub-tasks pays at least as much as each of its \
             subsets, but r(A,B) = 400 > r(A,B,C) = 350"
        );
        assert!(matches!(
            SubsetPayoffs::new(&[1.0, f64::NAN], &[], &names(2)),
            Err(PayoffError::Invalid { .. })
        ));
        assert!(matches!(
            SubsetPayoffs::new(&[1.0; 9], &[], &[]),
            Err(PayoffError::TooManyTasks(9))
        ));
    }

    #[test]
    fn preference_is_payoff_then_size_then_order() {
        // r(A) = r(B) = 100, r(A,B) = 100: {A} first (size, then order), then {B}, then {A,B}.
        let payoffs =
            SubsetPayoffs::new(&[100.0, 100.0], &[(TaskSet(0b11), 100.0)], &names(2)).unwrap();
        assert_eq!(
            payoffs.preference(),
            [TaskSet(0b01), TaskSet(0b10), TaskSet(0b11)]
        );
        let payoffs = SubsetPayoffs::new(&[50.0, 100.0, 10.0], &[], &names(3)).unwrap();
        assert_eq!(payoffs.preference()[0], TaskSet(0b111));
        assert_eq!(payoffs.preference()[1], TaskSet(0b011));
        assert_eq!(payoffs.preference().last().copied(), Some(TaskSet(0b100)));
    }

    #[test]
    fn sets_and_labels_print_with_names() {
        let names = names(3);
        assert_eq!(TaskSet(0b101).display(&names).to_string(), "A,C");
        let label = SubsetLabel {
            maximal: vec![TaskSet(0b011), TaskSet(0b100)],
            psi: true,
        };
        assert_eq!(label.display(&names), "{A,B} {C} | psi W");
        let none = SubsetLabel {
            maximal: vec![],
            psi: false,
        };
        assert_eq!(none.display(&names), "{} | psi L");
    }
}

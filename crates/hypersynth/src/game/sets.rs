//! Sets of sub-tasks as bit masks: bit i stands for sub-task i (at most [`MAX_TASKS`]).

use std::fmt;

/// The largest number of sub-tasks.
pub const MAX_TASKS: usize = 8;

/// A set of sub-tasks: bit i stands for sub-task i.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct TaskSet(pub u8);

impl TaskSet {
    /// All of the first `k` sub-tasks.
    pub fn all(k: usize) -> TaskSet {
        TaskSet(((1u16 << k) - 1) as u8)
    }

    /// The non-empty sets of the first `k` sub-tasks, in increasing mask order.
    pub fn non_empty(k: usize) -> impl Iterator<Item = TaskSet> {
        (1..1u16 << k).map(|mask| TaskSet(mask as u8))
    }

    /// Whether sub-task `i` is in the set.
    pub fn contains(self, i: usize) -> bool {
        self.0 >> i & 1 == 1
    }

    /// Number of sub-tasks in the set.
    pub fn len(self) -> usize {
        self.0.count_ones() as usize
    }

    /// Whether the set has no sub-task.
    pub fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// Whether every sub-task of `self` is in `other`.
    pub fn is_subset(self, other: TaskSet) -> bool {
        self.0 & !other.0 == 0
    }

    /// The sub-tasks in the set, in increasing order.
    pub fn iter(self) -> impl Iterator<Item = usize> {
        (0..MAX_TASKS).filter(move |&i| self.contains(i))
    }

    /// `A,B` for the names of the sub-tasks in the set.
    pub fn display<'a>(self, names: &'a [String]) -> impl fmt::Display + 'a {
        DisplaySet { set: self, names }
    }

    /// The names of the sub-tasks in the set.
    pub fn names(self, names: &[String]) -> Vec<String> {
        self.iter().map(|i| names[i].clone()).collect()
    }
}

struct DisplaySet<'a> {
    set: TaskSet,
    names: &'a [String],
}

impl fmt::Display for DisplaySet<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (n, i) in self.set.iter().enumerate() {
            if n > 0 {
                f.write_str(",")?;
            }
            f.write_str(&self.names[i])?;
        }
        Ok(())
    }
}

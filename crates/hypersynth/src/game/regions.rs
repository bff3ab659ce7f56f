//! The robot's winning regions of the paper's three tasks: one attractor per task, and the
//! win-label of each product state (DESIGN.md 3.5).

use super::Task;
use super::attractor::Attractor;
use super::labels::WinLabel;
use super::product::{HState, Hypergame};

/// The robot's winning regions `Win(phi1) = Attr(F1)`, `Win(phi2) = Attr(F2)` and
/// `Win(phi) = Attr(F12)`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct WinningRegions {
    /// Indexed like [`Task::ALL`].
    attractors: [Attractor; 3],
}

impl WinningRegions {
    /// Runs the three attractors on `game`: to the targets of `phi1`, `phi2` and `phi`.
    pub fn compute(game: &Hypergame) -> WinningRegions {
        WinningRegions {
            attractors: Task::ALL.map(|task| exact(Attractor::compute(game, &game.targets(task)))),
        }
    }

    /// `Win(task)`.
    pub fn get(&self, task: Task) -> &Attractor {
        &self.attractors[task as usize]
    }

    /// The win-label of `h`.
    pub fn label(&self, h: HState) -> WinLabel {
        WinLabel {
            phi1: self.get(Task::Phi1).contains(h),
            phi2: self.get(Task::Phi2).contains(h),
            phi: self.get(Task::Phi).contains(h),
        }
    }
}

/// `attractor` with no spare capacity, to be kept for the rest of the run. `Attractor::compute`
/// collects its ranks in place from its (rank, counter) pairs, so the ranks keep the pairs'
/// capacity: 8 bytes per state for 4 used, 12 bytes per product state over the three regions.
/// A clone allocates exactly (4N + N/8 bytes, while the original is dropped at once).
pub(super) fn exact(attractor: Attractor) -> Attractor {
    attractor.clone()
}

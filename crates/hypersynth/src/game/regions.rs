//! The robot's winning regions of the paper's three tasks: one attractor per task, and the
//! win-label of each product state (DESIGN.md 3.5).

use super::Task;
use super::attractor::Attractor;
use super::labels::WinLabel;
use super::product::{HState, Hypergame};
use crate::stage::{Meter, Stage};

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
        WinningRegions::compute_metered(game, &mut Meter::unobserved(Stage::Attractors))
    }

    /// [`WinningRegions::compute`], the three attractors in parallel (they are independent
    /// computations on a shared game, so the result does not depend on how they are
    /// scheduled), reporting to `meter` the states dealt with out of three times the game's.
    pub fn compute_metered(game: &Hypergame, meter: &mut Meter<'_>) -> WinningRegions {
        meter.set_total(3 * game.num_states() as u64);
        let jobs = Task::ALL
            .map(|task| {
                move |tally: &_| Attractor::compute_tallied(game, &game.targets(task), tally)
            })
            .to_vec();
        let attractors = <[Attractor; 3]>::try_from(meter.parallel(jobs))
            .unwrap_or_else(|_| unreachable!("one attractor per task"));
        WinningRegions { attractors }
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

//! `Win(T)` for every non-empty set of sub-tasks and `Win(psi)` over the index space
//! (docs/semantics.md §5, §8.3): the regions of [`TaskRegions`](crate::game::TaskRegions), one
//! bit per state each, with the largest rank and the initial state's rank of each (not a rank per
//! state).

use bit_set::BitSet;

use super::attractor::{Ranks, Region, attractor};
use super::moves::Moves;
use super::space::Space;
use crate::game::{Belief, HState, SubsetLabel, SubsetPayoffs, TaskSet, WinLabel, WinRegion, Wins};

/// The winning regions of a product of `k` sub-task automata (and psi's, last, for
/// [`Belief::Automaton`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Regions {
    k: usize,
    belief: Belief,
    /// Indexed by mask − 1.
    wins: Vec<Region>,
    believed: Option<Region>,
}

impl Regions {
    /// One attractor per non-empty set of sub-tasks, and psi's when it has its own automaton.
    pub fn compute<M: Moves>(space: &Space<'_, M>, k: usize, belief: Belief) -> Regions {
        let wins = TaskSet::non_empty(k)
            .map(|set| attractor(space, |h| space.is_target(set, h)))
            .collect();
        let believed =
            (belief == Belief::Automaton).then(|| attractor(space, |h| space.is_final(k, h)));
        Regions {
            k,
            belief,
            wins,
            believed,
        }
    }

    /// The number k of sub-tasks.
    pub fn num_tasks(&self) -> usize {
        self.k
    }

    /// `Win(T)` for a non-empty `set`.
    pub fn win(&self, set: TaskSet) -> &BitSet {
        &self.region(set).states
    }

    /// `Win(T)` for a non-empty `set`, with its ranks.
    pub fn region(&self, set: TaskSet) -> &Region {
        &self.wins[set.0 as usize - 1]
    }

    /// What psi is.
    pub fn belief(&self) -> Belief {
        self.belief
    }

    /// Every state's rank in `win` (`Win(psi)` only when psi has its own automaton), asking
    /// `budget(bytes)` first ([`Ranks::width`] bytes per product state): `None` where it says
    /// no.
    pub fn ranks<M: Moves>(
        &self,
        space: &Space<'_, M>,
        win: WinRegion,
        budget: impl FnOnce(u64) -> bool,
    ) -> Option<Ranks> {
        let k = self.k;
        let (region, is_target): (_, Box<dyn Fn(u32) -> bool>) = match win {
            WinRegion::Set(set) => (self.region(set), Box::new(move |h| space.is_target(set, h))),
            WinRegion::Believed => (
                self.believed.as_ref().expect("psi's own automaton"),
                Box::new(move |h| space.is_final(k, h)),
            ),
        };
        let bytes = Ranks::width(region.max_rank) as u64 * space.num_states() as u64;
        budget(bytes).then(|| Ranks::new(space, is_target, region.max_rank))
    }

    /// `Win(psi)`.
    pub fn believed(&self) -> &BitSet {
        match (self.belief, &self.believed) {
            (Belief::Tasks(set), _) => self.win(set),
            (Belief::Automaton, Some(win)) => &win.states,
            (Belief::Automaton, None) => unreachable!("computed with psi's automaton"),
        }
    }

    /// Whether `h ∈ Win(T)`.
    #[inline]
    pub fn wins(&self, set: TaskSet, h: u32) -> bool {
        self.win(set).contains(h as usize)
    }

    /// The set the robot commits to when it settles in `h` ([`Wins::best`]).
    pub fn best(&self, payoffs: &SubsetPayoffs, h: u32) -> Option<TaskSet> {
        Wins::best(self, payoffs, HState::from_u32(h))
    }

    /// `gr(h)` ([`Wins::guarantee`]).
    pub fn guarantee(&self, payoffs: &SubsetPayoffs, h: u32) -> f64 {
        Wins::guarantee(self, payoffs, HState::from_u32(h))
    }

    /// The paper's win-label of `h` ([`Wins::win_label`]).
    pub fn win_label(&self, h: u32) -> WinLabel {
        Wins::win_label(self, HState::from_u32(h))
    }

    /// The label of `h` ([`Wins::label`]).
    pub fn label(&self, h: u32) -> SubsetLabel {
        Wins::label(self, HState::from_u32(h))
    }
}

impl Wins for Regions {
    fn num_tasks(&self) -> usize {
        self.k
    }

    fn wins(&self, set: TaskSet, h: HState) -> bool {
        self.win(set).contains(h.index())
    }

    fn believed_wins(&self, h: HState) -> bool {
        self.believed().contains(h.index())
    }
}

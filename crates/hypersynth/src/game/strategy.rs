//! Reactive strategies from the attractors (docs/semantics.md §5), as sets of allowed product edges.
//!
//! The robot's rank-decreasing strategy for `Win(task)`: in a robot state of rank `k > 0`, the
//! allowed actions are exactly those whose successor has rank `< k` (so in `Win`, and each step
//! strictly lowers the rank; at least one such action exists by the definition of the rank).
//! Adversary states of rank `k > 0` have only successors of rank `< k`. Hence every play that
//! follows the strategy from a state of rank `k` reaches the targets, or a stuck adversary state
//! (which the attractor counts as won, see [`super::Attractor`]), within `k` steps, whatever the
//! adversary does. In a target robot state (rank 0) the task is already accomplished; the
//! strategy allows every action that stays in `Win`, which with absorbing final DFA states is
//! every action.
//!
//! The adversary's maximally permissive strategy against `Win(task)`: in every adversary state
//! outside `Win` (its winning region, the complement), every action whose successor stays
//! outside `Win`. At least one exists: otherwise the state would be attracted. Robot states
//! outside `Win` have no successor in `Win`, so following this strategy keeps every play out
//! of `Win` forever.

use bit_set::BitSet;

use super::attractor::Attractor;
use super::product::{HState, Hypergame};
use crate::arena::{ActionId, Owner};

/// A nondeterministic (permissive) memoryless strategy of one player: the states where it is
/// defined and, there, the allowed edges.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ReactiveStrategy {
    player: Owner,
    domain: BitSet,
    allowed: BitSet,
}

impl ReactiveStrategy {
    /// The robot's rank-decreasing winning strategy in `win = Win(task)`.
    pub fn robot(game: &Hypergame, win: &Attractor) -> ReactiveStrategy {
        Self::build(game, Owner::Robot, |h| {
            win.contains(h)
                .then_some(move |target| win.allows_robot_edge(h, target))
        })
    }

    /// The adversary's maximally permissive strategy outside the robot's `win = Win(task)`.
    pub fn adversary(game: &Hypergame, win: &Attractor) -> ReactiveStrategy {
        Self::build(game, Owner::Adversary, |h| {
            (!win.contains(h)).then_some(|target| !win.contains(target))
        })
    }

    /// Collects, for each state of `player` where `allows(h)` gives a filter, the edges whose
    /// target passes it.
    fn build<F: Fn(HState) -> bool>(
        game: &Hypergame,
        player: Owner,
        allows: impl Fn(HState) -> Option<F>,
    ) -> ReactiveStrategy {
        let mut domain = BitSet::with_capacity(game.num_states());
        let mut allowed = BitSet::with_capacity(game.num_edges());
        for h in game.states() {
            if game.owner(h) != player {
                continue;
            }
            let Some(filter) = allows(h) else { continue };
            domain.insert(h.index());
            for ((_, target), edge) in game.edges(h).zip(game.edge_range(h)) {
                if filter(target) {
                    allowed.insert(edge);
                }
            }
        }
        ReactiveStrategy {
            player,
            domain,
            allowed,
        }
    }

    /// The player whose strategy this is.
    pub fn player(&self) -> Owner {
        self.player
    }

    /// The states where the strategy is defined (the player's states of its winning region).
    pub fn domain(&self) -> &BitSet {
        &self.domain
    }

    /// Whether the strategy is defined at `h`: `h` is one of [`Self::domain`]'s states.
    pub fn is_defined(&self, h: HState) -> bool {
        self.domain.contains(h.index())
    }

    /// Whether product edge `edge` is allowed.
    pub fn allows(&self, edge: usize) -> bool {
        self.allowed.contains(edge)
    }

    /// The allowed actions in `h` with their successors (none where the strategy is undefined).
    pub fn moves<'g>(
        &'g self,
        game: &'g Hypergame,
        h: HState,
    ) -> impl Iterator<Item = (ActionId, HState)> + 'g {
        game.edges(h)
            .zip(game.edge_range(h))
            .filter(|&(_, edge)| self.allows(edge))
            .map(|(edge, _)| edge)
    }
}

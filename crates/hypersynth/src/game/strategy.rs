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
use super::product::{HState, Hypergame, States};
use super::regions::{Belief, TaskRegions};
use super::sets::TaskSet;
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

/// A winning region whose reactive strategies are exported: `Win(T)` for a non-empty set of
/// sub-tasks, or `Win(psi)` when psi has its own automaton.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WinRegion {
    /// `Win(T)`.
    Set(TaskSet),
    /// `Win(psi)`.
    Believed,
}

/// What the strategies' export (the report's `StrategyExport`) reads of a product and its
/// winning regions, from either engine: the enumerated states in product order, their owners,
/// names and edges, and each region's ranks.
pub trait StrategySource {
    /// Which product states are enumerated.
    fn enumeration(&self) -> States;
    /// The initial product state.
    fn initial(&self) -> u32;
    /// Calls `f` with each enumerated product state, in product order (the enumeration's).
    fn for_each_state(&self, f: &mut dyn FnMut(u32));
    /// Who moves in `h`.
    fn owner(&self, h: u32) -> Owner;
    /// The name of `h` (`ARENA_STATE|Q1|…`).
    fn name(&self, h: u32) -> String;
    /// Calls `f(action, target)` for each edge of `h`, in edge order.
    fn edges(&self, h: u32, f: &mut dyn FnMut(ActionId, u32));
    /// The name of `action`.
    fn action_name(&self, action: ActionId) -> &str;
    /// What psi is.
    fn belief(&self) -> Belief;
    /// Whether `h` is in `win`.
    fn wins(&self, win: WinRegion, h: u32) -> bool;
    /// The ranks of `win`'s states (`None` outside it), or `None` when the source cannot have
    /// them (it says why: serialisation then fails).
    fn ranks(&self, win: WinRegion) -> Option<Box<dyn Fn(u32) -> Option<u32> + '_>>;
}

/// The explicit engine's product and regions as the strategies' export reads them.
pub struct ProductStrategies<'a> {
    game: &'a Hypergame<'a>,
    regions: &'a TaskRegions,
}

impl<'a> ProductStrategies<'a> {
    /// The strategies of `game` with its `regions`.
    pub fn new(game: &'a Hypergame<'a>, regions: &'a TaskRegions) -> Self {
        ProductStrategies { game, regions }
    }

    fn attractor(&self, win: WinRegion) -> &'a Attractor {
        match win {
            WinRegion::Set(set) => self.regions.win(set),
            WinRegion::Believed => self.regions.believed(),
        }
    }
}

impl StrategySource for ProductStrategies<'_> {
    fn enumeration(&self) -> States {
        self.game.enumeration()
    }
    fn initial(&self) -> u32 {
        self.game.initial().as_u32()
    }
    fn for_each_state(&self, f: &mut dyn FnMut(u32)) {
        self.game.states().for_each(|h| f(h.as_u32()));
    }
    fn owner(&self, h: u32) -> Owner {
        self.game.owner(HState::from_u32(h))
    }
    fn name(&self, h: u32) -> String {
        self.game.name(HState::from_u32(h))
    }
    fn edges(&self, h: u32, f: &mut dyn FnMut(ActionId, u32)) {
        for (action, target) in self.game.edges(HState::from_u32(h)) {
            f(action, target.as_u32());
        }
    }
    fn action_name(&self, action: ActionId) -> &str {
        self.game.arena().action_name(action)
    }
    fn belief(&self) -> Belief {
        self.regions.belief()
    }
    fn wins(&self, win: WinRegion, h: u32) -> bool {
        self.attractor(win).contains(HState::from_u32(h))
    }
    fn ranks(&self, win: WinRegion) -> Option<Box<dyn Fn(u32) -> Option<u32> + '_>> {
        let attractor = self.attractor(win);
        Some(Box::new(move |h| attractor.rank(HState::from_u32(h))))
    }
}

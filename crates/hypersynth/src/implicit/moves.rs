//! The arena side of the implicit engine: an arena described by its move rules.
//!
//! [`Moves`] is what the engine asks of an arena: states numbered `0..num_states()`, each with
//! its owner, its label (an index into a table of distinct labels) and its edges in edge order,
//! and every state's predecessors, one per edge into it. Two arenas implement it:
//! - [`ArenaMoves`], a stored [`Arena`] with the transpose of its edges (a text arena: small
//!   beside the product);
//! - [`MapMoves`], a gridworld computed from its cells and moves: nothing per state is stored,
//!   and its numbering, labels and edge order are those of the arena [`Gridworld::build`] makes
//!   (docs/semantics.md §3.3), so both describe the same arena state by state.
//!
//! Invariant (both): `predecessors(t)` lists `s` once for every edge `s → t`, so that an
//! adversary state with two actions into one state is listed twice, as the attractor's counters
//! need.

use std::collections::HashMap;

use bit_set::BitSet;

use crate::arena::gridworld::{Cell, Checked, Collision, Gridworld, GridworldError, Move};
use crate::arena::{ActionId, Arena, LabelId, Owner, StateId};
use crate::csr::Csr;
use crate::opportunistic::adversary::ArenaLookup;

/// An arena given by rules: see the module documentation.
pub trait Moves: Sync {
    /// The number of arena states.
    fn num_states(&self) -> usize;
    /// The initial state.
    fn initial(&self) -> u32;
    /// Who moves in state `s`.
    fn owner(&self, s: u32) -> Owner;
    /// The label of state `s`, an index into [`Moves::labels`].
    fn label(&self, s: u32) -> LabelId;
    /// The distinct labels, each a set of indices into [`Moves::propositions`].
    fn labels(&self) -> &[BitSet];
    /// The arena's propositions.
    fn propositions(&self) -> &[String];
    /// The arena's action names, by [`ActionId`].
    fn actions(&self) -> &[String];
    /// Calls `f(action, successor, successor's label)` for each edge of `s`, in edge order.
    fn edges(&self, s: u32, f: impl FnMut(ActionId, u32, LabelId));
    /// Calls `f(source)` once for each edge into `t`.
    fn predecessors(&self, t: u32, f: impl FnMut(u32));
    /// The number of edges of `s`.
    fn degree(&self, s: u32) -> u32 {
        let mut n = 0;
        self.edges(s, |_, _, _| n += 1);
        n
    }
    /// The largest number of edges of a state: what the attractor's counters must hold.
    fn max_degree(&self) -> u32;
    /// The name of state `s`.
    fn name(&self, s: u32) -> String {
        let mut name = String::new();
        self.write_name(s, &mut name)
            .expect("formatting into a String does not fail");
        name
    }
    /// Writes the name of state `s` into `out` (no string made: what the random sigma_L's
    /// draws hash).
    fn write_name(&self, s: u32, out: &mut dyn std::fmt::Write) -> std::fmt::Result;
    /// The state named `name`, if any, found without a name per state.
    fn state_of(&self, name: &str) -> Option<u32>;
}

/// A weight table's names are resolved against the rules as against the arena they describe.
impl<M: Moves> ArenaLookup for M {
    type State = u32;

    fn find_state(&self, name: &str) -> Option<u32> {
        self.state_of(name)
    }

    fn state_name(&self, state: u32) -> String {
        Moves::name(self, state)
    }

    fn edge_action(&self, state: u32, edge: usize) -> String {
        let (mut place, mut found) = (0, None);
        self.edges(state, |a, _, _| {
            if place == edge {
                found = Some(a);
            }
            place += 1;
        });
        self.actions()[found.expect("an edge of the state") as usize].clone()
    }

    fn owner(&self, state: u32) -> Owner {
        Moves::owner(self, state)
    }

    fn degree(&self, state: u32) -> usize {
        Moves::degree(self, state) as usize
    }

    fn find_edge(&self, state: u32, action: &str) -> Option<usize> {
        let (mut place, mut found) = (0, None);
        self.edges(state, |a, _, _| {
            if found.is_none() && self.actions()[a as usize] == action {
                found = Some(place);
            }
            place += 1;
        });
        found
    }
}

/// A stored arena with the predecessor lists of its edges.
#[derive(Debug)]
pub struct ArenaMoves<'a> {
    arena: &'a Arena,
    predecessors: Csr<StateId, StateId>,
    max_degree: u32,
}

impl<'a> ArenaMoves<'a> {
    /// The rules of `arena`.
    pub fn new(arena: &'a Arena) -> ArenaMoves<'a> {
        let predecessors = Csr::group_from(arena.num_states(), || {
            arena
                .states()
                .flat_map(move |s| arena.edges(s).map(move |(_, t)| (t, s)))
        });
        let max_degree = arena
            .states()
            .map(|s| arena.edges(s).len() as u32)
            .max()
            .unwrap_or(0);
        ArenaMoves {
            arena,
            predecessors,
            max_degree,
        }
    }
}

impl Moves for ArenaMoves<'_> {
    fn num_states(&self) -> usize {
        self.arena.num_states()
    }

    fn initial(&self) -> u32 {
        self.arena.initial().as_u32()
    }

    fn owner(&self, s: u32) -> Owner {
        self.arena.owner(StateId::from_u32(s))
    }

    fn label(&self, s: u32) -> LabelId {
        self.arena.label_id(StateId::from_u32(s))
    }

    fn labels(&self) -> &[BitSet] {
        self.arena.labels()
    }

    fn propositions(&self) -> &[String] {
        self.arena.propositions()
    }

    fn actions(&self) -> &[String] {
        self.arena.actions()
    }

    fn edges(&self, s: u32, mut f: impl FnMut(ActionId, u32, LabelId)) {
        for (a, t) in self.arena.edges(StateId::from_u32(s)) {
            f(a, t.as_u32(), self.arena.label_id(t));
        }
    }

    fn predecessors(&self, t: u32, mut f: impl FnMut(u32)) {
        for s in self.predecessors.row(StateId::from_u32(t)) {
            f(s.as_u32());
        }
    }

    fn degree(&self, s: u32) -> u32 {
        self.arena.edges(StateId::from_u32(s)).len() as u32
    }

    fn max_degree(&self) -> u32 {
        self.max_degree
    }

    fn write_name(&self, s: u32, out: &mut dyn std::fmt::Write) -> std::fmt::Result {
        out.write_str(self.arena.name(StateId::from_u32(s)))
    }

    fn state_of(&self, name: &str) -> Option<u32> {
        self.arena.find_state(name).map(StateId::as_u32)
    }
}

/// No move: the marker in the step tables.
const NONE: u32 = u32::MAX;

/// A gridworld's states and edges computed from its cells and moves (docs/semantics.md §3.3):
/// state `turn · f² + r · f + a` has the robot on free cell `r`, the adversary on free cell `a`
/// (`f` free cells, by `x` then `y`) and `turn` (0 robot, 1 adversary) to move, as in the arena
/// [`Gridworld::build`] makes. Per free cell and move it stores where the move leads and where
/// it comes from; nothing per state.
#[derive(Clone, Debug)]
pub struct MapMoves {
    free: Vec<Cell>,
    /// Per player (robot, adversary): its moves' action ids, in the order given.
    actions: [Vec<ActionId>; 2],
    /// Per player: `forward[c * m + i]`, the free cell move `i` leads to from free cell `c`,
    /// and `backward[c * m + i]` the one it leads from into `c` (`NONE` for none).
    forward: [Vec<u32>; 2],
    backward: [Vec<u32>; 2],
    /// Whether the players may not share a cell.
    forbidden: bool,
    /// The label of a state by its robot cell; `shared[c]` when both players are on `c`.
    plain: Vec<LabelId>,
    shared: Vec<LabelId>,
    labels: Vec<BitSet>,
    propositions: Vec<String>,
    action_names: Vec<String>,
    initial: u32,
}

impl MapMoves {
    /// The rules of `world`, after the checks that building its arena makes (the same errors).
    pub fn new(world: &Gridworld) -> Result<MapMoves, GridworldError> {
        let Checked {
            grid,
            robot,
            adversary,
            cell_labels,
            shared_label,
            propositions,
        } = world.check()?;
        let free = grid.free_cells().to_vec();
        let f = free.len();
        let mut action_names: Vec<Move> = Vec::new();
        let mut action_of = |m: Move| {
            let id = match action_names.iter().position(|&n| n == m) {
                Some(i) => i,
                None => {
                    action_names.push(m);
                    action_names.len() - 1
                }
            };
            id as ActionId
        };
        let robot_actions: Vec<ActionId> =
            world.robot_moves.iter().map(|&m| action_of(m)).collect();
        let adversary_actions: Vec<ActionId> = world
            .adversary_moves
            .iter()
            .map(|&m| action_of(m))
            .collect();
        let tables = |moves: &[Move]| {
            let m = moves.len();
            let mut forward = vec![NONE; f * m];
            let mut backward = vec![NONE; f * m];
            for c in 0..f {
                for (i, &mv) in moves.iter().enumerate() {
                    if let Some(t) = grid.step(c, mv) {
                        forward[c * m + i] = t as u32;
                        backward[t * m + i] = c as u32;
                    }
                }
            }
            (forward, backward)
        };
        let (robot_forward, robot_backward) = tables(&world.robot_moves);
        let (adversary_forward, adversary_backward) = tables(&world.adversary_moves);
        let proposition_index = |p: &str| propositions.iter().position(|&q| q == p).unwrap_or(0);
        // Labels are numbered in order of first appearance among the states, as the arena
        // builder numbers them: robot turn first, robot cell, then adversary cell.
        let mut label_ids: HashMap<Vec<usize>, LabelId> = HashMap::new();
        let mut labels: Vec<BitSet> = Vec::new();
        let mut intern = |props: &[&str], with_shared: bool| -> LabelId {
            let mut ids: Vec<usize> = props.iter().map(|p| proposition_index(p)).collect();
            if with_shared {
                ids.extend(shared_label.map(proposition_index));
            }
            ids.sort_unstable();
            ids.dedup();
            *label_ids.entry(ids).or_insert_with_key(|ids| {
                labels.push(ids.iter().copied().collect());
                labels.len() as LabelId - 1
            })
        };
        let mut plain = Vec::with_capacity(f);
        let mut shared = Vec::with_capacity(f);
        for (r, props) in cell_labels.iter().enumerate() {
            // In robot cell r, the adversary cell 0 comes first: shared when r is 0.
            if r == 0 {
                shared.push(intern(props, true));
                plain.push(if f > 1 { intern(props, false) } else { NONE });
            } else {
                plain.push(intern(props, false));
                shared.push(intern(props, true));
            }
        }
        let turn = match world.first {
            Owner::Robot => 0,
            Owner::Adversary => 1,
        };
        Ok(MapMoves {
            initial: (turn * f * f + robot * f + adversary) as u32,
            free,
            actions: [robot_actions, adversary_actions],
            forward: [robot_forward, adversary_forward],
            backward: [robot_backward, adversary_backward],
            forbidden: world.collision == Collision::Forbidden,
            plain,
            shared,
            labels,
            propositions: propositions.iter().map(|p| p.to_string()).collect(),
            action_names: action_names.iter().map(|m| m.name().to_string()).collect(),
        })
    }

    /// The turn (0 robot, 1 adversary), robot cell and adversary cell of state `s`.
    #[inline]
    fn split(&self, s: u32) -> (usize, usize, usize) {
        let f = self.free.len();
        let s = s as usize;
        let turn = usize::from(s >= f * f);
        let within = s - turn * f * f;
        let r = within / f;
        (turn, r, within - r * f)
    }

    /// The label of a state with the robot on free cell `r` and the adversary on `a`.
    #[inline]
    fn label_of(&self, r: usize, a: usize) -> LabelId {
        if r == a {
            self.shared[r]
        } else {
            self.plain[r]
        }
    }

    #[inline]
    fn join(&self, turn: usize, r: usize, a: usize) -> u32 {
        let f = self.free.len();
        (turn * f * f + r * f + a) as u32
    }

    /// The moves of the player to move (`turn`) with the robot on free cell `r` and the
    /// adversary on `a`: each action and the free cell it leads the mover to, in edge order.
    #[inline]
    fn steps(&self, turn: usize, r: usize, a: usize) -> impl Iterator<Item = (ActionId, usize)> {
        let (mover, other) = if turn == 0 { (r, a) } else { (a, r) };
        let actions = &self.actions[turn];
        let forward = &self.forward[turn][mover * actions.len()..][..actions.len()];
        actions
            .iter()
            .zip(forward)
            .filter(move |&(_, &t)| t != NONE && !(self.forbidden && t as usize == other))
            .map(|(&action, &t)| (action, t as usize))
    }

    /// The robot's cell, the adversary's cell and the player to move in state `s`.
    pub fn cells(&self, s: u32) -> (Cell, Cell, Owner) {
        let (turn, r, a) = self.split(s);
        let owner = if turn == 0 {
            Owner::Robot
        } else {
            Owner::Adversary
        };
        (self.free[r], self.free[a], owner)
    }
}

impl Moves for MapMoves {
    fn num_states(&self) -> usize {
        2 * self.free.len() * self.free.len()
    }

    fn initial(&self) -> u32 {
        self.initial
    }

    fn owner(&self, s: u32) -> Owner {
        if (s as usize) < self.free.len() * self.free.len() {
            Owner::Robot
        } else {
            Owner::Adversary
        }
    }

    fn label(&self, s: u32) -> LabelId {
        let (_, r, a) = self.split(s);
        if r == a {
            self.shared[r]
        } else {
            self.plain[r]
        }
    }

    fn labels(&self) -> &[BitSet] {
        &self.labels
    }

    fn propositions(&self) -> &[String] {
        &self.propositions
    }

    fn actions(&self) -> &[String] {
        &self.action_names
    }

    #[inline]
    fn edges(&self, s: u32, mut f: impl FnMut(ActionId, u32, LabelId)) {
        let (turn, r, a) = self.split(s);
        for (action, t) in self.steps(turn, r, a) {
            // One call of `f`, so that it is inlined.
            let (r, a) = if turn == 0 { (t, a) } else { (r, t) };
            f(action, self.join(1 - turn, r, a), self.label_of(r, a));
        }
    }

    #[inline]
    fn predecessors(&self, t: u32, mut f: impl FnMut(u32)) {
        let (turn, r, a) = self.split(t);
        // The player who moved into t is the one not to move in t.
        let moved = 1 - turn;
        let (target, other) = if moved == 0 { (r, a) } else { (a, r) };
        if self.forbidden && target == other {
            return;
        }
        let m = self.actions[moved].len();
        for &source in &self.backward[moved][target * m..][..m] {
            if source == NONE {
                continue;
            }
            let c = source as usize;
            f(if moved == 0 {
                self.join(0, c, a)
            } else {
                self.join(1, r, c)
            });
        }
    }

    #[inline]
    fn degree(&self, s: u32) -> u32 {
        let (turn, r, a) = self.split(s);
        self.steps(turn, r, a).count() as u32
    }

    fn max_degree(&self) -> u32 {
        self.actions[0].len().max(self.actions[1].len()) as u32
    }

    fn write_name(&self, s: u32, out: &mut dyn std::fmt::Write) -> std::fmt::Result {
        let (robot, adversary, turn) = self.cells(s);
        Gridworld::write_state_name(out, robot, adversary, turn)
    }

    /// Reads the five numbers of `((xr,yr),(xa,ya),t)` and keeps the state only if its name
    /// is `name` exactly (no other spelling of the numbers, no other punctuation).
    fn state_of(&self, name: &str) -> Option<u32> {
        let mut numbers = name
            .split(|c: char| !c.is_ascii_digit())
            .filter(|part| !part.is_empty())
            .map(|part| part.parse::<u32>().ok());
        let mut next = || numbers.next().flatten();
        let robot = Cell {
            x: next()?,
            y: next()?,
        };
        let adversary = Cell {
            x: next()?,
            y: next()?,
        };
        let turn = next()?;
        let cell = |cell: Cell| self.free.binary_search(&cell).ok();
        let (r, a) = (cell(robot)?, cell(adversary)?);
        let s = self.join((turn < 2).then_some(turn as usize)?, r, a);
        (self.name(s) == name).then_some(s)
    }
}

/// Either arena's rules, for a caller that holds one engine value for both (the Python
/// package); the command line runs each kind of arena with its own type.
#[derive(Debug)]
pub enum SourceMoves<'a> {
    /// A stored arena's.
    Arena(ArenaMoves<'a>),
    /// A map's.
    Map(Box<MapMoves>),
}

/// `$call` on the rules of `$moves`, whichever they are.
macro_rules! either {
    ($moves:expr, $m:ident => $call:expr) => {
        match $moves {
            SourceMoves::Arena($m) => $call,
            SourceMoves::Map(map) => {
                let $m: &MapMoves = map;
                $call
            }
        }
    };
}

impl Moves for SourceMoves<'_> {
    fn num_states(&self) -> usize {
        either!(self, m => m.num_states())
    }
    fn initial(&self) -> u32 {
        either!(self, m => m.initial())
    }
    fn owner(&self, s: u32) -> Owner {
        either!(self, m => Moves::owner(m, s))
    }
    fn label(&self, s: u32) -> LabelId {
        either!(self, m => m.label(s))
    }
    fn labels(&self) -> &[BitSet] {
        either!(self, m => m.labels())
    }
    fn propositions(&self) -> &[String] {
        either!(self, m => m.propositions())
    }
    fn actions(&self) -> &[String] {
        either!(self, m => m.actions())
    }
    fn edges(&self, s: u32, f: impl FnMut(ActionId, u32, LabelId)) {
        either!(self, m => m.edges(s, f))
    }
    fn predecessors(&self, t: u32, f: impl FnMut(u32)) {
        either!(self, m => m.predecessors(t, f))
    }
    fn degree(&self, s: u32) -> u32 {
        either!(self, m => Moves::degree(m, s))
    }
    fn max_degree(&self) -> u32 {
        either!(self, m => m.max_degree())
    }
    fn write_name(&self, s: u32, out: &mut dyn std::fmt::Write) -> std::fmt::Result {
        either!(self, m => m.write_name(s, out))
    }
    fn state_of(&self, name: &str) -> Option<u32> {
        either!(self, m => m.state_of(name))
    }
}

//! The gridworld generator: a two-player turn-based game on a rectangular grid with obstacles.
//!
//! - Cells are `(x, y)` with `0 <= x < width` eastward and `0 <= y < height` northward: `N` moves
//!   to `(x, y+1)`, `NE` to `(x+1, y+1)`, `STAY` keeps the cell.
//! - There is one state per robot cell, adversary cell and turn, over all free (non-obstacle)
//!   cells, the two players sharing a cell included whatever the collision rule (docs/semantics.md §3.3).
//!   States are numbered by turn (robot to move first), then robot cell, then adversary cell,
//!   cells in order of `x` then `y`; state `((xr,yr),(xa,ya),t)` has the robot at `(xr,yr)`, the
//!   adversary at `(xa,ya)` and `t = 0` when the robot is to move, `1` when the adversary is.
//!   The player to move owns the state; every move passes the turn.
//! - A move exists iff its target cell is on the grid, is not an obstacle and, under
//!   [`Collision::Forbidden`], is not the other player's cell (so `STAY` is not possible either
//!   in a shared-cell state, which that rule makes unreachable).
//! - A state's label is the set of propositions of the *robot's* cell, since the tasks speak
//!   about where the robot goes; under [`Collision::Label`] a state where the players share a
//!   cell also carries that proposition. Obstacle cells carry [`OBSTACLE`]; it is declared so
//!   formulas may mention it, but no state carries it, since nobody stands on an obstacle.

use std::fmt;
use std::str::FromStr;

use bit_set::BitSet;

use super::model::{Arena, ArenaBuilder, BuildError, Owner, StateId};
use crate::diagnostic::brief;

/// The proposition of obstacle cells.
pub const OBSTACLE: &str = "O";

/// A cell of the grid: `x` counts columns eastward, `y` rows northward, both from 0.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Cell {
    /// The column, from 0 at the west edge.
    pub x: u32,
    /// The row, from 0 at the south edge.
    pub y: u32,
}

impl fmt::Display for Cell {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "({},{})", self.x, self.y)
    }
}

/// `x,y`, as on the command line.
impl FromStr for Cell {
    type Err = GridworldError;

    fn from_str(text: &str) -> Result<Cell, GridworldError> {
        let coordinate = |c: &str| c.trim().parse::<u32>().ok();
        text.split_once(',')
            .and_then(|(x, y)| {
                Some(Cell {
                    x: coordinate(x)?,
                    y: coordinate(y)?,
                })
            })
            .ok_or_else(|| GridworldError::BadCell(text.to_string()))
    }
}

/// A compass move (or staying put); its name is the action name in the arena.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Move {
    /// North: `y + 1`.
    N,
    /// South: `y - 1`.
    S,
    /// East: `x + 1`.
    E,
    /// West: `x - 1`.
    W,
    /// North-east: `x + 1`, `y + 1`.
    NE,
    /// North-west: `x - 1`, `y + 1`.
    NW,
    /// South-east: `x + 1`, `y - 1`.
    SE,
    /// South-west: `x - 1`, `y - 1`.
    SW,
    /// Staying in the cell (action `STAY`).
    Stay,
}

impl Move {
    /// Every move: the eight compass directions, then `Stay`.
    pub const ALL: [Move; 9] = [
        Move::N,
        Move::S,
        Move::E,
        Move::W,
        Move::NE,
        Move::NW,
        Move::SE,
        Move::SW,
        Move::Stay,
    ];

    /// The move's action name: `N` ... `SW`, or `STAY`.
    pub fn name(self) -> &'static str {
        match self {
            Move::N => "N",
            Move::S => "S",
            Move::E => "E",
            Move::W => "W",
            Move::NE => "NE",
            Move::NW => "NW",
            Move::SE => "SE",
            Move::SW => "SW",
            Move::Stay => "STAY",
        }
    }

    /// The change of `(x, y)`.
    pub fn offset(self) -> (i64, i64) {
        match self {
            Move::N => (0, 1),
            Move::S => (0, -1),
            Move::E => (1, 0),
            Move::W => (-1, 0),
            Move::NE => (1, 1),
            Move::NW => (-1, 1),
            Move::SE => (1, -1),
            Move::SW => (-1, -1),
            Move::Stay => (0, 0),
        }
    }
}

impl fmt::Display for Move {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Move {
    type Err = GridworldError;

    fn from_str(name: &str) -> Result<Move, GridworldError> {
        Move::ALL
            .into_iter()
            .find(|m| m.name() == name)
            .ok_or_else(|| GridworldError::BadMove(name.to_string()))
    }
}

/// The robot's moves unless told otherwise: the eight compass directions (all but `STAY`).
pub const ROBOT_MOVES: &[Move] = Move::ALL.split_at(8).0;

/// The adversary's moves unless told otherwise: the four main directions and staying put.
pub const ADVERSARY_MOVES: [Move; 5] = [Move::N, Move::S, Move::E, Move::W, Move::Stay];

/// What happens when a player moves into the other player's cell.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Collision {
    /// The move does not exist: players block each other.
    Forbidden,
    /// The move exists.
    Allowed,
    /// The move exists, and states where the players share a cell carry this proposition.
    Label(String),
}

/// `forbidden`, `allowed` or `label:NAME`, as on the command line.
impl FromStr for Collision {
    type Err = GridworldError;

    fn from_str(text: &str) -> Result<Collision, GridworldError> {
        match text {
            "forbidden" => Ok(Collision::Forbidden),
            "allowed" => Ok(Collision::Allowed),
            _ => match text.strip_prefix("label:") {
                Some(name) => Ok(Collision::Label(name.to_string())),
                None => Err(GridworldError::BadCollision(text.to_string())),
            },
        }
    }
}

impl fmt::Display for Collision {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Collision::Forbidden => f.write_str("forbidden"),
            Collision::Allowed => f.write_str("allowed"),
            Collision::Label(name) => write!(f, "label:{name}"),
        }
    }
}

/// Why a gridworld cannot be generated.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum GridworldError {
    /// A side of the grid is 0.
    #[error("the grid is {width}x{height}: both sides must be at least 1")]
    EmptyGrid {
        /// The width, in cells.
        width: u32,
        /// The height, in cells.
        height: u32,
    },
    /// A cell lies outside the grid.
    #[error("{what} {cell} is off the {width}x{height} grid (0 <= x < {width}, 0 <= y < {height})")]
    OffGrid {
        /// Which cell it is, in words (an obstacle, the robot's initial cell...).
        what: String,
        /// The cell.
        cell: Cell,
        /// The grid's width, in cells.
        width: u32,
        /// The grid's height, in cells.
        height: u32,
    },
    /// A cell that must be free (an initial cell, a labelled cell) is an obstacle.
    #[error("{what} {cell} is an obstacle")]
    OnObstacle {
        /// Which cell it is, in words (the robot's initial cell...).
        what: String,
        /// The cell.
        cell: Cell,
    },
    /// An obstacle, or a proposition's cell, is given twice.
    #[error("{what} {cell} is given twice")]
    Repeated {
        /// Which cell it is, in words (an obstacle, the cell of a label).
        what: String,
        /// The cell.
        cell: Cell,
    },
    /// Both players start on the given cell, which [`Collision::Forbidden`] does not allow.
    #[error("both players start on {0}, but collisions are forbidden")]
    SameStart(Cell),
    /// The given player (`robot` or `adversary`) has no moves.
    #[error("the {0} has no moves")]
    NoMoves(&'static str),
    /// A player's list of moves names a move twice.
    #[error("move {name} is given twice for the {player}")]
    RepeatedMove {
        /// The player, `robot` or `adversary`.
        player: &'static str,
        /// The move's name.
        name: &'static str,
    },
    /// A label's proposition name is empty.
    #[error("a proposition name cannot be empty")]
    EmptyProposition,
    /// The arena would have too many states (two per pair of free cells) for its transitions
    /// to be numbered in 32 bits.
    #[error(
        "the grid has {free_cells} free cells, hence 2 x {free_cells}^2 states: more than the \
         {MAX_STATES} whose transitions an arena can number"
    )]
    TooLarge {
        /// The number of free (non-obstacle) cells.
        free_cells: u64,
    },
    /// Text that is not a cell (`x,y`).
    #[error(
        "`{}` is not a cell: expected `x,y` with non-negative integers, such as `0,2`",
        brief(.0)
    )]
    BadCell(String),
    /// Text that is not a move's name.
    #[error("`{}` is not a move: expected one of N S E W NE NW SE SW STAY", brief(.0))]
    BadMove(String),
    /// Text that is not a collision rule.
    #[error(
        "`{}` is not a collision rule: expected `forbidden`, `allowed` or `label:NAME`",
        brief(.0)
    )]
    BadCollision(String),
    /// The arena builder refused the generated arena.
    #[error(transparent)]
    Build(#[from] BuildError),
}

/// The parameters of a gridworld.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Gridworld {
    /// The grid's width, in cells.
    pub width: u32,
    /// The grid's height, in cells.
    pub height: u32,
    /// The obstacle cells, none of them repeated.
    pub obstacles: Vec<Cell>,
    /// The robot's initial cell.
    pub robot: Cell,
    /// The adversary's initial cell.
    pub adversary: Cell,
    /// Labelled cells: a proposition and one cell it holds in (a proposition may be repeated).
    pub labels: Vec<(String, Cell)>,
    /// The moves the robot may make, none repeated.
    pub robot_moves: Vec<Move>,
    /// The moves the adversary may make, none repeated.
    pub adversary_moves: Vec<Move>,
    /// What happens when a player moves into the other's cell.
    pub collision: Collision,
    /// Who moves in the initial state.
    pub first: Owner,
}

impl Gridworld {
    /// A gridworld without obstacles or labels, with the default moves, forbidden collisions and
    /// the robot moving first.
    pub fn new(width: u32, height: u32, robot: Cell, adversary: Cell) -> Gridworld {
        Gridworld {
            width,
            height,
            obstacles: Vec::new(),
            robot,
            adversary,
            labels: Vec::new(),
            robot_moves: ROBOT_MOVES.to_vec(),
            adversary_moves: ADVERSARY_MOVES.to_vec(),
            collision: Collision::Forbidden,
            first: Owner::Robot,
        }
    }

    /// The name of the state with the players on these cells and `turn` to move.
    pub fn state_name(robot: Cell, adversary: Cell, turn: Owner) -> String {
        let mut name = String::new();
        Gridworld::write_state_name(&mut name, robot, adversary, turn)
            .expect("formatting into a String does not fail");
        name
    }

    /// Writes [`Gridworld::state_name`] into `out`, `((xr,yr),(xa,ya),t)`, digit by digit
    /// (the random sigma_L hashes a name per draw: no formatting machinery).
    pub fn write_state_name(
        out: &mut dyn fmt::Write,
        robot: Cell,
        adversary: Cell,
        turn: Owner,
    ) -> fmt::Result {
        let number = |out: &mut dyn fmt::Write, mut n: u32| {
            let mut digits = [0u8; 10];
            let mut start = digits.len();
            loop {
                start -= 1;
                digits[start] = b'0' + (n % 10) as u8;
                n /= 10;
                if n == 0 {
                    break;
                }
            }
            out.write_str(std::str::from_utf8(&digits[start..]).expect("ASCII digits"))
        };
        out.write_str("((")?;
        number(out, robot.x)?;
        out.write_char(',')?;
        number(out, robot.y)?;
        out.write_str("),(")?;
        number(out, adversary.x)?;
        out.write_char(',')?;
        number(out, adversary.y)?;
        out.write_str("),")?;
        out.write_str(["0", "1"][turn_number(turn)])?;
        out.write_char(')')
    }

    /// The parameters and the state naming scheme in words, a few lines for a file header.
    pub fn describe(&self) -> String {
        let cells = |cells: &mut dyn Iterator<Item = String>| {
            let list: Vec<String> = cells.collect();
            if list.is_empty() {
                "none".to_string()
            } else {
                list.join(" ")
            }
        };
        let moves = |moves: &[Move]| cells(&mut moves.iter().map(|m| m.name().to_string()));
        let first = player_name(self.first);
        format!(
            "gridworld {w}x{h}: cells (x,y) with 0 <= x < {w} eastward and 0 <= y < {h} northward\n\
             obstacles, labelled {OBSTACLE}: {obstacles}\n\
             labels: {labels}\n\
             robot: starts at {robot}, moves {robot_moves}\n\
             adversary: starts at {adversary}, moves {adversary_moves}\n\
             collisions: {collision}; the {first} moves first\n\
             state ((xr,yr),(xa,ya),t): robot at (xr,yr), adversary at (xa,ya), t = 0 if the \
             robot is to move, 1 if the adversary is; labelled as the robot's cell",
            w = self.width,
            h = self.height,
            obstacles = cells(&mut self.obstacles.iter().map(Cell::to_string)),
            labels = cells(&mut self.labels.iter().map(|(p, c)| format!("{p}={c}"))),
            robot = self.robot,
            robot_moves = moves(&self.robot_moves),
            adversary = self.adversary,
            adversary_moves = moves(&self.adversary_moves),
            collision = self.collision,
        )
    }

    /// The free cells and the numbering of the states [`Gridworld::build`] generates, after
    /// checking the grid and its obstacles.
    pub fn layout(&self) -> Result<Layout, GridworldError> {
        Layout::new(self.width, self.height, &self.obstacles)
    }

    /// Checks the parameters and generates the arena, each state with a display name in words.
    pub fn build(&self) -> Result<Arena, GridworldError> {
        self.generate(true)
    }

    /// [`Gridworld::build`] without display names, which only the arena writer shows: a third
    /// of the arena's memory on large grids (about 0.4 GB at 40×40), for arenas that are solved
    /// rather than written.
    pub fn build_without_display_names(&self) -> Result<Arena, GridworldError> {
        self.generate(false)
    }

    /// About the bytes [`Gridworld::build_without_display_names`] takes at its peak, for
    /// callers that check a memory budget before building: 64 per state and 24 per transition
    /// (an upper bound on the transitions: every move of every state). Measured: 1.0 GB at its
    /// peak for the 40x40 grid with the map's default moves (5.1 million states, 32 million
    /// transitions), 63 MB for 20x20.
    pub fn build_bytes(&self) -> Result<u64, GridworldError> {
        let free = self.layout()?.free_cells().len() as u64;
        let per_turn = free * free;
        let transitions = per_turn * (self.robot_moves.len() + self.adversary_moves.len()) as u64;
        Ok(64 * 2 * per_turn + 24 * transitions)
    }

    /// Checks every parameter as building the arena does, without making any state: what the
    /// arena and the implicit engine's rules for the map both start from.
    pub(crate) fn check(&self) -> Result<Checked<'_>, GridworldError> {
        let grid = self.layout()?;
        let robot = grid.free_index(|| "the robot's initial cell".to_string(), self.robot)?;
        let adversary = grid.free_index(
            || "the adversary's initial cell".to_string(),
            self.adversary,
        )?;
        if robot == adversary && self.collision == Collision::Forbidden {
            return Err(GridworldError::SameStart(self.robot));
        }
        let cell_labels = self.cell_labels(&grid)?;
        for (player, moves) in [
            ("robot", &self.robot_moves),
            ("adversary", &self.adversary_moves),
        ] {
            if moves.is_empty() {
                return Err(GridworldError::NoMoves(player));
            }
            for (i, m) in moves.iter().enumerate() {
                if moves[..i].contains(m) {
                    let name = m.name();
                    return Err(GridworldError::RepeatedMove { player, name });
                }
            }
        }

        let shared_label = match &self.collision {
            Collision::Label(name) if name.is_empty() => {
                return Err(GridworldError::EmptyProposition);
            }
            Collision::Label(name) => Some(name.as_str()),
            _ => None,
        };
        let mut propositions: Vec<&str> = Vec::new();
        let labels = self.labels.iter().map(|(p, _)| p.as_str());
        for p in labels.chain([OBSTACLE]).chain(shared_label) {
            if !propositions.contains(&p) {
                propositions.push(p);
            }
        }
        Ok(Checked {
            grid,
            robot,
            adversary,
            cell_labels,
            shared_label,
            propositions,
        })
    }

    fn generate(&self, display_names: bool) -> Result<Arena, GridworldError> {
        let Checked {
            grid,
            robot,
            adversary,
            cell_labels,
            shared_label,
            propositions,
        } = self.check()?;
        let mut builder = ArenaBuilder::new();
        for p in propositions {
            builder.proposition(p);
        }
        for m in self.robot_moves.iter().chain(&self.adversary_moves) {
            builder.action(m.name());
        }
        let f = grid.free.len();
        let id = |turn, r, a| grid.id(turn, r, a);
        let turns = [Owner::Robot, Owner::Adversary];
        for turn in turns {
            for (r, &robot) in grid.free.iter().enumerate() {
                for (a, &adversary) in grid.free.iter().enumerate() {
                    let shared = shared_label.filter(|_| r == a);
                    let label = cell_labels[r].iter().copied().chain(shared);
                    let display = display_names.then(|| {
                        format!(
                            "robot at {robot}, adversary at {adversary}, {} to move",
                            player_name(turn)
                        )
                    });
                    let name = Gridworld::state_name(robot, adversary, turn);
                    builder.add_state(&name, turn, label, display)?;
                }
            }
        }
        let forbidden = self.collision == Collision::Forbidden;
        for turn in turns {
            let next = match turn {
                Owner::Robot => Owner::Adversary,
                Owner::Adversary => Owner::Robot,
            };
            for r in 0..f {
                for a in 0..f {
                    let (mover, other, moves) = match turn {
                        Owner::Robot => (r, a, &self.robot_moves),
                        Owner::Adversary => (a, r, &self.adversary_moves),
                    };
                    for &m in moves {
                        let Some(target) = grid.step(mover, m) else {
                            continue;
                        };
                        if forbidden && target == other {
                            continue;
                        }
                        let successor = match turn {
                            Owner::Robot => id(next, target, a),
                            Owner::Adversary => id(next, r, target),
                        };
                        builder.add_transition(id(turn, r, a), m.name(), successor)?;
                    }
                }
            }
        }
        builder.set_initial(id(self.first, robot, adversary));
        Ok(builder.build()?)
    }

    /// The propositions of each free cell, in order of `labels`, after checking the labels.
    fn cell_labels(&self, grid: &Layout) -> Result<Vec<Vec<&str>>, GridworldError> {
        let mut cell_labels = vec![Vec::new(); grid.free.len()];
        for (proposition, cell) in &self.labels {
            if proposition.is_empty() {
                return Err(GridworldError::EmptyProposition);
            }
            let what = || format!("cell of label {proposition}");
            let labels: &mut Vec<&str> = &mut cell_labels[grid.free_index(what, *cell)?];
            if labels.contains(&proposition.as_str()) {
                return Err(GridworldError::Repeated {
                    what: what(),
                    cell: *cell,
                });
            }
            labels.push(proposition);
        }
        Ok(cell_labels)
    }
}

/// The `t` of state names: 0 when the robot is to move, 1 when the adversary is.
fn turn_number(turn: Owner) -> usize {
    match turn {
        Owner::Robot => 0,
        Owner::Adversary => 1,
    }
}

fn player_name(player: Owner) -> &'static str {
    match player {
        Owner::Robot => "robot",
        Owner::Adversary => "adversary",
    }
}

/// The most states a gridworld may have: with at most one transition per move, its transitions
/// must still be numbered by `u32`.
const MAX_STATES: u128 = u32::MAX as u128 / Move::ALL.len() as u128;

/// A gridworld whose parameters passed every check ([`Gridworld::check`]).
pub(crate) struct Checked<'g> {
    /// The free cells and their moves.
    pub(crate) grid: Layout,
    /// The players' initial cells, as indices among the free cells.
    pub(crate) robot: usize,
    pub(crate) adversary: usize,
    /// The propositions of each free cell, in the order of the labels given.
    pub(crate) cell_labels: Vec<Vec<&'g str>>,
    /// The proposition that a shared cell adds (collision rule `label:NAME`).
    pub(crate) shared_label: Option<&'g str>,
    /// The arena's propositions in declaration order: the labels', the obstacles', the shared
    /// cells'.
    pub(crate) propositions: Vec<&'g str>,
}

/// The free cells of a grid, the moves between them, and the numbering of a gridworld's states
/// by turn, robot cell and adversary cell.
#[derive(Clone, Debug)]
pub struct Layout {
    width: u32,
    height: u32,
    /// The free cells, by `x` then `y`.
    free: Vec<Cell>,
    /// The index in `free` of each cell (numbered `x * height + y`), `None` for obstacles.
    index: Vec<Option<usize>>,
}

impl Layout {
    /// Checks the size and the obstacles, and lists the free cells.
    fn new(width: u32, height: u32, obstacles: &[Cell]) -> Result<Layout, GridworldError> {
        if width == 0 || height == 0 {
            return Err(GridworldError::EmptyGrid { width, height });
        }
        let number = |cell: Cell| cell.x as usize * height as usize + cell.y as usize;
        let mut blocked = BitSet::new();
        for &cell in obstacles {
            if cell.x >= width || cell.y >= height {
                let what = "obstacle".to_string();
                return Err(GridworldError::OffGrid {
                    what,
                    cell,
                    width,
                    height,
                });
            }
            if !blocked.insert(number(cell)) {
                let what = "obstacle".to_string();
                return Err(GridworldError::Repeated { what, cell });
            }
        }
        // Obstacles are distinct cells of the grid, so the subtraction cannot overflow.
        let free_cells = u64::from(width) * u64::from(height) - obstacles.len() as u64;
        let states = u128::from(free_cells).pow(2).checked_mul(2);
        if states.is_none_or(|states| states > MAX_STATES) {
            return Err(GridworldError::TooLarge { free_cells });
        }
        let mut free = Vec::new();
        let mut index = Vec::with_capacity(width as usize * height as usize);
        for x in 0..width {
            for y in 0..height {
                let cell = Cell { x, y };
                if blocked.contains(number(cell)) {
                    index.push(None);
                } else {
                    index.push(Some(free.len()));
                    free.push(cell);
                }
            }
        }
        Ok(Layout {
            width,
            height,
            free,
            index,
        })
    }

    /// The free cells, by `x` then `y`.
    pub fn free_cells(&self) -> &[Cell] {
        &self.free
    }

    /// The state with the robot on `robot`, the adversary on `adversary` and `turn` to move;
    /// `None` unless both cells are free.
    pub fn state(&self, robot: Cell, adversary: Cell, turn: Owner) -> Option<StateId> {
        Some(self.id(turn, self.index(robot)?, self.index(adversary)?))
    }

    /// The robot's cell, the adversary's cell and the player to move in `state`, which must be
    /// a state of this layout's gridworld.
    pub fn cells(&self, state: StateId) -> (Cell, Cell, Owner) {
        let f = self.free.len();
        let state = state.index();
        let turn = if state < f * f {
            Owner::Robot
        } else {
            Owner::Adversary
        };
        let within = state % (f * f);
        (self.free[within / f], self.free[within % f], turn)
    }

    /// The state id of free cells `r` (robot) and `a` (adversary), by their indices.
    fn id(&self, turn: Owner, r: usize, a: usize) -> StateId {
        let f = self.free.len();
        StateId::new(turn_number(turn) * f * f + r * f + a)
    }

    /// The index of `cell` among the free cells, `None` for an obstacle or a cell off the grid.
    fn index(&self, cell: Cell) -> Option<usize> {
        if cell.x >= self.width || cell.y >= self.height {
            return None;
        }
        self.index[cell.x as usize * self.height as usize + cell.y as usize]
    }

    /// Like [`Layout::index`], with an error naming `what` the cell is for.
    fn free_index(&self, what: impl Fn() -> String, cell: Cell) -> Result<usize, GridworldError> {
        if cell.x >= self.width || cell.y >= self.height {
            let (width, height) = (self.width, self.height);
            let what = what();
            return Err(GridworldError::OffGrid {
                what,
                cell,
                width,
                height,
            });
        }
        self.index(cell)
            .ok_or_else(|| GridworldError::OnObstacle { what: what(), cell })
    }

    /// The free cell that move `m` leads to from free cell `from`, if any.
    pub(crate) fn step(&self, from: usize, m: Move) -> Option<usize> {
        let (dx, dy) = m.offset();
        let cell = self.free[from];
        let x = u32::try_from(i64::from(cell.x) + dx).ok()?;
        let y = u32::try_from(i64::from(cell.y) + dy).ok()?;
        self.index(Cell { x, y })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cell(x: u32, y: u32) -> Cell {
        Cell { x, y }
    }

    /// A 2×2 grid without obstacles; the robot moves E or N, the adversary W or stays.
    fn small() -> Gridworld {
        Gridworld {
            labels: vec![("A".to_string(), cell(1, 0))],
            robot_moves: vec![Move::E, Move::N],
            adversary_moves: vec![Move::W, Move::Stay],
            ..Gridworld::new(2, 2, cell(0, 0), cell(1, 1))
        }
    }

    /// The moves from the state with the robot on `r`, the adversary on `a` and `turn` to move,
    /// as (action, successor name).
    fn moves(arena: &Arena, r: Cell, a: Cell, turn: Owner) -> Vec<(String, String)> {
        let state = arena
            .find_state(&Gridworld::state_name(r, a, turn))
            .expect("state exists");
        assert_eq!(arena.owner(state), turn);
        arena
            .edges(state)
            .map(|(m, t)| (arena.action_name(m).to_string(), arena.name(t).to_string()))
            .collect()
    }

    fn expected(list: &[(&str, &str)]) -> Vec<(String, String)> {
        list.iter()
            .map(|&(a, t)| (a.to_string(), t.to_string()))
            .collect()
    }

    fn label<'a>(arena: &'a Arena, name: &str) -> Vec<&'a str> {
        let state = arena.find_state(name).expect("state exists");
        arena
            .label(state)
            .iter()
            .map(|p| arena.propositions()[p].as_str())
            .collect()
    }

    #[test]
    fn a_small_grid_worked_out_by_hand() {
        let arena = small().build().unwrap();
        assert_eq!(arena.num_states(), 2 * 4 * 4);
        assert_eq!(arena.name(arena.initial()), "((0,0),(1,1),0)");
        assert_eq!(arena.propositions(), ["A", "O"]);
        assert_eq!(arena.actions(), ["E", "N", "W", "STAY"]);
        let (r, a) = (Owner::Robot, Owner::Adversary);
        assert_eq!(
            moves(&arena, cell(0, 0), cell(1, 1), r),
            expected(&[("E", "((1,0),(1,1),1)"), ("N", "((0,1),(1,1),1)")])
        );
        assert_eq!(
            moves(&arena, cell(1, 0), cell(1, 1), a),
            expected(&[("W", "((1,0),(0,1),0)"), ("STAY", "((1,0),(1,1),0)")])
        );
        // E runs into the adversary, and collisions are forbidden.
        assert_eq!(
            moves(&arena, cell(0, 0), cell(1, 0), r),
            expected(&[("N", "((0,1),(1,0),1)")])
        );
        // Off the grid to the east and north.
        assert_eq!(moves(&arena, cell(1, 1), cell(0, 0), r), expected(&[]));
        // Sharing a cell (unreachable under this rule), the adversary cannot stay either.
        assert_eq!(
            moves(&arena, cell(1, 0), cell(1, 0), a),
            expected(&[("W", "((1,0),(0,0),0)")])
        );
        // The label is the robot's cell's, whoever is to move and wherever the adversary is.
        assert_eq!(label(&arena, "((1,0),(1,1),1)"), ["A"]);
        assert_eq!(label(&arena, "((1,0),(0,0),0)"), ["A"]);
        assert!(label(&arena, "((0,0),(1,0),0)").is_empty());
        assert_eq!(
            arena.display(arena.initial()),
            Some("robot at (0,0), adversary at (1,1), robot to move")
        );
    }

    #[test]
    fn the_layout_numbers_states_as_the_arena_names_them() {
        let world = Gridworld {
            obstacles: vec![cell(0, 1)],
            ..small()
        };
        let (arena, layout) = (world.build().unwrap(), world.layout().unwrap());
        assert_eq!(layout.free_cells(), [cell(0, 0), cell(1, 0), cell(1, 1)]);
        for state in arena.states() {
            let (r, a, turn) = layout.cells(state);
            assert_eq!(arena.name(state), Gridworld::state_name(r, a, turn));
            assert_eq!(layout.state(r, a, turn), Some(state));
        }
        assert_eq!(layout.state(cell(0, 1), cell(0, 0), Owner::Robot), None);
        assert_eq!(layout.state(cell(2, 0), cell(0, 0), Owner::Robot), None);
    }

    #[test]
    fn without_display_names_the_arena_is_the_same_otherwise() {
        let (named, unnamed) = (
            small().build().unwrap(),
            small().build_without_display_names().unwrap(),
        );
        assert!(unnamed.states().all(|s| unnamed.display(s).is_none()));
        assert_eq!(named.num_states(), unnamed.num_states());
        for s in named.states() {
            assert_eq!(named.name(s), unnamed.name(s));
            assert_eq!(named.owner(s), unnamed.owner(s));
            assert_eq!(named.label(s), unnamed.label(s));
            assert!(named.edges(s).eq(unnamed.edges(s)));
        }
        assert_eq!(named.initial(), unnamed.initial());
    }

    #[test]
    fn collision_rules_and_who_moves_first() {
        let allowed = Gridworld {
            collision: Collision::Allowed,
            first: Owner::Adversary,
            ..small()
        }
        .build()
        .unwrap();
        assert_eq!(allowed.name(allowed.initial()), "((0,0),(1,1),1)");
        assert_eq!(
            moves(&allowed, cell(0, 0), cell(1, 0), Owner::Robot),
            expected(&[("E", "((1,0),(1,0),1)"), ("N", "((0,1),(1,0),1)")])
        );
        assert!(label(&allowed, "((1,0),(1,0),1)") == ["A"]);

        let labelled = Gridworld {
            collision: Collision::Label("C".to_string()),
            ..small()
        }
        .build()
        .unwrap();
        assert_eq!(labelled.propositions(), ["A", "O", "C"]);
        assert_eq!(
            moves(&labelled, cell(1, 0), cell(1, 0), Owner::Adversary),
            expected(&[("W", "((1,0),(0,0),0)"), ("STAY", "((1,0),(1,0),0)")])
        );
        assert_eq!(label(&labelled, "((1,0),(1,0),1)"), ["A", "C"]);
        assert_eq!(label(&labelled, "((0,1),(0,1),0)"), ["C"]);
        assert!(label(&labelled, "((0,1),(1,1),0)").is_empty());
    }

    #[test]
    fn obstacles_remove_cells_and_moves() {
        let world = Gridworld {
            obstacles: vec![cell(0, 1)],
            ..small()
        };
        let arena = world.build().unwrap();
        assert_eq!(arena.num_states(), 2 * 3 * 3);
        assert!(arena.find_state("((0,1),(1,1),0)").is_none());
        // N from (0,0) is the obstacle.
        assert_eq!(
            moves(&arena, cell(0, 0), cell(1, 1), Owner::Robot),
            expected(&[("E", "((1,0),(1,1),1)")])
        );
        // W from (1,1) is the obstacle.
        assert_eq!(
            moves(&arena, cell(1, 0), cell(1, 1), Owner::Adversary),
            expected(&[("STAY", "((1,0),(1,1),0)")])
        );
        // No state is labelled O: nobody stands on an obstacle.
        assert!(arena.states().all(|s| arena.label(s).count() <= 1));
    }

    #[test]
    fn invalid_parameters_are_refused_with_a_reason() {
        let cases: Vec<(Gridworld, &str)> = vec![
            (
                Gridworld {
                    width: 0,
                    ..small()
                },
                "the grid is 0x2",
            ),
            (
                Gridworld {
                    obstacles: vec![cell(2, 0)],
                    ..small()
                },
                "obstacle (2,0) is off the 2x2 grid",
            ),
            (
                Gridworld {
                    obstacles: vec![cell(0, 1), cell(0, 1)],
                    ..small()
                },
                "obstacle (0,1) is given twice",
            ),
            (
                Gridworld {
                    obstacles: vec![cell(0, 0)],
                    ..small()
                },
                "the robot's initial cell (0,0) is an obstacle",
            ),
            (
                Gridworld {
                    adversary: cell(1, 5),
                    ..small()
                },
                "the adversary's initial cell (1,5) is off the 2x2 grid",
            ),
            (
                Gridworld {
                    adversary: cell(0, 0),
                    ..small()
                },
                "both players start on (0,0), but collisions are forbidden",
            ),
            (
                Gridworld {
                    obstacles: vec![cell(1, 0)],
                    ..small()
                },
                "cell of label A (1,0) is an obstacle",
            ),
            (
                Gridworld {
                    labels: vec![("B".into(), cell(3, 3))],
                    ..small()
                },
                "cell of label B (3,3) is off the 2x2 grid",
            ),
            (
                Gridworld {
                    labels: vec![("B".into(), cell(0, 1)); 2],
                    ..small()
                },
                "cell of label B (0,1) is given twice",
            ),
            (
                Gridworld {
                    labels: vec![(String::new(), cell(0, 1))],
                    ..small()
                },
                "a proposition name cannot be empty",
            ),
            (
                Gridworld {
                    collision: Collision::Label(String::new()),
                    ..small()
                },
                "a proposition name cannot be empty",
            ),
            (
                Gridworld {
                    robot_moves: vec![],
                    ..small()
                },
                "the robot has no moves",
            ),
            (
                Gridworld {
                    adversary_moves: vec![Move::W, Move::W],
                    ..small()
                },
                "move W is given twice for the adversary",
            ),
            (
                Gridworld {
                    width: 100_000,
                    height: 100_000,
                    ..small()
                },
                "the grid has 10000000000 free cells, hence 2 x 10000000000^2 states",
            ),
            (
                Gridworld {
                    width: u32::MAX,
                    height: u32::MAX,
                    ..small()
                },
                "the grid has 18446744065119617025 free cells",
            ),
            // 2 x 15446^2 = 477157832 states would fit, 2 x 15447^2 = 477219618 do not.
            (
                Gridworld {
                    width: 15447,
                    height: 1,
                    labels: vec![],
                    ..small()
                },
                "the grid has 15447 free cells",
            ),
        ];
        for (world, message) in cases {
            match world.build() {
                Ok(_) => panic!("accepted {world:?}"),
                Err(e) => assert!(e.to_string().contains(message), "`{e}` lacks `{message}`"),
            }
        }
        let shared_start = Gridworld {
            adversary: cell(0, 0),
            collision: Collision::Allowed,
            ..small()
        };
        assert!(shared_start.build().is_ok());
    }

    #[test]
    fn parameters_parse_from_their_command_line_spelling() {
        assert_eq!("3,14".parse::<Cell>(), Ok(cell(3, 14)));
        for bad in ["3", "3;4", "-1,2", "a,b", "1,2,3", ""] {
            assert_eq!(
                bad.parse::<Cell>(),
                Err(GridworldError::BadCell(bad.to_string()))
            );
        }
        assert_eq!("NE".parse::<Move>(), Ok(Move::NE));
        assert_eq!("STAY".parse::<Move>(), Ok(Move::Stay));
        assert_eq!(
            "ne".parse::<Move>(),
            Err(GridworldError::BadMove("ne".into()))
        );
        for rule in ["forbidden", "allowed", "label:crash"] {
            assert_eq!(rule.parse::<Collision>().unwrap().to_string(), rule);
        }
        assert!("sometimes".parse::<Collision>().is_err());
        for m in Move::ALL {
            assert_eq!(m.name().parse::<Move>(), Ok(m));
        }
    }

    #[test]
    fn a_state_name_is_written_as_its_cells_display_it() {
        for (robot, adversary, turn) in [
            (Cell { x: 0, y: 0 }, Cell { x: 9, y: 10 }, Owner::Robot),
            (
                Cell {
                    x: 123,
                    y: 4_000_000_000,
                },
                Cell { x: 70, y: 1 },
                Owner::Adversary,
            ),
        ] {
            let expected = format!("({robot},{adversary},{})", turn_number(turn));
            assert_eq!(Gridworld::state_name(robot, adversary, turn), expected);
        }
    }
}

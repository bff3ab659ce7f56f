//! The map format (`grammar/map.ebnf`, docs/formats.md): a gridworld drawn as text → [`Gridworld`].
//!
//! A map is the header line [`HEADER`], optional settings (moves, collision rule, who moves
//! first), then a `grid` line and the grid row by row, north at the top, cells separated by
//! spaces. The reader only fills in the generator's parameters; [`Gridworld::build`] makes the
//! arena, so a map and the equivalent `hypersynth gridworld` options give the same arena.
//!
//! Lexical rules are the arena format's (`syntax.rs`): lines end with LF or CR LF, tokens are
//! separated by spaces or tabs, `#` starts a comment. Columns count characters.
//!
//! Where the parameters need an order, the map's is the generator's cell order (`x`, then `y`):
//! obstacles and labelled cells are listed by cell, and a cell's propositions in written order,
//! so that the arena's propositions are declared in that order.
//!
//! Cost: linear in the text; the grid is checked against the generator's size limit before any
//! state is made.

use crate::diagnostic::{Collector, DEFAULT_LIMIT, Diagnostic, Diagnostics, brief};
use crate::position::Position;

use super::gridworld::{Cell, Collision, Gridworld, GridworldError, Move};
use super::model::Owner;
use super::syntax::{lines, owner, owner_keyword};

/// The first line of every map: the format and its version.
pub const HEADER: &str = "hypersynth map v1";

/// Whether `text` starts like a map (its first line begins with `hypersynth map`), whatever the
/// version: what the command line uses to tell maps from arenas.
pub fn is_map(text: &str) -> bool {
    let first = lines(text).next().map_or("", |(_, line)| line);
    let mut words = first.split([' ', '\t']).filter(|w| !w.is_empty());
    words.next() == Some("hypersynth") && words.next() == Some("map")
}

/// One reason why a text is not a map, and where: `message` is the kind of error.
pub type MapError = Diagnostic<MapErrorKind>;

/// What is wrong in a map; its `Display` is the message.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum MapErrorKind {
    /// The first line is not a map header.
    #[error("expected the header `{HEADER}` on the first line")]
    MissingHeader,
    /// The header names a version of the format this reader does not know; the version given.
    #[error("unsupported map version `{}`: this reader knows `{HEADER}`", brief(.0))]
    UnsupportedVersion(String),
    /// A setting line starts with an unknown keyword, given.
    #[error(
        "unknown setting `{}`: expected `robot-moves`, `adversary-moves`, `collision`, `first` \
         or `grid`",
        brief(.0)
    )]
    UnknownSetting(String),
    /// A setting is given on two lines.
    #[error("second `{setting}` line (the first is on line {first_line})")]
    RepeatedSetting {
        /// The setting's keyword.
        setting: &'static str,
        /// The line of its first occurrence.
        first_line: usize,
    },
    /// A word that is not a move's name.
    #[error("`{}` is not a move: expected one of N S E W NE NW SE SW STAY", brief(.0))]
    BadMove(String),
    /// A move named twice in one setting; the move's name.
    #[error("move {0} is given twice")]
    RepeatedMove(&'static str),
    /// The given player's moves setting lists no moves.
    #[error("the {} needs at least one move", owner_keyword(*.0))]
    NoMoves(Owner),
    /// The text at this place is not what the syntax allows.
    #[error("expected {expected}, found {found}")]
    Expected {
        /// What the syntax allows, in words.
        expected: &'static str,
        /// What was found, in words or quoted.
        found: String,
    },
    /// A word that is not a valid proposition name.
    #[error(
        "`{}` is not a proposition name: letters, digits and `_`, not starting with a digit",
        brief(.0)
    )]
    BadProposition(String),
    /// The settings are not followed by a `grid` line.
    #[error("no `grid` line: the grid must follow the settings")]
    MissingGrid,
    /// The `grid` line is followed by no row.
    #[error("the grid has no rows")]
    NoRows,
    /// A cell's text is none of the cell forms; the text given.
    #[error(
        "unknown cell `{}`: expected `.` (free), `O` (obstacle), `@r` (robot start), `@a` \
         (adversary start), propositions, or several of the last three joined by `+`",
        brief(.0)
    )]
    UnknownCell(String),
    /// An obstacle cell carries something else too (a start or the proposition given).
    #[error("an obstacle cell cannot also carry `{}`", brief(.0))]
    ObstacleWithMore(String),
    /// A proposition named twice in one cell.
    #[error("proposition `{}` is given twice in this cell", brief(.0))]
    RepeatedInCell(String),
    /// A row has more cells than the first row (reported at the first cell too many).
    #[error(
        "this row has {found} cells or more, but the first row (line {first_line}) has {width}"
    )]
    LongRow {
        /// The number of cells of the first row.
        width: usize,
        /// The number of cells counted up to the first cell too many (`width + 1`).
        found: usize,
        /// The line of the first row.
        first_line: usize,
    },
    /// A row has fewer cells than the first row.
    #[error("this row has {found} cells, but the first row (line {first_line}) has {width}")]
    ShortRow {
        /// The number of cells of the first row.
        width: usize,
        /// The number of cells of this row.
        found: usize,
        /// The line of the first row.
        first_line: usize,
    },
    /// A player has two start cells.
    #[error("second start of the {} (the first is at {first})", owner_keyword(*.player))]
    RepeatedStart {
        /// The player.
        player: Owner,
        /// The position of its first start.
        first: Position,
    },
    /// The given player starts on an obstacle.
    #[error("the {} cannot start on an obstacle", owner_keyword(*.0))]
    StartOnObstacle(Owner),
    /// Both players start on one cell under [`Collision::Forbidden`].
    #[error("both players start on this cell, but collisions are forbidden")]
    SameStart,
    /// The grid has no start cell for the given player.
    #[error("the grid has no start of the {} (`{}`)", owner_keyword(*.0), start_marker(*.0))]
    MissingStart(Owner),
    /// The generator refused the parameters read (the grid is too large, say).
    #[error(transparent)]
    Gridworld(GridworldError),
}

/// Reads a map into the generator's parameters; on errors, the first 20 in file order (see
/// [`parse_with_limit`]).
pub fn parse(text: &str) -> Result<Gridworld, Diagnostics<MapErrorKind>> {
    parse_with_limit(text, DEFAULT_LIMIT)
}

/// Reads a map into the generator's parameters; on errors, the first `limit` in file order and
/// the number of the others.
///
/// A wrong header is the only error reported: the text is not a map of this version, so
/// whatever follows is not worth checking. Otherwise reading goes on after an error: at the
/// next line after a malformed or repeated setting, at the next move or cell after a bad move
/// or cell. A cell's starts count even when the cell is wrong, and a row of the wrong width is
/// still read cell by cell, so that neither gives a missing-start error too. The size limit is
/// checked only on a map without errors.
pub fn parse_with_limit(text: &str, limit: usize) -> Result<Gridworld, Diagnostics<MapErrorKind>> {
    let mut lines = lines(text);
    let (_, first) = lines.next().unwrap_or((1, ""));
    let header = tokens(first);
    let at = |column| Position { line: 1, column };
    match header.as_slice() {
        [(_, "hypersynth"), (_, "map"), (_, "v1")] => {}
        [(_, "hypersynth"), (_, "map"), (column, version), ..] => {
            let kind = MapErrorKind::UnsupportedVersion(version.to_string());
            return Err(Diagnostic::new(at(*column), kind).into());
        }
        _ => return Err(Diagnostic::new(at(1), MapErrorKind::MissingHeader).into()),
    }
    let mut reader = Reader::new(limit);
    for (number, line) in lines {
        if let Err(error) = reader.line(number, line) {
            reader.errors.push(error);
        }
    }
    reader.finish(text)
}

/// The tokens of a line before any comment, with their 1-based character columns.
fn tokens(line: &str) -> Vec<(usize, &str)> {
    let line = line.split('#').next().unwrap_or("");
    let mut tokens = Vec::new();
    let mut start = None;
    for (column, (offset, c)) in line.char_indices().enumerate() {
        match (c == ' ' || c == '\t', start) {
            (true, Some((first_column, first_offset))) => {
                tokens.push((first_column, &line[first_offset..offset]));
                start = None;
            }
            (false, None) => start = Some((column + 1, offset)),
            _ => {}
        }
    }
    if let Some((column, offset)) = start {
        tokens.push((column, &line[offset..]));
    }
    tokens
}

/// The cell marker of a player's start.
pub fn start_marker(player: Owner) -> &'static str {
    match player {
        Owner::Robot => "@r",
        Owner::Adversary => "@a",
    }
}

/// Whether `name` may name a proposition of a cell.
fn is_proposition(name: &str) -> bool {
    name.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_')
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
}

const SETTINGS: [&str; 4] = ["robot-moves", "adversary-moves", "collision", "first"];

struct Reader {
    errors: Collector<MapErrorKind>,
    /// The line of each setting seen, indexed like [`SETTINGS`].
    setting_lines: [Option<usize>; 4],
    robot_moves: Option<Vec<Move>>,
    adversary_moves: Option<Vec<Move>>,
    collision: Option<Collision>,
    first: Option<Owner>,
    /// The line of `grid`, once seen.
    grid_line: Option<usize>,
    /// The first row's line and width.
    first_row: Option<(usize, usize)>,
    /// The rows read so far, north first; each cell is `None` for an obstacle, else its
    /// propositions.
    rows: Vec<Vec<Option<Vec<String>>>>,
    robot: Option<(Position, usize, usize)>,
    adversary: Option<(Position, usize, usize)>,
}

impl Reader {
    fn new(limit: usize) -> Reader {
        Reader {
            errors: Collector::new(limit),
            setting_lines: [None; 4],
            robot_moves: None,
            adversary_moves: None,
            collision: None,
            first: None,
            grid_line: None,
            first_row: None,
            rows: Vec::new(),
            robot: None,
            adversary: None,
        }
    }

    /// Reads a line; returns the error that ends it, if any (others are collected).
    fn line(&mut self, number: usize, line: &str) -> Result<(), MapError> {
        let tokens = tokens(line);
        let error = |column, kind| {
            let position = Position {
                line: number,
                column,
            };
            Diagnostic::new(position, kind)
        };
        let Some(&(column, keyword)) = tokens.first() else {
            return Ok(());
        };
        if self.grid_line.is_some() {
            return self.row(number, line, &tokens);
        }
        if keyword == "grid" {
            // The rows follow, even after a malformed `grid` line.
            self.grid_line = Some(number);
            if let Some(&(column, extra)) = tokens.get(1) {
                let found = format!("`{extra}`");
                let expected = "end of line after `grid`";
                return Err(error(column, MapErrorKind::Expected { expected, found }));
            }
            return Ok(());
        }
        let Some(index) = SETTINGS.iter().position(|s| *s == keyword) else {
            return Err(error(
                column,
                MapErrorKind::UnknownSetting(keyword.to_string()),
            ));
        };
        if let Some(first_line) = self.setting_lines[index] {
            let setting = SETTINGS[index];
            return Err(error(
                column,
                MapErrorKind::RepeatedSetting {
                    setting,
                    first_line,
                },
            ));
        }
        self.setting_lines[index] = Some(number);
        let values = &tokens[1..];
        let single = |expected: &'static str| match values {
            [value] => Ok(*value),
            [] => Err(error(
                line.chars().count() + 1,
                MapErrorKind::Expected {
                    expected,
                    found: "end of line".to_string(),
                },
            )),
            [_, (column, extra), ..] => Err(error(
                *column,
                MapErrorKind::Expected {
                    expected: "end of line",
                    found: format!("`{}`", brief(extra)),
                },
            )),
        };
        match index {
            0 | 1 => {
                let player = if index == 0 {
                    Owner::Robot
                } else {
                    Owner::Adversary
                };
                if values.is_empty() {
                    let column = line.chars().count() + 1;
                    return Err(error(column, MapErrorKind::NoMoves(player)));
                }
                let mut moves = Vec::new();
                for &(column, name) in values {
                    match name.parse::<Move>() {
                        Err(_) => {
                            let kind = MapErrorKind::BadMove(name.to_string());
                            self.errors.push(error(column, kind));
                        }
                        Ok(m) if moves.contains(&m) => {
                            let kind = MapErrorKind::RepeatedMove(m.name());
                            self.errors.push(error(column, kind));
                        }
                        Ok(m) => moves.push(m),
                    }
                }
                match player {
                    Owner::Robot => self.robot_moves = Some(moves),
                    Owner::Adversary => self.adversary_moves = Some(moves),
                }
            }
            2 => {
                let (column, rule) = single("`forbidden`, `allowed` or `label:NAME`")?;
                let collision = rule.parse::<Collision>().map_err(|_| {
                    error(
                        column,
                        MapErrorKind::Expected {
                            expected: "`forbidden`, `allowed` or `label:NAME`",
                            found: format!("`{}`", brief(rule)),
                        },
                    )
                })?;
                if let Collision::Label(name) = &collision
                    && !is_proposition(name)
                {
                    let kind = MapErrorKind::BadProposition(name.clone());
                    return Err(error(column + "label:".len(), kind));
                }
                self.collision = Some(collision);
            }
            _ => {
                let (column, player) = single("`robot` or `adversary`")?;
                let Some(first) = owner(player) else {
                    let expected = "`robot` or `adversary`";
                    let found = format!("`{player}`");
                    return Err(error(column, MapErrorKind::Expected { expected, found }));
                };
                self.first = Some(first);
            }
        }
        Ok(())
    }

    /// A row of the grid. A row of the wrong width is reported and read on (for its starts and
    /// cell errors), but not kept.
    fn row(&mut self, number: usize, line: &str, tokens: &[(usize, &str)]) -> Result<(), MapError> {
        let at = |column| Position {
            line: number,
            column,
        };
        let error = |column, kind| Diagnostic::new(at(column), kind);
        let (first_line, width) = *self.first_row.get_or_insert((number, tokens.len()));
        if tokens.len() > width {
            let kind = MapErrorKind::LongRow {
                width,
                found: width + 1,
                first_line,
            };
            self.errors.push(error(tokens[width].0, kind));
        }
        if tokens.len() < width {
            let found = tokens.len();
            let column = line
                .split('#')
                .next()
                .unwrap_or("")
                .trim_end()
                .chars()
                .count()
                + 1;
            let kind = MapErrorKind::ShortRow {
                width,
                found,
                first_line,
            };
            self.errors.push(error(column, kind));
        }
        let y_from_top = self.rows.len();
        let mut row = Vec::with_capacity(width);
        for (x, &(column, token)) in tokens.iter().enumerate() {
            if token == "." {
                row.push(Some(Vec::new()));
                continue;
            }
            let mut obstacle = false;
            let mut propositions: Vec<String> = Vec::new();
            let mut starts = Vec::new();
            let mut unknown = false;
            let mut part_column = column;
            for part in token.split('+') {
                match part {
                    "O" => obstacle = true,
                    marker if marker == start_marker(Owner::Robot) => {
                        starts.push((Owner::Robot, part_column));
                    }
                    marker if marker == start_marker(Owner::Adversary) => {
                        starts.push((Owner::Adversary, part_column));
                    }
                    name if is_proposition(name) => {
                        if propositions.iter().any(|p| p == name) {
                            let kind = MapErrorKind::RepeatedInCell(name.to_string());
                            self.errors.push(error(part_column, kind));
                        } else {
                            propositions.push(name.to_string());
                        }
                    }
                    // Once per cell; its other parts are still read (a start counts).
                    _ if unknown => {}
                    _ => {
                        unknown = true;
                        let kind = MapErrorKind::UnknownCell(token.to_string());
                        self.errors.push(error(column, kind));
                    }
                }
                part_column += part.chars().count() + 1;
            }
            if obstacle {
                if let Some(&(player, column)) = starts.first() {
                    self.errors
                        .push(error(column, MapErrorKind::StartOnObstacle(player)));
                } else if let Some(name) = propositions.first() {
                    let kind = MapErrorKind::ObstacleWithMore(name.clone());
                    self.errors.push(error(column, kind));
                }
            }
            for (player, column) in starts {
                let slot = match player {
                    Owner::Robot => &mut self.robot,
                    Owner::Adversary => &mut self.adversary,
                };
                match *slot {
                    Some((first, _, _)) => {
                        let kind = MapErrorKind::RepeatedStart { player, first };
                        self.errors.push(error(column, kind));
                    }
                    None => *slot = Some((at(column), x, y_from_top)),
                }
            }
            if let (Some((_, rx, ry)), Some((_, ax, ay))) = (self.robot, self.adversary)
                && (rx, ry) == (ax, ay)
                && (x, y_from_top) == (rx, ry)
                && self
                    .collision
                    .as_ref()
                    .is_none_or(|c| *c == Collision::Forbidden)
            {
                self.errors.push(error(column, MapErrorKind::SameStart));
            }
            row.push((!obstacle).then_some(propositions));
        }
        if tokens.len() == width {
            self.rows.push(row);
        }
        Ok(())
    }

    fn finish(self, text: &str) -> Result<Gridworld, Diagnostics<MapErrorKind>> {
        let mut errors = self.errors;
        let end = Position::of_offset(text, text.len());
        let Some(grid_line) = self.grid_line else {
            errors.add(end, MapErrorKind::MissingGrid);
            return Err(errors.failed());
        };
        let Some((_, width)) = self.first_row else {
            errors.add(end, MapErrorKind::NoRows);
            return Err(errors.failed());
        };
        let (Some(robot), Some(adversary)) = (self.robot, self.adversary) else {
            for (slot, player) in [
                (self.robot, Owner::Robot),
                (self.adversary, Owner::Adversary),
            ] {
                if slot.is_none() {
                    errors.add(end, MapErrorKind::MissingStart(player));
                }
            }
            return Err(errors.failed());
        };
        errors.or_ok(())?;
        let height = self.rows.len();
        let cell = |x: usize, y_from_top: usize| Cell {
            x: x as u32,
            y: (height - 1 - y_from_top) as u32,
        };
        let start = |(_, x, y): (Position, usize, usize)| cell(x, y);
        let mut world = Gridworld::new(width as u32, height as u32, start(robot), start(adversary));
        // The generator's cell order: x, then y (south first, so the last row first).
        for x in 0..width {
            for (y_from_top, row) in self.rows.iter().enumerate().rev() {
                match &row[x] {
                    None => world.obstacles.push(cell(x, y_from_top)),
                    Some(propositions) => world.labels.extend(
                        propositions
                            .iter()
                            .map(|p| (p.clone(), cell(x, y_from_top))),
                    ),
                }
            }
        }
        if let Some(moves) = self.robot_moves {
            world.robot_moves = moves;
        }
        if let Some(moves) = self.adversary_moves {
            world.adversary_moves = moves;
        }
        if let Some(collision) = self.collision {
            world.collision = collision;
        }
        if let Some(first) = self.first {
            world.first = first;
        }
        // The size limit, checked before anything is generated.
        world.layout().map_err(|e| {
            let position = Position {
                line: grid_line,
                column: 1,
            };
            Diagnostics::from(Diagnostic::new(position, MapErrorKind::Gridworld(e)))
        })?;
        Ok(world)
    }
}

/// The map of `world` in the map format, which [`parse`] reads back as `world` when its
/// obstacles and labelled cells are listed in the map's order (by cell, `x` then `y`; what
/// [`parse`] gives): settings always written, the grid north at the top, a cell's start markers
/// before its propositions, cells padded to one width.
pub fn write(world: &Gridworld) -> String {
    let moves = |moves: &[Move]| {
        let names: Vec<&str> = moves.iter().map(|m| m.name()).collect();
        names.join(" ")
    };
    let mut text = format!(
        "{HEADER}\nrobot-moves {}\nadversary-moves {}\ncollision {}\nfirst {}\ngrid\n",
        moves(&world.robot_moves),
        moves(&world.adversary_moves),
        world.collision,
        owner_keyword(world.first)
    );
    let cell_text = |x: u32, y: u32| {
        let cell = Cell { x, y };
        if world.obstacles.contains(&cell) {
            return "O".to_string();
        }
        let mut parts: Vec<&str> = Vec::new();
        if world.robot == cell {
            parts.push(start_marker(Owner::Robot));
        }
        if world.adversary == cell {
            parts.push(start_marker(Owner::Adversary));
        }
        parts.extend(
            world
                .labels
                .iter()
                .filter(|(_, at)| *at == cell)
                .map(|(name, _)| name.as_str()),
        );
        if parts.is_empty() {
            ".".to_string()
        } else {
            parts.join("+")
        }
    };
    let rows: Vec<Vec<String>> = (0..world.height)
        .rev()
        .map(|y| (0..world.width).map(|x| cell_text(x, y)).collect())
        .collect();
    let width = rows.iter().flatten().map(String::len).max().unwrap_or(1);
    for row in rows {
        let padded: Vec<String> = row.iter().map(|c| format!("{c:<width$}")).collect();
        text.push_str(padded.join(" ").trim_end());
        text.push('\n');
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cell(x: u32, y: u32) -> Cell {
        Cell { x, y }
    }

    /// The first error of reading `text`, as (line, column, message).
    fn error(text: &str) -> (usize, usize, String) {
        let errors = parse(text).expect_err("an invalid map");
        let e = errors.first();
        (e.position.line, e.position.column, e.message.to_string())
    }

    /// The errors of reading `text`, each as `LINE:COL: message`.
    fn errors(text: &str) -> Vec<String> {
        let errors = parse(text).expect_err("an invalid map");
        errors.iter().map(ToString::to_string).collect()
    }

    #[test]
    fn every_error_of_a_map_is_reported_in_file_order() {
        let text = "\
hypersynth map v1
robot-moves N NN N
speed 3
first robot adversary
grid
@r+?x . A+A
. .
O+@a . . .
";
        assert_eq!(
            errors(text),
            [
                "2:15: `NN` is not a move: expected one of N S E W NE NW SE SW STAY",
                "2:18: move N is given twice",
                "3:1: unknown setting `speed`: expected `robot-moves`, `adversary-moves`, \
                 `collision`, `first` or `grid`",
                "4:13: expected end of line, found `adversary`",
                "6:1: unknown cell `@r+?x`: expected `.` (free), `O` (obstacle), `@r` (robot \
                 start), `@a` (adversary start), propositions, or several of the last three \
                 joined by `+`",
                "6:11: proposition `A` is given twice in this cell",
                "7:4: this row has 2 cells, but the first row (line 6) has 3",
                "8:3: the adversary cannot start on an obstacle",
                "8:10: this row has 4 cells or more, but the first row (line 6) has 3",
            ]
        );
        // The starts in the wrong cells count: no missing start is reported.
        assert_eq!(
            errors(&format!("{HEADER}\ngrid now\n@r\n")),
            [
                "2:6: expected end of line after `grid`, found `now`",
                "4:1: the grid has no start of the adversary (`@a`)",
            ]
        );
        let limited = parse_with_limit(&format!("{HEADER}\nx\ny\nz\n"), 2).unwrap_err();
        assert_eq!((limited.as_slice().len(), limited.total()), (2, 4));
    }

    #[test]
    fn the_case_study_map_gives_the_case_study_parameters() {
        let world = parse(include_str!("../../../../specs/case-study/map.txt")).unwrap();
        // docs/semantics.md §11, written out independently of the map.
        let expected = Gridworld {
            obstacles: vec![cell(0, 1), cell(1, 0), cell(1, 1), cell(3, 4), cell(4, 3)],
            labels: vec![("A".into(), cell(0, 3)), ("B".into(), cell(4, 4))],
            ..Gridworld::new(5, 5, cell(0, 2), cell(4, 2))
        };
        assert_eq!(world, expected);
    }

    #[test]
    fn settings_cells_with_several_propositions_and_comments() {
        let text = "hypersynth map v1\r\n\
                    # a comment line\r\n\
                    \r\n\
                    first adversary   # trailing comment\r\n\
                    robot-moves E N\r\n\
                    adversary-moves\tSTAY\r\n\
                    collision label:crash\r\n\
                    grid\r\n\
                    @r+A+B_2 .\r\n\
                    \r\n\
                    O        @a+A\r\n";
        let world = parse(text).unwrap();
        let expected = Gridworld {
            obstacles: vec![cell(0, 0)],
            labels: vec![
                ("A".into(), cell(0, 1)),
                ("B_2".into(), cell(0, 1)),
                ("A".into(), cell(1, 0)),
            ],
            robot_moves: vec![Move::E, Move::N],
            adversary_moves: vec![Move::Stay],
            collision: Collision::Label("crash".into()),
            first: Owner::Adversary,
            ..Gridworld::new(2, 2, cell(0, 1), cell(1, 0))
        };
        assert_eq!(world, expected);
        // Both players may share a start when collisions are allowed.
        let shared = "hypersynth map v1\ncollision allowed\ngrid\n@r+@a .\n";
        assert_eq!(
            parse(shared).unwrap().robot,
            parse(shared).unwrap().adversary
        );
    }

    #[test]
    fn maps_are_recognised_by_their_header() {
        assert!(is_map("hypersynth map v1\ngrid\n"));
        assert!(is_map("hypersynth  map v2\n"));
        assert!(!is_map("# hypersynth arena v1\n"));
        assert!(!is_map("\nhypersynth map v1\n"));
        assert!(!is_map(""));
    }

    #[test]
    fn cell_errors_are_located() {
        let grid = |rows: &str| format!("{HEADER}\ngrid\n{rows}");
        let (line, column, message) = error(&grid("@r . ?x\n. . @a\n"));
        assert_eq!((line, column), (3, 6));
        assert!(message.starts_with("unknown cell `?x`"), "{message}");
        assert_eq!(error(&grid("@r A+ @a\n")).1, 4);
        assert_eq!(error(&grid("@r 1A @a\n")).1, 4);

        let (line, column, message) = error(&grid("@r . .\n. . . @a\n"));
        assert_eq!((line, column), (4, 7));
        assert_eq!(
            message,
            "this row has 4 cells or more, but the first row (line 3) has 3"
        );
        let (line, column, message) = error(&grid("@r . .\n. @a   # short\n"));
        assert_eq!((line, column), (4, 5));
        assert_eq!(
            message,
            "this row has 2 cells, but the first row (line 3) has 3"
        );

        let (line, column, message) = error(&grid("@r .\n. @a+A+@r\n"));
        assert_eq!((line, column), (4, 8));
        assert_eq!(message, "second start of the robot (the first is at 3:1)");

        let (line, column, message) = error(&grid(". O+@a\n@r .\n"));
        assert_eq!((line, column), (3, 5));
        assert_eq!(message, "the adversary cannot start on an obstacle");
        let (line, column, message) = error(&grid(". @a+O\n@r .\n"));
        assert_eq!((line, column), (3, 3));
        assert_eq!(message, "the adversary cannot start on an obstacle");

        let (line, column, message) = error(&grid(". O+A\n@r @a\n"));
        assert_eq!((line, column), (3, 3));
        assert_eq!(message, "an obstacle cell cannot also carry `A`");
        let (line, column, message) = error(&grid("@r A+B+A @a\n"));
        assert_eq!((line, column), (3, 8));
        assert_eq!(message, "proposition `A` is given twice in this cell");
        let (line, column, message) = error(&grid(". @r+@a\n"));
        assert_eq!((line, column), (3, 3));
        assert_eq!(
            message,
            "both players start on this cell, but collisions are forbidden"
        );
        let (line, column, message) = error(&grid("@r .\n. .\n"));
        assert_eq!((line, column), (5, 1));
        assert_eq!(message, "the grid has no start of the adversary (`@a`)");
    }

    #[test]
    fn header_and_setting_errors_are_located() {
        let (line, column, message) = error("hypersynth arena v1\n");
        assert_eq!((line, column), (1, 1));
        assert_eq!(
            message,
            "expected the header `hypersynth map v1` on the first line"
        );
        assert_eq!(error("hypersynth map v9\n").1, 16);
        let with = |settings: &str| format!("{HEADER}\n{settings}\ngrid\n@r @a\n");
        let (line, column, message) = error(&with("  speed 3"));
        assert_eq!((line, column), (2, 3));
        assert!(message.starts_with("unknown setting `speed`"));
        let (line, column, message) = error(&with("first robot\nfirst adversary"));
        assert_eq!((line, column), (3, 1));
        assert_eq!(message, "second `first` line (the first is on line 2)");
        assert_eq!(error(&with("robot-moves N NN")).1, 15);
        let (_, column, message) = error(&with("robot-moves N S N"));
        assert_eq!((column, message.as_str()), (17, "move N is given twice"));
        let (_, column, message) = error(&with("adversary-moves"));
        assert_eq!(
            (column, message.as_str()),
            (16, "the adversary needs at least one move")
        );
        assert_eq!(error(&with("collision sometimes")).1, 11);
        let (_, column, message) = error(&with("collision label:a-b"));
        assert_eq!(column, 17);
        assert!(message.starts_with("`a-b` is not a proposition name"));
        assert_eq!(error(&with("first nobody")).1, 7);
        assert_eq!(error(&with("first robot adversary")).1, 13);
        assert_eq!(error(&with("grid now")).1, 6);
        let (line, column, message) = error(&format!("{HEADER}\nfirst robot\n"));
        assert_eq!((line, column), (3, 1));
        assert_eq!(message, "no `grid` line: the grid must follow the settings");
        assert_eq!(
            error(&format!("{HEADER}\ngrid\n# nothing\n")).2,
            "the grid has no rows"
        );
    }

    /// The terminals the grammar quotes for the settings, moves and cell markers.
    #[test]
    fn the_grammar_names_the_readers_settings_moves_and_markers() {
        let grammar = include_str!("../../../../grammar/map.ebnf");
        let quoted = |word: &str| grammar.contains(&format!("\"{word}\""));
        assert!(
            grammar.contains(
                HEADER
                    .split(' ')
                    .map(|w| format!("\"{w}\""))
                    .collect::<Vec<_>>()
                    .join(" , ")
                    .as_str()
            )
        );
        for word in SETTINGS.iter().chain(&["grid", "O", "+", "label:"]) {
            assert!(quoted(word), "the grammar lacks {word}");
        }
        for m in Move::ALL {
            assert!(quoted(m.name()), "the grammar lacks {m}");
        }
        for player in [Owner::Robot, Owner::Adversary] {
            assert!(quoted(start_marker(player)) && quoted(owner_keyword(player)));
        }
        for rule in ["forbidden", "allowed"] {
            assert!(quoted(rule) && rule.parse::<Collision>().is_ok());
        }
    }

    #[test]
    fn a_grid_beyond_the_generators_limit_is_refused_before_generating() {
        let row = vec!["."; 20_000].join(" ");
        let text = format!("{HEADER}\ngrid\n@r @a {row}\n");
        let (line, column, message) = error(&text);
        assert_eq!((line, column), (2, 1));
        assert!(
            message.starts_with("the grid has 20002 free cells"),
            "{message}"
        );
    }

    #[test]
    fn a_written_map_reads_back_as_the_same_gridworld() {
        let case_study = include_str!("../../../../specs/case-study/map.txt");
        let decoy = include_str!("../../../../specs/decoy/map.txt");
        for text in [case_study, decoy] {
            let world = parse(text).unwrap();
            assert_eq!(parse(&write(&world)).unwrap(), world);
        }
        // Every setting away from its default, a shared start, a cell of two propositions.
        let mut world = Gridworld::new(3, 2, cell(0, 0), cell(0, 0));
        world.obstacles = vec![cell(1, 1)];
        world.labels = vec![
            ("A".into(), cell(0, 0)),
            ("B".into(), cell(2, 0)),
            ("C".into(), cell(2, 0)),
        ];
        world.robot_moves = vec![Move::E, Move::N];
        world.adversary_moves = vec![Move::Stay];
        world.collision = Collision::Label("meet".into());
        world.first = Owner::Adversary;
        let text = write(&world);
        assert_eq!(parse(&text).unwrap(), world, "{text}");
        assert_eq!(
            text.lines().skip(5).collect::<Vec<_>>(),
            ["grid", ".       O       .", "@r+@a+A .       B+C"]
        );
    }
}

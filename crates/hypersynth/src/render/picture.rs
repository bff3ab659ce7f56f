//! The drawings. Cell `(x, y)` is drawn north up: row `height - 1 - y` from the top, column
//! `x`. Every picture has its title lines at the top (unless left out), the grid with its
//! coordinates, and a legend on the right.
//!
//! A cell large enough for text (42 pixels and more) has three zones, so that nothing in it
//! overlaps: a band at the top for its propositions (on a white strip: the goal cells), `h0`
//! and the adversary's small diamond; a band at the bottom for its code or value; and the disc
//! between them for the controller's mark, which stays inside it whatever its direction. A
//! smaller cell has no text: marks fill its middle, goal cells and h0's cell are framed. In a
//! run, each player's markers sit side by side below the top band (the robot's on the left),
//! and each marker's step number is set to fit inside it. [`super::figure::overlaps`] checks
//! all of this on the finished picture.

use super::colour::{self, BLUE, GOAL_FILL, OBSTACLE_FILL, ORANGE, heat_colour};
use super::figure::{Anchor, Figure, Paint, Role, Shape};
use super::font;
use super::title::Title;
use crate::arena::Owner;
use crate::arena::gridworld::{Cell, Gridworld, Move};
use crate::game::WinLabel;

/// What the legend says of each possible label of the paper's form.
const LABEL_MEANINGS: [(&str, &str); 5] = [
    ("WWW", "phi can be forced"),
    ("WWL", "phi1 and phi2 each, not both"),
    ("WLL", "only phi1 can be forced"),
    ("LWL", "only phi2 can be forced"),
    ("LLL", "nothing can be forced"),
];

/// How the paper's win-label shows: its colour, its code (`WLL`) and its triple.
pub(super) fn win_label_tag(label: WinLabel) -> Tag {
    Tag {
        colour: colour::label_colour(label).to_string(),
        code: label.code().to_string(),
        text: label.to_string(),
    }
}

/// The legend of the paper's five possible win-labels.
pub(super) fn win_label_key() -> Key {
    let entries = LABEL_MEANINGS
        .iter()
        .map(|&(code, meaning)| {
            let label = WinLabel::ALL
                .into_iter()
                .find(|l| l.code() == code)
                .unwrap_or(WinLabel::ALL[0]);
            (
                Some(colour::label_colour(label).to_string()),
                format!("{label} {meaning}"),
            )
        })
        .collect();
    Key {
        heading: "Win-label of the robot's state".to_string(),
        entries,
    }
}

/// How a robot state shows in a picture: the fill of its cell (and of its row in a run's
/// table), the short code written in the cell, and its full label (tooltips). The explorer's
/// page carries the same tags, serialised.
#[derive(Clone, Debug, PartialEq, Eq, Hash, serde::Serialize)]
pub struct Tag {
    /// The fill, an SVG colour such as `#F0E442`.
    pub colour: String,
    /// The short code written in the cell when it is large enough, e.g. `WLL`.
    pub code: String,
    /// The full label, shown in tooltips, e.g. `(W, L, L)`.
    pub text: String,
}

/// The legend of the fills of a partition: a heading, then per line a swatch's colour (`None`:
/// a line of text alone) and its meaning.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct Key {
    /// The legend's first line.
    pub heading: String,
    /// The lines below it: a swatch's colour, or `None` for a line of text alone, and its meaning.
    pub entries: Vec<(Option<String>, String)>,
}

/// What the controller does in a robot cell.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mark {
    /// Moves (an arrow).
    Move(Move),
    /// Plays `stop` and settles for a sub-task (a square).
    Stop,
    /// Commits to a task it can force from here (a ring).
    Commit,
    /// Gives up: stuck with nothing to gain (a cross).
    GiveUp,
}

/// One robot cell of a partition picture.
#[derive(Clone, Debug, PartialEq)]
pub struct CellView {
    /// The robot's cell (the adversary's position is the slice's, the same for every cell).
    pub cell: Cell,
    /// How the robot's state there shows; `None` when the product has no such state
    /// (`--states reachable`).
    pub tag: Option<Tag>,
    /// What the controller does there; `None` without a controller (the games stage) or where its
    /// action is not a compass move.
    pub mark: Option<Mark>,
    /// The value of the state (lower bound), for the heat map.
    pub value: Option<f64>,
    /// Whether the state is the initial state h0.
    pub initial: bool,
}

/// How partition cells are filled.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shading {
    /// By win-label.
    Labels,
    /// By value, on a scale fitted to the values shown.
    Values {
        /// The largest payoff (the legend recalls it).
        max: f64,
    },
}

/// One state of a run.
#[derive(Clone, Debug, PartialEq)]
pub struct TracePoint {
    /// The robot's cell.
    pub robot: Cell,
    /// The adversary's cell.
    pub adversary: Cell,
    /// Whose move it is in this state.
    pub turn: Owner,
    /// How the state shows (its win-label).
    pub tag: Tag,
    /// The action played here, if any.
    pub action: Option<String>,
}

/// Space around everything, in pixels.
pub(super) const MARGIN: f64 = 16.0;
const TITLE_SIZE: f64 = 16.0;
const SUBTITLE_SIZE: f64 = 13.0;
pub(super) const LEGEND_SIZE: f64 = 12.5;
pub(super) const HEADING_SIZE: f64 = 13.5;
pub(super) const LEGEND_ROW: f64 = 22.0;
const SWATCH: f64 = 16.0;
pub(super) const AXIS_SIZE: f64 = 11.0;
pub(super) const GRID_LINE: &str = "#999999";
pub(super) const BLACK: &str = "#000000";
const WHITE: &str = "#FFFFFF";
/// A white outline under black text, so it reads on any fill.
const HALO: &str = "stroke=\"#FFFFFF\" stroke-width=\"2.5\" paint-order=\"stroke\" \
                    stroke-linejoin=\"round\"";

/// The pixel layout of a grid picture.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Geometry {
    /// The side of a cell, in pixels.
    pub cell: f64,
    /// The x coordinate of the grid's left edge, in pixels.
    pub left: f64,
    /// The y coordinate of the grid's top edge, below the title lines, in pixels.
    pub top: f64,
    width: u32,
    height: u32,
}

impl Geometry {
    /// The layout of `world` with its top edge at `top`: cells of 14 to 72 pixels, the grid at
    /// most about 720 pixels wide.
    pub fn new(world: &Gridworld, top: f64) -> Geometry {
        let side = f64::from(world.width.max(world.height));
        Geometry {
            cell: (720.0 / side).floor().clamp(14.0, 72.0),
            left: MARGIN + 34.0,
            top,
            width: world.width,
            height: world.height,
        }
    }

    /// The top-left corner of `cell`.
    pub fn corner(&self, cell: Cell) -> (f64, f64) {
        let row = f64::from(self.height - 1 - cell.y);
        (
            self.left + f64::from(cell.x) * self.cell,
            self.top + row * self.cell,
        )
    }

    /// The centre of `cell`, in pixels.
    pub fn centre(&self, cell: Cell) -> (f64, f64) {
        let (x, y) = self.corner(cell);
        (x + self.cell / 2.0, y + self.cell / 2.0)
    }

    fn grid_right(&self) -> f64 {
        self.left + f64::from(self.width) * self.cell
    }

    fn grid_bottom(&self) -> f64 {
        self.top + f64::from(self.height) * self.cell
    }

    /// Whether cells are large enough for text.
    fn roomy(&self) -> bool {
        self.cell >= 42.0
    }

    /// Whether cells are large enough for frames (goal and h0 cells when not roomy).
    fn framed(&self) -> bool {
        self.cell >= 24.0
    }

    /// The font size of the text in cells.
    fn code_size(&self) -> f64 {
        (self.cell * 0.17).clamp(8.0, 12.0)
    }

    /// The height of the text bands at the top and bottom of a cell (0 without text).
    fn band(&self) -> f64 {
        if self.roomy() {
            (self.code_size() * 1.3).ceil()
        } else {
            0.0
        }
    }

    /// The disc of `cell` a controller's mark stays in: its centre and radius.
    fn disc(&self, cell: Cell) -> ((f64, f64), f64) {
        let r = if self.roomy() {
            self.cell / 2.0 - self.band() - 1.5
        } else {
            self.cell * 0.3
        };
        (self.centre(cell), r)
    }

    /// Where a player's marker of a run stands in `cell` (the robot on the left, the
    /// adversary on the right, below the top band), and its radius.
    fn marker(&self, cell: Cell, player: Owner) -> ((f64, f64), f64) {
        let (x, y) = self.corner(cell);
        let c = self.cell;
        let band = if self.roomy() { self.band() } else { 0.3 * c };
        let cy = y + band + (c - band) / 2.0;
        let r = (0.19 * c).min((c - band) / 2.0 - 2.5);
        let cx = match player {
            Owner::Robot => x + 0.27 * c,
            Owner::Adversary => x + 0.73 * c,
        };
        ((cx, cy), r)
    }

    /// The screen direction of a move (y grows downwards on screen).
    fn direction(m: Move) -> (f64, f64) {
        let (dx, dy) = m.offset();
        let length = ((dx * dx + dy * dy) as f64).sqrt().max(1.0);
        (dx as f64 / length, -dy as f64 / length)
    }
}

/// Writes `title`'s lines at the top left of `figure` (the first one larger); returns where
/// the content below them starts and how far right they reach.
pub(super) fn title_lines(figure: &mut Figure, title: &Title) -> (f64, f64) {
    let mut y = MARGIN;
    let mut right: f64 = 0.0;
    for (i, line) in title.lines.iter().enumerate() {
        let size = if i == 0 { TITLE_SIZE } else { SUBTITLE_SIZE };
        let baseline = y + font::ASCENT * size;
        let (_, _, r, _) = figure.text(
            (MARGIN, baseline),
            size,
            Anchor::Start,
            BLACK,
            "",
            line,
            false,
        );
        right = right.max(r);
        y = baseline + font::DESCENT * size + 0.3 * size;
    }
    let top = if title.lines.is_empty() {
        MARGIN
    } else {
        y + 14.0
    };
    (top, right)
}

/// A player's shape centred on `centre`, `r` in radius: the robot a circle, the adversary a
/// diamond (a little larger, so that it holds as much text).
fn player_shape(player: Owner, (cx, cy): (f64, f64), r: f64) -> Shape {
    match player {
        Owner::Robot => Shape::Circle {
            centre: (cx, cy),
            r,
        },
        Owner::Adversary => {
            let r = r * 1.15;
            Shape::Polygon(vec![(cx, cy - r), (cx + r, cy), (cx, cy + r), (cx - r, cy)])
        }
    }
}

fn player_colour(player: Owner) -> &'static str {
    match player {
        Owner::Robot => BLUE,
        Owner::Adversary => ORANGE,
    }
}

/// A picture under construction: the figure, its layout, the legend's next line and how far
/// the content reaches.
struct Canvas<'w> {
    figure: Figure,
    geometry: Geometry,
    world: &'w Gridworld,
    legend_x: f64,
    legend_y: f64,
    right: f64,
}

impl<'w> Canvas<'w> {
    fn new(world: &'w Gridworld, title: &Title) -> Canvas<'w> {
        let mut figure = Figure::new(0.0, 0.0, &title.description);
        let (top, right) = title_lines(&mut figure, title);
        let geometry = Geometry::new(world, top);
        Canvas {
            figure,
            geometry,
            world,
            legend_x: geometry.grid_right() + 32.0,
            legend_y: top,
            right: right.max(geometry.grid_right()),
        }
    }

    fn text(&mut self, at: (f64, f64), size: f64, anchor: Anchor, colour: &str, text: &str) {
        let (_, _, r, _) = self.figure.text(at, size, anchor, colour, "", text, false);
        self.right = self.right.max(r);
    }

    /// The finished SVG.
    fn finish(mut self) -> String {
        let g = self.geometry;
        let width = self.right + MARGIN;
        let height = (g.grid_bottom() + 34.0).max(self.legend_y) + MARGIN;
        self.figure.resize(width.ceil(), height.ceil());
        self.figure.to_svg()
    }

    /// Obstacles (with an `O` on small grids; on large ones the letters would be clutter).
    fn obstacles(&mut self) {
        let g = self.geometry;
        for obstacle in &self.world.obstacles {
            let (x, y) = g.corner(*obstacle);
            self.figure.shape(
                Shape::Rect {
                    x,
                    y,
                    width: g.cell,
                    height: g.cell,
                },
                Role::Fill,
                Paint::fill(OBSTACLE_FILL),
            );
            if g.cell >= 56.0 {
                let (cx, cy) = g.centre(*obstacle);
                let size = (g.cell * 0.4).min(20.0);
                let baseline = cy + size * 0.36;
                self.text((cx, baseline), size, Anchor::Middle, WHITE, "O");
            }
        }
    }

    /// Goal cells (those carrying propositions) filled pale, as on the map and a run.
    fn goal_fills(&mut self) {
        let g = self.geometry;
        for (cell, _) in self.goals() {
            let (x, y) = g.corner(cell);
            self.figure.shape(
                Shape::Rect {
                    x,
                    y,
                    width: g.cell,
                    height: g.cell,
                },
                Role::Fill,
                Paint::fill(GOAL_FILL),
            );
        }
    }

    /// The labelled cells with their propositions, in the generator's order of first label.
    fn goals(&self) -> Vec<(Cell, String)> {
        let mut cells: Vec<(Cell, Vec<&str>)> = Vec::new();
        for (name, cell) in &self.world.labels {
            match cells.iter_mut().find(|(c, _)| c == cell) {
                Some((_, names)) => names.push(name),
                None => cells.push((*cell, vec![name])),
            }
        }
        cells
            .into_iter()
            .map(|(cell, names)| (cell, names.join(",")))
            .collect()
    }

    /// The grid lines and the coordinates along both axes.
    fn grid(&mut self) {
        let g = self.geometry;
        let stroke = Paint::outline(GRID_LINE, 1.0);
        for x in 0..=self.world.width {
            let px = g.left + f64::from(x) * g.cell;
            self.figure.shape(
                Shape::Polyline(vec![(px, g.top), (px, g.grid_bottom())]),
                Role::Line,
                stroke,
            );
        }
        for y in 0..=self.world.height {
            let py = g.top + f64::from(y) * g.cell;
            self.figure.shape(
                Shape::Polyline(vec![(g.left, py), (g.grid_right(), py)]),
                Role::Line,
                stroke,
            );
        }
        // Coordinates: every one where they fit, else every fifth.
        let step = if g.cell >= 24.0 { 1 } else { 5 };
        for x in (0..self.world.width).step_by(step) {
            let (cx, _) = g.centre(Cell { x, y: 0 });
            let at = (cx, g.grid_bottom() + 4.0 + font::ASCENT * AXIS_SIZE);
            self.text(at, AXIS_SIZE, Anchor::Middle, BLACK, &x.to_string());
        }
        for y in (0..self.world.height).step_by(step) {
            let (_, cy) = g.centre(Cell { x: 0, y });
            let at = (g.left - 6.0, cy + 0.36 * AXIS_SIZE);
            self.text(at, AXIS_SIZE, Anchor::End, BLACK, &y.to_string());
        }
        let at = (g.left, g.grid_bottom() + 30.0);
        self.text(
            at,
            AXIS_SIZE,
            Anchor::Start,
            BLACK,
            "x eastward, y northward",
        );
    }

    /// The propositions of the labelled cells, in the top band (roomy cells) or the top-left
    /// corner, on a white strip (`strip`: a partition, whose fill means something else) or on
    /// a small backing box (`backed`: a run, whose paths cross cells).
    fn propositions(&mut self, strip: bool, backed: bool) {
        let all: Vec<Cell> = self.goals().into_iter().map(|(c, _)| c).collect();
        self.propositions_where(strip, backed, &all);
    }

    /// [`Canvas::propositions`] of the goal cells among `cells`.
    fn propositions_where(&mut self, strip: bool, backed: bool, cells: &[Cell]) {
        let g = self.geometry;
        let size = if g.roomy() {
            g.code_size()
        } else {
            (g.cell * 0.3).clamp(7.0, 11.0)
        };
        for (cell, names) in self.goals() {
            if !cells.contains(&cell) {
                continue;
            }
            let (x, y) = g.corner(cell);
            if strip {
                self.figure.shape(
                    Shape::Rect {
                        x: x + 0.5,
                        y: y + 0.5,
                        width: g.cell - 1.0,
                        height: g.band() - 0.5,
                    },
                    Role::Fill,
                    Paint::fill(WHITE),
                );
            }
            let baseline = y + 1.5 + font::ASCENT * size;
            if backed {
                let width = font::width(&names, size);
                self.figure.shape(
                    Shape::Rect {
                        x: x + 1.0,
                        y: y + 1.0,
                        width: width + 4.0,
                        height: size + 2.0,
                    },
                    Role::Backing,
                    Paint::fill(WHITE),
                );
            }
            self.text((x + 3.0, baseline), size, Anchor::Start, BLACK, &names);
        }
    }

    /// A legend line: a swatch drawn by `swatch` in the 16-pixel square at the given corner,
    /// then `text`.
    fn legend(&mut self, text: &str, swatch: impl FnOnce(&mut Figure, f64, f64)) {
        let (x, y) = (self.legend_x, self.legend_y);
        swatch(&mut self.figure, x, y + 2.0);
        self.text(
            (x + SWATCH + 8.0, y + 14.0),
            LEGEND_SIZE,
            Anchor::Start,
            BLACK,
            text,
        );
        self.legend_y += LEGEND_ROW;
    }

    /// A legend line with a square swatch of `colour`.
    fn legend_colour(&mut self, colour: &str, text: &str) {
        self.legend(text, |figure, x, y| {
            figure.shape(
                Shape::Rect {
                    x,
                    y,
                    width: SWATCH,
                    height: SWATCH,
                },
                Role::Marker,
                Paint::filled(colour, BLACK, 1.0),
            );
        });
    }

    fn legend_heading(&mut self, text: &str) {
        if self.legend_y > self.geometry.top {
            self.legend_y += 8.0;
        }
        let (x, y) = (self.legend_x, self.legend_y);
        self.text((x, y + 15.0), HEADING_SIZE, Anchor::Start, BLACK, text);
        self.legend_y += LEGEND_ROW + 2.0;
    }

    /// A legend line with a player's shape.
    fn legend_player(&mut self, player: Owner, text: &str) {
        self.legend(text, |figure, x, y| {
            let centre = (x + SWATCH / 2.0, y + SWATCH / 2.0);
            figure.shape(
                player_shape(player, centre, 6.5),
                Role::Marker,
                Paint::filled(player_colour(player), BLACK, 1.0),
            );
        });
    }

    fn legend_obstacle(&mut self) {
        if !self.world.obstacles.is_empty() {
            self.legend_colour(OBSTACLE_FILL, "obstacle (O)");
        }
    }

    /// A player's shape on its cell's disc.
    fn player(&mut self, player: Owner, centre: (f64, f64), r: f64) {
        self.figure.shape(
            player_shape(player, centre, r),
            Role::Marker,
            Paint::filled(player_colour(player), BLACK, 1.5),
        );
    }
}

/// The map: grid, obstacles, goal cells (shaded, with their propositions), both starts.
pub fn map(world: &Gridworld, title: &Title) -> String {
    let mut canvas = Canvas::new(world, title);
    let g = canvas.geometry;
    canvas.goal_fills();
    canvas.obstacles();
    canvas.grid();
    // A goal's propositions large in its cell, unless a player starts there.
    let starts = [world.robot, world.adversary];
    for (cell, names) in canvas.goals() {
        if starts.contains(&cell) {
            continue;
        }
        let (cx, cy) = g.centre(cell);
        let size = (g.cell * 0.4)
            .min(20.0)
            .min((g.cell - 8.0) / font::width(&names, 1.0).max(1e-9));
        let baseline = cy + size * (font::ASCENT - font::DESCENT) / 2.0;
        canvas.text((cx, baseline), size, Anchor::Middle, BLACK, &names);
    }
    canvas.propositions_where(false, false, &starts);
    if world.robot == world.adversary {
        for player in [Owner::Robot, Owner::Adversary] {
            let (centre, r) = g.marker(world.robot, player);
            canvas.player(player, centre, r);
        }
    } else {
        for (player, cell) in [
            (Owner::Robot, world.robot),
            (Owner::Adversary, world.adversary),
        ] {
            let (centre, r) = g.disc(cell);
            canvas.player(player, centre, r * 0.8);
        }
    }
    canvas.legend_heading("Legend");
    canvas.legend_player(Owner::Robot, "the robot's start");
    canvas.legend_player(Owner::Adversary, "the adversary's start");
    canvas.legend_colour(GOAL_FILL, "a goal: the propositions of the cell");
    canvas.legend_obstacle();
    canvas.finish()
}

/// Whether a value is worth nothing (the robot can gain nothing there), shown apart from the
/// scale in the colour of "nothing".
fn worthless(value: f64) -> bool {
    value <= 0.0
}

/// The range of the positive values, and how many decimals tell them apart.
fn value_range(cells: &[CellView]) -> Option<(f64, f64, usize)> {
    let values = cells
        .iter()
        .filter_map(|v| v.value)
        .filter(|&v| v.is_finite() && !worthless(v));
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    });
    if lo > hi {
        return None;
    }
    let spread = hi - lo;
    let decimals = if spread > 1e-9 * hi.abs().max(1.0) {
        (1.0 - spread.log10().floor()).clamp(0.0, 3.0) as usize
    } else if (hi - hi.round()).abs() < 1e-9 {
        0
    } else {
        2
    };
    Some((lo, hi, decimals))
}

/// The win-label partition: each robot cell filled by the tag (or value) of the robot's state
/// there with the adversary on `adversary`, and the controller's mark; `key` is the legend of
/// the tags' colours.
pub fn partition(
    world: &Gridworld,
    title: &Title,
    adversary: Cell,
    cells: &[CellView],
    shading: Shading,
    key: &Key,
) -> String {
    let mut canvas = Canvas::new(world, title);
    let g = canvas.geometry;
    let range = value_range(cells);
    let shade = |value: f64| match range {
        _ if worthless(value) => colour::NOTHING_COLOUR.to_string(),
        Some((lo, hi, _)) if hi > lo => heat_colour((value - lo) / (hi - lo)),
        _ => heat_colour(0.5),
    };
    let band = g.band();
    let adversary_has_cell = cells.iter().any(|v| v.cell == adversary);
    for view in cells {
        let (x, y) = g.corner(view.cell);
        let fill = match (shading, &view.tag, view.value) {
            (Shading::Labels, Some(tag), _) => tag.colour.clone(),
            (Shading::Values { .. }, _, Some(value)) => shade(value),
            _ => WHITE.to_string(),
        };
        let mut tooltip = format!("robot at {}", view.cell);
        if let Some(tag) = &view.tag {
            tooltip += &format!(": {}", tag.text);
        }
        if let Some(value) = view.value {
            tooltip += &format!(", value {value:.2}");
        }
        if view.initial {
            tooltip += " (h0)";
        }
        canvas.figure.group(&tooltip);
        canvas.figure.shape(
            Shape::Rect {
                x,
                y,
                width: g.cell,
                height: g.cell,
            },
            Role::Fill,
            Paint::fill(&fill),
        );
        if g.roomy() {
            let text = match (shading, &view.tag, view.value) {
                (Shading::Values { .. }, _, Some(value)) => {
                    let decimals = if worthless(value) {
                        0
                    } else {
                        range.map_or(0, |r| r.2)
                    };
                    format!("{value:.decimals$}")
                }
                (_, Some(tag), _) => tag.code.clone(),
                _ => "-".to_string(),
            };
            // Long codes (the general form's) in a smaller font, to stay inside the cell.
            let fitting = (g.cell - 6.0) / font::width(&text, 1.0).max(1e-9);
            let size = g.code_size().min(fitting);
            let baseline = y + g.cell - (band - size) / 2.0 - font::DESCENT * size;
            canvas.figure.text(
                (x + g.cell / 2.0, baseline),
                size,
                Anchor::Middle,
                BLACK,
                HALO,
                &text,
                false,
            );
        }
        if let Some(mark) = view.mark {
            let (centre, r) = g.disc(view.cell);
            draw_mark(&mut canvas.figure, centre, r, mark, &fill);
        }
        canvas.figure.end_group();
    }
    canvas.obstacles();
    canvas.grid();
    let initial = cells.iter().find(|v| v.initial).map(|v| v.cell);
    let goals = canvas.goals();
    if g.roomy() {
        canvas.propositions(true, false);
        // h0 and the adversary (when it shares a robot cell) at the right of the top band.
        let size = g.code_size();
        if let Some(cell) = initial {
            let (x, y) = g.corner(cell);
            let right = if cell == adversary && adversary_has_cell {
                x + g.cell - band - 2.0
            } else {
                x + g.cell - 3.0
            };
            let baseline = y + 1.5 + font::ASCENT * size;
            let (_, _, r, _) = canvas.figure.text(
                (right, baseline),
                size,
                Anchor::End,
                BLACK,
                HALO,
                "h0",
                false,
            );
            canvas.right = canvas.right.max(r);
        }
    } else if g.framed() {
        for (cell, _) in &goals {
            let (x, y) = g.corner(*cell);
            goal_frame(&mut canvas.figure, x, y, g.cell);
        }
        if let Some(cell) = initial {
            let (x, y) = g.corner(cell);
            initial_frame(&mut canvas.figure, x, y, g.cell);
        }
    }
    // The adversary: large in its own cell, small in the top band when the robot has a state
    // there too (collisions allowed).
    if adversary_has_cell && g.roomy() {
        let (x, y) = g.corner(adversary);
        let r = (band / 2.0 - 1.5) / 1.15;
        canvas.player(
            Owner::Adversary,
            (x + g.cell - band / 2.0 - 1.0, y + band / 2.0),
            r,
        );
    } else if !adversary_has_cell {
        let (centre, r) = g.disc(adversary);
        canvas.player(Owner::Adversary, centre, r * 0.8);
    }

    match shading {
        Shading::Labels => {
            canvas.legend_heading(&key.heading);
            for (colour, text) in &key.entries {
                match colour {
                    Some(colour) => canvas.legend_colour(colour, text),
                    None => canvas.legend(text, |_, _, _| {}),
                }
            }
        }
        Shading::Values { max } => {
            canvas.legend_heading("Value of the robot's state");
            value_scale(&mut canvas, range, max);
            if cells.iter().any(|v| v.value.is_some_and(worthless)) {
                canvas.legend_colour(colour::NOTHING_COLOUR, "0: nothing to gain");
            }
        }
    }
    // The controller's legend only where the picture shows its marks.
    if cells.iter().any(|view| view.mark.is_some()) {
        canvas.legend_heading("Controller in each robot cell");
        for (mark, text) in [
            (Mark::Move(Move::E), "moves (arrow)"),
            (Mark::Stop, "stops: settles for a sub-task"),
            (Mark::Commit, "commits: plays to win a task"),
            (Mark::GiveUp, "gives up: stuck, nothing to gain"),
        ] {
            canvas.legend(text, |figure, x, y| {
                draw_mark(
                    figure,
                    (x + SWATCH / 2.0, y + SWATCH / 2.0),
                    9.0,
                    mark,
                    WHITE,
                );
            });
        }
    }
    canvas.legend_heading("Cells");
    if let Some(cell) = initial {
        if g.roomy() {
            canvas.legend(&format!("h0: the initial state, at {cell}"), |_, _, _| {});
        } else {
            canvas.legend(
                &format!("the initial state h0, at {cell}"),
                |figure, x, y| initial_frame(figure, x - 2.5, y - 2.5, SWATCH + 5.0),
            );
        }
    }
    if !goals.is_empty() {
        let names: Vec<&str> = goals.iter().map(|(_, n)| n.as_str()).collect();
        let text = format!("goals ({}): the cell's propositions", names.join(", "));
        if g.roomy() {
            canvas.legend(&text, |_, _, _| {});
        } else {
            canvas.legend(&text, |figure, x, y| {
                goal_frame(figure, x - 0.5, y - 0.5, SWATCH + 1.0);
            });
        }
    }
    canvas.legend_player(Owner::Adversary, &format!("the adversary, at {adversary}"));
    canvas.legend_obstacle();
    canvas.finish()
}

/// The dashed frame of a goal cell whose corner is `(x, y)` and side `side`, when the cell is
/// too small for its propositions.
fn goal_frame(figure: &mut Figure, x: f64, y: f64, side: f64) {
    figure.shape(
        Shape::Rect {
            x: x + 1.25,
            y: y + 1.25,
            width: side - 2.5,
            height: side - 2.5,
        },
        Role::Marker,
        Paint {
            fill: None,
            stroke: Some((BLACK, 1.5)),
            extra: "stroke-dasharray=\"3 2\"",
        },
    );
}

/// The frame of h0's cell whose corner is `(x, y)` and side `side`, inside a goal's frame, when
/// the cell is too small to write `h0`.
fn initial_frame(figure: &mut Figure, x: f64, y: f64, side: f64) {
    figure.shape(
        Shape::Rect {
            x: x + 3.5,
            y: y + 3.5,
            width: side - 7.0,
            height: side - 7.0,
        },
        Role::Marker,
        Paint::outline(BLACK, 2.0),
    );
}

/// The legend of the value picture: a continuous colour bar from the smallest to the largest
/// value shown, with round ticks; or, when every value shown is the same, one swatch saying so.
fn value_scale(canvas: &mut Canvas, range: Option<(f64, f64, usize)>, max: f64) {
    let Some((lo, hi, decimals)) = range.filter(|&(lo, hi, _)| hi > lo) else {
        let colour = heat_colour(0.5);
        match range {
            Some((value, _, decimals)) => {
                canvas.legend_colour(
                    &colour,
                    &format!("uniform: every state shown is worth {value:.decimals$}"),
                );
                canvas.legend(
                    "(undiscounted, values ignore how long a win takes:",
                    |_, _, _| {},
                );
                canvas.legend("draw with a discount below 1 to see it)", |_, _, _| {});
            }
            None => canvas.legend("no positive value to show", |_, _, _| {}),
        }
        return;
    };
    const BAR: f64 = 180.0;
    let (x, top) = (canvas.legend_x, canvas.legend_y + 6.0);
    let stops: Vec<String> = colour::SCALE
        .iter()
        .enumerate()
        .map(|(i, _)| {
            let t = i as f64 / (colour::SCALE.len() - 1) as f64;
            format!("<stop offset=\"{t}\" stop-color=\"{}\"/>", heat_colour(t))
        })
        .collect();
    canvas.figure.raw(&format!(
        "<defs><linearGradient id=\"value-scale\" x1=\"0\" y1=\"1\" x2=\"0\" y2=\"0\">{}\
         </linearGradient></defs>",
        stops.concat()
    ));
    canvas.figure.shape(
        Shape::Rect {
            x,
            y: top,
            width: SWATCH,
            height: BAR,
        },
        Role::Marker,
        Paint::filled("url(#value-scale)", BLACK, 1.0),
    );
    let at = |v: f64| top + BAR * (1.0 - (v - lo) / (hi - lo));
    // Round ticks about a fifth of the range apart, and both ends.
    let rough = (hi - lo) / 4.0;
    let magnitude = 10f64.powf(rough.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * magnitude)
        .find(|&s| s >= rough)
        .unwrap_or(10.0 * magnitude);
    let tick_decimals = decimals.max((-step.log10().floor()).max(0.0) as usize);
    let mut ticks = vec![(lo, decimals), (hi, decimals)];
    let mut v = (lo / step).ceil() * step;
    while v < hi {
        if (at(v) - at(lo)).abs() > 22.0 && (at(v) - at(hi)).abs() > 22.0 {
            ticks.push((v, tick_decimals));
        }
        v += step;
    }
    for (v, d) in ticks {
        let y = at(v);
        canvas.figure.shape(
            Shape::Polyline(vec![(x + SWATCH, y), (x + SWATCH + 4.0, y)]),
            Role::Line,
            Paint::outline(BLACK, 1.0),
        );
        let text = format!("{v:.d$}");
        canvas.text(
            (x + SWATCH + 8.0, y + 0.36 * LEGEND_SIZE),
            LEGEND_SIZE,
            Anchor::Start,
            BLACK,
            &text,
        );
    }
    canvas.legend_y = top + BAR + 12.0;
    canvas.legend("the scale spans the positive values shown", |_, _, _| {});
    canvas.legend(&format!("(payoffs go up to {max})"), |_, _, _| {});
}

/// The controller's mark in the disc of centre `(cx, cy)` and radius `r`, black, or white on a
/// dark `fill`. Nothing of it leaves the disc.
fn draw_mark(figure: &mut Figure, (cx, cy): (f64, f64), r: f64, mark: Mark, fill: &str) {
    let w = (r / 8.0).max(1.5);
    let colour = if colour::is_dark(fill) { WHITE } else { BLACK };
    let line = |figure: &mut Figure, from: (f64, f64), to: (f64, f64)| {
        figure.shape(
            Shape::Polyline(vec![from, to]),
            Role::Mark,
            Paint::outline(colour, w),
        );
    };
    let ring = |figure: &mut Figure, radius: f64| {
        figure.shape(
            Shape::Circle {
                centre: (cx, cy),
                r: radius,
            },
            Role::Mark,
            Paint::outline(colour, w),
        );
    };
    match mark {
        Mark::Move(Move::Stay) => ring(figure, r * 0.7),
        Mark::Move(m) => {
            let (dx, dy) = Geometry::direction(m);
            let tip_at = r - w;
            let tip = (cx + dx * tip_at, cy + dy * tip_at);
            let base = (cx + dx * (tip_at - 0.5 * r), cy + dy * (tip_at - 0.5 * r));
            let tail = (cx - dx * 0.55 * r, cy - dy * 0.55 * r);
            let (nx, ny) = (-dy * 0.32 * r, dx * 0.32 * r);
            line(figure, tail, base);
            figure.shape(
                Shape::Polygon(vec![
                    tip,
                    (base.0 + nx, base.1 + ny),
                    (base.0 - nx, base.1 - ny),
                ]),
                Role::Mark,
                Paint::fill(colour),
            );
        }
        Mark::Stop => {
            let h = r * 0.62;
            figure.shape(
                Shape::Rect {
                    x: cx - h,
                    y: cy - h,
                    width: 2.0 * h,
                    height: 2.0 * h,
                },
                Role::Mark,
                Paint::outline(colour, w),
            );
        }
        Mark::Commit => {
            ring(figure, r * 0.42);
            ring(figure, r * 0.8);
        }
        Mark::GiveUp => {
            let (a, b) = (r * 0.18, r * 0.62);
            for (sx, sy) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
                line(
                    figure,
                    (cx + sx * a, cy + sy * a),
                    (cx + sx * b, cy + sy * b),
                );
            }
        }
    }
}

/// How many steps a run's table lists one by one; longer runs get one row per stretch of
/// steps with the same label.
const TABLE_STEPS: usize = 20;

/// A table in the legend column: the header and the rows, each a swatch's colour and its
/// cells; the first column is right-aligned, the others left-aligned, the swatch before the
/// fourth.
fn table(canvas: &mut Canvas, header: &[&str], rows: &[(String, Vec<String>)]) {
    // The label column (the fourth) holds a swatch, then the code.
    let swatch = SWATCH - 2.0 + 4.0;
    let widths: Vec<f64> = (0..header.len())
        .map(|c| {
            let before = if c == 3 { swatch } else { 0.0 };
            rows.iter()
                .map(|(_, cells)| before + font::width(&cells[c], LEGEND_SIZE))
                .chain([font::width(header[c], LEGEND_SIZE)])
                .fold(0.0, f64::max)
        })
        .collect();
    let gap = 12.0;
    let mut xs = Vec::with_capacity(widths.len());
    let mut x = canvas.legend_x;
    for width in &widths {
        xs.push(x);
        x += width + gap;
    }
    let place = |c: usize| -> (f64, Anchor) {
        match c {
            0 => (xs[0] + widths[0], Anchor::End),
            3 => (xs[3] + swatch, Anchor::Start),
            _ => (xs[c], Anchor::Start),
        }
    };
    let y = canvas.legend_y;
    for (c, text) in header.iter().enumerate() {
        let (x, anchor) = match c {
            3 => (xs[3], Anchor::Start),
            c => place(c),
        };
        canvas.text((x, y + 14.0), LEGEND_SIZE, anchor, "#444444", text);
    }
    canvas.figure.shape(
        Shape::Polyline(vec![(canvas.legend_x, y + 19.5), (x - gap, y + 19.5)]),
        Role::Line,
        Paint::outline("#444444", 1.0),
    );
    canvas.legend_y += LEGEND_ROW + 2.0;
    for (colour, cells) in rows {
        let y = canvas.legend_y;
        canvas.figure.shape(
            Shape::Rect {
                x: xs[3],
                y: y + 3.0,
                width: SWATCH - 2.0,
                height: SWATCH - 2.0,
            },
            Role::Marker,
            Paint::filled(colour, BLACK, 1.0),
        );
        for (c, text) in cells.iter().enumerate() {
            let (x, anchor) = place(c);
            canvas.text((x, y + 14.0), LEGEND_SIZE, anchor, BLACK, text);
        }
        canvas.legend_y += LEGEND_ROW - 2.0;
    }
}

/// A run: the robot's path (solid blue, circles) and the adversary's (dashed orange,
/// diamonds), each position numbered by the step at which the player first got there, and a
/// table of the steps with their labels (one row per stretch of steps with the same label for
/// runs longer than 20 steps).
pub fn trace(world: &Gridworld, title: &Title, points: &[TracePoint]) -> String {
    let mut canvas = Canvas::new(world, title);
    let g = canvas.geometry;
    canvas.goal_fills();
    canvas.obstacles();
    canvas.grid();
    let players = [
        (Owner::Robot, ""),
        (Owner::Adversary, "stroke-dasharray=\"6 4\""),
    ];
    // Each player's positions in order, with the steps at which it arrived in each cell.
    let mut visits: Vec<Vec<(Cell, Vec<usize>)>> = Vec::new();
    for (player, dash) in players {
        let position = |p: &TracePoint| match player {
            Owner::Robot => p.robot,
            Owner::Adversary => p.adversary,
        };
        let mut path: Vec<(f64, f64)> = Vec::new();
        let mut cells: Vec<(Cell, Vec<usize>)> = Vec::new();
        let mut last = None;
        for (i, point) in points.iter().enumerate() {
            let cell = position(point);
            if last == Some(cell) {
                continue;
            }
            last = Some(cell);
            path.push(g.marker(cell, player).0);
            match cells.iter_mut().find(|(c, _)| *c == cell) {
                Some((_, steps)) => steps.push(i),
                None => cells.push((cell, vec![i])),
            }
        }
        if path.len() > 1 {
            let width = (g.cell / 14.0).max(2.0);
            canvas.figure.shape(
                Shape::Polyline(path),
                Role::Line,
                Paint {
                    fill: None,
                    stroke: Some((player_colour(player), width)),
                    extra: dash,
                },
            );
        }
        visits.push(cells);
    }
    for ((player, _), cells) in players.iter().zip(&visits) {
        let text_colour = match player {
            Owner::Robot => WHITE,
            Owner::Adversary => BLACK,
        };
        for (cell, steps) in cells {
            let (centre, r) = g.marker(*cell, *player);
            let listed: Vec<String> = steps.iter().map(usize::to_string).collect();
            let tooltip = match steps.len() {
                1 => format!("step {}", listed[0]),
                _ => format!("steps {}", listed.join(", ")),
            };
            canvas.figure.group(&tooltip);
            canvas.figure.shape(
                player_shape(*player, centre, r),
                Role::Marker,
                Paint::filled(player_colour(*player), BLACK, 1.0),
            );
            // The largest size at which the number's box fits: inside the circle (its
            // half-diagonal under r), inside the diamond (half-width plus half-height under
            // its radius).
            let number = &listed[0];
            let half_width = font::width(number, 1.0) / 2.0;
            let half_height = (font::ASCENT + font::DESCENT) / 2.0;
            let room = r - 1.0;
            let size = match player {
                Owner::Robot => room / half_width.hypot(half_height),
                Owner::Adversary => room * 1.15 / (half_width + half_height),
            }
            .min(r * 1.2);
            if size >= 6.0 {
                // Centre the box vertically on the marker.
                let baseline = centre.1 + size * (font::ASCENT - font::DESCENT) / 2.0;
                canvas.figure.text(
                    (centre.0, baseline),
                    size,
                    Anchor::Middle,
                    text_colour,
                    "",
                    number,
                    true,
                );
            }
            canvas.figure.end_group();
        }
    }
    canvas.propositions(false, true);

    canvas.legend_heading("Run (numbers: step of first arrival)");
    canvas.legend_player(Owner::Robot, "the robot's path");
    canvas.legend_player(Owner::Adversary, "the adversary's path");
    canvas.legend_colour(GOAL_FILL, "a goal: the propositions of the cell");
    let mover = |point: &TracePoint| match point.turn {
        Owner::Robot => "robot",
        Owner::Adversary => "adversary",
    };
    if points.len() <= TABLE_STEPS {
        canvas.legend_heading(&format!("Steps ({})", points.len()));
        let rows: Vec<(String, Vec<String>)> = points
            .iter()
            .enumerate()
            .map(|(i, point)| {
                let action = point
                    .action
                    .as_deref()
                    .map_or(String::new(), |a| format!("{} {a}", mover(point)));
                (
                    point.tag.colour.clone(),
                    vec![
                        i.to_string(),
                        point.robot.to_string(),
                        point.adversary.to_string(),
                        point.tag.code.clone(),
                        action,
                    ],
                )
            })
            .collect();
        table(
            &mut canvas,
            &["step", "robot", "adversary", "label", "action"],
            &rows,
        );
    } else {
        canvas.legend_heading(&format!(
            "Steps ({}), one row per stretch with the same label",
            points.len()
        ));
        let mut rows: Vec<(String, Vec<String>)> = Vec::new();
        let mut start = 0;
        for end in 1..=points.len() {
            if end < points.len() && points[end].tag == points[start].tag {
                continue;
            }
            let (first, last) = (&points[start], &points[end - 1]);
            let span = |a: Cell, b: Cell| {
                if a == b {
                    a.to_string()
                } else {
                    format!("{a}→{b}")
                }
            };
            let steps = if end - 1 == start {
                start.to_string()
            } else {
                format!("{start}–{}", end - 1)
            };
            rows.push((
                first.tag.colour.clone(),
                vec![
                    steps,
                    span(first.robot, last.robot),
                    span(first.adversary, last.adversary),
                    first.tag.code.clone(),
                ],
            ));
            start = end;
        }
        table(
            &mut canvas,
            &["steps", "robot", "adversary", "label"],
            &rows,
        );
    }
    canvas.finish()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::figure::{overlaps, read};
    use crate::render::title::TitleChoice;

    fn world() -> Gridworld {
        Gridworld {
            obstacles: vec![Cell { x: 1, y: 1 }],
            labels: vec![
                ("A".into(), Cell { x: 0, y: 2 }),
                ("B".into(), Cell { x: 0, y: 2 }),
            ],
            ..Gridworld::new(3, 3, Cell { x: 0, y: 0 }, Cell { x: 2, y: 2 })
        }
    }

    fn title(text: &str) -> Title {
        Title::new(vec![text.to_string()], &TitleChoice::Default)
    }

    #[test]
    fn cells_are_drawn_north_up() {
        let g = Geometry::new(&world(), 40.0);
        assert_eq!(g.cell, 72.0);
        // (0, 2) is the top-left cell, (2, 0) the bottom-right one.
        assert_eq!(g.corner(Cell { x: 0, y: 2 }), (g.left, g.top));
        assert_eq!(
            g.corner(Cell { x: 2, y: 0 }),
            (g.left + 2.0 * g.cell, g.top + 2.0 * g.cell)
        );
        assert_eq!(Geometry::direction(Move::N), (0.0, -1.0));
        let (dx, dy) = Geometry::direction(Move::SE);
        assert!((dx - 0.5f64.sqrt()).abs() < 1e-12 && (dy - 0.5f64.sqrt()).abs() < 1e-12);
        // The mark's disc leaves both text bands free: 72 / 2 - 16 - 1.5.
        assert_eq!(g.band(), 16.0);
        assert_eq!(g.disc(Cell { x: 0, y: 0 }).1, 18.5);
    }

    #[test]
    fn the_map_shows_obstacles_goals_and_both_starts() {
        let svg = map(&world(), &title("a <map>"));
        assert!(svg.starts_with("<svg xmlns=\"http://www.w3.org/2000/svg\""));
        assert!(svg.contains("<title>a &lt;map&gt;</title>"));
        let items = read(&svg).unwrap();
        let fills = |colour: &str| {
            items
                .iter()
                .filter(|i| i.fill.as_deref() == Some(colour))
                .count()
        };
        // The obstacle and its swatch; the goal cell and its swatch.
        assert_eq!(fills(OBSTACLE_FILL), 2);
        assert_eq!(fills(GOAL_FILL), 2);
        assert!(svg.contains(">A,B</text>"));
        // The robot's circle and the adversary's diamond, plus one of each in the legend.
        assert_eq!(svg.matches("<circle").count(), 2);
        assert_eq!(svg.matches("<polygon").count(), 2);
        assert_eq!(overlaps(&items), Vec::<String>::new());
    }

    #[test]
    fn no_title_leaves_the_grid_at_the_top_and_keeps_the_description() {
        let hidden = Title::new(vec!["What it shows".into()], &TitleChoice::None);
        let svg = map(&world(), &hidden);
        assert!(svg.contains("<title>What it shows</title>"));
        assert!(!svg.contains(">What it shows</text>"));
        let items = read(&svg).unwrap();
        // The grid's top line.
        let top = items
            .iter()
            .filter(|i| i.role == Role::Line)
            .filter_map(|i| match &i.shape {
                Shape::Polyline(points) => Some(points[0].1),
                _ => None,
            })
            .fold(f64::INFINITY, f64::min);
        assert_eq!(top, MARGIN);
    }

    /// Every mark in every cell of a roomy and a compact grid, with codes, values and
    /// propositions: nothing overlaps.
    #[test]
    fn marks_codes_and_propositions_never_overlap() {
        let moves = [
            Mark::Move(Move::N),
            Mark::Move(Move::S),
            Mark::Move(Move::E),
            Mark::Move(Move::W),
            Mark::Move(Move::NE),
            Mark::Move(Move::NW),
            Mark::Move(Move::SE),
            Mark::Move(Move::SW),
            Mark::Move(Move::Stay),
            Mark::Stop,
            Mark::Commit,
            Mark::GiveUp,
        ];
        for side in [3, 16, 24] {
            let mut world = Gridworld::new(side, side, Cell { x: 0, y: 0 }, Cell { x: 1, y: 0 });
            world.labels = vec![
                ("A".into(), Cell { x: 0, y: 1 }),
                ("B".into(), Cell { x: 0, y: 1 }),
                ("Corner".into(), Cell { x: 2, y: 2 }),
            ];
            let cells: Vec<CellView> = (0..side)
                .flat_map(|x| (0..side).map(move |y| Cell { x, y }))
                .filter(|&c| c != world.adversary)
                .enumerate()
                .map(|(i, cell)| CellView {
                    cell,
                    tag: Some(Tag {
                        colour: "#F0E442".into(),
                        code: ["WWW", "AB C|W", "A,B Corner|L"][i % 3].into(),
                        text: String::new(),
                    }),
                    mark: Some(moves[i % moves.len()]),
                    value: Some(365.0 + i as f64 * 0.37),
                    initial: cell == Cell { x: 0, y: 1 },
                })
                .collect();
            let key = win_label_key();
            for shading in [Shading::Labels, Shading::Values { max: 500.0 }] {
                let svg = partition(&world, &title("t"), world.adversary, &cells, shading, &key);
                let items = read(&svg).unwrap();
                assert_eq!(overlaps(&items), Vec::<String>::new(), "side {side}");
            }
        }
    }

    /// A run of `steps` steps back and forth along the bottom row, the label changing every
    /// `stretch` steps.
    fn run(steps: usize, stretch: usize) -> Vec<TracePoint> {
        (0..steps)
            .map(|i| {
                let x = (i % 3) as u32;
                let tag = if (i / stretch).is_multiple_of(2) {
                    win_label_tag(WinLabel::ALL[2])
                } else {
                    win_label_tag(WinLabel::ALL[0])
                };
                TracePoint {
                    robot: Cell { x, y: 0 },
                    adversary: Cell { x: 2, y: 2 },
                    turn: if i.is_multiple_of(2) {
                        Owner::Robot
                    } else {
                        Owner::Adversary
                    },
                    tag,
                    action: Some("E".into()),
                }
            })
            .collect()
    }

    fn rows_of(svg: &str) -> usize {
        // One swatch per table row, 14 pixels square.
        read(svg)
            .unwrap()
            .iter()
            .filter(|i| matches!(i.shape, Shape::Rect { width, height, .. } if width == 14.0 && height == 14.0))
            .count()
    }

    #[test]
    fn a_long_run_gets_one_row_per_stretch_and_nothing_overlaps() {
        let mut world = world();
        world.labels.clear();
        // 20 steps: one row each, aligned: every row's step right-aligned on one x.
        let short = trace(&world, &title("run"), &run(20, 5));
        assert_eq!(rows_of(&short), 20);
        assert_eq!(overlaps(&read(&short).unwrap()), Vec::<String>::new());
        // 60 steps in stretches of 12: five rows, and a picture no taller than the short one's.
        let long = trace(&world, &title("run"), &run(60, 12));
        assert_eq!(rows_of(&long), 5);
        assert!(long.contains(">12–23</text>") && long.contains(">48–59</text>"));
        assert_eq!(overlaps(&read(&long).unwrap()), Vec::<String>::new());
        let height = |svg: &str| read(svg).unwrap()[0].clone();
        let (
            Shape::Rect {
                height: long_height,
                ..
            },
            Shape::Rect {
                height: short_height,
                ..
            },
        ) = (height(&long).shape, height(&short).shape)
        else {
            panic!("no background");
        };
        assert!(
            long_height < short_height,
            "{long_height} >= {short_height}"
        );
        // Revisited cells carry one marker, numbered by the first arrival; the tooltip lists all.
        assert!(long.contains("<title>steps 0, 3, 6, "));
    }
}

//! The drawings. Cell `(x, y)` is drawn north up: row `height - 1 - y` from the top, column
//! `x`. Every picture has the title lines at the top, the grid with its coordinates, and a
//! legend on the right.

use super::svg::{Anchor, Svg};
use crate::arena::Owner;
use crate::arena::gridworld::{Cell, Gridworld, Move};
use crate::game::WinLabel;

/// Okabe–Ito colours.
const BLUISH_GREEN: &str = "#009E73";
const SKY_BLUE: &str = "#56B4E9";
const YELLOW: &str = "#F0E442";
const REDDISH_PURPLE: &str = "#CC79A7";
const VERMILLION: &str = "#D55E00";
const BLUE: &str = "#0072B2";
const ORANGE: &str = "#E69F00";
const OBSTACLE_FILL: &str = "#4D4D4D";
const GRID_LINE: &str = "#999999";

/// The fill of a robot cell with this win-label: greens and blues where the robot can force
/// more, yellow to vermillion where it can force less; black for the impossible labels.
pub fn label_colour(label: WinLabel) -> &'static str {
    match label.code() {
        "WWW" => BLUISH_GREEN,
        "WWL" => SKY_BLUE,
        "WLL" => YELLOW,
        "LWL" => REDDISH_PURPLE,
        "LLL" => VERMILLION,
        _ => "#000000",
    }
}

/// What the legend says of each possible label of the paper's form.
const LABEL_MEANINGS: [(&str, &str); 5] = [
    ("WWW", "phi can be forced"),
    ("WWL", "phi1 and phi2 each, not both"),
    ("WLL", "only phi1 can be forced"),
    ("LWL", "only phi2 can be forced"),
    ("LLL", "nothing can be forced"),
];

/// How the paper's win-label shows: its colour, its code (`WLL`) and its triple.
pub fn win_label_tag(label: WinLabel) -> Tag {
    Tag {
        colour: label_colour(label).to_string(),
        code: label.code().to_string(),
        text: label.to_string(),
    }
}

/// The legend of the paper's five possible win-labels.
pub fn win_label_key() -> Key {
    let entries = LABEL_MEANINGS
        .iter()
        .map(|&(code, meaning)| {
            let label = WinLabel::ALL
                .into_iter()
                .find(|l| l.code() == code)
                .unwrap_or(WinLabel::ALL[0]);
            (
                Some(label_colour(label).to_string()),
                format!("{label} {meaning}"),
            )
        })
        .collect();
    Key {
        heading: "Win-label of the robot's state".to_string(),
        entries,
    }
}

/// The fill of the general form's class `index` (0: the largest guarantee) among `count`
/// classes of positive guarantee; guarantee 0 is always vermillion, as the paper's `(L, L, L)`.
/// Up to seven classes get the Okabe–Ito colours (the largest guarantee bluish green, as the
/// paper's `(W, W, W)`), then a light grey; more get evenly spaced stops of the light part of
/// the value scale (the cells' codes tell close colours apart).
pub fn class_colour(index: usize, count: usize) -> String {
    const CATEGORICAL: [&str; 7] = [
        BLUISH_GREEN,
        SKY_BLUE,
        YELLOW,
        REDDISH_PURPLE,
        ORANGE,
        BLUE,
        "#BBBBBB",
    ];
    if count <= CATEGORICAL.len() {
        CATEGORICAL[index.min(CATEGORICAL.len() - 1)].to_string()
    } else {
        let t = 1.0 - index as f64 / (count - 1) as f64;
        heat_colour(0.3 + 0.7 * t)
    }
}

/// The fill of a state that can force nothing (guarantee 0) in the general form.
pub const NOTHING_COLOUR: &str = VERMILLION;

/// How a robot state shows in a picture: the fill of its cell (and of its row in a run's
/// table), the short code written in the cell, and its full label (tooltips).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Tag {
    /// The fill, an SVG colour such as `#F0E442`.
    pub colour: String,
    /// The short code written in the cell when it is large enough, e.g. `WLL`.
    pub code: String,
    /// The full label, shown in tooltips and a run's table, e.g. `(W, L, L)`.
    pub text: String,
}

/// The legend of the fills of a partition: a heading, then per line a swatch's colour (`None`:
/// a line of text alone) and its meaning.
#[derive(Clone, Debug, PartialEq, Eq)]
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
}

/// How partition cells are filled.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shading {
    /// By win-label.
    Labels,
    /// By value, on a scale from 0 to `max`.
    Values {
        /// The value at the top of the scale: the largest payoff.
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

const TITLE_SIZE: f64 = 15.0;
const LINE: f64 = 20.0;
const LEGEND_WIDTH: f64 = 330.0;

impl Geometry {
    /// The layout of `world` under `title_lines` lines of title: cells of 14 to 56 pixels, the
    /// grid at most about 640 pixels wide.
    pub fn new(world: &Gridworld, title_lines: usize) -> Geometry {
        let side = f64::from(world.width.max(world.height));
        Geometry {
            cell: (640.0 / side).floor().clamp(14.0, 56.0),
            left: 40.0,
            top: 14.0 + LINE * title_lines as f64 + 12.0,
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
        self.cell >= 28.0
    }

    /// The screen direction of a move (y grows downwards on screen).
    fn direction(m: Move) -> (f64, f64) {
        let (dx, dy) = m.offset();
        let length = ((dx * dx + dy * dy) as f64).sqrt().max(1.0);
        (dx as f64 / length, -dy as f64 / length)
    }
}

/// A player's shape centred on `(cx, cy)` with radius `r`: the robot a circle, the adversary
/// a diamond.
fn player_shape(svg: &mut Svg, player: Owner, (cx, cy): (f64, f64), r: f64, style: &str) {
    match player {
        Owner::Robot => svg.circle(cx, cy, r, style),
        Owner::Adversary => svg.path(
            &[(cx, cy - r), (cx + r, cy), (cx, cy + r), (cx - r, cy)],
            true,
            style,
        ),
    }
}

/// A picture under construction: the document, its layout and the legend's next line.
struct Canvas<'w> {
    svg: Svg,
    geometry: Geometry,
    world: &'w Gridworld,
    legend_x: f64,
    legend_y: f64,
}

impl<'w> Canvas<'w> {
    fn new(world: &'w Gridworld, title: &[String], legend_lines: usize) -> Canvas<'w> {
        let geometry = Geometry::new(world, title.len());
        let legend_x = geometry.grid_right() + 28.0;
        // Wide enough for the longest title line (about 0.6 em per character).
        let title_width = title
            .iter()
            .map(|line| 24.0 + 0.6 * TITLE_SIZE * line.chars().count() as f64)
            .fold(0.0, f64::max);
        let width = (legend_x + LEGEND_WIDTH).max(title_width);
        let legend_bottom = geometry.top + 26.0 * legend_lines as f64 + 20.0;
        let height = (geometry.grid_bottom() + 34.0).max(legend_bottom);
        let mut svg = Svg::new(width, height, &title.join(" — "));
        for (i, line) in title.iter().enumerate() {
            let weight = if i == 0 { "font-weight=\"bold\"" } else { "" };
            let y = 14.0 + LINE * (i as f64 + 1.0) - 4.0;
            svg.text(12.0, y, TITLE_SIZE, Anchor::Start, weight, line);
        }
        Canvas {
            svg,
            geometry,
            world,
            legend_x,
            legend_y: geometry.top,
        }
    }

    /// Obstacles, the grid lines and the coordinates along both axes.
    fn grid(&mut self) {
        let g = self.geometry;
        for obstacle in &self.world.obstacles {
            let (x, y) = g.corner(*obstacle);
            self.svg
                .rect(x, y, g.cell, g.cell, &format!("fill=\"{OBSTACLE_FILL}\""));
            if g.roomy() {
                let (cx, cy) = g.centre(*obstacle);
                let size = g.cell * 0.4;
                let style = "fill=\"#ffffff\" font-weight=\"bold\"";
                self.svg
                    .text(cx, cy + size * 0.35, size, Anchor::Middle, style, "O");
            }
        }
        let stroke = format!("stroke=\"{GRID_LINE}\" stroke-width=\"1\"");
        for x in 0..=self.world.width {
            let px = g.left + f64::from(x) * g.cell;
            self.svg.line((px, g.top), (px, g.grid_bottom()), &stroke);
        }
        for y in 0..=self.world.height {
            let py = g.top + f64::from(y) * g.cell;
            self.svg.line((g.left, py), (g.grid_right(), py), &stroke);
        }
        // Coordinates, every fifth on large grids.
        let step = if g.roomy() { 1 } else { 5 };
        let size = 11.0;
        for x in (0..self.world.width).step_by(step) {
            let (cx, _) = g.centre(Cell { x, y: 0 });
            let label = format!("{x}");
            self.svg
                .text(cx, g.grid_bottom() + 14.0, size, Anchor::Middle, "", &label);
        }
        for y in (0..self.world.height).step_by(step) {
            let (_, cy) = g.centre(Cell { x: 0, y });
            let label = format!("{y}");
            self.svg
                .text(g.left - 6.0, cy + 4.0, size, Anchor::End, "", &label);
        }
        let note = "x eastward, y northward";
        self.svg.text(
            g.left,
            g.grid_bottom() + 28.0,
            size,
            Anchor::Start,
            "",
            note,
        );
    }

    /// The propositions of labelled cells, at the top left of each.
    fn propositions(&mut self) {
        let g = self.geometry;
        let mut cells: Vec<(Cell, Vec<&str>)> = Vec::new();
        for (name, cell) in &self.world.labels {
            match cells.iter_mut().find(|(c, _)| c == cell) {
                Some((_, names)) => names.push(name),
                None => cells.push((*cell, vec![name])),
            }
        }
        let size = (g.cell * 0.3).clamp(9.0, 16.0);
        for (cell, names) in cells {
            let (x, y) = g.corner(cell);
            let style = "font-weight=\"bold\" fill=\"#000000\" stroke=\"#ffffff\" \
                         stroke-width=\"3\" paint-order=\"stroke\"";
            self.svg.text(
                x + 3.0,
                y + size + 1.0,
                size,
                Anchor::Start,
                style,
                &names.join(","),
            );
        }
    }

    /// The robot as a circle, the adversary as a diamond, around `cell`'s centre.
    fn player(&mut self, player: Owner, cell: Cell, fill: &str) {
        let g = self.geometry;
        let (cx, cy) = g.centre(cell);
        let r = g.cell * 0.28;
        let style = format!("fill=\"{fill}\" stroke=\"#000000\" stroke-width=\"1.5\"");
        player_shape(&mut self.svg, player, (cx, cy), r, &style);
    }

    /// A legend entry: a swatch drawn by `swatch` at its top-left corner, then `text`.
    fn legend(&mut self, text: &str, swatch: impl FnOnce(&mut Svg, f64, f64)) {
        let (x, y) = (self.legend_x, self.legend_y);
        swatch(&mut self.svg, x, y);
        self.svg
            .text(x + 26.0, y + 14.0, 12.5, Anchor::Start, "", text);
        self.legend_y += 26.0;
    }

    fn legend_heading(&mut self, text: &str) {
        let (x, y) = (self.legend_x, self.legend_y);
        self.svg.text(
            x,
            y + 14.0,
            13.0,
            Anchor::Start,
            "font-weight=\"bold\"",
            text,
        );
        self.legend_y += 24.0;
    }

    /// A legend entry with a player's shape in its colour.
    fn legend_player(&mut self, player: Owner, text: &str) {
        let fill = match player {
            Owner::Robot => BLUE,
            Owner::Adversary => ORANGE,
        };
        let style = format!("fill=\"{fill}\" stroke=\"#000000\" stroke-width=\"1.5\"");
        self.legend(text, |svg, x, y| {
            player_shape(svg, player, (x + 9.0, y + 9.0), 8.0, &style);
        });
    }

    fn legend_obstacle(&mut self) {
        let fill = format!("fill=\"{OBSTACLE_FILL}\"");
        self.legend("obstacle (O)", |svg, x, y| {
            svg.rect(x, y, 18.0, 18.0, &fill)
        });
    }
}

/// The map: grid, obstacles, labelled cells with their propositions, both starts.
pub fn map(world: &Gridworld, title: &[String]) -> String {
    let mut canvas = Canvas::new(world, title, 5);
    canvas.grid();
    canvas.propositions();
    canvas.player(Owner::Robot, world.robot, BLUE);
    canvas.player(Owner::Adversary, world.adversary, ORANGE);
    canvas.legend_heading("Legend");
    canvas.legend_player(Owner::Robot, "robot's start");
    canvas.legend_player(Owner::Adversary, "adversary's start");
    canvas.legend_obstacle();
    canvas.legend("A, B, ...: propositions of the cell", |_, _, _| {});
    canvas.svg.finish()
}

/// The win-label partition: each robot cell filled by the tag (or value) of the robot's
/// state there with the adversary on `adversary`, and the controller's mark; `key` is the
/// legend of the tags' colours.
pub fn partition(
    world: &Gridworld,
    title: &[String],
    adversary: Cell,
    cells: &[CellView],
    shading: Shading,
    key: &Key,
) -> String {
    let mut canvas = Canvas::new(world, title, 10 + key.entries.len());
    let g = canvas.geometry;
    for view in cells {
        let (x, y) = g.corner(view.cell);
        let fill = match (shading, &view.tag, view.value) {
            (Shading::Labels, Some(tag), _) => tag.colour.clone(),
            (Shading::Values { max }, _, Some(value)) => heat_colour(value / max.max(1e-300)),
            _ => "#ffffff".to_string(),
        };
        let mut tooltip = format!("robot at {}", view.cell);
        if let Some(tag) = &view.tag {
            tooltip += &format!(": {}", tag.text);
        }
        if let Some(value) = view.value {
            tooltip += &format!(", value {value:.2}");
        }
        canvas.svg.group(&tooltip);
        canvas
            .svg
            .rect(x, y, g.cell, g.cell, &format!("fill=\"{fill}\""));
        if g.roomy() {
            let text = match (shading, &view.tag, view.value) {
                (Shading::Values { .. }, _, Some(value)) => format!("{value:.0}"),
                (_, Some(tag), _) => tag.code.clone(),
                _ => "-".to_string(),
            };
            // Long codes (the general form's) in a smaller font, to stay inside the cell.
            let fitting = (g.cell - 6.0) / (0.62 * text.chars().count().max(1) as f64);
            let size = (g.cell * 0.2).min(fitting);
            let style = "fill=\"#000000\" stroke=\"#ffffff\" stroke-width=\"2.5\" \
                         paint-order=\"stroke\"";
            canvas.svg.text(
                x + g.cell - 3.0,
                y + g.cell - 4.0,
                size,
                Anchor::End,
                style,
                &text,
            );
        }
        if let Some(mark) = view.mark {
            draw_mark(&mut canvas.svg, g, view.cell, mark);
        }
        canvas.svg.end_group();
    }
    canvas.grid();
    canvas.propositions();
    canvas.player(Owner::Adversary, adversary, ORANGE);

    match shading {
        Shading::Labels => {
            canvas.legend_heading(&key.heading);
            for (colour, text) in &key.entries {
                match colour {
                    Some(colour) => {
                        let fill = format!("fill=\"{colour}\" stroke=\"#000000\"");
                        canvas.legend(text, |svg, x, y| svg.rect(x, y, 18.0, 18.0, &fill));
                    }
                    None => canvas.legend(text, |_, _, _| {}),
                }
            }
        }
        Shading::Values { max } => {
            canvas.legend_heading("Value of the robot's state");
            for step in [1.0, 0.75, 0.5, 0.25, 0.0] {
                let fill = format!("fill=\"{}\" stroke=\"#000000\"", heat_colour(step));
                canvas.legend(&format!("{:.0}", step * max), |svg, x, y| {
                    svg.rect(x, y, 18.0, 18.0, &fill);
                });
            }
        }
    }
    // The controller's legend only where the picture shows its marks.
    if cells.iter().any(|view| view.mark.is_some()) {
        canvas.legend_heading("Controller in each robot cell");
        let legend_geometry = Geometry {
            cell: 26.0,
            left: 0.0,
            top: 0.0,
            width: 1,
            height: 1,
        };
        for (mark, text) in [
            (Mark::Move(Move::E), "moves (arrow)"),
            (Mark::Stop, "stops: settles for a sub-task"),
            (Mark::Commit, "commits: plays to win a task"),
            (Mark::GiveUp, "gives up: stuck, nothing to gain"),
        ] {
            canvas.legend(text, |svg, x, y| {
                let shifted = Geometry {
                    left: x,
                    top: y,
                    ..legend_geometry
                };
                draw_mark(svg, shifted, Cell { x: 0, y: 0 }, mark);
            });
        }
    }
    canvas.legend_player(Owner::Adversary, "the adversary's cell");
    canvas.legend_obstacle();
    canvas.svg.finish()
}

/// The controller's mark in `cell`. The centre of the cell stays unpainted, so its colour is
/// the cell's fill (the raster test samples it).
fn draw_mark(svg: &mut Svg, g: Geometry, cell: Cell, mark: Mark) {
    let (cx, cy) = g.centre(cell);
    let c = g.cell;
    let width = (c / 14.0).max(1.5);
    let stroke = format!("stroke=\"#000000\" stroke-width=\"{width}\" fill=\"none\"");
    match mark {
        Mark::Move(Move::Stay) => svg.circle(cx, cy, c * 0.3, &stroke),
        Mark::Move(m) => {
            let (dx, dy) = Geometry::direction(m);
            let from = (cx + dx * c * 0.12, cy + dy * c * 0.12);
            let tip = (cx + dx * c * 0.46, cy + dy * c * 0.46);
            let base = (cx + dx * c * 0.28, cy + dy * c * 0.28);
            let (nx, ny) = (-dy * c * 0.11, dx * c * 0.11);
            svg.line(from, base, &stroke);
            svg.path(
                &[tip, (base.0 + nx, base.1 + ny), (base.0 - nx, base.1 - ny)],
                true,
                "fill=\"#000000\"",
            );
        }
        Mark::Stop => {
            let r = c * 0.22;
            svg.rect(cx - r, cy - r, 2.0 * r, 2.0 * r, &stroke);
        }
        Mark::Commit => {
            svg.circle(cx, cy, c * 0.16, &stroke);
            svg.circle(cx, cy, c * 0.26, &stroke);
        }
        Mark::GiveUp => {
            let (a, b) = (c * 0.1, c * 0.26);
            for (sx, sy) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
                svg.line(
                    (cx + sx * a, cy + sy * a),
                    (cx + sx * b, cy + sy * b),
                    &stroke,
                );
            }
        }
    }
}

/// A colour-blind-safe sequential scale (viridis' ends and three stops between) at `t` in
/// [0, 1].
pub fn heat_colour(t: f64) -> String {
    const STOPS: [(f64, f64, f64); 5] = [
        (68.0, 1.0, 84.0),
        (59.0, 82.0, 139.0),
        (33.0, 145.0, 140.0),
        (94.0, 201.0, 98.0),
        (253.0, 231.0, 37.0),
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let position = t * (STOPS.len() - 1) as f64;
    let i = (position.floor() as usize).min(STOPS.len() - 2);
    let f = position - i as f64;
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    let mix = |x: f64, y: f64| (x + (y - x) * f).round() as u8;
    format!(
        "#{:02X}{:02X}{:02X}",
        mix(a.0, b.0),
        mix(a.1, b.1),
        mix(a.2, b.2)
    )
}

/// A run: the robot's path (solid blue, circles) and the adversary's (dashed orange,
/// diamonds), each position numbered by the step at which the player got there, and a table
/// of the steps with their win-labels.
pub fn trace(world: &Gridworld, title: &[String], points: &[TracePoint]) -> String {
    const TABLE_ROWS: usize = 40;
    let shown = points.len().min(TABLE_ROWS);
    let mut canvas = Canvas::new(world, title, shown + 6);
    let g = canvas.geometry;
    canvas.grid();
    canvas.propositions();
    let offset = g.cell * 0.12;
    for (player, colour, dash, shift) in [
        (Owner::Robot, BLUE, "", -offset),
        (
            Owner::Adversary,
            ORANGE,
            " stroke-dasharray=\"6 4\"",
            offset,
        ),
    ] {
        let position = |p: &TracePoint| match player {
            Owner::Robot => p.robot,
            Owner::Adversary => p.adversary,
        };
        // The positions the player occupies, with the step at which it arrived.
        let mut stops: Vec<(usize, Cell)> = Vec::new();
        for (i, point) in points.iter().enumerate() {
            if stops.last().is_none_or(|&(_, c)| c != position(point)) {
                stops.push((i, position(point)));
            }
        }
        let path: Vec<(f64, f64)> = stops
            .iter()
            .map(|&(_, c)| {
                let (x, y) = g.centre(c);
                (x + shift, y + shift)
            })
            .collect();
        let width = (g.cell / 12.0).max(2.0);
        canvas.svg.path(
            &path,
            false,
            &format!("fill=\"none\" stroke=\"{colour}\" stroke-width=\"{width}\"{dash}"),
        );
        let r = (g.cell * 0.16).max(5.0);
        for (&(step, _), &(x, y)) in stops.iter().zip(&path) {
            let style = format!("fill=\"{colour}\" stroke=\"#000000\" stroke-width=\"1\"");
            canvas.svg.group(&format!("step {step}"));
            player_shape(&mut canvas.svg, player, (x, y), r, &style);
            // Three digits and more in a smaller font, to stay inside the marker.
            let size = if step >= 100 { r * 0.8 } else { r * 1.1 };
            canvas.svg.text(
                x,
                y + size * 0.36,
                size,
                Anchor::Middle,
                "fill=\"#ffffff\" font-weight=\"bold\"",
                &step.to_string(),
            );
            canvas.svg.end_group();
        }
    }
    canvas.legend_heading("Run (numbers: step of arrival)");
    canvas.legend_player(Owner::Robot, "robot's path");
    canvas.legend_player(Owner::Adversary, "adversary's path");
    canvas.legend_heading("step  robot  adversary  win-label  action");
    for (i, point) in points.iter().take(shown).enumerate() {
        let fill = format!("fill=\"{}\" stroke=\"#000000\"", point.tag.colour);
        let mover = match point.turn {
            Owner::Robot => "robot",
            Owner::Adversary => "adversary",
        };
        let action = point
            .action
            .as_deref()
            .map_or(String::new(), |a| format!("{mover} {a}"));
        let text = format!(
            "{i:>3}  {}  {}  {}  {action}",
            point.robot, point.adversary, point.tag.code
        );
        canvas.legend(&text, |svg, x, y| svg.rect(x, y + 2.0, 14.0, 14.0, &fill));
    }
    if points.len() > shown {
        let more = format!("... {} more steps", points.len() - shown);
        canvas.legend(&more, |_, _, _| {});
    }
    canvas.svg.finish()
}

#[cfg(test)]
mod tests {
    use super::*;

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

    #[test]
    fn cells_are_drawn_north_up() {
        let g = Geometry::new(&world(), 2);
        assert_eq!(g.cell, 56.0);
        // (0, 2) is the top-left cell, (2, 0) the bottom-right one.
        assert_eq!(g.corner(Cell { x: 0, y: 2 }), (g.left, g.top));
        assert_eq!(
            g.corner(Cell { x: 2, y: 0 }),
            (g.left + 2.0 * g.cell, g.top + 2.0 * g.cell)
        );
        assert_eq!(Geometry::direction(Move::N), (0.0, -1.0));
        let (dx, dy) = Geometry::direction(Move::SE);
        assert!((dx - 0.5f64.sqrt()).abs() < 1e-12 && (dy - 0.5f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn the_five_possible_labels_have_distinct_colours() {
        let mut colours: Vec<&str> = WinLabel::ALL[..5]
            .iter()
            .map(|&l| label_colour(l))
            .collect();
        colours.sort();
        colours.dedup();
        assert_eq!(colours.len(), 5);
        assert_eq!(heat_colour(0.0), "#440154");
        assert_eq!(heat_colour(1.0), "#FDE725");
        assert_eq!(heat_colour(0.5), "#21918C");
        // Halfway between the first two stops, rounded half away from zero.
        assert_eq!(heat_colour(0.125), "#402A70");
    }

    #[test]
    fn guarantee_classes_have_distinct_colours_and_none_is_vermillion() {
        // (At 255 classes some stops round to the same colour; the eye tells far fewer apart.)
        for count in [1, 4, 7, 12, 40] {
            let mut colours: Vec<String> = (0..count).map(|i| class_colour(i, count)).collect();
            colours.push(NOTHING_COLOUR.to_string());
            colours.sort();
            colours.dedup();
            assert_eq!(colours.len(), count + 1, "{count} classes");
        }
        // Up to seven: the largest guarantee is bluish green, as the paper's (W, W, W).
        assert_eq!(class_colour(0, 3), BLUISH_GREEN);
        assert_eq!(class_colour(6, 7), "#BBBBBB");
        // More: the light part of the value scale, the largest at its top.
        assert_eq!(class_colour(0, 8), heat_colour(1.0));
        assert_eq!(class_colour(7, 8), heat_colour(0.3));
    }

    #[test]
    fn the_map_shows_obstacles_propositions_and_both_starts() {
        let title = vec!["a <map>".to_string()];
        let svg = map(&world(), &title);
        assert!(svg.starts_with("<svg xmlns=\"http://www.w3.org/2000/svg\""));
        assert!(svg.contains("<title>a &lt;map&gt;</title>"));
        assert_eq!(svg.matches(&format!("fill=\"{OBSTACLE_FILL}\"")).count(), 2);
        assert!(svg.contains(">A,B</text>"));
        // The robot's circle and the adversary's diamond, plus one of each in the legend.
        assert_eq!(svg.matches("<circle").count(), 2);
        assert_eq!(svg.matches("<polygon").count(), 2);
    }
}

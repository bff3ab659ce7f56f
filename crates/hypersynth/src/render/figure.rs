//! A picture as an explicit list of shapes, each with its role, written as SVG and read back
//! from it; and the check that nothing in it overlaps ([`overlaps`]).
//!
//! Every shape's extent is known exactly: a text's box is its width in the bundled font
//! ([`super::font`], also written as `textLength`) by the font's ascent and descent. The SVG
//! carries each element's role as its `class`, so [`read`] gives back the items of any picture
//! this module wrote (the committed pictures are checked that way) without knowing how it was
//! laid out.
//!
//! The rule [`overlaps`] enforces: no text's box meets another text, a line (grid lines, a run's
//! paths), a controller's mark or a marker (players, swatches, frames), except the marker it is
//! written inside, which must contain it; and no mark or marker meets another. A text drawn on
//! an opaque backing box, or inside an opaque marker, may lie over what was drawn before that
//! box or marker. A mark is drawn in
//! several items (an arrow's shaft and head, over a white outline): consecutive mark items are
//! one mark, whose parts may meet.

use std::fmt::Write as _;

use super::font;
use super::svg::{escape, number};

/// The background's colour.
const BACKGROUND: &str = "#FFFFFF";

/// What an item is, for the overlap check.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// Backgrounds, cell fills, obstacles: text may lie on them.
    Fill,
    /// A line text must not cross: grid lines, a run's paths, tick marks.
    Line,
    /// A controller's mark: arrows, rings, squares, crosses.
    Mark,
    /// A solid shape: players and a run's markers, legend swatches, frames, the colour bar.
    Marker,
    /// An opaque box under the text that follows it, hiding what was drawn before.
    Backing,
    /// Text.
    Text,
}

impl Role {
    fn class(self) -> &'static str {
        match self {
            Role::Fill => "fill",
            Role::Line => "line",
            Role::Mark => "mark",
            Role::Marker => "marker",
            Role::Backing => "backing",
            Role::Text => "text",
        }
    }

    fn of_class(class: &str) -> Option<Role> {
        [
            Role::Fill,
            Role::Line,
            Role::Mark,
            Role::Marker,
            Role::Backing,
            Role::Text,
        ]
        .into_iter()
        .find(|role| role.class() == class)
    }
}

/// Where a text's `x` is on its baseline.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Anchor {
    /// The text begins at `x`.
    Start,
    /// The text is centred on `x`.
    Middle,
    /// The text ends at `x`.
    End,
}

impl Anchor {
    fn name(self) -> &'static str {
        match self {
            Anchor::Start => "start",
            Anchor::Middle => "middle",
            Anchor::End => "end",
        }
    }
}

/// An item's geometry, in pixels (y downwards).
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// A rectangle with its top-left corner at `(x, y)`.
    Rect {
        /// Left edge.
        x: f64,
        /// Top edge.
        y: f64,
        /// Width.
        width: f64,
        /// Height.
        height: f64,
    },
    /// A circle.
    Circle {
        /// Centre.
        centre: (f64, f64),
        /// Radius.
        r: f64,
    },
    /// An open path through the points (a line segment when there are two).
    Polyline(Vec<(f64, f64)>),
    /// A closed polygon.
    Polygon(Vec<(f64, f64)>),
    /// A line of text, `size` pixels high, whose baseline point `anchor` names is `(x, y)`.
    Text {
        /// Anchor's x.
        x: f64,
        /// Baseline.
        y: f64,
        /// Font size.
        size: f64,
        /// Where `x` is.
        anchor: Anchor,
        /// The text.
        text: String,
        /// Its width (the SVG's `textLength`).
        width: f64,
    },
}

/// One shape of a picture with its paint and role.
#[derive(Clone, Debug, PartialEq)]
pub struct Item {
    /// The geometry.
    pub shape: Shape,
    /// The role.
    pub role: Role,
    /// The fill colour; `None` for an outline (`fill="none"`).
    pub fill: Option<String>,
    /// The outline's colour and width, if any.
    pub stroke: Option<(String, f64)>,
    /// Other SVG attributes, written as given (a dash pattern, a halo).
    pub extra: String,
    /// For a text: it is written inside the last [`Role::Marker`] before it.
    pub inside: bool,
}

impl Item {
    fn stroke_width(&self) -> f64 {
        self.stroke.as_ref().map_or(0.0, |(_, w)| *w)
    }
}

/// What a figure holds, in drawing order.
#[derive(Clone, Debug, PartialEq)]
enum Element {
    Item(Item),
    /// Opens a group with a tooltip.
    Group(String),
    /// Closes the last group.
    End,
    /// Raw SVG (definitions), written as given.
    Raw(String),
}

/// A picture being built: its size, its accessible description and its elements in drawing
/// order.
#[derive(Clone, Debug, PartialEq)]
pub struct Figure {
    width: f64,
    height: f64,
    description: String,
    elements: Vec<Element>,
}

/// Paint for [`Figure::shape`]: fill, stroke.
#[derive(Clone, Copy, Debug)]
pub struct Paint<'a> {
    /// Fill colour, `None` for none.
    pub fill: Option<&'a str>,
    /// Stroke colour and width.
    pub stroke: Option<(&'a str, f64)>,
    /// Other attributes, e.g. `stroke-dasharray="6 4"`.
    pub extra: &'a str,
}

impl Paint<'_> {
    /// A solid fill without outline.
    pub fn fill(colour: &str) -> Paint<'_> {
        Paint {
            fill: Some(colour),
            stroke: None,
            extra: "",
        }
    }

    /// An outline without fill.
    pub fn outline(colour: &str, width: f64) -> Paint<'_> {
        Paint {
            fill: None,
            stroke: Some((colour, width)),
            extra: "",
        }
    }

    /// A fill with an outline.
    pub fn filled<'a>(fill: &'a str, stroke: &'a str, width: f64) -> Paint<'a> {
        Paint {
            fill: Some(fill),
            stroke: Some((stroke, width)),
            extra: "",
        }
    }
}

impl Figure {
    /// An empty figure of `width` × `height` pixels described by `description` (its `<title>`,
    /// the accessible name).
    pub fn new(width: f64, height: f64, description: &str) -> Figure {
        Figure {
            width,
            height,
            description: description.to_string(),
            elements: Vec::new(),
        }
    }

    /// Sets the size (when it is known only once everything is placed).
    pub fn resize(&mut self, width: f64, height: f64) {
        self.width = width;
        self.height = height;
    }

    /// Adds a shape.
    pub fn shape(&mut self, shape: Shape, role: Role, paint: Paint) {
        self.elements.push(Element::Item(Item {
            shape,
            role,
            fill: paint.fill.map(str::to_string),
            stroke: paint.stroke.map(|(c, w)| (c.to_string(), w)),
            extra: paint.extra.to_string(),
            inside: false,
        }));
    }

    /// Adds `text` at `(x, y)` in `size` pixels, filled with `colour`; `extra` as in [`Paint`].
    /// Returns its box `(left, top, right, bottom)`.
    #[allow(clippy::too_many_arguments)]
    pub fn text(
        &mut self,
        (x, y): (f64, f64),
        size: f64,
        anchor: Anchor,
        colour: &str,
        extra: &str,
        text: &str,
        inside: bool,
    ) -> (f64, f64, f64, f64) {
        // As written: two decimals.
        let width = (font::width(text, size) * 100.0).round() / 100.0;
        let shape = Shape::Text {
            x,
            y,
            size,
            anchor,
            text: text.to_string(),
            width,
        };
        let bounds = text_box(&shape);
        self.elements.push(Element::Item(Item {
            shape,
            role: Role::Text,
            fill: Some(colour.to_string()),
            stroke: None,
            extra: extra.to_string(),
            inside,
        }));
        bounds
    }

    /// Opens a group carrying a tooltip, closed by [`Figure::end_group`].
    pub fn group(&mut self, tooltip: &str) {
        self.elements.push(Element::Group(tooltip.to_string()));
    }

    /// Closes the group opened last.
    pub fn end_group(&mut self) {
        self.elements.push(Element::End);
    }

    /// Adds raw SVG (definitions such as a gradient), written as given.
    pub fn raw(&mut self, svg: &str) {
        self.elements.push(Element::Raw(svg.to_string()));
    }

    /// The items, in drawing order, starting with the white background.
    pub fn items(&self) -> Vec<Item> {
        let background = Item {
            shape: Shape::Rect {
                x: 0.0,
                y: 0.0,
                width: self.width,
                height: self.height,
            },
            role: Role::Fill,
            fill: Some(BACKGROUND.to_string()),
            stroke: None,
            extra: String::new(),
            inside: false,
        };
        std::iter::once(background)
            .chain(self.elements.iter().filter_map(|e| match e {
                Element::Item(item) => Some(item.clone()),
                _ => None,
            }))
            .collect()
    }

    /// The SVG document: one element per line, each with its role as `class`.
    pub fn to_svg(&self) -> String {
        let mut out = String::new();
        let (w, h) = (number(self.width), number(self.height));
        let _ = writeln!(
            out,
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" \
             viewBox=\"0 0 {w} {h}\" font-family=\"{}\">",
            font::FAMILY
        );
        let _ = writeln!(out, "<title>{}</title>", escape(&self.description));
        let _ = writeln!(
            out,
            "<rect class=\"fill\" x=\"0\" y=\"0\" width=\"{w}\" height=\"{h}\" \
             fill=\"{BACKGROUND}\"/>"
        );
        for element in &self.elements {
            match element {
                Element::Item(item) => write_item(&mut out, item),
                Element::Group(tooltip) => {
                    let _ = writeln!(out, "<g><title>{}</title>", escape(tooltip));
                }
                Element::End => out.push_str("</g>\n"),
                Element::Raw(text) => {
                    out.push_str(text);
                    out.push('\n');
                }
            }
        }
        out.push_str("</svg>\n");
        out
    }
}

/// The paint attributes of `item`.
fn paint(item: &Item) -> String {
    let mut out = match &item.fill {
        Some(fill) => format!("fill=\"{fill}\""),
        None => "fill=\"none\"".to_string(),
    };
    if let Some((colour, width)) = &item.stroke {
        let _ = write!(
            out,
            " stroke=\"{colour}\" stroke-width=\"{}\"",
            number(*width)
        );
    }
    if !item.extra.is_empty() {
        out.push(' ');
        out.push_str(&item.extra);
    }
    out
}

fn points(points: &[(f64, f64)]) -> String {
    let points: Vec<String> = points
        .iter()
        .map(|&(x, y)| format!("{},{}", number(x), number(y)))
        .collect();
    points.join(" ")
}

fn write_item(out: &mut String, item: &Item) {
    let mut class = item.role.class().to_string();
    if item.inside {
        class += " inside";
    }
    let paint = paint(item);
    let _ = match &item.shape {
        Shape::Rect {
            x,
            y,
            width,
            height,
        } => writeln!(
            out,
            "<rect class=\"{class}\" x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" {paint}/>",
            number(*x),
            number(*y),
            number(*width),
            number(*height)
        ),
        Shape::Circle { centre, r } => writeln!(
            out,
            "<circle class=\"{class}\" cx=\"{}\" cy=\"{}\" r=\"{}\" {paint}/>",
            number(centre.0),
            number(centre.1),
            number(*r)
        ),
        Shape::Polyline(p) => writeln!(
            out,
            "<polyline class=\"{class}\" points=\"{}\" {paint}/>",
            points(p)
        ),
        Shape::Polygon(p) => writeln!(
            out,
            "<polygon class=\"{class}\" points=\"{}\" {paint}/>",
            points(p)
        ),
        Shape::Text {
            x,
            y,
            size,
            anchor,
            text,
            width,
        } => writeln!(
            out,
            "<text class=\"{class}\" x=\"{}\" y=\"{}\" font-size=\"{}\" text-anchor=\"{}\" \
             textLength=\"{}\" lengthAdjust=\"spacingAndGlyphs\" {paint}>{}</text>",
            number(*x),
            number(*y),
            number(*size),
            anchor.name(),
            number(*width),
            escape(text)
        ),
    };
}

/// Why [`read`] could not read a picture back.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("line {line}: {message}")]
pub struct ReadError {
    /// The line (1-based).
    pub line: usize,
    /// What is wrong.
    pub message: String,
}

/// The items of a picture [`Figure::to_svg`] wrote, in drawing order, as [`Figure::items`]
/// gives them (groups and definitions left out).
pub fn read(svg: &str) -> Result<Vec<Item>, ReadError> {
    let mut items = Vec::new();
    for (index, line) in svg.lines().enumerate() {
        let error = |message: String| ReadError {
            line: index + 1,
            message,
        };
        let Some(rest) = line.strip_prefix('<') else {
            continue;
        };
        let Some(tag) = rest.split([' ', '>', '/']).next() else {
            continue;
        };
        if !matches!(tag, "rect" | "circle" | "polyline" | "polygon" | "text") {
            continue;
        }
        let head = match tag {
            "text" => &line[..line.find('>').unwrap_or(line.len())],
            _ => line,
        };
        let attribute = |name: &str| -> Option<&str> {
            let key = format!(" {name}=\"");
            let start = head.find(&key)? + key.len();
            let end = start + head[start..].find('"')?;
            Some(&head[start..end])
        };
        let Some(class) = attribute("class") else {
            continue;
        };
        let mut classes = class.split(' ');
        let role = classes
            .next()
            .and_then(Role::of_class)
            .ok_or_else(|| error(format!("unknown class `{class}`")))?;
        let inside = classes.any(|c| c == "inside");
        let num = |name: &str| -> Result<f64, ReadError> {
            attribute(name)
                .and_then(|v| v.parse().ok())
                .ok_or_else(|| error(format!("no number `{name}`")))
        };
        let point_list = || -> Result<Vec<(f64, f64)>, ReadError> {
            let text = attribute("points").ok_or_else(|| error("no points".into()))?;
            text.split(' ')
                .map(|p| {
                    let (x, y) = p.split_once(',')?;
                    Some((x.parse().ok()?, y.parse().ok()?))
                })
                .collect::<Option<Vec<_>>>()
                .ok_or_else(|| error(format!("bad points `{text}`")))
        };
        let shape = match tag {
            "rect" => Shape::Rect {
                x: num("x")?,
                y: num("y")?,
                width: num("width")?,
                height: num("height")?,
            },
            "circle" => Shape::Circle {
                centre: (num("cx")?, num("cy")?),
                r: num("r")?,
            },
            "polyline" => Shape::Polyline(point_list()?),
            "polygon" => Shape::Polygon(point_list()?),
            _ => {
                let anchor = match attribute("text-anchor") {
                    Some("middle") => Anchor::Middle,
                    Some("end") => Anchor::End,
                    _ => Anchor::Start,
                };
                let content = line[head.len() + 1..]
                    .strip_suffix("</text>")
                    .ok_or_else(|| error("a text not closed on its line".into()))?;
                Shape::Text {
                    x: num("x")?,
                    y: num("y")?,
                    size: num("font-size")?,
                    anchor,
                    text: unescape(content),
                    width: num("textLength")?,
                }
            }
        };
        let fill = match attribute("fill") {
            Some("none") | None => None,
            Some(colour) => Some(colour.to_string()),
        };
        let stroke = match (attribute("stroke"), attribute("stroke-width")) {
            (Some(colour), Some(width)) => width.parse().ok().map(|w| (colour.to_string(), w)),
            _ => None,
        };
        items.push(Item {
            shape,
            role,
            fill,
            stroke,
            extra: String::new(),
            inside,
        });
    }
    Ok(items)
}

fn unescape(text: &str) -> String {
    text.replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&quot;", "\"")
        .replace("&amp;", "&")
}

/// A text's box `(left, top, right, bottom)`.
pub fn text_box(shape: &Shape) -> (f64, f64, f64, f64) {
    match shape {
        Shape::Text {
            x,
            y,
            size,
            anchor,
            width,
            ..
        } => {
            let left = match anchor {
                Anchor::Start => *x,
                Anchor::Middle => x - width / 2.0,
                Anchor::End => x - width,
            };
            (
                left,
                y - font::ASCENT * size,
                left + width,
                y + font::DESCENT * size,
            )
        }
        _ => (0.0, 0.0, 0.0, 0.0),
    }
}

/// A convex polygon.
type Piece = Vec<(f64, f64)>;

fn rectangle(left: f64, top: f64, right: f64, bottom: f64) -> Piece {
    vec![(left, top), (right, top), (right, bottom), (left, bottom)]
}

/// The segment from `a` to `b` drawn `width` wide, as a rectangle.
fn thick_segment(a: (f64, f64), b: (f64, f64), width: f64) -> Piece {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let length = dx.hypot(dy);
    if length == 0.0 {
        let h = width / 2.0;
        return rectangle(a.0 - h, a.1 - h, a.0 + h, a.1 + h);
    }
    let (nx, ny) = (-dy / length * width / 2.0, dx / length * width / 2.0);
    vec![
        (a.0 + nx, a.1 + ny),
        (b.0 + nx, b.1 + ny),
        (b.0 - nx, b.1 - ny),
        (a.0 - nx, a.1 - ny),
    ]
}

/// A circle of radius `r` as a 32-gon.
fn circle_points(centre: (f64, f64), r: f64) -> Vec<(f64, f64)> {
    (0..32)
        .map(|i| {
            let angle = f64::from(i) * std::f64::consts::TAU / 32.0;
            (centre.0 + r * angle.cos(), centre.1 + r * angle.sin())
        })
        .collect()
}

/// The closed outline through `points`, `width` wide.
fn outline(points: &[(f64, f64)], width: f64) -> Vec<Piece> {
    (0..points.len())
        .map(|i| thick_segment(points[i], points[(i + 1) % points.len()], width))
        .collect()
}

/// What an item paints, as convex pieces: its interior when filled, its outline when stroked.
fn pieces(item: &Item) -> Vec<Piece> {
    let stroke = item.stroke_width();
    let filled = item.fill.is_some();
    match &item.shape {
        Shape::Text { .. } => {
            let (l, t, r, b) = text_box(&item.shape);
            vec![rectangle(l, t, r, b)]
        }
        Shape::Rect {
            x,
            y,
            width,
            height,
        } => {
            let corners = rectangle(*x, *y, x + width, y + height);
            if filled {
                let h = stroke / 2.0;
                vec![rectangle(x - h, y - h, x + width + h, y + height + h)]
            } else {
                outline(&corners, stroke)
            }
        }
        Shape::Circle { centre, r } => {
            if filled {
                vec![circle_points(*centre, r + stroke / 2.0)]
            } else {
                outline(&circle_points(*centre, *r), stroke)
            }
        }
        Shape::Polygon(points) => {
            let mut pieces = if stroke > 0.0 {
                outline(points, stroke)
            } else {
                Vec::new()
            };
            if filled {
                pieces.push(points.clone());
            }
            pieces
        }
        Shape::Polyline(points) => points
            .windows(2)
            .map(|pair| thick_segment(pair[0], pair[1], stroke.max(1.0)))
            .collect(),
    }
}

/// How far two convex polygons overlap: the smallest penetration over the separating axes of
/// both (0 or less: they do not).
fn penetration(a: &Piece, b: &Piece) -> f64 {
    let mut smallest = f64::INFINITY;
    for polygon in [a, b] {
        for i in 0..polygon.len() {
            let (p, q) = (polygon[i], polygon[(i + 1) % polygon.len()]);
            let (nx, ny) = (p.1 - q.1, q.0 - p.0);
            let length = nx.hypot(ny);
            if length == 0.0 {
                continue;
            }
            let project = |points: &Piece| {
                points
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &(x, y)| {
                        let d = (x * nx + y * ny) / length;
                        (lo.min(d), hi.max(d))
                    })
            };
            let ((a_lo, a_hi), (b_lo, b_hi)) = (project(a), project(b));
            smallest = smallest.min(a_hi.min(b_hi) - a_lo.max(b_lo));
        }
    }
    smallest
}

fn bounds(piece: &Piece) -> (f64, f64, f64, f64) {
    piece.iter().fold(
        (
            f64::INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
        ),
        |(l, t, r, b), &(x, y)| (l.min(x), t.min(y), r.max(x), b.max(y)),
    )
}

/// Overlaps smaller than this (in pixels) are rounding, not overlaps.
const TOLERANCE: f64 = 0.3;

fn meet(a: &[Piece], b: &[Piece]) -> bool {
    a.iter().any(|p| {
        let (l1, t1, r1, b1) = bounds(p);
        b.iter().any(|q| {
            let (l2, t2, r2, b2) = bounds(q);
            l1 < r2 - TOLERANCE
                && l2 < r1 - TOLERANCE
                && t1 < b2 - TOLERANCE
                && t2 < b1 - TOLERANCE
                && penetration(p, q) > TOLERANCE
        })
    })
}

/// Whether every corner of `text`'s box lies inside `container`'s shape, at least half its
/// stroke away from the outline.
fn contains(container: &Item, text: &Item) -> bool {
    let (l, t, r, b) = text_box(&text.shape);
    let polygon = match &container.shape {
        Shape::Circle { centre, r } => circle_points(*centre, *r),
        Shape::Polygon(points) => points.clone(),
        Shape::Rect {
            x,
            y,
            width,
            height,
        } => rectangle(*x, *y, x + width, y + height),
        _ => return false,
    };
    let inset = container.stroke_width() / 2.0 - TOLERANCE;
    let n = polygon.len();
    // The signed distance of `p` from edge `i`, positive on the side of the polygon's
    // interior whatever its orientation.
    let cross = |p: (f64, f64), i: usize| {
        let (a, b) = (polygon[i], polygon[(i + 1) % n]);
        ((b.0 - a.0) * (p.1 - a.1) - (b.1 - a.1) * (p.0 - a.0)) / (b.0 - a.0).hypot(b.1 - a.1)
    };
    let orientation = (0..n)
        .map(|i| cross(polygon[(i + 2) % n], i))
        .sum::<f64>()
        .signum();
    [(l, t), (r, t), (r, b), (l, b)]
        .iter()
        .all(|&p| (0..n).all(|i| cross(p, i) * orientation >= inset))
}

fn describe(item: &Item) -> String {
    match &item.shape {
        Shape::Text { text, x, y, .. } => format!("text `{text}` at ({x:.1}, {y:.1})"),
        shape => {
            let (l, t, _, _) = pieces(item).iter().map(bounds).fold(
                (
                    f64::INFINITY,
                    f64::INFINITY,
                    f64::NEG_INFINITY,
                    f64::NEG_INFINITY,
                ),
                |a, b| (a.0.min(b.0), a.1.min(b.1), a.2.max(b.2), a.3.max(b.3)),
            );
            let kind = match shape {
                Shape::Rect { .. } => "rect",
                Shape::Circle { .. } => "circle",
                Shape::Polyline(_) => "polyline",
                Shape::Polygon(_) => "polygon",
                Shape::Text { .. } => "text",
            };
            format!("{} {kind} near ({l:.1}, {t:.1})", item.role.class())
        }
    }
}

/// Every pair of items of a picture (in drawing order) that overlap against the rule of this
/// module, described. Quadratic in the items but for a bounding-box test per pair.
pub fn overlaps(items: &[Item]) -> Vec<String> {
    let shapes: Vec<Vec<Piece>> = items.iter().map(pieces).collect();
    let mut found = Vec::new();
    // The container of each text written inside a marker: the last marker before it.
    let mut last_marker = None;
    let mut containers = vec![None; items.len()];
    // The backing of each text drawn on one: the backing right before it.
    let mut backings = vec![None; items.len()];
    // Each mark item's mark: the first of its run of consecutive mark items.
    let mut marks = vec![usize::MAX; items.len()];
    for (i, item) in items.iter().enumerate() {
        match item.role {
            Role::Mark => {
                marks[i] = if i > 0 && items[i - 1].role == Role::Mark {
                    marks[i - 1]
                } else {
                    i
                };
            }
            Role::Marker => last_marker = Some(i),
            Role::Text => {
                if item.inside {
                    containers[i] = last_marker;
                }
                if i > 0 && items[i - 1].role == Role::Backing {
                    backings[i] = Some(i - 1);
                }
            }
            _ => {}
        }
    }
    for (i, item) in items.iter().enumerate() {
        match item.role {
            Role::Text => {
                if item.inside {
                    match containers[i] {
                        Some(c) if contains(&items[c], item) => {}
                        _ => found.push(format!("{} is not inside its marker", describe(item))),
                    }
                }
                for (j, other) in items.iter().enumerate() {
                    if j == i
                        || Some(j) == containers[i]
                        || !matches!(
                            other.role,
                            Role::Text | Role::Line | Role::Mark | Role::Marker
                        )
                        || (other.role == Role::Text && j < i)
                    {
                        continue;
                    }
                    // Hidden under this text's backing, or under the marker it is inside (which
                    // holds it, as checked above).
                    if backings[i].or(containers[i]).is_some_and(|b| j < b) {
                        continue;
                    }
                    // Hidden under the other text's backing (drawn after this one).
                    if other.role == Role::Text && backings[j].is_some_and(|b| i < b) {
                        continue;
                    }
                    if meet(&shapes[i], &shapes[j]) {
                        found.push(format!("{} meets {}", describe(item), describe(other)));
                    }
                }
            }
            Role::Mark | Role::Marker => {
                for (j, other) in items.iter().enumerate().skip(i + 1) {
                    let same_mark = item.role == Role::Mark && marks[j] == marks[i];
                    if matches!(other.role, Role::Mark | Role::Marker)
                        && !same_mark
                        && meet(&shapes[i], &shapes[j])
                    {
                        found.push(format!("{} meets {}", describe(item), describe(other)));
                    }
                }
            }
            _ => {}
        }
    }
    found
}

#[cfg(test)]
mod tests {
    use super::*;

    fn text_at(figure: &mut Figure, x: f64, y: f64, text: &str) {
        figure.text((x, y), 10.0, Anchor::Start, "#000000", "", text, false);
    }

    #[test]
    fn a_picture_reads_back_as_written() {
        let mut figure = Figure::new(100.0, 50.0, "a <b>");
        figure.shape(
            Shape::Rect {
                x: 1.0,
                y: 2.0,
                width: 3.0,
                height: 4.0,
            },
            Role::Fill,
            Paint::fill("#FF0000"),
        );
        figure.group("tip");
        figure.shape(
            Shape::Circle {
                centre: (20.0, 20.0),
                r: 8.0,
            },
            Role::Marker,
            Paint::filled("#0072B2", "#000000", 1.5),
        );
        figure.text(
            (20.0, 21.12),
            4.0,
            Anchor::Middle,
            "#FFFFFF",
            "",
            "1<2",
            true,
        );
        figure.end_group();
        figure.shape(
            Shape::Polyline(vec![(0.0, 0.0), (10.0, 5.5)]),
            Role::Line,
            Paint::outline("#999999", 1.0),
        );
        let svg = figure.to_svg();
        assert!(svg.contains("<title>a &lt;b&gt;</title>"));
        assert!(svg.contains(">1&lt;2</text>"));
        assert_eq!(read(&svg).unwrap(), figure.items());
        assert!(overlaps(&figure.items()).is_empty());
    }

    #[test]
    fn texts_must_not_meet_texts_lines_marks_or_markers() {
        let mut figure = Figure::new(200.0, 100.0, "");
        // "ab" at 10 px: 12.7 px wide, from y = 2.4 to 13.
        text_at(&mut figure, 10.0, 10.0, "ab");
        text_at(&mut figure, 24.0, 10.0, "cd");
        assert!(overlaps(&figure.items()).is_empty());
        text_at(&mut figure, 20.0, 14.0, "ef");
        assert_eq!(overlaps(&figure.items()).len(), 2);

        let mut figure = Figure::new(200.0, 100.0, "");
        text_at(&mut figure, 10.0, 10.0, "ab");
        // A vertical line 1 px wide at x = 30 misses it; at x = 15 it crosses it.
        for (x, expected) in [(30.0, 0), (15.0, 1)] {
            let mut f = figure.clone();
            f.shape(
                Shape::Polyline(vec![(x, 0.0), (x, 50.0)]),
                Role::Line,
                Paint::outline("#000000", 1.0),
            );
            assert_eq!(overlaps(&f.items()).len(), expected, "x = {x}");
        }
        // A ring around the text does not meet it; a filled disc does.
        for (fill, expected) in [(None, 0), (Some("#000000"), 1)] {
            let mut f = figure.clone();
            f.shape(
                Shape::Circle {
                    centre: (16.0, 8.0),
                    r: 12.0,
                },
                Role::Mark,
                Paint {
                    fill,
                    stroke: Some(("#000000", 1.0)),
                    extra: "",
                },
            );
            assert_eq!(overlaps(&f.items()).len(), expected, "{fill:?}");
        }
        // A diagonal arrow passing the box's corner at a distance misses it.
        let mut f = figure.clone();
        f.shape(
            Shape::Polyline(vec![(26.0, 0.0), (40.0, 14.0)]),
            Role::Mark,
            Paint::outline("#000000", 2.0),
        );
        assert!(overlaps(&f.items()).is_empty());
    }

    #[test]
    fn a_text_inside_a_marker_must_fit_it_and_a_backing_hides_what_came_before() {
        for (digits, fits) in [("7", true), ("10", true), ("100", false)] {
            let mut figure = Figure::new(100.0, 100.0, "");
            let r = 10.0;
            figure.shape(
                Shape::Polygon(vec![
                    (50.0, 50.0 - r),
                    (50.0 + r, 50.0),
                    (50.0, 50.0 + r),
                    (50.0 - r, 50.0),
                ]),
                Role::Marker,
                Paint::filled("#E69F00", "#000000", 1.0),
            );
            // The box centred on the marker: 8 * (0.8 - 0.24) / 2 below the centre.
            let baseline = 50.0 + 8.0 * (font::ASCENT - font::DESCENT) / 2.0;
            figure.text(
                (50.0, baseline),
                8.0,
                Anchor::Middle,
                "#000000",
                "",
                digits,
                true,
            );
            assert_eq!(overlaps(&figure.items()).is_empty(), fits, "{digits}");
        }
        let mut figure = Figure::new(100.0, 100.0, "");
        figure.shape(
            Shape::Polyline(vec![(0.0, 6.0), (100.0, 6.0)]),
            Role::Line,
            Paint::outline("#0072B2", 3.0),
        );
        let mut backed = figure.clone();
        text_at(&mut figure, 10.0, 10.0, "A");
        assert_eq!(overlaps(&figure.items()).len(), 1);
        backed.shape(
            Shape::Rect {
                x: 9.0,
                y: 1.0,
                width: 10.0,
                height: 12.0,
            },
            Role::Backing,
            Paint::fill("#FFFFFF"),
        );
        text_at(&mut backed, 10.0, 10.0, "A");
        assert!(overlaps(&backed.items()).is_empty());
    }
}

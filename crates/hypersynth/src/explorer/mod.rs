//! The interactive explorer: one self-contained HTML page (inline script, style and SVG; no
//! network) that shows a solved problem on its map slice by slice, the decision table of any
//! robot state it embeds, a seeded run step by step, and lets the user play the adversary
//! against the controller.
//!
//! This module holds the page's data as plain values ([`Page`]) and assembles the page
//! ([`html`]); `pipeline::explorer` computes the data from a solved problem. The page's code
//! and style are files of this directory (`page.html`, `page.css`, `page.js`), embedded at
//! compile time.
//!
//! **Data.** The page is a function of [`Page`], serialised to JSON, compressed (zlib) and
//! embedded in base 64; the page decompresses it with the browser's own `DecompressionStream`.
//! Per-state facts are dense [`Table`]s (the exported controller's base-64 tables) over the
//! *slices* the page covers: slice `(t, a)` is the automata tuple `coverage.tuples[t]` with
//! the adversary on free cell `coverage.adversaries[a]`, and entry `(t · A + a) · F + r` is the
//! state with the robot on free cell `r` (`F` free cells, `A` covered adversary cells).
//!
//! **User text stays text.** File names, formulas and task names reach the page only inside
//! the compressed data (base 64: no markup can form) and in the `<title>`, escaped; the script
//! writes them with `textContent` and SVG text nodes, never as markup, and evaluates nothing.
//! The page's Content-Security-Policy allows only its own script and style (by their SHA-256)
//! and no network at all, so that even a mistake there could not run a script or fetch
//! anything. The style and the script contain no `</`, so that they cannot close their element
//! (tested).

mod encode;

use serde::Serialize;

use crate::opportunistic::controller::Explanation;
use crate::opportunistic::export::{AutomatonTable, Table};
use crate::render::{Key, Tag};

pub use encode::{base64, sha256};

/// The format and version of the page's data.
pub const FORMAT: &str = "hypersynth-explorer/1";

/// Everything the page shows.
#[derive(Clone, Debug, Serialize)]
pub struct Page {
    /// [`FORMAT`].
    pub format: &'static str,
    /// The map's name (its file), shown as the page's heading.
    pub title: String,
    /// The tasks and the settings, one line each.
    pub lines: Vec<String>,
    /// The headline figures of the report: a name and its value, one per line.
    pub summary: Vec<(String, String)>,
    /// The whole text report.
    pub report: String,
    /// What the page leaves out (larger problems), one sentence each.
    pub notes: Vec<String>,
    /// The map.
    pub grid: Grid,
    /// The product's automata, in product order.
    pub automata: Vec<Automaton>,
    /// The product's automata tuples (its slots: one state per automaton).
    pub tuples: Vec<Vec<u32>>,
    /// Where plays start.
    pub start: Start,
    /// How robot states show: fill, code and label, referred to by index.
    pub tags: Vec<Tag>,
    /// The legend of the fills.
    pub key: Key,
    /// The value scale in 101 steps, spread over the positive values of the slice shown (as
    /// the static value picture's).
    pub heat: Vec<String>,
    /// The fill of a state worth 0 (nothing can be gained).
    pub nothing: String,
    /// The fills of [`Page::tags`], [`Page::heat`] and [`Page::nothing`] on which marks are
    /// drawn white rather than black (as in the static pictures).
    pub dark: Vec<String>,
    /// The largest payoff.
    pub max: f64,
    /// The controller's decisions before committing, referred to by index.
    pub choices: Vec<Choice>,
    /// How reports name each set of sub-tasks, by mask (the empty set's entry is empty).
    pub sets: Vec<String>,
    /// Which slices the page covers, and what it knows of their states.
    pub slices: Slices,
    /// Decision tables, by state index (see the module documentation).
    pub tables: Vec<(usize, Explanation)>,
    /// The seeded run, when the MDP stage ran.
    pub run: Option<Run>,
}

/// The map: its free cells, labels, moves and collision rule.
#[derive(Clone, Debug, Serialize)]
pub struct Grid {
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// The free cells `(x, y)`, by `x` then `y`: cell `r` of the state indices.
    pub cells: Vec<(u32, u32)>,
    /// Labelled cells: a proposition and a free cell's index.
    pub labels: Vec<(String, usize)>,
    /// `forbidden`, `allowed` or `label:NAME`.
    pub collision: String,
    /// Per free cell, the letter (an index into the automata's step tables) of a state with the
    /// robot there and the adversary elsewhere.
    pub letters: Vec<u32>,
    /// Per free cell, the letter of a state with both players there.
    pub shared: Vec<u32>,
    /// The robot's moves.
    pub robot_moves: Vec<Move>,
    /// The adversary's moves.
    pub adversary_moves: Vec<Move>,
}

/// A move: its action name and the change of `(x, y)`.
#[derive(Clone, Debug, Serialize)]
pub struct Move {
    /// The action's name.
    pub name: String,
    /// The change of `x` (eastward).
    pub dx: i64,
    /// The change of `y` (northward).
    pub dy: i64,
}

/// An automaton of the product.
#[derive(Clone, Debug, Serialize)]
pub struct Automaton {
    /// Its states' name in titles (`q1`, `q_A`).
    pub title: String,
    /// The states the product enumerates.
    pub states: Vec<u32>,
    /// Its table over the letters (as the exported controller's).
    pub table: AutomatonTable,
}

/// Where the map's plays start.
#[derive(Clone, Debug, Serialize)]
pub struct Start {
    /// The robot's cell (a free cell's index).
    pub robot: usize,
    /// The adversary's cell.
    pub adversary: usize,
    /// Whether the robot moves first.
    pub robot_first: bool,
    /// The automata tuple of h0.
    pub tuple: usize,
}

/// A decision of the controller before it commits.
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Choice {
    /// A robot move, by index into `grid.robot_moves`.
    Move(usize),
    /// `stop` and commit to a set (a mask).
    Stop(u8),
    /// Commit to a set without moving (an absorbing state).
    Commit(u8),
    /// Nothing can be gained.
    GiveUp,
}

/// The slices the page covers and, per state of theirs, what it knows.
#[derive(Clone, Debug, Serialize)]
pub struct Slices {
    /// The covered automata tuples (indices into `tuples`).
    pub tuples: Vec<usize>,
    /// The covered adversary cells (free cells' indices).
    pub adversaries: Vec<usize>,
    /// Per robot state: its tag (dots: no such product state).
    pub tags: Table,
    /// Per robot state: the controller's choice; `None` without the MDP stage.
    pub choices: Option<Table>,
    /// Per robot state: its value (lower bound) in hundredths; `None` without the MDP stage.
    pub values: Option<Table>,
    /// Per set the controller may commit to (a mask), per robot state: the move of its reactive
    /// strategy (dots: none, or the set holds); empty when the page does not offer play.
    pub reactive: Vec<(u8, Table)>,
    /// Per adversary state (same indices, the adversary to move): bit 0 whether it is worth 0,
    /// bit `1 + m` whether the model gives adversary move `m` a positive probability; `None`
    /// when the page does not offer play.
    pub adversary: Option<Table>,
}

/// The seeded run of the controller (the report's trace).
#[derive(Clone, Debug, Serialize)]
pub struct Run {
    /// The seed.
    pub seed: u64,
    /// Its steps from h0.
    pub steps: Vec<RunStep>,
    /// How it ended, as the report names it.
    pub outcome: String,
    /// What it paid.
    pub payoff: f64,
}

/// One step of the run.
#[derive(Clone, Debug, Serialize)]
pub struct RunStep {
    /// The robot's cell.
    pub robot: usize,
    /// The adversary's cell.
    pub adversary: usize,
    /// Whether the robot moves here.
    pub robot_turn: bool,
    /// The automata tuple.
    pub tuple: usize,
    /// The product state's name.
    pub state: String,
    /// Its label.
    pub label: String,
    /// The action played here, if any.
    pub action: Option<String>,
    /// The set committed to so far, if any.
    pub committed: Option<String>,
}

/// The page's template, style and script.
const TEMPLATE: &str = include_str!("page.html");
const STYLE: &str = include_str!("page.css");
const SCRIPT: &str = include_str!("page.js");

/// The page of `page`: the template with its style, script and Content-Security-Policy, and
/// the data compressed in base 64.
pub fn html(page: &Page) -> Result<String, serde_json::Error> {
    let json = serde_json::to_vec(page)?;
    let data = base64(&miniz_oxide::deflate::compress_to_vec_zlib(&json, 9));
    let csp = format!(
        "default-src 'none'; script-src 'sha256-{}'; style-src 'sha256-{}'; img-src data:",
        base64(&sha256(SCRIPT.as_bytes())),
        base64(&sha256(STYLE.as_bytes()))
    );
    let title = crate::render::svg::escape(&format!("Explorer: {}", page.title));
    let mut out = String::with_capacity(TEMPLATE.len() + STYLE.len() + SCRIPT.len() + data.len());
    // One pass over the template's markers, so that nothing inserted is read as a marker.
    let mut rest = TEMPLATE;
    while let Some(start) = rest.find("{{") {
        out.push_str(&rest[..start]);
        let end = start + rest[start..].find("}}").expect("a closed marker") + 2;
        out.push_str(match &rest[start..end] {
            "{{csp}}" => &csp,
            "{{title}}" => &title,
            "{{style}}" => STYLE,
            "{{script}}" => SCRIPT,
            "{{data}}" => &data,
            marker => unreachable!("unknown marker {marker} in page.html"),
        });
        rest = &rest[end..];
    }
    out.push_str(rest);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_template_has_each_marker_once_and_the_code_no_marker() {
        for marker in [
            "{{csp}}",
            "{{title}}",
            "{{style}}",
            "{{script}}",
            "{{data}}",
        ] {
            assert_eq!(TEMPLATE.matches(marker).count(), 1, "{marker}");
        }
        assert_eq!(TEMPLATE.matches("{{").count(), 5);
        // The style and the script must not end their element early.
        assert!(!STYLE.contains("</"));
        assert!(!SCRIPT.to_ascii_lowercase().contains("</script"));
    }
}

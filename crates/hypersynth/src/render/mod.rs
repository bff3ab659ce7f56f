//! Pictures of gridworlds as SVG: the map, the win-label partition with the controller's moves
//! (or the values as a heat map), and a run.
//!
//! - [`svg`]: a minimal SVG writer (elements, escaping, short numbers);
//! - [`picture`]: the drawings, from plain values ([`CellView`], [`TracePoint`]);
//! - [`scene`]: those values from a hypergame: which product state each cell shows, its
//!   win-label (the games stage), or in the general form its label and guarantee
//!   ([`SubtaskTags`]);
//! - [`controller`]: the one place that asks the MDP stage for the controller's moves, values
//!   and a simulated run.
//!
//! Colours are the Okabe–Ito palette, distinguishable with the common colour-vision
//! deficiencies, and never the only cue: cells also carry the label's code, players have
//! distinct shapes, and the legend names everything. Output is deterministic. Cost: linear in
//! the number of cells (and trace steps); a 40×40 grid is about 0.5 MB of SVG.

pub mod controller;
pub mod picture;
pub mod scene;
pub mod svg;

pub use controller::{ControllerView, controller_view};
pub use picture::{
    CellView, Geometry, Key, Mark, NOTHING_COLOUR, Shading, Tag, TracePoint, class_colour,
    label_colour, map, partition, trace, win_label_key, win_label_tag,
};
pub use scene::{RenderError, SubtaskTags, partition_cells, partition_states, trace_points};

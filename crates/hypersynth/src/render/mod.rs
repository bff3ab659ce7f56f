//! Pictures of gridworlds as SVG: the map, the win-label partition with the controller's moves
//! (or the values as a heat map), and a run.
//!
//! - [`figure`]: a picture as an explicit list of shapes with their roles, written as SVG, read
//!   back, and checked that nothing overlaps;
//! - [`font`]: the metrics of the one font pictures are laid out for (DejaVu Sans);
//! - [`colour`]: one colour per label and per set of tasks, the same in every picture;
//! - [`title`]: titles, replaced or left out on request, formulas with logical symbols;
//! - [`picture`]: the drawings, from plain values ([`CellView`], [`TracePoint`]);
//! - [`scene`]: those values from a hypergame: which product state each cell shows, its
//!   win-label (the games stage), or in the general form its label and guarantee
//!   ([`Tags`]);
//! - [`controller`]: the one place that asks the MDP stage for the controller's moves, values
//!   and a simulated run;
//! - [`curve`]: the learning curve, values against the number of observed runs (not a map);
//! - [`svg`]: numbers and escaping for the SVG text.
//!
//! Colours are the Okabe–Ito palette, distinguishable with the common colour-vision
//! deficiencies, and never the only cue: cells also carry the label's code, players have
//! distinct shapes, and the legend names everything. Output is deterministic. Cost: linear in
//! the number of cells (and trace steps); a 40×40 grid with a mark in every cell is about 0.6 MB
//! of SVG.

pub mod colour;
pub mod controller;
pub mod curve;
pub mod figure;
pub mod font;
pub mod picture;
pub mod scene;
pub mod svg;
pub mod title;

pub use colour::{NOTHING_COLOUR, label_colour};
pub use controller::{ControllerView, controller_view};
pub use curve::learning_curve;
pub use picture::{CellView, Geometry, Key, Mark, Shading, Tag, TracePoint, map, partition, trace};
pub use scene::{ProductView, RenderError, Tags, partition_cells, partition_states, trace_points};
pub use title::{Title, TitleChoice, typeset};

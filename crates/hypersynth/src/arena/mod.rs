//! Two-player turn-based arenas: the model, its text format (reader and writer), summary
//! statistics, DOT output for small arenas, the gridworld generator and its map format.

pub mod dot;
pub mod gridworld;
pub mod map;
mod model;
mod parse;
mod stats;
mod syntax;
mod write;

pub use model::{
    ActionId, Arena, ArenaBuilder, BuildError, LabelId, Owner, PropositionId, StateId,
};
pub(crate) use parse::line_names;
pub use parse::{
    ParseError, ParseErrorKind, Parsed, Summary, Warning, WarningKind, defects, parse,
    parse_metered, parse_with_limit, summarise,
};
pub use stats::Statistics;
pub(crate) use syntax::lines;
pub use syntax::{Name, NameToken, QuoteError, Spelled, read_name, read_quoted};
pub use write::{HEADER, write, write_with_comment};

//! Two-player turn-based arenas: the model, its text format (reader and writer), summary
//! statistics and the gridworld generator.

pub mod gridworld;
mod model;
mod parse;
mod stats;
mod syntax;
mod write;

pub use model::{
    ActionId, Arena, ArenaBuilder, BuildError, LabelId, Owner, PropositionId, StateId,
};
pub use parse::{ParseError, ParseErrorKind, Parsed, Warning, WarningKind, parse};
pub use stats::Statistics;
pub use syntax::{Name, NameToken, QuoteError, read_name, read_quoted};
pub use write::{HEADER, write, write_with_comment};

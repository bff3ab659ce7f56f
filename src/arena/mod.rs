//! Two-player turn-based arenas: the model, its text format (reader and writer) and the
//! gridworld generator.

mod model;

pub use model::{
    ActionId, Arena, ArenaBuilder, BuildError, LabelId, Owner, PropositionId, StateId,
};

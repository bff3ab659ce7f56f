//! The implicit engine: the product is never stored (docs/semantics.md §4, §5; ARCHITECTURE.md).
//!
//! The explicit pipeline expands a map into an arena and keeps predecessor lists and rank
//! vectors per product state. Here a product state is a number: [`Space`] computes its edges and
//! predecessors from the arena's rules ([`Moves`]: [`MapMoves`] computes a gridworld from its
//! cells and moves, [`ArenaMoves`] reads a stored arena) and the automata's step tables, and
//! [`Regions`] keeps one bit per state and region. The numbering is the explicit product's full
//! enumeration, so an index names the same product state in both engines.
//!
//! ```
//! use hypersynth::arena::map;
//! use hypersynth::game::{Belief, TaskSet};
//! use hypersynth::implicit::{MapMoves, Regions, Space};
//! use hypersynth::ltl;
//! use hypersynth::translate::{Builtin, TranslationLimits, Translator};
//!
//! // A 3x1 corridor: the robot starts in the west, A is in the east, the adversary stands in
//! // between, and the players may not share a cell.
//! let world = map::parse("hypersynth map v1\ngrid\n@r @a A\n")?;
//! let moves = MapMoves::new(&world)?;
//! let translator = Builtin::new(TranslationLimits::default());
//! let dfa = translator.translate(&ltl::parse("F A")?)?;
//! let space = Space::new(&moves, &[&dfa])?;
//! let regions = Regions::compute(&space, 1, Belief::Tasks(TaskSet(1)));
//! // The robot cannot move past the adversary, which may stay for ever: F A is not won.
//! assert!(!regions.wins(TaskSet(1), space.initial()));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod attractor;
mod backup;
mod colour;
mod controller;
mod drn;
mod ends;
mod frontier;
mod mdp;
mod moves;
mod numbering;
mod policy;
mod qualitative;
mod regions;
mod robust;
mod solve;
mod space;
mod strategies;

pub use attractor::{Ranks, Region, attractor};
pub use backup::COMPILED_PER_LIVE;
pub use controller::Controller;
pub use drn::Drn;
pub use mdp::{Choice, Distribution, Kind, Model, ModelError};
pub use moves::{ArenaMoves, MapMoves, Moves, SourceMoves};
pub use policy::{
    Chain, Evaluation, Policy, PolicyError, chain, evaluate, expected_moves_from, policy,
};
pub use regions::Regions;
pub use robust::{Intervals, robust_policy, solve_robust};
pub use solve::{Precision, Solution, SolveError, solve};
pub use space::Space;
pub use strategies::Strategies;
#[cfg(any(test, feature = "testing"))]
#[doc(hidden)]
pub mod testing;

//! hypersynth: opportunistic synthesis for hypergames.
//!
//! The robot's task is `phi = phi1 & phi2`; the adversary believes it is `psi = phi1` (the
//! paper's form), or in general the robot has k named sub-tasks with payoffs on their sets and
//! the adversary believes any task. The library turns co-safe LTL into DFAs ([`ltl`],
//! [`automata`], [`translate`]), plays them on two-player arenas ([`arena`], [`game`]), and
//! computes the opportunistic strategy on the hypergame MDP ([`opportunistic`], over the generic
//! MDP core [`mdp`]); [`render`] draws gridworlds and results as SVG, and [`explorer`] makes
//! an interactive page of a solved map.
//! Every stage is a pure function over in-memory values; only the readers and writers touch
//! text, and only the command line touches files.
//!
//! # Example: the case study, stage by stage
//!
//! Each stage is a function over plain values, so a caller can stop after any of them;
//! [`pipeline::run`] does them all at once.
//!
//! ```
//! use hypersynth::arena;
//! use hypersynth::game::{Payoffs, States};
//! use hypersynth::ltl;
//! use hypersynth::mdp::solve::SolveOptions;
//! use hypersynth::opportunistic::adversary::SigmaL;
//! use hypersynth::opportunistic::view::SolvedHypergame;
//! use hypersynth::pipeline::{MdpOptions, OpportunisticSolution, Tasks};
//! use hypersynth::translate::{Builtin, TranslationLimits};
//!
//! // The case study: a 5x5 gridworld, the robot must visit A and B avoiding obstacles (O); the
//! // adversary believes it only has to visit A.
//! let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../specs/case-study/arena.txt");
//! let arena = arena::parse(&std::fs::read_to_string(path)?)?.arena;
//! let phi = ltl::parse("(!O U A) & (!O U B)")?;
//! let psi = ltl::parse("!O U A")?;
//! let translator = Builtin::new(TranslationLimits::default());
//! let tasks = Tasks::from_formulas(&phi, &psi, None, &translator, Payoffs::default())?;
//!
//! // Each stage is a function over plain values: the hypergame, its winning regions...
//! let game = tasks.hypergame(&arena, States::Full)?;
//! let regions = tasks.regions(&game);
//! let solved = SolvedHypergame::new(&game, &regions, tasks.payoffs(), tasks.presentation());
//! // ... then the MDP of the adversary's stochastic strategies, solved with a certified bound.
//! let options = MdpOptions {
//!     sigma_l: SigmaL::Random { seed: 2019 },
//!     seed: 2019,
//!     solve: SolveOptions::default(),
//!     learnt: None,
//! };
//! let solution = OpportunisticSolution::solve(&solved, tasks.risk(), &options, &mut ())?;
//!
//! // From h0 the robot can force phi1 only, yet it collects r = 300 (both tasks): the
//! // adversary, believing the robot is after A alone, leaves the way to B open.
//! let value = solution.solution.value(solution.mdp.mdp().initial());
//! assert!((value.lower - 300.0).abs() < 1e-6 && value.upper - value.lower <= 1e-6);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! More in `examples/` (`cargo run -p hypersynth --example case_study`, `build_arena`).
//! See `ARCHITECTURE.md` for the code map and the invariants that cross modules; each module's
//! own are in its documentation.

#![warn(missing_docs)]

pub mod arena;
pub mod automata;
mod bdd;
pub mod certificate;
pub mod csr;
pub mod diagnostic;
pub mod explorer;
pub mod game;
pub mod implicit;
pub mod index;
pub mod limits;
pub mod ltl;
pub mod mdp;
pub mod opportunistic;
pub mod pipeline;
pub mod position;
pub mod render;
pub mod report;
pub mod stage;
#[cfg(any(test, feature = "testing"))]
#[doc(hidden)]
pub mod testing;
pub mod translate;

//! hypersynth: opportunistic synthesis for hypergames.
//!
//! The robot's task is `phi = phi1 & phi2`; the adversary believes it is `psi = phi1`.
//! The library turns co-safe LTL into DFAs ([`ltl`], [`automata`], [`translate`]), plays them on
//! two-player arenas ([`arena`], [`game`]), and computes the opportunistic strategy on the
//! hypergame MDP ([`mdp`], [`simulate`]); [`render`] draws gridworlds and results as SVG.
//! Every stage is a pure function over in-memory values; only the readers and writers touch
//! text, and only the command line touches files.
//!
//! See `ARCHITECTURE.md` for the code map and the invariants of each module.

pub mod arena;
pub mod automata;
mod bdd;
pub mod csr;
pub mod game;
pub mod index;
pub mod io;
pub mod ltl;
pub mod mdp;
pub mod position;
pub mod render;
pub mod report;
pub mod simulate;
pub mod stage;
pub mod translate;

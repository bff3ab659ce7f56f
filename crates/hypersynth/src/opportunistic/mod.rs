//! Opportunistic synthesis on the hypergame: the adversary model, the hypergame MDP built on
//! the generic core of [`crate::mdp`], the controller, its evaluation and its simulation, for
//! the paper's form and the general one alike (docs/semantics.md §6 to §8).

pub mod adversary;
pub mod build;
pub mod controller;
pub mod ending;
pub mod evaluate;
pub mod executor;
pub mod export;
pub mod levels;
pub mod load;
pub mod observations;
pub mod presentation;
pub mod risk;
pub mod simulate;
pub mod view;

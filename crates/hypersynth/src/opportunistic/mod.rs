//! Opportunistic synthesis on the hypergame: the adversary model, the hypergame MDP built on
//! the generic core of [`crate::mdp`], the controller, its evaluation and its simulation.

pub mod adversary;
pub mod build;
pub mod controller;
pub mod evaluate;
pub mod levels;
pub mod simulate;
pub mod subtasks;
pub mod view;

//! Hooks for the tests (the `testing` feature): the solve and the policy with the size from
//! which a component is swept by player on threads (`colour.rs`) as a parameter.

use super::{Model, Moves, Policy, PolicyError, Precision, Solution, SolveError};

/// [`solve`](super::solve()) sweeping by player, on the threads of the current pool, every component
/// of at least `coloured` states that allows it (the solve itself does so from 2^15 states).
pub fn solve_colouring<M: Moves>(
    model: &Model<'_, '_, M>,
    g: f64,
    precision: Precision,
    max_iterations: u32,
    coloured: usize,
) -> Result<Solution, SolveError> {
    super::solve::solve_colouring(model, g, precision, max_iterations, coloured)
}

/// [`policy`](super::policy()) sweeping the expected moves of every component of at least `coloured`
/// states by player where it can, as [`solve_colouring`].
pub fn policy_colouring<M: Moves>(
    model: &Model<'_, '_, M>,
    solution: &Solution,
    g: f64,
    max_iterations: u32,
    coloured: usize,
) -> Result<Policy, PolicyError> {
    super::policy::policy_colouring(model, solution, g, max_iterations, coloured)
}

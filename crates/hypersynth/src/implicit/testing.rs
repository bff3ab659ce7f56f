//! Hooks for the tests (the `testing` feature): the solve with its [`Tuning`] (when a component
//! is swept by player on threads, `colour.rs`, and when its edges are compiled, `backup.rs`) and
//! the policy with the size from which a component is swept by player as parameters.

pub use super::policy::policy_colouring;
pub use super::solve::{Tuning, solve_tuned};

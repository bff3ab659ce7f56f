//! Hooks for the tests (the `testing` feature): the solve and the policy with their [`Tuning`]
//! (when a component is swept by player on threads, `colour.rs`, and when its edges are
//! compiled, `backup.rs`) as a parameter.

pub use super::policy::policy_tuned;
pub use super::solve::{Tuning, solve_tuned};

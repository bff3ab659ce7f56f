//! Hooks for the tests (the `testing` feature): the solve and the policy with the size from
//! which a component is swept by player on threads (`colour.rs`) as a parameter.

pub use super::policy::policy_colouring;
pub use super::solve::solve_colouring;

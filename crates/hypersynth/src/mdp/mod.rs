//! The hypergame MDP: adversary models, construction, certified value iteration and the
//! opportunistic policy.
//!
//! - [`model`]: the explicit [`Mdp`] (CSR arrays, absorbing states with payoffs) and its
//!   validating [`MdpBuilder`];
//! - [`solve`](mod@solve): maximal expected payoff at absorption with discount, by interval
//!   iteration with end-component collapse, and a policy that attains it;
//! - [`drn`]: Storm's explicit DRN format, so that Storm can check the values;
//! - [`adversary`], [`build`], [`controller`]: the hypergame MDP of docs/semantics.md §6 and its
//!   controller; [`evaluate`]: the controller evaluated as a Markov chain, independently of the
//!   solver;
//! - [`subtasks`]: the general MDP of docs/semantics.md §8 (k sub-tasks, payoffs on sets, any belief)
//!   and its controller; [`levels`]: the backward searches both MDPs' risk and absorbing rules
//!   use.

pub mod absorption;
pub mod drn;
pub(crate) mod graph;
pub(crate) mod linear;
pub mod model;
pub mod robust;
pub mod solve;
#[cfg(test)]
pub(crate) mod testing;

pub use drn::{write_drn, write_induced_drn, write_interval_drn};
pub use model::{ChoiceId, Mdp, MdpBuilder, MdpError, MdpState, PROBABILITY_TOLERANCE};
pub use solve::{Discount, Interval, Solution, SolveError, SolveOptions, solve, solve_observed};

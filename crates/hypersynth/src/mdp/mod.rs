//! The generic MDP core: models, graph algorithms, certified solvers and DRN. It never sees a
//! game: the hypergame MDP, its adversary and its controller are built on it in
//! [`crate::opportunistic`].
//!
//! - [`model`]: the explicit [`Mdp`] (CSR arrays, pooled distributions, absorbing states with
//!   payoffs) and its validating [`MdpBuilder`];
//! - [`solve`](mod@solve): the maximal expected payoff at absorption with a discount, by
//!   qualitative preprocessing and interval iteration with end-component collapse, and a policy
//!   that attains it, one file per method;
//! - [`robust`]: the same with interval probabilities chosen by a minimising adversary;
//! - `operator`: the one Bellman operator both solves iterate (a compact layout of nodes,
//!   choices and targets; a fixed distribution or the worst one within intervals per choice;
//!   the discounted payoff or the expected moves as objective);
//! - [`absorption`]: where a Markov chain leaves a set of states, per component;
//! - [`drn`]: Storm's explicit DRN format (the MDP, a policy's induced chain, an interval MDP),
//!   in reward or reachability form, so that Storm can check the values.

pub mod absorption;
pub mod drn;
pub(crate) mod graph;
pub(crate) mod linear;
pub mod model;
mod operator;
pub mod robust;
pub mod solve;
#[cfg(test)]
pub(crate) mod testing;

pub use drn::{DrnForm, write_drn, write_induced_drn, write_interval_drn};
pub use model::{ChoiceId, Mdp, MdpBuilder, MdpError, MdpState, PROBABILITY_TOLERANCE};
pub use solve::{Discount, Interval, Solution, SolveError, SolveOptions, solve, solve_observed};

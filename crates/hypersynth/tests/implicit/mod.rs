//! The implicit engine against the explicit one.

mod engines;
mod solve;

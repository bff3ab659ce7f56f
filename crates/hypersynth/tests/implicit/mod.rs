//! The implicit engine against the explicit one.

mod engines;
mod observations;
mod policy;
mod robust;
mod solve;

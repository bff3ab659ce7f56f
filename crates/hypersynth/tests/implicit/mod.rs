//! The implicit engine against the explicit one.

mod engines;
mod policy;
mod robust;
mod solve;

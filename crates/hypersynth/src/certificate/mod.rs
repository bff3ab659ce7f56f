//! Certificates: bounds on a controller's value, and on the MDP's, that anyone can check from
//! the controller file alone (docs/semantics.md §9.4).
//!
//! - [`check`] (and [`check_json`]) re-derives the hypergame MDP from the file (the arena, the
//!   automata tables, the payoffs, the belief, the risk rule and the adversary's rules:
//!   `model`), then checks the lower certificate (x over the states the controller reaches,
//!   the values the file lists and those it derives, and the ranks it computes) and the upper
//!   one (y over the states any enabled choice reaches) inequality by inequality in exact
//!   arithmetic (`exact`); where a learnt sigma_L rules, against the least expectation over
//!   its confidence region (`check`'s region inequality). Its trusted base is this module
//!   but `make`, the file's reader (`opportunistic::load`, `opportunistic::export`'s tables),
//!   the arena's readers, `opportunistic::adversary::sigma_l_weights` and, for a learnt sigma_L,
//!   the region's definition (`opportunistic::observations::Region::new`); it uses nothing of the
//!   MDP's build, the solver, the policy or the evaluation, which the crate's layering test
//!   enforces.
//! - [`certify`] makes the certificate of an exported controller from approximate values (the
//!   controller's evaluation, the solver's upper bounds), repairing them until the checker's
//!   inequalities hold exactly (`make`).
//!
//! Cost: linear in the product states reachable from h0 and their edges (the attractors once
//! per set of sub-tasks), each inequality summed exactly over a few hundred machine words.

mod check;
mod exact;
mod make;
mod model;

use std::collections::HashMap;

use thiserror::Error;

pub use check::{Bound, Certified, Refusal};

use crate::opportunistic::export::{CertificateTables, ControllerFile, Table};
use crate::opportunistic::load::{self, ControllerError};
use model::Model;

/// Why a file's certificate does not certify its bounds.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum CheckError {
    /// The file is not a controller file this version reads.
    #[error("{0}")]
    Unreadable(ControllerError),
    /// The file has no certificate.
    #[error("the controller file has no certificate (export it with one)")]
    Missing,
    /// The file's parts do not make a product (a tuple the automata reach is missing).
    #[error("{0}")]
    Product(String),
    /// An inequality or a rank fails.
    #[error("{0}")]
    Refused(Refusal),
}

impl CheckError {
    /// The refusal, when the certificate was read and an inequality fails.
    pub fn refusal(&self) -> Option<&Refusal> {
        match self {
            CheckError::Refused(refusal) => Some(refusal),
            _ => None,
        }
    }
}

/// Checks the certificate of the controller file `text` (JSON).
pub fn check_json(text: &str) -> Result<Certified, CheckError> {
    check(load::read(text).map_err(CheckError::Unreadable)?)
}

/// Checks the certificate of `file`: re-derives its MDP and checks every inequality and rank
/// exactly; the bounds certified, or the first state and inequality that fail.
pub fn check(file: ControllerFile) -> Result<Certified, CheckError> {
    let checked = load::check(file).map_err(CheckError::Unreadable)?;
    let certificate = checked.certificate.as_ref().ok_or(CheckError::Missing)?;
    let model = Model::new(&checked).map_err(CheckError::Product)?;
    check::check(&model, certificate).map_err(CheckError::Refused)
}

/// The states whose values a certificate of `file` lists (its own certificate, if any,
/// ignored), by name (`ARENA_STATE|q_1|…`), in the order the file lists them: those of D_L
/// that carry their x, and those of D_U that carry their y (docs/semantics.md §9.4).
pub fn carried_states(file: &ControllerFile) -> Result<[Vec<String>; 2], CheckError> {
    let mut file = file.clone();
    file.certificate = None;
    let checked = load::check(file).map_err(CheckError::Unreadable)?;
    let model = Model::new(&checked).map_err(CheckError::Product)?;
    Ok(carried(&model).map(|states| states.into_iter().map(|u| model.name(u)).collect()))
}

/// The nodes of D_L that carry their x and those of D_U that carry their y, in the checker's
/// order.
fn carried(model: &Model) -> [Vec<u32>; 2] {
    let steps = check::steps(model);
    let lower = check::reach(model, |u| match steps[u as usize] {
        Some(step) => check::chain_successors(model, step, u).collect(),
        None => Vec::new(),
    })
    .into_iter()
    .filter(|&u| steps[u as usize].is_some_and(|step| check::lower_carries(model, step, u)))
    .collect();
    let rules = model.robot_rules();
    let rule = |u: u32| rules[u as usize].as_ref();
    let upper = check::reach(model, |u| {
        check::upper_successors(model, rule(u), u).collect()
    })
    .into_iter()
    .filter(|&u| check::upper_carries(model, rule(u), u))
    .collect();
    [lower, upper]
}

/// Why a certificate could not be made.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum CertifyError {
    /// The file does not read back.
    #[error("{0}")]
    Unreadable(ControllerError),
    /// The file's parts do not make a product.
    #[error("{0}")]
    Product(String),
    /// Repairing the values did not settle.
    #[error("the {0} certificate's values did not settle")]
    NotSettled(Bound),
}

/// The certificate of `file` (its own certificate, if any, ignored) from approximate lower
/// and upper values, each asked per (arena state, tuple) entry `s · |tuples| + t` (NaN where
/// unknown): the lower ones the controller's own values, the upper ones bounds on the MDP's.
/// Each is asked once per product state the file's model holds (those reachable from h0).
pub fn certify(
    file: &ControllerFile,
    lower: impl Fn(usize) -> f64,
    upper: impl Fn(usize) -> f64,
) -> Result<CertificateTables, CertifyError> {
    let mut file = file.clone();
    file.certificate = None;
    let checked = load::check(file).map_err(CertifyError::Unreadable)?;
    let model = Model::new(&checked).map_err(CertifyError::Product)?;
    let n = model.len() as u32;
    let x0: Vec<f64> = (0..n).map(|u| lower(model.entry(u))).collect();
    let y0: Vec<f64> = (0..n).map(|u| upper(model.entry(u))).collect();
    let x = make::lower(&model, &x0).ok_or(CertifyError::NotSettled(Bound::Lower))?;
    let y = make::upper(&model, &y0).ok_or(CertifyError::NotSettled(Bound::Upper))?;
    let [lower_states, upper_states] = carried(&model);
    let mut values: Vec<u64> = Vec::new();
    let mut index: HashMap<u64, u64> = HashMap::new();
    let mut intern = |value: f64| {
        *index.entry(value.to_bits()).or_insert_with(|| {
            values.push(value.to_bits());
            values.len() as u64 - 1
        })
    };
    let lower_list: Vec<u64> = lower_states
        .iter()
        .map(|&u| intern(x[u as usize]))
        .collect();
    let upper_list: Vec<u64> = upper_states
        .iter()
        .map(|&u| intern(y[u as usize]))
        .collect();
    // Every double in 11 digits, whatever the largest's bits.
    let value_table = Table::encode_wide(11, || values.iter().map(|&bits| Some(bits)));
    Ok(CertificateTables {
        values: value_table,
        lower: Table::encode(|| lower_list.iter().map(|&i| Some(i))),
        upper: Table::encode(|| upper_list.iter().map(|&i| Some(i))),
    })
}

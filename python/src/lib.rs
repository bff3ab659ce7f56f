//! `hypersynth._hypersynth`: the Python extension over the library's pipeline
//! (`hypersynth::pipeline`), one module per class: `arena` (`Arena`, `ArenaBuilder`),
//! `automaton` (`Automaton`, `translate`), `problem` (`Problem`), `solution` (`Solution`),
//! `controller` (`Controller`), `certificate` (`check`), and `errors` (the exceptions). It
//! holds no logic of its own beyond mapping Python values onto the library's (a problem onto
//! its specification, `hypersynth::pipeline::spec`, whose rules check them) and back: arenas,
//! tasks, the problem, its solution (kept solved, so that every question asked of it reads the
//! one solution), the exported controller's executor and its certificate's checker.
//!
//! Invariants: every library error becomes one exception of the `hypersynth.Error` hierarchy
//! whose message is the command line's (located texts are named after the Python argument that
//! gave them); the GIL is released while a problem is solved, and the solve polls Python's
//! signal handlers through the stage observer, so that Ctrl-C unwinds it through
//! `stage::interruptible`.

use pyo3::prelude::*;

mod arena;
mod automaton;
mod certificate;
mod controller;
mod dynamics;
mod errors;
mod problem;
mod solution;

use errors::{
    ArenaError, CertificateError, ControllerError, Error, OptionsError, ParseError, SolveError,
    TaskError, TranslationError,
};

#[pymodule]
fn _hypersynth(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add_class::<arena::Arena>()?;
    m.add_class::<arena::ArenaBuilder>()?;
    m.add_class::<automaton::Automaton>()?;
    m.add_class::<problem::Problem>()?;
    m.add_class::<solution::Solution>()?;
    m.add_class::<controller::Controller>()?;
    m.add_class::<controller::Answer>()?;
    m.add_class::<controller::ControllerPolicy>()?;
    m.add_class::<dynamics::Dynamics>()?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(automaton::translate_formula, m)?)?;
    m.add_function(wrap_pyfunction!(certificate::check, m)?)?;
    m.add("Error", py.get_type::<Error>())?;
    m.add("ParseError", py.get_type::<ParseError>())?;
    m.add("ArenaError", py.get_type::<ArenaError>())?;
    m.add("TranslationError", py.get_type::<TranslationError>())?;
    m.add("TaskError", py.get_type::<TaskError>())?;
    m.add("OptionsError", py.get_type::<OptionsError>())?;
    m.add("SolveError", py.get_type::<SolveError>())?;
    m.add("ControllerError", py.get_type::<ControllerError>())?;
    m.add("CertificateError", py.get_type::<CertificateError>())?;
    Ok(())
}

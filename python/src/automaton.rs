//! Tasks' automata (`Automaton`), formulas translated (`translate`), and the translator a
//! name chooses.

use pyo3::prelude::*;

use hypersynth::automata::hoa;
use hypersynth::ltl;
use hypersynth::pipeline::spec::{SpecErrorKind, Translation};
use hypersynth::pipeline::{HoaTaskError, Task};
use hypersynth::translate::{self, TranslatorChoice};

use crate::errors::{Error, OptionsError, exception, in_field};

/// A task's automaton: the minimal DFA of its good prefixes, with its HOA text.
#[pyclass(frozen, module = "hypersynth")]
#[derive(Clone)]
pub(crate) struct Automaton {
    pub(crate) task: Task,
}

#[pymethods]
impl Automaton {
    /// Reads the one automaton of a HOA text (from any tool: Spot's Python bindings give it
    /// with `aut.to_str("hoa")`); `name` names it in reports.
    #[staticmethod]
    #[pyo3(signature = (text, name = "<hoa>"))]
    fn from_hoa(text: &str, name: &str) -> PyResult<Automaton> {
        let task = Task::from_hoa(name, text).map_err(|error| {
            let kind = match error {
                HoaTaskError::Parse(errors) => SpecErrorKind::Hoa(errors),
                HoaTaskError::Count(n) => SpecErrorKind::AutomatonCount(n),
            };
            in_field(name, Some(text), None, kind)
        })?;
        Ok(Automaton { task })
    }

    /// The automaton in HOA.
    #[getter]
    fn hoa(&self) -> PyResult<String> {
        hoa::write(&self.task.dfa, Some(&self.task.name))
            .map_err(|e| exception::<Error>(e.to_string(), None, None))
    }

    /// How reports name it: its formula, or the name it was read under.
    #[getter]
    fn name(&self) -> &str {
        &self.task.name
    }

    /// What made it: a translator's name, or `hoa`.
    #[getter]
    fn translator(&self) -> &str {
        &self.task.translator
    }

    /// Its number of states.
    #[getter]
    fn num_states(&self) -> usize {
        self.task.dfa.num_states()
    }

    /// Its atomic propositions.
    #[getter]
    fn propositions(&self) -> Vec<String> {
        self.task.dfa.aps().to_vec()
    }

    fn __repr__(&self) -> String {
        format!(
            "<hypersynth.Automaton {:?}: {} states, by {}>",
            self.task.name,
            self.task.dfa.num_states(),
            self.task.translator
        )
    }
}

/// The translation `choice` names (`"auto"`, `"builtin"` or `"spot"`), with Spot's `ltl2tgba`
/// found as the command line finds it ($HYPERSYNTH_LTL2TGBA, else PATH) and the library's
/// default limits (2^20 states and a bounded amount of work).
pub(crate) fn translation(choice: &str) -> PyResult<Translation> {
    let choice = match choice {
        "auto" => TranslatorChoice::Auto,
        "builtin" => TranslatorChoice::Builtin,
        "spot" => TranslatorChoice::Spot,
        other => {
            return Err(exception::<OptionsError>(
                format!("translator: `{other}` is not one of auto, builtin, spot"),
                None,
                None,
            ));
        }
    };
    let ltl2tgba = translate::spot::locate_ltl2tgba(
        None,
        std::env::var_os(translate::spot::LTL2TGBA_VARIABLE).as_deref(),
        std::env::var_os("PATH").as_deref(),
    );
    Ok(Translation {
        choice,
        ltl2tgba,
        ..Translation::default()
    })
}

/// Translates co-safe LTL `formula` to the minimal DFA of its good prefixes, by `translator`
/// (`"auto"`: Spot's `ltl2tgba` when on PATH, else the built-in translation; `"builtin"`;
/// `"spot"`).
#[pyfunction(name = "translate")]
#[pyo3(signature = (formula, translator = "auto"))]
pub(crate) fn translate_formula(formula: &str, translator: &str) -> PyResult<Automaton> {
    let error = |kind| in_field("formula", Some(formula), None, kind);
    let parsed = ltl::parse(formula).map_err(|e| error(SpecErrorKind::Formula(e)))?;
    let chosen = translation(translator)?
        .translator()
        .map_err(|e| in_field("translator", None, None, SpecErrorKind::Translator(e)))?;
    let task = Task::from_formula(parsed, chosen.as_ref()).map_err(|e| {
        in_field(
            "formula",
            Some(formula),
            e.position(formula),
            SpecErrorKind::Translate(e),
        )
    })?;
    Ok(Automaton { task })
}

//! Tasks' automata (`Automaton`), formulas translated (`translate`), and the translator a
//! name chooses.

use pyo3::prelude::*;

use hypersynth::automata::hoa;
use hypersynth::ltl;
use hypersynth::pipeline::spec::{SpecErrorKind, Translation};
use hypersynth::pipeline::{HoaTaskError, Task};
use hypersynth::translate::{self, TranslatorChoice};

use crate::errors::{Error, OptionsError, exception, in_field};

/// A task's automaton: the minimal DFA of its good prefixes, with its HOA text. Made by
/// `translate` or `Automaton.from_hoa`; it pickles as what made it (the formula and the
/// translator asked for, or the HOA text and its name).
///
/// >>> automaton = hs.translate("!O U A", translator="builtin")
/// >>> automaton.num_states, automaton.propositions
/// (3, ['O', 'A'])
#[pyclass(frozen, module = "hypersynth")]
#[derive(Clone)]
pub(crate) struct Automaton {
    pub(crate) task: Task,
    /// What made it, to make it again: `(formula, translator)` or `(HOA text, name)`.
    pub(crate) origin: Origin,
}

/// What made an [`Automaton`].
#[derive(Clone)]
pub(crate) enum Origin {
    /// `translate(formula, translator)`.
    Formula { formula: String, translator: String },
    /// `Automaton.from_hoa(text, name)`.
    Hoa { text: String, name: String },
    /// A sub-task of a problem: its HOA text, named as the task.
    Task,
}

#[pymethods]
impl Automaton {
    /// Reads the one automaton of a HOA text (from any tool: Spot's Python bindings give it
    /// with `aut.to_str("hoa")`); `name` names it in reports.
    ///
    /// >>> hoa = hs.translate("F A", translator="builtin").hoa
    /// >>> hs.Automaton.from_hoa(hoa, name="eventually A").num_states
    /// 2
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
        Ok(Automaton {
            task,
            origin: Origin::Hoa {
                text: text.to_string(),
                name: name.to_string(),
            },
        })
    }

    /// The automaton in HOA.
    ///
    /// >>> print(hs.translate("F A", translator="builtin").hoa.splitlines()[0])
    /// HOA: v1
    #[getter]
    fn hoa(&self) -> PyResult<String> {
        hoa::write(&self.task.dfa, Some(&self.task.name))
            .map_err(|e| exception::<Error>(e.to_string(), None, None))
    }

    /// How reports name it: its formula, or the name it was read under.
    ///
    /// >>> hs.translate("F A", translator="builtin").name
    /// 'FA'
    #[getter]
    fn name(&self) -> &str {
        &self.task.name
    }

    /// What made it: a translator's name, or `hoa`.
    ///
    /// >>> hs.translate("F A", translator="builtin").translator
    /// 'builtin'
    #[getter]
    fn translator(&self) -> &str {
        &self.task.translator
    }

    /// Its number of states.
    ///
    /// >>> hs.translate("F A & F B", translator="builtin").num_states
    /// 4
    #[getter]
    fn num_states(&self) -> usize {
        self.task.dfa.num_states()
    }

    /// Its atomic propositions.
    ///
    /// >>> hs.translate("F A & F B", translator="builtin").propositions
    /// ['A', 'B']
    #[getter]
    fn propositions(&self) -> Vec<String> {
        self.task.dfa.aps().to_vec()
    }

    /// Pickles as what made it (see the class).
    ///
    /// >>> import pickle
    /// >>> automaton = hs.translate("F A", translator="builtin")
    /// >>> pickle.loads(pickle.dumps(automaton)).hoa == automaton.hoa
    /// True
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, (String, String))> {
        let py = slf.py();
        let this = slf.get();
        Ok(match &this.origin {
            Origin::Formula {
                formula,
                translator,
            } => (
                py.import("hypersynth")?.getattr("translate")?,
                (formula.clone(), translator.clone()),
            ),
            Origin::Hoa { text, name } => (
                slf.get_type().getattr("from_hoa")?,
                (text.clone(), name.clone()),
            ),
            Origin::Task => (
                slf.get_type().getattr("from_hoa")?,
                (this.hoa()?, this.task.name.clone()),
            ),
        })
    }

    /// Its name, size and maker.
    ///
    /// >>> hs.translate("F A", translator="builtin")
    /// <hypersynth.Automaton "F A": 2 states, by builtin>
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
///
/// >>> hs.translate("(!O U A) & (!O U B)", translator="builtin").num_states
/// 5
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
    Ok(Automaton {
        task,
        origin: Origin::Formula {
            formula: formula.to_string(),
            translator: translator.to_string(),
        },
    })
}

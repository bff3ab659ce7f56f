//! The `hypersynth.Error` hierarchy, and the library's errors as its exceptions: messages as
//! the command line's, texts located (`file`, `line`, `column`) under the name of the Python
//! argument that gave them.

use pyo3::exceptions::PyException;
use pyo3::prelude::*;
use pyo3::{PyTypeInfo, create_exception};

use hypersynth::diagnostic::{Diagnostic, Diagnostics, Source};
use hypersynth::pipeline::spec::SpecErrorKind;
use hypersynth::position::Position;

create_exception!(
    _hypersynth,
    Error,
    PyException,
    "Every error of hypersynth. `file`, `line` and `column` locate it when it is in a text \
     (None otherwise); the message is the command line's."
);
create_exception!(
    _hypersynth,
    ParseError,
    Error,
    "A text (arena, map, formula, HOA automaton, adversary weights, state name) is malformed."
);
create_exception!(
    _hypersynth,
    ArenaError,
    Error,
    "An arena cannot be built (a duplicate state, an unknown state, a bad map)."
);
create_exception!(
    _hypersynth,
    TranslationError,
    Error,
    "A formula cannot be translated to a DFA (not co-safe, too large, Spot missing or failing)."
);
create_exception!(
    _hypersynth,
    TaskError,
    Error,
    "The tasks do not fit together (psi not a conjunct of phi, payoffs not monotone, bad names)."
);
create_exception!(
    _hypersynth,
    OptionsError,
    Error,
    "A solve option is out of range (discount, epsilon, sigma_l, a picture's name)."
);
create_exception!(
    _hypersynth,
    SolveError,
    Error,
    "The MDP stage failed (iteration limit, the controller's check)."
);
create_exception!(
    _hypersynth,
    ControllerError,
    Error,
    "An exported controller is invalid, or was given a state it cannot take."
);

/// An exception of kind `E` with `message`, located at `position` of `file` when known.
pub(crate) fn exception<E: PyTypeInfo>(
    message: impl Into<String>,
    file: Option<&str>,
    position: Option<Position>,
) -> PyErr {
    let err = PyErr::new::<E, _>(message.into());
    Python::attach(|py| {
        let value = err.value(py);
        // Setting attributes on a fresh exception object cannot fail short of memory.
        let _ = value.setattr("file", file);
        let _ = value.setattr("line", position.map(|p| p.line));
        let _ = value.setattr("column", position.map(|p| p.column));
    });
    err
}

/// The errors of a reader of `text` (named `name`), rendered as the command line renders them:
/// `NAME:LINE:COL: message`, the line and a caret, for each.
pub(crate) fn located<E: PyTypeInfo, M: std::fmt::Display>(
    name: &str,
    text: &str,
    diagnostics: &Diagnostics<M>,
) -> PyErr {
    let message = Source::new(name, text).render(diagnostics).join("\n");
    exception::<E>(message, Some(name), Some(diagnostics.first().position))
}

/// One error at `position` of `text`, rendered as [`located`] does.
pub(crate) fn located_at<E: PyTypeInfo>(
    name: &str,
    text: &str,
    position: Position,
    message: &dyn std::fmt::Display,
) -> PyErr {
    let diagnostics: Diagnostics = Diagnostic::new(position, message.to_string()).into();
    located::<E, _>(name, text, &diagnostics)
}

/// An error of a specification's field named `name` (a Python argument: `phi`, `tasks[A]`...)
/// whose text is `text`: located in the text where it has a place there, else after the name;
/// of the exception its kind calls for.
pub(crate) fn in_field(
    name: &str,
    text: Option<&str>,
    position: Option<Position>,
    kind: SpecErrorKind,
) -> PyErr {
    let located_in = text.zip(position);
    let text = text.unwrap_or_default();
    match kind {
        SpecErrorKind::Formula(errors) | SpecErrorKind::Hoa(errors) => {
            located::<ParseError, _>(name, text, &errors)
        }
        SpecErrorKind::Arena(errors) => located::<ParseError, _>(name, text, &errors),
        SpecErrorKind::Map(errors) => located::<ParseError, _>(name, text, &errors),
        SpecErrorKind::Observations(errors) => located::<ParseError, _>(name, text, &errors),
        SpecErrorKind::WeightsFile(errors) => located::<OptionsError, _>(name, text, &errors),
        SpecErrorKind::AutomatonCount(_) => {
            exception::<ParseError>(format!("{name}: {kind}"), Some(name), None)
        }
        SpecErrorKind::Translate(error) => match located_in {
            Some((text, position)) => located_at::<TranslationError>(name, text, position, &error),
            None => exception::<TranslationError>(format!("{name}: {error}"), Some(name), None),
        },
        SpecErrorKind::Translator(error) => {
            exception::<TranslationError>(format!("{name}: {error}"), None, None)
        }
        SpecErrorKind::Split(error) => match located_in {
            Some((text, position)) => located_at::<TaskError>(name, text, position, &error),
            None => exception::<TaskError>(format!("{name}: {error}"), Some(name), None),
        },
        SpecErrorKind::Gridworld(error) => {
            exception::<ArenaError>(format!("{name}: {error}"), Some(name), None)
        }
        SpecErrorKind::Memory(error) => exception::<Error>(format!("{name}: {error}"), None, None),
        SpecErrorKind::Solve(error) => {
            exception::<OptionsError>(format!("{name}: {error}"), None, None)
        }
        SpecErrorKind::Weight(error) => {
            exception::<OptionsError>(format!("{name}: {error}"), Some("sigma_l"), None)
        }
        // The tasks' rules.
        SpecErrorKind::PaperPayoffs(_)
        | SpecErrorKind::TooManyTasks(_)
        | SpecErrorKind::TaskName(_)
        | SpecErrorKind::DuplicateTask(_) => exception::<TaskError>(kind.to_string(), None, None),
        kind => exception::<TaskError>(format!("{name}: {kind}"), None, None),
    }
}

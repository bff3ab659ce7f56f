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
    hypersynth,
    Error,
    PyException,
    "Every error of hypersynth. `file`, `line` and `column` locate it when it is in a text \
     (None otherwise); the message is the command line's.\n\n\
     >>> try:\n\
     ...     hs.Problem(problem.arena, phi=\"F (A\", psi=\"F A\")\n\
     ... except hs.Error as error:\n\
     ...     print(error.file, error.line, error.column)\n\
     phi 1 5"
);
create_exception!(
    hypersynth,
    ParseError,
    Error,
    "A text (arena, map, formula, HOA automaton, observations, state name) is malformed.\n\n\
     >>> hs.Arena.from_string(\"initial s\\nstate s sideways {}\\n\", name=\"bad\")\n\
     Traceback (most recent call last):\n\
     hypersynth.ParseError: bad:2:9: ..."
);
create_exception!(
    hypersynth,
    ArenaError,
    Error,
    "An arena cannot be built (a duplicate state, an unknown state, a bad map).\n\n\
     >>> hs.ArenaBuilder().add_transition(\"x\", \"go\", \"y\")\n\
     Traceback (most recent call last):\n\
     hypersynth.ArenaError: no state is named `x`"
);
create_exception!(
    hypersynth,
    TranslationError,
    Error,
    "A formula cannot be translated to a DFA (not co-safe, too large, Spot missing or failing).\n\n\
     >>> hs.translate(\"G A\", translator=\"builtin\")\n\
     Traceback (most recent call last):\n\
     hypersynth.TranslationError: formula:1:1: ..."
);
create_exception!(
    hypersynth,
    TaskError,
    Error,
    "The tasks do not fit together (psi not a conjunct of phi, payoffs not monotone, bad names).\n\n\
     >>> hs.Problem(problem.arena, phi=\"F A & F B\", psi=\"F C\")\n\
     Traceback (most recent call last):\n\
     hypersynth.TaskError: psi:1:1: ..."
);
create_exception!(
    hypersynth,
    OptionsError,
    Error,
    "A solve option is out of range (discount, epsilon, sigma_l, a picture's name).\n\n\
     >>> problem.solve(discount=1.5)\n\
     Traceback (most recent call last):\n\
     hypersynth.OptionsError: discount: ..."
);
create_exception!(
    hypersynth,
    SolveError,
    Error,
    "The MDP stage failed (iteration limit, the controller's check, the learnt region).\n\n\
     >>> problem.solve(discount=0.999, max_iterations=2)\n\
     Traceback (most recent call last):\n\
     hypersynth.SolveError: ...; raise max_iterations or epsilon"
);
create_exception!(
    hypersynth,
    ControllerError,
    Error,
    "An exported controller is invalid, or was given a state it cannot take.\n\n\
     >>> solution.controller().step(\"nowhere\")\n\
     Traceback (most recent call last):\n\
     hypersynth.ControllerError: step 0: `nowhere` is not a state of the arena"
);

create_exception!(
    hypersynth,
    CertificateError,
    Error,
    "A controller's certificate does not certify its bounds (`hypersynth.check`): `certificate` \
     (`\"lower\"` or `\"upper\"`), `state` (the first product state, `ARENA_STATE|q_1|...`, in \
     breadth-first order from h0) and `inequality` (the condition that fails there) say where.\n\n\
     >>> import json, pathlib, tempfile\n\
     >>> file = json.loads(solution.controller_json(certificate=True))\n\
     >>> file[\"payoffs\"] = [r / 2 for r in file[\"payoffs\"]]\n\
     >>> file[\"value\"] = [v / 2 for v in file[\"value\"]]\n\
     >>> path = pathlib.Path(tempfile.mkdtemp()) / \"halved.json\"\n\
     >>> _ = path.write_text(json.dumps(file))\n\
     >>> try:\n\
     ...     hs.check(path)\n\
     ... except hs.CertificateError as error:\n\
     ...     print(error.certificate)\n\
     lower"
);

/// The `hypersynth.FileError` of a file named `name` that cannot be read because of `error`:
/// the command line's message, and an `OSError` of the error's kind (`FileNotFoundError`...)
/// with `errno`, `strerror` and `filename` set (the class is made in `hypersynth._errors`).
pub(crate) fn file_error(py: Python<'_>, name: &str, error: &std::io::Error) -> PyErr {
    let message = format!("{name}: cannot read: {error}");
    let made = py.import("hypersynth._errors").and_then(|module| {
        module.getattr("file_error")?.call1((
            error.raw_os_error(),
            error.to_string(),
            name,
            message.as_str(),
        ))
    });
    match made {
        Ok(exception) => PyErr::from_value(exception),
        Err(e) => e,
    }
}

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
        SpecErrorKind::NotCoSafe(errors) => located::<TranslationError, _>(name, text, &errors),
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

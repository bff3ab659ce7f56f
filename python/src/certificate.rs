//! `hypersynth.check(path)`: the certificate of an exported controller checked from the file
//! alone (docs/semantics.md §9.4), as `hypersynth check` checks it: the bounds certified, or a
//! `CertificateError` naming the first state and inequality that fail.

use pyo3::prelude::*;
use pyo3::types::PyDict;

use hypersynth::certificate::{CheckError, check_json};

use crate::errors::{CertificateError, ControllerError, exception, file_error};

/// Checks the certificate of the controller file at `path` (written by
/// `Solution.controller_json(certificate=True)` or `--export-controller FILE --certificate`),
/// re-deriving its model from the file alone and checking every inequality exactly. Returns the
/// bounds it certifies: `lower` (the controller collects at least this from h0), `upper` (no
/// controller collects more), and the number of states each covers (`lower_states`,
/// `upper_states`). Raises `CertificateError` (with `certificate`, `state` and `inequality`)
/// when an inequality fails, `ControllerError` when the file is no controller or has no
/// certificate, `FileError` when it cannot be read.
///
/// >>> import pathlib, tempfile
/// >>> path = pathlib.Path(tempfile.mkdtemp()) / "controller.json"
/// >>> _ = path.write_text(solution.controller_json(certificate=True))
/// >>> bounds = hs.check(path)
/// >>> bounds["lower"] <= solution.policy_value <= bounds["upper"]
/// True
#[pyfunction]
pub(crate) fn check(py: Python<'_>, path: std::path::PathBuf) -> PyResult<Py<PyDict>> {
    let name = path.display().to_string();
    let text = std::fs::read_to_string(&path).map_err(|e| file_error(py, &name, &e))?;
    let verdict = py.detach(|| check_json(&text));
    match verdict {
        Ok(bounds) => {
            let dict = PyDict::new(py);
            dict.set_item("lower", bounds.lower)?;
            dict.set_item("upper", bounds.upper)?;
            dict.set_item("lower_states", bounds.lower_states)?;
            dict.set_item("upper_states", bounds.upper_states)?;
            Ok(dict.unbind())
        }
        Err(CheckError::Refused(refusal)) => {
            let err = exception::<CertificateError>(format!("{name}: {refusal}"), None, None);
            let value = err.value(py);
            value.setattr("certificate", refusal.bound.to_string())?;
            value.setattr("state", &refusal.state)?;
            value.setattr("inequality", &refusal.inequality)?;
            Err(err)
        }
        Err(error) => Err(exception::<ControllerError>(
            format!("{name}: {error}"),
            None,
            None,
        )),
    }
}

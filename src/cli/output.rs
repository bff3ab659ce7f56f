//! The conventions every command shares about what it prints: writing outputs
//! ([`write_output`], atomically to a file or whole to standard output), warnings ([`warn`],
//! silenced by `-q`, printed above a progress bar rather than through it) and errors
//! ([`print_error`], [`located`]: `hypersynth: error: ...`, located ones with the line and a
//! caret).

use std::io::Write as _;
use std::path::Path;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::Context as _;
use hypersynth::diagnostic::{Diagnostic, Diagnostics, Source};
use hypersynth::position::Position;
use indicatif::{ProgressBar, WeakProgressBar};

/// Exit code for failures other than usage errors (clap uses 2 for those).
pub const FAILURE: u8 = 1;

/// What starts every error message on stderr.
pub const ERROR: &str = "hypersynth: error: ";

/// Whether `-q` was given: warnings are then not printed.
static QUIET: AtomicBool = AtomicBool::new(false);

/// The bar being drawn, if any: warnings are printed above it rather than through it.
static VISIBLE: Mutex<Option<WeakProgressBar>> = Mutex::new(None);

/// Records whether `-q` was given (once, before any command runs).
pub fn set_quiet(quiet: bool) {
    QUIET.store(quiet, Ordering::Relaxed);
}

/// Whether `-q` was given: progress messages are then not printed either.
pub fn quiet() -> bool {
    QUIET.load(Ordering::Relaxed)
}

/// Makes `bar` the one drawn on standard error, which warnings clear while they print.
pub fn showing(bar: &ProgressBar) {
    if let Ok(mut visible) = VISIBLE.lock() {
        *visible = Some(bar.downgrade());
    }
}

/// Runs `print` (which writes to standard error) with the visible bar, if any, cleared.
fn suspended(print: impl FnOnce()) {
    let bar = VISIBLE
        .lock()
        .ok()
        .and_then(|visible| visible.as_ref().and_then(WeakProgressBar::upgrade));
    match bar {
        Some(bar) => bar.suspend(print),
        None => print(),
    }
}

/// Prints `hypersynth: warning: MESSAGE` on stderr, unless `-q` was given.
pub fn warn(message: impl std::fmt::Display) {
    if !quiet() {
        suspended(|| eprintln!("hypersynth: warning: {message}"));
    }
}

/// Prints `hypersynth: error: MESSAGE` on stderr, for commands that report several errors
/// before failing. Lines of MESSAGE after the first are context, already indented.
pub fn print_error(message: impl std::fmt::Display) {
    eprintln!("{ERROR}{message}");
}

/// Errors located in `source`, as one error to return: each as the library's renderer shows
/// it (`NAME:LINE:COL: message`, the line, a caret), the second and later (and the count of
/// those not shown) each starting its own `hypersynth: error:` line.
pub fn located<M: std::fmt::Display>(
    source: &Source,
    diagnostics: &Diagnostics<M>,
) -> anyhow::Error {
    anyhow::anyhow!(source.render(diagnostics).join(&format!("\n{ERROR}")))
}

/// One error at `position` in `source`, shown as [`located`] shows errors.
pub fn located_at(
    source: &Source,
    position: Position,
    message: impl std::fmt::Display,
) -> anyhow::Error {
    located(
        source,
        &Diagnostics::from(Diagnostic::new(position, message)),
    )
}

/// Writes a command's whole output: to `file` atomically (all of it, or nothing on error), or
/// to standard output when there is no file.
pub fn write_output(file: Option<&Path>, text: &str) -> anyhow::Result<()> {
    match file {
        Some(path) => super::io::write_atomically(path, text.as_bytes())
            .with_context(|| format!("cannot write {}", path.display())),
        // A reader that stops early (`| head`) makes this fail with BrokenPipe, which the
        // dispatcher turns into a quiet exit 0.
        None => std::io::stdout()
            .lock()
            .write_all(text.as_bytes())
            .context("cannot write to standard output"),
    }
}

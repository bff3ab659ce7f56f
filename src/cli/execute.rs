//! `hypersynth execute CONTROLLER`: runs an exported controller (`--export-controller`) on a play
//! read from standard input, one arena state per line, answering each robot turn on standard
//! output at once (one line, flushed), so that a robot or a simulator can drive it through a
//! pipe. Moves off the model or off the controller are warnings; the first error (an unknown
//! state, a step that is no arena transition, a state the controller was not exported for) ends
//! the command with the line and step it happened at.

use std::io::{BufRead as _, Write as _};
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context as _;
use hypersynth::arena::{QuoteError, read_quoted};
use hypersynth::diagnostic::{Diagnostics, Source, brief};
use hypersynth::opportunistic::executor::{ControllerError, ExecutionError, Executor};
use hypersynth::opportunistic::export::Scope;

/// The answers a robot turn gets, at the end of `hypersynth execute --help`.
pub const ANSWERS: &str = "\
Answers (one line per robot turn):
  N                  play the arena action N
  commit SET N       the state is absorbing: commit to SET (phi, phi2, or A,B in the general
                     form), then play N
  stop SET N         play `stop` (instant) and commit to SET, then play N
  commit SET done    commit (or stop SET done): SET already holds
  done               every sub-task of the set committed to holds
  give up            nothing can be gained from here (value 0)";

/// Options of `hypersynth execute`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The exported controller, a file written by `--export-controller`.
    #[arg(value_name = "CONTROLLER")]
    pub controller: PathBuf,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let shown = args.controller.display().to_string();
    let text = super::io::read_input(&shown).with_context(|| format!("{shown}: cannot read"))?;
    let mut executor = Executor::from_json(&text).map_err(|e| file_error(&shown, &text, &e))?;
    let stdin = std::io::stdin();
    let mut stdout = std::io::stdout().lock();
    for (number, line) in stdin.lock().lines().enumerate() {
        let line = line.context("<stdin>: cannot read")?;
        let at = format!("<stdin>:{}", number + 1);
        let Some(name) = state_name(&line).map_err(|e| anyhow::anyhow!("{at}: {e}"))? else {
            continue;
        };
        let turn = executor.observe(&name).map_err(|e| match e {
            ExecutionError::NotCovered {
                scope: Scope::Reachable,
                ..
            } => anyhow::anyhow!("{at}: {e}: export it with --controller-scope all"),
            e => anyhow::anyhow!("{at}: {e}"),
        })?;
        if let Some(off_model) = &turn.off_model {
            super::output::warn(format_args!("{at}: {off_model}"));
        }
        if let Some(answer) = &turn.answer {
            writeln!(stdout, "{}", executor.answer_line(answer))?;
            stdout.flush()?;
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// The state named on `line`: double-quoted as in the arena format, or the line itself
/// without its surrounding white space; `None` for a blank line.
fn state_name(line: &str) -> anyhow::Result<Option<String>> {
    let trimmed = line.trim();
    if trimmed.is_empty() {
        return Ok(None);
    }
    if !trimmed.starts_with('"') {
        return Ok(Some(trimmed.to_string()));
    }
    let (name, end) = read_quoted(trimmed, 0).map_err(|(_, error)| match error {
        QuoteError::Unterminated => anyhow::anyhow!("the closing quote is missing"),
        QuoteError::UnknownEscape(letter) => {
            anyhow::anyhow!("unknown escape `\\{}`", letter.escape_debug())
        }
    })?;
    if !trimmed[end..].trim().is_empty() {
        anyhow::bail!(
            "one state per line: `{}` follows the name",
            brief(trimmed[end..].trim())
        );
    }
    Ok(Some(name.into_owned()))
}

/// A controller file's error: a JSON syntax error shown under its line as other readers show
/// theirs, or each problem of the file on its own `hypersynth: error:` line.
pub(super) fn file_error(shown: &str, text: &str, error: &ControllerError) -> anyhow::Error {
    match error {
        ControllerError::Syntax(diagnostic) => super::output::located(
            &Source::new(shown, text),
            &Diagnostics::from(diagnostic.clone()),
        ),
        ControllerError::Invalid(_) => {
            let lines: Vec<String> = error
                .to_string()
                .lines()
                .map(|line| format!("{shown}: {line}"))
                .collect();
            anyhow::anyhow!(lines.join(&format!("\n{}", super::output::ERROR)))
        }
    }
}

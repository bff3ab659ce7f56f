//! Command-line parsing (clap derive) and dispatch. Each subcommand lives in its own file with an
//! `Args` struct and a `run` function; this file only wires them together and turns errors into
//! `hypersynth: error: ...` on stderr with a non-zero exit code.

use std::io::Write as _;
use std::path::Path;
use std::process::ExitCode;

use anyhow::Context as _;
use clap::{Parser, Subcommand};

mod arena;
mod gridworld;
mod hoa;
mod ltl;
pub(crate) mod opportunistic;
mod render;
mod synth;
mod translate;

#[derive(Parser, Debug)]
#[command(
    name = "hypersynth",
    version,
    about = "Opportunistic synthesis for hypergames: co-safe LTL tasks, two-player arenas, \
             winning regions and the opportunistic strategy",
    args_conflicts_with_subcommands = true,
    arg_required_else_help = true
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,

    /// The main form: `hypersynth --phi PHI --psi PSI ARENA`.
    #[command(flatten)]
    synthesis: synth::Args,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Parse LTL formulas, print them normalised and classify them (co-safe or not).
    Ltl(ltl::Args),
    /// Translate a co-safe LTL formula into a minimal complete DFA, written as HOA.
    Translate(translate::Args),
    /// Read HOA files, validate them and print their size, or convert them to DOT.
    Hoa(hoa::Args),
    /// Validate an arena file and print its statistics.
    Arena(arena::Args),
    /// Generate a two-player turn-based gridworld arena.
    Gridworld(gridworld::Args),
}

/// Exit code for failures other than usage errors (clap uses 2 for those).
const FAILURE: u8 = 1;

pub fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Some(Command::Ltl(args)) => ltl::run(args),
        Some(Command::Translate(args)) => translate::run(args),
        Some(Command::Hoa(args)) => hoa::run(args),
        Some(Command::Arena(args)) => arena::run(args),
        Some(Command::Gridworld(args)) => gridworld::run(args),
        None => synth::run(cli.synthesis),
    };
    match result {
        Ok(code) => code,
        Err(error) => report_error(&error),
    }
}

/// Prints an error as `hypersynth: error: ...`: the first line is the whole message; further
/// lines (for example a caret under a formula) are context and are printed indented as given.
fn report_error(error: &anyhow::Error) -> ExitCode {
    print_error(format_args!("{error:#}"));
    ExitCode::from(FAILURE)
}

/// Prints `hypersynth: error: MESSAGE` on stderr, for commands that report several errors
/// before failing. Lines of MESSAGE after the first are context, already indented.
fn print_error(message: impl std::fmt::Display) {
    eprintln!("hypersynth: error: {message}");
}

/// Writes a command's whole output: to `file` atomically (all of it, or nothing on error), or
/// to standard output when there is no file.
fn write_output(file: Option<&Path>, text: &str) -> anyhow::Result<()> {
    match file {
        Some(path) => hypersynth::io::write_atomically(path, text.as_bytes())
            .with_context(|| format!("cannot write {}", path.display())),
        None => match std::io::stdout().lock().write_all(text.as_bytes()) {
            // A reader that stops early (`| head`) is not an error of ours.
            Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
            result => result.context("cannot write to standard output"),
        },
    }
}

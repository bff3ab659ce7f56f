//! Command-line parsing (clap derive) and dispatch. Each subcommand lives in its own file with an
//! `Args` struct and a `run` function; this file only wires them together and turns errors into
//! `hypersynth: error: ...` on stderr with a non-zero exit code.

use std::process::ExitCode;

use clap::{Parser, Subcommand};

mod arena;
mod gridworld;
mod hoa;
mod ltl;
pub(crate) mod opportunistic;
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
    eprintln!("hypersynth: error: {error:#}");
    ExitCode::from(FAILURE)
}

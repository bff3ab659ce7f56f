//! Command-line parsing (clap derive) and dispatch. Each subcommand lives in its own file with an
//! `Args` struct and a `run` function; this file only wires them together and turns errors into
//! `hypersynth: error: ...` on stderr with a non-zero exit code.

use std::process::ExitCode;

use clap::{Parser, Subcommand};

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
    synthesis: SynthesisArgs,
}

/// Reserved for the main form (solved by the hypergame and MDP stages).
#[derive(clap::Args, Debug)]
struct SynthesisArgs {
    /// The robot's task, a co-safe LTL formula `phi1 & phi2`.
    #[arg(long, value_name = "PHI")]
    phi: Option<String>,
    /// The task the adversary believes the robot has (`phi1`).
    #[arg(long, value_name = "PSI")]
    psi: Option<String>,
    /// The arena file (`-` for standard input).
    #[arg(value_name = "ARENA")]
    arena: Option<String>,
}

#[derive(Subcommand, Debug)]
enum Command {}

/// Exit code for failures other than usage errors (clap uses 2 for those).
const FAILURE: u8 = 1;

pub fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Some(command) => match command {},
        None => Err(anyhow::anyhow!(
            "the main form `--phi PHI --psi PSI ARENA` is not available yet: use a subcommand \
             (see `hypersynth --help`)"
        )),
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

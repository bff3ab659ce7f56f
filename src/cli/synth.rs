//! The main form: `hypersynth --phi PHI --psi PSI ARENA`.

use std::process::ExitCode;

/// The main form's options (solved by the hypergame and MDP stages).
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The robot's task, a co-safe LTL formula `phi1 & phi2`.
    #[arg(long, value_name = "PHI")]
    pub phi: Option<String>,
    /// The task the adversary believes the robot has (`phi1`).
    #[arg(long, value_name = "PSI")]
    pub psi: Option<String>,
    /// The arena file (`-` for standard input).
    #[arg(value_name = "ARENA")]
    pub arena: Option<String>,
}

pub fn run(_args: Args) -> anyhow::Result<ExitCode> {
    anyhow::bail!(
        "the main form `--phi PHI --psi PSI ARENA` is not available yet: use a subcommand \
         (see `hypersynth --help`)"
    )
}

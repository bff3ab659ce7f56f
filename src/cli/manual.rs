//! `hypersynth completions SHELL` and `hypersynth man [SUBCOMMAND]`: the shell completion script
//! and the manual page, both generated from the command-line definition itself, so they name
//! exactly the subcommands and options that `--help` describes.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context as _;

#[derive(clap::Args, Debug)]
pub struct CompletionsArgs {
    /// The shell to complete for.
    #[arg(value_enum)]
    shell: clap_complete::Shell,
    /// Write the script to FILE (atomically) instead of standard output.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    output: Option<PathBuf>,
}

#[derive(clap::Args, Debug)]
pub struct ManArgs {
    /// The subcommand whose page to print (`translate`, ...) instead of hypersynth's.
    #[arg(value_name = "SUBCOMMAND")]
    subcommand: Option<String>,
    /// Write the page to FILE (atomically) instead of standard output.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    output: Option<PathBuf>,
}

/// The completion script of `command` for the chosen shell.
pub fn completions(args: CompletionsArgs, mut command: clap::Command) -> anyhow::Result<ExitCode> {
    let mut script = Vec::new();
    clap_complete::generate(args.shell, &mut command, "hypersynth", &mut script);
    let script = String::from_utf8(script).context("the completion script is not UTF-8")?;
    super::output::write_output(args.output.as_deref(), &script)?;
    Ok(ExitCode::SUCCESS)
}

/// The roff manual page of `command`, or of one of its subcommands (titled
/// `hypersynth-SUBCOMMAND`, its usage line `hypersynth SUBCOMMAND ...`).
pub fn man(args: ManArgs, mut command: clap::Command) -> anyhow::Result<ExitCode> {
    command.build();
    let (page, title) = match &args.subcommand {
        None => (command, "hypersynth".to_string()),
        Some(name) => {
            let Some(subcommand) = command.find_subcommand(name) else {
                let names: Vec<&str> = command.get_subcommands().map(|c| c.get_name()).collect();
                anyhow::bail!(
                    "no subcommand `{name}` (the subcommands are {})",
                    names.join(", ")
                );
            };
            let title = format!("hypersynth-{name}");
            (subcommand.clone().display_name(title.clone()), title)
        }
    };
    let mut roff = Vec::new();
    clap_mangen::Man::new(page)
        .title(title)
        .source(format!("hypersynth {}", env!("CARGO_PKG_VERSION")))
        .render(&mut roff)
        .context("cannot render the manual page")?;
    let roff = String::from_utf8(roff).context("the manual page is not UTF-8")?;
    super::output::write_output(args.output.as_deref(), &roff)?;
    Ok(ExitCode::SUCCESS)
}

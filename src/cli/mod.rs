//! Command-line parsing (clap derive) and dispatch, nothing else. Each subcommand lives in its
//! own file with an `Args` struct and a `run` function, the main form in `synth` (its tasks in
//! `tasks`, its MDP stage's options in `opportunistic`); the conventions every command shares
//! (writing outputs, warnings silenced by `-q`, errors) are `output`'s. This file wires them
//! together and turns errors into `hypersynth: error: ...` on stderr with a non-zero exit code;
//! a closed standard output (`| head`) ends the command quietly with status 0. The modules
//! import each other only sideways, never this one.

use std::ffi::OsString;
use std::path::Path;
use std::process::ExitCode;

use clap::{CommandFactory as _, FromArgMatches as _, Parser, Subcommand};

mod arena;
mod batch;
mod check;
mod choices;
mod execute;
mod gridworld;
mod hoa;
mod io;
mod ltl;
mod manual;
mod memory;
mod opportunistic;
mod output;
mod pattern;
mod progress;
mod render;
mod synth;
mod tasks;
mod translate;

/// The main form's examples, at the end of `--help`: the bundled examples, from the
/// repository's root.
const EXAMPLES: &str = "\
Examples (from the repository's root):
  The paper's case study: the report, h0's decision table, a picture of the controller
    hypersynth --phi '(!O U A) & (!O U B)' --psi '!O U A' specs/case-study/map.txt \\
        --discount 0.99 --sigma-l uniform --explain --svg partition.svg
  Three sub-tasks with payoffs on sets, the adversary believing only A
    hypersynth specs/decoy/arena.txt --task 'A=!O U A' --task 'B=!O U B' --task 'C=F C' \\
        --payoff A=200 --payoff B=100 --payoff C=50 --payoff A,B=350 --believed '!O U A'
  The controller as a file, run step by step on the states of a play
    hypersynth --phi '(!O U A) & (!O U B)' --psi '!O U A' specs/case-study/map.txt \\
        --export-controller controller.json
    hypersynth execute controller.json < play.txt
  sigma_L learnt from observed runs: the robust value and the learning curve
    hypersynth --phi '(!O U A) & (!O U B)' --psi '!O U A' specs/case-study/arena.txt \\
        --discount 0.99 --observations specs/learnt/runs.txt --learning-curve curve.svg
  The MDP for Storm, and the seconds of every stage
    hypersynth --phi '(!O U A) & (!O U B)' --psi '!O U A' specs/case-study/arena.txt \\
        --export-mdp mdp.drn --timings";

#[derive(Parser, Debug)]
#[command(
    name = "hypersynth",
    version,
    subcommand_negates_reqs = true,
    about = "Opportunistic synthesis for hypergames: co-safe LTL tasks, two-player arenas, \
             winning regions and the opportunistic strategy",
    args_conflicts_with_subcommands = true,
    arg_required_else_help = true,
    after_help = EXAMPLES
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,

    /// Do not print warnings or progress messages on standard error (errors still are).
    #[arg(short, long, global = true)]
    quiet: bool,

    /// The main form: `hypersynth --phi PHI --psi PSI ARENA`.
    #[command(flatten)]
    synthesis: synth::Args,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Parse LTL formulas, print them normalised and classify them (co-safe or not).
    Ltl(ltl::Args),
    /// Translate co-safe LTL formulas (-f, -F as in Spot) into minimal complete DFAs, written as
    /// one HOA stream.
    Translate(translate::Args),
    /// Read HOA files, validate them and print their size, convert them to DOT, or write them
    /// back as minimal complete DFAs in HOA.
    Hoa(hoa::Args),
    /// Validate an arena file and print its statistics.
    Arena(arena::Args),
    /// Generate a two-player turn-based gridworld arena.
    Gridworld(gridworld::Args),
    /// Run an exported controller (--export-controller): read the play's arena states one per
    /// line on standard input, answer each robot turn on standard output.
    #[command(after_help = execute::ANSWERS)]
    Execute(execute::Args),
    /// Check the certificate of an exported controller (--export-controller FILE
    /// --certificate) from the file alone: the bounds it certifies, or the first state and
    /// inequality that fail.
    Check(check::Args),
    /// Print a shell completion script (bash, zsh, fish, elvish, powershell).
    Completions(manual::CompletionsArgs),
    /// Print the manual page (roff) of hypersynth or of one of its subcommands.
    Man(manual::ManArgs),
}

pub fn main() -> ExitCode {
    let arguments = quiet_after_subcommand(std::env::args_os().collect());
    if let Some(error) = unknown_subcommand(&arguments)
        .or_else(|| stats_on_main_form(&arguments))
        .or_else(|| explain_without_equals(&arguments))
    {
        error.exit();
    }
    let matches = Cli::command().get_matches_from(&arguments);
    let cli = Cli::from_arg_matches(&matches).unwrap_or_else(|error| error.exit());
    output::set_quiet(cli.quiet);
    if cli.command.is_none()
        && let Err(message) = cli.synthesis.check_usage()
    {
        Cli::command()
            .error(clap::error::ErrorKind::MissingRequiredArgument, message)
            .exit();
    }
    let sub_matches = |name| matches.subcommand_matches(name).unwrap_or(&matches);
    let result = match cli.command {
        Some(Command::Ltl(args)) => ltl::run(args, sub_matches("ltl")),
        Some(Command::Translate(args)) => translate::run(args, sub_matches("translate")),
        Some(Command::Hoa(args)) => hoa::run(args),
        Some(Command::Arena(args)) => arena::run(args),
        Some(Command::Gridworld(args)) => gridworld::run(args),
        Some(Command::Execute(args)) => execute::run(args),
        Some(Command::Check(args)) => check::run(args),
        Some(Command::Completions(args)) => manual::completions(args, Cli::command()),
        Some(Command::Man(args)) => manual::man(args, Cli::command()),
        None => {
            cli.synthesis.memory.install();
            synth::run(cli.synthesis)
        }
    };
    match result {
        Ok(code) => code,
        Err(error) => report_error(&error),
    }
}

/// Prints an error as `hypersynth: error: ...`: the first line is the whole message; further
/// lines (for example a caret under a formula) are context and are printed indented as given,
/// or, after several located errors ([`located`]), the next ones, already prefixed.
/// A reader that closed standard output early (`| head`) is not an error of ours: exit 0.
fn report_error(error: &anyhow::Error) -> ExitCode {
    let closed_pipe = error.chain().any(|cause| {
        cause
            .downcast_ref::<std::io::Error>()
            .is_some_and(|e| e.kind() == std::io::ErrorKind::BrokenPipe)
    });
    if closed_pipe {
        return ExitCode::SUCCESS;
    }
    output::print_error(format_args!("{error:#}"));
    ExitCode::from(output::FAILURE)
}

/// Whether an argument is `-q` or `--quiet`.
fn is_quiet(argument: &OsString) -> bool {
    argument == "-q" || argument == "--quiet"
}

/// `-q` before a subcommand (`hypersynth -q translate ...`) goes after the subcommand's name.
/// clap would otherwise count it as an argument of the main form, and arguments of the main form
/// exclude subcommands; the global flag reads the same after the name.
fn quiet_after_subcommand(arguments: Vec<OsString>) -> Vec<OsString> {
    let leading = arguments.iter().skip(1).take_while(|a| is_quiet(a)).count();
    let name = arguments.get(1 + leading).and_then(|a| a.to_str());
    let is_subcommand = name.is_some_and(|name| {
        name == "help"
            || Cli::command()
                .get_subcommands()
                .any(|command| command.get_name() == name)
    });
    if leading == 0 || !is_subcommand {
        return arguments;
    }
    let mut reordered = arguments;
    reordered[1..=1 + leading].rotate_right(1);
    reordered
}

/// `--stats` on the main form: Spot's `--stats FORMAT` prints automata statistics, which
/// `translate` and `hoa` do; the main form's stage timings are `--timings`. Without this check
/// `--stats '%s' ARENA` would be a baffling usage error about `%s`.
fn stats_on_main_form(arguments: &[OsString]) -> Option<clap::Error> {
    let mut command = Cli::command();
    let first = arguments.get(1)?.to_str()?;
    if first == "help" || command.get_subcommands().any(|c| c.get_name() == first) {
        return None;
    }
    let given = arguments
        .iter()
        .skip(1)
        .take_while(|a| *a != "--")
        .any(|a| a == "--stats" || a.to_str().is_some_and(|a| a.starts_with("--stats=")));
    given.then(|| {
        command.error(
            clap::error::ErrorKind::UnknownArgument,
            "the main form has no --stats: the seconds of its stages are --timings; Spot's \
             --stats FORMAT (automata statistics) is an option of `hypersynth translate` and \
             `hypersynth hoa`",
        )
    })
}

/// `--explain STATE` on the main form: `--explain` takes its state only after `=` (so that
/// `--explain ARENA` leaves ARENA to the main form), and without it clap would read the state as
/// the arena and the arena as a subcommand. A separate argument after `--explain` that looks like
/// a product state (`ARENA_STATE|Q1|Q2`, an arena state's tuple, or `h0`) and names no file is
/// refused with the command corrected.
fn explain_without_equals(arguments: &[OsString]) -> Option<clap::Error> {
    let mut command = Cli::command();
    let first = arguments.get(1)?.to_str()?;
    if first == "help" || command.get_subcommands().any(|c| c.get_name() == first) {
        return None;
    }
    let options = arguments.iter().take_while(|a| *a != "--").count();
    let at = (1..options).find(|&i| {
        arguments[i] == "--explain"
            && arguments
                .get(i + 1)
                .and_then(|a| a.to_str())
                .is_some_and(|next| {
                    (next.contains('|') || next.starts_with('(') || next == "h0")
                        && !Path::new(next).exists()
                })
    })?;
    let state = arguments[at + 1].to_str()?;
    let mut corrected = vec![String::from("hypersynth")];
    for (i, argument) in arguments.iter().enumerate().skip(1) {
        match i {
            _ if i == at => corrected.push(format!("--explain={}", shell_quoted(state))),
            _ if i == at + 1 => {}
            _ => corrected.push(shell_quoted(&argument.to_string_lossy())),
        }
    }
    Some(command.error(
        clap::error::ErrorKind::ArgumentConflict,
        format!(
            "--explain takes its state after `=`: `--explain {state}` reads `{state}` as the \
             arena; corrected:\n\n  {}",
            corrected.join(" ")
        ),
    ))
}

/// An argument as a POSIX shell reads it back: bare when it has only safe characters, else in
/// single quotes.
fn shell_quoted(argument: &str) -> String {
    let safe = !argument.is_empty()
        && argument
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_./=,:@%+".contains(c));
    if safe {
        argument.to_string()
    } else {
        format!("'{}'", argument.replace('\'', "'\\''"))
    }
}

/// A first argument that is neither an option, a subcommand nor an existing file is a
/// misspelled subcommand (the main form's ARENA would otherwise take it and fail later with a
/// confusing message): a usage error, with the closest subcommand as a suggestion.
fn unknown_subcommand(arguments: &[OsString]) -> Option<clap::Error> {
    // `-q` may come first (`hypersynth -q tranlsate`).
    let first = arguments.iter().skip(1).find(|a| !is_quiet(a))?.to_str()?;
    let command = Cli::command();
    let names: Vec<&str> = command
        .get_subcommands()
        .map(clap::Command::get_name)
        .chain(["help"])
        .collect();
    let looks_like_a_word = first
        .chars()
        .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_');
    if first.starts_with('-') || names.contains(&first) || !looks_like_a_word {
        return None;
    }
    if Path::new(first).exists() {
        return None;
    }
    let suggestion = names
        .iter()
        .map(|name| (edit_distance(first, name), *name))
        .filter(|&(distance, name)| distance <= 2.max(name.len() / 3))
        .min();
    let tip = match suggestion {
        Some((_, name)) => format!("\n\n  tip: a similar subcommand exists: '{name}'"),
        None => String::new(),
    };
    Some(command.clone().error(
        clap::error::ErrorKind::InvalidSubcommand,
        format!(
            "unknown subcommand '{first}' (and no arena file of that name){tip}\n\n\
             For the main form, give the options first: hypersynth --phi PHI --psi PSI ARENA"
        ),
    ))
}

/// Levenshtein distance between two short ASCII words.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut previous: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut current = vec![i + 1];
        for (j, &cb) in b.iter().enumerate() {
            let substitution = previous[j] + usize::from(ca != cb);
            current.push(substitution.min(previous[j + 1] + 1).min(current[j] + 1));
        }
        previous = current;
    }
    previous[b.len()]
}

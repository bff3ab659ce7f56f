//! `hypersynth arena`: validates an arena file, warns about its stuck and unreachable states (one
//! line per kind) and prints its statistics, or with `--check` lists those states. Also where
//! every subcommand reads an arena (the main form's as the problem specification's text, whose
//! errors [`error`] locates), so errors look the same everywhere; the other subcommands read
//! arenas without warnings about their structure (stuck and unreachable states are semantics,
//! docs/semantics.md §3.2, and a generated gridworld has both by design).

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use hypersynth::arena::gridworld::Gridworld;
use hypersynth::arena::{self, Arena, Name, Statistics, Warning, map};
use hypersynth::diagnostic::Source;
use hypersynth::pipeline::spec::{ArenaSpec, SpecErrorKind};

#[derive(clap::Args, Debug)]
pub struct Args {
    /// The arena or map file (`-` for standard input).
    #[arg(value_name = "FILE")]
    file: String,
    /// How to print the statistics.
    #[arg(long, value_enum, default_value_t = Format::Text)]
    format: Format,
    /// Print the arena as a Graphviz graph instead (at most 200 states).
    #[arg(long, conflicts_with = "format")]
    dot: bool,
    /// List every stuck state and every state unreachable from the initial state instead, one
    /// per line, located at its `state` line (the warnings summarise them).
    #[arg(long, conflicts_with_all = ["format", "dot"])]
    check: bool,
    /// Write to FILE (atomically) instead of standard output.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    output: Option<PathBuf>,
}

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Text,
    Json,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let (arena, defects) = load_checked(&args.file)?;
    let file = display_name(&args.file);
    if args.check {
        let listing: String = defects
            .iter()
            .map(|warning| match warning.position {
                Some(_) => format!("{file}:{warning}\n"),
                None => format!("{file}: {warning}\n"),
            })
            .collect();
        super::output::write_output(args.output.as_deref(), &listing)?;
        return Ok(ExitCode::SUCCESS);
    }
    for summary in arena::summarise(&defects) {
        super::output::warn(format_args!(
            "{file}: {summary} (`hypersynth arena --check {file}` lists them)"
        ));
    }
    if args.dot {
        let dot = arena::dot::to_dot(&arena, arena::dot::MAX_DOT_STATES)
            .with_context(|| file.to_string())?;
        super::output::write_output(args.output.as_deref(), &dot)?;
        return Ok(ExitCode::SUCCESS);
    }
    let stats = Statistics::of(&arena);
    let output = match args.format {
        Format::Json => serde_json::to_string_pretty(&stats)? + "\n",
        Format::Text => text(&stats),
    };
    super::output::write_output(args.output.as_deref(), &output)?;
    Ok(ExitCode::SUCCESS)
}

/// Reads an arena or a map (`-` for standard input) with its stuck and unreachable states:
/// located at their `state` lines in an arena text, by name alone in a map's arena.
fn load_checked(file: &str) -> anyhow::Result<(Arena, Vec<Warning>)> {
    let (shown, text) = read(file)?;
    if map::is_map(&text) {
        let arena = parse_map(shown, &text)?
            .build()
            .with_context(|| shown.to_string())?;
        let defects = arena::defects(&arena);
        return Ok((arena, defects));
    }
    let parsed = arena::parse(&text)
        .map_err(|errors| super::output::located(&Source::new(shown, &text), &errors))?;
    Ok((parsed.arena, parsed.warnings))
}

/// The main form's ARENA (`-` for standard input), an arena file or a map (recognised by its
/// header) as the library's specification, named as given on the command line in reports.
pub fn spec(file: &str) -> anyhow::Result<ArenaSpec> {
    let (_, text) = read(file)?;
    Ok(ArenaSpec::Text {
        name: file.to_string(),
        text,
    })
}

/// An error of the arena of `spec` (the one [`spec`] made): located as `FILE:LINE:COLUMN` with
/// the line and a caret (all of them, up to the reader's limit), like the other subcommands'.
pub fn error(spec: &ArenaSpec, kind: SpecErrorKind) -> anyhow::Error {
    let shown = display_name(spec.name());
    let source = Source::new(shown, spec.text().unwrap_or_default());
    match kind {
        SpecErrorKind::Arena(errors) => super::output::located(&source, &errors),
        SpecErrorKind::Map(errors) => super::output::located(&source, &errors),
        SpecErrorKind::Gridworld(error) => anyhow::Error::new(error).context(shown.to_string()),
        SpecErrorKind::Memory(error) => anyhow::Error::new(error).context(shown.to_string()),
        other => anyhow::Error::new(other).context(shown.to_string()),
    }
}

/// How `file` is named in messages.
fn display_name(file: &str) -> &str {
    if file == "-" { "<stdin>" } else { file }
}

/// Reads a map file (`-` for standard input), errors located as [`error`] locates them.
pub fn load_map(file: &str) -> anyhow::Result<Gridworld> {
    let (shown, text) = read(file)?;
    parse_map(shown, &text)
}

/// The name of `file` in messages, and its text.
fn read(file: &str) -> anyhow::Result<(&str, String)> {
    let shown = display_name(file);
    let text = super::io::read_input(file).with_context(|| shown.to_string())?;
    Ok((shown, text))
}

fn parse_map(shown: &str, text: &str) -> anyhow::Result<Gridworld> {
    map::parse(text).map_err(|errors| super::output::located(&Source::new(shown, text), &errors))
}

fn text(stats: &Statistics) -> String {
    let names = |names: &[String]| {
        names
            .iter()
            .map(|n| Name(n).to_string())
            .collect::<Vec<_>>()
            .join(" ")
    };
    format!(
        "states           {} (robot {}, adversary {})\n\
         transitions      {}\n\
         actions          {}: {}\n\
         propositions     {}: {}\n\
         distinct labels  {}\n\
         initial state    {}\n\
         stuck states     {} (robot {}, adversary {})\n\
         unreachable      {}\n",
        stats.states,
        stats.robot_states,
        stats.adversary_states,
        stats.transitions,
        stats.actions.len(),
        names(&stats.actions),
        stats.propositions.len(),
        names(&stats.propositions),
        stats.distinct_labels,
        Name(&stats.initial),
        stats.stuck_robot_states + stats.stuck_adversary_states,
        stats.stuck_robot_states,
        stats.stuck_adversary_states,
        stats.unreachable_states,
    )
}

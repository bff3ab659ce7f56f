//! `hypersynth arena`: validates an arena file and prints its statistics. Also the loader every
//! subcommand that reads an arena goes through, so errors and warnings look the same everywhere.

use std::process::ExitCode;

use anyhow::Context;
use hypersynth::arena::gridworld::Gridworld;
use hypersynth::arena::{self, Arena, Name, Statistics, Warning, WarningKind, map};
use hypersynth::diagnostic::Source;
use hypersynth::stage::{Meter, Stage};

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
}

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Text,
    Json,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let arena = load(&args.file)?;
    if args.dot {
        let dot = arena::dot::to_dot(&arena, arena::dot::MAX_DOT_STATES)
            .with_context(|| display_name(&args.file).to_string())?;
        super::write_output(None, &dot)?;
        return Ok(ExitCode::SUCCESS);
    }
    let stats = Statistics::of(&arena);
    let output = match args.format {
        Format::Json => serde_json::to_string_pretty(&stats)? + "\n",
        Format::Text => text(&stats),
    };
    super::write_output(None, &output)?;
    Ok(ExitCode::SUCCESS)
}

/// Reads an arena file, or a map (recognised by its header), whose arena is built in memory
/// (`-` for standard input); arena warnings go to stderr, errors (all of them, up to the
/// reader's limit) are located as `FILE:LINE:COLUMN` with the line and a caret.
pub fn load(file: &str) -> anyhow::Result<Arena> {
    load_input(file, &mut Meter::unobserved(Stage::Parse)).map(|input| input.arena)
}

/// What [`load`] read: the arena, and the map's gridworld when the file was a map.
pub struct Input {
    pub arena: Arena,
    pub map: Option<Gridworld>,
}

/// [`load`], keeping the map.
pub fn load_input(file: &str, meter: &mut Meter<'_>) -> anyhow::Result<Input> {
    let (shown, text) = read(file)?;
    if map::is_map(&text) {
        let world = parse_map(shown, &text)?;
        if let Ok(bytes) = world.build_bytes() {
            meter
                .reserve(bytes, || {
                    format!("the arena of the {}x{} map", world.width, world.height)
                })
                .with_context(|| shown.to_string())?;
        }
        // Display names serve only the arena writer; solving never shows them.
        let arena = world
            .build_without_display_names()
            .with_context(|| shown.to_string())?;
        return Ok(Input {
            arena,
            map: Some(world),
        });
    }
    let parsed = arena::parse_metered(&text, meter)
        .map_err(|errors| super::located(&Source::new(shown, &text), &errors))?;
    print_warnings(shown, &parsed.warnings);
    Ok(Input {
        arena: parsed.arena,
        map: None,
    })
}

/// How `file` is named in messages.
fn display_name(file: &str) -> &str {
    if file == "-" { "<stdin>" } else { file }
}

/// Reads a map file (`-` for standard input), errors located as [`load`] locates them.
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
    map::parse(text).map_err(|errors| super::located(&Source::new(shown, text), &errors))
}

/// How many warnings of one kind are printed before the rest are only counted.
const SHOWN_PER_KIND: usize = 5;

fn print_warnings(file: &str, warnings: &[Warning]) {
    let kinds = ["stuck", "unreachable"];
    let (mut shown, mut hidden) = ([0; 2], [0; 2]);
    for warning in warnings {
        let kind = match warning.kind {
            WarningKind::Stuck(_) => 0,
            WarningKind::Unreachable => 1,
        };
        if shown[kind] < SHOWN_PER_KIND {
            super::warn(format_args!("{file}:{warning}"));
            shown[kind] += 1;
        } else {
            hidden[kind] += 1;
        }
    }
    for (kind, hidden) in kinds.iter().zip(hidden) {
        if hidden > 0 {
            super::warn(format_args!("{file}: {hidden} more {kind} states"));
        }
    }
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

//! `hypersynth hoa`: read HOA files, validate every automaton in them, and print one summary
//! line per automaton (`stats`), the DOT graphs of their DFAs, or the DFAs written back as one
//! HOA stream (`hoa`: minimised and complete, as `autfilt` normalises). All inputs are read and
//! checked before anything is printed or written, so a failure leaves no partial output.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

use super::io::read_input;
use super::pattern::{self, Field, Pattern, Subject};
use anyhow::Context;
use hypersynth::automata::dot::to_dot;
use hypersynth::automata::hoa::{self, HoaAutomaton};
use hypersynth::automata::minimize;
use hypersynth::diagnostic::Source;
use hypersynth::report::counted;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// HOA files to read (`-` reads standard input); each may hold several automata.
    #[arg(required = true, value_name = "FILE")]
    files: Vec<String>,

    /// What to print for each automaton: a summary line (`stats`), its DFA as a DOT graph
    /// (`dot`), or its minimal complete DFA in HOA (`hoa`), keeping the automaton's name. The
    /// last of --format, -d, -H and --stats counts, as in Spot.
    #[arg(long = "format", alias = "output-format", value_enum,
          default_value_t = OutputFormat::Stats, overrides_with_all = ["dot", "hoa", "stats"])]
    format: OutputFormat,

    /// Same as `--format dot`.
    #[arg(short = 'd', long, overrides_with_all = ["format", "hoa", "stats"])]
    dot: bool,

    /// Same as `--format hoa`.
    #[arg(short = 'H', long, overrides_with_all = ["format", "dot", "stats"])]
    hoa: bool,

    /// Instead of the summary, one line per automaton following FORMAT, as Spot's tools do:
    /// `%s` states, `%e` edges, `%t` transitions (letters), `%a` acceptance sets, `%x` atomic
    /// propositions (of the DFA as read, completed), `%m` the automaton's name, `%F` its file,
    /// `%%` a `%`.
    #[arg(long, value_name = "FORMAT", overrides_with_all = ["format", "dot", "hoa"],
          value_parser = |text: &str| Pattern::parse(text, &pattern::with_counts(&STATS)))]
    stats: Option<Pattern>,

    /// Write the output to FILE (all of it, or nothing on error) instead of standard output.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    output: Option<PathBuf>,
}

/// The sequences of `--stats` besides the counts: the automaton's name and file.
const STATS: [(char, Field); 2] = [('m', Field::Name), ('F', Field::File)];

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
enum OutputFormat {
    Stats,
    Dot,
    Hoa,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let mut out = String::new();
    for file in &args.files {
        let shown = if file == "-" { "<stdin>" } else { file };
        let text = read_input(file).with_context(|| shown.to_string())?;
        let automata = hoa::parse(&text)
            .map_err(|errors| super::output::located(&Source::new(shown, &text), &errors))?;
        let format = if args.dot {
            OutputFormat::Dot
        } else if args.hoa {
            OutputFormat::Hoa
        } else {
            args.format
        };
        for (i, automaton) in automata.iter().enumerate() {
            let name = automaton.name.as_deref();
            match (format, &args.stats) {
                (OutputFormat::Dot, _) => out.push_str(
                    &to_dot(&automaton.dfa, name)
                        .with_context(|| format!("{shown}: automaton {}", i + 1))?,
                ),
                (OutputFormat::Hoa, _) => out.push_str(
                    &hoa::write(&minimize(&automaton.dfa), name)
                        .with_context(|| format!("{shown}: automaton {}", i + 1))?,
                ),
                (OutputFormat::Stats, Some(stats)) => {
                    let subject = Subject {
                        dfa: &automaton.dfa,
                        name: name.unwrap_or(""),
                        file,
                        location: i + 1,
                    };
                    let _ = writeln!(out, "{}", stats.expand(&subject));
                }
                (OutputFormat::Stats, None) => {
                    let _ = writeln!(out, "{shown}: automaton {}: {}", i + 1, summary(automaton));
                }
            }
        }
    }
    super::output::write_output(args.output.as_deref(), &out)?;
    Ok(ExitCode::SUCCESS)
}

/// `4 states, 5 edges, 1 AP, 1 final state`, counted on the DFA, with `, completed with a
/// rejecting sink` when the automaton was incomplete.
fn summary(automaton: &HoaAutomaton) -> String {
    let dfa = &automaton.dfa;
    let mut line = format!(
        "{}, {}, {}, {}",
        counted(dfa.num_states(), "state", "states"),
        counted(dfa.num_edges(), "edge", "edges"),
        counted(dfa.aps().len(), "AP", "APs"),
        counted(dfa.finals().iter().count(), "final state", "final states"),
    );
    if automaton.sink.is_some() {
        line.push_str(", completed with a rejecting sink");
    }
    line
}

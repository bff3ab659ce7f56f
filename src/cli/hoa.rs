//! `hypersynth hoa`: read HOA files, validate every automaton in them, and print one summary
//! line per automaton (`stats`), the DOT graphs of their DFAs, or the DFAs written back as one
//! HOA stream (`hoa`: minimised and complete, as `autfilt` normalises). All inputs are read and
//! checked before anything is printed or written, so a failure leaves no partial output.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

use super::io::read_input;
use anyhow::Context;
use hypersynth::automata::dot::to_dot;
use hypersynth::automata::hoa::{self, HoaAutomaton};
use hypersynth::automata::minimize;
use hypersynth::diagnostic::Source;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// HOA files to read (`-` reads standard input); each may hold several automata.
    #[arg(required = true, value_name = "FILE")]
    files: Vec<String>,

    /// What to print for each automaton: a summary line (`stats`), its DFA as a DOT graph
    /// (`dot`), or its minimal complete DFA in HOA (`hoa`), keeping the automaton's name.
    #[arg(long, value_enum, default_value_t = OutputFormat::Stats)]
    output_format: OutputFormat,

    /// Same as `--output-format dot`.
    #[arg(long, conflicts_with = "output_format")]
    dot: bool,

    /// Write the output to FILE (all of it, or nothing on error) instead of standard output.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    output: Option<PathBuf>,
}

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
            .map_err(|errors| super::located(&Source::new(shown, &text), &errors))?;
        let format = if args.dot {
            OutputFormat::Dot
        } else {
            args.output_format
        };
        for (i, automaton) in automata.iter().enumerate() {
            let name = automaton.name.as_deref();
            match format {
                OutputFormat::Dot => out.push_str(
                    &to_dot(&automaton.dfa, name)
                        .with_context(|| format!("{shown}: automaton {}", i + 1))?,
                ),
                OutputFormat::Hoa => out.push_str(
                    &hoa::write(&minimize(&automaton.dfa), name)
                        .with_context(|| format!("{shown}: automaton {}", i + 1))?,
                ),
                OutputFormat::Stats => {
                    let _ = writeln!(out, "{shown}: automaton {}: {}", i + 1, summary(automaton));
                }
            }
        }
    }
    super::write_output(args.output.as_deref(), &out)?;
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

fn counted(n: usize, singular: &str, plural: &str) -> String {
    format!("{n} {}", if n == 1 { singular } else { plural })
}

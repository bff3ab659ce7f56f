//! `hypersynth translate`: co-safe LTL formulas to the minimal complete DFAs of their good
//! prefixes, written as one HOA stream (or DOT graphs, or one `--stats` line per automaton).
//! Formulas come as Spot's tools take them (`-f`, `-F`, see `batch`). Every formula is
//! translated before anything is written: on any error nothing is output. Says on stderr which
//! translator was used.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use anyhow::anyhow;
use hypersynth::automata::{Dfa, dot::to_dot, hoa};
use hypersynth::ltl;
use hypersynth::translate::spot::{self, LTL2TGBA_VARIABLE};
use hypersynth::translate::{DEFAULT_MAX_STATES, Translator, resolve};

use super::batch::{self, FormulaArgs, Input};
use super::choices::TranslatorArg;

#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    inputs: FormulaArgs,

    #[command(flatten)]
    translation: TranslatorArgs,

    /// Write to FILE (atomically: all of it or, on error, nothing) instead of standard output.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    output: Option<PathBuf>,

    /// Write the DFAs as DOT graphs instead of HOA.
    #[arg(long, conflicts_with = "stats")]
    dot: bool,

    /// Instead of the automata, print one line per automaton following FORMAT, as Spot's
    /// tools do: `%s` states, `%e` edges, `%t` transitions (letters), `%a` acceptance sets,
    /// `%x` atomic propositions, `%f` the formula, `%%` a `%`.
    #[arg(long, value_name = "FORMAT", value_parser = parse_stats)]
    stats: Option<Stats>,
}

/// How formulas become DFAs; shared by every command that translates.
#[derive(clap::Args, Debug)]
#[group(id = "translation")]
pub struct TranslatorArgs {
    /// Which translation to use: `auto` runs Spot's ltl2tgba when it is found, the built-in
    /// translation otherwise.
    #[arg(long, value_enum, default_value_t = TranslatorArg::Auto)]
    translator: TranslatorArg,

    /// The ltl2tgba executable [default: $HYPERSYNTH_LTL2TGBA, else ltl2tgba on PATH].
    #[arg(long, value_name = "PATH")]
    ltl2tgba: Option<PathBuf>,

    /// Seconds the translation may take: ltl2tgba is killed after them; the built-in
    /// translation stops after the work they stand for (20 million BDD steps a second, counted,
    /// so the outcome does not depend on the machine).
    #[arg(long, value_name = "SECS", default_value = "60", value_parser = parse_seconds)]
    translator_timeout: Duration,

    /// The most states a translated automaton may have (before minimisation).
    #[arg(long, value_name = "N", default_value_t = DEFAULT_MAX_STATES)]
    max_states: usize,
}

impl TranslatorArgs {
    /// The chosen translator; the environment is read here, not in the library.
    pub fn resolve(&self) -> anyhow::Result<Box<dyn Translator>> {
        let ltl2tgba = spot::locate_ltl2tgba(
            self.ltl2tgba.as_deref(),
            std::env::var_os(LTL2TGBA_VARIABLE).as_deref(),
            std::env::var_os("PATH").as_deref(),
        );
        Ok(resolve(
            self.translator.into(),
            ltl2tgba,
            self.translator_timeout,
            self.max_states,
        )?)
    }
}

fn parse_seconds(text: &str) -> Result<Duration, String> {
    let seconds: f64 = text
        .parse()
        .map_err(|_| format!("`{text}` is not a number of seconds"))?;
    if seconds.is_nan() || seconds <= 0.0 {
        return Err("the timeout must be positive".to_string());
    }
    Duration::try_from_secs_f64(seconds).map_err(|error| error.to_string())
}

pub fn run(args: Args, matches: &clap::ArgMatches) -> anyhow::Result<ExitCode> {
    let inputs = batch::read(&args.inputs, matches)?;
    let translator = args.translation.resolve()?;
    let mut translated = Vec::with_capacity(inputs.len());
    let mut failures = 0;
    for input in &inputs {
        match translate(translator.as_ref(), input) {
            Ok(result) => translated.push(result),
            Err(error) if inputs.len() == 1 => return Err(error),
            Err(error) => {
                super::print_error(format_args!("{error:#}"));
                failures += 1;
            }
        }
    }
    if failures > 0 {
        anyhow::bail!(
            "{failures} of {} formulas could not be translated; nothing was written",
            inputs.len()
        );
    }
    let mut text = String::new();
    for (name, dfa) in &translated {
        match &args.stats {
            Some(stats) => {
                let _ = writeln!(text, "{}", stats.format(name, dfa));
            }
            None if args.dot => text.push_str(&to_dot(dfa, Some(name))),
            None => text.push_str(&hoa::write(dfa, Some(name))?),
        }
    }
    super::write_output(args.output.as_deref(), &text)?;
    if !super::quiet() {
        let states: usize = translated.iter().map(|(_, dfa)| dfa.num_states()).sum();
        match translated.len() {
            1 => eprintln!(
                "hypersynth: translated with {} ({states} states)",
                translator.name()
            ),
            n => eprintln!(
                "hypersynth: translated {n} formulas with {} ({states} states in all)",
                translator.name()
            ),
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// One formula to its DFA, with the formula as hypersynth prints it (the automaton's name).
fn translate(translator: &dyn Translator, input: &Input) -> anyhow::Result<(String, Dfa)> {
    let formula =
        ltl::parse(&input.text).map_err(|errors| super::located(&input.located(), &errors))?;
    let dfa =
        translator
            .translate(&formula)
            .map_err(|error| match error.position(&input.text) {
                Some(position) => input.error_at(position, &error),
                None => anyhow!("{}: {error}", input.source()),
            })?;
    Ok((formula.to_string(), dfa))
}

/// A `--stats` format, parsed when the options are (unknown sequences are usage errors).
#[derive(Clone, Debug)]
pub struct Stats(Vec<Piece>);

/// A piece of a `--stats` format: text, or what a `%` sequence stands for.
#[derive(Clone, Debug)]
enum Piece {
    Text(String),
    States,
    Edges,
    Transitions,
    AcceptanceSets,
    Propositions,
    Formula,
}

fn parse_stats(text: &str) -> Result<Stats, String> {
    if text.is_empty() {
        return Err("empty format string".to_string());
    }
    let mut pieces = Vec::new();
    let mut literal = String::new();
    let mut chars = text.chars();
    while let Some(c) = chars.next() {
        if c != '%' {
            literal.push(c);
            continue;
        }
        let piece = match chars.next() {
            Some('%') => {
                literal.push('%');
                continue;
            }
            Some('s') => Piece::States,
            Some('e') => Piece::Edges,
            Some('t') => Piece::Transitions,
            Some('a') => Piece::AcceptanceSets,
            Some('x') => Piece::Propositions,
            Some('f') => Piece::Formula,
            Some(other) => {
                return Err(format!(
                    "`%{other}` is not supported (use %s %e %t %a %x %f or %%)"
                ));
            }
            None => return Err("the format ends with a lone `%`".to_string()),
        };
        pieces.push(Piece::Text(std::mem::take(&mut literal)));
        pieces.push(piece);
    }
    pieces.push(Piece::Text(literal));
    Ok(Stats(pieces))
}

impl Stats {
    /// The line of one automaton, counted as Spot counts the automata it prints: `%e` the
    /// edges (one per pair of states, as written), `%t` the transitions (one per letter: a
    /// complete DFA has 2^|AP| per state), `%a` the acceptance sets (1: `Inf(0)`).
    fn format(&self, formula: &str, dfa: &Dfa) -> String {
        let mut line = String::new();
        for piece in &self.0 {
            let _ = match piece {
                Piece::Text(text) => write!(line, "{text}"),
                Piece::States => write!(line, "{}", dfa.num_states()),
                Piece::Edges => write!(line, "{}", dfa.num_edges()),
                Piece::Transitions => {
                    write!(line, "{}", (dfa.num_states() as u128) << dfa.aps().len())
                }
                Piece::AcceptanceSets => write!(line, "1"),
                Piece::Propositions => write!(line, "{}", dfa.aps().len()),
                Piece::Formula => write!(line, "{formula}"),
            };
        }
        line
    }
}

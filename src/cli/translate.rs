//! `hypersynth translate`: co-safe LTL formulas to the minimal complete DFAs of their good
//! prefixes, written as one HOA stream (or DOT graphs, or one `--stats` line per automaton), to
//! standard output, one file, or one file per automaton when `-o` holds `%` sequences.
//! Formulas come as Spot's tools take them (`-f`, `-F`, see `batch`). Every formula is
//! translated before anything is written: on any error nothing is output. Says on stderr which
//! translator was used.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Duration;

use anyhow::anyhow;
use hypersynth::automata::{Dfa, dot::to_dot, hoa};
use hypersynth::ltl::{self, Formula};
use hypersynth::pipeline::spec::Translation;
use hypersynth::translate::spot::{self, LTL2TGBA_VARIABLE};
use hypersynth::translate::{
    DEFAULT_MAX_STATES, Limit, TranslateError, TranslationLimits, Translator,
};

use super::batch::{self, FormulaArgs, Input};
use super::choices::TranslatorArg;
use super::pattern::{self, Field, Pattern, Subject};

#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    inputs: FormulaArgs,

    #[command(flatten)]
    translation: TranslatorArgs,

    #[command(flatten)]
    memory: super::memory::Args,

    /// Write to FILE (atomically: all of it or, on error, nothing) instead of standard output.
    /// FILE may hold Spot's `%` sequences (those of --stats, and `%F` the input file, `%L` the
    /// formula's line in it): each automaton then goes to the file its sequences name
    /// (`-o 'phi%L.hoa'`), automata naming one file one after another in it.
    #[arg(short = 'o', long = "output", value_name = "FILE", value_parser = parse_output)]
    output: Option<Pattern>,

    /// Write the DFAs as DOT graphs instead of HOA. The last of -d, -H and --stats counts, as
    /// in Spot.
    #[arg(short = 'd', long, overrides_with_all = ["hoa", "stats"])]
    dot: bool,

    /// Write the DFAs in HOA (the default).
    #[arg(short = 'H', long, overrides_with_all = ["dot", "stats"])]
    hoa: bool,

    /// Instead of the automata, print one line per automaton following FORMAT, as Spot's
    /// tools do: `%s` states, `%e` edges, `%t` transitions (letters), `%a` acceptance sets,
    /// `%x` atomic propositions, `%f` the formula, `%F` the input file, `%L` the formula's line
    /// in it (or N for the Nth formula given directly), `%%` a `%`.
    #[arg(long, value_name = "FORMAT", overrides_with_all = ["dot", "hoa"],
          value_parser = |text: &str| Pattern::parse(text, &pattern::with_counts(&OUTPUT)))]
    stats: Option<Pattern>,
}

/// The sequences of `--stats` and `-o` besides the counts: the formula and where it came from.
const OUTPUT: [(char, Field); 3] = [
    ('f', Field::Name),
    ('F', Field::File),
    ('L', Field::Location),
];

/// `-o FILE`: a pattern of file names. Spot's `>>FILE` (append) is refused rather than taken
/// as a name: every output is written whole, atomically.
fn parse_output(text: &str) -> Result<Pattern, String> {
    if text.starts_with(">>") {
        return Err("`>>` (append, in Spot) is not supported: each file is written whole".into());
    }
    Pattern::parse(text, &pattern::with_counts(&OUTPUT))
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

    /// Seconds of wall-clock time the translation may take (`translate`: each formula; the
    /// main form: all its formulas together), minimisation included: ltl2tgba is killed at
    /// them, the built-in translation stops within a few milliseconds of them.
    #[arg(long, value_name = "SECS", default_value = "60", value_parser = parse_seconds)]
    translator_timeout: Duration,

    /// The most states a translated automaton may have before minimisation; the built-in
    /// translation also allows 8 BDD nodes and 4 edges per state.
    #[arg(long, value_name = "N", default_value_t = DEFAULT_MAX_STATES)]
    max_states: usize,
}

impl TranslatorArgs {
    /// The translation the options choose, as the library's specification: ltl2tgba found
    /// here (the environment is read here, not in the library), the memory what the run's
    /// ceiling leaves now, the time limit starting when the translator is made.
    pub fn translation(&self) -> Translation {
        let ltl2tgba = spot::locate_ltl2tgba(
            self.ltl2tgba.as_deref(),
            std::env::var_os(LTL2TGBA_VARIABLE).as_deref(),
            std::env::var_os("PATH").as_deref(),
        );
        // Work is not counted: the deadline bounds the time, and the counted limits the size.
        let limits = TranslationLimits::new(self.max_states, u64::MAX)
            .with_max_bytes(super::memory::available());
        Translation {
            choice: self.translator.into(),
            ltl2tgba,
            limits,
            timeout: Some(self.translator_timeout),
        }
    }

    /// The chosen translator, its time limit starting now, its limit errors [`noted`].
    pub fn resolve(&self) -> anyhow::Result<Box<dyn Translator>> {
        let translator = self.translation().translator()?;
        Ok(Box::new(Noted(translator)))
    }
}

/// A translator whose limit errors end with the option that raises the limit.
struct Noted(Box<dyn Translator>);

impl Translator for Noted {
    fn name(&self) -> &str {
        self.0.name()
    }

    fn translate(&self, formula: &Formula) -> Result<Dfa, TranslateError> {
        self.0.translate(formula).map_err(noted)
    }
}

/// A translation error whose limit, if one stopped it, ends with the option that raises it.
pub fn noted(error: TranslateError) -> TranslateError {
    match error {
        TranslateError::Limit(mut error) => {
            error.note = match error.limit {
                Limit::States(_) => Some("raise it with --max-states".to_string()),
                Limit::Nodes(_) => {
                    Some("8 per state of --max-states: raise that to raise it".to_string())
                }
                Limit::Edges(_) => {
                    Some("4 per state of --max-states: raise that to raise it".to_string())
                }
                Limit::Bytes(_) => Some(super::memory::raise_note()),
                Limit::Time(_) => Some("raise it with --translator-timeout".to_string()),
                Limit::Steps(_) => None,
            };
            TranslateError::Limit(error)
        }
        other => other,
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
    args.memory.install();
    let inputs = batch::read(&args.inputs, matches)?;
    let mut translator_name = String::new();
    let mut translated = Vec::with_capacity(inputs.len());
    let mut failures = 0;
    for input in &inputs {
        // Each formula has the whole time limit, and what memory the others left.
        let translator = args.translation.resolve()?;
        translator_name = translator.name().to_string();
        match translate(translator.as_ref(), input) {
            Ok(result) => translated.push(result),
            Err(error) if inputs.len() == 1 => return Err(error),
            Err(error) => {
                super::output::print_error(format_args!("{error:#}"));
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
    // Each output file's text, in the order the files are first named (`None`: stdout).
    let mut outputs: Vec<(Option<String>, String)> = Vec::new();
    let mut index: HashMap<Option<String>, usize> = HashMap::new();
    for (input, (name, dfa)) in inputs.iter().zip(&translated) {
        let subject = Subject {
            dfa,
            name,
            file: input.file.as_deref().unwrap_or(""),
            location: input.location,
        };
        // -d, -H and --stats override each other: at most one is set.
        let text = match &args.stats {
            Some(stats) => stats.expand(&subject) + "\n",
            None if args.dot && !args.hoa => to_dot(dfa, Some(name))?,
            None => hoa::write(dfa, Some(name))?,
        };
        let file = args.output.as_ref().map(|pattern| pattern.expand(&subject));
        let slot = *index.entry(file.clone()).or_insert_with(|| {
            outputs.push((file, String::new()));
            outputs.len() - 1
        });
        outputs[slot].1.push_str(&text);
    }
    // No formula (a file of comments) still creates a named output, empty.
    if outputs.is_empty()
        && let Some(file) = args.output.as_ref().and_then(Pattern::as_literal)
    {
        outputs.push((Some(file), String::new()));
    }
    for (file, text) in &outputs {
        super::output::write_output(file.as_deref().map(Path::new), text)?;
    }
    if !super::output::quiet() {
        let states: usize = translated.iter().map(|(_, dfa)| dfa.num_states()).sum();
        match translated.len() {
            1 => eprintln!("hypersynth: translated with {translator_name} ({states} states)"),
            n => eprintln!(
                "hypersynth: translated {n} formulas with {translator_name} ({states} states in \
                 all)"
            ),
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// One formula to its DFA, with the formula as hypersynth prints it (the automaton's name).
fn translate(translator: &dyn Translator, input: &Input) -> anyhow::Result<(String, Dfa)> {
    let formula = ltl::parse(&input.text)
        .map_err(|errors| super::output::located(&input.located(), &errors))?;
    let dfa =
        translator
            .translate(&formula)
            .map_err(|error| match error.position(&input.text) {
                Some(position) => input.error_at(position, &error),
                None => anyhow!("{}: {error}", input.source()),
            })?;
    Ok((formula.to_string(), dfa))
}

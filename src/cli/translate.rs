//! `hypersynth translate`: a co-safe LTL formula to the minimal complete DFA of its good
//! prefixes, written as HOA (or DOT). Says on stderr which translator was used.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use anyhow::anyhow;
use hypersynth::automata::{dot::to_dot, hoa};
use hypersynth::ltl::{self, caret_context};
use hypersynth::position::Position;
use hypersynth::translate::spot::{self, LTL2TGBA_VARIABLE};
use hypersynth::translate::{
    DEFAULT_MAX_STATES, TranslateError, Translator, TranslatorChoice, resolve,
};

#[derive(clap::Args, Debug)]
pub struct Args {
    /// The formula, in Spot's LTL syntax; it must be syntactically co-safe.
    #[arg(value_name = "FORMULA")]
    formula: String,

    #[command(flatten)]
    translation: TranslatorArgs,

    /// Write to FILE (atomically: all of it or, on error, nothing) instead of standard output.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    output: Option<PathBuf>,

    /// Write the DFA as a DOT graph instead of HOA.
    #[arg(long)]
    dot: bool,

    /// Do not say on standard error which translator was used.
    #[arg(short, long)]
    quiet: bool,
}

/// How formulas become DFAs; shared by every command that translates.
#[derive(clap::Args, Debug)]
#[group(id = "translation")]
pub struct TranslatorArgs {
    /// Which translation to use: `auto` runs Spot's ltl2tgba when it is found, the built-in
    /// translation otherwise.
    #[arg(long, value_enum, default_value_t = TranslatorChoice::Auto)]
    translator: TranslatorChoice,

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
            self.translator,
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

/// Where errors in the formula are located, as `hypersynth ltl` names its arguments.
const ORIGIN: &str = "argument 1";

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let formula = ltl::parse(&args.formula).map_err(|error| {
        anyhow!(
            "{ORIGIN}:{}: {}\n{}",
            error.position,
            error.message,
            error.context()
        )
    })?;
    let translator = args.translation.resolve()?;
    let dfa = translator
        .translate(&formula)
        .map_err(|error| match error {
            TranslateError::NotCoSafe(error) => {
                located(&args.formula, error.position(&args.formula), &error)
            }
            other => anyhow!("{ORIGIN}: {other}"),
        })?;
    let name = formula.to_string();
    let text = if args.dot {
        to_dot(&dfa, Some(&name))
    } else {
        hoa::write(&dfa, Some(&name))?
    };
    super::write_output(args.output.as_deref(), &text)?;
    if !args.quiet {
        eprintln!(
            "hypersynth: translated with {} ({} states)",
            translator.name(),
            dfa.num_states()
        );
    }
    Ok(ExitCode::SUCCESS)
}

/// `argument 1:LINE:COL: MESSAGE` and a caret under the column of `text`.
fn located(text: &str, position: Position, message: &dyn std::fmt::Display) -> anyhow::Error {
    let line = text.lines().nth(position.line - 1).unwrap_or_default();
    anyhow!(
        "{ORIGIN}:{position}: {message}\n{}",
        caret_context(line, position.column)
    )
}

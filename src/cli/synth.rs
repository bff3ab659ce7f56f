//! The main form: `hypersynth --phi PHI --psi PSI ARENA`, or with automata for the tasks:
//! `hypersynth --phi1-hoa FILE --phi2-hoa FILE ARENA` (or one file and one formula).
//!
//! Parses the formulas, splits `phi` into `phi1 = psi` and `phi2`, translates both (options
//! shared with `translate`), or reads the tasks' DFAs from HOA files (minimised, so that a file
//! `translate` wrote gives exactly the formula's DFA); reads the arena (or map), builds and
//! solves the hypergame, draws the `--svg` picture if asked, then (unless `--games-only`)
//! builds and solves the hypergame MDP, and prints the report. Errors in a formula are located as `--phi:LINE:COL` (or `--psi`, `--phi2`) with a
//! caret under the text; errors in a HOA file as `FILE:LINE:COL`.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context as _, anyhow};
use hypersynth::automata::{Dfa, hoa, minimize};
use hypersynth::game::{Hypergame, Operand, States, WinningRegions, split_task};
use hypersynth::ltl::{self, Formula, caret_context};
use hypersynth::mdp::build::Payoffs;
use hypersynth::position::Position;
use hypersynth::report::{GamesReport, StrategyExport, TaskAutomaton};
use hypersynth::stage::{Stage, Timings, timed};
use hypersynth::translate::Translator;

/// The main form's options.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The robot's task, a co-safe LTL formula `phi1 & phi2`.
    #[arg(long, value_name = "PHI")]
    pub phi: Option<String>,
    /// The task the adversary believes the robot has (`phi1`): one or several conjuncts of PHI.
    #[arg(long, value_name = "PSI")]
    pub psi: Option<String>,
    /// The rest of PHI (`phi2`) [default: the conjuncts of PHI not in PSI]; PSI and PHI2
    /// together must give exactly PHI's conjuncts.
    #[arg(long, value_name = "PHI2")]
    pub phi2: Option<String>,
    /// Read phi1 (what the adversary believes the task is) from FILE, a DFA of good prefixes
    /// in HOA (`-` for standard input), instead of giving --psi; phi is phi1 & phi2.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["psi", "phi"])]
    pub phi1_hoa: Option<String>,
    /// Read phi2 from FILE, a DFA of good prefixes in HOA (`-` for standard input), instead of
    /// giving --phi2; phi is phi1 & phi2.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["phi2", "phi"])]
    pub phi2_hoa: Option<String>,
    /// The arena file (`-` for standard input).
    #[arg(value_name = "ARENA", required = true)]
    pub arena: Option<String>,
    /// Write the report to FILE (atomically: all of it or, on error, nothing) instead of
    /// standard output.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Stop after the hypergame: print its report (sizes, winning regions, win-labels).
    #[arg(long)]
    pub games_only: bool,
    /// Which product states to enumerate: every configuration, or those reachable from h0.
    #[arg(long, value_enum, default_value_t = States::Full)]
    pub states: States,
    /// How to print the report.
    #[arg(long, value_enum, default_value_t = Format::Text)]
    pub format: Format,
    /// Report the seconds spent in each stage: a `stats:` line on standard error, and with
    /// `--format json` a `timings` object in the report (paper form).
    #[arg(long)]
    pub stats: bool,
    /// Also write the reactive strategies (both players, three tasks) as JSON to FILE.
    #[arg(long, value_name = "FILE")]
    pub export_strategy: Option<PathBuf>,
    #[command(flatten)]
    pub translation: super::translate::TranslatorArgs,
    /// The opportunistic stage's options (ignored with --games-only).
    #[command(flatten)]
    pub mdp: super::opportunistic::Args,
    /// Beyond the paper: named sub-tasks, payoffs on sets of them, any believed task.
    #[command(flatten)]
    pub general: super::subtasks::Args,
    #[command(flatten)]
    pub render: super::render::Args,
}

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Text,
    Json,
}

/// A formula with the text it was parsed from and the option that gave it, for locating errors.
pub(super) struct Source<'a> {
    pub(super) option: &'a str,
    pub(super) text: &'a str,
}

impl Source<'_> {
    /// `--option:LINE:COL: message` and a caret under the column.
    pub(super) fn error_at(
        &self,
        position: Position,
        message: &dyn std::fmt::Display,
    ) -> anyhow::Error {
        let line = self
            .text
            .lines()
            .nth(position.line.saturating_sub(1))
            .unwrap_or_default();
        anyhow!(
            "{}:{position}: {message}\n{}",
            self.option,
            caret_context(line, position.column)
        )
    }

    pub(super) fn parse(&self) -> anyhow::Result<Formula> {
        ltl::parse(self.text).map_err(|e| self.error_at(e.position, &e.message))
    }

    pub(super) fn translate(
        &self,
        translator: &dyn Translator,
        formula: &Formula,
    ) -> anyhow::Result<Dfa> {
        translator
            .translate(formula)
            .map_err(|error| match error.position(self.text) {
                Some(position) => self.error_at(position, &error),
                None => anyhow!("{}: {error}", self.option),
            })
    }
}

impl Args {
    /// What clap cannot say about the main form's options: which task is missing, and inputs
    /// that would read standard input twice. The message of a usage error (exit status 2).
    pub fn check_usage(&self) -> Result<(), String> {
        if self.general.is_active() {
            return self.general.check_usage(self.arena.as_deref());
        }
        if let Some(option) = self.general.stray_option() {
            return Err(format!(
                "{option} belongs to the general form: give the sub-tasks with --task NAME=FORMULA \
                 or --task-hoa NAME=FILE"
            ));
        }
        let from_files = self.phi1_hoa.is_some() || self.phi2_hoa.is_some();
        if !from_files && self.phi.is_none() {
            return Err(
                "the robot's task is missing: give --phi PHI (with --psi PSI), or the \
                 tasks' automata with --phi1-hoa FILE and --phi2-hoa FILE"
                    .to_string(),
            );
        }
        if self.psi.is_none() && self.phi1_hoa.is_none() {
            return Err(
                "--psi PSI is missing: the task the adversary believes the robot has \
                 (phi1), one or several conjuncts of PHI (or give --phi1-hoa FILE)"
                    .to_string(),
            );
        }
        if from_files && self.phi2.is_none() && self.phi2_hoa.is_none() {
            return Err(
                "phi2 is missing: with --phi1-hoa or --phi2-hoa, give the other task \
                 as --phi2 PHI2 or --phi2-hoa FILE (--psi for phi1)"
                    .to_string(),
            );
        }
        let stdin_readers = [&self.phi1_hoa, &self.phi2_hoa, &self.arena]
            .into_iter()
            .filter(|input| input.as_deref() == Some("-"))
            .count();
        if stdin_readers > 1 {
            return Err(
                "only one of ARENA, --phi1-hoa and --phi2-hoa can be `-` (standard \
                 input)"
                    .to_string(),
            );
        }
        Ok(())
    }
}

/// A task's DFA and how the report names it: its formula, or the HOA file it was read from.
pub(super) struct Task {
    pub(super) name: String,
    pub(super) dfa: Dfa,
    pub(super) translator: String,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    args.check_usage().map_err(|message| anyhow!(message))?;
    if args.general.is_active() {
        let text = super::subtasks::run(&args)?;
        super::write_output(args.output.as_deref(), &text)?;
        return Ok(ExitCode::SUCCESS);
    }
    let mut progress = super::progress::Progress::new();
    let (phi, task1, task2) = timed(&mut progress, Stage::Translate, || {
        if args.phi1_hoa.is_some() || args.phi2_hoa.is_some() {
            tasks_from_files(&args)
        } else {
            tasks_from_formulas(&args)
        }
    })?;
    let text = paper_report(&args, &phi, [&task1, &task2], None, &mut progress)?;
    super::write_output(args.output.as_deref(), &text)?;
    if args.stats && args.format == Format::Text {
        eprintln!("hypersynth: {}", progress.stats_line());
    }
    Ok(ExitCode::SUCCESS)
}

/// The paper's form (DESIGN.md 3.4-3.6) on its two tasks: the games report, or the opportunistic
/// one, as text or JSON; the payoffs are `--r1`, `--r2`, `--r` unless given. Every stage runs
/// under `progress`.
pub(super) fn paper_report(
    args: &Args,
    phi: &str,
    [task1, task2]: [&Task; 2],
    payoffs: Option<Payoffs>,
    progress: &mut super::progress::Progress,
) -> anyhow::Result<String> {
    let arena_file = args.arena.as_deref().unwrap_or("-");
    let input = timed(progress, Stage::Parse, || {
        super::arena::load_input(arena_file)
    })?;
    let game = timed(progress, Stage::Product, || {
        Hypergame::new(&input.arena, &task1.dfa, &task2.dfa, args.states)
    })?;
    for proposition in game.missing_propositions() {
        super::warn(format_args!(
            "proposition `{proposition}` is carried by no state of {arena_file}: it is always \
             false"
        ));
    }
    let regions = timed(progress, Stage::Attractors, || {
        WinningRegions::compute(&game)
    });
    if let Some(path) = &args.export_strategy {
        let json = serde_json::to_vec_pretty(&StrategyExport::new(&game, &regions))?;
        hypersynth::io::write_atomically(path, &json)
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    let payoffs = match payoffs {
        Some(payoffs) => payoffs,
        None => Payoffs::new(args.mdp.r1, args.mdp.r2, args.mdp.r)?,
    };
    let subject = super::render::Subject {
        arena_file,
        map: input.map.as_ref(),
        game: &game,
        regions: &regions,
        formulas: [phi, &task1.name, &task2.name],
    };
    super::render::run(
        &args.render,
        &subject,
        (!args.games_only).then_some((&args.mdp, payoffs)),
    )?;
    let automata = [task1, task2].map(|task| TaskAutomaton {
        formula: &task.name,
        dfa: &task.dfa,
        translator: &task.translator,
    });
    let games = GamesReport::new(phi, automata, &game, &regions);
    Ok(match (args.games_only, args.format) {
        (true, Format::Text) => games.to_string(),
        (true, Format::Json) => json_text(
            serde_json::to_value(&games)?,
            args.stats.then_some(&progress.timings),
        )?,
        (false, format) => {
            let report =
                super::opportunistic::run(&args.mdp, payoffs, &game, &regions, games, progress)?;
            match format {
                Format::Text => report.to_string(),
                Format::Json => {
                    json_text(report.to_json(), args.stats.then_some(&progress.timings))?
                }
            }
        }
    })
}

/// A JSON report as text, with the stage timings added under `timings` when given (only with
/// `--stats`: without it the same inputs give byte-identical reports).
fn json_text(mut value: serde_json::Value, timings: Option<&Timings>) -> anyhow::Result<String> {
    if let (Some(timings), serde_json::Value::Object(map)) = (timings, &mut value) {
        map.insert("timings".into(), serde_json::to_value(timings)?);
    }
    Ok(serde_json::to_string_pretty(&value)? + "\n")
}

/// `--phi PHI --psi PSI [--phi2 PHI2]`: phi split into its conjuncts, both parts translated.
fn tasks_from_formulas(args: &Args) -> anyhow::Result<(String, Task, Task)> {
    let (Some(phi_text), Some(psi_text)) = (&args.phi, &args.psi) else {
        anyhow::bail!("the main form needs --phi PHI and --psi PSI");
    };
    let phi_source = Source {
        option: "--phi",
        text: phi_text,
    };
    let psi_source = Source {
        option: "--psi",
        text: psi_text,
    };
    let phi2_source = args.phi2.as_deref().map(|text| Source {
        option: "--phi2",
        text,
    });
    let phi = phi_source.parse()?;
    let psi = psi_source.parse()?;
    let explicit_phi2 = phi2_source.as_ref().map(Source::parse).transpose()?;
    let split = split_task(&phi, &psi, explicit_phi2.as_ref()).map_err(|error| {
        let source = match error.operand() {
            Operand::Phi => &phi_source,
            Operand::Psi => &psi_source,
            Operand::Phi2 => phi2_source.as_ref().unwrap_or(&phi_source),
        };
        source.error_at(Position::of_offset(source.text, error.span().start), &error)
    })?;
    // phi2's subformulas come from --phi2 when given, else from --phi itself.
    let phi2_origin = phi2_source.as_ref().unwrap_or(&phi_source);

    let translator = args.translation.resolve()?;
    let task = |source: &Source, formula: &Formula| -> anyhow::Result<Task> {
        Ok(Task {
            name: formula.to_string(),
            dfa: source.translate(translator.as_ref(), formula)?,
            translator: translator.name().to_string(),
        })
    };
    let task1 = task(&psi_source, &split.phi1)?;
    let task2 = task(phi2_origin, &split.phi2)?;
    Ok((split.phi.to_string(), task1, task2))
}

/// `--phi1-hoa FILE` or `--psi PSI`, with `--phi2-hoa FILE` or `--phi2 PHI2`: each task on its
/// own; phi is their conjunction, named after the files and formulas.
fn tasks_from_files(args: &Args) -> anyhow::Result<(String, Task, Task)> {
    let mut translator = None;
    let mut task =
        |file: &Option<String>, formula: &Option<String>, option| -> anyhow::Result<Task> {
            if let Some(file) = file {
                return read_task(file);
            }
            let Some(text) = formula else {
                anyhow::bail!("{option} is missing");
            };
            let source = Source { option, text };
            let formula = source.parse()?;
            let translator: &dyn Translator = match &translator {
                Some(translator) => translator,
                None => translator.insert(args.translation.resolve()?),
            }
            .as_ref();
            Ok(Task {
                name: formula.to_string(),
                dfa: source.translate(translator, &formula)?,
                translator: translator.name().to_string(),
            })
        };
    let task1 = task(&args.phi1_hoa, &args.psi, "--psi")?;
    let task2 = task(&args.phi2_hoa, &args.phi2, "--phi2")?;
    let operand = |task: &Task, file: &Option<String>| {
        if file.is_some() {
            task.name.clone()
        } else {
            format!("({})", task.name)
        }
    };
    let phi = format!(
        "{} & {}",
        operand(&task1, &args.phi1_hoa),
        operand(&task2, &args.phi2_hoa)
    );
    Ok((phi, task1, task2))
}

/// The one automaton of a HOA file, read as a DFA of good prefixes and minimised; the report
/// names it after the file (`<stdin>` for `-`).
pub(super) fn read_task(file: &str) -> anyhow::Result<Task> {
    let shown = if file == "-" { "<stdin>" } else { file };
    let text = hypersynth::io::read_input(file).with_context(|| format!("{shown}: cannot read"))?;
    let automata = hoa::parse(&text).map_err(|error| anyhow!("{shown}:{error}"))?;
    let [automaton] = automata.as_slice() else {
        anyhow::bail!("{shown}: expected one automaton, found {}", automata.len());
    };
    Ok(Task {
        name: shown.to_string(),
        dfa: minimize(&automaton.dfa),
        translator: "hoa".to_string(),
    })
}

//! The main form: `hypersynth --phi PHI --psi PSI ARENA`, or with automata for the tasks:
//! `hypersynth --phi1-hoa FILE --phi2-hoa FILE ARENA` (or one file and one formula).
//!
//! Parses the formulas, splits `phi` into `phi1 = psi` and `phi2`, translates both (options
//! shared with `translate`), or reads the tasks' DFAs from HOA files (minimised, so that a file
//! `translate` wrote gives exactly the formula's DFA); reads the arena (or map), builds and
//! solves the hypergame, draws the `--svg` picture if asked, then (unless `--games-only`)
//! builds and solves the hypergame MDP, and prints the report. Errors in a formula are located
//! as `--phi:LINE:COL` (or `--psi`, `--phi2`), errors in a HOA file as `FILE:LINE:COL`, each
//! with the line and a caret under the column.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context as _, anyhow};
use hypersynth::automata::hoa;
use hypersynth::diagnostic;
use hypersynth::game::Operand;
use hypersynth::game::Payoffs;
use hypersynth::ltl::{self, Formula};
use hypersynth::pipeline::{
    self, ExplorerError, PictureError, PipelineError, Problem, Requests, Task, Tasks, TasksError,
};
use hypersynth::position::Position;
use hypersynth::stage::{Stage, metered, timed};
use hypersynth::translate::{TranslateError, Translator};

use super::choices::StatesArg;

/// The main form's options.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The robot's task, a co-safe LTL formula `phi1 & phi2`.
    #[arg(help_heading = "Tasks (the paper's form)", long, value_name = "PHI")]
    pub phi: Option<String>,
    /// The task the adversary believes the robot has (`phi1`): one or several conjuncts of PHI.
    #[arg(help_heading = "Tasks (the paper's form)", long, value_name = "PSI")]
    pub psi: Option<String>,
    /// The rest of PHI (`phi2`) [default: the conjuncts of PHI not in PSI]; PSI and PHI2
    /// together must give exactly PHI's conjuncts.
    #[arg(help_heading = "Tasks (the paper's form)", long, value_name = "PHI2")]
    pub phi2: Option<String>,
    /// Read phi1 (what the adversary believes the task is) from FILE, a DFA of good prefixes
    /// in HOA (`-` for standard input), instead of giving --psi; phi is phi1 & phi2.
    #[arg(help_heading = "Tasks (the paper's form)", long, value_name = "FILE", conflicts_with_all = ["psi", "phi"])]
    pub phi1_hoa: Option<String>,
    /// Read phi2 from FILE, a DFA of good prefixes in HOA (`-` for standard input), instead of
    /// giving --phi2; phi is phi1 & phi2.
    #[arg(help_heading = "Tasks (the paper's form)", long, value_name = "FILE", conflicts_with_all = ["phi2", "phi"])]
    pub phi2_hoa: Option<String>,
    /// The arena file (`-` for standard input).
    #[arg(value_name = "ARENA", required = true)]
    pub arena: Option<String>,
    /// Beyond the paper: named sub-tasks, payoffs on sets of them, any believed task.
    #[command(
        flatten,
        next_help_heading = "Tasks beyond the paper (k named sub-tasks)"
    )]
    pub general: super::subtasks::Args,
    #[command(flatten, next_help_heading = "Translation")]
    pub translation: super::translate::TranslatorArgs,
    /// Stop after the hypergame: print its report (sizes, winning regions, win-labels).
    #[arg(help_heading = "Arena and games", long)]
    pub games_only: bool,
    /// Which product states to enumerate: every configuration, or those reachable from h0.
    #[arg(help_heading = "Arena and games", long, value_enum, default_value_t = StatesArg::Full)]
    pub states: StatesArg,
    /// The opportunistic stage's options (ignored with --games-only).
    #[command(flatten)]
    pub mdp: super::opportunistic::Args,
    /// Write the report to FILE (atomically: all of it or, on error, nothing) instead of
    /// standard output.
    #[arg(
        help_heading = "Output",
        short = 'o',
        long = "output",
        value_name = "FILE"
    )]
    pub output: Option<PathBuf>,
    /// How to print the report.
    #[arg(help_heading = "Output", long, value_enum, default_value_t = Format::Text)]
    pub format: Format,
    /// Report the seconds spent in each stage: a `timings:` line on standard error, and with
    /// `--format json` a `timings` object in the report.
    #[arg(help_heading = "Output", long)]
    pub timings: bool,
    /// Also write the reactive strategies as JSON to FILE: both players', for the three tasks
    /// (general form: for every set of sub-tasks, and psi).
    #[arg(help_heading = "Output", long, value_name = "FILE")]
    pub export_strategy: Option<PathBuf>,
    #[command(flatten, next_help_heading = "Pictures (of a map)")]
    pub render: super::render::Args,
    #[command(flatten, next_help_heading = "Limits")]
    pub memory: super::memory::Args,
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
    /// The text as errors locate it: `--option:LINE:COL`.
    fn located(&self) -> diagnostic::Source<'_> {
        diagnostic::Source::new(self.option, self.text)
    }

    /// `--option:LINE:COL: message` and a caret under the column.
    pub(super) fn error_at(
        &self,
        position: Position,
        message: &dyn std::fmt::Display,
    ) -> anyhow::Error {
        super::located_at(&self.located(), position, message)
    }

    pub(super) fn parse(&self) -> anyhow::Result<Formula> {
        ltl::parse(self.text).map_err(|errors| super::located(&self.located(), &errors))
    }

    /// A translation error of this formula (or of a part of it), located when it can be.
    pub(super) fn translate_error(&self, error: TranslateError) -> anyhow::Error {
        match error.position(self.text) {
            Some(position) => self.error_at(position, &error),
            None => anyhow!("{}: {error}", self.option),
        }
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

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    args.check_usage().map_err(|message| anyhow!(message))?;
    let mut progress = super::progress::Progress::new();
    let tasks = timed(&mut progress, Stage::Translate, || {
        if args.general.is_active() {
            super::subtasks::tasks(&args)
        } else if args.phi1_hoa.is_some() || args.phi2_hoa.is_some() {
            tasks_from_files(&args)
        } else {
            tasks_from_formulas(&args)
        }
    })?;
    let arena_file = args.arena.as_deref().unwrap_or("-");
    let input = metered(&mut progress, Stage::Parse, |meter| {
        super::arena::load_input(arena_file, meter)
    })?;
    let mdp = match args.games_only {
        true => None,
        false => Some(super::opportunistic::options(&args.mdp, &input.arena)?),
    };
    let problem = Problem {
        arena_name: arena_file.to_string(),
        arena: input.arena,
        map: input.map,
        tasks,
        states: args.states.into(),
        mdp,
    };
    let requests = Requests {
        export_strategy: args.export_strategy.is_some(),
        picture: args.render.request(),
        html: args.render.html.is_some(),
        ..super::opportunistic::requests(&args.mdp, args.render.title())
    };
    let outcome =
        pipeline::run(&problem, &requests, &mut progress).map_err(|error| match error {
            PipelineError::Explain(error) => super::opportunistic::explain_error(&args.mdp, error),
            PipelineError::Stage(error) => super::opportunistic::stage_error(&args.mdp, error),
            PipelineError::Picture(error @ PictureError::NotAMap) => {
                anyhow!(
                    "{}: {}: {error}",
                    problem.arena_name,
                    args.render.file_flag()
                )
            }
            PipelineError::Picture(PictureError::NeedsMdp) => anyhow!(
                "--picture {}: the value and trace pictures need the opportunistic stage: \
                 drop --games-only",
                args.render.picture_name()
            ),
            PipelineError::Explorer(error @ ExplorerError::NotAMap) => {
                anyhow!("{}: --html: {error}", problem.arena_name)
            }
            error @ PipelineError::CurveWithoutObservations => {
                anyhow!("--learning-curve: {error}: drop --games-only")
            }
            other => other.into(),
        })?;
    let outputs = [
        (&args.export_strategy, &outcome.strategy),
        (&args.render.svg, &outcome.svg),
        (&args.mdp.export_mdp, &outcome.drn),
        (&args.mdp.export_controller, &outcome.controller),
        (&args.mdp.record, &outcome.record),
        (&args.render.html, &outcome.html),
        (&args.mdp.learning_curve, &outcome.curve_svg),
    ];
    for (path, text) in outputs {
        if let (Some(path), Some(text)) = (path, text) {
            super::io::write_atomically(path, text.as_bytes())
                .with_context(|| format!("cannot write {}", path.display()))?;
        }
    }
    args.render.write_png(outcome.svg.as_deref())?;
    args.render.write_png_to(
        args.mdp.learning_curve_png.as_ref(),
        outcome.curve_svg.as_deref(),
    )?;
    let text = match args.format {
        Format::Text => outcome.report.to_string(),
        Format::Json => outcome
            .report
            .to_json(args.timings.then_some(&progress.timings))?,
    };
    super::write_output(args.output.as_deref(), &text)?;
    if args.timings && args.format == Format::Text {
        eprintln!("hypersynth: {}", progress.timings_line());
    }
    Ok(ExitCode::SUCCESS)
}

/// The paper's payoffs `--r1`, `--r2`, `--r` (checked only when the MDP stage runs: the games
/// do not need them).
fn paper_payoffs(args: &Args) -> anyhow::Result<Payoffs> {
    let mdp = &args.mdp;
    match Payoffs::new(mdp.r1, mdp.r2, mdp.r) {
        Ok(payoffs) => Ok(payoffs),
        Err(_) if args.games_only => Ok(Payoffs::default()),
        Err(error) => Err(error.into()),
    }
}

/// `--phi PHI --psi PSI [--phi2 PHI2]`: phi split into its conjuncts, both parts translated.
fn tasks_from_formulas(args: &Args) -> anyhow::Result<Tasks> {
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
    let translator = args.translation.resolve()?;
    let source = |operand| match operand {
        Operand::Phi => &phi_source,
        Operand::Psi => &psi_source,
        Operand::Phi2 => phi2_source.as_ref().unwrap_or(&phi_source),
    };
    let payoffs = paper_payoffs(args)?;
    Tasks::from_formulas(
        &phi,
        &psi,
        explicit_phi2.as_ref(),
        translator.as_ref(),
        payoffs,
    )
    .map_err(|error| match error {
        TasksError::Split(error) => {
            let source = source(error.operand());
            source.error_at(Position::of_offset(source.text, error.span().start), &error)
        }
        TasksError::Translate { operand, error } => source(operand).translate_error(error),
    })
}

/// `--phi1-hoa FILE` or `--psi PSI`, with `--phi2-hoa FILE` or `--phi2 PHI2`: each task on its
/// own; phi is their conjunction.
fn tasks_from_files(args: &Args) -> anyhow::Result<Tasks> {
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
            Task::from_formula(formula, translator).map_err(|e| source.translate_error(e))
        };
    let phi1 = task(&args.phi1_hoa, &args.psi, "--psi")?;
    let phi2 = task(&args.phi2_hoa, &args.phi2, "--phi2")?;
    Ok(Tasks::from_parts(phi1, phi2, paper_payoffs(args)?))
}

/// The one automaton of a HOA file, read as a DFA of good prefixes and minimised; the report
/// names it after the file (`<stdin>` for `-`).
pub(super) fn read_task(file: &str) -> anyhow::Result<Task> {
    let shown = if file == "-" { "<stdin>" } else { file };
    let text = super::io::read_input(file).with_context(|| format!("{shown}: cannot read"))?;
    let automata = hoa::parse(&text)
        .map_err(|errors| super::located(&diagnostic::Source::new(shown, &text), &errors))?;
    let [automaton] = automata.as_slice() else {
        anyhow::bail!("{shown}: expected one automaton, found {}", automata.len());
    };
    Ok(Task::from_automaton(shown, &automaton.dfa))
}

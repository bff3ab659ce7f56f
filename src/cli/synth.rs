//! The main form: `hypersynth --phi PHI --psi PSI ARENA`, the tasks' automata instead of
//! formulas (`--phi1-hoa FILE --phi2-hoa FILE`), or named sub-tasks (`--task NAME=FORMULA`...).
//!
//! Maps the options onto the library's problem specification
//! ([`hypersynth::pipeline::spec`]): the tasks (`tasks`), the arena, the translation
//! (`translate`) and, unless `--games-only`, the MDP stage's options (`opportunistic`), every
//! input file read first. The library checks every rule and builds the problem (translating
//! the tasks, reading the arena or map), solves it, draws the `--svg` picture if asked, and
//! this prints the report. The specification's errors are told in the options' terms: in a
//! formula as `--phi:LINE:COL` (or `--psi`, `--phi2`, `--task`...), in a file as
//! `FILE:LINE:COL`, each with the line and a caret under the column.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context as _, anyhow};
use hypersynth::pipeline::spec::{Field, PaperPayoffs, ProblemSpec, SpecError};
use hypersynth::pipeline::{
    self, ExplorerError, Output, PictureError, PipelineError, Requests, RunError, Sinks,
};
use hypersynth::render::RenderError;

use super::choices::{EngineArg, StatesArg};

/// The main form's options.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The arena file (`-` for standard input).
    #[arg(value_name = "ARENA", required = true)]
    pub arena: Option<String>,
    /// The robot's tasks: the paper's form, or named sub-tasks.
    #[command(flatten)]
    pub tasks: super::tasks::Args,
    #[command(flatten, next_help_heading = "Translation")]
    pub translation: super::translate::TranslatorArgs,
    /// Stop after the hypergame: print its report (sizes, winning regions, win-labels).
    #[arg(help_heading = "Arena and games", long)]
    pub games_only: bool,
    /// Which product states to enumerate: every configuration, or those reachable from h0.
    #[arg(help_heading = "Arena and games", long, value_enum, default_value_t = StatesArg::Full)]
    pub states: StatesArg,
    /// Which engine holds the product (docs/engines.md): the explicit one stores it, the
    /// implicit one computes it and makes the report, decision tables and the controller only.
    #[arg(help_heading = "Arena and games", long, value_enum, default_value_t = EngineArg::Auto)]
    pub engine: EngineArg,
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

impl Args {
    /// What clap cannot say about the main form's options: which task is missing, and inputs
    /// that would read standard input twice. The message of a usage error (exit status 2).
    pub fn check_usage(&self) -> Result<(), String> {
        self.tasks.check_usage(self.arena.as_deref())
    }

    /// The problem as the library's specification, every input file read.
    fn spec(&self) -> anyhow::Result<ProblemSpec> {
        let mdp = &self.mdp;
        let payoffs = PaperPayoffs {
            r1: mdp.r1,
            r2: mdp.r2,
            r: mdp.r,
        };
        let tasks = self.tasks.spec(payoffs)?;
        let arena = super::arena::spec(self.arena.as_deref().unwrap_or("-"))?;
        let mdp = match self.games_only {
            true => None,
            false => Some(super::opportunistic::spec(mdp)?),
        };
        Ok(ProblemSpec {
            arena,
            tasks,
            states: self.states.into(),
            translation: self.translation.translation(),
            mdp,
            engine: self.engine.into(),
        })
    }

    /// An error of `spec` (the one [`Args::spec`] made) in the options' terms.
    fn spec_error(&self, spec: &ProblemSpec, error: SpecError) -> anyhow::Error {
        match (&error.field, &spec.mdp) {
            (Field::Arena, _) => super::arena::error(&spec.arena, *error.kind),
            (
                Field::Weights
                | Field::Weight { .. }
                | Field::Observations
                | Field::Discount
                | Field::Precision,
                Some(mdp),
            ) => super::opportunistic::error(mdp, &error.field, *error.kind),
            _ => self.tasks.error(&spec.tasks, error),
        }
    }

    /// An error of the pipeline in the options' terms.
    fn pipeline_error(
        &self,
        spec: &ProblemSpec,
        arena_name: &str,
        error: PipelineError,
    ) -> anyhow::Error {
        match error {
            PipelineError::Explain(error) => super::opportunistic::explain_error(&self.mdp, error),
            PipelineError::Stage(error) => {
                super::opportunistic::stage_error(&self.mdp, spec.mdp.as_ref(), error)
            }
            PipelineError::Picture(error @ PictureError::NotAMap) => {
                anyhow!("{}: {}: {error}", arena_name, self.render.file_flag())
            }
            // The defaults (h0's automata and adversary cell) always exist: these come from
            // the options.
            PipelineError::Picture(PictureError::Render(
                error @ (RenderError::AutomatonState { .. } | RenderError::AutomataCount { .. }),
            )) => anyhow!("--automata: {error}"),
            PipelineError::Picture(PictureError::Render(error @ RenderError::AdversaryCell(_))) => {
                anyhow!("--adversary-at: {error}")
            }
            PipelineError::Picture(PictureError::NeedsMdp) => anyhow!(
                "--picture {}: the value and trace pictures need the opportunistic stage: \
                 drop --games-only",
                self.render.picture_name()
            ),
            PipelineError::Explorer(error @ ExplorerError::NotAMap) => {
                anyhow!("{}: --html: {error}", arena_name)
            }
            error @ PipelineError::CurveWithoutObservations => {
                anyhow!("--learning-curve: {error}: drop --games-only")
            }
            other => other.into(),
        }
    }
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    args.check_usage().map_err(|message| anyhow!(message))?;
    let mut progress = super::progress::Progress::new();
    let spec = args.spec()?;
    let requests = Requests {
        export_strategy: args.export_strategy.is_some(),
        picture: args.render.request(),
        html: args.render.html.is_some(),
        ..super::opportunistic::requests(&args.mdp, args.render.title())
    };
    let arena_name = spec.arena.name();
    // The MDP's DRN and the strategies are streamed into their files (each renamed over its
    // target once the run is done).
    let write_error = |path: &std::path::Path, e| anyhow!("cannot write {}: {e}", path.display());
    let create = |path: &Option<std::path::PathBuf>| match path {
        Some(path) => super::io::AtomicFile::create(path)
            .map(|file| Some((path.clone(), file)))
            .map_err(|e| write_error(path, e)),
        None => Ok(None),
    };
    let mut drn = create(&args.mdp.export_mdp)?;
    let mut strategy = create(&args.export_strategy)?;
    let sinks = Sinks {
        drn: drn
            .as_mut()
            .map(|(_, file)| file as &mut dyn std::io::Write),
        strategy: strategy
            .as_mut()
            .map(|(_, file)| file as &mut dyn std::io::Write),
    };
    let outcome = pipeline::solve_into(&spec, &requests, sinks, &mut progress).map_err(
        |error| match error {
            RunError::Spec(error) => args.spec_error(&spec, error),
            RunError::Pipeline(error) => args.pipeline_error(&spec, arena_name, error),
            RunError::Memory(error) => anyhow!("{arena_name}: {error}"),
            RunError::Implicit(error) => anyhow!("{arena_name}: {error}"),
            RunError::Write(output, e) => {
                let path = match output {
                    Output::Drn => args.mdp.export_mdp.as_ref(),
                    Output::Strategy => args.export_strategy.as_ref(),
                };
                match path {
                    Some(path) => write_error(path, e),
                    None => anyhow!(e),
                }
            }
        },
    )?;
    if let Some((path, file)) = strategy {
        file.commit().map_err(|e| write_error(&path, e))?;
    }
    // Without the MDP stage nothing was written: the temporary file goes.
    if let Some((path, file)) = drn.filter(|_| outcome.report.synthesis.is_some()) {
        file.commit().map_err(|e| write_error(&path, e))?;
    }
    let outputs = [
        (&args.render.svg, &outcome.svg),
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
    super::output::write_output(args.output.as_deref(), &text)?;
    if args.timings && args.format == Format::Text {
        eprintln!("hypersynth: {}", progress.timings_line());
    }
    Ok(ExitCode::SUCCESS)
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser as _;
    use hypersynth::game::States;
    use hypersynth::opportunistic::adversary::SigmaL;
    use hypersynth::opportunistic::build::Risk;
    use hypersynth::pipeline::spec::{
        ArenaSpec, GeneralSpec, LearntSpec, MdpSpec, NamedTask, Precision, SetPayoff, SigmaLSpec,
        TaskSource, TasksSpec,
    };

    /// The main form's options alone.
    #[derive(clap::Parser)]
    struct Main {
        #[command(flatten)]
        args: Args,
    }

    /// The specification the options `arguments` map onto.
    fn spec(arguments: &[&str]) -> ProblemSpec {
        let main =
            Main::try_parse_from(std::iter::once("hypersynth").chain(arguments.iter().copied()))
                .unwrap();
        main.args.spec().unwrap()
    }

    fn file(path: &str) -> String {
        std::fs::read_to_string(path).unwrap()
    }

    const ARENA: &str = "specs/decoy/arena.txt";

    /// A file for `--task-hoa` and `--phi1-hoa` (its text is the library's to read), in a
    /// directory removed when the first value is dropped.
    fn hoa_file() -> (tempfile::TempDir, String) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("task.hoa");
        std::fs::write(&path, "HOA: v1\n--BODY--\n--END--\n").unwrap();
        let path = path.to_str().unwrap().to_string();
        (dir, path)
    }

    #[test]
    fn the_general_forms_options_map_onto_the_specification() {
        let (_dir, hoa) = hoa_file();
        let spec = spec(&[
            ARENA,
            "--task",
            "A=!O U A",
            "--task",
            "B=F B",
            "--task-hoa",
            &format!("C={hoa}"),
            "--payoff",
            "A,B=350",
            "--payoff",
            "C= 7 ",
            "--believed",
            "F B",
            "--risk",
            "strict",
            "--states",
            "reachable",
            "--sigma-l",
            "uniform",
            "--discount",
            "0.9",
            "--relative-epsilon",
            "1e-4",
            "--max-iterations",
            "17",
            "--seed",
            "5",
        ]);
        let named = |name: &str, task| NamedTask {
            name: name.into(),
            task,
        };
        let expected = TasksSpec::General(GeneralSpec {
            tasks: vec![
                named("A", TaskSource::Formula("!O U A".into())),
                named("B", TaskSource::Formula("F B".into())),
                named(
                    "C",
                    TaskSource::Hoa {
                        name: hoa.clone(),
                        text: file(&hoa),
                    },
                ),
            ],
            payoffs: vec![
                SetPayoff {
                    set: vec!["A".into(), "B".into()],
                    value: 350.0,
                },
                SetPayoff {
                    set: vec!["C".into()],
                    value: 7.0,
                },
            ],
            believed: TaskSource::Formula("F B".into()),
            risk: Risk::Strict,
        });
        assert_eq!(spec.tasks, expected);
        assert_eq!(
            spec.arena,
            ArenaSpec::Text {
                name: ARENA.into(),
                text: file(ARENA),
            }
        );
        assert_eq!(spec.states, States::Reachable);
        let mdp = MdpSpec {
            sigma_l: SigmaLSpec::Value(SigmaL::Uniform),
            seed: 5,
            discount: 0.9,
            precision: Precision::Relative(1e-4),
            max_iterations: 17,
            learnt: None,
        };
        assert_eq!(spec.mdp, Some(mdp));
    }

    #[test]
    fn the_papers_options_map_onto_the_specification() {
        let paper = spec(&[
            ARENA,
            "--phi",
            "F A & F B",
            "--psi",
            "F A",
            "--r1",
            "1",
            "--r2",
            "2",
            "--r",
            "4",
        ]);
        let payoffs = PaperPayoffs {
            r1: 1.0,
            r2: 2.0,
            r: 4.0,
        };
        let expected = TasksSpec::Paper {
            phi: "F A & F B".into(),
            psi: "F A".into(),
            phi2: None,
            payoffs,
        };
        assert_eq!(paper.tasks, expected);
        let weights = "specs/learnt/truth.txt";
        let runs = "specs/learnt/runs.txt";
        let (_dir, hoa) = hoa_file();
        let parts = spec(&[
            ARENA,
            "--phi1-hoa",
            &hoa,
            "--phi2",
            "F B",
            "--adversary",
            weights,
            "--observations",
            runs,
            "--delta",
            "0.1",
        ]);
        let expected = TasksSpec::PaperParts {
            phi1: TaskSource::Hoa {
                name: hoa.clone(),
                text: file(&hoa),
            },
            phi2: TaskSource::Formula("F B".into()),
            payoffs: PaperPayoffs::default(),
        };
        assert_eq!(parts.tasks, expected);
        let mdp = parts.mdp.unwrap();
        let sigma_l = SigmaLSpec::WeightsFile {
            name: weights.into(),
            text: file(weights),
        };
        assert_eq!(mdp.sigma_l, sigma_l);
        let learnt = LearntSpec {
            name: runs.into(),
            text: file(runs),
            delta: 0.1,
        };
        assert_eq!(mdp.learnt, Some(learnt));
        // Without the MDP stage, its options are not read.
        let games = spec(&[
            ARENA,
            "--phi",
            "F A",
            "--psi",
            "F A",
            "--games-only",
            "--adversary",
            "missing",
        ]);
        assert_eq!(games.mdp, None);
    }
}

//! The main form: `hypersynth --phi PHI --psi PSI ARENA`.
//!
//! Parses the formulas, splits `phi` into `phi1 = psi` and `phi2`, translates both (options shared with `translate`), reads the
//! arena (or map), builds and solves the hypergame, draws the `--svg` picture if asked, then (unless `--games-only`) builds and solves the
//! hypergame MDP, and prints the report. Errors in a formula are
//! located as `--phi:LINE:COL` (or `--psi`, `--phi2`) with a caret under the text.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context as _, anyhow};
use hypersynth::automata::Dfa;
use hypersynth::game::{Hypergame, Operand, States, WinningRegions, split_task};
use hypersynth::ltl::{self, Formula, caret_context};
use hypersynth::position::Position;
use hypersynth::report::{GamesReport, StrategyExport, TaskAutomaton};
use hypersynth::translate::{TranslateError, Translator};

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
    /// The arena file (`-` for standard input).
    #[arg(value_name = "ARENA")]
    pub arena: Option<String>,
    /// Stop after the hypergame: print its report (sizes, winning regions, win-labels).
    #[arg(long)]
    pub games_only: bool,
    /// Which product states to enumerate: every configuration, or those reachable from h0.
    #[arg(long, value_enum, default_value_t = States::Full)]
    pub states: States,
    /// How to print the report.
    #[arg(long, value_enum, default_value_t = Format::Text)]
    pub format: Format,
    /// Also write the reactive strategies (both players, three tasks) as JSON to FILE.
    #[arg(long, value_name = "FILE")]
    pub export_strategy: Option<PathBuf>,
    #[command(flatten)]
    pub translation: super::translate::TranslatorArgs,
    /// The opportunistic stage's options (ignored with --games-only).
    #[command(flatten)]
    pub mdp: super::opportunistic::Args,
    #[command(flatten)]
    pub render: super::render::Args,
}

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Text,
    Json,
}

/// A formula with the text it was parsed from and the option that gave it, for locating errors.
struct Source<'a> {
    option: &'static str,
    text: &'a str,
}

impl Source<'_> {
    /// `--option:LINE:COL: message` and a caret under the column.
    fn error_at(&self, position: Position, message: &dyn std::fmt::Display) -> anyhow::Error {
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

    fn parse(&self) -> anyhow::Result<Formula> {
        ltl::parse(self.text).map_err(|e| self.error_at(e.position, &e.message))
    }

    fn translate(&self, translator: &dyn Translator, formula: &Formula) -> anyhow::Result<Dfa> {
        translator.translate(formula).map_err(|error| match error {
            TranslateError::NotCoSafe(error) => self.error_at(error.position(self.text), &error),
            other => anyhow!("{}: {other}", self.option),
        })
    }
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let (Some(phi_text), Some(psi_text), Some(arena_file)) = (&args.phi, &args.psi, &args.arena)
    else {
        anyhow::bail!(
            "the main form needs --phi PHI, --psi PSI and an ARENA file (see `hypersynth --help`)"
        );
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
    let dfa1 = psi_source.translate(translator.as_ref(), &split.phi1)?;
    let dfa2 = phi2_origin.translate(translator.as_ref(), &split.phi2)?;

    let input = super::arena::load_input(arena_file)?;
    let game = Hypergame::new(&input.arena, &dfa1, &dfa2, args.states)?;
    for proposition in game.missing_propositions() {
        eprintln!(
            "hypersynth: warning: proposition `{proposition}` is carried by no state of \
             {arena_file}: it is always false"
        );
    }
    let regions = WinningRegions::compute(&game);
    if let Some(path) = &args.export_strategy {
        let json = serde_json::to_vec_pretty(&StrategyExport::new(&game, &regions))?;
        hypersynth::io::write_atomically(path, &json)
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    let (phi1_text, phi2_text) = (split.phi1.to_string(), split.phi2.to_string());
    let phi_text = split.phi.to_string();
    let subject = super::render::Subject {
        arena_file,
        map: input.map.as_ref(),
        game: &game,
        regions: &regions,
        formulas: [&phi_text, &phi1_text, &phi2_text],
    };
    super::render::run(
        &args.render,
        &subject,
        (!args.games_only).then_some(&args.mdp),
    )?;
    let automata = [
        TaskAutomaton {
            formula: &phi1_text,
            dfa: &dfa1,
            translator: translator.name(),
        },
        TaskAutomaton {
            formula: &phi2_text,
            dfa: &dfa2,
            translator: translator.name(),
        },
    ];
    let games = GamesReport::new(&phi_text, automata, &game, &regions);
    let text = if args.games_only {
        match args.format {
            Format::Text => games.to_string(),
            Format::Json => serde_json::to_string_pretty(&games)? + "\n",
        }
    } else {
        let report = super::opportunistic::run(&args.mdp, &game, &regions, games)?;
        match args.format {
            Format::Text => report.to_string(),
            Format::Json => serde_json::to_string_pretty(&report.to_json())? + "\n",
        }
    };
    super::write_output(None, &text)?;
    Ok(ExitCode::SUCCESS)
}

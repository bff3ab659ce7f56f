//! The MDP stage of the main form: its options (flattened into `synth::Args`) and the step that
//! turns a solved hypergame and its games report into the opportunistic report, writing the DRN
//! export if asked.

use std::path::PathBuf;

use anyhow::Context;

use hypersynth::game::{Hypergame, WinningRegions};
use hypersynth::io::{read_input, write_atomically};
use hypersynth::mdp::adversary::{SigmaL, WeightTable};
use hypersynth::mdp::build::Payoffs;
use hypersynth::mdp::solve::{Discount, SolveOptions};
use hypersynth::mdp::view::SolvedHypergame;
use hypersynth::mdp::write_drn;
use hypersynth::report::{
    GamesReport, MdpConfig, OpportunisticReport, StageError, opportunistic_report,
};

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum SigmaLKind {
    Uniform,
    Random,
}

/// Options of the opportunistic (MDP) stage.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The adversary's distribution where it believes it has lost: uniform, or random weights
    /// drawn from `--seed`.
    #[arg(long, value_enum, default_value = "random")]
    pub sigma_l: SigmaLKind,
    /// Seed of the random weights and of the simulation.
    #[arg(long, default_value_t = 2019)]
    pub seed: u64,
    /// Read sigma_L's weights from FILE (`STATE ACTION WEIGHT` lines), instead of --sigma-l.
    #[arg(long, value_name = "FILE", conflicts_with = "sigma_l")]
    pub adversary: Option<String>,
    /// Payoff of phi1.
    #[arg(long, default_value_t = 200.0)]
    pub r1: f64,
    /// Payoff of phi2.
    #[arg(long, default_value_t = 100.0)]
    pub r2: f64,
    /// Payoff of phi (at least r1 + r2).
    #[arg(long, default_value_t = 300.0)]
    pub r: f64,
    /// Discount g per robot move, 0 < g <= 1.
    #[arg(long, default_value_t = 1.0)]
    pub discount: f64,
    /// Certified bound on the error of the values.
    #[arg(long, default_value_t = 1e-6)]
    pub epsilon: f64,
    /// Print the decision table of STATE (`ARENA_STATE|Q1|Q2`; default h0).
    #[arg(long, value_name = "STATE", num_args = 0..=1, default_missing_value = "h0")]
    pub explain: Option<String>,
    /// Simulate N runs of the controller against the adversary model.
    #[arg(long, value_name = "N")]
    pub simulate: Option<u32>,
    /// Print one simulated run state by state.
    #[arg(long)]
    pub trace: bool,
    /// Step bound of simulated runs.
    #[arg(long, default_value_t = 1000)]
    pub max_steps: u32,
    /// Write the hypergame MDP in Storm's DRN format to FILE.
    #[arg(long, value_name = "FILE")]
    pub export_mdp: Option<PathBuf>,
}

/// Builds, solves and reports the hypergame MDP of a solved hypergame, writing the DRN export
/// if asked.
#[expect(
    dead_code,
    reason = "called by the main form in synth.rs once it solves hypergames"
)]
pub fn run(
    args: &Args,
    product: &Hypergame,
    regions: &WinningRegions,
    games: GamesReport,
) -> anyhow::Result<OpportunisticReport> {
    let located = |path: &str, e: &dyn std::fmt::Display| anyhow::anyhow!("{path}:{e}");
    let (sigma_l, sigma_l_name) = match (&args.adversary, args.sigma_l) {
        (Some(path), _) => {
            let text = read_input(path).with_context(|| format!("{path}: cannot read"))?;
            let table = WeightTable::parse(&text).map_err(|e| located(path, &e))?;
            (SigmaL::Weights(table), format!("file:{path}"))
        }
        (None, SigmaLKind::Uniform) => (SigmaL::Uniform, "uniform".to_string()),
        (None, SigmaLKind::Random) => (SigmaL::Random { seed: args.seed }, "random".to_string()),
    };
    let explain = match args.explain.as_deref() {
        None => None,
        Some("h0") => Some(product.initial()),
        Some(text) => Some(
            product
                .parse_state(text)
                .map_err(|e| located("--explain", &e))?,
        ),
    };
    let config = MdpConfig {
        sigma_l,
        sigma_l_name,
        seed: args.seed,
        payoffs: Payoffs::new(args.r1, args.r2, args.r)?,
        solve: SolveOptions {
            discount: Discount::new(args.discount).context("--discount")?,
            epsilon: args.epsilon,
            ..SolveOptions::default()
        },
        explain,
        simulate: args.simulate,
        trace: args.trace,
        max_steps: args.max_steps,
    };
    let game = SolvedHypergame::new(product, regions);
    let (report, built) =
        opportunistic_report(&game, games, &config).map_err(|e| match (&e, &args.adversary) {
            (StageError::Adversary(_), Some(path)) => located(path, &e),
            _ => e.into(),
        })?;
    if let Some(path) = &args.export_mdp {
        write_atomically(
            path,
            write_drn(built.mdp(), config.solve.discount).as_bytes(),
        )
        .with_context(|| format!("{}: cannot write", path.display()))?;
    }
    Ok(report)
}

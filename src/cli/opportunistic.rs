//! The MDP stage of the main form: its options (flattened into `synth::Args`) and the step that
//! turns a solved hypergame and its games report into the opportunistic report, writing the DRN
//! export if asked.

use std::path::PathBuf;

use anyhow::Context;

use hypersynth::game::{Hypergame, WinningRegions};
use hypersynth::io::{read_input, write_atomically};
use hypersynth::mdp::adversary::{SigmaL, WeightTable};
use hypersynth::mdp::build::Payoffs;
use hypersynth::mdp::solve::{Discount, SolveError, SolveOptions};
use hypersynth::mdp::view::SolvedHypergame;
use hypersynth::mdp::{Mdp, MdpState, write_drn};
use hypersynth::report::{
    GamesReport, MdpConfig, OpportunisticReport, StageError, opportunistic_report,
};
use hypersynth::stage::Observer;

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum SigmaLKind {
    Uniform,
    Random,
}

/// Options of the opportunistic (MDP) stage.
#[derive(clap::Args, Debug)]
#[group(id = "opportunistic")]
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
    /// Sweeps of value iteration after which the solver gives up.
    #[arg(long, value_name = "N", default_value_t = SolveOptions::default().max_iterations)]
    pub max_iterations: u32,
    /// Print the decision table of STATE (`--explain=ARENA_STATE|Q1|Q2`; default h0). The `=`
    /// is required, so that `--explain ARENA` leaves ARENA to the main form.
    #[arg(
        long,
        value_name = "STATE",
        num_args = 0..=1,
        require_equals = true,
        default_missing_value = "h0"
    )]
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

/// sigma_L as the options give it (reading `--adversary`'s file), with its name in reports.
pub fn sigma_l(args: &Args) -> anyhow::Result<(SigmaL, String)> {
    Ok(match (&args.adversary, args.sigma_l) {
        (Some(path), _) => {
            let text = read_input(path).with_context(|| format!("{path}: cannot read"))?;
            let table = WeightTable::parse(&text).map_err(|e| anyhow::anyhow!("{path}:{e}"))?;
            (SigmaL::Weights(table), format!("file:{path}"))
        }
        (None, SigmaLKind::Uniform) => (SigmaL::Uniform, "uniform".to_string()),
        (None, SigmaLKind::Random) => (SigmaL::Random { seed: args.seed }, "random".to_string()),
    })
}

/// A failed MDP stage as the CLI reports it: adversary file errors located in the file, and
/// the options to change when the solver or the evaluation ran out of sweeps.
pub fn stage_error(args: &Args, error: StageError) -> anyhow::Error {
    match (&error, &args.adversary) {
        (StageError::Adversary(_), Some(path)) => anyhow::anyhow!("{path}:{error}"),
        (StageError::Solve(SolveError::IterationLimit { .. }), _)
        | (StageError::Evaluation(_), _) => anyhow::anyhow!(
            "{error}; raise --max-iterations (now {}) or --epsilon",
            args.max_iterations
        ),
        _ => error.into(),
    }
}

/// Writes `--export-mdp` (DRN, atomically) if asked, with the states' display names.
pub fn export_mdp(
    args: &Args,
    mdp: &Mdp,
    discount: Discount,
    name: impl Fn(MdpState) -> Option<String>,
) -> anyhow::Result<()> {
    if let Some(path) = &args.export_mdp {
        let text = write_drn(mdp, discount, name);
        write_atomically(path, text.as_bytes())
            .with_context(|| format!("{}: cannot write", path.display()))?;
    }
    Ok(())
}

/// The MDP stage's settings from its options (the weights file read and parsed) and the
/// payoffs; no state to explain.
pub fn config(args: &Args, payoffs: Payoffs) -> anyhow::Result<MdpConfig> {
    let (sigma_l, sigma_l_name) = sigma_l(args)?;
    Ok(MdpConfig {
        sigma_l,
        sigma_l_name,
        seed: args.seed,
        payoffs,
        solve: SolveOptions {
            discount: Discount::new(args.discount).context("--discount")?,
            epsilon: args.epsilon,
            max_iterations: args.max_iterations,
        },
        explain: None,
        simulate: args.simulate,
        trace: args.trace,
        max_steps: args.max_steps,
    })
}

/// Builds, solves and reports the hypergame MDP of a solved hypergame, telling `observer` about
/// each stage, and writes the DRN export if asked.
pub fn run(
    args: &Args,
    payoffs: Payoffs,
    product: &Hypergame,
    regions: &WinningRegions,
    games: GamesReport,
    observer: &mut dyn Observer,
) -> anyhow::Result<OpportunisticReport> {
    let mut config = config(args, payoffs)?;
    config.explain = match args.explain.as_deref() {
        None => None,
        Some("h0") => Some(product.initial()),
        Some(text) => Some(
            product
                .parse_state(text)
                .map_err(|e| anyhow::anyhow!("--explain:{e}"))?,
        ),
    };
    let game = SolvedHypergame::new(product, regions);
    let (report, built) =
        opportunistic_report(&game, games, &config, observer).map_err(|e| stage_error(args, e))?;
    export_mdp(args, built.mdp(), config.solve.discount, |s| {
        Some(built.state_name(&game, s))
    })?;
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;
    use hypersynth::arena::{Arena, ArenaBuilder, Owner};
    use hypersynth::automata::{Dfa, Guard};
    use hypersynth::game::States;
    use hypersynth::report::TaskAutomaton;

    /// Robot `r` moves `go` to adversary `a`, which moves `x` back to `r` or `y` to robot `g`
    /// (labelled A and B, with a self-loop `stay`).
    fn arena() -> Arena {
        let mut b = ArenaBuilder::new();
        let r = b.add_state("r", Owner::Robot, [], None).unwrap();
        let a = b.add_state("a", Owner::Adversary, [], None).unwrap();
        let g = b.add_state("g", Owner::Robot, ["A", "B"], None).unwrap();
        for (from, action, to) in [(r, "go", a), (a, "x", r), (a, "y", g), (g, "stay", g)] {
            b.add_transition(from, action, to).unwrap();
        }
        b.set_initial(r);
        b.build().unwrap()
    }

    /// `F p`: 0 waits, 1 final.
    fn eventually(p: &str) -> Dfa {
        let p_holds = Guard::literal(0, true);
        let edges = vec![
            vec![(p_holds.not(), 0), (p_holds, 1)],
            vec![(Guard::always(), 1)],
        ];
        Dfa::new(vec![p.into()], 0, [1].into_iter().collect(), edges).unwrap()
    }

    fn args(adversary: Option<String>, export: Option<PathBuf>) -> Args {
        Args {
            sigma_l: SigmaLKind::Uniform,
            seed: 1,
            adversary,
            r1: 200.0,
            r2: 100.0,
            r: 300.0,
            discount: 1.0,
            epsilon: 1e-6,
            max_iterations: 100_000,
            explain: None,
            simulate: None,
            trace: false,
            max_steps: 10,
            export_mdp: export,
        }
    }

    fn run_on(args: &Args) -> anyhow::Result<OpportunisticReport> {
        let arena = arena();
        let (dfa1, dfa2) = (eventually("A"), eventually("B"));
        let product = Hypergame::new(&arena, &dfa1, &dfa2, States::Full).unwrap();
        let regions = WinningRegions::compute(&product);
        let automata = [("F A", &dfa1), ("F B", &dfa2)].map(|(formula, dfa)| TaskAutomaton {
            formula,
            dfa,
            translator: "test",
        });
        let games = GamesReport::new("F A & F B", automata, &product, &regions);
        run(args, Payoffs::default(), &product, &regions, games, &mut ())
    }

    #[test]
    fn weights_file_errors_name_the_file_line_and_column() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("weights.txt");
        std::fs::write(&path, "# weights\na  z 1\n").unwrap();
        let path = path.to_str().unwrap().to_string();
        let error = run_on(&args(Some(path.clone()), None)).unwrap_err();
        assert_eq!(
            error.to_string(),
            format!("{path}:2:4: action `z` is not enabled in adversary state `a`")
        );
    }

    #[test]
    fn export_writes_the_drn_of_the_solved_mdp() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("mdp.drn");
        let report = run_on(&args(None, Some(path.clone()))).unwrap();
        // The adversary can answer x forever, so h0 is (L, L, L), and in `a` (outside
        // Win(phi1)) sigma_W plays its only safe action x: the robot never reaches g, value 0.
        assert_eq!(report.initial.value, 0.0);
        assert_eq!(report.mdp.robot_states, 8);
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.starts_with("// hypersynth MDP"));
        assert!(text.contains("@type: MDP"));
    }
}

//! The paper's case study solved from code, stage by stage: the robot must visit A and B
//! avoiding obstacles, the adversary believes it only has to visit A.
//!
//! Run with `cargo run -p hypersynth --example case_study`.

use hypersynth::arena;
use hypersynth::game::{States, Task as Goal, WinningRegions};
use hypersynth::ltl;
use hypersynth::mdp::solve::SolveOptions;
use hypersynth::opportunistic::adversary::SigmaL;
use hypersynth::opportunistic::build::Payoffs;
use hypersynth::opportunistic::view::SolvedHypergame;
use hypersynth::pipeline::{MdpOptions, OpportunisticSolution, PaperTasks, ReportRequests};
use hypersynth::report::GamesReport;
use hypersynth::translate::{Builtin, Limits};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../specs/case-study/arena.txt"
    );
    let arena = arena::parse(&std::fs::read_to_string(path)?)?.arena;
    let translator = Builtin::new(Limits::default());
    let tasks = PaperTasks::from_formulas(
        &ltl::parse("(!O U A) & (!O U B)")?,
        &ltl::parse("!O U A")?,
        None,
        &translator,
    )?;

    // The games: who can force which task from where.
    let game = tasks.hypergame(&arena, States::Full)?;
    let regions = WinningRegions::compute(&game);
    for goal in [Goal::Phi1, Goal::Phi2, Goal::Phi] {
        println!("Win({goal}) has {} product states", regions.get(goal).len());
    }

    // The hypergame MDP of the adversary's stochastic strategies, solved with a certified bound.
    let solved = SolvedHypergame::new(&game, &regions);
    let options = MdpOptions {
        sigma_l: SigmaL::Random { seed: 2019 },
        seed: 2019,
        payoffs: Payoffs::default(),
        solve: SolveOptions::default(),
    };
    let solution = OpportunisticSolution::solve(&solved, &options, &mut ())?;

    // The report the command line prints, with h0's decision table.
    let games = GamesReport::new(
        &tasks.phi,
        [tasks.phi1.automaton(), tasks.phi2.automaton()],
        &game,
        &regions,
    );
    let requests = ReportRequests {
        explain: Some(game.initial()),
        max_steps: 1000,
        ..ReportRequests::default()
    };
    print!("{}", solution.report(&solved, games, &requests, &mut ()));
    Ok(())
}

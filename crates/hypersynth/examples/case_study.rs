//! The paper's case study solved from code, stage by stage: the robot must visit A and B
//! avoiding obstacles, the adversary believes it only has to visit A.
//!
//! Run with `cargo run -p hypersynth --example case_study`.

use hypersynth::arena;
use hypersynth::game::{Payoffs, States, TaskSet};
use hypersynth::ltl;
use hypersynth::mdp::solve::SolveOptions;
use hypersynth::opportunistic::adversary::SigmaL;
use hypersynth::opportunistic::view::SolvedHypergame;
use hypersynth::pipeline::{MdpOptions, OpportunisticSolution, ReportRequests, Tasks};
use hypersynth::report::Report;
use hypersynth::translate::{Builtin, TranslationLimits};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../specs/case-study/arena.txt"
    );
    let arena = arena::parse(&std::fs::read_to_string(path)?)?.arena;
    let translator = Builtin::new(TranslationLimits::default());
    let tasks = Tasks::from_formulas(
        &ltl::parse("(!O U A) & (!O U B)")?,
        &ltl::parse("!O U A")?,
        None,
        &translator,
        Payoffs::default(),
    )?;

    // The games: who can force which task from where.
    let game = tasks.hypergame(&arena, States::Full)?;
    let regions = tasks.regions(&game);
    let presentation = tasks.presentation();
    for set in TaskSet::non_empty(2) {
        println!(
            "Win({}) has {} product states",
            presentation.set_name(set),
            regions.win(set).len()
        );
    }

    // The hypergame MDP of the adversary's stochastic strategies, solved with a certified bound.
    let solved = SolvedHypergame::new(&game, &regions, tasks.payoffs(), presentation);
    let options = MdpOptions {
        sigma_l: SigmaL::Random { seed: 2019 },
        seed: 2019,
        solve: SolveOptions::default(),
        learnt: None,
    };
    let solution = OpportunisticSolution::solve(&solved, tasks.risk(), &options, &mut ())?;

    // The report the command line prints, with h0's decision table.
    let requests = ReportRequests {
        explain: Some(game.initial()),
        max_steps: 1000,
        ..ReportRequests::default()
    };
    let report = Report {
        presentation: presentation.clone(),
        games: tasks.games(&game, &regions),
        synthesis: Some(solution.synthesis(&solved, &requests, None, &mut ())),
    };
    print!("{report}");
    Ok(())
}

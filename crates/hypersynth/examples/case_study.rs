//! The paper's case study solved from code, stage by stage: the robot must visit A and B
//! avoiding obstacles, the adversary believes it only has to visit A.
//!
//! Run with `cargo run -p hypersynth --example case_study`.

use hypersynth::arena;
use hypersynth::game::{Payoffs, States, Task as Goal};
use hypersynth::ltl;
use hypersynth::mdp::solve::SolveOptions;
use hypersynth::opportunistic::adversary::SigmaL;
use hypersynth::opportunistic::view::SolvedHypergame;
use hypersynth::pipeline::{MdpOptions, OpportunisticSolution, ReportRequests, Tasks};
use hypersynth::report::{Games, GamesReport, Report};
use hypersynth::translate::{Builtin, Limits};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../specs/case-study/arena.txt"
    );
    let arena = arena::parse(&std::fs::read_to_string(path)?)?.arena;
    let translator = Builtin::new(Limits::default());
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
    for goal in [Goal::Phi1, Goal::Phi2, Goal::Phi] {
        println!(
            "Win({goal}) has {} product states",
            regions.win(goal.set()).len()
        );
    }

    // The hypergame MDP of the adversary's stochastic strategies, solved with a certified bound.
    let names = tasks.names();
    let solved = SolvedHypergame::new(&game, &regions, tasks.payoffs(), &names, tasks.form());
    let options = MdpOptions {
        sigma_l: SigmaL::Random { seed: 2019 },
        seed: 2019,
        solve: SolveOptions::default(),
    };
    let solution = OpportunisticSolution::solve(&solved, tasks.risk(), &options, &mut ())?;

    // The report the command line prints, with h0's decision table.
    let [phi1, phi2] = tasks.subtasks() else {
        unreachable!("the paper's form has two tasks");
    };
    let automata = [phi1.task.automaton(), phi2.task.automaton()];
    let games = GamesReport::new(tasks.phi(), automata, &game, &regions);
    let requests = ReportRequests {
        explain: Some(game.initial()),
        max_steps: 1000,
        ..ReportRequests::default()
    };
    let report = Report {
        games: Games::Paper(Box::new(games)),
        synthesis: Some(solution.synthesis(&solved, &requests, None, &mut ())),
    };
    print!("{report}");
    Ok(())
}

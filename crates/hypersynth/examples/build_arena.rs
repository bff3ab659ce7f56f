//! An arena built in code and solved in one call.
//!
//! A corridor `start - hall - goal` with a guard who can block the hall: from `hall` the
//! adversary either lets the robot through to `goal` (labelled `B`) or sends it back to
//! `start`; `start` carries `A`. The robot's task is `F A & F B`; the adversary believes it is
//! only `F A`, which holds at once, so it thinks the robot has already won and moves at random.
//!
//! Run with `cargo run -p hypersynth --example build_arena`.

use hypersynth::arena::{ArenaBuilder, Owner};
use hypersynth::game::{Payoffs, States};
use hypersynth::ltl;
use hypersynth::mdp::solve::SolveOptions;
use hypersynth::opportunistic::adversary::SigmaL;
use hypersynth::pipeline::{self, MdpOptions, Problem, Requests, Tasks};
use hypersynth::translate::{Builtin, TranslationLimits};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut builder = ArenaBuilder::new();
    let start = builder.add_state("start", Owner::Robot, ["A"], None)?;
    let hall = builder.add_state("hall", Owner::Adversary, [], None)?;
    let goal = builder.add_state("goal", Owner::Robot, ["B"], None)?;
    builder.add_transition(start, "walk", hall)?;
    builder.add_transition(hall, "let_pass", goal)?;
    builder.add_transition(hall, "send_back", start)?;
    builder.add_transition(goal, "stay", goal)?;
    builder.set_initial(start);
    let arena = builder.build()?;

    let translator = Builtin::new(TranslationLimits::default());
    let phi = ltl::parse("F A & F B")?;
    let psi = ltl::parse("F A")?;
    let problem = Problem {
        arena_name: "corridor".to_string(),
        arena,
        map: None,
        tasks: Tasks::from_formulas(&phi, &psi, None, &translator, Payoffs::default())?,
        states: States::Reachable,
        mdp: Some(MdpOptions {
            sigma_l: SigmaL::Uniform,
            seed: 1,
            solve: SolveOptions::default(),
            learnt: None,
        }),
    };
    let requests = Requests {
        max_steps: 100,
        ..Requests::default()
    };
    let outcome = pipeline::run(&problem, &requests, &mut ())?;
    let report = outcome.report;
    let synthesis = report
        .synthesis
        .as_ref()
        .expect("the MDP stage was asked for");
    // The guard lets the robot pass with probability 1/2 each time, so it gets through with
    // probability 1: the value at h0 is the payoff of both tasks.
    println!(
        "value at h0: {:.3} (payoff of both tasks {})",
        synthesis.decision.value,
        Payoffs::default().r()
    );
    print!("{report}");
    Ok(())
}

//! Times the solve of a map in process: the Rust side of the Python bindings' overhead
//! measurement (`scripts/python-overhead`, which times the same solve from Python).
//!
//! `cargo run --release -p hypersynth --example solve_map -- MAP DISCOUNT RUNS` reads MAP, solves
//! `(!O U A) & (!O U B)` believed `!O U A` with DISCOUNT and a uniform sigma_L RUNS times, and
//! prints the value of h0 and the fastest run's seconds (product to evaluation, as
//! `pipeline::Solved::new` runs them).

use std::time::Instant;

use hypersynth::arena::map;
use hypersynth::game::{Payoffs, States};
use hypersynth::ltl;
use hypersynth::mdp::solve::{Discount, SolveOptions};
use hypersynth::opportunistic::adversary::SigmaL;
use hypersynth::pipeline::{MdpOptions, Problem, Solved, Task, Tasks};
use hypersynth::translate::{Builtin, TranslationLimits};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [file, discount, runs] = args.as_slice() else {
        return Err("usage: solve_map MAP DISCOUNT RUNS".into());
    };
    let world = map::parse(&std::fs::read_to_string(file)?).map_err(|e| e.to_string())?;
    // phi1 and phi2 on their own: the same problem as phi = phi1 & phi2 believed phi1.
    let translator = Builtin::new(TranslationLimits::default());
    let [phi1, phi2] = ["!O U A", "!O U B"]
        .map(|text| ltl::parse(text).map(|formula| Task::from_formula(formula, &translator)));
    let tasks = Tasks::from_parts(phi1??, phi2??, Payoffs::default());
    let problem = Problem {
        arena_name: file.clone(),
        arena: world.build_without_display_names()?,
        map: Some(world),
        tasks,
        states: States::Full,
        mdp: Some(MdpOptions {
            sigma_l: SigmaL::Uniform,
            seed: 2019,
            solve: SolveOptions {
                discount: Discount::new(discount.parse()?)?,
                ..SolveOptions::default()
            },
            learnt: None,
        }),
    };
    let mut best = f64::INFINITY;
    let mut value = 0.0;
    for _ in 0..runs.parse::<u32>()? {
        let start = Instant::now();
        let solved = Solved::new(&problem, &mut ())?;
        best = best.min(start.elapsed().as_secs_f64());
        let solution = solved.solution.as_ref().expect("solved with the MDP stage");
        value = solution
            .solution
            .value(solution.mdp.node(solved.product.initial()))
            .lower;
    }
    println!("{value} {best:.4}");
    Ok(())
}

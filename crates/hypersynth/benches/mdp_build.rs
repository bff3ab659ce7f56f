//! Hypergame MDP construction and solution on gridworlds of growing size: adversary model,
//! MDP build (folding the adversary's chance nodes) and certified solve, with sizes and times.
//!
//! `cargo bench --bench mdp_build [-- MAX_SIDE]` (default 14). Each n×n gridworld comes from the
//! gridworld generator with about 10% obstacles (a fixed pattern), the robot starting west and
//! the adversary east, `A` west of the robot's start and `B` in the north-east corner; tasks
//! `!O U A` and `!O U B`, sigma_L random (seed 1), discount 0.99 and 1.

mod common;

use std::time::Instant;

use hypersynth::game::{Hypergame, States};
use hypersynth::mdp::solve::{Discount, SolveOptions, solve};
use hypersynth::opportunistic::adversary::{AdversaryModel, SigmaL};
use hypersynth::opportunistic::build::{HypergameMdp, Risk};
use hypersynth::testing::PaperGame;
use hypersynth::testing::avoid_until;

fn main() {
    let max_side = common::side_argument(14);
    let (dfa1, dfa2) = (avoid_until("O", "A"), avoid_until("O", "B"));
    println!(
        "{:>4} {:>9} {:>9} {:>9} {:>9} {:>8} {:>8} {:>10} {:>6} {:>10} {:>6}",
        "side",
        "product",
        "robot",
        "mdp",
        "trans",
        "adv ms",
        "build ms",
        "g=.99 ms",
        "iters",
        "g=1 ms",
        "iters"
    );
    for n in (5..=max_side).step_by(3) {
        let arena = common::gridworld(
            n,
            &[
                ("A", common::cell(0, n / 2 + 1)),
                ("B", common::cell(n - 1, n - 1)),
            ],
        )
        .build()
        .unwrap();
        let product = Hypergame::new(&arena, &dfa1, &dfa2, States::Full).unwrap();
        let paper = PaperGame::new(&product);
        let game = paper.view(&product);
        let start = Instant::now();
        let adversary = AdversaryModel::new(&game, &SigmaL::Random { seed: 1 }).unwrap();
        let adversary_ms = start.elapsed().as_secs_f64() * 1e3;
        let start = Instant::now();
        let built = HypergameMdp::build(&game, &adversary, Risk::Paper).unwrap();
        let build_ms = start.elapsed().as_secs_f64() * 1e3;
        let mdp = built.mdp();
        let timed_solve = |g: f64| {
            let options = SolveOptions {
                discount: Discount::new(g).unwrap(),
                ..SolveOptions::default()
            };
            let start = Instant::now();
            let solution = solve(mdp, &options).unwrap();
            (start.elapsed().as_secs_f64() * 1e3, solution)
        };
        let (discounted_ms, discounted) = timed_solve(0.99);
        let (total_ms, total) = timed_solve(1.0);
        println!(
            "{n:>4} {:>9} {:>9} {:>9} {:>9} {adversary_ms:>8.1} {build_ms:>8.1} {discounted_ms:>10.1} {:>6} {total_ms:>10.1} {:>6}",
            product.num_states(),
            built.sizes(&game, &total).robot_states,
            mdp.num_states(),
            mdp.num_transitions(),
            discounted.iterations(),
            total.iterations(),
        );
    }
}

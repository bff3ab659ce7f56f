//! The robust solver against the nominal one on the same hypergame MDP: the n×n gridworld
//! (default 24) of `scripts/bench-robust`, tasks `!O U A` and `!O U B`, uniform sigma_L, and intervals on every chance
//! choice of two targets or more around the model's probabilities, of half-width 0 (the exact
//! region: the robust value is the nominal one), 0.05 and 1 (anything goes), at g = 0.99 and
//! g = 1. Prints the nominal solve's time and each robust solve's, its ratio to the nominal
//! one, and its sweeps.
//!
//! `cargo bench --bench robust_solve [-- SIDE]`. The recorded runs of `scripts/bench-robust`
//! leave most states unobserved (`[0, 1]`); the exact region is the robust solver's hardest
//! case, every interval choice needing its full sort per sweep.

mod common;

use std::time::Instant;

use hypersynth::arena::gridworld::Gridworld;
use hypersynth::game::{Hypergame, States};
use hypersynth::mdp::robust::{self, Intervals};
use hypersynth::mdp::solve::{Discount, SolveOptions, solve};
use hypersynth::opportunistic::adversary::{AdversaryModel, SigmaL};
use hypersynth::opportunistic::build::{HypergameMdp, Risk};
use hypersynth::testing::PaperGame;
use hypersynth::testing::avoid_until;

fn main() {
    let n = common::side_argument(24);
    let (dfa1, dfa2) = (avoid_until("O", "A"), avoid_until("O", "B"));
    // The gridworld of scripts/bench-robust and bench-vs-storm: robot at (0, n/2), adversary
    // at (n-1, n/2), obstacles (n/2, n/2) and (n/2-1, 1), A and B in the northern corners.
    let (cell, mid) = (common::cell, n / 2);
    let mut grid = Gridworld::new(n, n, cell(0, mid), cell(n - 1, mid));
    grid.obstacles = vec![cell(mid, mid), cell(mid - 1, 1)];
    grid.labels = vec![
        ("A".to_string(), cell(0, n - 1)),
        ("B".to_string(), cell(n - 1, n - 1)),
    ];
    let arena = grid.build().unwrap();
    let product = Hypergame::new(&arena, &dfa1, &dfa2, States::Full).unwrap();
    let paper = PaperGame::new(&product);
    let game = paper.view(&product);
    let adversary = AdversaryModel::new(&game, &SigmaL::Uniform).unwrap();
    let built = HypergameMdp::build(&game, &adversary, Risk::Paper).unwrap();
    let mdp = built.mdp();
    println!(
        "{n}x{n}: {} MDP states, {} transitions",
        mdp.num_states(),
        mdp.num_transitions()
    );
    let region = |width: f64| {
        let mut intervals = Intervals::exact(mdp);
        for choice in mdp.all_choices() {
            if mdp.targets(choice).len() < 2 {
                continue;
            }
            let bounds: Vec<[f64; 2]> = mdp
                .successors(choice)
                .map(|(_, p)| [(p - width).max(0.0), (p + width).min(1.0)])
                .collect();
            intervals.set(mdp, choice, &bounds).unwrap();
        }
        intervals
    };
    println!(
        "{:>5} {:>10} {:>8} {:>10} {:>8} {:>6} {:>10}",
        "g", "region", "nominal", "robust s", "ratio", "sweeps", "value h0"
    );
    for g in [0.99, 1.0] {
        let options = SolveOptions {
            discount: Discount::new(g).unwrap(),
            ..SolveOptions::default()
        };
        let start = Instant::now();
        let nominal = solve(mdp, &options).unwrap();
        let nominal_s = start.elapsed().as_secs_f64();
        let s0 = mdp.initial();
        for (name, width) in [("exact", 0.0), ("+-0.05", 0.05), ("[0,1]", 1.0)] {
            let intervals = region(width);
            let start = Instant::now();
            let solution = robust::solve(mdp, &intervals, &options).unwrap();
            let robust_s = start.elapsed().as_secs_f64();
            println!(
                "{g:>5} {name:>10} {nominal_s:>8.2} {robust_s:>10.2} {:>8.2} {:>6} {:>10.4}",
                robust_s / nominal_s,
                solution.iterations(),
                solution.value(s0).lower
            );
        }
        println!(
            "{g:>5} {:>10} nominal value at h0 {:.4}, {} sweeps",
            "",
            nominal.value(s0).lower,
            nominal.iterations()
        );
    }
}

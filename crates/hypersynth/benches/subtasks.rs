//! The general form (DESIGN.md 3.8) at k = 4 on a 12×12 gridworld: product, the 2^4 − 1 regions
//! (and psi's), the general MDP, its certified solution and the controller's evaluation, with
//! sizes, times and the peak resident memory of each stage.
//!
//! `cargo bench --bench subtasks [-- SIDE]` (default 12). The regions are computed twice, on one
//! thread and on all, to show what running the 2^k − 1 attractors side by side gains. The gridworld comes from the generator
//! with about 10% obstacles (a fixed pattern), the robot starting west and the adversary east,
//! labelled cells A, B, C, D near the four corners and E in the middle of the south edge; tasks
//! `!O U A`, `!O U B`, `!O U C`, `!O U D` (200, 100, 50, 50; all four 600); sigma_L random
//! (seed 1), risk paper. Two beliefs: `!O U A` (a sub-task: no automaton added) and `!O U E`
//! (a decoy: its automaton doubles the product). Peak memory is VmHWM from /proc/self/status,
//! reset before each stage through /proc/self/clear_refs (Linux only; "-" elsewhere).

mod common;
mod memory;

use std::time::Instant;

use hypersynth::arena::gridworld::{Cell, Gridworld};
use hypersynth::automata::Dfa;
use hypersynth::game::{Belief, Hypergame, States, SubsetPayoffs, TaskRegions, TaskSet};
use hypersynth::mdp::solve::{Discount, SolveOptions, solve};
use hypersynth::opportunistic::adversary::{AdversaryModel, SigmaL};
use hypersynth::opportunistic::evaluate::ControllerEvaluation;
use hypersynth::opportunistic::subtasks::{Risk, SubtaskController, SubtaskGame, SubtaskMdp};

fn gridworld(n: u32) -> Gridworld {
    let cell = |x, y| Cell { x, y };
    common::gridworld(
        n,
        &[
            ("A", cell(0, n - 1)),
            ("B", cell(n - 1, n - 1)),
            ("C", cell(0, 0)),
            ("D", cell(n - 1, 0)),
            ("E", cell(n / 2, 0)),
        ],
    )
}

/// Runs `stage`, printing its name, time and peak memory and `describe`'s sizes.
fn stage<T>(name: &str, run: impl FnOnce() -> T, describe: impl FnOnce(&T) -> String) -> T {
    memory::reset_peak();
    let start = Instant::now();
    let value = run();
    let ms = start.elapsed().as_secs_f64() * 1e3;
    println!(
        "  {name:<22} {ms:>9.1} ms  peak {:>8} MiB  {}",
        memory::peak_text(),
        describe(&value)
    );
    value
}

fn main() {
    let side = common::side_argument(12);
    let arena = gridworld(side).build().unwrap();
    let tasks: Vec<Dfa> = ["A", "B", "C", "D"].map(common::avoid_until).into();
    let decoy = common::avoid_until("E");
    let names: Vec<String> = ["A", "B", "C", "D"].map(String::from).into();
    let payoffs = SubsetPayoffs::new(
        &[200.0, 100.0, 50.0, 50.0],
        &[(TaskSet::all(4), 600.0)],
        &names,
    )
    .unwrap();
    println!(
        "{side}x{side} gridworld: {} arena states, {} transitions; k = 4; {} threads",
        arena.num_states(),
        arena.num_transitions(),
        std::thread::available_parallelism().map_or(1, usize::from)
    );
    for (title, psi, belief) in [
        (
            "psi = !O U A (sub-task A)",
            None,
            Belief::Tasks(TaskSet(0b0001)),
        ),
        ("psi = !O U E (decoy)", Some(&decoy), Belief::Automaton),
    ] {
        println!("{title}");
        let mut automata: Vec<(&str, &Dfa)> =
            names.iter().map(String::as_str).zip(&tasks).collect();
        automata.extend(psi.map(|dfa| ("psi", dfa)));
        let product = stage(
            "product",
            || Hypergame::with_automata(&arena, &automata, States::Full).unwrap(),
            |p| format!("{} states, {} edges", p.num_states(), p.num_edges()),
        );
        let sequential = stage(
            "regions, 1 thread",
            || TaskRegions::compute_on(&product, 4, belief, 1),
            |r| format!("|Win(all)| = {}", r.win(TaskSet::all(4)).len()),
        );
        drop(sequential);
        let regions = stage(
            "regions, all threads",
            || TaskRegions::compute(&product, 4, belief),
            |r| format!("|Win(all)| = {}", r.win(TaskSet::all(4)).len()),
        );
        let game = SubtaskGame::new(&product, &regions, &payoffs, &names);
        let adversary = AdversaryModel::new(&game, &SigmaL::Random { seed: 1 }).unwrap();
        let built = stage(
            "MDP build",
            || SubtaskMdp::build(&game, &adversary, Risk::Paper).unwrap(),
            |m| {
                format!(
                    "{} states, {} choices, {} transitions",
                    m.mdp().num_states(),
                    m.mdp().num_choices(),
                    m.mdp().num_transitions()
                )
            },
        );
        for g in [0.99, 1.0] {
            let options = SolveOptions {
                discount: Discount::new(g).unwrap(),
                ..SolveOptions::default()
            };
            let solution = stage(
                &format!("solve g = {g}"),
                || solve(built.mdp(), &options).unwrap(),
                |s| {
                    format!(
                        "{} sweeps, V(h0) = {:.3}",
                        s.iterations(),
                        s.value(built.node(product.initial())).lower
                    )
                },
            );
            let controller = SubtaskController {
                game: &game,
                mdp: &built,
                solution: &solution,
            };
            stage(
                &format!("evaluate g = {g}"),
                || ControllerEvaluation::new(&controller, &adversary, 1e-6, 100_000).unwrap(),
                |e| format!("collects {:.3}", e.value(product.initial()).lower),
            );
        }
    }
}

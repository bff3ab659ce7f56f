//! The general form (docs/semantics.md §8) against the paper's form, and at k = 4.
//!
//! First, the cost per product state of the one pipeline on the same map: the paper's form (A
//! and B, the adversary believing A) and the general form with three sub-tasks (A, B and C, the
//! adversary believing A), each run whole through `pipeline::run` at g = 0.99, stage by stage
//! (the library's own timings), with the ratio general / paper of the seconds per product state.
//!
//! Then k = 4 on the same map: product, the 2^4 − 1 regions (and psi's), the MDP, its certified
//! solution and the controller's evaluation, with sizes, times and the peak resident memory of
//! each stage.
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

use hypersynth::arena::Arena;
use hypersynth::arena::gridworld::{Cell, Gridworld};
use hypersynth::automata::Dfa;
use hypersynth::game::{Belief, Hypergame, States, SubsetPayoffs, TaskRegions, TaskSet};
use hypersynth::mdp::solve::{Discount, SolveOptions, solve};
use hypersynth::opportunistic::adversary::{AdversaryModel, SigmaL};
use hypersynth::opportunistic::build::{HypergameMdp, Risk};
use hypersynth::opportunistic::controller::Controller;
use hypersynth::opportunistic::evaluate::ControllerEvaluation;
use hypersynth::opportunistic::presentation::Presentation;
use hypersynth::opportunistic::view::SolvedHypergame;
use hypersynth::pipeline::{self, Believed, MdpOptions, Problem, Requests, Subtask, Task, Tasks};
use hypersynth::stage::{Stage, Timings};
use hypersynth::testing::avoid_until;

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

/// The whole pipeline on `arena` with the sub-tasks `names` (each `!O U NAME`, the adversary
/// believing the first), at g = 0.99: the product's size and the library's stage timings.
fn run_form(arena: &Arena, names: &[&str], payoffs: &[f64]) -> (bool, usize, Timings) {
    let subtasks: Vec<Subtask> = names
        .iter()
        .map(|&name| Subtask {
            name: name.to_string(),
            task: Task::from_automaton(&format!("!O U {name}"), &avoid_until("O", name)),
        })
        .collect();
    let named: Vec<String> = names.iter().map(|n| n.to_string()).collect();
    let payoffs = SubsetPayoffs::new(payoffs, &[], &named).unwrap();
    let believed = Believed::Tasks {
        formula: format!("!O U {}", names[0]),
        set: TaskSet(1),
    };
    let tasks = Tasks::new(subtasks, payoffs, believed, Risk::Paper);
    let paper = tasks.presentation().whole_task().is_some();
    let problem = Problem {
        arena_name: "bench".to_string(),
        arena: arena.clone(),
        map: None,
        tasks,
        states: States::Full,
        mdp: Some(MdpOptions {
            sigma_l: SigmaL::Random { seed: 1 },
            seed: 1,
            solve: SolveOptions {
                discount: Discount::new(0.99).unwrap(),
                ..SolveOptions::default()
            },
            learnt: None,
        }),
    };
    let mut timings = Timings::default();
    let outcome = pipeline::run(&problem, &Requests::default(), &mut timings).unwrap();
    (paper, outcome.report.games.product_states, timings)
}

fn main() {
    let side = common::side_argument(12);
    let arena = gridworld(side).build().unwrap();
    println!("{side}x{side} gridworld, g = 0.99: seconds per million product states");
    let paper = run_form(&arena, &["A", "B"], &[200.0, 100.0]);
    let general = run_form(&arena, &["A", "B", "C"], &[200.0, 100.0, 50.0]);
    assert!(
        paper.0 && !general.0,
        "the paper's preset and a general problem"
    );
    println!(
        "  {:<12} {:>14} {:>14} {:>8}",
        "stage", "paper (k = 2)", "general (k = 3)", "ratio"
    );
    let per_state = |(_, states, timings): &(bool, usize, Timings), stage: Option<Stage>| {
        let seconds = stage.map_or(timings.total(), |stage| timings.get(stage));
        seconds * 1e6 / *states as f64
    };
    for stage in Stage::ALL.iter().copied().map(Some).chain([None]) {
        let (p, g) = (per_state(&paper, stage), per_state(&general, stage));
        if p == 0.0 && g == 0.0 {
            continue;
        }
        let name = stage.map_or("total".to_string(), |stage| format!("{stage:?}"));
        println!("  {name:<12} {p:>14.3} {g:>14.3} {:>8.2}", g / p);
    }
    println!("  product states: paper {}, general {}", paper.1, general.1);
    let tasks: Vec<Dfa> = ["A", "B", "C", "D"]
        .map(|goal| avoid_until("O", goal))
        .into();
    let decoy = avoid_until("O", "E");
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
        let presentation = Presentation::general(names.clone());
        let game = SolvedHypergame::new(&product, &regions, &payoffs, &presentation);
        let adversary = AdversaryModel::new(&game, &SigmaL::Random { seed: 1 }).unwrap();
        let built = stage(
            "MDP build",
            || HypergameMdp::build(&game, &adversary, Risk::Paper).unwrap(),
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
            let controller = Controller {
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

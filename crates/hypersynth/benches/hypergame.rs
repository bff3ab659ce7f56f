//! Hypergame stages on two-agent gridworlds of growing size: product, attractors, partition and
//! strategies, with product size, time per stage and peak memory, to show time linear in edges.
//!
//! `cargo bench --bench hypergame [-- MAX_SIDE]` (default 30). The arena comes from the gridworld
//! generator: an n×n grid with about 10% obstacles (a fixed pseudo-random pattern), the robot
//! (8 moves) starting west, the adversary (N S E W STAY) east, players blocking each other, `A`
//! west and `B` north-east. Tasks `!O U A` and `!O U B`.

mod common;
mod memory;

use hypersynth::game::Wins;
use std::time::Instant;

use hypersynth::game::{Belief, Hypergame, Partition, ReactiveStrategy, States, TaskRegions};
use hypersynth::testing::{PHI, PHI1, PHI2, avoid_until};

fn seconds(start: Instant) -> f64 {
    start.elapsed().as_secs_f64()
}

fn main() {
    let max_side = common::side_argument(30);
    let (d1, d2) = (avoid_until("O", "A"), avoid_until("O", "B"));
    println!(
        "| grid | arena states | product states | product edges | arena (s) | product (s) | \
         attractors (s) | partition (s) | strategies (s) | ns/edge product | ns/edge attr | \
         peak MiB | Win(phi1) | Win(phi2) | Win(phi) | h0 |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for n in (5..=max_side).step_by(5) {
        memory::reset_peak();
        let start = Instant::now();
        let arena = common::gridworld(
            n,
            &[
                ("A", common::cell(0, n / 2 + 1)),
                ("B", common::cell(n - 1, n - 1)),
            ],
        )
        .build()
        .unwrap();
        let t_arena = seconds(start);

        let start = Instant::now();
        let game = Hypergame::new(&arena, &d1, &d2, States::Full).unwrap();
        let t_product = seconds(start);

        let start = Instant::now();
        let regions = TaskRegions::compute(&game, 2, Belief::Tasks(PHI1));
        let t_attractors = seconds(start);

        let start = Instant::now();
        let partition = Partition::compute(&game, &regions);
        let t_partition = seconds(start);

        let start = Instant::now();
        let strategies: Vec<ReactiveStrategy> = [PHI1, PHI2, PHI]
            .into_iter()
            .flat_map(|set| {
                let win = regions.win(set);
                [
                    ReactiveStrategy::robot(&game, win),
                    ReactiveStrategy::adversary(&game, win),
                ]
            })
            .collect();
        let t_strategies = seconds(start);
        assert_eq!(strategies.len(), 6);
        let total: usize = partition.iter().map(|(_, c)| c.total).sum();
        assert_eq!(total, game.num_states());

        let edges = game.num_edges() as f64;
        println!(
            "| {n}×{n} | {} | {} | {} | {t_arena:.3} | {t_product:.3} | {t_attractors:.3} | \
             {t_partition:.3} | {t_strategies:.3} | {:.1} | {:.1} | {} | {} | {} | {} | {} |",
            arena.num_states(),
            game.num_states(),
            game.num_edges(),
            t_product * 1e9 / edges,
            t_attractors * 1e9 / edges / 3.0,
            memory::peak_mib().map_or("?".to_string(), |m| format!("{m:.0}")),
            regions.win(PHI1).len(),
            regions.win(PHI2).len(),
            regions.win(PHI).len(),
            regions.win_label(game.initial()),
        );
    }
}

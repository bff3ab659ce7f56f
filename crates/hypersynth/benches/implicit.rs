//! The implicit engine's product and winning regions against the explicit engine's, on
//! gridworlds too large to expand: per side and engine, in its own process so that its peak
//! memory is its own, the product states, the seconds to build the product (the explicit
//! engine: the arena, then the product with its predecessor lists) and to compute the regions
//! of the paper's three sets, the peak resident memory and bytes per product state at that
//! peak, the regions' sizes (the same in both engines) and the label of h0.
//!
//! `cargo bench --bench implicit [-- [--explicit] [--blocks W] SIDE...]` (default 40 64 100;
//! the explicit engine only with `--explicit`). Side 40 is `gridworld_40`'s world (four
//! obstacles); other sides are the benchmarks' common gridworld (about 10% obstacles). The
//! tasks are the case study's, `!O U A` and `!O U B`.
//!
//! `--blocks W` also splits the index space into W blocks of consecutive robot-cell rows (the
//! plan of a distributed engine, ARCHITECTURE.md) and counts, per sweep over every edge, the
//! states whose value a block must receive from another block: the bytes a sweep exchanges at
//! 16 bytes (two bounds) per such state.

mod common;
mod memory;

use std::time::Instant;

use bit_set::BitSet;
use hypersynth::arena::gridworld::{Cell, Gridworld};
use hypersynth::game::{Belief, Hypergame, States, TaskRegions, TaskSet};
use hypersynth::implicit::{MapMoves, Moves, Regions, Space};
use hypersynth::testing::avoid_until;

/// `gridworld_40`'s world at side 40, the common gridworld otherwise.
fn world(n: u32) -> Gridworld {
    let cell = |x, y| Cell { x, y };
    let labels = [("A", cell(n / 4, n / 4)), ("B", cell(n - 1, n - 1))];
    if n != 40 {
        return common::gridworld(n, &labels);
    }
    let mut grid = Gridworld::new(n, n, cell(0, n / 2), cell(n - 1, n / 2));
    let (c, d) = (n / 2 - 1, n / 2 + 1);
    grid.obstacles = vec![cell(c, c), cell(c, d), cell(d, c), cell(d, d)];
    grid.labels = labels.iter().map(|&(l, c)| (l.to_string(), c)).collect();
    grid
}

const SETS: [TaskSet; 3] = [TaskSet(0b01), TaskSet(0b10), TaskSet(0b11)];

fn one(n: u32, explicit: bool, blocks: Option<usize>) {
    let world = world(n);
    let (dfa1, dfa2) = (avoid_until("O", "A"), avoid_until("O", "B"));
    let belief = Belief::Tasks(TaskSet(0b01));
    memory::reset_peak();
    let start = Instant::now();
    let (states, build, regions, sizes, label) = if explicit {
        let arena = world.build_without_display_names().expect("a valid world");
        let game = Hypergame::new(&arena, &dfa1, &dfa2, States::Full).expect("a product");
        let build = start.elapsed().as_secs_f64();
        let start = Instant::now();
        let won = TaskRegions::compute(&game, 2, belief);
        let seconds = start.elapsed().as_secs_f64();
        let sizes = SETS.map(|set| won.win(set).len());
        let label = won.win_label(game.initial()).to_string();
        (game.num_states(), build, seconds, sizes, label)
    } else {
        let moves = MapMoves::new(&world).expect("a valid world");
        let space = Space::new(&moves, &[&dfa1, &dfa2]).expect("a product");
        let build = start.elapsed().as_secs_f64();
        let start = Instant::now();
        let won = Regions::compute(&space, 2, belief);
        let seconds = start.elapsed().as_secs_f64();
        let sizes = SETS.map(|set| won.win(set).len());
        let label = won.win_label(space.initial()).to_string();
        if let Some(blocks) = blocks {
            exchange(&space, &moves, blocks);
        }
        (space.num_states(), build, seconds, sizes, label)
    };
    let peak = memory::peak_mib().unwrap_or(f64::NAN);
    println!(
        "{n:>4} {:>8} {states:>11} {build:>8.2} {regions:>8.2} {peak:>9.1} {:>7.1} {:>11} {:>11} {:>11}  {label}",
        if explicit { "explicit" } else { "implicit" },
        peak * 1048576.0 / states as f64,
        sizes[0],
        sizes[1],
        sizes[2],
    );
}

/// Splits the index space into `blocks` blocks of robot-cell rows and counts the states each
/// block reads from the others in one sweep over every edge (each counted once per block).
fn exchange(space: &Space<'_, MapMoves>, moves: &MapMoves, blocks: usize) {
    let height = (0..moves.num_states() as u32)
        .map(|s| moves.cells(s).0.y)
        .max()
        .unwrap_or(0)
        + 1;
    let block_of = |h: u32| {
        let y = moves.cells(space.arena_state(h)).0.y as usize;
        y * blocks / height as usize
    };
    let mut received = 0u64;
    let start = Instant::now();
    for b in 0..blocks {
        let mut needed = BitSet::with_capacity(space.num_states());
        for h in 0..space.num_states() as u32 {
            if block_of(h) != b {
                continue;
            }
            space.edges(h, |_, t| {
                if block_of(t) != b {
                    needed.insert(t as usize);
                }
            });
        }
        received += needed.len() as u64;
    }
    println!(
        "     blocks {blocks}: a sweep exchanges {received} states' values, {:.1} MiB at 16 bytes \
         each ({:.2}% of the states; counted in {:.1} s)",
        received as f64 * 16.0 / 1048576.0,
        100.0 * received as f64 / space.num_states() as f64,
        start.elapsed().as_secs_f64()
    );
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let blocks = args
        .iter()
        .position(|a| a == "--blocks")
        .and_then(|i| args.get(i + 1)?.parse().ok());
    if let [flag, side, rest @ ..] = args.as_slice()
        && flag == "--one"
    {
        let explicit = rest.iter().any(|a| a == "--explicit");
        one(side.parse().expect("a side"), explicit, blocks);
        return;
    }
    let explicit = args.iter().any(|a| a == "--explicit");
    let sides: Vec<u32> = args
        .iter()
        .enumerate()
        .filter(|&(i, _)| i == 0 || args[i - 1] != "--blocks")
        .filter_map(|(_, a)| a.parse().ok())
        .collect();
    let sides = if sides.is_empty() {
        vec![40, 64, 100]
    } else {
        sides
    };
    println!(
        "side   engine     product    build  regions  peak MiB B/state   Win(phi1)   Win(phi2)    Win(phi)  h0"
    );
    for side in sides {
        let engines: &[bool] = if explicit { &[true, false] } else { &[false] };
        for &engine in engines {
            let mut command =
                std::process::Command::new(std::env::current_exe().expect("own path"));
            command.args(["--one", &side.to_string()]);
            if engine {
                command.arg("--explicit");
            }
            if let Some(blocks) = blocks {
                command.args(["--blocks", &blocks.to_string()]);
            }
            let status = command.status().expect("the benchmark runs itself");
            assert!(status.success(), "side {side} failed");
        }
    }
}

//! What the benchmarks share: gridworlds with a fixed pseudo-random pattern of about 10%
//! obstacles, and a grid side from the command line. Each benchmark uses a part of it; the
//! automata and the paper's view of a product are the library's test helpers
//! (`hypersynth::testing`).
#![allow(dead_code)]

use hypersynth::arena::gridworld::{Cell, Gridworld};

/// An n×n gridworld from the generator: the robot starting west (`(0, n/2)`), the adversary
/// east, the given labelled cells, and obstacles where `(7919 x + 104729 y) mod 10 = 3`
/// (never on a start or a labelled cell).
pub fn gridworld(n: u32, labels: &[(&str, Cell)]) -> Gridworld {
    let cell = |x, y| Cell { x, y };
    let mut grid = Gridworld::new(n, n, cell(0, n / 2), cell(n - 1, n / 2));
    let mut keep = vec![grid.robot, grid.adversary];
    keep.extend(labels.iter().map(|&(_, c)| c));
    grid.obstacles = (0..n)
        .flat_map(|x| (0..n).map(move |y| cell(x, y)))
        .filter(|c| !keep.contains(c) && (c.x * 7919 + c.y * 104_729) % 10 == 3)
        .collect();
    grid.labels = labels.iter().map(|&(l, c)| (l.to_string(), c)).collect();
    grid
}

/// A cell of the grid.
pub fn cell(x: u32, y: u32) -> Cell {
    Cell { x, y }
}

/// The benchmark's first numeric argument (a grid side), or `default`.
pub fn side_argument(default: u32) -> u32 {
    std::env::args()
        .skip(1)
        .find_map(|a| a.parse().ok())
        .unwrap_or(default)
}

//! What the benchmarks share: gridworlds with a fixed pseudo-random pattern of about 10%
//! obstacles, and the DFA of `!O U goal`.
//! Each benchmark uses a part of it.
#![allow(dead_code)]

use hypersynth::arena::gridworld::{Cell, Gridworld};
use hypersynth::automata::{Dfa, Guard};
use hypersynth::game::{Belief, Hypergame, Payoffs, SubsetPayoffs, TaskRegions, TaskSet};
use hypersynth::opportunistic::presentation::Presentation;
use hypersynth::opportunistic::view::SolvedHypergame;

/// The paper's `phi1`, `phi2` and `phi` as sets of its two sub-tasks.
pub const PHI1: TaskSet = TaskSet(0b01);
/// `phi2`.
pub const PHI2: TaskSet = TaskSet(0b10);
/// `phi`.
pub const PHI: TaskSet = TaskSet(0b11);

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

/// `!O U goal` over [O, goal]: 0 initial, 1 final, 2 rejecting sink.
pub fn avoid_until(goal: &str) -> Dfa {
    let (o, g) = (Guard::literal(0, true), Guard::literal(1, true));
    let edges = vec![
        vec![(g.clone(), 1), (o.or(&g).not(), 0), (o.and(&g.not()), 2)],
        vec![(Guard::always(), 1)],
        vec![(Guard::always(), 2)],
    ];
    Dfa::new(
        vec!["O".into(), goal.into()],
        0,
        [1].into_iter().collect(),
        edges,
    )
    .unwrap()
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

/// What the MDP stage's view of a product of the paper's two tasks borrows: its regions (the
/// adversary believing phi1), the case study's payoffs on the sets, and the paper's
/// presentation.
pub struct Paper {
    pub regions: TaskRegions,
    pub payoffs: SubsetPayoffs,
    pub presentation: Presentation,
}

impl Paper {
    /// The attractors of `product` (on all threads).
    pub fn new(product: &Hypergame) -> Paper {
        let presentation = Presentation::paper("phi");
        Paper {
            regions: TaskRegions::compute(product, 2, Belief::Tasks(PHI1)),
            payoffs: Payoffs::default().subsets(presentation.names()),
            presentation,
        }
    }

    /// The MDP stage's view of `product`.
    pub fn view<'g, 'a>(&'g self, product: &'g Hypergame<'a>) -> SolvedHypergame<'g, 'a> {
        SolvedHypergame::new(product, &self.regions, &self.payoffs, &self.presentation)
    }
}

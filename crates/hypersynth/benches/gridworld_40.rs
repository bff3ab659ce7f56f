//! The scale target: an n×n gridworld with 4 obstacles and labels A and B, through
//! product, attractors, adversary model, MDP build and solve at g = 1, in process, for n = 10,
//! 20, 30 and 40 (about 10^7 product states), each size in its own process so that its peak
//! memory is its own.
//!
//! `cargo bench --bench gridworld_40 [-- SIDE...]` (default 10 20 30 40). Per size: product
//! states, the seconds of each stage and their total, peak resident memory (VmHWM, Linux) and
//! bytes per product state at that peak. Target at 40: total under 60 s, peak under 8 GiB.
//!
//! `-- --stages SIDE...` also prints, per stage, to standard error: its own peak and what is
//! still resident when it ends (VmHWM reset before each stage, VmRSS after it), in MiB and in
//! bytes per product state, and the same for the bytes live on the heap (a counting allocator),
//! with the sizes of the product and the MDP, and the seconds of the solver's two stages.

mod memory;

use std::time::Instant;

use hypersynth::arena::gridworld::{Cell, Gridworld};
use hypersynth::game::{Hypergame, States};
use hypersynth::mdp::solve::{SolveOptions, solve_observed};
use hypersynth::opportunistic::adversary::{AdversaryModel, SigmaL};
use hypersynth::opportunistic::build::{HypergameMdp, Risk};
use hypersynth::stage::{Observer, Stage};
use hypersynth::testing::PaperGame;
use hypersynth::testing::avoid_until;

#[global_allocator]
static HEAP: memory::Counting = memory::Counting;

/// Per stage: its name, its own peak and the resident set at its end, then the same two for
/// the bytes live on the heap (MiB). The overall peak is the largest stage peak (the peaks are
/// reset at each stage's start). The solver's two stages also keep their seconds.
#[derive(Default)]
struct Meter {
    stages: Vec<(&'static str, [f64; 4])>,
    seconds: Vec<(&'static str, f64)>,
}

impl Meter {
    fn start(&mut self) {
        memory::reset_peak();
        memory::reset_heap_peak();
    }

    fn end(&mut self, name: &'static str) {
        let peak = memory::peak_mib().unwrap_or(f64::NAN);
        let now = memory::current_mib().unwrap_or(f64::NAN);
        let heap = [memory::heap_peak_mib(), memory::heap_mib()];
        self.stages.push((name, [peak, now, heap[0], heap[1]]));
    }

    fn peak(&self) -> Option<f64> {
        let peak = self.stages.iter().map(|s| s.1[0]).fold(f64::NAN, f64::max);
        (!peak.is_nan()).then_some(peak)
    }
}

/// The solver's two stages, metered.
impl Observer for Meter {
    fn started(&mut self, _stage: Stage) {
        self.start();
    }
    fn finished(&mut self, stage: Stage, seconds: f64) {
        self.end(stage.name());
        self.seconds.push((stage.name(), seconds));
    }
}

/// The robot starts west, the adversary east; four obstacles in a square around the centre;
/// A in the north-west quarter, B in the south-east corner.
fn world(n: u32) -> Gridworld {
    let cell = |x, y| Cell { x, y };
    let mut grid = Gridworld::new(n, n, cell(0, n / 2), cell(n - 1, n / 2));
    let (c, d) = (n / 2 - 1, n / 2 + 1);
    grid.obstacles = vec![cell(c, c), cell(c, d), cell(d, c), cell(d, d)];
    grid.labels = vec![
        ("A".to_string(), cell(n / 4, n / 4)),
        ("B".to_string(), cell(n - 1, n - 1)),
    ];
    grid
}

/// Runs every stage on the n×n world and prints one row.
fn one(n: u32, stages: bool) {
    if stages {
        memory::count_heap();
    }
    let arena = world(n)
        .build_without_display_names()
        .expect("a valid gridworld");
    let (dfa1, dfa2) = (avoid_until("O", "A"), avoid_until("O", "B"));
    let mut seconds = Vec::new();
    let mut time = |start: Instant| seconds.push(start.elapsed().as_secs_f64());
    let mut meter = Meter::default();
    meter.end("input");

    meter.start();
    let start = Instant::now();
    let mut product = Hypergame::new(&arena, &dfa1, &dfa2, States::Full).expect("a product");
    time(start);
    meter.end("product");
    meter.start();
    let start = Instant::now();
    let paper = PaperGame::new(&product);
    time(start);
    // As the pipeline does: the predecessor lists are the attractors' alone.
    product.release_predecessors();
    let game = paper.view(&product);
    meter.end("attractors");
    meter.start();
    let start = Instant::now();
    let adversary = AdversaryModel::new(&game, &SigmaL::Random { seed: 1 }).expect("a model");
    time(start);
    meter.end("adversary");
    meter.start();
    let start = Instant::now();
    let built = HypergameMdp::build(&game, &adversary, Risk::Paper).expect("an MDP");
    time(start);
    meter.end("mdp_build");
    let start = Instant::now();
    let solution =
        solve_observed(built.mdp(), &SolveOptions::default(), &mut meter).expect("a solution");
    time(start);

    let states = product.num_states();
    let total: f64 = seconds.iter().sum();
    let peak = meter.peak();
    if stages {
        let mdp = built.mdp();
        eprintln!(
            "side {n}: {states} product states, {} edges; MDP {} states, {} choices, {} \
             transitions",
            product.num_edges(),
            mdp.num_states(),
            mdp.num_choices(),
            mdp.num_transitions()
        );
        let per = |mib: f64| mib * 1048576.0 / states as f64;
        eprintln!(
            "  {:<11} {:>17} {:>17}   {:>17} {:>17}",
            "B/state (MiB)", "peak RSS", "RSS at end", "heap peak", "heap at end"
        );
        for (name, values) in &meter.stages {
            let cells: Vec<String> = values
                .iter()
                .map(|&mib| format!("{:>7.0} ({mib:>7.1})", per(mib)))
                .collect();
            eprintln!("  {name:<13} {}", cells.join("   "));
        }
        let split: Vec<String> = meter
            .seconds
            .iter()
            .map(|(name, s)| format!("{name} {s:.2} s"))
            .collect();
        eprintln!("  solver stages: {}", split.join(", "));
    }
    let per_state = peak.map_or_else(
        || "-".to_string(),
        |mib| format!("{:.0}", mib * 1048576.0 / states as f64),
    );
    let value = solution.value(built.mdp().initial());
    let row: Vec<String> = seconds.iter().map(|s| format!("{s:>8.2}")).collect();
    println!(
        "{n:>4} {states:>10} {} {total:>8.2} {:>9} {per_state:>7}  [{:.3}, {:.3}]",
        row.join(" "),
        peak.map_or_else(|| "-".to_string(), |mib| format!("{mib:.1}")),
        value.lower,
        value.upper
    );
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if let [flag, side, rest @ ..] = args.as_slice()
        && flag == "--one"
    {
        one(
            side.parse().expect("a side"),
            rest.iter().any(|a| a == "--stages"),
        );
        return;
    }
    let stages = args.iter().any(|a| a == "--stages");
    let sides: Vec<u32> = args.iter().filter_map(|a| a.parse().ok()).collect();
    let sides = if sides.is_empty() {
        vec![10, 20, 30, 40]
    } else {
        sides
    };
    println!(
        "{:>4} {:>10} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>9} {:>7}  value at h0",
        "side",
        "product",
        "product",
        "attract",
        "adv",
        "build",
        "solve",
        "total",
        "peak MiB",
        "B/state"
    );
    for side in sides {
        let status = std::process::Command::new(std::env::current_exe().expect("own path"))
            .args(["--one", &side.to_string()])
            .args(stages.then_some("--stages"))
            .status()
            .expect("the benchmark runs itself");
        assert!(status.success(), "side {side} failed");
    }
}

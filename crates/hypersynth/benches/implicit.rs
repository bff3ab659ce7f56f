//! The implicit engine's product and winning regions against the explicit engine's, on
//! gridworlds too large to expand: per side and engine, in its own process so that its peak
//! memory is its own, the product states, the seconds to build the product (the explicit
//! engine: the arena, then the product with its predecessor lists) and to compute the regions
//! of the paper's three sets, the peak resident memory and bytes per product state at that
//! peak, the regions' sizes (the same in both engines) and the label of h0.
//!
//! `cargo bench --bench implicit [-- [--explicit] [--solve G [--policy]] [--blocks W] SIDE...]` (default
//! 40 64 100; the explicit engine only with `--explicit`). With `--solve G` each engine also
//! builds the MDP (sigma_L uniform, the paper's risk rule) and solves it at discount G to an
//! absolute 1e-6, and the row gives the seconds of that stage, the live states (implicit: the
//! states with bounds; explicit: the MDP's states) and the certified value of h0. Side 40 is `gridworld_40`'s world (four
//! obstacles); other sides are the benchmarks' common gridworld (about 10% obstacles). The
//! tasks are the case study's, `!O U A` and `!O U B`.
//!
//! `--policy` (with `--solve`, implicit engine) then chooses the opportunistic policy from the
//! solution and evaluates it as a Markov chain from h0 (the solution dropped first, as a
//! pipeline would once h0's bounds are read): the seconds of each, the policy's action at h0,
//! the chain's states, what it collects and its expected robot moves, and the peak resident
//! memory of the two over what was resident before them.
//!
//! `--map SIDE` prints the map of side SIDE (`hypersynth map v1`), for the command line:
//! `scripts/bench-map-export` runs both engines' whole pipeline on it, controller exported.
//!
//! `--blocks W` also splits the index space into W blocks of consecutive robot-cell rows (the
//! plan of a distributed engine, docs/semantics.md §13.4) and counts, per sweep over every edge, the
//! states whose value a block must receive from another block: the bytes a sweep exchanges at
//! 16 bytes (two bounds) per such state.

mod common;
mod memory;

use hypersynth::game::Wins;
use std::time::Instant;

use bit_set::BitSet;
use hypersynth::arena::gridworld::{Cell, Gridworld};
use hypersynth::automata::Dfa;
use hypersynth::game::{Belief, Hypergame, Payoffs, States, TaskSet};
use hypersynth::implicit::{
    Choice, MapMoves, Model, Moves, Precision, Regions, Space, evaluate, policy,
    solve as implicit_solve,
};
use hypersynth::mdp::solve::{Discount, SolveOptions, solve as mdp_solve};
use hypersynth::opportunistic::adversary::{AdversaryModel, SigmaL};
use hypersynth::opportunistic::build::{HypergameMdp, Risk};
use hypersynth::opportunistic::presentation::Presentation;
use hypersynth::testing::{PaperGame, avoid_until};

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

/// What a run measured.
struct Row {
    states: usize,
    build: f64,
    regions: f64,
    sizes: [usize; 3],
    label: String,
    /// With a solve: its seconds, the states it keeps values for, h0's interval, the sweeps.
    solve: Option<(f64, usize, f64, f64, u32)>,
    /// With `--policy`: the policy's and evaluation's figures, as printed, and the peak
    /// before them (MiB).
    policy: Option<String>,
    solve_peak: f64,
}

fn one(n: u32, explicit: bool, solve: Option<f64>, blocks: Option<usize>, with_policy: bool) {
    let world = world(n);
    let (dfa1, dfa2) = (avoid_until("O", "A"), avoid_until("O", "B"));
    memory::reset_peak();
    let row = if explicit {
        run_explicit(&world, &dfa1, &dfa2, solve)
    } else {
        run_implicit(&world, &dfa1, &dfa2, solve, blocks, with_policy)
    };
    let peak = memory::peak_mib().unwrap_or(f64::NAN);
    let peak = if row.policy.is_some() {
        // The policy's stage reset the peak: the solve's was recorded before it.
        row.solve_peak.max(peak)
    } else {
        peak
    };
    let solved = row
        .solve
        .map_or_else(String::new, |(seconds, live, lower, upper, sweeps)| {
            format!(
                "  solve {seconds:.2} s over {live} states ({sweeps} sweeps), h0 in [{lower:.6}, \
             {upper:.6}]"
            )
        });
    println!(
        "{n:>4} {:>8} {:>11} {:>8.2} {:>8.2} {peak:>9.1} {:>7.1} {:>11} {:>11} {:>11}  {}{solved}",
        if explicit { "explicit" } else { "implicit" },
        row.states,
        row.build,
        row.regions,
        peak * 1048576.0 / row.states as f64,
        row.sizes[0],
        row.sizes[1],
        row.sizes[2],
        row.label,
    );
    if let Some(line) = &row.policy {
        println!("{line}");
    }
}

fn run_explicit(world: &Gridworld, dfa1: &Dfa, dfa2: &Dfa, solve: Option<f64>) -> Row {
    let start = Instant::now();
    let arena = world.build_without_display_names().expect("a valid world");
    let mut game = Hypergame::new(&arena, dfa1, dfa2, States::Full).expect("a product");
    let build = start.elapsed().as_secs_f64();
    let start = Instant::now();
    let paper = PaperGame::new(&game);
    let regions = start.elapsed().as_secs_f64();
    game.release_predecessors();
    let sizes = SETS.map(|set| paper.regions.win(set).len());
    let label = paper.regions.win_label(game.initial()).to_string();
    let solve = solve.map(|g| {
        let start = Instant::now();
        let view = paper.view(&game);
        let adversary = AdversaryModel::new(&view, &SigmaL::Uniform).expect("a model");
        let built = HypergameMdp::build(&view, &adversary, Risk::Paper).expect("an MDP");
        let options = SolveOptions {
            discount: Discount::new(g).expect("a discount"),
            ..SolveOptions::default()
        };
        let solution = mdp_solve(built.mdp(), &options).expect("a solution");
        let value = solution.value(built.mdp().initial());
        let states = built.mdp().num_states();
        let sweeps = solution.iterations();
        (
            start.elapsed().as_secs_f64(),
            states,
            value.lower,
            value.upper,
            sweeps,
        )
    });
    Row {
        states: game.num_states(),
        build,
        regions,
        sizes,
        label,
        solve,
        policy: None,
        solve_peak: f64::NAN,
    }
}

fn run_implicit(
    world: &Gridworld,
    dfa1: &Dfa,
    dfa2: &Dfa,
    solve: Option<f64>,
    blocks: Option<usize>,
    with_policy: bool,
) -> Row {
    let start = Instant::now();
    let moves = MapMoves::new(world).expect("a valid world");
    let space = Space::new(&moves, &[dfa1, dfa2]).expect("a product");
    let build = start.elapsed().as_secs_f64();
    let start = Instant::now();
    let won = Regions::compute(&space, 2, Belief::Tasks(TaskSet(0b01)));
    let regions = start.elapsed().as_secs_f64();
    let sizes = SETS.map(|set| won.win(set).count());
    let label = won.win_label(space.initial()).to_string();
    if let Some(blocks) = blocks {
        exchange(&space, &moves, blocks);
    }
    let presentation = Presentation::paper("phi");
    let payoffs = Payoffs::default().subsets(presentation.names());
    let (mut solve_peak, mut policy_text) = (f64::NAN, None);
    let solve = solve.map(|g| {
        let start = Instant::now();
        let model = Model::new(
            &space,
            &won,
            &payoffs,
            &presentation,
            Risk::Paper,
            &SigmaL::Uniform,
        )
        .expect("a model");
        let solution =
            implicit_solve(&model, g, Precision::absolute(1e-6), 100_000).expect("a solution");
        let h0 = space.initial();
        let value = solution.value(&model, h0);
        let seconds = start.elapsed().as_secs_f64();
        let sweeps = solution.iterations();
        let live = solution.num_live();
        if with_policy {
            solve_peak = memory::peak_mib().unwrap_or(f64::NAN);
            let before = memory::current_mib().unwrap_or(f64::NAN);
            memory::reset_peak();
            let start = Instant::now();
            let chosen = policy(&model, &solution, g, 100_000).expect("a policy");
            let choosing = start.elapsed().as_secs_f64();
            drop(solution);
            let start = Instant::now();
            let evaluation = evaluate(&model, &chosen, value, 1e-6, 100_000).expect("evaluated");
            let evaluating = start.elapsed().as_secs_f64();
            let extra = memory::peak_mib().unwrap_or(f64::NAN) - before;
            let mut choices = Vec::new();
            model.choices(h0, |c| choices.push(c));
            let action = match chosen.choice(h0).map(|c| choices[usize::from(c)]) {
                Some(Choice::Move { action, .. }) => moves.actions()[action as usize].to_string(),
                Some(Choice::Stop { .. }) => "stop".to_string(),
                None => "-".to_string(),
            };
            policy_text = Some(format!(
                "     policy {choosing:.2} s, evaluation {evaluating:.2} s over {} chain states; \
                 h0 plays {action}, collects [{:.6}, {:.6}] in {:.3} expected moves; \
                 peak {extra:.1} MiB over the {before:.1} resident before",
                evaluation.states,
                evaluation.value.lower,
                evaluation.value.upper,
                evaluation.expected_moves,
            ));
        }
        (seconds, live, value.lower, value.upper, sweeps)
    });
    Row {
        states: space.num_states(),
        build,
        regions,
        sizes,
        label,
        solve,
        policy: policy_text,
        solve_peak,
    }
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
        received += needed.count() as u64;
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
    let value_of = |flag: &str| {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1))
            .cloned()
    };
    let blocks: Option<usize> = value_of("--blocks").and_then(|b| b.parse().ok());
    let solve: Option<f64> = value_of("--solve").and_then(|g| g.parse().ok());
    if let [flag, side] = args.as_slice()
        && flag == "--map"
    {
        print!(
            "{}",
            hypersynth::arena::map::write(&world(side.parse().expect("a side")))
        );
        return;
    }
    if let [flag, side, rest @ ..] = args.as_slice()
        && flag == "--one"
    {
        let explicit = rest.iter().any(|a| a == "--explicit");
        let with_policy = rest.iter().any(|a| a == "--policy");
        one(
            side.parse().expect("a side"),
            explicit,
            solve,
            blocks,
            with_policy,
        );
        return;
    }
    let explicit = args.iter().any(|a| a == "--explicit");
    let sides: Vec<u32> = args
        .iter()
        .enumerate()
        .filter(|&(i, _)| i == 0 || (args[i - 1] != "--blocks" && args[i - 1] != "--solve"))
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
            if let Some(g) = solve {
                command.args(["--solve", &g.to_string()]);
            }
            if args.iter().any(|a| a == "--policy") && !engine {
                command.arg("--policy");
            }
            let status = command.status().expect("the benchmark runs itself");
            assert!(status.success(), "side {side} failed");
        }
    }
}

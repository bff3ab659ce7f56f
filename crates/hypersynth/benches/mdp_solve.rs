//! Build and solve large MDPs, reporting times, sweeps, end components and memory.
//!
//! `cargo bench --bench mdp_solve` runs every case; `cargo bench --bench mdp_solve -- quick`
//! only those of about 10^5 states. Memory is the bytes of the model's arrays (computed from its
//! counts) and the process's peak resident set so far (VmHWM, Linux only).

mod memory;

use std::time::Instant;

use hypersynth::mdp::{Discount, Mdp, MdpBuilder, MdpState, SolveOptions, solve};
use rand_chacha::ChaCha8Rng;
use rand_core::{RngCore, SeedableRng};

fn main() {
    let quick = std::env::args().any(|arg| arg == "quick");
    let sides: &[u32] = if quick { &[316] } else { &[316, 1000] };
    for &side in sides {
        for g in [1.0, 0.9] {
            run(&format!("grid {side}x{side}"), g, || grid(side, 100));
        }
        // Every cell a hazard: no end component, so with g = 1 only the crash risk brings the
        // upper sequence down.
        run(&format!("risky grid {side}x{side}"), 1.0, || {
            grid(side, 1000)
        });
    }
    let sizes: &[u32] = if quick {
        &[100_000]
    } else {
        &[100_000, 1_000_000]
    };
    for &n in sizes {
        for g in [1.0, 0.9] {
            run(&format!("random {n}"), g, || random(n));
        }
    }
}

fn run(name: &str, g: f64, build: impl FnOnce() -> Mdp) {
    let start = Instant::now();
    let mdp = build();
    let built = start.elapsed();
    let options = SolveOptions {
        discount: Discount::new(g).expect("valid discount"),
        ..SolveOptions::default()
    };
    let start = Instant::now();
    let solution = solve(&mdp, &options).expect("the benchmark models converge");
    let solved = start.elapsed();
    println!(
        "{name:>18}  g={g:<4} states={:>8} choices={:>8} transitions={:>9}  build {:>7.3}s  \
         solve {:>7.3}s  sweeps={:>4} mecs={:>6} gap={:.1e}  model {:>6.1} MB  peak RSS {} \
         value(init)={:.4}",
        mdp.num_states(),
        mdp.num_choices(),
        mdp.num_transitions(),
        built.as_secs_f64(),
        solved.as_secs_f64(),
        solution.iterations(),
        solution.end_components(),
        solution.gap(),
        model_bytes(&mdp) as f64 / 1e6,
        memory::peak_text(),
        solution.value(mdp.initial()).midpoint(),
    );
}

/// The bytes of the model's CSR arrays: two offset arrays, one action id per choice, a target
/// (u32) and a probability (f64) per transition, a payoff (f64) per state.
fn model_bytes(mdp: &Mdp) -> u64 {
    let (n, c, t) = (
        mdp.num_states() as u64,
        mdp.num_choices() as u64,
        mdp.num_transitions() as u64,
    );
    4 * (n + 1) + 4 * c + 4 * (c + 1) + 12 * t + 8 * n
}

/// A gridworld like the hypergame's: the robot moves N/S/E/W; the adversary's reply makes the
/// move fail (stay put) with probability 0.2. 0.1% of the cells are goals (payoff 100, 200 or
/// 300); 1% offer `stop` (payoff 50); of the others, `hazard_permille` ‰ are hazards, whose
/// moves also crash (payoff 0) with probability 0.05. With g = 1 the hazard-free regions are
/// end components.
fn grid(side: u32, hazard_permille: u32) -> Mdp {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let cells = side * side;
    // Per cell: a draw in 0..1000 for its kind and one for being a hazard.
    let kinds: Vec<(u32, bool)> = (0..cells)
        .map(|_| {
            (
                rng.next_u32() % 1000,
                rng.next_u32() % 1000 < hazard_permille,
            )
        })
        .collect();
    let is_goal = |kind: u32| kind < 1;
    let has_stop = |kind: u32| (1..11).contains(&kind);
    let state = MdpState::from_u32;
    let crash = state(cells);
    let stopped = state(cells + 1);
    let mut builder = MdpBuilder::new();
    let moves = ["N", "S", "E", "W"].map(|name| builder.action(name).unwrap());
    let stop = builder.action("stop").unwrap();
    for cell in 0..cells {
        let (kind, hazard) = kinds[cell as usize];
        if is_goal(kind) {
            builder
                .add_absorbing_state(f64::from(100 * (1 + cell % 3)))
                .unwrap();
            continue;
        }
        builder.add_decision_state().unwrap();
        let (x, y) = (cell % side, cell / side);
        let neighbours = [
            (y + 1 < side).then(|| cell + side),
            (y > 0).then(|| cell - side),
            (x + 1 < side).then(|| cell + 1),
            (x > 0).then(|| cell - 1),
        ];
        let cell = state(cell);
        for (action, neighbour) in moves.iter().zip(neighbours) {
            if let Some(next) = neighbour.map(state) {
                if hazard {
                    builder
                        .add_choice(*action, &[(next, 0.75), (cell, 0.2), (crash, 0.05)])
                        .unwrap();
                } else {
                    builder
                        .add_choice(*action, &[(next, 0.8), (cell, 0.2)])
                        .unwrap();
                }
            }
        }
        if has_stop(kind) {
            builder.add_choice(stop, &[(stopped, 1.0)]).unwrap();
        }
    }
    builder.add_absorbing_state(0.0).unwrap();
    builder.add_absorbing_state(50.0).unwrap();
    builder.set_initial(MdpState::new(
        kinds.iter().position(|&(k, _)| !is_goal(k)).unwrap(),
    ));
    builder.build().unwrap()
}

/// `n` states, 1% absorbing with payoffs 1..=300, the others with three choices of three
/// uniformly random successors: one giant strongly connected core.
fn random(n: u32) -> Mdp {
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let mut builder = MdpBuilder::new();
    let actions = ["a", "b", "c"].map(|name| builder.action(name).unwrap());
    for _ in 0..n {
        if rng.next_u32() % 100 == 0 {
            builder
                .add_absorbing_state(f64::from(1 + rng.next_u32() % 300))
                .unwrap();
            continue;
        }
        builder.add_decision_state().unwrap();
        for action in actions {
            let successors = [0.5, 0.3, 0.2].map(|p| (MdpState::from_u32(rng.next_u32() % n), p));
            builder.add_choice(action, &successors).unwrap();
        }
    }
    builder.set_initial(MdpState::new(0));
    builder.build().unwrap()
}

//! Learning sigma_L on the implicit engine against the explicit one: observed runs counted over
//! the index space give the explicit product's counts and errors, the sparse confidence region
//! gives every (arena state, edge) the estimate and interval of the documented formula, computed
//! here densely, and a large map's region is built from a few runs without its arena.

use super::solve::{Engines, random_tasks, solve_both, with_model};
use crate::common::{random_arena, random_world};
use hypersynth::arena::gridworld::{Cell, Gridworld};
use hypersynth::arena::{Arena, Owner, Spelled, StateId};
use hypersynth::implicit::{ArenaMoves, MapMoves, Moves};
use hypersynth::ltl;
use hypersynth::opportunistic::adversary::SigmaL;
use hypersynth::opportunistic::build::Risk;
use hypersynth::opportunistic::observations::{
    Counts, Observations, ObservationsError, Region, record,
};
use hypersynth::opportunistic::simulate::Against;
use hypersynth::pipeline::{Believed, Subtask, Task, Tasks, sigma_l_states};
use hypersynth::translate::{Builtin, TranslationLimits};
use rand_chacha::ChaCha8Rng;
use rand_core::{RngCore, SeedableRng};

fn below(rng: &mut ChaCha8Rng, n: u32) -> u32 {
    rng.next_u32() % n
}

/// What a set of runs met, over all cases: each kind of error, and counted, sigma_W and
/// misfit steps.
#[derive(Default)]
struct Met {
    errors: std::collections::BTreeSet<String>,
    counted: u64,
    sigma_w: u64,
    misfits: u32,
}

/// `runs` random runs on the arena of `moves`, one line each, names spelled as the arena
/// format writes them: from the initial state, each step a random edge; with `faults`, now and
/// then a run starts elsewhere or a step names an action no state has, a state no arena has or
/// another state than the edge's target. Comments and blank lines between them.
fn random_runs(rng: &mut ChaCha8Rng, moves: &impl Moves, runs: u32, faults: bool) -> String {
    let n = moves.num_states() as u32;
    let mut text = String::from("# random runs\n");
    for _ in 0..runs {
        let steps = below(rng, 30);
        // 0: start elsewhere; 1: an unknown action; 2: another successor; 3: an unknown state.
        let fault = if faults { below(rng, 12) } else { 12 };
        let at = below(rng, steps.max(1));
        let mut s = match fault {
            0 => below(rng, n),
            _ => moves.initial(),
        };
        let mut words = vec![moves.name(s)];
        for i in 0..steps {
            let mut edges = Vec::new();
            moves.edges(s, |a, t, _| edges.push((a, t)));
            if edges.is_empty() {
                break;
            }
            let (a, t) = edges[below(rng, edges.len() as u32) as usize];
            words.push(match (fault, i == at) {
                (1, true) => "nothing".to_string(),
                _ => moves.actions()[a as usize].clone(),
            });
            s = match (fault, i == at) {
                (2, true) => below(rng, n),
                _ => t,
            };
            words.push(match (fault, i == at) {
                (3, true) => "nowhere".to_string(),
                _ => moves.name(s),
            });
        }
        let words: Vec<String> = words.iter().map(|w| Spelled(w).to_string()).collect();
        text.push_str(&words.join(" "));
        text.push_str(if below(rng, 4) == 0 { "\n\n" } else { "\n" });
    }
    text
}

/// The adversary steps of the runs of `text` (each `s a` pair whose `s` is an adversary state
/// of `arena`), run by run.
fn adversary_steps(text: &str, arena: &Arena) -> u64 {
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.is_empty())
        .map(|line| {
            let names: Vec<&str> = line.split(' ').collect();
            names
                .iter()
                .step_by(2)
                .take(names.len() / 2)
                .filter(|name| {
                    let s = arena.find_state(name.trim_matches('"')).unwrap();
                    arena.owner(s) == Owner::Adversary
                })
                .count() as u64
        })
        .sum()
}

/// Counts `text` in both engines' products: the same counts, or the same errors. Valid runs
/// count every adversary step once, as sigma_L's or sigma_W's, and each counted step in its
/// state's row. Returns the counts.
fn count_both<M: Moves>(
    engines: &Engines<'_, M>,
    arena: &Arena,
    text: &str,
    met: &mut Met,
    case: &str,
) -> Option<Counts> {
    let observations = Observations::parse(text).unwrap();
    let explicit = observations.count(engines.solved, &engines.explicit.adversary);
    let implicit = observations.count_on(engines.model);
    assert_eq!(implicit, explicit, "{case}: {text}");
    match explicit {
        Ok(counts) => {
            assert_eq!(counts.runs as usize, observations.num_runs(), "{case}");
            assert_eq!(
                counts.counted + counts.sigma_w_steps,
                adversary_steps(text, arena),
                "{case}: {text}"
            );
            let rows: u64 = counts
                .observed()
                .map(|(_, row)| row.iter().map(|&c| u64::from(c)).sum::<u64>())
                .sum();
            assert_eq!(rows, counts.counted, "{case}");
            met.counted += counts.counted;
            met.sigma_w += counts.sigma_w_steps;
            met.misfits += counts.misfits;
            Some(counts)
        }
        Err(errors) => {
            for error in errors.iter() {
                let kind = match error.message {
                    ObservationsError::UnknownState { .. } => "unknown state",
                    ObservationsError::NotInitial { .. } => "not initial",
                    ObservationsError::UnknownAction { .. } => "unknown action",
                    ObservationsError::NotATransition { .. } => "not a transition",
                    _ => "other",
                };
                met.errors.insert(kind.to_string());
            }
            None
        }
    }
}

/// The estimate and interval `[p_hat, lower, upper]` of every edge of an adversary state with
/// counts `row`, by the formula of the module documentation written out: `K` pairs in the union
/// bound, confidence `1 − delta`.
fn formula(row: &[u32], pairs: u32, delta: f64) -> (Vec<[f64; 3]>, Option<f64>) {
    let degree = row.len();
    let n: u64 = row.iter().map(|&c| u64::from(c)).sum();
    if degree < 2 {
        return (vec![[1.0, 1.0, 1.0]; degree], None);
    }
    if n == 0 {
        return (vec![[1.0 / degree as f64, 0.0, 1.0]; degree], None);
    }
    let log = (2.0 * f64::from(pairs.max(1)) / delta).ln();
    let e = (log / (2.0 * n as f64)).sqrt();
    let rows = row
        .iter()
        .map(|&c| {
            let p = f64::from(c) / n as f64;
            [p, (p - e).max(0.0), (p + e).min(1.0)]
        })
        .collect();
    (rows, Some(e))
}

/// The region of `counts` against the dense one of the formula, on every edge of every
/// adversary state of `arena`; its listing is the observed states', in order.
fn assert_region_is_the_formula(arena: &Arena, counts: &Counts, delta: f64, case: &str) {
    let region = Region::new(counts, delta).unwrap();
    let adversary: Vec<StateId> = arena
        .states()
        .filter(|&s| arena.owner(s) == Owner::Adversary)
        .collect();
    let row = |s: StateId| -> Vec<u32> {
        counts
            .of(s)
            .map(<[u32]>::to_vec)
            .unwrap_or_else(|| vec![0; arena.edges(s).len()])
    };
    let observed = |row: &[u32]| row.iter().any(|&c| c > 0);
    let pairs: u32 = adversary
        .iter()
        .map(|&s| row(s))
        .filter(|r| r.len() >= 2 && observed(r))
        .map(|r| r.len() as u32)
        .sum();
    assert_eq!(region.pairs, pairs, "{case}");
    let mut listed = Vec::new();
    for &s in &adversary {
        let counts = row(s);
        let degree = counts.len();
        let (expected, radius) = formula(&counts, pairs, delta);
        for (edge, &[p, lower, upper]) in expected.iter().enumerate() {
            assert_eq!(region.estimate(s, edge, degree), p, "{case} {s}");
            assert_eq!(
                region.interval(s, edge, degree),
                [lower, upper],
                "{case} {s}"
            );
        }
        assert_eq!(region.radius(s), radius, "{case} {s}");
        assert_eq!(region.is_observed(s), observed(&counts), "{case} {s}");
        if observed(&counts) {
            listed.push((s, radius, expected));
        }
    }
    let rows: Vec<_> = region
        .observed()
        .map(|row| (row.state, row.radius, row.edges.to_vec()))
        .collect();
    assert_eq!(rows, listed, "{case}");
}

/// Checks, on one problem solved by both engines: runs the explicit controller records and
/// random runs with faults counted alike; the regions of the valid ones against the formula;
/// counts written as a controller file's entries and read back in either engine's arena; and
/// the sigma_L states both engines find.
fn check<M: Moves>(
    engines: &Engines<'_, M>,
    arena: &Arena,
    rng: &mut ChaCha8Rng,
    met: &mut Met,
    case: &str,
) {
    let controller = engines.explicit.controller(engines.solved);
    let recorded = record(
        &controller,
        &engines.explicit.adversary,
        1 + below(rng, 6),
        u64::from(below(rng, 1000)),
        30,
    );
    let moves = engines.model.space().moves();
    let runs = 1 + below(rng, 8);
    let faulty = random_runs(rng, moves, runs, true);
    let random = random_runs(rng, moves, runs, false);
    let delta = [0.05, 0.2, 0.5, 1e-3][below(rng, 4) as usize];
    for text in [recorded, faulty, random] {
        let Some(counts) = count_both(engines, arena, &text, met, case) else {
            continue;
        };
        assert_region_is_the_formula(arena, &counts, delta, case);
        // The entries by name, read back in either engine's arena.
        let entries = counts.entries(arena);
        assert_eq!(counts.entries(moves), entries, "{case}");
        let read = Counts::from_entries(arena, &entries);
        assert_eq!(Counts::from_entries(moves, &entries), read, "{case}");
        assert!(read.observed().eq(counts.observed()), "{case}");
        assert_eq!(read.counted, counts.counted, "{case}");
        // The sigma_L states: the same over both products.
        let region = Region::new(&counts, delta).unwrap();
        let explicit = Against {
            game: engines.solved,
            adversary: &engines.explicit.adversary,
        };
        let found = sigma_l_states(&explicit, &region);
        assert_eq!(sigma_l_states(engines.model, &region), found, "{case}");
        assert!(found.1 <= found.0, "{case}");
    }
}

/// Every kind of error was met, and steps of both rules (and with `misfits`, misfits: a map's
/// adversary rarely has a safe and an unsafe move at once).
fn report(met: &Met, misfits: bool) {
    assert_eq!(met.errors.len(), 4, "{:?}", met.errors);
    assert!(met.counted > 0 && met.sigma_w > 0);
    assert!(!misfits || met.misfits > 0);
}

#[test]
fn runs_count_alike_in_both_engines_on_random_text_arenas() {
    let mut rng = ChaCha8Rng::seed_from_u64(41);
    let mut met = Met::default();
    for case in 0..80 {
        let arena = random_arena(&mut rng, case);
        let tasks = random_tasks(&mut rng);
        let moves = ArenaMoves::new(&arena);
        let mut runs = ChaCha8Rng::seed_from_u64(u64::from(case));
        solve_both(&moves, &arena, &tasks, &mut rng, |engines| {
            check(
                engines,
                &arena,
                &mut runs,
                &mut met,
                &format!("arena {case}"),
            )
        });
    }
    report(&met, true);
}

#[test]
fn runs_count_alike_in_both_engines_on_random_maps() {
    let mut rng = ChaCha8Rng::seed_from_u64(43);
    let mut met = Met::default();
    for case in 0..60u32 {
        let world = random_world(&mut rng);
        let arena = world.build().unwrap();
        let tasks = random_tasks(&mut rng);
        let moves = MapMoves::new(&world).unwrap();
        let mut runs = ChaCha8Rng::seed_from_u64(u64::from(case));
        solve_both(&moves, &arena, &tasks, &mut rng, |engines| {
            check(engines, &arena, &mut runs, &mut met, &format!("map {case}"))
        });
    }
    report(&met, false);
}

/// One sub-task, `F a`, psi the same: the cheapest product of a large map.
fn reach_a() -> Tasks {
    let translator = Builtin::new(TranslationLimits::default());
    let subtasks = vec![Subtask {
        name: "A".into(),
        task: Task::from_formula(ltl::parse("F a").unwrap(), &translator).unwrap(),
    }];
    let names = ["A".to_string()];
    let payoffs = hypersynth::game::SubsetPayoffs::new(&[100.0], &[], &names).unwrap();
    let believed =
        Believed::from_formula(ltl::parse("F a").unwrap(), &subtasks, &translator).unwrap();
    Tasks::new(subtasks, payoffs, believed, Risk::Paper)
}

/// A 40x40 map (about 5 million arena states, twice as many product states) learns sigma_L
/// from a few runs over the index space, its arena never expanded: the counts and the region
/// hold one row per observed state, each as the formula gives it, and an unobserved state's
/// row comes from its number of edges.
#[test]
fn a_large_maps_region_holds_only_its_observed_states() {
    let side = 40;
    let world = Gridworld {
        labels: vec![(
            "a".into(),
            Cell {
                x: side - 1,
                y: side - 1,
            },
        )],
        ..Gridworld::new(side, side, Cell { x: 0, y: 0 }, Cell { x: 1, y: 0 })
    };
    let moves = MapMoves::new(&world).unwrap();
    assert_eq!(moves.num_states(), 2 * 1600 * 1600);
    let mut rng = ChaCha8Rng::seed_from_u64(47);
    let text = random_runs(&mut rng, &moves, 8, false);
    let observations = Observations::parse(&text).unwrap();
    let tasks = reach_a();
    let (counts, found) = with_model(&moves, &tasks, &SigmaL::Uniform, |model| {
        let model = model.unwrap();
        let counts = observations.count_on(&model).unwrap();
        let region = Region::new(&counts, 0.05).unwrap();
        (counts, sigma_l_states(&model, &region))
    });
    let steps = text.split(' ').count() as u64;
    assert!(counts.counted + counts.sigma_w_steps > 0);
    assert!(counts.observed().len() as u64 <= counts.counted);
    assert!(counts.counted <= steps);
    let region = Region::new(&counts, 0.05).unwrap();
    assert_eq!(region.observed().len(), counts.observed().len());
    // Every observed row as the formula gives it, and an unobserved state's by its degree.
    for (row, (s, c)) in region.observed().zip(counts.observed()) {
        assert_eq!(row.state, s);
        let (expected, radius) = formula(c, region.pairs, 0.05);
        assert_eq!((row.edges.to_vec(), row.radius), (expected, radius));
    }
    let unobserved = (moves.num_states() / 2..moves.num_states())
        .map(|s| s as u32)
        .find(|&s| !region.is_observed(StateId::from_u32(s)) && moves.degree(s) >= 2)
        .unwrap();
    let degree = moves.degree(unobserved) as usize;
    let s = StateId::from_u32(unobserved);
    assert_eq!(region.estimate(s, 0, degree), 1.0 / degree as f64);
    assert_eq!(region.interval(s, degree - 1, degree), [0.0, 1.0]);
    assert_eq!(region.radius(s), None);
    // Some sigma_L state, at most as many observed as counted rows.
    assert!(found.0 > 0 && found.0 - found.1 <= counts.observed().len() as u32);
}

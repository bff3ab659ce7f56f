//! The robust solve against hand computations, the nominal solve, and a naive robust value
//! iteration whose inner minimum enumerates the vertices of the intervals' polytope (no code
//! shared with the solver).

use super::*;
use crate::mdp::solve::solve as nominal;
use crate::mdp::testing::{
    Spec::Absorb, Spec::Decide, mdp_from, ms, random_intervals, random_mdp, rng, vertex_minimum,
};

fn options(g: f64) -> SolveOptions {
    SolveOptions {
        discount: Discount::new(g).unwrap(),
        epsilon: 1e-9,
        ..SolveOptions::default()
    }
}

/// `intervals` with the given choices (first choice of the given states) set.
fn with(mdp: &Mdp, rows: &[(u32, &[[f64; 2]])]) -> Intervals {
    let mut intervals = Intervals::exact(mdp);
    for &(state, bounds) in rows {
        let choice = mdp.choices(ms(state)).start();
        intervals.set(mdp, choice, bounds).unwrap();
    }
    intervals
}

fn assert_value(solution: &Solution, state: u32, expected: f64) {
    let value = solution.value(ms(state));
    assert!(
        value.lower <= expected + 1e-9 && expected - 1e-9 <= value.upper,
        "state {state}: {value:?}, expected {expected}"
    );
}

#[test]
fn an_adversary_that_may_send_the_run_back_forever_makes_it_worth_nothing() {
    // r0 → c1; c1 goes to r0 or to the payoff 1 (state 2), each in [0, 1]: the adversary loops.
    let mdp = mdp_from(&[
        Decide(&[("go", &[(1, 1.0)])]),
        Decide(&[("x", &[(0, 0.5), (2, 0.5)])]),
        Absorb(1.0),
    ]);
    let loose = with(&mdp, &[(1, &[[0.0, 1.0], [0.0, 1.0]])]);
    for g in [1.0, 0.9] {
        let solution = solve(&mdp, &loose, &options(g)).unwrap();
        assert_eq!(solution.value(ms(0)).upper, 0.0);
    }
    // A lower bound of 0.25 on the payoff forces the run out eventually: worth 1 at g = 1,
    // and at g = 0.9 (both choices are moves) v = 0.81 · (0.25 + 0.75 v) = 0.2025 / 0.3925.
    let forced = with(&mdp, &[(1, &[[0.0, 0.75], [0.25, 1.0]])]);
    assert_value(&solve(&mdp, &forced, &options(1.0)).unwrap(), 0, 1.0);
    let solution = solve(&mdp, &forced, &options(0.9)).unwrap();
    assert_value(&solution, 0, 0.2025 / 0.3925);
    // Upper bounds that do not add up to 1 without the payoff force it too: at least 0.4.
    let short = with(&mdp, &[(1, &[[0.0, 0.6], [0.0, 1.0]])]);
    assert_value(&solve(&mdp, &short, &options(1.0)).unwrap(), 0, 1.0);
}

#[test]
fn end_components_the_adversary_can_keep_are_deflated() {
    // r0 and r2 both move to c1, which sends the run to r0 or r2 (each in [0, 1]); r0 can stop
    // for 0.3 (state 3), r2 for 0.6 (state 4). The adversary sends every run to r0: r0 and c1
    // are worth 0.3, r2 0.6. Without deflation the upper bounds stay at 0.6 or above.
    let mdp = mdp_from(&[
        Decide(&[("go", &[(1, 1.0)]), ("stop", &[(3, 1.0)])]),
        Decide(&[("x", &[(0, 0.5), (2, 0.5)])]),
        Decide(&[("go", &[(1, 1.0)]), ("stop", &[(4, 1.0)])]),
        Absorb(0.3),
        Absorb(0.6),
    ]);
    let intervals = with(&mdp, &[(1, &[[0.0, 1.0], [0.0, 1.0]])]);
    let solution = solve(&mdp, &intervals, &options(1.0)).unwrap();
    for (state, value) in [(0, 0.3), (1, 0.3), (2, 0.6)] {
        assert_value(&solution, state, value);
    }
    assert!(solution.gap() <= 1e-9);
}

#[test]
fn at_g_1_the_policy_leaves_a_tie_the_adversary_could_loop() {
    // r0: `a` → c1 (back to r0 or to the payoff 0.5, each in [0, 1]), `b` → c2 → payoff 0.5
    // exactly. Both are worth 0.5, but `a` lets the adversary loop forever: the policy plays
    // `b`.
    let mdp = mdp_from(&[
        Decide(&[("a", &[(1, 1.0)]), ("b", &[(2, 1.0)])]),
        Decide(&[("x", &[(0, 0.5), (3, 0.5)])]),
        Decide(&[("y", &[(3, 1.0)])]),
        Absorb(0.5),
    ]);
    let intervals = with(&mdp, &[(1, &[[0.0, 1.0], [0.0, 1.0]])]);
    let solution = solve(&mdp, &intervals, &options(1.0)).unwrap();
    assert_value(&solution, 0, 0.5);
    assert_eq!(mdp.action_name(solution.policy(ms(0)).unwrap()), "b");
}

#[test]
fn intervals_are_checked() {
    let mdp = mdp_from(&[Decide(&[("x", &[(0, 0.5), (1, 0.5)])]), Absorb(1.0)]);
    let choice = mdp.choices(ms(0)).start();
    let mut intervals = Intervals::exact(&mdp);
    assert!(matches!(
        intervals.set(&mdp, choice, &[[0.0, 1.0]]),
        Err(IntervalError::Length {
            targets: 2,
            given: 1,
            ..
        })
    ));
    assert!(matches!(
        intervals.set(&mdp, choice, &[[0.6, 0.5], [0.0, 1.0]]),
        Err(IntervalError::Invalid { .. })
    ));
    assert!(matches!(
        intervals.set(&mdp, choice, &[[0.6, 0.7], [0.6, 1.0]]),
        Err(IntervalError::Infeasible { .. })
    ));
    assert!(matches!(
        intervals.set(&mdp, choice, &[[0.0, 0.4], [0.0, 0.4]]),
        Err(IntervalError::Infeasible { .. })
    ));
    assert_eq!(intervals, Intervals::exact(&mdp));
    intervals
        .set(&mdp, choice, &[[0.1, 0.9], [0.1, 0.9]])
        .unwrap();
    intervals
        .set(&mdp, choice, &[[0.2, 0.8], [0.2, 0.8]])
        .unwrap();
    assert_eq!(
        intervals.get(&mdp, choice),
        Some(&[[0.2, 0.8], [0.2, 0.8]][..])
    );
    assert_eq!(intervals.num_uncertain(), 1);
}

/// Robust value iteration from 0 (Jacobi), the inner minimum by vertex enumeration, until no
/// value moves by more than 1e-13 (or 200 000 iterations); with whether it got there.
fn naive(mdp: &Mdp, intervals: &Intervals, g: f64) -> (Vec<f64>, bool) {
    let mut values: Vec<f64> = mdp.states().map(|s| mdp.payoff(s).unwrap_or(0.0)).collect();
    for _ in 0..200_000 {
        let next: Vec<f64> = mdp
            .states()
            .map(|s| {
                if let Some(payoff) = mdp.payoff(s) {
                    return payoff;
                }
                mdp.choices(s)
                    .map(|c| {
                        let f = if mdp.is_instant(c) { 1.0 } else { g };
                        let successor: Vec<f64> =
                            mdp.targets(c).iter().map(|t| values[t.index()]).collect();
                        f * match intervals.get(mdp, c) {
                            Some(bounds) => vertex_minimum(&successor, bounds),
                            None => mdp.successors(c).map(|(t, p)| p * values[t.index()]).sum(),
                        }
                    })
                    .fold(0.0, f64::max)
            })
            .collect();
        let change = next
            .iter()
            .zip(&values)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        values = next;
        if change <= 1e-13 {
            return (values, true);
        }
    }
    (values, false)
}

#[test]
fn without_intervals_the_robust_solve_is_the_nominal_one() {
    let mut rng = rng(26);
    for _ in 0..200 {
        let mdp = random_mdp(&mut rng, 12);
        for g in [1.0, 0.8] {
            let robust = solve(&mdp, &Intervals::exact(&mdp), &options(g)).unwrap();
            let expected = nominal(&mdp, &options(g)).unwrap();
            for s in mdp.states() {
                let (a, b) = (robust.value(s), expected.value(s));
                assert!(
                    a.lower <= b.upper + 1e-8 && b.lower <= a.upper + 1e-8,
                    "{s:?}: {a:?} vs {b:?}"
                );
            }
        }
    }
}

#[test]
fn the_robust_value_is_that_of_naive_robust_value_iteration() {
    let mut rng = rng(2026);
    let mut compared = 0;
    for _ in 0..300 {
        let mdp = random_mdp(&mut rng, 10);
        let intervals = random_intervals(&mut rng, &mdp);
        for g in [1.0, 0.9] {
            let solution = solve(&mdp, &intervals, &options(g)).unwrap();
            let (values, converged) = naive(&mdp, &intervals, g);
            for s in mdp.states() {
                let bounds = solution.value(s);
                let v = values[s.index()];
                // Iterates from below never exceed the value: the upper bound is sound.
                assert!(
                    v <= bounds.upper + 1e-9,
                    "{s:?}: naive {v} above {bounds:?}"
                );
                if converged {
                    assert!(
                        v >= bounds.lower - 1e-8,
                        "{s:?}: naive {v} below {bounds:?}"
                    );
                }
            }
            compared += usize::from(converged);
            assert!(solution.gap() <= 1e-9);
        }
    }
    assert!(
        compared >= 500,
        "only {compared} of 600 naive runs converged"
    );
}

/// The expected payoff of a stationary policy against the worst adversary: naive value
/// iteration from 0 on the adversary's problem alone (the robot's choices fixed).
fn naive_policy_value(mdp: &Mdp, intervals: &Intervals, g: f64, policy: &Solution) -> Vec<f64> {
    let mut values: Vec<f64> = mdp.states().map(|s| mdp.payoff(s).unwrap_or(0.0)).collect();
    for _ in 0..200_000 {
        let next: Vec<f64> = mdp
            .states()
            .map(|s| {
                let Some(c) = policy.policy(s) else {
                    return mdp.payoff(s).unwrap_or(0.0);
                };
                let f = if mdp.is_instant(c) { 1.0 } else { g };
                let successor: Vec<f64> =
                    mdp.targets(c).iter().map(|t| values[t.index()]).collect();
                f * match intervals.get(mdp, c) {
                    Some(bounds) => vertex_minimum(&successor, bounds),
                    None => mdp.successors(c).map(|(t, p)| p * values[t.index()]).sum(),
                }
            })
            .collect();
        let change = next
            .iter()
            .zip(&values)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        values = next;
        if change <= 1e-13 {
            break;
        }
    }
    values
}

#[test]
fn the_policy_collects_the_lower_bound_against_the_worst_adversary() {
    let mut rng = rng(7);
    for _ in 0..300 {
        let mdp = random_mdp(&mut rng, 10);
        let intervals = random_intervals(&mut rng, &mdp);
        for g in [1.0, 0.9] {
            let solution = solve(&mdp, &intervals, &options(g)).unwrap();
            let collected = naive_policy_value(&mdp, &intervals, g, &solution);
            for s in mdp.states() {
                let lower = solution.value(s).lower;
                assert!(
                    collected[s.index()] >= lower - 1e-7,
                    "{s:?}: the policy collects {} < {lower}",
                    collected[s.index()]
                );
            }
        }
    }
}

#[test]
fn point_intervals_at_the_models_probabilities_give_the_nominal_value() {
    // Every choice of two targets or more gets [p, p]: the region holds the model alone.
    let mut rng = rng(11);
    for _ in 0..200 {
        let mdp = random_mdp(&mut rng, 12);
        let mut intervals = Intervals::exact(&mdp);
        for choice in mdp.all_choices() {
            let bounds: Vec<[f64; 2]> = mdp.successors(choice).map(|(_, p)| [p, p]).collect();
            if bounds.len() >= 2 {
                intervals.set(&mdp, choice, &bounds).unwrap();
            }
        }
        for g in [1.0, 0.8] {
            let robust = solve(&mdp, &intervals, &options(g)).unwrap();
            let expected = nominal(&mdp, &options(g)).unwrap();
            for s in mdp.states() {
                let (a, b) = (robust.value(s), expected.value(s));
                assert!(
                    a.lower <= b.upper + 1e-8 && b.lower <= a.upper + 1e-8,
                    "{s:?}: {a:?} vs {b:?}"
                );
            }
        }
    }
}

/// An observer with a memory ceiling and nothing in use, which records what it was asked.
struct Ceiling {
    budget: crate::limits::MemoryBudget,
    asked: Vec<(Stage, u64)>,
}

impl Observer for Ceiling {
    fn reserve(
        &mut self,
        stage: Stage,
        bytes: u64,
        what: &dyn Fn() -> String,
    ) -> Result<(), crate::limits::MemoryLimit> {
        self.asked.push((stage, bytes));
        self.budget.check(0, bytes, what)
    }
}

#[test]
fn the_robust_solve_asks_for_its_memory_and_stops_when_refused() {
    let mdp = mdp_from(&[
        Decide(&[("go", &[(1, 1.0)]), ("stop", &[(3, 1.0)])]),
        Decide(&[("x", &[(0, 0.5), (2, 0.5)])]),
        Absorb(1.0),
        Absorb(0.25),
    ]);
    let intervals = with(&mdp, &[(1, &[[0.0, 0.75], [0.25, 1.0]])]);
    // 4 states, 4 transitions, 3 choices: the nominal solver's 100 · 4 + 16 · 4 + 24 · 3 =
    // 536 bytes, and 24 · 4 = 96 more.
    let mut tiny = Ceiling {
        budget: crate::limits::MemoryBudget::new(600),
        asked: Vec::new(),
    };
    let error = solve_observed(&mdp, &intervals, &options(1.0), &mut tiny).unwrap_err();
    let SolveError::Memory(limit) = &error else {
        panic!("{error:?}");
    };
    assert_eq!(limit.needed, 632);
    assert_eq!(tiny.asked, [(Stage::RobustSolve, 632)]);
    assert_eq!(
        error.to_string(),
        "solving the interval MDP robustly (4 states, 4 transitions, 1 of 3 choices with \
         intervals) needs about 632 B more, with 0 B already in use: more than the memory limit of 600 B"
    );
    let mut enough = Ceiling {
        budget: crate::limits::MemoryBudget::new(632),
        asked: Vec::new(),
    };
    let solution = solve_observed(&mdp, &intervals, &options(1.0), &mut enough).unwrap();
    // The adversary sends the run back at least 0 and to the payoff at least 0.25 of the
    // time: the robot retries until it gets 1.
    assert_value(&solution, 0, 1.0);
}

#[test]
fn a_relative_precision_bounds_each_width_by_its_lower_bound() {
    // Values between 0 and 5 and a loose relative precision: a state worth 0.2 may have an
    // interval of width 0.01 at most, where the absolute 0.05 would allow 0.05.
    let mut rng = rng(77);
    let mut narrower = 0;
    for _ in 0..200 {
        let mdp = random_mdp(&mut rng, 10);
        let intervals = random_intervals(&mut rng, &mdp);
        for g in [1.0, 0.9] {
            let relative = SolveOptions {
                epsilon: 0.05,
                relative: true,
                ..options(g)
            };
            let solution = solve(&mdp, &intervals, &relative).unwrap();
            let exact = solve(&mdp, &intervals, &options(g)).unwrap();
            for s in mdp.states() {
                let (bounds, v) = (solution.value(s), exact.value(s));
                assert!(
                    bounds.upper - bounds.lower <= 0.05 * bounds.lower.max(0.0) + 1e-12,
                    "{s:?}: {bounds:?} wider than 5% of its lower bound"
                );
                assert!(bounds.lower <= v.upper + 1e-9 && v.lower <= bounds.upper + 1e-9);
                narrower += usize::from(bounds.upper - bounds.lower > 0.0);
            }
        }
    }
    assert!(narrower > 0, "every interval closed: nothing was tested");
}

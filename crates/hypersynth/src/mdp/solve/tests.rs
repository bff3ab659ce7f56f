//! The solver's tests: hand-computed values, and exact evaluation on random MDPs.

use super::*;
use crate::mdp::testing::{
    Spec::{Absorb, Decide},
    chain_mdp, mc, mdp_from, ms, optimal_values_by_enumeration, policy_value, random_mdp,
    random_mdp_with_weights, rng,
};

fn options(g: f64) -> SolveOptions {
    SolveOptions {
        discount: Discount::new(g).unwrap(),
        ..SolveOptions::default()
    }
}

/// Asserts that the certified interval of every state contains `expected` and is at most
/// epsilon wide.
fn assert_values(solution: &Solution, expected: &[f64]) {
    for (state, &value) in expected.iter().enumerate() {
        let Interval { lower, upper } = solution.value(MdpState::new(state));
        assert!(
            lower <= value + 1e-12 && value <= upper + 1e-12 && upper - lower <= 1e-6,
            "state {state}: expected {value}, got [{lower}, {upper}]"
        );
    }
}

#[test]
fn stop_beats_a_risky_action_unless_the_risk_is_small() {
    // 0 --stop--> 1 (payoff 200); 0 --risky--> 2 (payoff 300) w.p. p, 3 (payoff 0) w.p. 1-p.
    let build = |p: f64| {
        mdp_from(&[
            Decide(&[("stop", &[(1, 1.0)]), ("risky", &[(2, p), (3, 1.0 - p)])]),
            Absorb(200.0),
            Absorb(300.0),
            Absorb(0.0),
        ])
    };
    // p = 0.6, g = 1: stop = 200, risky = 0.6 · 300 = 180 → stop.
    let solution = solve(&build(0.6), &options(1.0)).unwrap();
    assert_values(&solution, &[200.0, 200.0, 300.0, 0.0]);
    assert_eq!(solution.policy(ms(0)), Some(mc(0)));
    assert_eq!(solution.policy(ms(1)), None);
    // p = 0.6, g = 0.9: stop = 0.9 · 200 = 180, risky = 0.9 · 180 = 162 → stop.
    let solution = solve(&build(0.6), &options(0.9)).unwrap();
    assert_values(&solution, &[180.0]);
    assert_eq!(solution.policy(ms(0)), Some(mc(0)));
    // p = 0.7, g = 1: risky = 0.7 · 300 = 210 > 200 → risky.
    let solution = solve(&build(0.7), &options(1.0)).unwrap();
    assert_values(&solution, &[210.0]);
    assert_eq!(solution.policy(ms(0)), Some(mc(1)));
    // The decision table's Q-values: stop 200, risky 210.
    let mdp = build(0.7);
    assert!((solution.choice_value(&mdp, mc(0)).midpoint() - 200.0).abs() < 1e-9);
    assert!((solution.choice_value(&mdp, mc(1)).midpoint() - 210.0).abs() < 1e-9);
}

#[test]
fn discount_prefers_near_payoffs() {
    // 0 --stop--> 4 (payoff 5); 0 --walk--> 1 --walk--> 2 --walk--> 3 (payoff 8).
    let mdp = mdp_from(&[
        Decide(&[("stop", &[(4, 1.0)]), ("walk", &[(1, 1.0)])]),
        Decide(&[("walk", &[(2, 1.0)])]),
        Decide(&[("walk", &[(3, 1.0)])]),
        Absorb(8.0),
        Absorb(5.0),
    ]);
    // g = 1: walking is worth 8 > 5.
    let solution = solve(&mdp, &options(1.0)).unwrap();
    assert_values(&solution, &[8.0, 8.0, 8.0, 8.0, 5.0]);
    assert_eq!(solution.policy(ms(0)), Some(mc(1)));
    // g = 0.9: walk = 0.9³ · 8 = 5.832 > stop = 0.9 · 5 = 4.5; V1 = 0.9² · 8, V2 = 0.9 · 8.
    let solution = solve(&mdp, &options(0.9)).unwrap();
    assert_values(&solution, &[5.832, 6.48, 7.2]);
    assert_eq!(solution.policy(ms(0)), Some(mc(1)));
    // g = 0.5: walk = 0.125 · 8 = 1 < stop = 0.5 · 5 = 2.5.
    let solution = solve(&mdp, &options(0.5)).unwrap();
    assert_values(&solution, &[2.5, 2.0, 4.0]);
    assert_eq!(solution.policy(ms(0)), Some(mc(0)));
}

/// 0 and 1 form an end component (go / back); `try` leaves it towards payoff 10 half the
/// time and loses (payoff 0) a tenth of the time, `cash` takes payoff 4. From 0 and 1 the
/// largest payoff within reach is 10, which the upper sequence starts from; inside the end
/// component it would stay there (0 and 1 keep each other's upper bounds up), so only the
/// end-component collapse lets it come down to the value. State 4 reaches payoff 20 elsewhere.
fn end_component_mdp() -> Mdp {
    mdp_from(&[
        Decide(&[("go", &[(1, 1.0)]), ("cash", &[(3, 1.0)])]),
        Decide(&[
            ("back", &[(0, 1.0)]),
            ("try", &[(2, 0.5), (0, 0.4), (6, 0.1)]),
        ]),
        Absorb(10.0),
        Absorb(4.0),
        Decide(&[("jump", &[(5, 1.0)])]),
        Absorb(20.0),
        Absorb(0.0),
    ])
}

#[test]
fn end_component_is_left_by_the_policy_when_everything_ties() {
    let mdp = end_component_mdp();
    let solution = solve(&mdp, &options(1.0)).unwrap();
    // g = 1: from 0 or 1, retrying `try` is worth V = 0.5 · 10 + 0.4 · V, V = 25/3 (> cash 4).
    let v = 25.0 / 3.0;
    assert_values(&solution, &[v, v, 10.0, 4.0, 20.0, 20.0, 0.0]);
    assert_eq!(solution.end_components(), 1);
    // In 1, `back` (choice 2) and `try` (choice 3) both have Q-value V; the lowest id would
    // loop 0 → 1 → 0 forever and collect 0. The policy must take `try`.
    assert_eq!(solution.policy(ms(0)), Some(mc(0)));
    assert_eq!(solution.policy(ms(1)), Some(mc(3)));
    let value = policy_value(
        &mdp,
        &mdp.states().map(|s| solution.policy(s)).collect::<Vec<_>>(),
        1.0,
    );
    for (state, expected) in [v, v, 10.0, 4.0, 20.0, 20.0, 0.0].into_iter().enumerate() {
        assert!(
            (value[state] - expected).abs() < 1e-9,
            "{state}: {}",
            value[state]
        );
    }
}

#[test]
fn states_that_surely_reach_their_largest_payoff_are_settled_without_iterating() {
    // Without the loss of `end_component_mdp`, retrying `try` reaches payoff 10 surely: 0 and
    // 1 are worth 10, the largest payoff they can reach, and are settled from the graph alone
    // (no sweep, no end component left to collapse); the policy still leaves the loop.
    let mdp = mdp_from(&[
        Decide(&[("go", &[(1, 1.0)]), ("cash", &[(3, 1.0)])]),
        Decide(&[("back", &[(0, 1.0)]), ("try", &[(2, 0.5), (0, 0.5)])]),
        Absorb(10.0),
        Absorb(4.0),
    ]);
    let solution = solve(&mdp, &options(1.0)).unwrap();
    for state in [0, 1] {
        assert_eq!(
            solution.value(ms(state)),
            Interval {
                lower: 10.0,
                upper: 10.0
            }
        );
    }
    assert_eq!(solution.iterations(), 0);
    assert_eq!(solution.end_components(), 0);
    assert_eq!(solution.policy(ms(1)), Some(mc(3)));
    let policy: Vec<Option<ChoiceId>> = mdp.states().map(|s| solution.policy(s)).collect();
    assert_eq!(policy_value(&mdp, &policy, 1.0)[0], 10.0);
}

#[test]
fn end_component_with_discount_is_not_collapsed() {
    let solution = solve(&end_component_mdp(), &options(0.9)).unwrap();
    // g = 0.9, guessing go in 0 and try in 1:
    //   V0 = 0.9 V1, V1 = 0.9 (0.5 · 10 + 0.4 V0) = 4.5 + 0.36 V0
    //   ⇒ V0 = 4.05 + 0.324 V0 ⇒ V0 = 4.05 / 0.676 = 2025/338, V1 = 2250/338.
    // The guess holds: cash = 0.9 · 4 = 3.6 < 2025/338 ≈ 5.99 and back = 0.9 V0 < V1.
    assert_values(
        &solution,
        &[2025.0 / 338.0, 2250.0 / 338.0, 10.0, 4.0, 18.0, 20.0, 0.0],
    );
    assert_eq!(solution.end_components(), 0);
    assert_eq!(solution.policy(ms(0)), Some(mc(0)));
    assert_eq!(solution.policy(ms(1)), Some(mc(3)));
}

#[test]
fn states_that_cannot_reach_a_payoff_are_fixed_to_zero() {
    // 1 can only loop or drop into 4 (payoff 0); 5 can loop or go to 1: both are worth 0
    // exactly. 0: a → 1 is worth 0, b is worth 0.5 · 0 + 0.5 · 6 = 3.
    let mdp = mdp_from(&[
        Decide(&[("a", &[(1, 1.0)]), ("b", &[(2, 0.5), (3, 0.5)])]),
        Decide(&[("loop", &[(1, 1.0)]), ("drop", &[(4, 1.0)])]),
        Absorb(0.0),
        Absorb(6.0),
        Absorb(0.0),
        Decide(&[("x", &[(5, 1.0)]), ("y", &[(1, 1.0)])]),
    ]);
    let solution = solve(&mdp, &options(1.0)).unwrap();
    for state in [1, 5] {
        assert_eq!(
            solution.value(ms(state)),
            Interval {
                lower: 0.0,
                upper: 0.0
            }
        );
    }
    // Only state 0 is iterated, and its successors are all fixed: a trivial component, one
    // exact step and no sweep.
    assert_eq!(
        solution.value(ms(0)),
        Interval {
            lower: 3.0,
            upper: 3.0
        }
    );
    assert_eq!(solution.iterations(), 0);
    assert_eq!(solution.gap(), 0.0);
    assert_eq!(solution.end_components(), 0);
    assert_eq!(solution.policy(ms(0)), Some(mc(1)));
}

#[test]
fn tiny_exits_are_solved_exactly_and_large_slow_components_hit_the_limit() {
    // try: payoff 1 w.p. 1e-9, payoff 0 w.p. 1e-9, else back to 0 (value 1/2): value
    // iteration would need about 1e10 sweeps; after its quick sweeps, policy iteration
    // solves the one-state component exactly in one round.
    let mdp = mdp_from(&[
        Decide(&[("try", &[(1, 1e-9), (2, 1e-9), (0, 1.0 - 2e-9)])]),
        Absorb(1.0),
        Absorb(0.0),
    ]);
    let solution = solve(&mdp, &SolveOptions::default()).unwrap();
    assert_values(&solution, &[0.5, 1.0, 0.0]);
    assert_eq!(solution.iterations(), QUICK_SWEEPS + 1);
    // A ring of 300 states (more than policy iteration takes), each moving on w.p. 0.9985,
    // to payoff 1 w.p. 0.001 and to payoff 0 w.p. 0.0005 (value 2/3): sweeps are needed, and
    // 10 are not enough.
    let n = 300u32;
    let states: Vec<Vec<(u32, f64)>> = (0..n)
        .map(|i| vec![((i + 1) % n, 0.9985), (n, 0.001), (n + 1, 0.0005)])
        .collect();
    let ring = chain_mdp(&states, &[1.0, 0.0]);
    let limited = SolveOptions {
        max_iterations: 10,
        ..SolveOptions::default()
    };
    match solve(&ring, &limited) {
        Err(SolveError::IterationLimit {
            iterations: 10,
            gap,
            epsilon,
        }) => {
            assert!(gap > 1e-3, "{gap}");
            assert_eq!(epsilon, 1e-6);
        }
        other => panic!(
            "expected the iteration limit, got {:?}",
            other.map(|s| s.gap())
        ),
    }
    let solution = solve(&ring, &SolveOptions::default()).unwrap();
    let mut expected = vec![2.0 / 3.0; n as usize];
    expected.extend([1.0, 0.0]);
    assert_values(&solution, &expected);
}

#[test]
fn tiny_exit_probabilities_and_deep_chains_agree_with_exact_evaluation() {
    let mut rng = rng(12);
    for instance in 0..200 {
        let mdp = random_mdp_with_weights(&mut rng, 8, &[1.0, 1e6]);
        let g = if instance % 2 == 0 { 1.0 } else { 0.9 };
        let solution = solve(&mdp, &options(g)).unwrap();
        let optimal = optimal_values_by_enumeration(&mdp, g);
        let policy: Vec<Option<ChoiceId>> = mdp.states().map(|s| solution.policy(s)).collect();
        let achieved = policy_value(&mdp, &policy, g);
        for s in 0..mdp.num_states() {
            let Interval { lower, upper } = solution.value(MdpState::new(s));
            let context = format!(
                "instance {instance}, g = {g}, state {s}: [{lower}, {upper}] optimal {} achieved {}: {mdp:?}",
                optimal[s], achieved[s]
            );
            assert!(upper - lower <= 1e-6, "{context}");
            assert!(
                lower <= optimal[s] + 1e-7 && optimal[s] <= upper + 1e-7,
                "{context}"
            );
            assert!(achieved[s] >= lower - 1e-6, "{context}");
        }
    }
    // A chain of 1000 states, each leaving to payoff 1 w.p. 1e-6 and otherwise moving on;
    // the last pays 5; then the same chain closed into a ring (every state worth 1, its
    // largest payoff within reach: settled before any iteration); then both again with a
    // second exit, to payoff 0 w.p. 1e-6, so that no state is worth the largest payoff it can
    // reach (the ring is then one component larger than policy iteration takes, left only
    // through the 1e-6 exits, and worth 1/2).
    let n = 1000u32;
    let p = 1e-6;
    for (ring, loss) in [(false, 0.0), (true, 0.0), (false, p), (true, p)] {
        let choices: Vec<Vec<(u32, f64)>> = (0..n)
            .map(|i| {
                let next = if i + 1 < n {
                    i + 1
                } else if ring {
                    0
                } else {
                    n + 1
                };
                let mut successors = vec![(next, 1.0 - p - loss), (n, p)];
                if loss > 0.0 {
                    successors.push((n + 2, loss));
                }
                successors
            })
            .collect();
        let mdp = chain_mdp(&choices, &[1.0, 5.0, 0.0]);
        let solution = solve(&mdp, &options(1.0)).unwrap();
        // Backwards: V(n-1) = (1-p-loss)·5 + p, V(i) = (1-p-loss)·V(i+1) + p; on the ring,
        // V = p / (p + loss).
        let mut expected = vec![p / (p + loss); n as usize];
        if !ring {
            let mut next = 5.0;
            for i in (0..n as usize).rev() {
                expected[i] = (1.0 - p - loss) * next + p;
                next = expected[i];
            }
        }
        assert_values(&solution, &expected);
    }
}

#[test]
fn bad_epsilon_and_discount_are_typed_errors() {
    for g in [0.0, -0.5, 1.5, f64::NAN, f64::INFINITY] {
        assert!(
            matches!(Discount::new(g), Err(SolveError::InvalidDiscount(_))),
            "{g}"
        );
    }
    assert_eq!(Discount::new(1.0), Ok(Discount::NONE));
    let mdp = mdp_from(&[Absorb(1.0)]);
    for epsilon in [0.0, -1e-6, f64::NAN, f64::INFINITY] {
        let options = SolveOptions {
            epsilon,
            ..SolveOptions::default()
        };
        assert!(
            matches!(solve(&mdp, &options), Err(SolveError::InvalidEpsilon(_))),
            "{epsilon}"
        );
    }
}

#[test]
fn random_mdps_are_solved_with_certified_bounds_and_an_optimal_policy() {
    let epsilon = 1e-6;
    let tolerance = 1e-9;
    let mut rng = rng(7);
    for instance in 0..200 {
        let mdp = random_mdp(&mut rng, 8);
        let g = if instance % 2 == 0 { 1.0 } else { 0.9 };
        let solution = solve(&mdp, &options(g)).unwrap();
        assert!(solution.gap() <= epsilon);
        let optimal = optimal_values_by_enumeration(&mdp, g);
        let policy: Vec<Option<ChoiceId>> = mdp.states().map(|s| solution.policy(s)).collect();
        let achieved = policy_value(&mdp, &policy, g);
        for s in mdp.states() {
            let Interval { lower, upper } = solution.value(s);
            let context = format!("instance {instance}, g = {g}, state {s}: {mdp:?}");
            assert!(upper - lower <= epsilon, "{context}");
            assert!(lower <= optimal[s.index()] + tolerance, "{context}");
            assert!(optimal[s.index()] <= upper + tolerance, "{context}");
            // The policy attains the certified lower bound, hence is epsilon-optimal.
            assert!(achieved[s.index()] >= lower - tolerance, "{context}");
            assert!(achieved[s.index()] <= upper + tolerance, "{context}");
            // Every Q-value interval contains the exact g · Σ P · V*.
            for choice in mdp.choices(s) {
                let exact: f64 = g * mdp
                    .successors(choice)
                    .map(|(t, p)| p * optimal[t.index()])
                    .sum::<f64>();
                let q = solution.choice_value(&mdp, choice);
                assert!(
                    q.lower <= exact + tolerance && exact <= q.upper + tolerance,
                    "{context}"
                );
            }
        }
        // No single deviation improves the policy's exact value by more than epsilon.
        for s in mdp.states() {
            for choice in mdp.choices(s) {
                let mut deviation = policy.clone();
                deviation[s.index()] = Some(choice);
                let value = policy_value(&mdp, &deviation, g);
                for t in 0..mdp.num_states() {
                    assert!(
                        value[t] <= achieved[t] + epsilon + tolerance,
                        "instance {instance}: playing {choice} in {s} improves state {t}"
                    );
                }
            }
        }
    }
}

#[test]
fn a_false_end_component_does_not_share_its_best_exit() {
    // 0 → 1, or cash 100; 1: b reaches 0 or 2 (worth 1) half and half, c loops. {0, 1}
    // looks strongly connected through b, but b leaves it: 1 is worth 0.5 · 100 + 0.5 · 1,
    // not the 100 of 0, which a false end component {0, 1} would give it.
    let mdp = mdp_from(&[
        Decide(&[("a", &[(1, 1.0)]), ("cash", &[(4, 1.0)])]),
        Decide(&[("b", &[(0, 0.5), (2, 0.5)]), ("c", &[(1, 1.0)])]),
        Decide(&[("s", &[(3, 1.0)])]),
        Absorb(1.0),
        Absorb(100.0),
    ]);
    let solution = solve(&mdp, &options(1.0)).unwrap();
    assert_values(&solution, &[100.0, 50.5, 1.0, 1.0, 100.0]);
    assert_eq!(solution.end_components(), 1);
}

/// `mdp` with the payoff of every absorbing state `s` multiplied by `scale(s)`.
fn rescaled(mdp: &Mdp, scale: impl Fn(MdpState) -> f64) -> Mdp {
    let mut builder = crate::mdp::MdpBuilder::new();
    for name in mdp.action_names() {
        builder.action(name).unwrap();
    }
    for state in mdp.states() {
        match mdp.payoff(state) {
            Some(payoff) => {
                builder.add_absorbing_state(payoff * scale(state)).unwrap();
            }
            None => {
                builder.add_decision_state().unwrap();
                for choice in mdp.choices(state) {
                    let successors: Vec<(MdpState, f64)> = mdp.successors(choice).collect();
                    builder.add_choice(mdp.action(choice), &successors).unwrap();
                }
            }
        }
    }
    builder.set_initial(mdp.initial());
    builder.build().unwrap()
}

#[test]
fn a_relative_precision_bounds_every_state_by_its_own_value() {
    // Payoffs spread over six orders of magnitude: an absolute 1e-6 says nothing about a
    // state worth 1e-4, a relative 1e-6 bounds every state's error by a millionth of its value.
    let mut rng = rng(31);
    let options = |g: f64| SolveOptions {
        discount: Discount::new(g).unwrap(),
        epsilon: 1e-6,
        relative: true,
        ..SolveOptions::default()
    };
    let mut small = 0;
    for instance in 0..200 {
        let mdp = rescaled(&random_mdp(&mut rng, 8), |s| {
            [1e-5, 1.0, 10.0][s.index() % 3]
        });
        let g = if instance % 2 == 0 { 1.0 } else { 0.9 };
        let solution = solve(&mdp, &options(g)).unwrap();
        let optimal = optimal_values_by_enumeration(&mdp, g);
        let policy: Vec<Option<ChoiceId>> = mdp.states().map(|s| solution.policy(s)).collect();
        let achieved = policy_value(&mdp, &policy, g);
        for s in mdp.states() {
            let Interval { lower, upper } = solution.value(s);
            let exact = optimal[s.index()];
            let context = format!(
                "instance {instance}, g = {g}, state {s}: [{lower}, {upper}] vs {exact}: {mdp:?}"
            );
            assert!(upper - lower <= 1e-6 * lower + 1e-15, "{context}");
            assert!(
                lower <= exact * (1.0 + 1e-12) && exact <= upper * (1.0 + 1e-12),
                "{context}"
            );
            assert!(achieved[s.index()] >= lower * (1.0 - 1e-9), "{context}");
            small += usize::from(exact > 0.0 && exact < 1e-3);
        }
    }
    assert!(small > 20, "{small}");
    // A ring of 300 states (iterated: more than policy iteration takes) worth about 5e-5 at
    // g = 0.99 (its exits pay 1e-3 and 0 w.p. 0.001 and 0.009), where an absolute 1e-6 is
    // a fiftieth of the value: the relative precision takes more sweeps to its far tighter
    // bounds.
    let n = 300u32;
    let states: Vec<Vec<(u32, f64)>> = (0..n)
        .map(|i| vec![((i + 1) % n, 0.99), (n, 0.001), (n + 1, 0.009)])
        .collect();
    let ring = chain_mdp(&states, &[1e-3, 0.0]);
    // V = 0.99 · (0.99 V + 0.001 · 1e-3).
    let value = 0.99 * 1e-6 / (1.0 - 0.99 * 0.99);
    let relative = solve(&ring, &options(0.99)).unwrap();
    let absolute = solve(
        &ring,
        &SolveOptions {
            discount: Discount::new(0.99).unwrap(),
            ..SolveOptions::default()
        },
    )
    .unwrap();
    for s in 0..n {
        let Interval { lower, upper } = relative.value(ms(s));
        assert!(
            lower <= value * (1.0 + 1e-12) && value <= upper * (1.0 + 1e-12),
            "{s}: [{lower}, {upper}]"
        );
        assert!(upper - lower <= 1e-6 * lower, "{s}: [{lower}, {upper}]");
    }
    assert!(absolute.gap() > 1e-6 * value, "{}", absolute.gap());
    assert!(relative.iterations() > absolute.iterations());
}

#[test]
fn a_large_component_iterated_over_its_block_gets_the_same_bounds_to_the_bit() {
    use super::system::{System, place};
    use crate::mdp::graph::strongly_connected_components_by;
    let mut rng = rng(41);
    let precision = Precision {
        epsilon: 1e-9,
        relative: false,
    };
    let mut checked = 0;
    while checked < 6 {
        let mdp = random_mdp(&mut rng, 3000);
        let order: Vec<MdpState> = mdp.states().filter(|&s| mdp.payoff(s).is_none()).collect();
        let bounds = |s: MdpState| match mdp.payoff(s) {
            Some(payoff) => [payoff, payoff],
            None => [0.0, 5.0],
        };
        let none = vec![None; mdp.num_states()];
        let system = || System::new(&mdp, &order, &none, &BitSet::new(), bounds);
        let (mut in_place, mut whole) = (system(), system());
        let components =
            strongly_connected_components_by(whole.nodes(), |n| whole.successor_slots(n));
        let Some(largest) = components.rows().max_by_key(|&c| components.row(c).len()) else {
            continue;
        };
        let mut component = components.row(largest).to_vec();
        if component.len() <= EXACT_LIMIT {
            continue;
        }
        checked += 1;
        component.sort_unstable();
        let mut position = vec![0; whole.nodes()];
        place(&component, &mut position);
        // The nodes outside the component get exact (made-up) values in both runs, as if
        // solved before it: the block holds copies of them, the system reads them in place.
        for node in 0..whole.nodes() {
            if component.binary_search(&(node as u32)).is_err() {
                whole.values[node] = [(node % 6) as f64; 2];
            }
        }
        for (g, max_iterations) in [(0.95, 100_000), (0.95, 7), (0.999, 100_000)] {
            in_place.values.clone_from(&whole.values);
            in_place.sources = in_place.component_sources(&component, &position);
            in_place.dirty = vec![false; in_place.nodes()];
            let expected = in_place.optimistic_iteration(
                &component,
                g,
                precision,
                5.0,
                max_iterations,
                &mut |_| {},
            );
            let (mut block, local) = whole.block(&component, &position);
            let got =
                block.optimistic_iteration(&local, g, precision, 5.0, max_iterations, &mut |_| {});
            assert_eq!(got, expected, "g = {g}, {} nodes", component.len());
            for (i, &node) in component.iter().enumerate() {
                let (a, b) = (in_place.values[node as usize], block.values[i]);
                assert_eq!(
                    a.map(f64::to_bits),
                    b.map(f64::to_bits),
                    "g = {g}, node {node}"
                );
            }
        }
    }
}

/// At g = 1 two sure ways to the same payoff tie in value; the expected numbers of moves break
/// the tie only when they differ by more than a relative 1e-3 (§6.6). From 0, `slow` (choice 0)
/// enters 1, which reaches the payoff with probability `p` per move (1 + 1/p moves in all), and
/// `fast` (choice 1) enters 2, which does with probability `q`.
#[test]
fn expected_moves_closer_than_a_thousandth_tie_and_the_first_choice_plays() {
    let policy_at_0 = |p: f64, q: f64| {
        let mdp = mdp_from(&[
            Decide(&[("slow", &[(1, 1.0)]), ("fast", &[(2, 1.0)])]),
            Decide(&[("walk", &[(3, p), (1, 1.0 - p)])]),
            Decide(&[("walk", &[(3, q), (2, 1.0 - q)])]),
            Absorb(10.0),
        ]);
        let solution = solve(&mdp, &options(1.0)).unwrap();
        assert_values(&solution, &[10.0, 10.0, 10.0, 10.0]);
        solution.policy(ms(0))
    };
    // 101 moves against 100.95: 5.0e-4 fewer, a tie, so the first choice.
    assert_eq!(policy_at_0(0.01, 1.0 / 99.95), Some(mc(0)));
    // 101 against 100.75: 2.5e-3 fewer, so the faster.
    assert_eq!(policy_at_0(0.01, 1.0 / 99.75), Some(mc(1)));
    // The other way round: `slow` is the faster now, by 2.5e-3 and by 5.0e-4.
    assert_eq!(policy_at_0(1.0 / 99.75, 0.01), Some(mc(0)));
    assert_eq!(policy_at_0(1.0 / 99.95, 0.01), Some(mc(0)));
}

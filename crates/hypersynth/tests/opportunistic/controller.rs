//! The opportunistic controller collects the value the solver reports (docs/semantics.md §6).
//!
//! On gridworlds, the case study and random arenas (adversary chains, diamonds, cycles with
//! exits, adversary-first arenas), at g = 1 and g < 1:
//! - the controller evaluated as a Markov chain (`ControllerEvaluation`, which shares no code
//!   with the solver) collects, from every state, the certified value within epsilon, and its
//!   expected number of robot moves is finite wherever the value is positive;
//! - every robot state is worth at least what it can settle for;
//! - the MDP equals one built naively from the text of docs/semantics.md §6;
//! - the full and the reachable enumeration give the same value at h0 for every sigma_L.

use crate::common;

use rand_chacha::ChaCha8Rng;
use rand_core::SeedableRng;

use hypersynth::arena::gridworld::{Cell, Gridworld};
use hypersynth::arena::{Arena, Owner};
use hypersynth::automata::Dfa;
use hypersynth::game::Payoffs;
use hypersynth::game::{HState, Hypergame, States};
use hypersynth::mdp::MdpState;
use hypersynth::mdp::solve::{Discount, Solution, SolveOptions, solve};
use hypersynth::opportunistic::adversary::{AdversaryModel, SigmaL, WeightTable};
use hypersynth::opportunistic::build::{CHANCE, HypergameMdp, Risk, STOP};
use hypersynth::opportunistic::controller::Controller;
use hypersynth::opportunistic::evaluate::ControllerEvaluation;
use hypersynth::opportunistic::view::{GameView, SolvedGame, SolvedHypergame};

use crate::common::{PHI1, PaperGame, win_label};

const EPSILON: f64 = 1e-6;

/// An MDP choice as compared here: action name, whether instant, distribution.
/// An action, whether it is instant, and its distribution with the targets as numbers.
type Choice = (String, bool, Vec<(u32, f64)>);

/// Everything solved for one arena, two task automata, a sigma_L and a discount.
fn with_solution<T>(
    arena: &Arena,
    dfas: [&Dfa; 2],
    states: States,
    sigma_l: &SigmaL,
    g: f64,
    check: impl FnOnce(&SolvedHypergame, &AdversaryModel, &HypergameMdp, &Solution) -> T,
) -> T {
    let product = Hypergame::new(arena, dfas[0], dfas[1], states).unwrap();
    let paper = PaperGame::new(&product);
    let game = paper.view(&product);
    let adversary = AdversaryModel::new(&game, sigma_l).unwrap();
    let built = HypergameMdp::build(&game, &adversary, Risk::Paper).unwrap();
    let options = SolveOptions {
        discount: Discount::new(g).unwrap(),
        epsilon: EPSILON,
        ..SolveOptions::default()
    };
    let solution = solve(built.mdp(), &options).unwrap();
    check(&game, &adversary, &built, &solution)
}

/// The controller's exact value matches the certified one from every state, its expected
/// number of moves is finite where the value is positive, and no robot state is worth less than
/// what it can settle for.
fn check_controller(
    game: &impl SolvedGame,
    adversary: &AdversaryModel,
    built: &HypergameMdp,
    solution: &Solution,
    context: &str,
) {
    let payoffs = Payoffs::default();
    let controller = Controller {
        game,
        mdp: built,
        solution,
    };
    let evaluation = ControllerEvaluation::new(&controller, adversary, 1e-9, 1_000_000).unwrap();
    for h in game.states() {
        let value = solution.value(built.node(h));
        let collected = evaluation.value(h);
        assert!(
            collected.upper >= value.lower - EPSILON && collected.lower <= value.upper + EPSILON,
            "{context}: state {} is worth [{}, {}] but the controller collects [{}, {}]",
            game.state_name(h),
            value.lower,
            value.upper,
            collected.lower,
            collected.upper
        );
        if value.upper > 0.0 {
            assert!(
                evaluation.expected_moves(h).is_finite(),
                "{context}: state {} has value {} but no finite expected time",
                game.state_name(h),
                value.lower
            );
        }
        if game.is_robot(h) {
            let settle = match win_label(game, h).code() {
                "WLL" => payoffs.r1(),
                "WWL" => payoffs.r1().max(payoffs.r2()),
                "LWL" => payoffs.r2(),
                "WWW" => payoffs.r(),
                _ => 0.0,
            };
            assert!(
                value.lower >= settle - 1e-9,
                "{context}: robot state {} is worth {} < its settling payoff {settle}",
                game.state_name(h),
                value.lower
            );
        }
    }
}

/// Solves the full product and checks its controller (`check_controller`).
fn check_solved(arena: &Arena, dfas: [&Dfa; 2], sigma_l: &SigmaL, g: f64, context: &str) {
    with_solution(arena, dfas, States::Full, sigma_l, g, |game, adv, b, s| {
        check_controller(game, adv, b, s, context)
    });
}

/// A gridworld with A and B on the far side, a few obstacles, the robot moving first.
fn gridworld(side: u32, first: Owner) -> Arena {
    let cell = |x, y| Cell { x, y };
    let mut grid = Gridworld::new(side, side, cell(0, side / 2), cell(side - 1, side / 2));
    grid.labels = vec![
        ("A".into(), cell(0, side - 1)),
        ("B".into(), cell(side - 1, side - 1)),
    ];
    grid.obstacles = vec![cell(side / 2, side / 2), cell(side / 2 - 1, 1)];
    grid.first = first;
    grid.build().unwrap()
}

#[test]
fn the_controller_collects_the_reported_value_on_gridworlds() {
    let (dfa1, dfa2) = (
        crate::common::avoid_until("O", "A"),
        crate::common::avoid_until("O", "B"),
    );
    for (side, first) in [
        (5, Owner::Robot),
        (6, Owner::Adversary),
        (8, Owner::Robot),
        (10, Owner::Robot),
        (12, Owner::Robot),
    ] {
        let arena = gridworld(side, first);
        for (sigma_l, g) in [
            (SigmaL::Random { seed: 2019 }, 1.0),
            (SigmaL::Uniform, 0.99),
        ] {
            let context = format!("{side}x{side}, {first:?} first, {sigma_l:?}, g = {g}");
            check_solved(&arena, [&dfa1, &dfa2], &sigma_l, g, &context);
        }
    }
}

#[test]
fn the_case_study_controller_collects_the_reported_value() {
    let text = include_str!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../specs/case-study/arena.txt"
    ));
    let arena = hypersynth::arena::parse(text).unwrap().arena;
    let (dfa1, dfa2) = (
        crate::common::avoid_until("O", "A"),
        crate::common::avoid_until("O", "B"),
    );
    for g in [1.0, 0.99, 0.5] {
        for sigma_l in [SigmaL::Uniform, SigmaL::Random { seed: 2019 }] {
            check_solved(
                &arena,
                [&dfa1, &dfa2],
                &sigma_l,
                g,
                &format!("case study, {sigma_l:?}, g = {g}"),
            );
        }
    }
}

#[test]
fn the_controller_collects_the_reported_value_on_random_arenas() {
    let mut rng = ChaCha8Rng::seed_from_u64(10);
    for instance in 0..300 {
        let arena = common::random_arena(&mut rng, instance);
        let (dfa1, dfa2) = (common::random_dfa(&mut rng), common::random_dfa(&mut rng));
        let g = [1.0, 0.9, 0.5][instance as usize % 3];
        let sigma_l = SigmaL::Random {
            seed: instance.into(),
        };
        let context = format!("random arena {instance}, g = {g}");
        with_solution(
            &arena,
            [&dfa1, &dfa2],
            States::Full,
            &sigma_l,
            g,
            |game, adv, b, s| check_controller(game, adv, b, s, &context),
        );
    }
}

/// sigma_L of arena state `s` as docs/semantics.md §6 states it, computed here from scratch:
/// uniform, or each edge's weight the documented function of the seed, the state's name and the
/// action's name (SplitMix64's finaliser and FNV-1a, written out again from their definitions).
fn naive_sigma_l(arena: &Arena, seed: Option<u64>) -> Vec<Vec<f64>> {
    fn finalise(x: u64) -> u64 {
        let x = (x ^ (x >> 30)).wrapping_mul(0xbf58476d1ce4e5b9);
        let x = (x ^ (x >> 27)).wrapping_mul(0x94d049bb133111eb);
        x ^ (x >> 31)
    }
    fn fnv1a(text: &str) -> u64 {
        let mut h: u64 = 14695981039346656037;
        for b in text.bytes() {
            h ^= u64::from(b);
            h = h.wrapping_mul(1099511628211);
        }
        h
    }
    let weight = |seed: u64, state: &str, action: &str| {
        let h = finalise(seed ^ u64::from_be_bytes(*b"hypersys"));
        let h = finalise(h ^ fnv1a(state));
        let h = finalise(h ^ fnv1a(action));
        ((h >> 11) + 1) as f64
    };
    arena
        .states()
        .map(|s| {
            if arena.owner(s) == Owner::Robot {
                return Vec::new();
            }
            let weights: Vec<f64> = arena
                .edges(s)
                .map(|(a, _)| match seed {
                    Some(seed) => weight(seed, arena.name(s), arena.action_name(a)),
                    None => 1.0,
                })
                .collect();
            let total: f64 = weights.iter().sum();
            weights.iter().map(|w| w / total).collect()
        })
        .collect()
}

#[test]
fn the_mdp_equals_a_naive_construction_from_the_design() {
    let mut rng = ChaCha8Rng::seed_from_u64(36);
    let payoffs = Payoffs::default();
    for instance in 0..300u32 {
        let arena = common::random_arena(&mut rng, instance);
        let (dfa1, dfa2) = (common::random_dfa(&mut rng), common::random_dfa(&mut rng));
        let seed = (instance % 2 == 0).then_some(u64::from(instance));
        let sigma_l = match seed {
            Some(seed) => SigmaL::Random { seed },
            None => SigmaL::Uniform,
        };
        let sigma = naive_sigma_l(&arena, seed);
        with_solution(
            &arena,
            [&dfa1, &dfa2],
            States::Full,
            &sigma_l,
            1.0,
            |game, _, built, _| {
                let mdp = built.mdp();
                let label = |h: HState| win_label(game, h).code();
                let win1 = |h: HState| game.wins(PHI1, h);
                // The adversary's distribution: sigma_W (uniform over safe actions) outside
                // Win(phi1) when it has a safe action, else sigma_L of its arena state.
                let distribution = |h: HState| -> Vec<(HState, f64)> {
                    let edges: Vec<HState> = game.edges(h).map(|(_, t)| t).collect();
                    let safe: Vec<HState> = edges.iter().copied().filter(|&t| !win1(t)).collect();
                    if !win1(h) && !safe.is_empty() {
                        safe.iter().map(|&t| (t, 1.0 / safe.len() as f64)).collect()
                    } else {
                        edges
                            .iter()
                            .zip(&sigma[game.arena_state(h).index()])
                            .map(|(&t, &p)| (t, p))
                            .collect()
                    }
                };
                // Whether the next robot state after entering `t` can be (L,L,L): depth-first
                // through adversary states along positive-probability edges.
                let risky = |t: HState| {
                    let mut seen = vec![t];
                    let mut stack = vec![t];
                    while let Some(u) = stack.pop() {
                        if game.is_robot(u) {
                            if label(u) == "LLL" {
                                return true;
                            }
                            continue;
                        }
                        for (v, p) in distribution(u) {
                            if p > 0.0 && !seen.contains(&v) {
                                seen.push(v);
                                stack.push(v);
                            }
                        }
                    }
                    false
                };
                let n = game.num_states() as u32;
                for h in game.states() {
                    let choices: Vec<Choice> = mdp
                        .choices(built.node(h))
                        .map(|c| {
                            (
                                mdp.action_name(c).to_string(),
                                mdp.is_instant(c),
                                mdp.successors(c).map(|(t, p)| (t.as_u32(), p)).collect(),
                            )
                        })
                        .collect();
                    let stuck = game.edges(h).next().is_none();
                    let (expected_payoff, expected): (Option<f64>, Vec<Choice>) =
                        if !game.is_robot(h) {
                            if stuck {
                                (Some(payoffs.r()), Vec::new())
                            } else {
                                let mut d: Vec<(u32, f64)> = distribution(h)
                                    .into_iter()
                                    .filter(|&(_, p)| p > 0.0)
                                    .map(|(t, p)| (t.as_u32(), p))
                                    .collect();
                                d.sort_by_key(|&(t, _)| t);
                                // Two actions to one state are one outcome.
                                d.dedup_by(|next, kept| {
                                    let same = next.0 == kept.0;
                                    if same {
                                        kept.1 += next.1;
                                    }
                                    same
                                });
                                (None, vec![(CHANCE.to_string(), true, d)])
                            }
                        } else {
                            match label(h) {
                                "WWW" => (Some(payoffs.r()), Vec::new()),
                                "LWL" => (Some(payoffs.r2()), Vec::new()),
                                "LLL" if stuck => (Some(0.0), Vec::new()),
                                code => {
                                    let mut list: Vec<Choice> = game
                                        .edges(h)
                                        .filter(|&(_, t)| code == "LLL" || !risky(t))
                                        .map(|(a, t)| {
                                            let to = vec![(t.as_u32(), 1.0)];
                                            (game.action_name(a).to_string(), false, to)
                                        })
                                        .collect();
                                    match code {
                                        "WLL" => list.push((STOP.into(), true, vec![(n, 1.0)])),
                                        "WWL" => list.push((STOP.into(), true, vec![(n + 1, 1.0)])),
                                        _ => {}
                                    }
                                    (None, list)
                                }
                            }
                        };
                    assert_eq!(
                        mdp.payoff(built.node(h)),
                        expected_payoff,
                        "instance {instance}, state {h}"
                    );
                    assert_eq!(
                        choices.len(),
                        expected.len(),
                        "instance {instance}, state {h}"
                    );
                    for (real, naive) in choices.iter().zip(&expected) {
                        assert_eq!(
                            (&real.0, real.1),
                            (&naive.0, naive.1),
                            "instance {instance}, state {h}"
                        );
                        assert_eq!(
                            real.2.len(),
                            naive.2.len(),
                            "instance {instance}, state {h}"
                        );
                        for (&(t, p), &(u, q)) in real.2.iter().zip(&naive.2) {
                            assert!(
                                t == u && (p - q).abs() < 1e-12,
                                "instance {instance}, state {h}: {real:?} vs {naive:?}"
                            );
                        }
                    }
                }
                let sink = |i: u32| MdpState::from_u32(n + i);
                assert_eq!(mdp.payoff(sink(0)), Some(payoffs.r1()));
                assert_eq!(mdp.payoff(sink(1)), Some(200.0));
                assert_eq!(mdp.initial(), built.node(game.initial()));
            },
        );
    }
}

#[test]
fn full_and_reachable_enumerations_agree_at_h0_for_every_sigma_l() {
    let text = include_str!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../specs/case-study/arena.txt"
    ));
    let arena = hypersynth::arena::parse(text).unwrap().arena;
    let (dfa1, dfa2) = (
        crate::common::avoid_until("O", "A"),
        crate::common::avoid_until("O", "B"),
    );
    // Weights for every adversary arena state, in the quoted form the arena file uses.
    let mut weights = String::new();
    for s in arena.states() {
        if arena.owner(s) == Owner::Adversary {
            for (i, (action, _)) in arena.edges(s).enumerate() {
                let name = arena.name(s);
                let action = arena.action_name(action);
                weights.push_str(&format!(
                    "\"{name}\" {action} {}\n",
                    (s.index() + i) % 4 + 1
                ));
            }
        }
    }
    let table = WeightTable::parse(&weights).unwrap();
    for sigma_l in [
        SigmaL::Uniform,
        SigmaL::Random { seed: 2019 },
        SigmaL::Weights {
            table,
            file: "weights.txt".into(),
        },
    ] {
        for g in [1.0, 0.99] {
            let value = |states| {
                with_solution(
                    &arena,
                    [&dfa1, &dfa2],
                    states,
                    &sigma_l,
                    g,
                    |game, _, built, solution| solution.value(built.node(game.initial())).lower,
                )
            };
            let (full, reachable) = (value(States::Full), value(States::Reachable));
            assert!(
                (full - reachable).abs() <= EPSILON,
                "g = {g}: full {full}, reachable {reachable}"
            );
        }
    }
}

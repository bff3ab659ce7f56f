//! The general form (docs/semantics.md §8) against the paper's form and its stated properties, on random
//! arenas (adversary chains, diamonds, cycles with exits, adversary-first arenas):
//! - k = 2, psi = phi1, `--risk paper` gives the value of docs/semantics.md §6 at every robot state
//!   (g = 1 and g < 1);
//! - every robot state is worth at least its guarantee, for every risk rule and g, and the
//!   general controller, evaluated as a Markov chain, collects the certified value everywhere;
//! - with psi the conjunction of all sub-tasks (a correctly informed adversary), no robot state
//!   outside `Win(all)` satisfies all sub-tasks with positive probability under the controller
//!   (exact: a search of the controller's Markov chain over its positive-probability moves).

use crate::common;

use rand_chacha::ChaCha8Rng;
use rand_core::{RngCore, SeedableRng};

use hypersynth::arena::Arena;
use hypersynth::automata::Dfa;
use hypersynth::game::{
    Belief, HState, Hypergame, Payoffs, States, SubsetPayoffs, TaskRegions, TaskSet,
};
use hypersynth::mdp::solve::{Discount, Solution, SolveOptions, solve};
use hypersynth::opportunistic::adversary::{AdversaryModel, SigmaL};
use hypersynth::opportunistic::build::{HypergameMdp, Risk};
use hypersynth::opportunistic::controller::{Controller, Decision};
use hypersynth::opportunistic::evaluate::ControllerEvaluation;
use hypersynth::opportunistic::presentation::Presentation;
use hypersynth::opportunistic::view::{GameView, SolvedGame, SolvedHypergame};

const EPSILON: f64 = 1e-6;

fn options(g: f64) -> SolveOptions {
    SolveOptions {
        discount: Discount::new(g).unwrap(),
        epsilon: EPSILON,
        ..SolveOptions::default()
    }
}

fn names(k: usize) -> Vec<String> {
    (0..k).map(|i| format!("T{i}")).collect()
}

/// Everything solved in the general form: sub-task automata `tasks`, psi's automaton if
/// `belief` is `Belief::Automaton`.
#[allow(clippy::too_many_arguments)]
fn with_general<T>(
    arena: &Arena,
    tasks: &[&Dfa],
    psi: Option<&Dfa>,
    belief: Belief,
    payoffs: &SubsetPayoffs,
    risk: Risk,
    sigma_l: &SigmaL,
    g: f64,
    check: impl FnOnce(&SolvedHypergame, &AdversaryModel, &HypergameMdp, &Solution) -> T,
) -> T {
    let names = names(tasks.len());
    let mut automata: Vec<(&str, &Dfa)> = names
        .iter()
        .map(String::as_str)
        .zip(tasks.iter().copied())
        .collect();
    if let Some(psi) = psi {
        automata.push(("psi", psi));
    }
    let product = Hypergame::with_automata(arena, &automata, States::Full).unwrap();
    let regions = TaskRegions::compute(&product, tasks.len(), belief);
    let presentation = Presentation::general(names.to_vec());
    let game = SolvedHypergame::new(&product, &regions, payoffs, &presentation);
    let adversary = AdversaryModel::new(&game, sigma_l).unwrap();
    let built = HypergameMdp::build(&game, &adversary, risk).unwrap();
    let solution = solve(built.mdp(), &options(g)).unwrap();
    check(&game, &adversary, &built, &solution)
}

fn overlaps(a: (f64, f64), b: (f64, f64)) -> bool {
    a.0 <= b.1 + 2.0 * EPSILON && b.0 <= a.1 + 2.0 * EPSILON
}

#[test]
fn two_sub_tasks_believed_phi1_with_the_paper_risk_give_the_papers_values() {
    let mut rng = ChaCha8Rng::seed_from_u64(16);
    for instance in 0..300u32 {
        let arena = common::random_arena(&mut rng, instance);
        let (dfa1, dfa2) = (common::random_dfa(&mut rng), common::random_dfa(&mut rng));
        let g = [1.0, 0.9, 0.5][instance as usize % 3];
        let (r1, r2, r) = [(200.0, 100.0, 300.0), (100.0, 150.0, 400.0)][instance as usize % 2];
        let sigma_l = SigmaL::Random {
            seed: instance.into(),
        };
        let product = Hypergame::new(&arena, &dfa1, &dfa2, States::Full).unwrap();
        let paper_game =
            common::PaperGame::with_payoffs(&product, Payoffs::new(r1, r2, r).unwrap());
        let paper = paper_game.view(&product);
        let adversary = AdversaryModel::new(&paper, &sigma_l).unwrap();
        let built = HypergameMdp::build(&paper, &adversary, Risk::Paper).unwrap();
        let expected = solve(built.mdp(), &options(g)).unwrap();
        let payoffs = SubsetPayoffs::new(&[r1, r2], &[(TaskSet(0b11), r)], &names(2)).unwrap();
        with_general(
            &arena,
            &[&dfa1, &dfa2],
            None,
            Belief::Tasks(TaskSet(0b01)),
            &payoffs,
            Risk::Paper,
            &sigma_l,
            g,
            |game, _, general, solution| {
                for h in game.states().filter(|&h| game.is_robot(h)) {
                    let (a, b) = (
                        expected.value(built.node(h)),
                        solution.value(general.node(h)),
                    );
                    assert!(
                        overlaps((a.lower, a.upper), (b.lower, b.upper)),
                        "arena {instance}, g = {g}: {} is worth [{}, {}] in the paper's form \
                         but [{}, {}] in the general one",
                        game.state_name(h),
                        a.lower,
                        a.upper,
                        b.lower,
                        b.upper
                    );
                }
                assert_eq!(general.mdp().initial(), general.node(game.initial()));
            },
        );
    }
}

/// Random monotone payoffs for k sub-tasks: sums of per-task payoffs, some sets raised to at
/// least every subset's payoff plus a bonus.
fn random_payoffs(rng: &mut ChaCha8Rng, k: usize) -> SubsetPayoffs {
    let per_task: Vec<f64> = (0..k).map(|_| f64::from(rng.next_u32() % 5 * 50)).collect();
    let mut overrides = Vec::new();
    let mut values: Vec<f64> = (0..1usize << k)
        .map(|mask| TaskSet(mask as u8).iter().map(|i| per_task[i]).sum::<f64>())
        .collect();
    for mask in 1..1usize << k {
        if rng.next_u32().is_multiple_of(3) {
            let floor = (0..mask)
                .filter(|&sub| sub & !mask == 0)
                .map(|sub| values[sub])
                .fold(0.0, f64::max);
            values[mask] = floor + f64::from(rng.next_u32() % 4 * 25);
            overrides.push((TaskSet(mask as u8), values[mask]));
        }
    }
    // Raising a set may break its supersets' defaults: raise them in mask order too.
    for mask in 1..1usize << k {
        let floor = (0..mask)
            .filter(|&sub| sub & !mask == 0)
            .map(|sub| values[sub])
            .fold(0.0, f64::max);
        if values[mask] < floor {
            values[mask] = floor;
            overrides.push((TaskSet(mask as u8), floor));
        }
    }
    SubsetPayoffs::new(&per_task, &overrides, &names(k)).unwrap()
}

#[test]
fn values_are_at_least_the_guarantee_and_the_controller_collects_them() {
    let mut rng = ChaCha8Rng::seed_from_u64(1616);
    for instance in 0..240u32 {
        let arena = common::random_arena(&mut rng, instance);
        let k = 1 + (instance as usize % 3);
        let tasks: Vec<Dfa> = (0..k).map(|_| common::random_dfa(&mut rng)).collect();
        let task_refs: Vec<&Dfa> = tasks.iter().collect();
        let psi = common::random_dfa(&mut rng);
        let (psi, belief) = match instance % 4 {
            0 => (Some(&psi), Belief::Automaton),
            _ => (
                None,
                Belief::Tasks(TaskSet(1 + (rng.next_u32() % ((1 << k) - 1)) as u8)),
            ),
        };
        let payoffs = random_payoffs(&mut rng, k);
        let risk = [Risk::Paper, Risk::Strict, Risk::Neutral][instance as usize % 3];
        let g = [1.0, 0.9, 0.5, 1.0][(instance as usize / 3) % 4];
        let sigma_l = SigmaL::Random {
            seed: instance.into(),
        };
        let context = format!("arena {instance}, k = {k}, {risk:?}, g = {g}");
        with_general(
            &arena,
            &task_refs,
            psi,
            belief,
            &payoffs,
            risk,
            &sigma_l,
            g,
            |game, adversary, built, solution| {
                let controller = Controller {
                    game,
                    mdp: built,
                    solution,
                };
                let evaluation =
                    ControllerEvaluation::new(&controller, adversary, 1e-9, 1_000_000).unwrap();
                for h in game.states() {
                    let value = solution.value(built.node(h));
                    if game.is_robot(h) {
                        assert!(
                            value.lower >= game.guarantee(h) - 1e-9,
                            "{context}: {} is worth {} < its guarantee {}",
                            game.state_name(h),
                            value.lower,
                            game.guarantee(h)
                        );
                    }
                    let collected = evaluation.value(h);
                    assert!(
                        overlaps(
                            (value.lower, value.upper),
                            (collected.lower, collected.upper)
                        ),
                        "{context}: {} is worth [{}, {}] but the controller collects [{}, {}]",
                        game.state_name(h),
                        value.lower,
                        value.upper,
                        collected.lower,
                        collected.upper
                    );
                }
            },
        );
    }
}

#[test]
fn a_correctly_informed_adversary_leaves_no_chance_of_the_whole_task_outside_win_all() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let mut outside = 0;
    for instance in 0..240u32 {
        let arena = common::random_arena(&mut rng, instance);
        let k = 2 + (instance as usize % 2);
        let tasks: Vec<Dfa> = (0..k).map(|_| common::random_dfa(&mut rng)).collect();
        let task_refs: Vec<&Dfa> = tasks.iter().collect();
        let payoffs = random_payoffs(&mut rng, k);
        let risk = [Risk::Paper, Risk::Strict, Risk::Neutral][instance as usize % 3];
        let g = [1.0, 0.9][instance as usize % 2];
        let all = TaskSet::all(k);
        with_general(
            &arena,
            &task_refs,
            None,
            Belief::Tasks(all),
            &payoffs,
            risk,
            &SigmaL::Random {
                seed: instance.into(),
            },
            g,
            |game, adversary, built, solution| {
                let controller = Controller {
                    game,
                    mdp: built,
                    solution,
                };
                let win_all = game.regions().win(all);
                for h in game.states() {
                    if game.is_robot(h) && !win_all.contains(h) {
                        outside += 1;
                        assert!(
                            !may_satisfy_all(&controller, adversary, h, all),
                            "arena {instance}: from {} outside Win(all) the controller may \
                             satisfy every sub-task",
                            game.state_name(h)
                        );
                    }
                }
            },
        );
    }
    assert!(outside > 1000, "only {outside} states were checked");
}

/// Whether the controller's Markov chain from `h` (uncommitted) reaches, with positive
/// probability, a state where every sub-task is satisfied: a search over (state, commitment).
fn may_satisfy_all(
    controller: &Controller<SolvedHypergame>,
    adversary: &AdversaryModel,
    h: HState,
    all: TaskSet,
) -> bool {
    let game = controller.game;
    let mut seen = std::collections::HashSet::new();
    let mut stack = vec![(h, None::<TaskSet>)];
    let mut scratch = Vec::new();
    let mut moves = Vec::new();
    while let Some((s, committed)) = stack.pop() {
        if !seen.insert((s, committed)) {
            continue;
        }
        if game.is_target(all, s) {
            return true;
        }
        if game.is_robot(s) {
            match committed {
                Some(set) => {
                    if let Some((_, t)) = game.reactive_move(set, s) {
                        stack.push((t, committed));
                    }
                }
                None => match controller.decide(s) {
                    Decision::Move { successor, .. } => stack.push((successor, None)),
                    Decision::Commit(set) | Decision::Stop(set) => stack.push((s, Some(set))),
                    Decision::GiveUp => {}
                },
            }
        } else {
            adversary.positive_moves(game, s, &mut scratch, &mut moves);
            stack.extend(moves.iter().map(|&(t, _)| (t, committed)));
        }
    }
    false
}

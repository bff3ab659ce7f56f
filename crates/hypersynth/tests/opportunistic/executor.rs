//! The exported controller (docs/semantics.md §9) on the case study, the decoy and the
//! three-tasks examples (`hypersynth execute` is the command's `tests/controller_export.rs`):
//! - evaluated from the file alone (its decisions and reactive moves, read by the executor's
//!   tables, against the adversary model), it collects the controller's `policy_value`;
//! - run step by step by the executor, fed the arena states a simulation draws with the same
//!   random stream as `--simulate`, it gives exactly the same runs: outcome counts and mean
//!   payoff (the driver below is written here, not the library's simulation);
//! - of scope `all`, it answers what the controller decides after the robot's slips.

use rand_chacha::ChaCha8Rng;
use rand_core::{RngCore, SeedableRng};

use crate::common::{examples, map_arena};
use hypersynth::arena::{Arena, Owner};
use hypersynth::game::{States, TaskSet};
use hypersynth::mdp::solve::{Discount, SolveOptions};
use hypersynth::opportunistic::adversary::{AdversaryModel, SigmaL};
use hypersynth::opportunistic::build::Risk;
use hypersynth::opportunistic::evaluate::ControllerEvaluation;
use hypersynth::opportunistic::executor::{Answer, Executor, Then};
use hypersynth::opportunistic::simulate::SimulationOptions;
use hypersynth::opportunistic::view::{GameView, SolvedHypergame};
use hypersynth::pipeline::{self, MdpOptions, Problem, Requests, Tasks};

/// The problem of an example on its map with the MDP stage's options: sigma_L uniform, `seed`,
/// the discount `g`; its arena and options besides.
fn problem(tasks: &Tasks, map: &str, g: f64, seed: u64) -> (Arena, MdpOptions, Problem) {
    let (arena, world) = map_arena(map);
    let options = MdpOptions {
        sigma_l: SigmaL::Uniform,
        seed,
        solve: SolveOptions {
            discount: Discount::new(g).unwrap(),
            ..SolveOptions::default()
        },
        learnt: None,
    };
    let problem = Problem {
        arena_name: map.into(),
        arena: arena.clone(),
        map: Some(world),
        tasks: tasks.clone(),
        states: States::Full,
        mdp: Some(options.clone()),
    };
    (arena, options, problem)
}

/// How a driven run ended: a satisfied set (its mask), stuck, none, step bound.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Ending {
    Satisfied(u8),
    Stuck,
    Nothing,
    Bound,
}

/// One run driven through the executor: the adversary's moves drawn from `adversary` at the
/// product state the executor's automata give (one 53-bit draw per move, as `--simulate`
/// draws), the robot's from the executor's answers.
fn drive(
    executor: &mut Executor,
    game: &SolvedHypergame,
    adversary: &AdversaryModel,
    rng: &mut ChaCha8Rng,
    max_steps: u32,
) -> (Ending, f64) {
    let product = game.game();
    let file = executor.file().clone();
    executor.reset();
    let mut s = product.arena().initial();
    let mut turn = executor.observe_state(s).unwrap();
    let (mut moves, mut steps) = (0i32, 0u32);
    let mut distribution = Vec::new();
    let payoff = |set: Option<TaskSet>, moves: i32| {
        let all = *file.payoffs.last().unwrap();
        set.map_or(all, |set| file.payoffs[set.0 as usize]) * file.discount.powi(moves)
    };
    loop {
        if executor.is_done() {
            let set = executor.committed();
            return (Ending::Satisfied(set.unwrap().0), payoff(set, moves));
        }
        if steps >= max_steps {
            return (Ending::Bound, 0.0);
        }
        let h = product.find_tuple(s, executor.automata()).unwrap();
        let action = if product.arena().owner(s) == Owner::Robot {
            match turn.answer.clone().unwrap() {
                Answer::Move(a) => {
                    if executor.committed().is_none() {
                        moves += 1;
                    }
                    a
                }
                Answer::Commit {
                    then: Then::Move(a),
                    ..
                } => a,
                Answer::Commit {
                    then: Then::Done, ..
                }
                | Answer::Done => continue,
                Answer::GiveUp => return (Ending::Nothing, 0.0),
            }
        } else if game.edges(h).next().is_none() {
            return (Ending::Stuck, payoff(executor.committed(), moves));
        } else if executor.committed().is_none() && executor.is_worthless() {
            return (Ending::Nothing, 0.0);
        } else {
            adversary.distribution(game, h, &mut distribution);
            let u = (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
            let (mut cumulative, mut chosen) = (0.0, None);
            for ((a, _), &p) in game.edges(h).zip(&distribution) {
                if p > 0.0 {
                    chosen = Some(a);
                    cumulative += p;
                    if u < cumulative {
                        break;
                    }
                }
            }
            chosen.unwrap()
        };
        s = product.arena().successor(s, action).unwrap();
        turn = executor.observe_state(s).unwrap();
        steps += 1;
    }
}

#[test]
fn the_exported_controller_collects_policy_value_and_replays_the_simulation() {
    let seed = 2019;
    for (name, tasks, map, g) in examples() {
        let (arena, _, problem) = problem(&tasks, map, g, seed);
        let requests = Requests {
            simulate: Some(400),
            max_steps: 1000,
            export_controller: true,
            ..Requests::default()
        };
        let outcome = pipeline::run(&problem, &requests, &mut ()).unwrap();
        let synthesis = outcome.report.synthesis.unwrap();
        let mut executor = Executor::from_json(&outcome.controller.unwrap()).unwrap();

        // The stages again, for the file's plan and the driver.
        let product = tasks.hypergame(&arena, States::Full).unwrap();
        let regions = tasks.regions(&product);
        let game = SolvedHypergame::new(&product, &regions, tasks.payoffs(), tasks.presentation());
        let adversary = AdversaryModel::new(&game, &SigmaL::Uniform).unwrap();

        let plan = executor.plan(&game);
        let evaluation = ControllerEvaluation::new(&plan, &adversary, 1e-9, 1_000_000).unwrap();
        let collected = evaluation.value(product.initial());
        let expected = synthesis.decision.policy_value;
        assert!(
            (collected.lower - expected).abs() <= 1e-6
                && (collected.upper - expected).abs() <= 1e-6,
            "{name}: the file's controller collects {collected:?}, policy_value {expected}"
        );

        let simulation = synthesis.simulation.unwrap();
        assert_eq!(
            simulation.options,
            SimulationOptions {
                runs: 400,
                seed,
                max_steps: 1000
            }
        );
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut satisfied = vec![0u32; simulation.satisfied.len()];
        let (mut stuck, mut nothing, mut bound, mut sum) = (0, 0, 0, 0.0);
        for _ in 0..400 {
            let (ending, payoff) = drive(&mut executor, &game, &adversary, &mut rng, 1000);
            match ending {
                Ending::Satisfied(set) => satisfied[set as usize] += 1,
                Ending::Stuck => stuck += 1,
                Ending::Nothing => nothing += 1,
                Ending::Bound => bound += 1,
            }
            sum += payoff;
        }
        assert_eq!(satisfied, simulation.satisfied, "{name}");
        assert_eq!(
            (stuck, nothing, bound),
            (
                simulation.adversary_stuck,
                simulation.none,
                simulation.step_bound
            ),
            "{name}"
        );
        assert_eq!(sum / 400.0, simulation.mean_payoff, "{name}");
    }
}

/// Scope `all` (`--controller-scope all`): a play goes on after the robot's slips. Walks in
/// which the uncommitted robot plays a random move (mostly not the one answered) and the
/// adversary any move: at every uncommitted robot turn, the file of scope `all` answers what the
/// library's controller decides at that product state, where a file of scope `reachable` soon
/// has no answer; once committed, the robot follows the answers to the end.
#[test]
fn a_controller_of_scope_all_answers_after_the_robots_slips() {
    use hypersynth::opportunistic::controller::Decision;
    use hypersynth::opportunistic::executor::ExecutionError;
    use hypersynth::opportunistic::export::Scope;
    use hypersynth::pipeline::OpportunisticSolution;

    for (name, tasks, map, g) in examples() {
        let (arena, options, problem) = problem(&tasks, map, g, 1);
        let file = |scope| {
            let requests = Requests {
                export_controller: true,
                controller_scope: scope,
                ..Requests::default()
            };
            let outcome = pipeline::run(&problem, &requests, &mut ()).unwrap();
            Executor::from_json(&outcome.controller.unwrap()).unwrap()
        };
        let mut all = file(Scope::All);
        let mut reachable = file(Scope::Reachable);
        assert_eq!(all.file().scope, Scope::All);

        let product = tasks.hypergame(&arena, States::Full).unwrap();
        let regions = tasks.regions(&product);
        let game = SolvedHypergame::new(&product, &regions, tasks.payoffs(), tasks.presentation());
        let solved = OpportunisticSolution::solve(&game, Risk::Paper, &options, &mut ()).unwrap();
        let controller = solved.controller(&game);

        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let (mut slips, mut reachable_lost) = (0, 0);
        for _ in 0..200 {
            all.reset();
            reachable.reset();
            let mut s = arena.initial();
            let mut reachable_on = true;
            for _ in 0..60 {
                let turn = all
                    .observe_state(s)
                    .unwrap_or_else(|e| panic!("{name}: {e}"));
                if reachable_on {
                    match reachable.observe_state(s) {
                        Ok(_) => {}
                        Err(ExecutionError::NotCovered { .. }) => {
                            reachable_on = false;
                            reachable_lost += 1;
                        }
                        Err(e) => panic!("{name}: {e}"),
                    }
                }
                if all.is_done() || matches!(turn.answer, Some(Answer::GiveUp)) {
                    break;
                }
                let edges: Vec<_> = arena.edges(s).collect();
                if edges.is_empty() {
                    break;
                }
                let random = edges[rng.next_u32() as usize % edges.len()].1;
                s = match turn.answer {
                    None => random,
                    Some(answer) => {
                        let h = product.find_tuple(s, all.automata()).unwrap();
                        let committed_before = matches!(answer, Answer::Commit { .. });
                        if all.committed().is_none() || committed_before {
                            // The answer is the controller's decision at h.
                            let expected = match controller.decide(h) {
                                Decision::Move { action, .. } => Answer::Move(action),
                                Decision::GiveUp => Answer::GiveUp,
                                Decision::Commit(set) | Decision::Stop(set) => {
                                    let Answer::Commit { set: given, .. } = answer else {
                                        panic!("{name}: {answer:?}, where {set:?} is committed to")
                                    };
                                    assert_eq!(given, set, "{name}");
                                    answer.clone()
                                }
                            };
                            assert_eq!(answer, expected, "{name} at {}", game.state_name(h));
                        }
                        match answer {
                            Answer::Move(a) if all.committed().is_none() => {
                                let slip = edges.iter().find(|&&(b, _)| b != a);
                                if let Some(&(_, t)) = slip.filter(|_| rng.next_u32() % 4 != 0) {
                                    slips += 1;
                                    t
                                } else {
                                    arena.successor(s, a).unwrap()
                                }
                            }
                            Answer::Move(a)
                            | Answer::Commit {
                                then: Then::Move(a),
                                ..
                            } => arena.successor(s, a).unwrap(),
                            _ => break,
                        }
                    }
                };
            }
        }
        assert!(slips > 200, "{name}: {slips} slips");
        assert!(
            reachable_lost > 0,
            "{name}: the reachable file never lost the play"
        );
    }
}

//! The implicit engine's policy and its evaluation against the explicit controller's, on the
//! random text arenas and maps of `solve.rs`: the choice of every robot state against
//! `Controller::decide`, and the evaluation at h0 against `ControllerEvaluation`'s.

use super::solve::{EPSILON, Engines, random_tasks, solve_both};
use crate::common::random_arena;
use crate::common::random_world;
use hypersynth::arena::Owner;
use hypersynth::game::HState;
use hypersynth::implicit::{
    ArenaMoves, Choice, MapMoves, Moves, PolicyError, Precision, evaluate, policy,
};
use hypersynth::mdp::MdpState;
use hypersynth::mdp::solve::Interval;
use hypersynth::opportunistic::controller::Decision;
use hypersynth::pipeline::Tasks;
use rand_chacha::ChaCha8Rng;
use rand_core::SeedableRng;

/// What the comparisons found: the robot states where both engines play a choice, and where
/// the choices differ (each between choices whose values the explicit engine certifies equal
/// within epsilon).
#[derive(Default, Debug)]
struct Tally {
    decisions: usize,
    differ: Vec<String>,
}

fn compare<M: Moves>(engines: &Engines<'_, M>, tasks: &Tasks, case: &str, tally: &mut Tally) {
    let Engines {
        game,
        solved,
        explicit,
        model,
        implicit,
        g,
        ..
    } = engines;
    let chosen = policy(model, implicit, *g, 100_000).unwrap();
    let mut differ = false;
    let controller = explicit.controller(*solved);
    let mdp = explicit.mdp.mdp();
    for h in game.states() {
        if model.space().owner(h.as_u32()) != Owner::Robot {
            assert_eq!(chosen.choice(h.as_u32()), None, "{case}: adversary state");
            continue;
        }
        let decision = controller.decide(h);
        let name = game.name(h);
        let Some(position) = chosen.choice(h.as_u32()) else {
            assert!(
                matches!(decision, Decision::Commit(_) | Decision::GiveUp),
                "{case} {name}: implicit gives no choice, explicit {decision:?}"
            );
            continue;
        };
        tally.decisions += 1;
        let mut listed = Vec::new();
        model.choices(h.as_u32(), |c| listed.push(c));
        let same = match (listed[usize::from(position)], decision) {
            (Choice::Move { action, .. }, Decision::Move { action: a, .. }) => action == a,
            (Choice::Stop { .. }, Decision::Stop(_)) => true,
            (_, Decision::Commit(_) | Decision::GiveUp) => {
                panic!("{case} {name}: implicit plays {position}, explicit {decision:?}")
            }
            _ => false,
        };
        if !same {
            let node = MdpState::new(h.index());
            let explicit_choice = explicit.solution.policy(node).unwrap();
            let ours = mdp.choices(node).nth(usize::from(position)).unwrap();
            let (e, i) = (
                explicit.solution.choice_value(mdp, explicit_choice),
                explicit.solution.choice_value(mdp, ours),
            );
            // A tie the solvers' rounding breaks: both choices are optimal, their values
            // certified equal to within epsilon (the engines' lower bounds differ by up to
            // epsilon, so their argmax may fall on either).
            assert!(
                i.upper >= e.lower - 1e-9 && e.upper >= i.lower - 1e-9,
                "{case} {name}: explicit plays {} {e:?}, implicit {} {i:?}",
                mdp.action_name(explicit_choice),
                mdp.action_name(ours),
            );
            differ = true;
            tally.differ.push(format!(
                "{case} {name} g={g} risk {:?}: explicit {} {e:?}, implicit {} {i:?}, value {:?} / {:?}",
                tasks.risk(),
                mdp.action_name(explicit_choice),
                mdp.action_name(ours),
                explicit.solution.value(node),
                implicit.value(model, h.as_u32()),
            ));
        }
    }
    // The evaluation at h0: both certified to within epsilon, both containing the value of
    // an optimal policy; the same expected moves where the policies agree.
    let h0 = model.space().initial();
    let evaluation = evaluate(model, &chosen, implicit.value(model, h0), EPSILON, 100_000).unwrap();
    let (value, reference) = (
        evaluation.value,
        explicit.evaluation.value(HState::new(h0 as usize)),
    );
    assert!(value.upper - value.lower <= EPSILON, "{case}: {value:?}");
    assert!(
        value.lower <= reference.upper + EPSILON && reference.lower <= value.upper + EPSILON,
        "{case}: implicit {value:?}, explicit {reference:?}"
    );
    // A value the policy does not collect is refused.
    let wrong = Interval {
        lower: value.upper + 2.0 * EPSILON + 1e-6,
        upper: value.upper + 2.0 * EPSILON + 1e-6,
    };
    assert!(
        matches!(
            evaluate(model, &chosen, wrong, EPSILON, 100_000),
            Err(PolicyError::Mismatch { .. })
        ),
        "{case}"
    );
    let (moves, expected) = (
        evaluation.expected_moves,
        explicit.evaluation.expected_moves(HState::new(h0 as usize)),
    );
    assert!(
        differ || moves == expected || (moves - expected).abs() <= 1e-9 * expected.max(1.0),
        "{case}: implicit {moves} moves, explicit {expected}"
    );
}

/// Checks that the cases had decisions to compare and lists where the choices differ.
fn report(tally: &Tally) {
    assert!(tally.decisions > 500, "{} decisions", tally.decisions);
    eprintln!(
        "{} robot states decide, {} differ:",
        tally.decisions,
        tally.differ.len()
    );
    for line in &tally.differ {
        eprintln!("  {line}");
    }
}

#[test]
fn policies_equal_the_explicit_controllers_on_random_text_arenas() {
    let mut rng = ChaCha8Rng::seed_from_u64(31);
    let mut tally = Tally::default();
    for case in 0..400 {
        let arena = random_arena(&mut rng, case);
        let tasks = random_tasks(&mut rng);
        let moves = ArenaMoves::new(&arena);
        solve_both(&moves, &arena, &tasks, &mut rng, |engines| {
            compare(engines, &tasks, &format!("arena case {case}"), &mut tally)
        });
    }
    report(&tally);
}

#[test]
fn policies_equal_the_explicit_controllers_on_random_maps() {
    let mut rng = ChaCha8Rng::seed_from_u64(33);
    let mut tally = Tally::default();
    for case in 0..200 {
        let world = random_world(&mut rng);
        let arena = world.build().unwrap();
        let tasks = random_tasks(&mut rng);
        let moves = MapMoves::new(&world).unwrap();
        solve_both(&moves, &arena, &tasks, &mut rng, |engines| {
            compare(engines, &tasks, &format!("map case {case}"), &mut tally)
        });
    }
    report(&tally);
}

/// Random arenas whose robot states have 15 to 20 moves each (more than the 14 edges the
/// policy's eligibility masks hold, so its other rule decides there) into adversary states of
/// one to three moves back, over propositions a and b.
fn wide_arena(rng: &mut ChaCha8Rng) -> hypersynth::arena::Arena {
    use hypersynth::arena::{ArenaBuilder, StateId};
    use rand_core::RngCore;
    let below = |rng: &mut ChaCha8Rng, n: u32| rng.next_u32() % n;
    let (robots, adversaries) = (2 + below(rng, 3), 3 + below(rng, 4));
    let mut b = ArenaBuilder::new();
    for s in 0..robots + adversaries {
        let owner = if s < robots {
            Owner::Robot
        } else {
            Owner::Adversary
        };
        let label = below(rng, 5);
        let props = match label {
            0 => vec!["a"],
            1 => vec!["b"],
            _ => vec![],
        };
        b.add_state(&format!("s{s}"), owner, props, None).unwrap();
    }
    let id = StateId::from_u32;
    for s in 0..robots {
        for m in 0..15 + below(rng, 6) {
            let target = robots + below(rng, adversaries);
            b.add_transition(id(s), &format!("m{m}"), id(target))
                .unwrap();
        }
    }
    for s in robots..robots + adversaries {
        for m in 0..1 + below(rng, 3) {
            let target = below(rng, robots + adversaries);
            b.add_transition(id(s), &format!("m{m}"), id(target))
                .unwrap();
        }
    }
    b.set_initial(id(0));
    b.build().unwrap()
}

#[test]
fn policies_equal_the_explicit_controllers_where_robot_states_have_many_moves() {
    let mut rng = ChaCha8Rng::seed_from_u64(35);
    let mut tally = Tally::default();
    for case in 0..120 {
        let arena = wide_arena(&mut rng);
        let tasks = random_tasks(&mut rng);
        let moves = ArenaMoves::new(&arena);
        solve_both(&moves, &arena, &tasks, &mut rng, |engines| {
            compare(engines, &tasks, &format!("wide case {case}"), &mut tally)
        });
    }
    report(&tally);
}

#[test]
fn a_state_with_more_than_255_choices_and_invalid_parameters_are_refused() {
    use hypersynth::arena::{ArenaBuilder, StateId};
    use hypersynth::game::{Belief, Payoffs, TaskSet};
    use hypersynth::implicit::{Model, Regions, Space, solve};
    use hypersynth::ltl;
    use hypersynth::opportunistic::adversary::SigmaL;
    use hypersynth::opportunistic::build::Risk;
    use hypersynth::opportunistic::presentation::Presentation;
    use hypersynth::translate::{Builtin, TranslationLimits, Translator};
    // Robot state s0 has `actions` moves to adversary state s1 (labelled a), which loops: F a
    // is won surely, F b never; psi is F a, so s0 does not commit and decides among its moves
    // and `stop`.
    let run = |actions: usize, g: f64, epsilon: f64| {
        let mut b = ArenaBuilder::new();
        b.add_state("s0", Owner::Robot, [], None).unwrap();
        b.add_state("s1", Owner::Adversary, ["a"], None).unwrap();
        b.add_state("s2", Owner::Adversary, ["b"], None).unwrap();
        for i in 0..actions {
            b.add_transition(StateId::from_u32(0), &format!("m{i}"), StateId::from_u32(1))
                .unwrap();
        }
        b.add_transition(StateId::from_u32(1), "x", StateId::from_u32(1))
            .unwrap();
        b.add_transition(StateId::from_u32(2), "x", StateId::from_u32(2))
            .unwrap();
        b.set_initial(StateId::from_u32(0));
        let arena = b.build().unwrap();
        let translator = Builtin::new(TranslationLimits::default());
        let phi1 = translator.translate(&ltl::parse("F a").unwrap()).unwrap();
        let phi2 = translator.translate(&ltl::parse("F b").unwrap()).unwrap();
        let moves = ArenaMoves::new(&arena);
        let space = Space::new(&moves, &[&phi1, &phi2]).unwrap();
        let regions = Regions::compute(&space, 2, Belief::Tasks(TaskSet(0b01)));
        let presentation = Presentation::paper("phi");
        let payoffs = Payoffs::default().subsets(presentation.names());
        let model = Model::new(
            &space,
            &regions,
            &payoffs,
            &presentation,
            Risk::Paper,
            &SigmaL::Uniform,
        )
        .unwrap();
        let h0 = space.initial();
        let mut choices = 0;
        model.choices(h0, |_| choices += 1);
        assert_eq!(choices, actions + 1, "the moves and stop");
        let solution = solve(&model, 0.9, Precision::absolute(1e-6), 1000).unwrap();
        let chosen = policy(&model, &solution, g, 1000)?;
        evaluate(&model, &chosen, solution.value(&model, h0), epsilon, 1000).map(|_| h0)
    };
    // 255 choices fit; 256 do not.
    assert!(run(254, 0.9, 1e-6).is_ok());
    assert_eq!(
        run(255, 0.9, 1e-6),
        Err(PolicyError::TooManyChoices {
            state: 0,
            choices: 256
        })
    );
    assert_eq!(
        run(3, 1.5, 1e-6),
        Err(PolicyError::Invalid {
            discount: 1.5,
            epsilon: 0.0
        })
    );
    assert_eq!(
        run(3, 0.9, 0.0),
        Err(PolicyError::Invalid {
            discount: 0.9,
            epsilon: 0.0
        })
    );
}

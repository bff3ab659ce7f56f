//! The implicit engine's certified values against the explicit pipeline's, state by state, on
//! random text arenas and random maps: both forms (the paper's is recognised by `Tasks::new` when
//! k = 2, psi is one sub-task, the rule is `paper` and the payoffs fit), k = 2 and 3 sub-tasks,
//! psi a set of sub-tasks or its own automaton, every risk rule, sigma_L uniform, random and a
//! random weight table, discounts 0.9, 0.99 and 1 (end components of every size included).

use crate::common::{bad_table, random_arena, random_table, random_world};
use hypersynth::arena::Arena;
use hypersynth::arena::gridworld::{Cell, Gridworld};
use hypersynth::game::{Hypergame, States, SubsetPayoffs, TaskSet};
use hypersynth::implicit::testing::{Tuning, policy_tuned, solve_tuned};
use hypersynth::implicit::{
    ArenaMoves, Choice, Distribution, Kind, MapMoves, Model, ModelError, Moves, Precision, Regions,
    Solution, Space, solve,
};
use hypersynth::ltl;
use hypersynth::mdp::MdpState;
use hypersynth::mdp::solve::{Discount, SolveOptions};
use hypersynth::opportunistic::adversary::{AdversaryModel, EntryError, SigmaL, WeightTable};
use hypersynth::opportunistic::build::Risk;
use hypersynth::opportunistic::view::SolvedHypergame;
use hypersynth::pipeline::{Believed, MdpOptions, OpportunisticSolution, Subtask, Task, Tasks};
use hypersynth::translate::{Builtin, TranslationLimits};
use rand_chacha::ChaCha8Rng;
use rand_core::{RngCore, SeedableRng};

const FORMULAS: [&str; 6] = ["F a", "F b", "!a U b", "!b U a", "F (a & X b)", "a U b"];
pub const EPSILON: f64 = 1e-6;

/// A choice as both engines can list it: its arena action (`None` for `stop` and the
/// adversary's move) and its targets with their probabilities.
type Listed = (Option<u32>, Vec<(usize, f64)>);

fn below(rng: &mut ChaCha8Rng, n: u32) -> u32 {
    rng.next_u32() % n
}

/// Random tasks over a and b: k sub-tasks from [`FORMULAS`], payoffs, a belief (a sub-task, a
/// formula of its own or the conjunction of all), a risk rule.
pub fn random_tasks(rng: &mut ChaCha8Rng) -> Tasks {
    let translator = Builtin::new(TranslationLimits::default());
    let k = 2 + below(rng, 2) as usize;
    let names = ["A", "B", "C"];
    let subtasks: Vec<Subtask> = (0..k)
        .map(|i| Subtask {
            name: names[i].into(),
            task: Task::from_formula(
                ltl::parse(FORMULAS[below(rng, 6) as usize]).unwrap(),
                &translator,
            )
            .unwrap(),
        })
        .collect();
    let per_task: Vec<f64> = (0..k)
        .map(|_| f64::from(50 * (1 + below(rng, 4))))
        .collect();
    let names: Vec<String> = names[..k].iter().map(|n| n.to_string()).collect();
    let overrides = match below(rng, 2) {
        0 => vec![(TaskSet::all(k), per_task.iter().sum::<f64>() + 100.0)],
        _ => vec![],
    };
    let payoffs = SubsetPayoffs::new(&per_task, &overrides, &names).unwrap();
    let believed = match below(rng, 3) {
        0 => subtasks[0].task.formula.clone().unwrap(),
        1 => ltl::parse(FORMULAS[below(rng, 6) as usize]).unwrap(),
        _ => ltl::parse(&format!(
            "({}) & ({})",
            subtasks[0].task.formula.as_ref().unwrap(),
            subtasks[1].task.formula.as_ref().unwrap()
        ))
        .unwrap(),
    };
    let believed = Believed::from_formula(believed, &subtasks, &translator).unwrap();
    let risk = [Risk::Paper, Risk::Paper, Risk::Strict, Risk::Neutral][below(rng, 4) as usize];
    Tasks::new(subtasks, payoffs, believed, risk)
}

/// One problem solved by both engines.
pub struct Engines<'e, M: Moves> {
    /// The explicit engine's product and its solved view.
    pub game: &'e Hypergame<'e>,
    pub solved: &'e SolvedHypergame<'e, 'e>,
    /// The explicit engine's MDP, solution and controller evaluation.
    pub explicit: &'e OpportunisticSolution,
    /// The implicit engine's model and solution.
    pub model: &'e Model<'e, 'e, M>,
    pub implicit: &'e Solution,
    /// The discount, sigma_L and the precision both solved to.
    pub g: f64,
    pub sigma_l: SigmaL,
}

/// Solves `tasks` on `arena` with both engines (`moves` describes `arena`) at a random
/// discount and sigma_L (uniform, random or a random weight table), and runs `test` on them.
pub fn solve_both<M: Moves>(
    moves: &M,
    arena: &Arena,
    tasks: &Tasks,
    rng: &mut ChaCha8Rng,
    test: impl FnOnce(&Engines<'_, M>),
) {
    let g = [0.9, 0.99, 1.0][below(rng, 3) as usize];
    let sigma_l = match below(rng, 3) {
        0 => SigmaL::Uniform,
        1 => SigmaL::Random {
            seed: u64::from(below(rng, 1000)),
        },
        _ => SigmaL::Weights {
            table: random_table(rng, arena),
            file: "w.txt".into(),
        },
    };
    let game = tasks.hypergame(arena, States::Full).unwrap();
    let regions = tasks.regions(&game);
    let solved = SolvedHypergame::new(&game, &regions, tasks.payoffs(), tasks.presentation());
    let options = MdpOptions {
        sigma_l: sigma_l.clone(),
        seed: 1,
        solve: SolveOptions {
            discount: Discount::new(g).unwrap(),
            epsilon: EPSILON,
            ..SolveOptions::default()
        },
        learnt: None,
    };
    let explicit = OpportunisticSolution::solve(&solved, tasks.risk(), &options, &mut ()).unwrap();

    with_model(moves, tasks, &sigma_l, |model| {
        let model = model.unwrap();
        let implicit = solve(&model, g, Precision::absolute(EPSILON), 100_000).unwrap();
        test(&Engines {
            game: &game,
            solved: &solved,
            explicit: &explicit,
            model: &model,
            implicit: &implicit,
            g,
            sigma_l: sigma_l.clone(),
        })
    });
}

/// Runs `test` on the implicit engine's model of `tasks` on `moves` with `sigma_l` (or why it
/// cannot be made).
pub fn with_model<M: Moves, R>(
    moves: &M,
    tasks: &Tasks,
    sigma_l: &SigmaL,
    test: impl FnOnce(Result<Model<'_, '_, M>, ModelError>) -> R,
) -> R {
    let automata: Vec<_> = tasks.automata().into_iter().map(|(_, dfa)| dfa).collect();
    let space = Space::new(moves, &automata).unwrap();
    let k = tasks.subtasks().len();
    let won = Regions::compute(&space, k, tasks.believed().belief());
    test(Model::new(
        &space,
        &won,
        tasks.payoffs(),
        tasks.presentation(),
        tasks.risk(),
        sigma_l,
    ))
}

/// Compares every product state's interval: both at most epsilon wide and overlapping, so that
/// both contain the exact value; also the absorbing states and the choices, in order, against
/// the explicit MDP's, and each chance node's distribution, bit for bit, against the explicit
/// engine's adversary model.
fn compare<M: Moves>(engines: &Engines<'_, M>, tasks: &Tasks, case: &str) {
    let Engines {
        game,
        solved,
        explicit,
        model,
        implicit,
        g,
        sigma_l,
        ..
    } = engines;
    let mdp = explicit.mdp.mdp();
    let adversary = AdversaryModel::new(*solved, sigma_l).unwrap();
    let (mut scratch, mut expected) = (Vec::new(), Vec::new());
    for h in game.states() {
        let e = explicit.solution.value(MdpState::new(h.index()));
        let i = implicit.value(model, h.as_u32());
        let name = game.name(h);
        assert!(
            e.upper - e.lower <= EPSILON,
            "{case} {name}: explicit {e:?}"
        );
        assert!(
            i.upper - i.lower <= EPSILON,
            "{case} {name}: implicit {i:?}"
        );
        assert!(
            i.lower <= e.upper + 1e-9 && e.lower <= i.upper + 1e-9,
            "{case} {name}, g = {g}, {sigma_l:?}, risk {:?}: explicit {e:?}, implicit {i:?}",
            tasks.risk()
        );
        let node = MdpState::new(h.index());
        let kind = model.kind(h.as_u32());
        assert_eq!(
            matches!(kind, Kind::Absorbing(_)),
            mdp.is_absorbing(node),
            "{case} {name}: absorbing"
        );
        // The choices of a decision node: arena actions with their successor, then stop with
        // its sink (numbered after the product states), or the adversary's distribution.
        let explicit_choices: Vec<Listed> = mdp
            .choices(node)
            .map(|c| {
                let action = explicit.mdp.arena_action(c);
                let targets = mdp.targets(c).iter().map(|t| t.index());
                (
                    action,
                    targets.zip(mdp.probabilities(c).iter().copied()).collect(),
                )
            })
            .collect();
        let mut implicit_choices = Vec::new();
        match kind {
            Kind::Decision => model.choices(h.as_u32(), |c| {
                implicit_choices.push(match c {
                    Choice::Move { action, target } => (Some(action), vec![(target as usize, 1.0)]),
                    Choice::Stop { payoff } => {
                        let sink = model.stop_sink(h.as_u32());
                        assert_eq!(payoff, model.sinks()[sink].payoff, "{case} {name}: stop");
                        (None, vec![(game.num_states() + sink, 1.0)])
                    }
                })
            }),
            Kind::Chance => {
                let mut distribution = Distribution::default();
                model.distribution(h.as_u32(), &mut distribution);
                adversary.positive_moves(*solved, h, &mut scratch, &mut expected);
                let expected: Vec<(u32, f64)> =
                    expected.iter().map(|&(t, p)| (t.as_u32(), p)).collect();
                assert_eq!(
                    distribution.iter().collect::<Vec<_>>(),
                    expected,
                    "{case} {name}: {sigma_l:?}"
                );
                // The explicit MDP lists a distribution by target, parallel moves merged.
                let mut moves: Vec<(usize, f64)> = Vec::new();
                let mut sorted: Vec<(u32, f64)> = distribution.iter().collect();
                sorted.sort_by_key(|&(t, _)| t);
                for (t, p) in sorted {
                    match moves.last_mut() {
                        Some(last) if last.0 == t as usize => last.1 += p,
                        _ => moves.push((t as usize, p)),
                    }
                }
                implicit_choices.push((None, moves));
            }
            Kind::Absorbing(_) => {}
        }
        // Probabilities within rounding: the explicit MDP's builder stores them its own way.
        let same = implicit_choices.len() == explicit_choices.len()
            && implicit_choices
                .iter()
                .zip(&explicit_choices)
                .all(|(i, e)| {
                    i.0 == e.0
                        && i.1.len() == e.1.len()
                        && i.1
                            .iter()
                            .zip(&e.1)
                            .all(|(x, y)| x.0 == y.0 && (x.1 - y.1).abs() < 1e-12)
                });
        assert!(
            same,
            "{case} {name}: choices {implicit_choices:?} against {explicit_choices:?}"
        );
    }
}

#[test]
fn values_equal_the_explicit_engines_on_random_text_arenas() {
    let mut rng = ChaCha8Rng::seed_from_u64(21);
    for case in 0..120 {
        let arena = random_arena(&mut rng, case);
        let tasks = random_tasks(&mut rng);
        let moves = ArenaMoves::new(&arena);
        solve_both(&moves, &arena, &tasks, &mut rng, |engines| {
            compare(engines, &tasks, &format!("arena case {case}"))
        });
    }
}

/// A relative precision: every live state's interval at most 5% of its lower bound wide, and
/// overlapping the explicit engine's (certified to `EPSILON`), so that both contain the value;
/// values reach 300 here, and some intervals stay wider than an absolute 0.05 would allow.
#[test]
fn a_relative_precision_bounds_each_gap_by_its_lower_bound() {
    let mut rng = ChaCha8Rng::seed_from_u64(25);
    let mut loose = 0;
    for case in 0..60 {
        let arena = random_arena(&mut rng, case);
        let tasks = random_tasks(&mut rng);
        let moves = ArenaMoves::new(&arena);
        solve_both(&moves, &arena, &tasks, &mut rng, |engines| {
            let (model, g) = (engines.model, engines.g);
            let relative = solve(model, g, Precision::relative(0.05), 100_000).unwrap();
            for h in engines.game.states() {
                let e = engines.explicit.solution.value(MdpState::new(h.index()));
                let r = relative.value(model, h.as_u32());
                let name = engines.game.name(h);
                assert!(
                    r.upper - r.lower <= 0.05 * r.lower.max(0.0) * (1.0 + 1e-12),
                    "case {case} {name}: {r:?} wider than 5% of its lower bound"
                );
                assert!(
                    r.lower <= e.upper + 1e-9 && e.lower <= r.upper + 1e-9,
                    "case {case} {name}: {r:?} against the explicit {e:?}"
                );
                loose += usize::from(r.upper - r.lower > 0.05);
            }
        });
    }
    // Some interval is wider than an absolute 0.05 would allow: the precision is relative.
    assert!(loose > 0, "no interval was left wider than 0.05");
}

#[test]
fn values_equal_the_explicit_engines_on_random_maps() {
    let mut rng = ChaCha8Rng::seed_from_u64(23);
    for case in 0..60 {
        let world = random_world(&mut rng);
        let arena = world.build().unwrap();
        let tasks = random_tasks(&mut rng);
        let moves = MapMoves::new(&world).unwrap();
        solve_both(&moves, &arena, &tasks, &mut rng, |engines| {
            compare(engines, &tasks, &format!("map case {case}"))
        });
    }
}

/// The solve and (at g = 1) the policy of `model` on a one-thread pool, sweeping in index
/// order from the rules, against both on a two-thread pool, every component of two states or
/// more compiled and, where its turns alternate, swept by player: the same bounds, bit for bit,
/// the same sweeps and the same choices. Whether the model had a component swept more than once.
fn same_on_two_threads<M: Moves>(model: &Model<'_, '_, M>, g: f64, case: &str) -> bool {
    let pool = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
    };
    let (one_thread, two) = (pool(1), pool(2));
    let precision = Precision::absolute(EPSILON);
    // One thread, every state backed up from the rules, in index order; two threads, every
    // component of two states or more compiled, swept by player where its turns alternate.
    let rules = Tuning {
        coloured: usize::MAX,
        compiled: 0,
    };
    let compiled = Tuning {
        coloured: 2,
        compiled: usize::MAX,
    };
    let one = one_thread
        .install(|| solve_tuned(model, g, precision, 100_000, rules))
        .unwrap();
    let by_player = two
        .install(|| solve_tuned(model, g, precision, 100_000, compiled))
        .unwrap();
    assert_eq!(one.iterations(), by_player.iterations(), "{case}");
    for h in 0..model.space().num_states() as u32 {
        let (a, b) = (one.value(model, h), by_player.value(model, h));
        assert_eq!(
            (a.lower.to_bits(), a.upper.to_bits()),
            (b.lower.to_bits(), b.upper.to_bits()),
            "{case}, state {h}"
        );
    }
    // At g = 1 the policy (its ties, ranks, expected moves and proof of properness), chosen
    // alike.
    if g == 1.0 {
        let first = one_thread
            .install(|| policy_tuned(model, &one, g, 100_000, rules))
            .unwrap();
        let second = two
            .install(|| policy_tuned(model, &by_player, g, 100_000, compiled))
            .unwrap();
        for h in 0..model.space().num_states() as u32 {
            assert_eq!(first.choice(h), second.choice(h), "{case}, state {h}");
        }
    }
    one.iterations() > 1
}

#[test]
fn solving_on_two_threads_gives_the_one_thread_solves_bounds_and_choices_bit_for_bit() {
    // The searches of the graph (the waves of the payoff levels, the settled states, the
    // policy's ranks), the masks, the ties and the choices are made on all threads, the sweeps
    // of large components by player: on one thread and on two, the same results.
    let mut rng = ChaCha8Rng::seed_from_u64(27);
    let mut coloured = 0;
    for case in 0..24 {
        // Open grids of side 4 to 6 (the random worlds are too small for cycles of more than
        // one state to survive the regions), a and b on random cells.
        let n = 4 + below(&mut rng, 3);
        let cell = |rng: &mut ChaCha8Rng| Cell {
            x: below(rng, n),
            y: below(rng, n),
        };
        let mut world = Gridworld::new(n, n, Cell { x: 0, y: n / 2 }, Cell { x: n - 1, y: n / 2 });
        world.labels = vec![("a".into(), cell(&mut rng)), ("b".into(), cell(&mut rng))];
        let tasks = random_tasks(&mut rng);
        let moves = MapMoves::new(&world).unwrap();
        let sigma_l = match case % 2 {
            0 => SigmaL::Uniform,
            _ => SigmaL::Random { seed: case },
        };
        let g = [0.9, 0.99, 1.0][case as usize % 3];
        with_model(&moves, &tasks, &sigma_l, |model| {
            let case = format!("map case {case}");
            coloured += usize::from(same_on_two_threads(&model.unwrap(), g, &case));
        });
    }
    // Most cases have a component swept more than once (the case of a map is a cycle).
    assert!(coloured >= 12, "{coloured} cases with a cycle");
    // Random text arenas, whose states the searches reach through their stored predecessors.
    for case in 0..12 {
        let arena = random_arena(&mut rng, case);
        let tasks = random_tasks(&mut rng);
        let moves = ArenaMoves::new(&arena);
        let g = [0.9, 1.0][case as usize % 2];
        with_model(&moves, &tasks, &SigmaL::Uniform, |model| {
            same_on_two_threads(&model.unwrap(), g, &format!("arena case {case}"));
        });
    }
}

#[test]
fn an_invalid_discount_or_precision_is_refused() {
    use hypersynth::implicit::SolveError;
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let arena = random_arena(&mut rng, 0);
    let tasks = random_tasks(&mut rng);
    let moves = ArenaMoves::new(&arena);
    with_model(&moves, &tasks, &SigmaL::Uniform, |model| {
        let model = model.unwrap();
        for (g, epsilon) in [(0.0, 1e-6), (1.5, 1e-6), (0.9, 0.0), (0.9, f64::INFINITY)] {
            assert_eq!(
                solve(&model, g, Precision::absolute(epsilon), 100).unwrap_err(),
                SolveError::Invalid {
                    discount: g,
                    epsilon
                },
                "g = {g}, epsilon = {epsilon}"
            );
        }
    });
}

/// Checks that the implicit engine refuses `table` with the explicit engine's errors, and that
/// these are those of `kinds`, in order (NaN weights compared as such).
fn refuses_as_the_explicit_engine<M: Moves>(
    moves: &M,
    arena: &Arena,
    tasks: &Tasks,
    (table, kinds): (WeightTable, Vec<EntryError>),
    case: &str,
) {
    let game = tasks.hypergame(arena, States::Full).unwrap();
    let regions = tasks.regions(&game);
    let solved = SolvedHypergame::new(&game, &regions, tasks.payoffs(), tasks.presentation());
    let sigma_l = SigmaL::Weights {
        table,
        file: "w.txt".into(),
    };
    let explicit = AdversaryModel::new(&solved, &sigma_l).unwrap_err();
    let implicit = with_model(moves, tasks, &sigma_l, |model| model.err());
    let Some(ModelError::Table(implicit)) = implicit else {
        panic!("{case}: the implicit engine took the table");
    };
    assert_eq!(implicit.to_string(), explicit.to_string(), "{case}");
    let found: Vec<String> = implicit
        .as_slice()
        .iter()
        .map(|e| format!("{:?}", e.error))
        .collect();
    let expected: Vec<String> = kinds.iter().map(|e| format!("{e:?}")).collect();
    assert_eq!(found, expected, "{case}");
}

#[test]
fn a_bad_weight_table_gets_the_explicit_engines_errors() {
    let mut rng = ChaCha8Rng::seed_from_u64(31);
    let mut kinds = std::collections::BTreeSet::new();
    let mut disabled = false;
    let mut meet = |bad: &(WeightTable, Vec<EntryError>)| {
        for kind in &bad.1 {
            kinds.insert(format!("{:?}", std::mem::discriminant(kind)));
            disabled |=
                matches!(kind, EntryError::UnknownAction { action, .. } if action != "nothing");
        }
    };
    for case in 0..40 {
        let arena = random_arena(&mut rng, case);
        let tasks = random_tasks(&mut rng);
        let bad = bad_table(&arena);
        meet(&bad);
        let moves = ArenaMoves::new(&arena);
        refuses_as_the_explicit_engine(&moves, &arena, &tasks, bad, &format!("arena {case}"));
        let world = random_world(&mut rng);
        let arena = world.build().unwrap();
        let tasks = random_tasks(&mut rng);
        let bad = bad_table(&arena);
        meet(&bad);
        let moves = MapMoves::new(&world).unwrap();
        refuses_as_the_explicit_engine(&moves, &arena, &tasks, bad, &format!("map {case}"));
    }
    // Every kind of error, the disabled action's included, was met.
    assert_eq!(kinds.len(), 6, "{kinds:?}");
    assert!(disabled);
}

//! Certificates (docs/semantics.md §9.4): every committed example and random arenas (adversary
//! chains, diamonds and cycles, end components) export a certificate that checks, with bounds
//! around the reported value; single changes of a file are refused whenever they make a
//! claimed bound false (judged by the library's own evaluation and solver, which the checker
//! shares nothing with), naming the state; and without its ranks a cycle that never pays would
//! pass the inequalities.

use rand_chacha::ChaCha8Rng;
use rand_core::{RngCore, SeedableRng};

use hypersynth::arena::Arena;
use hypersynth::certificate::{self, Bound, CheckError};
use hypersynth::game::{Payoffs, States};
use hypersynth::mdp::solve::{Discount, SolveOptions};
use hypersynth::opportunistic::adversary::{AdversaryModel, SigmaL};
use hypersynth::opportunistic::evaluate::ControllerEvaluation;
use hypersynth::opportunistic::executor::Executor;
use hypersynth::opportunistic::export::{ArenaSource, Choice, ControllerFile, Mode, Table};
use hypersynth::opportunistic::view::{GameView, SolvedHypergame};
use hypersynth::pipeline::{self, MdpOptions, Problem, Requests, Task, Tasks};
use hypersynth::translate::{Builtin, TranslationLimits};

use crate::common::{self, examples, map_arena};

/// What a run reports and exports: the controller file (with its certificate), the solver's
/// bounds on h0's value and the controller's own value at h0 (upper bound).
struct Exported {
    file: ControllerFile,
    value: [f64; 2],
    policy_upper: f64,
}

fn problem(arena: &Arena, tasks: &Tasks, sigma_l: SigmaL, g: f64) -> Problem {
    Problem {
        arena_name: "arena".into(),
        arena: arena.clone(),
        map: None,
        tasks: tasks.clone(),
        states: States::Full,
        mdp: Some(MdpOptions {
            sigma_l,
            seed: 1,
            solve: SolveOptions {
                discount: Discount::new(g).unwrap(),
                ..SolveOptions::default()
            },
            learnt: None,
        }),
    }
}

fn export(problem: &Problem) -> Exported {
    let requests = Requests {
        export_controller: true,
        certificate: true,
        ..Requests::default()
    };
    let outcome = pipeline::run(problem, &requests, &mut ()).unwrap();
    let decision = outcome.report.synthesis.unwrap().decision;
    Exported {
        file: serde_json::from_str(&outcome.controller.unwrap()).unwrap(),
        value: [decision.value, decision.value_upper],
        policy_upper: decision.policy_value_upper,
    }
}

/// The certified bounds hold around the reported value, within the solver's precision.
fn assert_bounds(exported: &Exported, context: &str) -> certificate::Certified {
    let certified =
        certificate::check(exported.file.clone()).unwrap_or_else(|e| panic!("{context}: {e}"));
    let [lower, upper] = exported.value;
    let slack = 1e-9 * upper.max(1.0);
    assert!(
        certified.lower <= exported.policy_upper + slack,
        "{context}: {certified:?}"
    );
    assert!(certified.lower <= upper + slack, "{context}: {certified:?}");
    assert!(certified.upper >= lower - slack, "{context}: {certified:?}");
    assert!(
        certified.upper - certified.lower <= 1e-6 + slack,
        "{context}: {certified:?}, reported [{lower}, {upper}]"
    );
    certified
}

#[test]
fn every_example_exports_a_certificate_that_checks() {
    for (name, tasks, map, _) in examples() {
        let (arena, world) = map_arena(map);
        for g in [1.0, 0.99] {
            for sigma_l in [SigmaL::Uniform, SigmaL::Random { seed: 2019 }] {
                let mut problem = problem(&arena, &tasks, sigma_l.clone(), g);
                problem.map = Some(world.clone());
                let exported = export(&problem);
                let certified = assert_bounds(&exported, &format!("{name}, g = {g}, {sigma_l:?}"));
                assert!(certified.lower > 0.0, "{name}");
            }
        }
    }
}

/// The learnt example's problem (`make learnt`): the case study with sigma_L learnt from
/// specs/learnt's runs at confidence `1 − delta`, the model (`--adversary`) the truth those
/// runs were recorded against.
fn learnt_problem(g: f64, delta: f64) -> Problem {
    use hypersynth::opportunistic::adversary::WeightTable;
    use hypersynth::opportunistic::observations::Observations;
    let specs = concat!(env!("CARGO_MANIFEST_DIR"), "/../../specs/learnt");
    let read = |name: &str| std::fs::read_to_string(format!("{specs}/{name}")).unwrap();
    let truth = SigmaL::Weights {
        table: WeightTable::parse(&read("truth.txt")).unwrap(),
        file: "truth.txt".into(),
    };
    let (name, tasks, map, _) = examples().remove(0);
    assert_eq!(name, "case study");
    let (arena, world) = map_arena(map);
    let mut problem = problem(&arena, &tasks, truth, g);
    problem.map = Some(world);
    problem.mdp.as_mut().unwrap().learnt = Some(pipeline::Learnt {
        observations: Observations::parse(&read("runs.txt")).unwrap(),
        file: "runs.txt".into(),
        delta,
    });
    problem
}

/// The exported controller of `problem` (sigma_L learnt) and the report's robust summary.
fn export_robust(problem: &Problem) -> (ControllerFile, hypersynth::report::RobustSummary) {
    let requests = Requests {
        export_controller: true,
        certificate: true,
        ..Requests::default()
    };
    let outcome = pipeline::run(problem, &requests, &mut ()).unwrap();
    let robust = outcome.report.synthesis.unwrap().robust.unwrap();
    (
        serde_json::from_str(&outcome.controller.unwrap()).unwrap(),
        robust,
    )
}

/// With sigma_L learnt, the exported controller is the robust one and its certificate holds
/// against every adversary within the learnt region (§9.4): the file names the counts the
/// report counted and delta, its value is the robust solver's, and the certified bounds lie
/// around the robust value within the solver's precision; L is at most what the controller
/// collects against the worst case (the report's check, by the nominal solver). Changing the
/// confidence parameter changes the region: a wider one (delta 1e-9) makes L false and a
/// narrower one (delta 0.9) makes U false, by the robust value of the changed problem, and the
/// checker refuses each such file; whenever it accepts one, both bounds hold for it.
#[test]
fn the_learnt_example_certifies_its_robust_controller() {
    use hypersynth::opportunistic::export::SigmaLRule;
    for g in [0.99, 1.0] {
        let (file, robust) = export_robust(&learnt_problem(g, 0.05));
        let SigmaLRule::Learnt { delta, counts } = &file.sigma_l else {
            panic!(
                "g = {g}: the file names no learnt sigma_L: {:?}",
                file.sigma_l
            );
        };
        assert_eq!(*delta, 0.05);
        let counted: u64 = counts.iter().map(|c| u64::from(c.count)).sum();
        assert_eq!(counted, robust.counted, "g = {g}");
        assert_eq!(file.value, [robust.value, robust.value_upper], "g = {g}");
        let certified = certificate::check(file.clone()).unwrap_or_else(|e| panic!("g = {g}: {e}"));
        let slack = 1e-9 * robust.value_upper.max(1.0);
        assert!(certified.lower > 0.0, "g = {g}: {certified:?}");
        assert!(
            certified.lower <= robust.value_upper + slack,
            "g = {g}: {certified:?}"
        );
        // The report gives the lower bound of the worst case's value, certified to 1e-6.
        assert!(
            certified.lower <= robust.worst_case_value + 1e-6 + slack,
            "g = {g}: {certified:?}"
        );
        assert!(
            certified.upper >= robust.value - slack,
            "g = {g}: {certified:?}"
        );
        assert!(
            certified.upper - certified.lower <= 1e-6 + slack,
            "g = {g}: {certified:?}"
        );
        // The region, not the truth: the robust value lies below the nominal one.
        assert!(
            certified.upper <= robust.nominal_value_upper + slack,
            "g = {g}"
        );
        let mut refused = 0;
        for changed_delta in [1e-9, 0.9] {
            let mut changed = file.clone();
            if let SigmaLRule::Learnt { delta, .. } = &mut changed.sigma_l {
                *delta = changed_delta;
            }
            let (_, truth) = export_robust(&learnt_problem(g, changed_delta));
            let context = format!("g = {g}, delta {changed_delta}");
            let slack = 1e-9 * truth.value_upper.max(1.0);
            match certificate::check(changed) {
                Ok(accepted) => {
                    assert!(accepted.lower <= truth.value_upper + slack, "{context}");
                    assert!(accepted.upper >= truth.value - slack, "{context}");
                }
                Err(CheckError::Refused(refusal)) => {
                    let false_bound = match refusal.bound {
                        Bound::Lower => certified.lower > truth.value_upper + slack,
                        Bound::Upper => certified.upper < truth.value - slack,
                    };
                    assert!(false_bound, "{context}: refused a true bound: {refusal}");
                    refused += 1;
                }
                Err(other) => panic!("{context}: {other}"),
            }
        }
        if g < 1.0 {
            // At g = 0.99 the region matters at h0 both ways.
            assert_eq!(refused, 2, "g = {g}");
        }
    }
}

/// With `--controller-scope all` the certificate covers every robot state a play can reach
/// from h0 (any move of either player), not only those the controller reaches: on the case
/// study and the decoy it checks, and at each such state x lies within the controller's own
/// value from there and y above the MDP's (both by the library's evaluation and solver, which
/// the checker shares nothing with).
#[test]
fn scope_all_certifies_every_state_a_play_reaches() {
    use hypersynth::opportunistic::export::Scope;
    for (name, tasks, map, g) in examples().into_iter().take(2) {
        let (arena, world) = map_arena(map);
        let mut problem = problem(&arena, &tasks, SigmaL::Random { seed: 2019 }, g);
        problem.map = Some(world);
        let requests = Requests {
            export_controller: true,
            certificate: true,
            controller_scope: Scope::All,
            ..Requests::default()
        };
        let solved = pipeline::Solved::new(&problem, &mut ()).unwrap();
        let outcome = solved.outcome(&requests, &mut ()).unwrap();
        let file: ControllerFile = serde_json::from_str(&outcome.controller.unwrap()).unwrap();
        assert_eq!(file.scope, Scope::All, "{name}");
        let certified = certificate::check(file.clone()).unwrap_or_else(|e| panic!("{name}: {e}"));
        // x and y by state name, where the file lists them.
        let listed = |file: &ControllerFile| {
            let tables = file.certificate.as_ref().unwrap();
            let values: Vec<f64> = present(&tables.values)
                .iter()
                .map(|&(_, v)| f64::from_bits(v))
                .collect();
            let names = certificate::carried_states(file).unwrap();
            let [lower, upper] = [&tables.lower, &tables.upper].map(|table| {
                present(table)
                    .iter()
                    .map(|&(_, i)| values[i as usize])
                    .collect::<Vec<f64>>()
            });
            let [lower_names, upper_names] = names;
            let by_name = |names: Vec<String>, values: Vec<f64>| {
                names
                    .into_iter()
                    .zip(values)
                    .collect::<std::collections::HashMap<String, f64>>()
            };
            (by_name(lower_names, lower), by_name(upper_names, upper))
        };
        let (lower, upper) = listed(&file);
        // The lower values of the default scope: the states the controller reaches from h0.
        let reachable = Requests {
            controller_scope: Scope::Reachable,
            ..requests
        };
        let outcome = solved.outcome(&reachable, &mut ()).unwrap();
        let reachable: ControllerFile = serde_json::from_str(&outcome.controller.unwrap()).unwrap();
        let (from_h0, _) = listed(&reachable);
        let game = solved.game();
        let solution = solved.solution.as_ref().unwrap();
        let tuples = file.tuples.len();
        // The robot states a play reaches: a search over the product from h0, any move.
        let mut seen = std::collections::HashSet::from([game.initial()]);
        let mut stack = vec![game.initial()];
        let (mut robot, mut beyond, mut positive) = (0, 0, 0);
        while let Some(h) = stack.pop() {
            for (_, t) in game.edges(h) {
                if seen.insert(t) {
                    stack.push(t);
                }
            }
            if !game.is_robot(h) {
                continue;
            }
            robot += 1;
            let e = game.arena_state(h).index() * tuples + solved.product.automata_slot(h) as usize;
            let state = entry_name(&file, &arena, e);
            let context = format!("{name}, {state}");
            let own = solution.evaluation.value(h);
            let best = solution.solution.value(solution.mdp.node(h));
            let slack = 1e-9 * best.upper.max(1.0);
            if let Some(&x) = lower.get(&state) {
                assert!(x <= own.upper + slack, "{context}: x = {x}, {own:?}");
                assert!(
                    x >= own.lower - 1e-6,
                    "{context}: x = {x} far below {own:?}"
                );
                positive += usize::from(x > 0.0);
                // States the controller's own play from h0 never visits are covered too.
                beyond += usize::from(x > 0.0 && !from_h0.contains_key(&state));
            }
            if let Some(&y) = upper.get(&state) {
                assert!(y >= best.lower - slack, "{context}: y = {y}, {best:?}");
                assert!(
                    y <= best.upper + 1e-6,
                    "{context}: y = {y} far above {best:?}"
                );
            }
        }
        assert!(
            certified.lower_states >= robot,
            "{name}: {certified:?}, {robot}"
        );
        assert!(positive > 0 && beyond > 0, "{name}");
    }
}

/// The tasks of random instance `instance`: the paper's form from two random DFAs, or (every
/// third) the general form with psi its own random automaton and the strict risk rule.
fn random_tasks(rng: &mut ChaCha8Rng, instance: u32) -> Tasks {
    let (dfa1, dfa2) = (common::random_dfa(rng), common::random_dfa(rng));
    if instance % 3 != 2 {
        return Tasks::from_parts(
            Task::from_automaton("phi1", &dfa1),
            Task::from_automaton("phi2", &dfa2),
            Payoffs::default(),
        );
    }
    let psi = common::random_dfa(rng);
    let subtasks = vec![
        pipeline::Subtask {
            name: "A".into(),
            task: Task::from_automaton("A", &dfa1),
        },
        pipeline::Subtask {
            name: "B".into(),
            task: Task::from_automaton("B", &dfa2),
        },
    ];
    let names = ["A".to_string(), "B".to_string()];
    let payoffs = hypersynth::game::SubsetPayoffs::new(&[200.0, 100.0], &[], &names).unwrap();
    let believed = pipeline::Believed::Automaton(Box::new(Task::from_automaton("psi", &psi)));
    Tasks::new(
        subtasks,
        payoffs,
        believed,
        hypersynth::opportunistic::build::Risk::Strict,
    )
}

/// The arena of a file.
fn file_arena(file: &ControllerFile) -> Arena {
    match &file.arena {
        ArenaSource::Text(text) => hypersynth::arena::parse(text).unwrap().arena,
        ArenaSource::Map(text) => hypersynth::arena::map::parse(text)
            .unwrap()
            .build()
            .unwrap(),
    }
}

/// The name of a certificate table's entry `e`, as the checker names states.
fn entry_name(file: &ControllerFile, arena: &Arena, e: usize) -> String {
    let tuples = file.tuples.len();
    let s = hypersynth::arena::StateId::new(e / tuples);
    let mut name = arena.name(s).to_string();
    for q in &file.tuples[e % tuples] {
        name.push_str(&format!("|{q}"));
    }
    name
}

/// `table` with entry `e` replaced by `value` (added when `e` is its length).
fn replaced(table: &Table, e: usize, value: Option<u64>) -> Table {
    let entries = table.decode().unwrap();
    let len = entries.len().max(e + 1);
    Table::encode(|| (0..len).map(|i| if i == e { value } else { entries.get(i) }))
}

/// The present entries of `table`.
fn present(table: &Table) -> Vec<(usize, u64)> {
    let entries = table.decode().unwrap();
    (0..entries.len())
        .filter_map(|i| Some((i, entries.get(i)?)))
        .collect()
}

/// `file` with a new value for `x` (lower) or `y` (upper) at position `i` of the certificate's
/// list (the `i`-th state of `certificate::carried_states`).
fn with_value(file: &ControllerFile, upper: bool, i: usize, value: f64) -> ControllerFile {
    let mut file = file.clone();
    let certificate = file.certificate.as_mut().unwrap();
    let mut values: Vec<u64> = present(&certificate.values)
        .iter()
        .map(|&(_, v)| v)
        .collect();
    values.push(value.to_bits());
    certificate.values = Table::encode_wide(11, || values.iter().map(|&v| Some(v)));
    let index = Some(values.len() as u64 - 1);
    let table = if upper {
        &mut certificate.upper
    } else {
        &mut certificate.lower
    };
    *table = replaced(table, i, index);
    file
}

/// The refusal of `file`, which must be refused with `bound` at a named state.
fn refusal_of(file: ControllerFile, bound: Bound, context: &str) -> certificate::Refusal {
    match certificate::check(file) {
        Err(CheckError::Refused(refusal)) => {
            assert_eq!(refusal.bound, bound, "{context}: {refusal}");
            refusal
        }
        other => panic!("{context}: expected a refusal of the {bound} certificate, got {other:?}"),
    }
}

/// What the controller of `file` really collects from h0 on the file's own arena, against
/// `sigma_l`, by the library's evaluation (which the checker shares nothing with); `None` when
/// the file does not load as a controller.
fn controller_value(file: &ControllerFile, tasks: &Tasks, sigma_l: &SigmaL) -> Option<f64> {
    let executor = Executor::new(file.clone()).ok()?;
    let arena = file_arena(file);
    let product = tasks.hypergame(&arena, States::Full).unwrap();
    let regions = tasks.regions(&product);
    let game = SolvedHypergame::new(&product, &regions, tasks.payoffs(), tasks.presentation());
    let adversary = AdversaryModel::new(&game, sigma_l).unwrap();
    let plan = executor.plan(&game);
    let evaluation = ControllerEvaluation::new(&plan, &adversary, 1e-12, 1_000_000).ok()?;
    Some(evaluation.value(game.initial()).upper)
}

/// If the checker accepts `file` (a change of a certified file, whose model is `tasks` on the
/// file's arena against `sigma_l` at discount `g`), both of its bounds are true: the file's
/// controller collects at least L, and the MDP's value is at most U. Whether it was accepted.
fn sound(file: &ControllerFile, tasks: &Tasks, sigma_l: &SigmaL, g: f64, context: &str) -> bool {
    let Ok(certified) = certificate::check(file.clone()) else {
        return false;
    };
    let collected = controller_value(file, tasks, sigma_l).expect("an accepted file loads");
    let value = export(&problem(&file_arena(file), tasks, sigma_l.clone(), g)).value;
    let slack = 1e-9 * value[1].max(1.0);
    assert!(
        certified.lower <= collected + slack,
        "{context}: accepted L = {} above what the controller collects, {collected}",
        certified.lower
    );
    assert!(
        certified.upper >= value[0] - slack,
        "{context}: accepted U = {} below the value {}",
        certified.upper,
        value[0]
    );
    true
}

#[test]
fn random_arenas_certify_and_changed_files_are_refused_when_a_bound_is_false() {
    let mut rng = ChaCha8Rng::seed_from_u64(936);
    let below = |rng: &mut ChaCha8Rng, n: usize| rng.next_u32() as usize % n;
    let (mut accepted, mut refused) = (0, 0);
    for instance in 0..90u32 {
        let arena = common::random_arena(&mut rng, instance);
        let tasks = random_tasks(&mut rng, instance);
        let g = [1.0, 0.9][instance as usize % 2];
        let sigma_l = match instance % 4 {
            0 | 1 => SigmaL::Random {
                seed: instance.into(),
            },
            _ => SigmaL::Uniform,
        };
        let context = format!("random arena {instance}, g = {g}, {sigma_l:?}");
        let exported = export(&problem(&arena, &tasks, sigma_l.clone(), g));
        assert_bounds(&exported, &context);
        let file = &exported.file;
        let certificate = file.certificate.as_ref().unwrap();
        let top = *file.payoffs.last().unwrap();

        // A lower value raised above every payoff: false there, refused there.
        let [lower, upper] = certificate::carried_states(file).unwrap();
        assert_eq!(present(&certificate.lower).len(), lower.len(), "{context}");
        assert_eq!(present(&certificate.upper).len(), upper.len(), "{context}");
        if !lower.is_empty() {
            let i = below(&mut rng, lower.len());
            let changed = with_value(file, false, i, top + 1.0);
            let refusal = refusal_of(changed, Bound::Lower, &context);
            assert_eq!(refusal.state, lower[i], "{context}");
        }

        // h0's upper value lowered below the value: refused at h0 (when it carries one).
        let h0 = name_of_h0(file, &arena);
        if exported.value[0] > 0.0
            && let Some(i) = upper.iter().position(|name| *name == h0)
        {
            let changed = with_value(file, true, i, exported.value[0] / 2.0);
            let refusal = refusal_of(changed, Bound::Upper, &context);
            assert_eq!(refusal.state, h0, "{context}");
        }

        // One value too many, or too few: refused.
        for (bound, upper) in [(Bound::Lower, false), (Bound::Upper, true)] {
            let mut changed = file.clone();
            let tables = changed.certificate.as_mut().unwrap();
            let table = if upper {
                &mut tables.upper
            } else {
                &mut tables.lower
            };
            let mut list: Vec<u64> = present(table).iter().map(|&(_, v)| v).collect();
            let empty = list.pop().is_none();
            *table = Table::encode(|| list.iter().map(|&v| Some(v)));
            if empty {
                // One value where no state carries one.
                changed = with_value(&changed, upper, 0, 0.0);
            }
            refusal_of(changed, bound, &format!("{context}, {bound} list changed"));
        }

        // Payoffs halved or doubled: every value scales with them, so the file's listed values
        // claim a false L (halved) or U (doubled) wherever they matter. The checker refuses,
        // or accepts bounds that are true of the scaled values (when every value that
        // matters is derived from the payoffs, as where h0 ends the play at once).
        for (factor, bound) in [(0.5, Bound::Lower), (2.0, Bound::Upper)] {
            let mut changed = file.clone();
            changed.payoffs.iter_mut().for_each(|r| *r *= factor);
            changed.value = [changed.value[0] * factor, changed.value[1] * factor];
            let context = format!("{context}, payoffs × {factor}");
            match certificate::check(changed) {
                Err(CheckError::Refused(refusal)) => {
                    assert_eq!(refusal.bound, bound, "{context}: {refusal}");
                    refused += 1;
                }
                Ok(scaled) => {
                    let slack = 1e-9 * factor * exported.value[1].max(1.0);
                    assert!(
                        scaled.lower <= factor * exported.policy_upper + slack,
                        "{context}: {scaled:?}"
                    );
                    assert!(
                        scaled.upper >= factor * exported.value[0] - slack,
                        "{context}: {scaled:?}"
                    );
                    accepted += 1;
                }
                Err(other) => panic!("{context}: {other:?}"),
            }
        }

        // A decision changed to another action enabled there.
        let decisions = file.modes.iter().find(|m| m.set == 0).unwrap();
        let robot_entries = present(&decisions.table);
        let robot_states: Vec<_> = arena
            .states()
            .filter(|&s| arena.owner(s) == hypersynth::arena::Owner::Robot)
            .collect();
        for &(i, c) in &robot_entries {
            let s = robot_states[i / file.tuples.len()];
            let Choice::Move(current) = &file.choices[c as usize] else {
                continue;
            };
            let Some((a, _)) = arena
                .edges(s)
                .find(|&(a, _)| arena.action_name(a) != current)
            else {
                continue;
            };
            let mut changed = file.clone();
            let other = Choice::Move(arena.action_name(a).to_string());
            let index = match changed.choices.iter().position(|c| *c == other) {
                Some(index) => index,
                None => {
                    changed.choices.push(other);
                    changed.choices.len() - 1
                }
            };
            let mode: &mut Mode = changed.modes.iter_mut().find(|m| m.set == 0).unwrap();
            mode.table = replaced(&mode.table, i, Some(index as u64));
            let context = format!("{context}, decision at {} changed", arena.name(s));
            match sound(&changed, &tasks, &sigma_l, g, &context) {
                true => accepted += 1,
                false => refused += 1,
            }
            break;
        }

        // sigma_L's draws changed (another seed).
        if let SigmaL::Random { seed } = sigma_l {
            let mut changed = file.clone();
            let other = SigmaL::Random { seed: seed + 1000 };
            changed.sigma_l = hypersynth::opportunistic::export::SigmaLRule::of(&other);
            match sound(
                &changed,
                &tasks,
                &other,
                g,
                &format!("{context}, seed changed"),
            ) {
                true => accepted += 1,
                false => refused += 1,
            }
        }

        // An arena edge redirected to another state.
        let ArenaSource::Text(text) = &file.arena else {
            unreachable!("random arenas travel as text")
        };
        let edges: Vec<(usize, &str)> = text
            .lines()
            .enumerate()
            .filter(|(_, line)| line.starts_with("edge "))
            .collect();
        if !edges.is_empty() {
            let (at, line) = edges[below(&mut rng, edges.len())];
            let words: Vec<&str> = line.split_whitespace().collect();
            let target = arena.name(hypersynth::arena::StateId::new(below(
                &mut rng,
                arena.num_states(),
            )));
            let new_line = format!("edge {} {} {}", words[1], words[2], target);
            let new_text: String = text
                .lines()
                .enumerate()
                .map(|(i, l)| if i == at { new_line.clone() } else { l.to_string() } + "\n")
                .collect();
            let mut changed = file.clone();
            changed.arena = ArenaSource::Text(new_text);
            let context = format!("{context}, `{line}` now to {target}");
            match sound(&changed, &tasks, &sigma_l, g, &context) {
                true => accepted += 1,
                false => refused += 1,
            }
        }
    }
    // Both outcomes occur: the changes are not all harmless, nor all refused.
    assert!(
        accepted > 0 && refused > 0,
        "{accepted} accepted, {refused} refused"
    );
}

/// The name of h0 in a file: the arena's initial state and the automata after reading its label.
fn name_of_h0(file: &ControllerFile, arena: &Arena) -> String {
    let s0 = arena.initial();
    let label: std::collections::BTreeSet<&str> = arena
        .label(s0)
        .iter()
        .map(|p| arena.propositions()[p].as_str())
        .collect();
    let letter = file
        .labels
        .iter()
        .position(|l| {
            l.iter()
                .map(String::as_str)
                .collect::<std::collections::BTreeSet<_>>()
                == label
        })
        .unwrap();
    let mut name = arena.name(s0).to_string();
    for automaton in &file.automata {
        let q = automaton.step[automaton.initial as usize][letter];
        name.push_str(&format!("|{q}"));
    }
    name
}

/// A robot state that moves into two adversary states that only lead to each other: a cycle
/// that never pays. Claiming the largest payoff on all three satisfies every inequality of the
/// lower certificate (x(r) ≤ x(c0), x(c0) ≤ x(c1), x(c1) ≤ x(c0)); only the rank condition
/// (no path of positive x leads to a payoff) refuses it.
#[test]
fn without_ranks_a_cycle_that_never_pays_would_be_certified() {
    let text = "propositions a b\nactions go x\ninitial r\nstate r robot {}\nedge r go c0\n\
                state c0 adversary {}\nedge c0 x c1\nstate c1 adversary {}\nedge c1 x c0\n\
                state t robot {a b}\n";
    let arena = hypersynth::arena::parse(text).unwrap().arena;
    let translator = Builtin::new(TranslationLimits::default());
    let task =
        |f: &str| Task::from_formula(hypersynth::ltl::parse(f).unwrap(), &translator).unwrap();
    let tasks = Tasks::from_parts(task("F a"), task("F b"), Payoffs::default());
    let exported = export(&problem(&arena, &tasks, SigmaL::Uniform, 1.0));
    let certified = certificate::check(exported.file.clone()).unwrap();
    assert_eq!((certified.lower, certified.upper), (0.0, 0.0));
    // The controller gives up at r (worth 0); make it move into the cycle and claim 300 there.
    let mut file = exported.file.clone();
    file.choices.push(Choice::Move("go".into()));
    let go = file.choices.len() as u64 - 1;
    let mode = file.modes.iter_mut().find(|m| m.set == 0).unwrap();
    let (r, _) = present(&mode.table)[0];
    mode.table = replaced(&mode.table, r, Some(go));
    // r moves and c0, c1 have an adversary successor each: all three carry their x, in this
    // order.
    let [lower, _] = certificate::carried_states(&file).unwrap();
    let names: Vec<&str> = lower.iter().map(|n| n.split('|').next().unwrap()).collect();
    assert_eq!(names, ["r", "c0", "c1"]);
    let tables = file.certificate.as_mut().unwrap();
    tables.lower = Table::encode(|| [0u64; 3].into_iter().map(Some));
    for i in 0..3 {
        file = with_value(&file, false, i, 300.0);
    }
    let refusal = refusal_of(file, Bound::Lower, "never-paying cycle");
    assert!(
        refusal.inequality.contains("no rank"),
        "every inequality held; the missing rank refuses it: {refusal}"
    );
}

/// A learnt region's ranks (§9.4): a robot state `r` moves into adversary state `c0`, which
/// steps to `t` (where both sub-tasks hold and the robot stops with the largest payoff) or to
/// `c1`, which steps back to `c0`; psi holds from the start, so sigma_L rules everywhere.
/// Observed 30 times at `c0` (20 to `t`; `c1`'s single action is certain), the step to `t` has a positive lower end, the
/// adversary cannot keep the play in the cycle, and at g = 1 the robust controller goes and
/// collects the largest payoff: certified, also when the largest payoff is claimed at `r`,
/// `c0` and `c1`. The same file with the counts removed (every
/// interval at `c0` `[0, 1]`) still satisfies every inequality (the least expectation over the
/// region is the largest payoff, both successors claiming it), but an adversary within that
/// region can loop forever: only the rank condition, which asks for a positive lower end
/// (or the others' upper ends below 1), refuses it.
#[test]
fn a_learnt_region_gives_no_rank_where_the_adversary_may_loop_forever() {
    use hypersynth::opportunistic::export::{Scope, SigmaLRule};
    use hypersynth::opportunistic::observations::Observations;
    let text = "propositions a b\nactions go x y\ninitial r\nstate r robot {a}\nedge r go c0\n\
                state c0 adversary {a}\nedge c0 x c1\nedge c0 y t\nstate c1 adversary {a}\n\
                edge c1 x c0\nstate t robot {a b}\n";
    let arena = hypersynth::arena::parse(text).unwrap().arena;
    let translator = Builtin::new(TranslationLimits::default());
    let task =
        |f: &str| Task::from_formula(hypersynth::ltl::parse(f).unwrap(), &translator).unwrap();
    let tasks = Tasks::from_parts(task("F a"), task("F b"), Payoffs::default());
    let runs = "r go c0 y t\nr go c0 x c1 x c0 y t\n".repeat(10);
    let mut problem = problem(&arena, &tasks, SigmaL::Uniform, 1.0);
    problem.mdp.as_mut().unwrap().learnt = Some(pipeline::Learnt {
        observations: Observations::parse(&runs).unwrap(),
        file: "runs.txt".into(),
        delta: 0.05,
    });
    let requests = Requests {
        export_controller: true,
        certificate: true,
        controller_scope: Scope::All,
        ..Requests::default()
    };
    let outcome = pipeline::run(&problem, &requests, &mut ()).unwrap();
    let file: ControllerFile = serde_json::from_str(&outcome.controller.unwrap()).unwrap();
    let SigmaLRule::Learnt { counts, .. } = &file.sigma_l else {
        panic!("{:?}", file.sigma_l);
    };
    let counts: Vec<(&str, &str, u32)> = counts
        .iter()
        .map(|c| (c.state.as_str(), c.action.as_str(), c.count))
        .collect();
    assert_eq!(counts, [("c0", "x", 10), ("c0", "y", 20), ("c1", "x", 10)]);
    let largest = *file.payoffs.last().unwrap();
    let certified = certificate::check(file.clone()).unwrap();
    assert!(certified.lower >= largest - 1e-6, "{certified:?}");
    // The value is exactly the largest payoff: claiming it at r, c0 and c1 certifies too.
    let [lower, _] = certificate::carried_states(&file).unwrap();
    let names: Vec<&str> = lower.iter().map(|n| n.split('|').next().unwrap()).collect();
    assert_eq!(names, ["r", "c0", "c1"]);
    let mut file = file;
    for i in 0..names.len() {
        file = with_value(&file, false, i, largest);
    }
    let certified = certificate::check(file.clone()).unwrap();
    assert_eq!(certified.lower, largest, "{certified:?}");
    let mut unobserved = file.clone();
    unobserved.sigma_l = SigmaLRule::Learnt {
        delta: 0.05,
        counts: Vec::new(),
    };
    let refusal = refusal_of(unobserved, Bound::Lower, "unobserved cycle");
    // The first state without a rank in the breadth-first order: r, whose one successor c0 has
    // none.
    assert!(refusal.state.starts_with("r|"), "{refusal}");
    assert!(refusal.inequality.contains("no rank"), "{refusal}");
}

/// Learnt regions on random arenas (adversary chains, diamonds and cycles; both forms; strict
/// risk; g = 1 and 0.9): sigma_L is learnt from a few runs recorded against a random sigma_L
/// (so some states are unobserved, some observed a few times), and the robust controller's
/// certificate checks with L <= the robust value <= U within the solver's precision, and L at
/// most what the controller collects against the worst case (the nominal solver's check).
#[test]
fn learnt_regions_on_random_arenas_certify() {
    use hypersynth::opportunistic::observations::Observations;
    let mut rng = ChaCha8Rng::seed_from_u64(3612);
    let mut positive = 0;
    for instance in 0..60u32 {
        let arena = common::random_arena(&mut rng, instance);
        let tasks = random_tasks(&mut rng, instance);
        let g = [1.0, 0.9][instance as usize % 2];
        let sigma_l = SigmaL::Random {
            seed: instance.into(),
        };
        let mut problem = problem(&arena, &tasks, sigma_l, g);
        let record = Requests {
            simulate: Some(1 + instance % 12),
            record: true,
            ..Requests::default()
        };
        let runs = pipeline::run(&problem, &record, &mut ())
            .unwrap()
            .record
            .unwrap();
        problem.mdp.as_mut().unwrap().learnt = Some(pipeline::Learnt {
            observations: Observations::parse(&runs).unwrap(),
            file: "runs.txt".into(),
            delta: 0.05,
        });
        let context = format!("instance {instance}, g = {g}");
        let (file, robust) = export_robust(&problem);
        let certified = certificate::check(file).unwrap_or_else(|e| panic!("{context}: {e}"));
        let slack = 1e-9 * robust.value_upper.max(1.0);
        assert!(
            certified.lower <= robust.value_upper + slack,
            "{context}: {certified:?}"
        );
        // The report gives the lower bound of the worst case's value, certified to 1e-6.
        assert!(
            certified.lower <= robust.worst_case_value + 1e-6 + slack,
            "{context}: {certified:?}, worst case {}",
            robust.worst_case_value
        );
        assert!(
            certified.upper >= robust.value - slack,
            "{context}: {certified:?}"
        );
        assert!(
            certified.upper - certified.lower <= 1e-6 + slack,
            "{context}: {certified:?}, robust [{}, {}]",
            robust.value,
            robust.value_upper
        );
        positive += usize::from(certified.lower > 0.0);
    }
    assert!(
        positive >= 10,
        "{positive} of 60 certify a positive lower bound"
    );
}

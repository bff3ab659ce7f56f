//! The two engines behind [`pipeline::solve`]: the same reports (but for the engine's name and
//! the solver's own line; values within the precision) on random text arenas and maps and on
//! every committed example, the choice `auto` makes against a memory limit, and the refusals.

use crate::common::{bad_table, random_arena, random_table, random_world, weights_file};
use hypersynth::arena::gridworld::Cell;
use hypersynth::arena::{Arena, Owner, StateId, map};
use hypersynth::certificate;
use hypersynth::game::{Engine, States};
use hypersynth::implicit::ArenaMoves;
use hypersynth::limits::{MemoryBudget, MemoryLimit};
use hypersynth::mdp::DrnForm;
use hypersynth::opportunistic::adversary::{SigmaL, WeightTable};
use hypersynth::opportunistic::build::Risk;
use hypersynth::opportunistic::controller::Explanation;
use hypersynth::opportunistic::executor::Executor;
use hypersynth::opportunistic::export::{Choice, ControllerFile, Scope, Table};
use hypersynth::pipeline::spec::{
    ArenaSpec, GeneralSpec, LearntSpec, MdpSpec, NamedTask, PaperPayoffs, Precision, ProblemSpec,
    SetPayoff, SigmaLSpec, TaskSource, TasksSpec, Translation,
};
use hypersynth::pipeline::{
    self, CurveRequest, ImplicitProduct, ImplicitSolution, Picture, PictureRequest, PipelineError,
    Requests, RunError, Sinks, Source,
};
use hypersynth::render::TitleChoice;
use hypersynth::report::{Games, Report};
use hypersynth::stage::{Observer, Stage};
use hypersynth::testing::explorer_data;
use hypersynth::translate::TranslatorChoice;
use rand_chacha::ChaCha8Rng;
use rand_core::{RngCore, SeedableRng};

const EPSILON: f64 = 1e-6;
const FORMULAS: [&str; 6] = ["F a", "F b", "!a U b", "!b U a", "F (a & X b)", "a U b"];

fn below(rng: &mut ChaCha8Rng, n: u32) -> u32 {
    rng.next_u32() % n
}

fn builtin() -> Translation {
    Translation {
        choice: TranslatorChoice::Builtin,
        ..Translation::default()
    }
}

/// A random sigma_L on `arena`: uniform, random, or a random weight table given as values or as
/// a weights file.
fn random_sigma_l(rng: &mut ChaCha8Rng, arena: &Arena) -> SigmaLSpec {
    match below(rng, 4) {
        0 => SigmaLSpec::Value(SigmaL::Uniform),
        1 => SigmaLSpec::Value(SigmaL::Random {
            seed: u64::from(below(rng, 1000)),
        }),
        2 => SigmaLSpec::Value(SigmaL::Weights {
            table: random_table(rng, arena),
            file: "values".into(),
        }),
        _ => SigmaLSpec::WeightsFile {
            name: "w.txt".into(),
            text: weights_file(&random_table(rng, arena)),
        },
    }
}

/// Random tasks over a and b: the paper's form or k = 2, 3 named sub-tasks with payoffs, a
/// belief and a risk rule; with the MDP stage at a random discount and sigma_L on `read` (the
/// arena `arena` describes), or games only.
fn random_spec(rng: &mut ChaCha8Rng, arena: ArenaSpec, read: &Arena) -> ProblemSpec {
    let formula = |rng: &mut ChaCha8Rng| FORMULAS[below(rng, 6) as usize].to_string();
    let tasks = if below(rng, 3) == 0 {
        let (a, b) = (formula(rng), formula(rng));
        TasksSpec::Paper {
            phi: format!("({a}) & ({b})"),
            psi: format!("({a})"),
            phi2: None,
            payoffs: PaperPayoffs::default(),
        }
    } else {
        let k = 2 + below(rng, 2) as usize;
        let names = ["A", "B", "C"];
        let tasks: Vec<NamedTask> = (0..k)
            .map(|i| NamedTask {
                name: names[i].into(),
                task: TaskSource::Formula(formula(rng)),
            })
            .collect();
        let mut payoffs: Vec<SetPayoff> = (0..k)
            .map(|i| SetPayoff {
                set: vec![names[i].into()],
                value: f64::from(50 * (1 + below(rng, 4))),
            })
            .collect();
        if below(rng, 2) == 0 {
            payoffs.push(SetPayoff {
                set: names[..k].iter().map(|n| n.to_string()).collect(),
                value: 700.0,
            });
        }
        let believed = match below(rng, 2) {
            0 => TaskSource::Formula(formula(rng)),
            _ => tasks[0].task.clone(),
        };
        let risk = [Risk::Paper, Risk::Strict, Risk::Neutral][below(rng, 3) as usize];
        TasksSpec::General(GeneralSpec {
            tasks,
            payoffs,
            believed,
            risk,
        })
    };
    let mdp = (below(rng, 4) != 0).then(|| MdpSpec {
        sigma_l: random_sigma_l(rng, read),
        discount: [0.9, 0.99, 1.0][below(rng, 3) as usize],
        // A third of the problems certify each value to EPSILON times its lower bound.
        precision: match below(rng, 3) {
            0 => Precision::Relative(EPSILON),
            _ => Precision::Absolute(EPSILON),
        },
        ..MdpSpec::default()
    });
    ProblemSpec {
        arena,
        tasks,
        states: States::Full,
        translation: builtin(),
        mdp,
        engine: None,
    }
}

/// `spec` run on `engine`.
fn run(spec: &ProblemSpec, engine: Engine) -> Result<Report, RunError> {
    let spec = ProblemSpec {
        engine: Some(engine),
        ..spec.clone()
    };
    pipeline::solve(&spec, &Requests::default(), &mut ()).map(|outcome| outcome.report)
}

/// The controller files `spec` exports on `engine` with `scope`.
fn controller(spec: &ProblemSpec, engine: Engine, scope: Scope) -> String {
    let spec = ProblemSpec {
        engine: Some(engine),
        ..spec.clone()
    };
    let requests = Requests {
        export_controller: true,
        controller_scope: scope,
        ..Requests::default()
    };
    let outcome = pipeline::solve(&spec, &requests, &mut ()).unwrap();
    outcome.controller.expect("a controller was asked for")
}

/// The MDP `spec` exports in DRN on `engine`: the whole MDP in `form`, or with `induced` the
/// policy's chain.
fn drn(spec: &ProblemSpec, engine: Engine, form: DrnForm, induced: bool) -> String {
    let spec = ProblemSpec {
        engine: Some(engine),
        ..spec.clone()
    };
    let requests = Requests {
        export_mdp: true,
        drn_form: form,
        induced,
        ..Requests::default()
    };
    let outcome = pipeline::solve(&spec, &requests, &mut ()).unwrap();
    outcome.drn.expect("the MDP was asked for")
}

/// Both engines write the same MDP in DRN, byte for byte, in both forms; the policies' chains
/// (`induced`) have the same states, and each decision state of the implicit engine's chain
/// keeps one of the choices the MDP lists for it, written as the MDP writes it.
fn assert_same_drn(spec: &ProblemSpec, case: &str) {
    for form in [DrnForm::Reward, DrnForm::Reachability] {
        let explicit = drn(spec, Engine::Explicit, form, false);
        let implicit = drn(spec, Engine::Implicit, form, false);
        assert!(explicit == implicit, "{case}: the DRN ({form:?}) differs");
    }
    // A DRN's blocks by state: the `state` line and the lines after it.
    let blocks = |text: &str| -> Vec<Vec<String>> {
        let body = text.split("@model\n").nth(1).unwrap();
        let mut blocks: Vec<Vec<String>> = Vec::new();
        for line in body.lines().filter(|l| !l.starts_with("//")) {
            if line.starts_with("state ") {
                blocks.push(Vec::new());
            }
            blocks.last_mut().unwrap().push(line.to_string());
        }
        blocks
    };
    let mdp = blocks(&drn(spec, Engine::Implicit, DrnForm::Reward, false));
    let explicit = blocks(&drn(spec, Engine::Explicit, DrnForm::Reward, true));
    let implicit = blocks(&drn(spec, Engine::Implicit, DrnForm::Reward, true));
    assert_eq!(implicit.len(), explicit.len(), "{case}: chain states");
    for ((chain, other), whole) in implicit.iter().zip(&explicit).zip(&mdp) {
        if chain == other {
            continue;
        }
        assert_eq!(chain[0], whole[0], "{case}: a state's line");
        let action = &chain[1..];
        // The choice's lines, whole: followed by the next choice or the state's end.
        let kept = (1..whole.len()).any(|at| {
            whole[at..].starts_with(action)
                && whole
                    .get(at + action.len())
                    .is_none_or(|next| next.starts_with("\taction"))
        });
        assert!(kept, "{case}: {chain:?} keeps no choice of {whole:?}");
        assert_eq!(
            action.iter().filter(|l| l.starts_with("\taction")).count(),
            1,
            "{case}: one choice per state of a chain"
        );
    }
}

/// The reactive strategies `spec` exports on `engine`: the text the run returns, which is
/// what the run streams into a sink, byte for byte.
fn strategies(spec: &ProblemSpec, engine: Engine) -> String {
    let spec = ProblemSpec {
        engine: Some(engine),
        ..spec.clone()
    };
    let requests = Requests {
        export_strategy: true,
        ..Requests::default()
    };
    let outcome = pipeline::solve(&spec, &requests, &mut ()).unwrap();
    let text = outcome.strategy.expect("the strategies were asked for");
    let mut streamed = Vec::new();
    let sinks = Sinks {
        strategy: Some(&mut streamed),
        ..Sinks::default()
    };
    let outcome = pipeline::solve_into(&spec, &requests, sinks, &mut ()).unwrap();
    assert!(outcome.strategy.is_none(), "streamed, not returned");
    assert!(
        streamed == text.as_bytes(),
        "{engine:?}: the streamed strategies differ"
    );
    text
}

/// Both engines export the same reactive strategies, byte for byte, naming the enumeration
/// `spec` asks for.
fn assert_same_strategies(spec: &ProblemSpec, case: &str) {
    let explicit = strategies(spec, Engine::Explicit);
    let implicit = strategies(spec, Engine::Implicit);
    assert!(explicit == implicit, "{case}: the strategies differ");
    let json: serde_json::Value = serde_json::from_str(&implicit).unwrap();
    assert_eq!(
        json["states"],
        serde_json::to_value(spec.states).unwrap(),
        "{case}"
    );
}

/// `spec` enumerating only the states reachable from h0.
fn reachable(spec: &ProblemSpec) -> ProblemSpec {
    ProblemSpec {
        states: States::Reachable,
        ..spec.clone()
    }
}

/// Both engines run `spec` with the full and with the reachable enumeration: the same reports
/// and strategies and (with the MDP stage) the same outputs ([`assert_same_outputs`]), those
/// of the reachable enumeration only when `reachable_outputs` (the random cases alternate, to
/// keep the suite's time). Returns whether the reachable product is smaller than the full one.
fn assert_same_enumerations(
    spec: &ProblemSpec,
    (rng, count): (&mut ChaCha8Rng, u32),
    (refusals, reachable_outputs): (bool, bool),
    case: &str,
    kinds: &mut Kinds,
) -> bool {
    let mut sizes = Vec::new();
    for spec in [spec.clone(), reachable(spec)] {
        let case = format!("{case}, {:?} states", spec.states);
        let explicit = run(&spec, Engine::Explicit).unwrap();
        let implicit = run(&spec, Engine::Implicit).unwrap();
        assert_same(&explicit, &implicit, &case);
        assert_same_strategies(&spec, &case);
        let outputs = spec.states == States::Full || reachable_outputs;
        if spec.mdp.is_some() && outputs {
            let initial = &explicit.games.initial.state;
            assert_same_outputs(&spec, initial, (rng, count), refusals, &case, kinds);
        }
        sizes.push(explicit.games.product_states);
    }
    sizes[1] < sizes[0]
}

/// A table's present entries by index, read back.
fn entries(table: &Table) -> Vec<(usize, u64)> {
    let entries = table.decode().unwrap();
    (0..entries.len())
        .filter_map(|i| entries.get(i).map(|v| (i, v)))
        .collect()
}

/// Per mode (by set), its choices by entry.
fn decisions(file: &ControllerFile) -> Vec<(u8, std::collections::BTreeMap<usize, Choice>)> {
    file.modes
        .iter()
        .map(|mode| {
            let choices = entries(&mode.table)
                .into_iter()
                .map(|(i, c)| (i, file.choices[c as usize].clone()))
                .collect();
            (mode.set, choices)
        })
        .collect()
}

/// Both engines' controllers of `spec` exported with scope `all` are the same file but for
/// the value (within the precision) and for the policy's choice where two choices' values are
/// within the precision of each other (the engines' lower bounds differ by up to it, so they
/// may break such a tie differently, at g = 1 also through which choices are eligible for the
/// least expected moves: docs/engines.md): there, the explicit engine's decision table of the
/// state shows both choices of equal value within the precision; the reactive strategies and the adversary's table agree wherever both files have an entry. The
/// implicit engine's file with scope `reachable` is part of its file with scope `all`, and
/// both read back (every reader check). Returns the explicit engine's controller and the
/// number of ties.
fn assert_same_controllers(spec: &ProblemSpec, case: &str) -> (Executor, usize) {
    let text = controller(spec, Engine::Explicit, Scope::All);
    let explicit = Executor::from_json(&text).unwrap();
    let implicit = Executor::from_json(&controller(spec, Engine::Implicit, Scope::All)).unwrap();
    let (e, i) = (explicit.file(), implicit.file());
    let parts = |f: &ControllerFile| {
        serde_json::json!([
            f.format, f.form, f.scope, f.tasks, f.believed, f.payoffs, f.discount, f.risk,
            f.sigma_w, f.sigma_l, f.arena, f.labels, f.automata, f.tuples
        ])
    };
    assert_eq!(parts(i), parts(e), "{case}: the model's parts");
    for (a, b) in e.value.iter().zip(&i.value) {
        assert!(
            close(*a, *b),
            "{case}: value {:?} against {:?}",
            e.value,
            i.value
        );
    }
    let (e_modes, i_modes) = (decisions(e), decisions(i));
    let arena = explicit.arena();
    let robot: Vec<_> = arena
        .states()
        .filter(|&s| arena.owner(s) == Owner::Robot)
        .collect();
    let mut ties = 0;
    for (set, e_table) in &e_modes {
        let Some((_, i_table)) = i_modes.iter().find(|(s, _)| s == set) else {
            assert!(ties > 0 || *set != 0, "{case}: mode {set} missing");
            continue;
        };
        if *set != 0 {
            for (entry, choice) in e_table {
                if let Some(other) = i_table.get(entry) {
                    assert_eq!(other, choice, "{case}: mode {set} entry {entry}");
                }
            }
            continue;
        }
        let keys: Vec<_> = e_table.keys().collect();
        assert_eq!(
            keys,
            i_table.keys().collect::<Vec<_>>(),
            "{case}: mode 0 covers"
        );
        for (entry, choice) in e_table {
            let other = &i_table[entry];
            if other == choice {
                continue;
            }
            ties += 1;
            // The state's name, as reports name it.
            let tuples = e.tuples.len();
            let mut name = arena.name(robot[entry / tuples]).to_string();
            for q in &e.tuples[entry % tuples] {
                name.push_str(&format!("|{q}"));
            }
            let requests = Requests {
                explain: Some(name.clone()),
                ..Requests::default()
            };
            let spec = ProblemSpec {
                engine: Some(Engine::Explicit),
                ..spec.clone()
            };
            let outcome = pipeline::solve(&spec, &requests, &mut ()).unwrap();
            let table = outcome.report.synthesis.unwrap().explanation.unwrap();
            let row = |choice: &Choice| {
                let action = match choice {
                    Choice::Move(action) => action.as_str(),
                    Choice::Stop(_) => "stop",
                    other => panic!("{case}: {name}: {other:?} is no tie of a move"),
                };
                let row = table.actions.iter().find(|r| r.action == action).unwrap();
                row.value
            };
            let (a, b) = (row(choice), row(other));
            assert!(
                (a - b).abs() <= 2.0 * EPSILON * a.abs().max(b.abs()).max(1.0),
                "{case}: {name}: {choice:?} (worth {a}) against {other:?} (worth {b})"
            );
        }
    }
    if ties == 0 {
        assert_eq!(i_modes, e_modes, "{case}: the modes");
    }
    let e_adversary = entries(&e.adversary);
    let i_adversary: std::collections::BTreeMap<_, _> = entries(&i.adversary).into_iter().collect();
    for (entry, code) in e_adversary {
        if let Some(other) = i_adversary.get(&entry) {
            assert_eq!(*other, code, "{case}: adversary entry {entry}");
        }
    }
    // Scope `reachable`: a part of the file of scope `all`.
    let reachable =
        Executor::from_json(&controller(spec, Engine::Implicit, Scope::Reachable)).unwrap();
    for (set, table) in decisions(reachable.file()) {
        let (_, all) = i_modes.iter().find(|(s, _)| *s == set).unwrap();
        for (entry, choice) in table {
            assert_eq!(
                all.get(&entry),
                Some(&choice),
                "{case}: reachable {set} {entry}"
            );
        }
    }
    (explicit, ties)
}

/// The decision table of `state` that `spec` gives on `engine`.
fn explain(spec: &ProblemSpec, engine: Engine, state: &str) -> Result<Explanation, RunError> {
    let spec = ProblemSpec {
        engine: Some(engine),
        ..spec.clone()
    };
    let requests = Requests {
        explain: Some(state.into()),
        ..Requests::default()
    };
    let outcome = pipeline::solve(&spec, &requests, &mut ())?;
    Ok(outcome.report.synthesis.unwrap().explanation.unwrap())
}

/// How many tables of each kind the comparisons saw: robot states with choices, robot states
/// without (absorbing), adversary states, ties (the engines chose differently) and tables
/// whose expected moves were compared; and the maps whose solved pictures and page were
/// compared.
#[derive(Debug, Default)]
struct Kinds {
    deciding: usize,
    absorbing: usize,
    adversary: usize,
    ties: usize,
    timed: usize,
    drawn: usize,
    /// Names of states the reachable enumeration leaves out.
    unreachable: usize,
}

/// Both engines' decision tables of h0 and of `count` random product states of `spec`
/// (named from `controller`, the explicit engine's, whose arena and tuples number the
/// product): the same states, labels, actions and outcomes, the values within the precision
/// and the probabilities within 1e-9. Where the engines chose differently, the two choices'
/// values are within the precision of each other (a tie, as [`assert_same_controllers`]
/// accepts). The expected moves are compared (within the tie-break's relative 1e-3, twice)
/// only where the controllers decide alike everywhere (`alike`): after a tie broken
/// differently, here or anywhere the run may reach, the controllers' runs differ.
fn assert_same_explanations(
    spec: &ProblemSpec,
    (controller, alike): (&Executor, bool),
    (rng, count): (&mut ChaCha8Rng, u32),
    case: &str,
    kinds: &mut Kinds,
) {
    let (arena, tuples) = (controller.arena(), &controller.file().tuples);
    let mut states = vec!["h0".to_string()];
    // In turn: a robot state where the controller decides before committing (an entry of
    // its mode 0), an adversary state, any robot state.
    let named = |s: StateId, tuple: usize| {
        let mut name = arena.name(s).to_string();
        for q in &tuples[tuple] {
            name.push_str(&format!("|{q}"));
        }
        name
    };
    let owned = |owner| -> Vec<StateId> {
        arena
            .states()
            .filter(|&s| arena.owner(s) == owner)
            .collect()
    };
    let (robot, adversary) = (owned(Owner::Robot), owned(Owner::Adversary));
    let deciding: Vec<usize> = decisions(controller.file())
        .into_iter()
        .filter(|(set, _)| *set == 0)
        .flat_map(|(_, table)| table.into_iter())
        .filter(|(_, choice)| matches!(choice, Choice::Move(_) | Choice::Stop(_)))
        .map(|(entry, _)| entry)
        .collect();
    for n in 0..count {
        let (of, tuple) = match n % 3 {
            0 if !deciding.is_empty() => {
                let entry = deciding[below(rng, deciding.len() as u32) as usize];
                states.push(named(robot[entry / tuples.len()], entry % tuples.len()));
                continue;
            }
            1 if !adversary.is_empty() => (&adversary, below(rng, tuples.len() as u32)),
            _ if robot.is_empty() => continue,
            _ => (&robot, below(rng, tuples.len() as u32)),
        };
        states.push(named(
            of[below(rng, of.len() as u32) as usize],
            tuple as usize,
        ));
    }
    for state in &states {
        let case = format!("{case}: {state}");
        let (e, i) = match (
            explain(spec, Engine::Explicit, state),
            explain(spec, Engine::Implicit, state),
        ) {
            (Ok(e), Ok(i)) => (e, i),
            // A state the reachable enumeration leaves out.
            (
                Err(RunError::Pipeline(PipelineError::Explain(e))),
                Err(RunError::Pipeline(PipelineError::Explain(i))),
            ) => {
                assert_eq!(i, e, "{case}");
                kinds.unreachable += 1;
                continue;
            }
            (e, i) => panic!("{case}: {e:?} against {i:?}"),
        };
        assert_eq!(
            (&i.state, &i.label, i.robot),
            (&e.state, &e.label, e.robot),
            "{case}"
        );
        let (a, b) = (e.value, i.value);
        assert!(close(a, b), "{case}: value {a} against {b}");
        let actions = |x: &Explanation| -> Vec<String> {
            x.actions.iter().map(|row| row.action.clone()).collect()
        };
        assert_eq!(actions(&i), actions(&e), "{case}: the actions");
        match (e.robot, e.actions.is_empty()) {
            (true, false) => kinds.deciding += 1,
            (true, true) => kinds.absorbing += 1,
            (false, _) => kinds.adversary += 1,
        }
        if i.chosen != e.chosen {
            kinds.ties += 1;
            let worth = |choice: &Option<String>| {
                let action = choice.as_deref().expect("both choose");
                e.actions.iter().find(|r| r.action == action).unwrap().value
            };
            let (a, b) = (worth(&e.chosen), worth(&i.chosen));
            assert!(
                (a - b).abs() <= 2.0 * EPSILON * a.abs().max(b.abs()).max(1.0),
                "{case}: {:?} (worth {a}) against {:?} (worth {b})",
                e.chosen,
                i.chosen
            );
        }
        for (er, ir) in e.actions.iter().zip(&i.actions) {
            let row = format!("{case}: {}", er.action);
            let (a, b) = (er.value, ir.value);
            assert!(close(a, b), "{row}: value {a} against {b}");
            assert_eq!(
                ir.outcomes.len(),
                er.outcomes.len(),
                "{row}: {:?}",
                ir.outcomes
            );
            for (eo, io) in er.outcomes.iter().zip(&ir.outcomes) {
                assert_eq!((&io.state, &io.label), (&eo.state, &eo.label), "{row}");
                assert!(
                    (eo.probability - io.probability).abs() <= 1e-9,
                    "{row}: {eo:?} against {io:?}"
                );
                assert!(close(eo.value, io.value), "{row}: {eo:?} against {io:?}");
            }
        }
        if alike && i.chosen == e.chosen {
            kinds.timed += 1;
            let moves = |x: &Explanation| -> Vec<f64> {
                std::iter::once(x.expected_moves)
                    .chain(x.actions.iter().map(|row| row.expected_moves))
                    .collect()
            };
            for (a, b) in moves(&e).into_iter().zip(moves(&i)) {
                assert!(
                    a == b || (a - b).abs() <= 2e-3 * a.abs().max(1.0),
                    "{case}: expected moves {a} against {b}"
                );
            }
        }
    }
}

/// Names that are no product state of `spec` (malformed, an unknown arena state, an automaton
/// state out of range or not a number), made from h0's `initial` name, give the same error on
/// both engines.
fn assert_same_refusals(spec: &ProblemSpec, initial: &str, case: &str) {
    let fields: Vec<&str> = initial.rsplitn(2, '|').collect();
    let (head, last) = (fields[1], fields[0]);
    let arena = head.split('|').next().unwrap();
    let rest = &initial[arena.len()..];
    let names = [
        head.to_string(),
        format!("{initial}|0"),
        format!("nowhere{rest}"),
        format!(" {initial}"),
        format!("{head}|9999"),
        format!("{head}|x"),
        format!("{head}|-{last}"),
        // Map states: a cell off the map, a turn that is no player's, a space.
        format!("((99,0),(0,0),0){rest}"),
        format!("((0,0),(0,0),2){rest}"),
        format!("((0, 0),(0,0),0){rest}"),
    ];
    for name in names {
        let refusal = |engine| match explain(spec, engine, &name) {
            Err(RunError::Pipeline(PipelineError::Explain(error))) => error,
            other => panic!("{case}: {name} on {engine:?}: {other:?}"),
        };
        assert_eq!(
            refusal(Engine::Implicit),
            refusal(Engine::Explicit),
            "{case}: {name}"
        );
    }
}

/// Where both engines' controllers decide alike everywhere (no tie broken differently), their
/// simulations from one seed are the same runs: the same counts and mean payoff, the same
/// traced run, step by step, named and labelled alike, and the same recorded runs (`--record`).
fn assert_same_simulation(spec: &ProblemSpec, case: &str) {
    let requests = Requests {
        simulate: Some(200),
        trace: true,
        record: true,
        max_steps: 200,
        ..Requests::default()
    };
    let simulate = |engine| {
        let spec = ProblemSpec {
            engine: Some(engine),
            ..spec.clone()
        };
        let outcome = pipeline::solve(&spec, &requests, &mut ()).unwrap();
        let synthesis = outcome.report.synthesis.unwrap();
        let record = outcome.record.unwrap();
        (
            synthesis.simulation.unwrap(),
            synthesis.trace.unwrap(),
            record,
        )
    };
    let (explicit, implicit) = (simulate(Engine::Explicit), simulate(Engine::Implicit));
    assert_eq!(implicit.0, explicit.0, "{case}: the simulations");
    assert_eq!(implicit.1, explicit.1, "{case}: the traces");
    assert!(!implicit.1.steps.is_empty());
    assert!(implicit.2 == explicit.2, "{case}: the recorded runs");
    assert_eq!(implicit.2.lines().count(), 200);
}

/// The pictures and the explorer page `spec` gives on `engine` with `requests`' others, its
/// picture `picture` (of the slice `slice`: the adversary's cell and the automata's states,
/// when given) and the page.
fn drawings(
    spec: &ProblemSpec,
    engine: Engine,
    picture: Picture,
    slice: Option<(Cell, Vec<u32>)>,
) -> Result<(String, String), RunError> {
    let spec = ProblemSpec {
        engine: Some(engine),
        ..spec.clone()
    };
    let (adversary_at, automata) = slice.unzip();
    let requests = Requests {
        picture: Some(PictureRequest {
            picture,
            adversary_at,
            automata,
            title: TitleChoice::Default,
        }),
        html: true,
        max_steps: 100,
        ..Requests::default()
    };
    let outcome = pipeline::solve(&spec, &requests, &mut ())?;
    Ok((outcome.svg.unwrap(), outcome.html.unwrap()))
}

/// Both engines draw the same pictures of `spec` and make the same explorer page (on a map;
/// elsewhere both refuse with the same message). Where the controllers decide alike
/// (`alike`), every picture is the same bytes, and so is a partition and a value picture of
/// another slice than h0's (the adversary on the last free cell, the automata in the last
/// tuple of `controller`'s); the page's data is the same but for the numbers the solvers
/// certify (within the precision) and the report's lines that name the engine and the
/// solver. Where a tie is broken differently, the map and the games-only pictures and page
/// are compared.
fn assert_same_drawings(
    spec: &ProblemSpec,
    (controller, alike): (&Executor, bool),
    case: &str,
    kinds: &mut Kinds,
) {
    let world = match &spec.arena {
        ArenaSpec::Map { text, .. } => map::parse(text).unwrap(),
        ArenaSpec::Text { text, .. } if map::is_map(text) => map::parse(text).unwrap(),
        _ => {
            let refusal = |engine| match drawings(spec, engine, Picture::Map, None) {
                Err(error) => error.to_string(),
                Ok(_) => panic!("{case}: a picture of a text arena on {engine:?}"),
            };
            assert_eq!(
                refusal(Engine::Implicit),
                refusal(Engine::Explicit),
                "{case}"
            );
            return;
        }
    };
    let free = world.layout().unwrap().free_cells().to_vec();
    let other = (
        *free.last().unwrap(),
        controller.file().tuples.last().unwrap().clone(),
    );
    let games = ProblemSpec {
        mdp: None,
        ..spec.clone()
    };
    let mut cases = vec![
        (&games, Picture::Map, None),
        (&games, Picture::Partition, None),
        (&games, Picture::Partition, Some(other.clone())),
    ];
    if alike {
        kinds.drawn += 1;
        cases.extend([
            (spec, Picture::Partition, None),
            (spec, Picture::Value, None),
            (spec, Picture::Trace, None),
            (spec, Picture::Partition, Some(other.clone())),
            (spec, Picture::Value, Some(other)),
        ]);
    }
    for (spec, picture, slice) in cases {
        let case = format!(
            "{case}: {picture:?} {slice:?}, games only {}",
            spec.mdp.is_none()
        );
        let (e_svg, e_html) = drawings(spec, Engine::Explicit, picture, slice.clone()).unwrap();
        let (i_svg, i_html) = drawings(spec, Engine::Implicit, picture, slice).unwrap();
        assert!(e_svg == i_svg, "{case}: the pictures differ");
        assert!(e_svg.starts_with("<svg"), "{case}");
        assert_same_page(&explorer_data(&e_html), &explorer_data(&i_html), "", &case);
    }
}

/// Two pages' data (`explicit`, `implicit`) the same at `path` and below: numbers within the
/// precision, the report (compared as reports, `assert_same`) left out, and of the summary's
/// lines the names only where they carry a certified number or the solver's own figures.
fn assert_same_page(
    explicit: &serde_json::Value,
    implicit: &serde_json::Value,
    path: &str,
    case: &str,
) {
    use serde_json::Value;
    match (explicit, implicit) {
        (Value::Object(e), Value::Object(i)) => {
            let keys = |o: &serde_json::Map<String, Value>| o.keys().cloned().collect::<Vec<_>>();
            assert_eq!(keys(e), keys(i), "{case}: {path}");
            for (key, value) in e {
                if path.is_empty() && key == "report" {
                    continue;
                }
                assert_same_page(value, &i[key], &format!("{path}.{key}"), case);
            }
        }
        (Value::Array(e), Value::Array(i)) => {
            assert_eq!(e.len(), i.len(), "{case}: {path}");
            let certified = ["value of h0", "controller", "solver"];
            for (n, (a, b)) in e.iter().zip(i).enumerate() {
                if path == ".summary" && certified.contains(&a[0].as_str().unwrap()) {
                    assert_eq!(a[0], b[0], "{case}: {path}[{n}]");
                    continue;
                }
                assert_same_page(a, b, &format!("{path}[{n}]"), case);
            }
        }
        (Value::Number(e), Value::Number(i)) if e != i => {
            let (a, b) = (e.as_f64().unwrap(), i.as_f64().unwrap());
            let moves = path.ends_with("expected_moves");
            let within = match moves {
                true => (a - b).abs() <= 2e-3 * a.abs().max(1.0),
                false => close(a, b) || (a - b).abs() <= 1e-9,
            };
            assert!(within, "{case}: {path}: {a} against {b}");
        }
        _ => assert_eq!(explicit, implicit, "{case}: {path}"),
    }
}

/// Both engines' controllers exported with their certificates: each checks (the checker
/// re-derives the MDP from the file alone), and their certified bounds at h0 are within the
/// precision of each other and of the reports' values; where the controllers decide alike
/// (`alike`), the certificates carry the same states.
fn assert_same_certificates(spec: &ProblemSpec, alike: bool, case: &str) {
    let requests = Requests {
        export_controller: true,
        certificate: true,
        ..Requests::default()
    };
    let certified = |engine| {
        let spec = ProblemSpec {
            engine: Some(engine),
            ..spec.clone()
        };
        let outcome = pipeline::solve(&spec, &requests, &mut ()).unwrap();
        let text = outcome.controller.expect("a controller was asked for");
        let decision = outcome.report.synthesis.unwrap().decision;
        let checked = certificate::check_json(&text)
            .unwrap_or_else(|e| panic!("{case}: {engine:?}'s certificate: {e}"));
        (checked, decision)
    };
    let (explicit, decision) = certified(Engine::Explicit);
    let (implicit, _) = certified(Engine::Implicit);
    let tolerance = 2.0 * EPSILON * decision.value_upper.max(1.0);
    for checked in [&explicit, &implicit] {
        assert!(checked.lower <= decision.value_upper + tolerance, "{case}");
        assert!(checked.upper >= decision.value - tolerance, "{case}");
    }
    assert!(
        close(implicit.upper, explicit.upper),
        "{case}: upper {} against {}",
        implicit.upper,
        explicit.upper
    );
    if alike {
        assert!(
            close(implicit.lower, explicit.lower),
            "{case}: lower {} against {}",
            implicit.lower,
            explicit.lower
        );
        assert_eq!(
            (implicit.lower_states, implicit.upper_states),
            (explicit.lower_states, explicit.upper_states),
            "{case}: the states the certificates carry"
        );
    }
}

/// Whether `a` and `b` are within the precision of each other (both certified to `EPSILON`,
/// or to `EPSILON` times the value).
fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 2.0 * EPSILON * a.abs().max(1.0)
}

/// The explicit engine's report and the implicit one's: the games the same but for the
/// engine; the MDP stage's settings, sizes and decision the same, values within the precision,
/// expected moves within the tie-break's relative 1e-3 (they are approximated from below).
fn assert_same(explicit: &Report, implicit: &Report, case: &str) {
    assert_eq!(explicit.games.engine, Engine::Explicit, "{case}");
    assert_eq!(implicit.games.engine, Engine::Implicit, "{case}");
    let mut games = implicit.games.clone();
    games.engine = Engine::Explicit;
    assert_eq!(games, explicit.games, "{case}: games");
    match (&explicit.synthesis, &implicit.synthesis) {
        (None, None) => {}
        (Some(e), Some(i)) => {
            assert_eq!(i.settings, e.settings, "{case}: settings");
            assert_eq!(i.mdp, e.mdp, "{case}: MDP sizes");
            let (e, i) = (&e.decision, &i.decision);
            assert_eq!(
                (&i.action, &i.commits_to, i.adversary_first),
                (&e.action, &e.commits_to, e.adversary_first),
                "{case}: the decision at h0"
            );
            for (name, a, b) in [
                ("value", e.value, i.value),
                ("value_upper", e.value_upper, i.value_upper),
                ("policy_value", e.policy_value, i.policy_value),
                (
                    "policy_value_upper",
                    e.policy_value_upper,
                    i.policy_value_upper,
                ),
            ] {
                assert!(close(a, b), "{case}: {name} {a} against {b}");
            }
            let (a, b) = (e.expected_moves, i.expected_moves);
            assert!(
                a == b || (a - b).abs() <= 2e-3 * a.abs().max(1.0),
                "{case}: expected moves {a} against {b}"
            );
        }
        _ => panic!("{case}: one engine ran the MDP stage, the other did not"),
    }
}

#[test]
fn both_engines_report_the_same_on_random_text_arenas() {
    let mut rng = ChaCha8Rng::seed_from_u64(41);
    let (mut kinds, mut smaller) = (Kinds::default(), 0);
    for case in 0..80 {
        let arena = random_arena(&mut rng, case);
        let spec = random_spec(
            &mut rng,
            ArenaSpec::Built {
                name: "random".into(),
                arena: Box::new(arena.clone()),
                map: None,
            },
            &arena,
        );
        let checks = (case % 10 == 0, case % 2 == 1);
        let case = format!("arena case {case}");
        let kinds = &mut kinds;
        smaller += assert_same_enumerations(&spec, (&mut rng, 4), checks, &case, kinds) as u32;
    }
    assert_seen(&kinds);
    assert!(
        smaller >= 20,
        "{smaller} reachable products smaller than the full one"
    );
}

#[test]
fn both_engines_report_the_same_on_random_maps() {
    let mut rng = ChaCha8Rng::seed_from_u64(43);
    let (mut kinds, mut smaller) = (Kinds::default(), 0);
    for case in 0..50 {
        let world = random_world(&mut rng);
        let text = map::write(&world);
        let spec = random_spec(
            &mut rng,
            ArenaSpec::Map {
                name: "random".into(),
                text,
            },
            &world.build().unwrap(),
        );
        let checks = (case % 5 == 0, case % 2 == 1);
        let case = format!("map case {case}");
        let kinds = &mut kinds;
        smaller += assert_same_enumerations(&spec, (&mut rng, 4), checks, &case, kinds) as u32;
    }
    assert_seen(&kinds);
    assert!(kinds.drawn > 0, "{kinds:?}");
    assert!(
        smaller >= 10,
        "{smaller} reachable products smaller than the full one"
    );
}

/// What both engines make of `spec` besides the report, compared: the controllers, the
/// simulations where they decide alike, the DRN, the decision tables of h0 and `count` other
/// states and, when `refusals`, the errors on names that are no state (`initial`: h0's name).
fn assert_same_outputs(
    spec: &ProblemSpec,
    initial: &str,
    (rng, count): (&mut ChaCha8Rng, u32),
    refusals: bool,
    case: &str,
    kinds: &mut Kinds,
) {
    let (controller, ties) = assert_same_controllers(spec, case);
    if ties == 0 {
        assert_same_simulation(spec, case);
    }
    assert_same_drn(spec, case);
    assert_same_drawings(spec, (&controller, ties == 0), case, kinds);
    assert_same_certificates(spec, ties == 0, case);
    let controller = (&controller, ties == 0);
    assert_same_explanations(spec, controller, (rng, count), case, kinds);
    if refusals {
        assert_same_refusals(spec, initial, case);
    }
}

/// The random problems' tables covered every kind of state, and compared expected moves.
fn assert_seen(kinds: &Kinds) {
    assert!(
        kinds.deciding > 0
            && kinds.absorbing > 0
            && kinds.adversary > 0
            && kinds.timed > 0
            && kinds.unreachable > 0,
        "{kinds:?}"
    );
}

/// The committed examples' problems (the Makefile's), read from their files.
fn examples() -> Vec<(String, ProblemSpec)> {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../");
    let arena = |path: &str| ArenaSpec::Text {
        name: path.into(),
        text: std::fs::read_to_string(format!("{root}{path}")).unwrap(),
    };
    let formula = |text: &str| TaskSource::Formula(text.into());
    let named = |name: &str, text: &str| NamedTask {
        name: name.into(),
        task: formula(text),
    };
    let payoff = |set: &[&str], value: f64| SetPayoff {
        set: set.iter().map(|s| s.to_string()).collect(),
        value,
    };
    let mdp = |discount: f64| MdpSpec {
        sigma_l: SigmaLSpec::Value(SigmaL::Uniform),
        discount,
        ..MdpSpec::default()
    };
    let mut examples = Vec::new();
    for g in [1.0, 0.99, 0.95] {
        for path in ["specs/case-study/arena.txt", "specs/case-study/map.txt"] {
            // The learnt example's true sigma_L, a weights file on the case study's arena.
            let truth = SigmaLSpec::WeightsFile {
                name: "specs/learnt/truth.txt".into(),
                text: std::fs::read_to_string(format!("{root}specs/learnt/truth.txt")).unwrap(),
            };
            for (name, sigma_l) in [
                ("uniform", SigmaLSpec::Value(SigmaL::Uniform)),
                ("random", SigmaLSpec::Value(SigmaL::Random { seed: 2019 })),
                ("truth.txt", truth),
            ] {
                let spec = ProblemSpec {
                    arena: arena(path),
                    tasks: TasksSpec::Paper {
                        phi: "(!O U A) & (!O U B)".into(),
                        psi: "!O U A".into(),
                        phi2: None,
                        payoffs: PaperPayoffs::default(),
                    },
                    states: States::Full,
                    translation: builtin(),
                    mdp: Some(MdpSpec {
                        sigma_l: sigma_l.clone(),
                        ..mdp(g)
                    }),
                    engine: None,
                };
                examples.push((format!("{path} sigma_L {name} g = {g}"), spec));
            }
        }
        for path in ["specs/decoy/arena.txt", "specs/decoy/map.txt"] {
            let two = vec![named("A", "!O U A"), named("B", "!O U B")];
            let two_payoffs = vec![payoff(&["A"], 200.0), payoff(&["B"], 100.0)];
            for believed in ["F C", "(!O U A) & (!O U B)"] {
                let tasks = TasksSpec::General(GeneralSpec {
                    tasks: two.clone(),
                    payoffs: two_payoffs.clone(),
                    believed: formula(believed),
                    risk: Risk::Paper,
                });
                let spec = ProblemSpec {
                    arena: arena(path),
                    tasks,
                    states: States::Full,
                    translation: builtin(),
                    mdp: Some(mdp(g)),
                    engine: None,
                };
                examples.push((format!("{path} believed {believed} g = {g}"), spec));
            }
            for risk in [Risk::Paper, Risk::Strict] {
                let mut three = two.clone();
                three.push(named("C", "F C"));
                let mut payoffs = two_payoffs.clone();
                payoffs.extend([payoff(&["C"], 50.0), payoff(&["A", "B", "C"], 500.0)]);
                let tasks = TasksSpec::General(GeneralSpec {
                    tasks: three,
                    payoffs,
                    believed: formula("!O U A"),
                    risk,
                });
                let spec = ProblemSpec {
                    arena: arena(path),
                    tasks,
                    states: States::Full,
                    translation: builtin(),
                    mdp: Some(mdp(g)),
                    engine: None,
                };
                examples.push((format!("{path} three tasks {risk:?} g = {g}"), spec));
            }
        }
    }
    examples
}

#[test]
fn both_engines_report_the_same_on_the_committed_examples() {
    let mut rng = ChaCha8Rng::seed_from_u64(47);
    let (mut kinds, mut smaller) = (Kinds::default(), 0);
    for (n, (case, spec)) in examples().into_iter().enumerate() {
        // Bad names on the case study's arena and map, once.
        let checks = (n < 2, true);
        let kinds = &mut kinds;
        smaller += assert_same_enumerations(&spec, (&mut rng, 2), checks, &case, kinds) as u32;
        let games = ProblemSpec { mdp: None, ..spec };
        let case = format!("{case}, games only");
        assert_same_enumerations(&games, (&mut rng, 0), (false, true), &case, kinds);
    }
    assert_seen(&kinds);
    assert!(kinds.drawn > 0, "{kinds:?}");
    assert!(
        smaller > 0,
        "no example's reachable product is smaller than the full one"
    );
}

/// `spec` with sigma_L from `table`, as values or as a weights file.
fn with_table(spec: &ProblemSpec, table: &WeightTable, file: bool) -> ProblemSpec {
    let sigma_l = if file {
        SigmaLSpec::WeightsFile {
            name: "w.txt".into(),
            text: weights_file(table),
        }
    } else {
        SigmaLSpec::Value(SigmaL::Weights {
            table: table.clone(),
            file: "values".into(),
        })
    };
    let mdp = MdpSpec {
        sigma_l,
        ..spec.mdp.clone().unwrap_or_default()
    };
    ProblemSpec {
        mdp: Some(mdp),
        ..spec.clone()
    }
}

#[test]
fn both_engines_refuse_a_bad_weight_table_with_the_same_error() {
    let mut rng = ChaCha8Rng::seed_from_u64(47);
    for case in 0..30 {
        let world = random_world(&mut rng);
        let built = world.build().unwrap();
        let (arena, read) = if case % 2 == 0 {
            let arena = random_arena(&mut rng, case);
            let spec = ArenaSpec::Built {
                name: "random".into(),
                arena: Box::new(arena.clone()),
                map: None,
            };
            (spec, arena)
        } else {
            let text = map::write(&world);
            let spec = ArenaSpec::Map {
                name: "random".into(),
                text,
            };
            (spec, built)
        };
        let spec = random_spec(&mut rng, arena, &read);
        let (table, _) = bad_table(&read);
        for file in [false, true] {
            let spec = with_table(&spec, &table, file);
            let explicit = run(&spec, Engine::Explicit).unwrap_err();
            let implicit = run(&spec, Engine::Implicit).unwrap_err();
            let (RunError::Spec(explicit), RunError::Spec(implicit)) = (explicit, implicit) else {
                panic!("case {case}: not the specification's errors");
            };
            // NaN weights compare as their text.
            assert_eq!(
                format!("{implicit:?}"),
                format!("{explicit:?}"),
                "case {case}, file {file}"
            );
        }
    }
}

/// An observer with a memory ceiling and nothing in use.
struct Ceiling(u64);

impl Observer for Ceiling {
    fn reserve(
        &mut self,
        _stage: Stage,
        bytes: u64,
        what: &dyn Fn() -> String,
    ) -> Result<(), MemoryLimit> {
        MemoryBudget::new(self.0).check(0, bytes, what)
    }
}

#[test]
fn auto_takes_the_explicit_engine_where_it_fits_else_the_implicit_one_else_refuses() {
    let (_, spec) = examples().swap_remove(0);
    // The case study: 3 200 product states.
    let states = 3200;
    let explicit = pipeline::explicit_bytes(states, true);
    let implicit = pipeline::implicit_bytes(states, 0);
    assert!(implicit < explicit);
    let report = |ceiling| {
        pipeline::solve(&spec, &Requests::default(), &mut Ceiling(ceiling))
            .map(|outcome| outcome.report.games.engine)
    };
    // Every stage's reservation of the explicit engine is well below its estimate here.
    assert_eq!(report(explicit).unwrap(), Engine::Explicit);
    assert_eq!(report(explicit - 1).unwrap(), Engine::Implicit);
    let Err(RunError::Memory(error)) = report(implicit - 1) else {
        panic!("a ceiling below both estimates is refused")
    };
    assert_eq!((error.needed, error.limit), (implicit, implicit - 1));
    assert!(error.what.contains("3200 states"), "{}", error.what);
    // Asked for something only the explicit engine makes, auto takes it; a decision table
    // and the strategies the implicit engine makes.
    let ask = |requests: Requests| {
        let outcome = pipeline::solve(&spec, &requests, &mut Ceiling(explicit - 1)).unwrap();
        outcome.report.games.engine
    };
    // The robust stage, its interval MDP in DRN and its learning curve take the implicit
    // engine (the explicit engine's robust solve would ask for more than the ceiling); the
    // explorer page, of the case study's map (3 200 product states too), is made by either.
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../");
    let mut learnt = spec.clone();
    learnt.mdp.as_mut().unwrap().learnt = Some(LearntSpec {
        name: "runs.txt".into(),
        text: std::fs::read_to_string(format!("{root}specs/learnt/runs.txt")).unwrap(),
        delta: 0.05,
    });
    let solve =
        |requests: Requests| pipeline::solve(&learnt, &requests, &mut Ceiling(explicit - 1));
    let interval_drn = solve(Requests {
        export_mdp: true,
        ..Requests::default()
    })
    .unwrap();
    assert_eq!(interval_drn.report.games.engine, Engine::Implicit);
    assert!(
        interval_drn
            .drn
            .is_some_and(|drn| drn.contains("double-interval"))
    );
    let curve = solve(Requests {
        learning_curve: Some(CurveRequest::default()),
        ..Requests::default()
    })
    .unwrap();
    assert_eq!(curve.report.games.engine, Engine::Implicit);
    let robust = curve.report.synthesis.unwrap().robust.unwrap();
    // 1, 2, 5, 10, 20, 50, 100, 200, 500 and all 1000 runs.
    assert_eq!(robust.learning_curve.len(), 10);
    let (map, map_spec) = examples().swap_remove(3);
    assert!(map.starts_with("specs/case-study/map.txt"), "{map}");
    let page = Requests {
        html: true,
        ..Requests::default()
    };
    let outcome = pipeline::solve(&map_spec, &page, &mut Ceiling(explicit - 1)).unwrap();
    assert_eq!(outcome.report.games.engine, Engine::Implicit);
    assert!(outcome.html.is_some());
    let explain = Requests {
        explain: Some("h0".into()),
        ..Requests::default()
    };
    assert_eq!(ask(explain), Engine::Implicit);
    let strategies = Requests {
        export_strategy: true,
        ..Requests::default()
    };
    assert_eq!(ask(strategies), Engine::Implicit);
    // A weight table is no such thing.
    let mut table = WeightTable::new();
    table.add("((4,4),(0,2),1)", "N", 1.0);
    let weights = with_table(&spec, &table, true);
    let outcome = pipeline::solve(&weights, &Requests::default(), &mut Ceiling(explicit - 1));
    assert!(outcome.is_ok_and(|o| o.report.games.engine == Engine::Implicit));
}

#[test]
fn the_implicit_robust_stage_asks_for_its_memory_before_it_solves() {
    let (_, spec) = examples().swap_remove(0);
    let mut learnt = ProblemSpec {
        engine: Some(Engine::Implicit),
        ..spec
    };
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../");
    learnt.mdp.as_mut().unwrap().learnt = Some(LearntSpec {
        name: "runs".into(),
        text: std::fs::read_to_string(format!("{root}specs/learnt/runs.txt")).unwrap(),
        delta: 0.05,
    });
    let refused = &mut NoMemoryIn(Stage::RobustSolve);
    let result = pipeline::solve(&learnt, &Requests::default(), refused);
    let Err(RunError::Memory(error)) = result else {
        panic!("the robust stage did not ask for its bounds");
    };
    assert!(
        error.what.contains("robust and nominal bounds"),
        "{}",
        error.what
    );
}

/// `spec` with sigma_L learnt from `runs` runs its explicit controller records against the
/// model's sigma_L.
fn learnt(spec: &ProblemSpec, runs: u32) -> ProblemSpec {
    let requests = Requests {
        simulate: Some(runs),
        record: true,
        ..Requests::default()
    };
    let explicit = ProblemSpec {
        engine: Some(Engine::Explicit),
        ..spec.clone()
    };
    let text = pipeline::solve(&explicit, &requests, &mut ())
        .unwrap()
        .record
        .expect("the runs were recorded");
    let mut spec = spec.clone();
    spec.mdp.as_mut().expect("an MDP stage").learnt = Some(LearntSpec {
        name: "runs".into(),
        text,
        delta: 0.05,
    });
    spec
}

/// Both engines' robust stage on `spec` (sigma_L learnt): the same counts, region and sizes,
/// robust and nominal values and choices at h0 within the precision, the same actions where
/// no other choice comes within the precision, a worst case at least the robust value; the
/// implicit engine's robust controller certified by the independent checker. Returns whether
/// the robust value at h0 is below the nominal one.
fn assert_same_robust(spec: &ProblemSpec, case: &str) -> bool {
    let requests = Requests {
        simulate: Some(20),
        export_controller: true,
        certificate: true,
        learning_curve: Some(CurveRequest {
            runs: Vec::new(),
            picture: Some(TitleChoice::Default),
        }),
        ..Requests::default()
    };
    let outcome = |engine| {
        let spec = ProblemSpec {
            engine: Some(engine),
            ..spec.clone()
        };
        pipeline::solve(&spec, &requests, &mut ()).unwrap_or_else(|e| panic!("{case}: {e}"))
    };
    let (explicit, implicit) = (outcome(Engine::Explicit), outcome(Engine::Implicit));
    assert_same(&explicit.report, &implicit.report, case);
    // The interval MDP in DRN, byte for byte in both forms.
    for form in [DrnForm::Reward, DrnForm::Reachability] {
        let interval_drn = |engine| {
            let spec = ProblemSpec {
                engine: Some(engine),
                ..spec.clone()
            };
            let requests = Requests {
                export_mdp: true,
                drn_form: form,
                ..Requests::default()
            };
            let outcome = pipeline::solve(&spec, &requests, &mut ()).unwrap();
            outcome.drn.expect("the MDP was asked for")
        };
        let (e, i) = (
            interval_drn(Engine::Explicit),
            interval_drn(Engine::Implicit),
        );
        assert!(e.contains("double-interval"), "{case}: not an interval MDP");
        assert!(e == i, "{case}: the interval DRN ({form:?}) differs");
    }
    let robust = |o: &pipeline::Outcome| o.report.synthesis.clone().unwrap().robust.unwrap();
    let (e, i) = (robust(&explicit), robust(&implicit));
    assert_eq!(
        (
            &i.observations,
            i.delta,
            i.runs,
            i.counted,
            i.sigma_w_steps,
            i.misfits
        ),
        (
            &e.observations,
            e.delta,
            e.runs,
            e.counted,
            e.sigma_w_steps,
            e.misfits
        ),
        "{case}: the counts"
    );
    assert_eq!(
        (i.pairs, i.sigma_l_states, i.never_observed),
        (e.pairs, e.sigma_l_states, e.never_observed),
        "{case}: the region"
    );
    for (name, a, b) in [
        ("value", e.value, i.value),
        ("value_upper", e.value_upper, i.value_upper),
        ("nominal_value", e.nominal_value, i.nominal_value),
        (
            "nominal_value_upper",
            e.nominal_value_upper,
            i.nominal_value_upper,
        ),
    ] {
        assert!(close(a, b), "{case}: robust {name} {a} against {b}");
    }
    let tolerance = 2.0 * EPSILON * e.value_upper.max(1.0);
    assert!(i.worst_case_value >= i.value - tolerance, "{case}: {i:?}");
    assert_eq!(i.choices.len(), e.choices.len(), "{case}: choices");
    for (a, b) in e.choices.iter().zip(&i.choices) {
        assert_eq!(a.action, b.action, "{case}");
        assert!(close(a.robust, b.robust), "{case}: {a:?} against {b:?}");
        assert!(close(a.nominal, b.nominal), "{case}: {a:?} against {b:?}");
    }
    // Where one choice at h0 is better than every other by more than the precision, both
    // engines play it.
    let clear = |value: fn(&hypersynth::report::RobustChoice) -> f64| {
        let mut values: Vec<f64> = e.choices.iter().map(value).collect();
        values.sort_by(|a, b| b.total_cmp(a));
        values.len() < 2 || values[0] - values[1] > 4.0 * EPSILON * values[0].max(1.0)
    };
    if clear(|c| c.robust) {
        assert_eq!(i.action, e.action, "{case}: the robust action");
    }
    if clear(|c| c.nominal) {
        assert_eq!(
            i.nominal_action, e.nominal_action,
            "{case}: the nominal action"
        );
    }
    assert!(i.simulation.is_some() && e.simulation.is_some(), "{case}");
    // The learning curves: the same points (every one learnt afresh from its first runs).
    assert_eq!(i.learning_curve.len(), e.learning_curve.len(), "{case}");
    for (a, b) in e.learning_curve.iter().zip(&i.learning_curve) {
        assert_eq!(
            (a.runs, a.counted, a.never_observed),
            (b.runs, b.counted, b.never_observed),
            "{case}: curve"
        );
        for (x, y) in [
            (a.value, b.value),
            (a.value_upper, b.value_upper),
            (a.nominal_value, b.nominal_value),
            (a.nominal_value_upper, b.nominal_value_upper),
        ] {
            assert!(close(x, y), "{case}: curve point {a:?} against {b:?}");
        }
    }
    assert!(
        explicit.curve_svg.is_some() && implicit.curve_svg.is_some(),
        "{case}"
    );
    let text = implicit.controller.expect("a controller was asked for");
    let checked = certificate::check_json(&text)
        .unwrap_or_else(|err| panic!("{case}: the implicit robust certificate: {err}"));
    assert!(checked.upper >= i.value - tolerance, "{case}: {checked:?}");
    assert!(
        checked.lower <= i.value_upper + tolerance,
        "{case}: {checked:?}"
    );
    e.value_upper < e.nominal_value - EPSILON
}

#[test]
fn both_engines_learn_and_solve_the_robust_stage_alike() {
    let mut rng = ChaCha8Rng::seed_from_u64(47);
    let (mut compared, mut lowered) = (0, 0);
    for case in 0..40 {
        let (spec, case) = if case % 2 == 0 {
            let arena = random_arena(&mut rng, case);
            let built = ArenaSpec::Built {
                name: "random".into(),
                arena: Box::new(arena.clone()),
                map: None,
            };
            (
                random_spec(&mut rng, built, &arena),
                format!("arena case {case}"),
            )
        } else {
            let world = random_world(&mut rng);
            let text = map::write(&world);
            let arena = world.build().unwrap();
            let spec = ArenaSpec::Map {
                name: "random".into(),
                text,
            };
            (
                random_spec(&mut rng, spec, &arena),
                format!("map case {case}"),
            )
        };
        if spec.mdp.is_none() {
            continue;
        }
        let runs = 1 + below(&mut rng, 30);
        compared += 1;
        lowered += u32::from(assert_same_robust(&learnt(&spec, runs), &case));
    }
    assert!(
        compared >= 20 && lowered > 0,
        "{compared} compared, {lowered} lowered"
    );
    // The committed learnt example: the case study's arena and map, its true sigma_L and
    // the 1000 runs recorded against it, at every discount of the examples.
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../");
    let runs = std::fs::read_to_string(format!("{root}specs/learnt/runs.txt")).unwrap();
    for (case, mut spec) in examples()
        .into_iter()
        .filter(|(case, _)| case.contains("case-study") && case.contains("truth.txt"))
    {
        spec.mdp.as_mut().unwrap().learnt = Some(LearntSpec {
            name: "specs/learnt/runs.txt".into(),
            text: runs.clone(),
            delta: 0.05,
        });
        assert_same_robust(&spec, &case);
    }
}

/// A problem on a three-state arena whose robot can reach A and B through the adversary, at
/// discount `g` with at most `sweeps` sweeps, its robot's first action named `action`.
fn tiny(action: &str, g: f64, sweeps: u32) -> ProblemSpec {
    let text = format!(
        "propositions A B\nstate r robot {{}}\nstate a adversary {{}}\nstate g robot {{A B}}\n\
         initial r\nedge r {action} a\nedge a on g\nedge a back r\nedge g stay g\n"
    );
    ProblemSpec {
        arena: ArenaSpec::Text {
            name: "tiny".into(),
            text,
        },
        tasks: TasksSpec::Paper {
            phi: "F A & F B".into(),
            psi: "F A".into(),
            phi2: None,
            payoffs: PaperPayoffs::default(),
        },
        states: States::Full,
        translation: builtin(),
        mdp: Some(MdpSpec {
            sigma_l: SigmaLSpec::Value(SigmaL::Uniform),
            discount: g,
            max_iterations: sweeps,
            ..MdpSpec::default()
        }),
        engine: None,
    }
}

#[test]
fn both_engines_refuse_an_action_named_stop_and_a_solve_past_its_sweep_limit() {
    use hypersynth::opportunistic::build::BuildError;
    use hypersynth::pipeline::{ImplicitError, PipelineError};
    use hypersynth::report::StageError;
    let reserved = |result: Result<Report, RunError>| {
        matches!(
            result,
            Err(RunError::Pipeline(PipelineError::Stage(StageError::Build(
                BuildError::ReservedAction
            ))))
        )
    };
    let spec = tiny("stop", 0.99, 1000);
    assert!(reserved(run(&spec, Engine::Explicit)));
    assert!(reserved(run(&spec, Engine::Implicit)));
    // The adversary may send the robot back: a cycle whose bounds need more than one sweep.
    let spec = tiny("go", 0.99, 1);
    assert!(run(&spec, Engine::Explicit).is_err());
    let result = run(&spec, Engine::Implicit);
    assert!(
        matches!(result, Err(RunError::Implicit(ImplicitError::Solve(_)))),
        "{result:?}"
    );
    assert!(run(&tiny("go", 0.99, 1000), Engine::Implicit).is_ok());
}

/// An observer that refuses whatever one stage asks for.
struct NoMemoryIn(Stage);

impl Observer for NoMemoryIn {
    fn reserve(
        &mut self,
        stage: Stage,
        bytes: u64,
        what: &dyn Fn() -> String,
    ) -> Result<(), MemoryLimit> {
        let limit = if stage == self.0 { 0 } else { u64::MAX };
        MemoryBudget::new(limit).check(0, bytes, what)
    }
}

#[test]
fn the_implicit_engine_asks_for_a_reactive_strategys_ranks_before_exporting_or_playing() {
    let (_, spec) = examples().swap_remove(0);
    let spec = ProblemSpec {
        engine: Some(Engine::Implicit),
        ..spec
    };
    let export = Requests {
        export_controller: true,
        ..Requests::default()
    };
    let play = Requests {
        simulate: Some(10),
        trace: true,
        record: true,
        max_steps: 100,
        ..Requests::default()
    };
    let strategies = Requests {
        export_strategy: true,
        ..Requests::default()
    };
    let cases = [
        (export, Stage::Policy),
        (play, Stage::Simulation),
        (strategies, Stage::Attractors),
    ];
    for (requests, stage) in cases {
        // The case study's controller commits to phi, and its strategies' export starts with
        // phi1's region (3 200 product states, two bytes each), in the stage that asks for
        // them.
        let mut observer = NoMemoryIn(stage);
        let Err(RunError::Memory(error)) = pipeline::solve(&spec, &requests, &mut observer) else {
            panic!("the ranks are refused in {stage:?}")
        };
        assert_eq!(error.needed, 6400);
        assert!(error.what.contains("3200 product states"), "{}", error.what);
        // Without these outputs, nothing is asked in that stage.
        let outcome = pipeline::solve(&spec, &Requests::default(), &mut NoMemoryIn(stage));
        assert!(outcome.is_ok());
    }
    // A certificate asks for the controller's values (a bit per product state, 24 bytes per
    // live one) once the file is made: refused, the run ends with that refusal.
    let certified = Requests {
        export_controller: true,
        certificate: true,
        ..Requests::default()
    };
    let Err(RunError::Memory(error)) = pipeline::solve(&spec, &certified, &mut NoCertificate)
    else {
        panic!("the certificate's values are refused")
    };
    assert!(
        error.what.contains("certificate over 3200 product states"),
        "{}",
        error.what
    );
    assert!(error.needed > 3200 / 8 && (error.needed - 3200 / 8) % 24 == 0);
    let outcome = pipeline::solve(&spec, &Requests::default(), &mut NoCertificate);
    assert!(outcome.is_ok());
}

/// An observer that refuses only what a certificate asks for.
struct NoCertificate;

impl Observer for NoCertificate {
    fn reserve(
        &mut self,
        _: Stage,
        bytes: u64,
        what: &dyn Fn() -> String,
    ) -> Result<(), MemoryLimit> {
        let limit = match what().contains("certificate") {
            true => 0,
            false => u64::MAX,
        };
        MemoryBudget::new(limit).check(0, bytes, what)
    }
}

#[test]
fn both_engines_refuse_bad_observations_and_a_curve_without_them_alike() {
    let (_, spec) = examples().swap_remove(0);
    let on = |engine, spec: &ProblemSpec, requests: &Requests| {
        let spec = ProblemSpec {
            engine: Some(engine),
            ..spec.clone()
        };
        match pipeline::solve(&spec, requests, &mut ()) {
            Err(RunError::Pipeline(error)) => error.to_string(),
            other => panic!("{engine:?}: {:?}", other.map(|o| o.report.games.engine)),
        }
    };
    // A learning curve without observations.
    let curve = Requests {
        learning_curve: Some(CurveRequest::default()),
        ..Requests::default()
    };
    let explicit = on(Engine::Explicit, &spec, &curve);
    assert_eq!(on(Engine::Implicit, &spec, &curve), explicit);
    // A run from a state the arena does not have.
    let mut learnt = spec.clone();
    learnt.mdp.as_mut().unwrap().learnt = Some(LearntSpec {
        name: "runs".into(),
        text: "nowhere\n".into(),
        delta: 0.05,
    });
    let requests = Requests::default();
    let explicit = on(Engine::Explicit, &learnt, &requests);
    assert!(explicit.contains("nowhere"), "{explicit}");
    assert_eq!(on(Engine::Implicit, &learnt, &requests), explicit);
}

#[test]
fn an_implicit_solution_of_the_games_only_refuses_the_mdp_stages_questions() {
    // The implicit engine's steps on a problem without the MDP stage: the games report is the
    // explicit engine's (but for the engine), and every question of the MDP stage is refused
    // with one error.
    let mut rng = ChaCha8Rng::seed_from_u64(53);
    for case in 0..6 {
        let arena = random_arena(&mut rng, case);
        let spec = ArenaSpec::Built {
            name: "random".into(),
            arena: Box::new(arena.clone()),
            map: None,
        };
        let spec = ProblemSpec {
            mdp: None,
            ..random_spec(&mut rng, spec, &arena)
        };
        let problem = spec.build(&mut ()).unwrap();
        let moves = ArenaMoves::new(&problem.arena);
        let about = ("random", Source::Arena(&problem.arena));
        let product =
            ImplicitProduct::new(&problem.tasks, about, &moves, (States::Full, None), &mut ())
                .unwrap();
        let solution = ImplicitSolution::new(&product, &mut ()).unwrap();
        let h0 = product.space().initial();
        assert!(solution.decision().is_none() && solution.value(h0).is_none());
        let refusals = [
            solution.explain(h0, &mut ()).map(|_| ()),
            solution.drn(false, DrnForm::Reward, &mut ()).map(|_| ()),
            solution.runs(&Requests::default(), 1, &mut ()).map(|_| ()),
        ];
        for refusal in refusals {
            let error = refusal.unwrap_err();
            assert!(
                matches!(error, RunError::Pipeline(PipelineError::NoMdpStage)),
                "case {case}: {error:?}"
            );
            assert_eq!(
                error.to_string(),
                "the problem was solved without the MDP stage"
            );
        }
        let outcome = solution
            .outcome(&Requests::default(), Sinks::default(), &mut ())
            .unwrap();
        assert!(outcome.report.synthesis.is_none());
        let explicit = run(&spec, Engine::Explicit).unwrap();
        let games = Games {
            engine: Engine::Explicit,
            ..outcome.report.games
        };
        assert_eq!(games, explicit.games, "case {case}");
    }
}

//! Helpers shared by the library's integration tests: a hand-solved arena, an exhaustive check
//! of the robot's strategies, random arenas and DFAs, named sub-tasks translated from formulas,
//! a structural comparison of DFAs and the paper's win-label. The helpers the command's tests and
//! the benchmarks use too (DFAs from transition tables, the paper's view of a product) are the
//! library's `hypersynth::testing`, re-exported here.

pub use hypersynth::testing::{
    PAPER_TASKS, PHI, PHI1, PHI2, PaperGame, avoid_until, dfa_from_table, eventually, paper_regions,
};

use hypersynth::arena::gridworld::{Cell, Collision, Gridworld, Move};
use hypersynth::arena::{Arena, ArenaBuilder, Owner, Spelled, StateId};
use hypersynth::automata::{Dfa, DfaState};
use hypersynth::game::Payoffs;
use hypersynth::game::{Attractor, HState, Hypergame, ReactiveStrategy, TaskSet, WinLabel};
use hypersynth::ltl;
use hypersynth::opportunistic::adversary::{EntryError, WeightTable};
use hypersynth::opportunistic::build::Risk;
use hypersynth::opportunistic::view::SolvedGame;
use hypersynth::pipeline::{Believed, Subtask, Task, Tasks};
use hypersynth::translate::{Builtin, TranslationLimits};
use rand_chacha::ChaCha8Rng;
use rand_core::RngCore;
use std::collections::HashMap;

/// ```text
/// s0 (robot, {})      go → s1, wait → s0        initial
/// s1 (adversary, {})  l → s2, r → s3, t → s6
/// s2 (robot, {a})     go → s4
/// s3 (robot, {a})     go → s5
/// s4 (robot, {b})     stuck
/// s5 (robot, {})      stuck
/// s6 (adversary, {})  stuck
/// ```
/// With phi1 = F a and phi2 = F b: from s0 the robot reaches a whatever the adversary does, but
/// b only if the adversary plays l (or t, into its stuck state).
pub fn seven_state_arena() -> Arena {
    let mut b = ArenaBuilder::new();
    let spec: [(&str, Owner, &[&str]); 7] = [
        ("s0", Owner::Robot, &[]),
        ("s1", Owner::Adversary, &[]),
        ("s2", Owner::Robot, &["a"]),
        ("s3", Owner::Robot, &["a"]),
        ("s4", Owner::Robot, &["b"]),
        ("s5", Owner::Robot, &[]),
        ("s6", Owner::Adversary, &[]),
    ];
    for (name, owner, label) in spec {
        b.add_state(name, owner, label.iter().copied(), None)
            .unwrap();
    }
    let edges = [
        ("s0", "go", "s1"),
        ("s0", "wait", "s0"),
        ("s1", "l", "s2"),
        ("s1", "r", "s3"),
        ("s1", "t", "s6"),
        ("s2", "go", "s4"),
        ("s3", "go", "s5"),
    ];
    for (from, action, to) in edges {
        let (from, to) = (b.find_state(from).unwrap(), b.find_state(to).unwrap());
        b.add_transition(from, action, to).unwrap();
    }
    b.set_initial(StateId::new(0));
    b.build().unwrap()
}

/// Whether every play from `h` in which the robot follows `strategy` (any allowed move) reaches
/// a target of `set`, or a stuck adversary state, within `budget` steps, whatever the adversary
/// does.
fn forced(
    game: &Hypergame,
    strategy: &ReactiveStrategy,
    set: TaskSet,
    h: HState,
    budget: u32,
    memo: &mut HashMap<(HState, u32), bool>,
) -> bool {
    if game.is_target(set, h) || (game.owner(h) == Owner::Adversary && game.is_stuck(h)) {
        return true;
    }
    if budget == 0 {
        return false;
    }
    if let Some(&known) = memo.get(&(h, budget)) {
        return known;
    }
    let next: Vec<HState> = match game.owner(h) {
        Owner::Robot => strategy.moves(game, h).map(|(_, t)| t).collect(),
        Owner::Adversary => game.successors(h).collect(),
    };
    let result = !next.is_empty()
        && next
            .iter()
            .all(|&t| forced(game, strategy, set, t, budget - 1, memo));
    memo.insert((h, budget), result);
    result
}

/// The robot states of `win = Win(set)` from which the robot's strategy does not force a target
/// (or a stuck adversary state) within the state's rank, by exploring every play: empty when
/// the strategy is correct.
pub fn strategy_failures(game: &Hypergame, set: TaskSet, win: &Attractor) -> Vec<String> {
    let strategy = ReactiveStrategy::robot(game, win);
    let mut memo = HashMap::new();
    game.states()
        .filter(|&h| game.owner(h) == Owner::Robot)
        .filter_map(|h| Some((h, win.rank(h)?)))
        .filter(|&(h, rank)| !forced(game, &strategy, set, h, rank, &mut memo))
        .map(|(h, _)| game.name(h))
        .collect()
}

/// Random arenas over propositions a, b: states 0.. with random owners, labels and up to three
/// edges; plus, depending on `shape`, a chain, a diamond or a cycle (with an exit) of adversary
/// states wired in after state 0.
pub fn random_arena(rng: &mut ChaCha8Rng, shape: u32) -> Arena {
    let below = |rng: &mut ChaCha8Rng, n: u32| rng.next_u32() % n;
    let id = StateId::from_u32;
    let n = 3 + below(rng, 8);
    let extra = 4;
    let mut b = ArenaBuilder::new();
    for s in 0..n + extra {
        let owner = if s >= n || below(rng, 2) == 0 {
            Owner::Adversary
        } else {
            Owner::Robot
        };
        let label = below(rng, 4);
        let props = ["a", "b"]
            .into_iter()
            .enumerate()
            .filter(|(bit, _)| label & (1 << bit) != 0)
            .map(|(_, p)| p);
        b.add_state(&format!("s{s}"), owner, props, None).unwrap();
    }
    for s in 0..n {
        let mut used = [false; 3];
        for _ in 0..below(rng, 4) {
            let action = below(rng, 3) as usize;
            if !std::mem::replace(&mut used[action], true) {
                let target = below(rng, n + extra);
                b.add_transition(id(s), ["x", "y", "z"][action], id(target))
                    .unwrap();
            }
        }
    }
    // The special adversary states n..n+4, entered from anywhere they are targeted.
    let (c0, c1, c2, c3) = (id(n), id(n + 1), id(n + 2), id(n + 3));
    let exit = id(below(rng, n));
    let edges: Vec<(StateId, &str, StateId)> = match shape % 3 {
        // A chain c0 → c1 → c2 → c3 → exit.
        0 => vec![(c0, "x", c1), (c1, "x", c2), (c2, "x", c3), (c3, "x", exit)],
        // A diamond c0 → {c1, c2} → c3 → exit or back to 0.
        1 => vec![
            (c0, "x", c1),
            (c0, "y", c2),
            (c1, "x", c3),
            (c2, "x", c3),
            (c3, "x", exit),
            (c3, "y", id(0)),
        ],
        // A cycle c0 → c1 → c2 → c0 with an exit from c2; c3 → c0.
        _ => vec![
            (c0, "x", c1),
            (c1, "x", c2),
            (c2, "x", c0),
            (c2, "y", exit),
            (c3, "x", c0),
        ],
    };
    for (from, action, to) in edges {
        b.add_transition(from, action, to).unwrap();
    }
    let initial = if below(rng, 4) == 0 { c3 } else { id(0) };
    b.set_initial(initial);
    b.build().unwrap()
}

/// A random weight table for sigma_L on `arena`: each adversary state with an action listed
/// with probability 1/2, with a random non-empty subset of its actions in random order, weights
/// among 0, 1e-3, 0.5, 1, 2 and 7 (some 0, at least one positive per state); the entries of
/// the states interleaved.
pub fn random_table(rng: &mut ChaCha8Rng, arena: &Arena) -> WeightTable {
    let below = |rng: &mut ChaCha8Rng, n: u32| rng.next_u32() % n;
    let mut entries = Vec::new();
    for s in arena.states() {
        let mut actions: Vec<&str> = Vec::new();
        for (a, _) in arena.edges(s) {
            let name = arena.action_name(a);
            if !actions.contains(&name) {
                actions.push(name);
            }
        }
        if arena.owner(s) == Owner::Robot || actions.is_empty() || below(rng, 2) == 0 {
            continue;
        }
        let listed = 1 + below(rng, actions.len() as u32) as usize;
        let mut weights: Vec<f64> = (0..listed)
            .map(|_| [0.0, 1e-3, 0.5, 1.0, 2.0, 7.0][below(rng, 6) as usize])
            .collect();
        if weights.iter().all(|&w| w == 0.0) {
            weights[below(rng, listed as u32) as usize] = 1.0;
        }
        for weight in weights {
            let action = actions.remove(below(rng, actions.len() as u32) as usize);
            entries.push((arena.name(s).to_string(), action.to_string(), weight));
        }
    }
    let mut table = WeightTable::new();
    while !entries.is_empty() {
        let (state, action, weight) = entries.remove(below(rng, entries.len() as u32) as usize);
        table.add(state, action, weight);
    }
    table
}

/// `table` as a weights file: one `STATE ACTION WEIGHT` line per entry, names spelled as the
/// format spells them.
pub fn weights_file(table: &WeightTable) -> String {
    table
        .entries()
        .iter()
        .map(|w| {
            format!(
                "{} {} {}\n",
                Spelled(&w.state),
                Spelled(&w.action),
                w.weight
            )
        })
        .collect()
}

/// A table with one bad entry of each kind `arena` allows, among good ones: an unknown state, a
/// robot state, an unknown action, an action of the arena the state does not enable, a state
/// and action twice, an invalid weight, a state whose weights are all 0. The kinds it holds.
pub fn bad_table(arena: &Arena) -> (WeightTable, Vec<EntryError>) {
    let mut table = WeightTable::new();
    let mut kinds = Vec::new();
    let name = |s| arena.name(s).to_string();
    let adversary: Vec<_> = arena
        .states()
        .filter(|&s| arena.owner(s) == Owner::Adversary && arena.edges(s).len() > 0)
        .collect();
    let action = |s| {
        arena
            .action_name(arena.edges(s).next().unwrap().0)
            .to_string()
    };
    table.add("nowhere", "x", 1.0);
    kinds.push(EntryError::UnknownState {
        state: "nowhere".into(),
    });
    if let Some(r) = arena.states().find(|&s| arena.owner(s) == Owner::Robot) {
        table.add(name(r), "x", 1.0);
        kinds.push(EntryError::RobotState { state: name(r) });
    }
    if let Some(&a) = adversary.first() {
        table.add(name(a), action(a), 2.0);
        table.add(name(a), "nothing", 1.0);
        kinds.push(EntryError::UnknownAction {
            state: name(a),
            action: "nothing".into(),
        });
        table.add(name(a), action(a), 1.0);
        kinds.push(EntryError::Duplicate {
            state: name(a),
            action: action(a),
            first: table.entries().len() - 3,
        });
        table.add(name(a), action(a), f64::NAN);
        kinds.push(EntryError::Weight { weight: f64::NAN });
    }
    let disabled = adversary.iter().find_map(|&a| {
        let enabled: Vec<&str> = arena.edges(a).map(|(x, _)| arena.action_name(x)).collect();
        let other = arena
            .actions()
            .iter()
            .find(|x| !enabled.contains(&x.as_str()))?;
        Some((a, other.clone()))
    });
    if let Some((a, other)) = disabled {
        table.add(name(a), &other, 1.0);
        kinds.push(EntryError::UnknownAction {
            state: name(a),
            action: other,
        });
    }
    if let Some(&a) = adversary.get(1) {
        table.add(name(a), action(a), 0.0);
        kinds.push(EntryError::AllZero { state: name(a) });
    }
    (table, kinds)
}

/// A random complete DFA over a, b with 1..=3 states.
pub fn random_dfa(rng: &mut ChaCha8Rng) -> Dfa {
    let k = 1 + rng.next_u32() % 3;
    let table: Vec<Vec<u32>> = (0..k)
        .map(|_| (0..4).map(|_| rng.next_u32() % k).collect())
        .collect();
    let finals: Vec<u32> = (0..k)
        .filter(|_| rng.next_u32().is_multiple_of(2))
        .collect();
    dfa_from_table(&["a", "b"], 0, &finals, &table)
}

/// Named sub-tasks `(name, formula)` and the believed task `believed`, translated by the
/// built-in translator with its default limits.
pub fn translated_subtasks(
    tasks: &[(&str, &str)],
    believed: &str,
) -> (
    Vec<hypersynth::pipeline::Subtask>,
    hypersynth::pipeline::Believed,
) {
    use hypersynth::pipeline::{Believed, Subtask, Task};
    use hypersynth::translate::{Builtin, TranslationLimits};
    let translator = Builtin::new(TranslationLimits::default());
    let tasks: Vec<Subtask> = tasks
        .iter()
        .map(|&(name, formula)| Subtask {
            name: name.into(),
            task: Task::from_formula(hypersynth::ltl::parse(formula).unwrap(), &translator)
                .unwrap(),
        })
        .collect();
    let believed = hypersynth::ltl::parse(believed).unwrap();
    let believed = Believed::from_formula(believed, &tasks, &translator).unwrap();
    (tasks, believed)
}

/// `None` when the two DFAs have the same propositions, states, finality and edges (targets
/// equal, guards equivalent), otherwise the first difference.
pub fn structural_difference(x: &Dfa, y: &Dfa) -> Option<String> {
    if x.aps() != y.aps() || x.num_states() != y.num_states() || x.initial() != y.initial() {
        return Some(format!(
            "{:?}, {} states, start {} vs {:?}, {} states, start {}",
            x.aps(),
            x.num_states(),
            x.initial(),
            y.aps(),
            y.num_states(),
            y.initial()
        ));
    }
    for q in 0..x.num_states() as DfaState {
        let (ex, ey): (Vec<_>, Vec<_>) = (x.edges(q).collect(), y.edges(q).collect());
        let same = x.is_final(q) == y.is_final(q)
            && ex.len() == ey.len()
            && ex
                .iter()
                .zip(&ey)
                .all(|((gx, tx), (gy, ty))| tx == ty && gx.equivalent(gy));
        if !same {
            return Some(format!("state {q} differs"));
        }
    }
    None
}

/// The paper's win-label of `h` in a game of its two tasks.
pub fn win_label(game: &impl SolvedGame, h: HState) -> WinLabel {
    let [phi1, phi2, phi] = PAPER_TASKS.map(|(_, set)| game.wins(set, h));
    WinLabel { phi1, phi2, phi }
}

/// The `.rs` files under `directory`, at any depth, sorted.
pub fn rust_files(directory: &std::path::Path) -> Vec<std::path::PathBuf> {
    let mut files = Vec::new();
    let mut directories = vec![directory.to_path_buf()];
    while let Some(directory) = directories.pop() {
        for entry in std::fs::read_dir(&directory).expect("a readable directory") {
            let path = entry.expect("a directory entry").path();
            if path.is_dir() {
                directories.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                files.push(path);
            }
        }
    }
    files.sort();
    files
}

// The committed examples (specs/), as the exported controller's tests and the certificates'
// run them.

pub const CASE_STUDY: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../specs/case-study/map.txt"
);
pub const DECOY: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../specs/decoy/map.txt");

pub fn map_arena(file: &str) -> (Arena, hypersynth::arena::gridworld::Gridworld) {
    let text = std::fs::read_to_string(file).unwrap();
    let world = hypersynth::arena::map::parse(&text).unwrap();
    (world.build().unwrap(), world)
}

/// Sub-tasks from `(name, formula)` pairs, psi from a formula, payoffs per task and overrides.
pub fn general(tasks: &[(&str, &str)], believed: &str, payoffs: &[f64], all: Option<f64>) -> Tasks {
    let translator = Builtin::new(TranslationLimits::default());
    let subtasks: Vec<Subtask> = tasks
        .iter()
        .map(|&(name, formula)| Subtask {
            name: name.into(),
            task: Task::from_formula(ltl::parse(formula).unwrap(), &translator).unwrap(),
        })
        .collect();
    let names: Vec<String> = tasks.iter().map(|t| t.0.to_string()).collect();
    let overrides: Vec<(TaskSet, f64)> = all
        .map(|r| (TaskSet::all(tasks.len()), r))
        .into_iter()
        .collect();
    let payoffs = hypersynth::game::SubsetPayoffs::new(payoffs, &overrides, &names).unwrap();
    let believed =
        Believed::from_formula(ltl::parse(believed).unwrap(), &subtasks, &translator).unwrap();
    Tasks::new(subtasks, payoffs, believed, Risk::Paper)
}

/// The three examples: name, tasks, map, discount.
pub fn examples() -> Vec<(&'static str, Tasks, &'static str, f64)> {
    let translator = Builtin::new(TranslationLimits::default());
    let case_study = Tasks::from_formulas(
        &ltl::parse("(!O U A) & (!O U B)").unwrap(),
        &ltl::parse("!O U A").unwrap(),
        None,
        &translator,
        Payoffs::default(),
    )
    .unwrap();
    let decoy = general(
        &[("A", "!O U A"), ("B", "!O U B")],
        "F C",
        &[200.0, 100.0],
        None,
    );
    let three = general(
        &[("A", "!O U A"), ("B", "!O U B"), ("C", "F C")],
        "!O U A",
        &[200.0, 100.0, 50.0],
        Some(500.0),
    );
    vec![
        ("case study", case_study, CASE_STUDY, 0.99),
        ("decoy", decoy, DECOY, 0.95),
        ("three tasks", three, DECOY, 1.0),
    ]
}

/// A random gridworld of at most 4x4 cells: obstacles, cells labelled a or b, the moves of each
/// player a random non-empty subset in random order, a random collision rule and first player.
pub fn random_world(rng: &mut ChaCha8Rng) -> Gridworld {
    let below = |rng: &mut ChaCha8Rng, n: u32| rng.next_u32() % n;
    let (width, height) = (1 + below(rng, 4), 1 + below(rng, 4));
    let cells: Vec<Cell> = (0..width)
        .flat_map(|x| (0..height).map(move |y| Cell { x, y }))
        .collect();
    let mut free = cells.clone();
    let mut obstacles = Vec::new();
    while free.len() > 2 && below(rng, 4) == 0 {
        obstacles.push(free.remove(below(rng, free.len() as u32) as usize));
    }
    let robot = free[below(rng, free.len() as u32) as usize];
    let mut adversary = free[below(rng, free.len() as u32) as usize];
    let collision = match below(rng, 3) {
        0 if free.len() > 1 => Collision::Forbidden,
        0 => Collision::Allowed,
        1 => Collision::Allowed,
        _ => Collision::Label("meet".to_string()),
    };
    if collision == Collision::Forbidden && robot == adversary {
        adversary = *free.iter().find(|&&c| c != robot).unwrap();
    }
    let mut labels = Vec::new();
    for &cell in &free {
        for p in ["a", "b"] {
            if below(rng, 3) == 0 {
                labels.push((p.to_string(), cell));
            }
        }
    }
    let moves = |rng: &mut ChaCha8Rng| {
        let mut all = Move::ALL.to_vec();
        let mut chosen = Vec::new();
        while chosen.is_empty() || (!all.is_empty() && below(rng, 3) != 0) {
            chosen.push(all.remove(below(rng, all.len() as u32) as usize));
        }
        chosen
    };
    Gridworld {
        obstacles,
        labels,
        robot_moves: moves(rng),
        adversary_moves: moves(rng),
        collision,
        first: if below(rng, 2) == 0 {
            Owner::Robot
        } else {
            Owner::Adversary
        },
        ..Gridworld::new(width, height, robot, adversary)
    }
}

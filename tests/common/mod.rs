//! Helpers shared by the integration tests: DFAs from transition tables, a hand-solved arena,
//! an exhaustive check of the robot's strategies, a structural comparison of DFAs, and a DRN
//! reader with Storm's value of the model (`drn`).

pub mod drn;

pub use hypersynth::testing::{PaperGame, avoid_until, dfa_from_table, eventually, paper_regions};

use hypersynth::arena::{Arena, ArenaBuilder, Owner, StateId};
use hypersynth::automata::{Dfa, DfaState};
use hypersynth::game::{Attractor, HState, Hypergame, ReactiveStrategy, Task, TaskSet, WinLabel};
use hypersynth::opportunistic::view::SolvedGame;
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

/// The case study's tasks in the paper's form (specs/case-study): phi and psi = phi1.
pub const CASE_STUDY_TASKS: &[&str] = &["--phi", "(!O U A) & (!O U B)", "--psi", "!O U A"];

/// The three-tasks example's options (specs/three-tasks): sub-tasks A, B, C with their payoffs
/// and a bonus for all three; the adversary believes the task is A's.
pub const THREE_TASKS: &[&str] = &[
    "--task",
    "A=!O U A",
    "--task",
    "B=!O U B",
    "--task",
    "C=F C",
    "--payoff",
    "A=200",
    "--payoff",
    "B=100",
    "--payoff",
    "C=50",
    "--payoff",
    "A,B,C=500",
    "--believed",
    "!O U A",
];

/// The decoy example's sub-tasks and payoffs (specs/decoy), without the believed task: A pays
/// 200, B 100, and both together 300.
pub const DECOY_TASKS: &[&str] = &[
    "--task", "A=!O U A", "--task", "B=!O U B", "--payoff", "A=200", "--payoff", "B=100",
];

/// A robot cell as the SVG of a gridworld picture draws it: `<g><title>robot at (x,y): ...`
/// followed by its `<rect>` and, in the general form's partition, a `<text>` code.
#[derive(Clone, Debug, PartialEq)]
pub struct SvgCell {
    /// The cell `(x, y)`.
    pub cell: (u32, u32),
    /// Its square on screen `(left, top, side)`.
    pub square: (f64, f64, f64),
    /// The code written in it, if any.
    pub code: Option<String>,
}

/// Every robot cell of a picture, in document order.
pub fn svg_cells(svg: &str) -> Vec<SvgCell> {
    let attribute = |element: &str, name: &str| -> f64 {
        let start = element.find(&format!(" {name}=\"")).unwrap() + name.len() + 3;
        let end = start + element[start..].find('"').unwrap();
        element[start..end].parse().unwrap()
    };
    svg.split("<g><title>robot at (")
        .skip(1)
        .map(|group| {
            let group = &group[..group.find("</g>").unwrap()];
            let (cell, rest) = group.split_once(')').unwrap();
            let (x, y) = cell.split_once(',').unwrap();
            let rect = &rest[rest.find("<rect").unwrap()..];
            let rect = &rect[..rect.find("/>").unwrap()];
            let side = attribute(rect, "width");
            assert_eq!(side, attribute(rect, "height"), "{rect}");
            let code = rest.find("<text").map(|start| {
                let text = &rest[start..];
                text[text.find('>').unwrap() + 1..text.find("</text>").unwrap()].to_string()
            });
            SvgCell {
                cell: (x.parse().unwrap(), y.parse().unwrap()),
                square: (attribute(rect, "x"), attribute(rect, "y"), side),
                code,
            }
        })
        .collect()
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
    use hypersynth::translate::{Builtin, Limits};
    let translator = Builtin::new(Limits::default());
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
    let [phi1, phi2, phi] = Task::ALL.map(|task| game.wins(task.set(), h));
    WinLabel { phi1, phi2, phi }
}

/// Robot `r0` moves `a` to adversary `x0`, which moves `a` to itself, `b` to `x1` or `c` to `r1`
/// (A holds); `x1` moves `a` to `x0`, `b` to itself, `c` to `r2` (B holds): adversary states
/// that lead into each other. With psi = F A, `x0` and `x1` are outside Win(F A) (the adversary
/// can avoid `r1` for ever) and play sigma_W: at `x0`, `c` leads into Win(F A), so the model
/// gives it probability 0.
pub const CHANCE_CYCLE: &str = "initial r0
state r0 robot {}
state x0 adversary {}
state x1 adversary {}
state r1 robot {A}
state r2 robot {B}
edge r0 a x0
edge x0 a x0
edge x0 b x1
edge x0 c r1
edge x1 a x0
edge x1 b x1
edge x1 c r2
";

/// Runs the `hypersynth` binary quietly with `args` and `stdin` as its standard input.
pub fn run_hypersynth(args: &[&str]) -> std::process::Output {
    assert_cmd::Command::cargo_bin("hypersynth")
        .unwrap()
        .arg("-q")
        .args(args)
        .output()
        .unwrap()
}

/// Runs `hypersynth execute CONTROLLER` with `play` piped to its standard input.
pub fn execute(controller: &std::path::Path, play: &str) -> std::process::Output {
    use std::io::Write as _;
    use std::process::{Command, Stdio};
    let mut child = Command::new(assert_cmd::cargo::cargo_bin("hypersynth"))
        .arg("execute")
        .arg(controller)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    child
        .stdin
        .take()
        .unwrap()
        .write_all(play.as_bytes())
        .unwrap();
    child.wait_with_output().unwrap()
}

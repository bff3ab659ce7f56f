//! The general form's strategy export (`--export-strategy`), checked by walks that share nothing
//! with the library's product or attractors: the arena below is small enough to step the
//! product by hand (each sub-task is `F p`, whose minimal DFA is 0 until `p` holds, then 1), so
//! every product state and successor is computed here from the arena's text.
//!
//! For every set T of sub-tasks (and for psi): from every robot state of `Win(T)`, following any
//! exported robot action against every adversary action, the play satisfies T within the
//! state's exported rank; from every state outside `Win(T)`, following the adversary's exported
//! actions against every robot action, the play never satisfies T and stays outside.

use crate::common;

use std::collections::BTreeMap;

use serde_json::Value;

use hypersynth::arena;
use hypersynth::game::{States, SubsetPayoffs};
use hypersynth::opportunistic::build::Risk;
use hypersynth::pipeline::{self, Problem, Requests, Tasks};

/// r0 can reach `a` and `b` in either order through the adversary's d2, which cannot stop both;
/// through d1 the adversary can send the robot back for ever; `z` (the decoy psi = F z) is one
/// robot move away; through dt the adversary can hold the robot in rt for ever (holding is its
/// only move that stays outside the robot's regions there, freeing it is not).
const ARENA: &str = r#"
initial r0
state r0 robot {}
state d1 adversary {}
state d2 adversary {}
state ra robot {a}
state rb robot {b}
state d3a adversary {}
state d3b adversary {}
state rb2 robot {b}
state rb3 robot {b}
state ra2 robot {a}
state ra3 robot {a}
state d4 adversary {}
state rz robot {z}
state dt adversary {}
state rt robot {}
edge r0 go1 d1
edge r0 go2 d2
edge r0 gz rz
edge d1 x ra
edge d1 y r0
edge d2 x ra
edge d2 y rb
edge ra go d3a
edge rb go d3b
edge d3a p rb2
edge d3a q rb3
edge d3b p ra2
edge d3b q ra3
edge rb2 on d4
edge rb3 on d4
edge ra2 on d4
edge ra3 on d4
edge d4 back r0
edge rz back d1
edge r0 gt dt
edge dt hold rt
edge dt free r0
edge rt wait dt
"#;

/// The propositions of the automata, in product order: A = F a, B = F b, psi = F z.
const PROPOSITIONS: [&str; 3] = ["a", "b", "z"];

/// The arena as this test reads it: owner (robot?), label and edges per state.
struct Model {
    robot: BTreeMap<String, bool>,
    labels: BTreeMap<String, Vec<String>>,
    edges: BTreeMap<String, Vec<(String, String)>>,
}

fn model() -> Model {
    let mut m = Model {
        robot: BTreeMap::new(),
        labels: BTreeMap::new(),
        edges: BTreeMap::new(),
    };
    for line in ARENA.lines() {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["state", name, owner, label] => {
                m.robot.insert(name.to_string(), *owner == "robot");
                let label = label.trim_matches(|c| c == '{' || c == '}');
                m.labels.insert(
                    name.to_string(),
                    label
                        .split(',')
                        .filter(|p| !p.is_empty())
                        .map(str::to_string)
                        .collect(),
                );
                m.edges.entry(name.to_string()).or_default();
            }
            ["edge", from, action, to] => m
                .edges
                .entry(from.to_string())
                .or_default()
                .push((action.to_string(), to.to_string())),
            _ => {}
        }
    }
    m
}

/// A product state: arena state and one bit per automaton (its `F p` has seen `p`).
type State = (String, [bool; 3]);

fn name((s, q): &State) -> String {
    format!(
        "{s}|{}|{}|{}",
        u8::from(q[0]),
        u8::from(q[1]),
        u8::from(q[2])
    )
}

impl Model {
    /// Every product state of the full enumeration: every arena state with every bit vector
    /// (each letter `{a}`, `{b}`, `{z}` and `{}` labels some arena state).
    fn states(&self) -> Vec<State> {
        let mut out = Vec::new();
        for s in self.robot.keys() {
            for bits in 0..8u8 {
                out.push((s.clone(), [bits & 1 != 0, bits & 2 != 0, bits & 4 != 0]));
            }
        }
        out
    }

    /// The successors of a product state: (action, next state).
    fn successors(&self, (s, q): &State) -> Vec<(String, State)> {
        self.edges[s]
            .iter()
            .map(|(action, t)| {
                let label = &self.labels[t];
                let mut next = *q;
                for (i, p) in PROPOSITIONS.iter().enumerate() {
                    next[i] |= label.iter().any(|l| l == p);
                }
                (action.clone(), (t.clone(), next))
            })
            .collect()
    }
}

/// The export of the general form on the arena above (A = F a, B = F b, psi = F z), as text.
fn export() -> String {
    let parsed = arena::parse(ARENA).unwrap().arena;
    let (tasks, believed) = common::translated_subtasks(&[("A", "F a"), ("B", "F b")], "F z");
    let names = ["A".to_string(), "B".to_string()];
    let payoffs = SubsetPayoffs::new(&[200.0, 100.0], &[], &names).unwrap();
    let problem = Problem {
        arena_name: "test".into(),
        arena: parsed,
        map: None,
        tasks: Tasks::new(tasks, payoffs, believed, Risk::Paper),
        states: States::Full,
        mdp: None,
    };
    let requests = Requests {
        export_strategy: true,
        ..Requests::default()
    };
    let outcome = pipeline::run(&problem, &requests, &mut ()).unwrap();
    outcome.strategy.unwrap()
}

/// Checks the strategies of one region; `target` says which automata must be final.
fn check_region(m: &Model, entry: &Value, target: &[usize], what: &str) -> (usize, usize) {
    let states = m.states();
    let robot = entry["robot"].as_object().unwrap();
    let adversary = entry["adversary"].as_object().unwrap();
    let by_name: BTreeMap<String, &State> = states.iter().map(|s| (name(s), s)).collect();
    for key in robot.keys().chain(adversary.keys()) {
        assert!(by_name.contains_key(key), "{what}: unknown state {key}");
    }
    let satisfied = |(_, q): &State| target.iter().all(|&i| q[i]);
    // In Win: every robot state of Win listed with its rank; walk every play the exported
    // robot strategy allows, against every adversary action.
    let in_win = |s: &State| {
        if m.robot[&s.0] {
            robot.contains_key(&name(s))
        } else {
            !adversary.contains_key(&name(s))
        }
    };
    for (key, ranked) in robot {
        let rank = ranked["rank"].as_u64().unwrap() as usize;
        let start = by_name[key].clone();
        // Depth-first over (state, steps taken).
        let mut stack = vec![(start, 0usize)];
        while let Some((s, steps)) = stack.pop() {
            if satisfied(&s) {
                continue;
            }
            assert!(
                steps < rank,
                "{what}: from {key} (rank {rank}), {} after {steps} steps is not satisfied",
                name(&s)
            );
            let successors = m.successors(&s);
            let moves: Vec<State> = if m.robot[&s.0] {
                let allowed = robot
                    .get(&name(&s))
                    .unwrap_or_else(|| panic!("{what}: the robot left Win at {}", name(&s)))["actions"]
                    .as_array()
                    .unwrap();
                assert!(!allowed.is_empty(), "{what}: no action at {}", name(&s));
                allowed
                    .iter()
                    .map(|a| {
                        let a = a.as_str().unwrap();
                        successors.iter().find(|(b, _)| b == a).unwrap().1.clone()
                    })
                    .collect()
            } else {
                successors.into_iter().map(|(_, t)| t).collect()
            };
            stack.extend(moves.into_iter().map(|t| (t, steps + 1)));
        }
    }
    // Outside Win: the adversary's exported actions against every robot action never
    // satisfy the task and never enter Win.
    let outside: Vec<&State> = states.iter().filter(|s| !in_win(s)).collect();
    for &start in &outside {
        let mut seen = std::collections::BTreeSet::new();
        let mut stack = vec![start.clone()];
        while let Some(s) = stack.pop() {
            if !seen.insert(name(&s)) {
                continue;
            }
            assert!(
                !satisfied(&s),
                "{what}: {} reached from {}",
                name(&s),
                name(start)
            );
            assert!(
                !in_win(&s),
                "{what}: {} in Win reached from {}",
                name(&s),
                name(start)
            );
            let successors = m.successors(&s);
            if m.robot[&s.0] {
                stack.extend(successors.into_iter().map(|(_, t)| t));
            } else {
                let allowed = adversary[&name(&s)].as_array().unwrap();
                assert!(!allowed.is_empty(), "{what}: no action at {}", name(&s));
                for a in allowed {
                    let a = a.as_str().unwrap();
                    stack.push(successors.iter().find(|(b, _)| b == a).unwrap().1.clone());
                }
            }
        }
    }
    (robot.len(), outside.len())
}

#[test]
fn every_exported_strategy_wins_within_its_rank_or_keeps_the_complement() {
    let m = model();
    let text = export();
    // Sets in mask order (a `Value` would sort its keys).
    let at = |key: &str| text.find(&format!("\n    \"{key}\": {{")).unwrap();
    assert!(at("A") < at("B") && at("B") < at("A,B"));
    let export: Value = serde_json::from_str(&text).unwrap();
    assert_eq!(export["states"], "full");
    assert_eq!(export["initial"], "r0|0|0|0");
    assert_eq!(export["subtasks"], serde_json::json!(["A", "B"]));
    let tasks = export["tasks"].as_object().unwrap();
    assert_eq!(tasks.len(), 3);
    assert_eq!(tasks["A,B"]["payoff"], 300.0);
    // Both sub-tasks can be forced from r0 through d2 (rank 4: r0, d2, ra, d3a, rb2).
    assert_eq!(tasks["A,B"]["realizable"], true);
    assert_eq!(tasks["A,B"]["robot"]["r0|0|0|0"]["rank"], 4);
    assert_eq!(
        tasks["A,B"]["robot"]["r0|0|0|0"]["actions"],
        serde_json::json!(["go2"])
    );
    let mut sizes = Vec::new();
    for (key, target) in [("A", &[0][..]), ("B", &[1]), ("A,B", &[0, 1])] {
        sizes.push(check_region(&m, &tasks[key], target, key));
    }
    // psi = F z has its own automaton, so `believed` carries its strategies.
    let believed = &export["believed"];
    assert_eq!(believed["formula"], "Fz");
    assert_eq!(believed["tasks"], Value::Null);
    assert_eq!(believed["realizable"], true);
    sizes.push(check_region(&m, believed, &[2], "psi"));
    // Neither side is vacuous: every region has winning robot states and a complement.
    assert!(
        sizes.iter().all(|&(won, lost)| won > 0 && lost > 0),
        "{sizes:?}"
    );
}

//! The exported controller's JSON Schema (`schema/controller.schema.json`) and its reader
//! (`opportunistic::load`, through `Executor::from_json`) say the same:
//! - every bundled example's exported controller is valid under the schema and reads;
//! - each mutation of a file below is refused by the reader with the part it breaks named (its
//!   JSON path), and either the schema refuses it too or it breaks a rule the schema cannot say,
//!   listed in docs/formats.md (the schema must then accept it, so that the list is exact);
//! - over random mutations of the examples, whatever the schema refuses, the reader refuses.

use hypersynth::opportunistic::executor::Executor;
use hypersynth::opportunistic::export::Table;
use jsonschema::Validator;
use serde_json::{Value, json};

use crate::common::exported_controllers;

fn validator() -> Validator {
    let schema: Value =
        serde_json::from_str(include_str!("../schema/controller.schema.json")).unwrap();
    jsonschema::validator_for(&schema).expect("a valid JSON Schema")
}

/// The rules of docs/formats.md that a reader checks beyond the schema, by their key.
fn documented_rules() -> Vec<String> {
    let doc = include_str!("../docs/formats.md");
    let section = doc
        .split("### Rules beyond the schema")
        .nth(1)
        .expect("docs/formats.md lists the rules beyond the schema");
    section
        .lines()
        .take_while(|line| !line.starts_with('#'))
        .filter_map(|line| line.strip_prefix("- **"))
        .map(|rest| rest.split("**").next().unwrap().to_string())
        .collect()
}

#[test]
fn the_examples_exported_controllers_are_valid_and_read() {
    let validator = validator();
    for (name, text) in exported_controllers() {
        let file: Value = serde_json::from_str(&text).unwrap();
        let errors: Vec<String> = validator
            .iter_errors(&file)
            .map(|e| format!("{}: {e}", e.instance_path()))
            .collect();
        assert!(errors.is_empty(), "{name}: {errors:?}");
        Executor::from_json(&text).unwrap_or_else(|e| panic!("{name}: {e}"));
    }
}

/// Which check refuses a mutation besides the reader.
#[derive(Clone, Copy, Debug)]
enum Refused {
    /// The schema.
    BySchema,
    /// A rule beyond the schema, by its key in docs/formats.md.
    Beyond(&'static str),
}

use Refused::{Beyond, BySchema};

/// A mutation: the example it changes, the change, the JSON path the reader's error names,
/// what else refuses it.
type Mutation = (&'static str, Box<dyn Fn(&mut Value)>, &'static str, Refused);

/// Sets the member or item at `pointer` (adding a member that is not there).
fn set(pointer: &'static str, value: Value) -> Box<dyn Fn(&mut Value)> {
    Box::new(move |file| {
        let (parent, last) = pointer.rsplit_once('/').unwrap();
        match file.pointer_mut(parent).expect(pointer) {
            Value::Object(members) => {
                members.insert(last.to_string(), value.clone());
            }
            Value::Array(items) => items[last.parse::<usize>().unwrap()] = value.clone(),
            _ => panic!("{pointer}"),
        }
    })
}

/// The robot (or adversary) arena states of `executor`'s arena in arena order: the rows of its
/// tables.
fn rows(executor: &Executor, robot: bool) -> Vec<hypersynth::arena::StateId> {
    let arena = executor.arena();
    arena
        .states()
        .filter(|&s| (arena.owner(s) == hypersynth::arena::Owner::Robot) == robot)
        .collect()
}

/// The entries of the table at `pointer` (an object with `width` and `codes`).
fn entries(file: &Value, pointer: &str) -> Vec<Option<u64>> {
    let at = file.pointer(pointer).unwrap();
    let table = Table {
        width: at["width"].as_u64().unwrap() as usize,
        codes: at["codes"].as_str().unwrap().to_string(),
    };
    let entries = table.decode().unwrap();
    (0..entries.len()).map(|i| entries.get(i)).collect()
}

/// Writes `entries` as the table at `pointer`.
fn set_entries(file: &mut Value, pointer: &str, entries: &[Option<u64>]) {
    let table = Table::encode(|| entries.iter().copied());
    let at = file.pointer_mut(pointer).unwrap();
    at["width"] = json!(table.width);
    at["codes"] = json!(table.codes);
}

/// Mode 0 plays, at one of its states, an action the state does not enable.
fn disabled_move(file: &mut Value) {
    let executor = Executor::from_json(&file.to_string()).unwrap();
    let arena = executor.arena();
    let robot = rows(&executor, true);
    let tuples = file["tuples"].as_array().unwrap().len();
    let mut table = entries(file, "/modes/0");
    let (i, action) = (0..table.len())
        .filter(|&i| table[i].is_some())
        .find_map(|i| {
            let s = robot[i / tuples];
            let action = arena
                .actions()
                .iter()
                .filter_map(|name| arena.find_action(name))
                .find(|&a| arena.successor(s, a).is_none())?;
            Some((i, arena.action_name(action).to_string()))
        })
        .expect("a state without some action");
    let choices = file["choices"].as_array_mut().unwrap();
    choices.push(json!({ "move": action }));
    table[i] = Some(choices.len() as u64 - 1);
    set_entries(file, "/modes/0", &table);
}

/// The adversary table marks a move past the last edge of a state.
fn move_past_the_edges(file: &mut Value) {
    let executor = Executor::from_json(&file.to_string()).unwrap();
    let adversary = rows(&executor, false);
    let tuples = file["tuples"].as_array().unwrap().len();
    let mut table = entries(file, "/adversary");
    let i = (0..table.len()).find(|&i| table[i].is_some()).unwrap();
    let edges = executor.arena().edges(adversary[i / tuples]).len();
    table[i] = Some(table[i].unwrap() | 1 << (edges + 1));
    set_entries(file, "/adversary", &table);
}

fn mutations() -> Vec<Mutation> {
    let remove = |pointer: &'static str, key: &'static str| -> Box<dyn Fn(&mut Value)> {
        Box::new(move |file| {
            file.pointer_mut(pointer)
                .unwrap()
                .as_object_mut()
                .unwrap()
                .remove(key);
        })
    };
    let study = "case study";
    vec![
        // The five the reader used to accept.
        (study, set("/discount", json!(-1)), "$.discount", BySchema),
        (
            study,
            set("/discount", json!(1e308)),
            "$.discount",
            BySchema,
        ),
        (study, set("/believed", json!("zz")), "$.believed", BySchema),
        (
            study,
            set("/value", json!([250.0, 200.0])),
            "$.value",
            Beyond("value"),
        ),
        (
            study,
            set("/payoffs/1", json!(-200.0)),
            "$.payoffs[1]",
            BySchema,
        ),
        // The format and the model.
        (
            study,
            set("/format", json!("hypersynth-controller/1")),
            "$.format",
            BySchema,
        ),
        (study, set("/format", json!(2)), "$.format", BySchema),
        (study, remove("", "risk"), "$", BySchema),
        (study, set("/extra", json!(1)), "$.extra", BySchema),
        (
            study,
            set("/scope", json!("everywhere")),
            "$.scope",
            BySchema,
        ),
        (study, set("/tasks", json!([])), "$.tasks", BySchema),
        (
            study,
            set("/tasks/1", json!("phi1")),
            "$.tasks[1]",
            BySchema,
        ),
        (study, set("/form", json!("papers")), "$.form", BySchema),
        (
            "three tasks",
            set("/form", json!("paper")),
            "$.form",
            Beyond("form"),
        ),
        (
            study,
            set("/believed/set", json!(0)),
            "$.believed.set",
            BySchema,
        ),
        (
            study,
            set("/believed/set", json!(4)),
            "$.believed.set",
            Beyond("believed"),
        ),
        (
            "decoy",
            set("/believed/automaton", json!(1)),
            "$.believed.automaton",
            Beyond("believed"),
        ),
        (
            study,
            set(
                "/believed",
                json!({"name": "psi", "set": 1, "automaton": 2}),
            ),
            "$.believed",
            BySchema,
        ),
        (
            study,
            set("/payoffs/0", json!(5.0)),
            "$.payoffs[0]",
            BySchema,
        ),
        (
            study,
            set("/payoffs", json!([0.0, 200.0, 100.0])),
            "$.payoffs",
            Beyond("payoffs"),
        ),
        (
            study,
            set("/payoffs/3", json!(150.0)),
            "$.payoffs[1]",
            Beyond("payoffs"),
        ),
        (
            study,
            set("/payoffs/2", json!(null)),
            "$.payoffs[2]",
            BySchema,
        ),
        (study, set("/discount", json!(0)), "$.discount", BySchema),
        (
            study,
            set("/discount", json!("0.99")),
            "$.discount",
            BySchema,
        ),
        (study, set("/risk", json!("reckless")), "$.risk", BySchema),
        (
            study,
            set("/sigma_w", json!("uniform")),
            "$.sigma_w",
            BySchema,
        ),
        (
            study,
            set("/sigma_l/random/seed", json!(-1)),
            "$.sigma_l.random.seed",
            BySchema,
        ),
        (
            study,
            set("/sigma_l/random/draws", json!("xorshift")),
            "$.sigma_l.random.draws",
            BySchema,
        ),
        (
            study,
            set("/sigma_l", json!("gaussian")),
            "$.sigma_l",
            BySchema,
        ),
        (
            "decoy",
            set("/sigma_l/weights/0/weight", json!(0.0)),
            "$.sigma_l.weights[0].weight",
            BySchema,
        ),
        (
            "decoy",
            set("/sigma_l/weights/0/weight", json!(-1.0)),
            "$.sigma_l.weights[0].weight",
            BySchema,
        ),
        (
            "decoy",
            set("/sigma_l/weights/1/state", json!("nowhere")),
            "$.sigma_l.weights[1].state",
            Beyond("sigma_l"),
        ),
        (
            "decoy",
            set("/sigma_l/weights/1/state", json!("((0,2),(4,2),0)")),
            "$.sigma_l.weights[1].state",
            Beyond("sigma_l"),
        ),
        (
            "decoy",
            set("/sigma_l/weights/1/action", json!("FLY")),
            "$.sigma_l.weights[1].action",
            Beyond("sigma_l"),
        ),
        (
            "decoy",
            set(
                "/sigma_l/weights/1",
                json!({"state": "((0,0),(0,2),1)", "action": "N", "weight": 2.0}),
            ),
            "$.sigma_l.weights[1].state",
            Beyond("sigma_l"),
        ),
        // A learnt sigma_L: the confidence parameter and the counts.
        (
            "learnt",
            set("/sigma_l/learnt/delta", json!(1.0)),
            "$.sigma_l.learnt.delta",
            BySchema,
        ),
        (
            "learnt",
            set("/sigma_l/learnt/counts/0/count", json!(0)),
            "$.sigma_l.learnt.counts[0].count",
            BySchema,
        ),
        (
            "learnt",
            set("/sigma_l/learnt/counts/0/count", json!(2.5)),
            "$.sigma_l.learnt.counts[0].count",
            BySchema,
        ),
        (
            "learnt",
            set("/sigma_l/learnt/counts/1/state", json!("nowhere")),
            "$.sigma_l.learnt.counts[1].state",
            Beyond("sigma_l"),
        ),
        (
            "learnt",
            set("/sigma_l/learnt/counts/1/action", json!("FLY")),
            "$.sigma_l.learnt.counts[1].action",
            Beyond("sigma_l"),
        ),
        (
            "learnt",
            Box::new(|file: &mut Value| {
                let counts = file.pointer_mut("/sigma_l/learnt/counts").unwrap();
                counts[1] = counts[0].clone();
            }),
            "$.sigma_l.learnt.counts[1].state",
            Beyond("sigma_l"),
        ),
        (
            study,
            set("/value", json!([1.0, 2.0, 3.0])),
            "$.value",
            BySchema,
        ),
        (
            study,
            set("/value", json!([-1.0, 300.0])),
            "$.value",
            BySchema,
        ),
        (
            study,
            set("/value", json!([0.0, 1e6])),
            "$.value",
            Beyond("value"),
        ),
        // The arena and the automata.
        (
            study,
            set("/arena", json!({"text": "initial nowhere\n"})),
            "$.arena.text",
            Beyond("arena"),
        ),
        (
            "case study map",
            set("/arena", json!({"map": "hypersynth map v1\ngrid\n@r\n"})),
            "$.arena.map",
            Beyond("arena"),
        ),
        (
            study,
            set("/arena", json!({"map": "x", "text": "y"})),
            "$.arena",
            BySchema,
        ),
        (
            study,
            set("/labels", json!([[], ["A"]])),
            "$.labels",
            Beyond("labels"),
        ),
        (
            study,
            set("/labels/1", json!(["Z"])),
            "$.labels[1]",
            Beyond("labels"),
        ),
        (
            study,
            set("/labels/2", json!(["B", "B"])),
            "$.labels[2]",
            BySchema,
        ),
        (study, set("/labels/2", json!(["A"])), "$.labels", BySchema),
        (
            study,
            set("/automata/0/name", json!("Q")),
            "$.automata[0].name",
            Beyond("automata"),
        ),
        (
            study,
            set("/automata/0/step/0/0", json!(99)),
            "$.automata[0].step[0][0]",
            Beyond("automata"),
        ),
        (
            study,
            set("/automata/0/step/0", json!([0, 1])),
            "$.automata[0].step[0]",
            Beyond("automata"),
        ),
        (
            study,
            set("/automata/0/step/0/0", json!(1.5)),
            "$.automata[0].step[0][0]",
            BySchema,
        ),
        (
            study,
            set("/automata/0/initial", json!(7)),
            "$.automata[0].initial",
            Beyond("automata"),
        ),
        (
            study,
            set("/automata/0/finals", json!([2, 2])),
            "$.automata[0].finals[1]",
            BySchema,
        ),
        (
            study,
            set("/automata/0/step", json!([])),
            "$.automata[0].step",
            BySchema,
        ),
        (
            "decoy",
            Box::new(|file: &mut Value| {
                file["automata"].as_array_mut().unwrap().pop();
            }),
            "$.automata",
            Beyond("automata"),
        ),
        (
            study,
            set("/tuples/0", json!([9, 9])),
            "$.tuples[0]",
            Beyond("tuples"),
        ),
        (
            study,
            set("/tuples/0", json!([0])),
            "$.tuples[0]",
            Beyond("tuples"),
        ),
        (
            study,
            set("/tuples/1", json!([0, 0])),
            "$.tuples[1]",
            BySchema,
        ),
        // The controller's tables.
        (
            study,
            set("/choices/0", json!({"move": "FLY"})),
            "$.choices[0].move",
            Beyond("choices"),
        ),
        (
            study,
            set("/choices/0", json!({"stop": 0})),
            "$.choices[0].stop",
            BySchema,
        ),
        (
            study,
            set("/choices/0", json!({"commit": 4})),
            "$.choices[0].commit",
            Beyond("choices"),
        ),
        (
            study,
            set("/choices/0", json!({"commit": 1})),
            "$.choices[0].commit",
            Beyond("choices"),
        ),
        (
            study,
            set("/choices/0", json!("give up")),
            "$.choices[0]",
            BySchema,
        ),
        (
            study,
            set("/modes/0/width", json!(0)),
            "$.modes[0].width",
            BySchema,
        ),
        (
            study,
            set("/modes/0/codes", json!("~~")),
            "$.modes[0].codes",
            BySchema,
        ),
        (
            study,
            set("/modes/0/codes", json!("0")),
            "$.modes[0].codes",
            Beyond("modes"),
        ),
        (
            study,
            set("/modes/0/set", json!(2)),
            "$.modes",
            Beyond("modes"),
        ),
        (
            study,
            set("/modes/1/set", json!(0)),
            "$.modes[1].set",
            Beyond("modes"),
        ),
        (
            study,
            set("/modes/1/set", json!(9)),
            "$.modes[1].set",
            Beyond("modes"),
        ),
        (
            study,
            Box::new(disabled_move),
            "$.modes[0].codes",
            Beyond("modes"),
        ),
        (
            study,
            set("/adversary/codes", json!("")),
            "$.adversary.codes",
            Beyond("adversary"),
        ),
        (
            study,
            Box::new(move_past_the_edges),
            "$.adversary.codes",
            Beyond("adversary"),
        ),
    ]
}

#[test]
fn every_refused_mutation_is_refused_by_the_schema_or_a_documented_rule() {
    let validator = validator();
    let documented = documented_rules();
    let examples = exported_controllers();
    let mut failures = Vec::new();
    for (example, change, path, refused) in mutations() {
        let (_, text) = examples.iter().find(|(name, _)| *name == example).unwrap();
        let mut file: Value = serde_json::from_str(text).unwrap();
        change(&mut file);
        let error = match Executor::from_json(&file.to_string()) {
            Ok(_) => {
                failures.push(format!("{example}: accepted ({path})"));
                continue;
            }
            Err(error) => error.to_string(),
        };
        if !error
            .lines()
            .any(|line| line.starts_with(&format!("{path}: ")))
        {
            failures.push(format!("{example}: {path} is not named: {error}"));
        }
        let valid = validator.is_valid(&file);
        match refused {
            BySchema if valid => failures.push(format!("{example}: {path}: the schema accepts it")),
            Beyond(rule) if !valid => failures.push(format!(
                "{example}: {path}: the schema refuses it, not only rule {rule}"
            )),
            Beyond(rule) if !documented.iter().any(|r| r == rule) => {
                failures.push(format!("rule {rule} is not in docs/formats.md"))
            }
            _ => {}
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// A small deterministic generator (xorshift).
struct Rng(u64);

impl Rng {
    fn below(&mut self, n: usize) -> usize {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 % n as u64) as usize
    }
}

/// Every place of `value` (JSON pointers), but inside strings.
fn places(value: &Value, at: String, out: &mut Vec<String>) {
    match value {
        Value::Object(members) => {
            for (key, member) in members {
                places(member, format!("{at}/{key}"), out);
            }
        }
        Value::Array(items) => {
            for (i, item) in items.iter().enumerate() {
                places(item, format!("{at}/{i}"), out);
            }
        }
        _ => {}
    }
    out.push(at);
}

#[test]
fn whatever_the_schema_refuses_the_reader_refuses() {
    let validator = validator();
    let replacements = [
        json!(-1),
        json!(0),
        json!(0.5),
        json!(1),
        json!(2),
        json!(255),
        json!(1e308),
        json!(u64::MAX),
        json!("zz"),
        json!(""),
        json!(null),
        json!(true),
        json!([]),
        json!([0, 0]),
        json!({}),
        json!("give_up"),
        json!({"move": "N"}),
    ];
    let mut rng = Rng(0x2545_f491_4f6c_dd1d);
    let (mut refused_by_schema, mut accepted) = (0, 0);
    for (name, text) in exported_controllers() {
        let original: Value = serde_json::from_str(&text).unwrap();
        let mut all = Vec::new();
        places(&original, String::new(), &mut all);
        for _ in 0..150 {
            let mut file = original.clone();
            let at = &all[rng.below(all.len())];
            if rng.below(4) == 0 && !at.is_empty() {
                // Remove the member or item.
                let (parent, last) = at.rsplit_once('/').unwrap();
                match file.pointer_mut(parent).unwrap() {
                    Value::Object(members) => {
                        members.remove(last);
                    }
                    Value::Array(items) => {
                        items.remove(last.parse().unwrap());
                    }
                    _ => unreachable!(),
                }
            } else {
                *file.pointer_mut(at).unwrap() =
                    replacements[rng.below(replacements.len())].clone();
            }
            let read = Executor::from_json(&file.to_string());
            if !validator.is_valid(&file) {
                refused_by_schema += 1;
                assert!(
                    read.is_err(),
                    "{name}: {at}: the reader accepts what the schema refuses"
                );
            }
            if read.is_ok() {
                accepted += 1;
            }
        }
    }
    // Most mutations break the file; some (a value within its range) do not.
    assert!(refused_by_schema > 300, "{refused_by_schema}");
    assert!(accepted < 200, "{accepted}");
}

/// A file of scope `all`, its uncommitted table deciding at every robot state and tuple (here
/// the first action each state enables, or giving up where it enables none, where the exported
/// file has no choice), reads under
/// the schema and the reader; `execute` answers after the robot's own slip at the state where
/// the file of scope `reachable` stops.
#[test]
fn a_file_of_scope_all_reads_and_goes_on_after_a_slip() {
    let examples = exported_controllers();
    let (_, text) = examples
        .iter()
        .find(|(n, _)| *n == "case study map")
        .unwrap();
    let mut file: Value = serde_json::from_str(text).unwrap();
    let executor = Executor::from_json(text).unwrap();
    let arena = executor.arena();
    let robot = rows(&executor, true);
    let tuples = file["tuples"].as_array().unwrap().len();
    let mut table = entries(&file, "/modes/0");
    let added = table.iter().filter(|e| e.is_none()).count();
    for (i, entry) in table.iter_mut().enumerate() {
        if entry.is_none() {
            // A state without moves gives up.
            let choice = match arena.edges(robot[i / tuples]).next() {
                Some((action, _)) => json!({ "move": arena.action_name(action) }),
                None => json!("give_up"),
            };
            let choices = file["choices"].as_array_mut().unwrap();
            let c = match choices.iter().position(|c| *c == choice) {
                Some(c) => c,
                None => {
                    choices.push(choice);
                    choices.len() - 1
                }
            };
            *entry = Some(c as u64);
        }
    }
    assert!(added > 0);
    set_entries(&mut file, "/modes/0", &table);
    file["scope"] = json!("all");
    assert!(validator().is_valid(&file));
    Executor::from_json(&file.to_string()).unwrap();

    // The robot plays E where N was answered; the adversary then moves W.
    let play = "((0,2),(4,2),0)\n((1,2),(4,2),1)\n((1,2),(3,2),0)\n";
    let dir = tempfile::tempdir().unwrap();
    let (reachable, all) = (
        dir.path().join("reachable.json"),
        dir.path().join("all.json"),
    );
    std::fs::write(&reachable, text).unwrap();
    std::fs::write(&all, file.to_string()).unwrap();
    let output = crate::common::execute(&reachable, play);
    assert_eq!(output.status.code(), Some(1));
    assert!(
        String::from_utf8(output.stderr)
            .unwrap()
            .contains("step 2: the controller has no choice")
    );
    let output = crate::common::execute(&all, play);
    assert!(output.status.success(), "{output:?}");
    let slipped = arena.find_state("((1,2),(3,2),0)").unwrap();
    let first = arena.action_name(arena.edges(slipped).next().unwrap().0);
    assert_eq!(
        String::from_utf8(output.stdout).unwrap(),
        format!("N\n{first}\n")
    );
}

/// Numbers are read correctly rounded, so that a file written and read back is the same file:
/// a payoff of 42 digits that the fuzz target found read one unit in the last place off (and
/// read back differently once written) before the JSON reader parsed floats exactly.
#[test]
fn numbers_read_exactly_and_a_file_reads_back_the_same() {
    let examples = exported_controllers();
    let (_, text) = examples.iter().find(|(n, _)| *n == "case study").unwrap();
    let long = "302222222222222222222222222222222222222220.0";
    let from = "\"payoffs\":[0.0,200.0,100.0,300.0]";
    assert!(text.contains(from));
    let text = text.replace(from, &format!("\"payoffs\":[0.0,200.0,100.0,{long}]"));
    let file = hypersynth::opportunistic::load::read(&text).unwrap();
    assert_eq!(file.payoffs[3], long.parse::<f64>().unwrap());
    let written = serde_json::to_string(&file).unwrap();
    assert_eq!(
        hypersynth::opportunistic::load::read(&written).unwrap(),
        file
    );
}

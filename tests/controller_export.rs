//! The exported controller (docs/semantics.md §9) through the command (what the file collects
//! and how the executor replays a simulation are the library's
//! `tests/opportunistic/executor.rs`):
//! - `hypersynth execute` answers a recorded run (the in-process trace) line by line through a
//!   pipe, reports an off-model adversary move and goes on, and locates its errors;
//! - a file claiming scope `all` must cover what `all` covers;
//! - the implicit engine exports the same controller and prints the same decision tables.

use crate::common::{CHANCE_CYCLE, THREE_TASKS, execute};
use assert_cmd::Command;
use hypersynth::opportunistic::executor::Executor;

const CASE_STUDY: &str = "specs/case-study/map.txt";
const DECOY: &str = "specs/decoy/map.txt";
/// The case study's discounted problem with sigma_L random.
const RANDOM_SIGMA_L: &[&str] = &[
    "--discount",
    "0.95",
    "--sigma-l",
    "random",
    "--seed",
    "2019",
];

#[test]
fn execute_answers_a_recorded_run_line_by_line() {
    let dir = tempfile::tempdir().unwrap();
    let controller = dir.path().join("controller.json");
    let output = Command::cargo_bin("hypersynth")
        .unwrap()
        .args(["--phi", "(!O U A) & (!O U B)", "--psi", "!O U A"])
        .args(["--discount", "0.99", "--sigma-l", "uniform", "--trace"])
        .args(["--format", "json", "--export-controller"])
        .arg(&controller)
        .arg(CASE_STUDY)
        .output()
        .unwrap();
    assert!(output.status.success(), "{output:?}");
    let report: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    let steps = report["trace"]["steps"].as_array().unwrap().clone();
    // The arena state of each step (a product state is `ARENA|Q1|Q2`) and the answer the trace
    // implies at each robot step: its action, preceded by the commitment made there.
    let arena_state = |step: &serde_json::Value| {
        let state = step["state"].as_str().unwrap();
        state.rsplitn(3, '|').last().unwrap().to_string()
    };
    let play: String = steps.iter().map(|s| arena_state(s) + "\n").collect();
    let mut expected = Vec::new();
    let mut committed: Option<String> = None;
    for step in &steps {
        let robot = arena_state(step).ends_with(",0)");
        let now = step["committed"].as_str().map(str::to_string);
        let action = step["action"].as_str();
        if robot {
            match (action, now == committed, &now) {
                (Some(a), true, _) => expected.push(a.to_string()),
                (Some(a), false, Some(set)) => expected.push(format!("commit {set} {a}")),
                (None, true, Some(_)) => expected.push("done".to_string()),
                (None, false, Some(set)) => expected.push(format!("commit {set} done")),
                other => panic!("unexpected step {other:?}"),
            }
        }
        committed = now;
    }
    let output = execute(&controller, &play);
    assert!(output.status.success(), "{output:?}");
    let answers: Vec<String> = String::from_utf8(output.stdout)
        .unwrap()
        .lines()
        .map(str::to_string)
        .collect();
    assert_eq!(answers, expected);
    assert!(output.stderr.is_empty());
}

#[test]
fn execute_reports_an_off_model_adversary_move_and_goes_on() {
    let dir = tempfile::tempdir().unwrap();
    let arena = dir.path().join("arena.txt");
    std::fs::write(&arena, CHANCE_CYCLE).unwrap();
    let controller = dir.path().join("controller.json");
    let output = Command::cargo_bin("hypersynth")
        .unwrap()
        .args(["--phi", "F A & F B", "--psi", "F A", "--sigma-l", "uniform"])
        .args(["-q", "--export-controller"])
        .arg(&controller)
        .arg(&arena)
        .output()
        .unwrap();
    assert!(output.status.success(), "{output:?}");
    // On the model: r0 plays a; x0 → x1 → r2 (B, phi2's region: commit to phi2, B holds).
    let output = execute(&controller, "r0\nx0\nx1\nr2\n");
    assert!(output.status.success(), "{output:?}");
    assert_eq!(
        String::from_utf8(output.stdout).unwrap(),
        "a\ncommit phi2 done\n"
    );
    assert!(output.stderr.is_empty());
    // Off the model: x0 plays c into r1 (A holds, phi1 can be settled for by stop).
    let output = execute(&controller, "r0\nx0\nr1\n");
    assert!(output.status.success(), "{output:?}");
    assert_eq!(
        String::from_utf8(output.stdout).unwrap(),
        "a\nstop phi1 done\n"
    );
    assert_eq!(
        String::from_utf8(output.stderr).unwrap(),
        "hypersynth: warning: <stdin>:3: step 2: off-model move: the adversary played `c`, \
         which the model gives probability 0; play goes on\n"
    );
}

#[test]
fn execute_locates_its_errors_and_refuses_a_broken_controller() {
    let dir = tempfile::tempdir().unwrap();
    let controller = dir.path().join("controller.json");
    let status = Command::cargo_bin("hypersynth")
        .unwrap()
        .args(["--phi", "(!O U A) & (!O U B)", "--psi", "!O U A"])
        .args(["-q", "--export-controller"])
        .arg(&controller)
        .arg(CASE_STUDY)
        .output()
        .unwrap();
    assert!(status.status.success());
    let error = |controller: &std::path::Path, play: &str| {
        let output = execute(controller, play);
        assert_eq!(output.status.code(), Some(1), "{output:?}");
        String::from_utf8(output.stderr).unwrap()
    };
    // A play that does not start in the initial state, a step that is no move, a name that is no
    // state; the answers before the error are printed.
    assert!(
        error(&controller, "((0,3),(4,2),0)\n")
            .contains("<stdin>:1: step 0: the play must start in the initial state")
    );
    let stderr = error(&controller, "((0,2),(4,2),0)\n\n((4,4),(4,2),1)\n");
    assert!(
        stderr.contains(
            "<stdin>:3: step 1: no move leads from `((0,2),(4,2),0)` to `((4,4),(4,2),1)`"
        ),
        "{stderr}"
    );
    assert!(
        error(&controller, "nowhere\n").contains("<stdin>:1: step 0: `nowhere` is not a state")
    );
    // Broken files: not JSON (located at its line and column, under an excerpt of the line),
    // another format, version 1, a table of the wrong length.
    let text = std::fs::read_to_string(&controller).unwrap();
    let broken = dir.path().join("broken.json");
    let half = text.len() / 2;
    std::fs::write(&broken, &text[..half]).unwrap();
    let stderr = error(&broken, "");
    assert!(
        stderr.starts_with(&format!(
            "hypersynth: error: {}:1:{half}: ",
            broken.display()
        )),
        "not JSON: {stderr}"
    );
    assert_eq!(stderr.lines().count(), 3, "{stderr}");
    std::fs::write(
        &broken,
        text.replace("hypersynth-controller/2", "hypersynth-controller/9"),
    )
    .unwrap();
    assert!(error(&broken, "").contains(
        "broken.json: $.format: expected \"hypersynth-controller/2\", found \"hypersynth-controller/9\""
    ));
    std::fs::write(
        &broken,
        text.replace("hypersynth-controller/2", "hypersynth-controller/1"),
    )
    .unwrap();
    let stderr = error(&broken, "");
    assert!(
        stderr.contains("$.format: a file of version 1 of the format")
            && stderr.contains("export the controller again"),
        "{stderr}"
    );
    let mut value: serde_json::Value = serde_json::from_str(&text).unwrap();
    let codes = value["modes"][0]["codes"].as_str().unwrap().to_string();
    value["modes"][0]["codes"] = serde_json::Value::String(codes[1..].to_string());
    std::fs::write(&broken, value.to_string()).unwrap();
    let stderr = error(&broken, "");
    assert!(
        stderr.contains("broken.json: $.modes[0].codes: "),
        "{stderr}"
    );
}

/// The schema in `schema/` names exactly the parts an exported file with a certificate has, all
/// required but the certificate, and every choice of a file has one of the shapes it allows.
#[test]
fn the_json_schema_describes_the_exported_file() {
    let schema: serde_json::Value =
        serde_json::from_str(include_str!("../schema/controller.schema.json")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let controller = dir.path().join("controller.json");
    let output = Command::cargo_bin("hypersynth")
        .unwrap()
        .args(THREE_TASKS)
        .args([
            "-q",
            "--sigma-l",
            "uniform",
            "--certificate",
            "--export-controller",
        ])
        .arg(&controller)
        .arg(DECOY)
        .output()
        .unwrap();
    assert!(output.status.success(), "{output:?}");
    let file: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&controller).unwrap()).unwrap();
    let keys = |value: &serde_json::Value| -> Vec<String> {
        let mut keys: Vec<String> = value.as_object().unwrap().keys().cloned().collect();
        keys.sort();
        keys
    };
    let mut required: Vec<String> = schema["required"]
        .as_array()
        .unwrap()
        .iter()
        .map(|k| k.as_str().unwrap().to_string())
        .collect();
    required.push("certificate".to_string());
    required.sort();
    assert_eq!(keys(&file), required);
    assert_eq!(keys(&schema["properties"]), required);
    assert!(!schema["required"].to_string().contains("certificate"));
    assert_eq!(file["format"], schema["properties"]["format"]["const"]);
    for choice in file["choices"].as_array().unwrap() {
        let shape = match choice {
            serde_json::Value::String(s) => s.clone(),
            other => keys(other).join(","),
        };
        assert!(
            ["move", "stop", "commit", "give_up"].contains(&shape.as_str()),
            "{choice}"
        );
    }
    let digits = |codes: &serde_json::Value| {
        codes
            .as_str()
            .unwrap()
            .bytes()
            .all(|b| b.is_ascii_alphanumeric() || b"-_.~".contains(&b))
    };
    for mode in file["modes"].as_array().unwrap() {
        assert!(digits(&mode["codes"]));
    }
    assert!(digits(&file["adversary"]["codes"]));
    let certificate = &file["certificate"];
    assert_eq!(
        keys(certificate),
        keys(&schema["properties"]["certificate"]["properties"])
    );
    for table in ["values", "lower", "upper"] {
        assert!(digits(&certificate[table]["codes"]), "{table}");
    }
}

/// The expected total reward from the `init` state of a DRN Markov chain (one action per
/// state), by value iteration from 0 until it moves by less than 1e-13: what Storm's
/// `R{"r"}max=? [C]` computes on it. Read by the rules of `mdp::drn`'s documentation.
fn chain_value(drn: &str) -> f64 {
    let (mut init, mut states) = (None, Vec::<(f64, Vec<(usize, f64)>)>::new());
    let mut model = false;
    for line in drn.lines().filter(|l| !l.starts_with("//")) {
        if line == "@model" {
            model = true;
        } else if !model {
        } else if let Some(rest) = line.strip_prefix("state ") {
            if rest.split(' ').any(|w| w == "init") {
                init = Some(states.len());
            }
            states.push((0.0, Vec::new()));
        } else if let Some(rest) = line.strip_prefix("\taction ") {
            let state = states.last_mut().unwrap();
            assert!(
                state.1.is_empty(),
                "one action per state in an induced chain"
            );
            let reward = rest.split('[').nth(1).unwrap().trim_end_matches(']');
            state.0 = reward.parse().unwrap();
        } else {
            let (target, p) = line.trim().split_once(" : ").unwrap();
            let state = states.last_mut().unwrap();
            state.1.push((target.parse().unwrap(), p.parse().unwrap()));
        }
    }
    let mut x = vec![0.0; states.len()];
    loop {
        let mut change: f64 = 0.0;
        for (s, (reward, successors)) in states.iter().enumerate() {
            let value = reward + successors.iter().map(|&(t, p)| p * x[t]).sum::<f64>();
            change = change.max((value - x[s]).abs());
            x[s] = value;
        }
        if change < 1e-13 {
            return x[init.unwrap()];
        }
    }
}

#[test]
fn the_induced_drn_is_the_controllers_chain_and_its_value_is_policy_value() {
    let dir = tempfile::tempdir().unwrap();
    let drn = dir.path().join("induced.drn");
    for extra in [
        &[
            "--phi",
            "(!O U A) & (!O U B)",
            "--psi",
            "!O U A",
            "--discount",
            "0.99",
        ][..],
        &[&["--sigma-l", "uniform"][..], THREE_TASKS].concat()[..],
    ]
    .into_iter()
    .flat_map(|extra| [(extra, "explicit"), (extra, "implicit")])
    {
        // Both engines: the implicit one's chain is its own policy's.
        let (extra, engine) = extra;
        let output = Command::cargo_bin("hypersynth")
            .unwrap()
            .args(extra)
            .args(["-q", "--format", "json", "--induced", "--engine", engine])
            .arg("--export-mdp")
            .arg(&drn)
            .arg(DECOY)
            .output()
            .unwrap();
        assert!(output.status.success(), "{output:?}");
        let report: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
        let policy_value = report["initial"]["policy_value"]
            .as_f64()
            .or(report["decision"]["policy_value"].as_f64())
            .unwrap();
        let text = std::fs::read_to_string(&drn).unwrap();
        let value = chain_value(&text);
        assert!(
            (value - policy_value).abs() < 1e-6,
            "{value} vs {policy_value}"
        );
    }
    // --induced needs --export-mdp.
    let output = Command::cargo_bin("hypersynth")
        .unwrap()
        .args([
            "--phi",
            "F A & F B",
            "--psi",
            "F A",
            "--induced",
            CASE_STUDY,
        ])
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(2));
}

/// A file that claims scope `all` must cover what `all` covers: the case study's file of scope
/// `reachable` relabelled `all` is refused at the uncommitted mode's table, and the same file
/// exported with `--controller-scope all` is read.
#[test]
fn a_file_claiming_scope_all_must_cover_every_robot_state_a_play_reaches() {
    let dir = tempfile::tempdir().unwrap();
    let export = |scope: &str| {
        let path = dir.path().join(format!("{scope}.json"));
        let output = Command::cargo_bin("hypersynth")
            .unwrap()
            .args(["--phi", "(!O U A) & (!O U B)", "--psi", "!O U A"])
            .args(["--translator", "builtin", "-q", "--controller-scope", scope])
            .arg("--export-controller")
            .arg(&path)
            .arg(CASE_STUDY)
            .output()
            .unwrap();
        assert!(output.status.success(), "{output:?}");
        std::fs::read_to_string(&path).unwrap()
    };
    let reachable = export("reachable");
    assert!(reachable.contains(r#""scope":"reachable""#));
    let claimed = reachable.replace(r#""scope":"reachable""#, r#""scope":"all""#);
    let error = Executor::from_json(&claimed).err().expect("refused");
    let text = error.to_string();
    assert!(
        text.starts_with("$.modes[0].codes: scope `all`, but no choice at `"),
        "{text}"
    );
    let all = export("all");
    assert!(all.contains(r#""scope":"all""#));
    assert!(Executor::from_json(&all).is_ok());
    // Covering more states, the file is larger.
    assert!(all.len() > reachable.len());
}

/// The implicit engine exports the explicit engine's controller: on the case study (g = 1,
/// sigma_L uniform; g = 0.95, sigma_L random), where no two choices tie along the plays it
/// covers, the same file but for the certified value (within the precision), which
/// `hypersynth execute` runs alike. (Random models, ties included: the library's
/// `tests/pipeline/engines.rs`.)
#[test]
fn the_implicit_engine_exports_the_same_controller() {
    let dir = tempfile::tempdir().unwrap();
    for options in [
        &["--discount", "1", "--sigma-l", "uniform", "--seed", "1"],
        RANDOM_SIGMA_L,
    ] {
        let mut files = Vec::new();
        for engine in ["explicit", "implicit"] {
            let path = dir.path().join(format!("{engine}.json"));
            Command::cargo_bin("hypersynth")
                .unwrap()
                .args(["--phi", "(!O U A) & (!O U B)", "--psi", "!O U A"])
                .args(options)
                .args(["--engine", engine, "--export-controller"])
                .arg(&path)
                .arg(CASE_STUDY)
                .assert()
                .success();
            let text = std::fs::read_to_string(&path).unwrap();
            let mut file: serde_json::Value = serde_json::from_str(&text).unwrap();
            let value = file["value"].take();
            files.push((path, file, value));
        }
        let [(explicit, e, e_value), (implicit, i, i_value)] = &files[..] else {
            unreachable!()
        };
        assert_eq!(i, e, "{options:?}");
        for k in 0..2 {
            let (a, b) = (e_value[k].as_f64().unwrap(), i_value[k].as_f64().unwrap());
            assert!(
                (a - b).abs() <= 2e-6 * a.max(1.0),
                "{options:?}: {a} against {b}"
            );
        }
        let executor = Executor::from_json(&std::fs::read_to_string(implicit).unwrap()).unwrap();
        let arena = executor.arena();
        let play = format!("{}\n", arena.name(arena.initial()));
        let (a, b) = (execute(explicit, &play), execute(implicit, &play));
        assert!(a.status.success() && b.status.success(), "{b:?}");
        assert!(!a.stdout.is_empty());
        assert_eq!(a.stdout, b.stdout);
    }
}

/// `--explain=STATE` gives the same decision table on the implicit engine as on the explicit
/// one, on the case study's map (h0, a robot state whose `N` leads through the adversary to
/// three states, an adversary state): at g = 1 with sigma_L uniform, where both solves are
/// exact, the same text; at g = 0.95 with sigma_L random, the same JSON table but for the
/// numbers, within the precision (1e-6: both solvers stop anywhere inside the certified
/// interval). A name that is no product state gets the same error from both.
#[test]
fn the_implicit_engine_prints_the_same_decision_tables() {
    let run = |engine: &str, options: &[&str], state: &str| {
        Command::cargo_bin("hypersynth")
            .unwrap()
            .args(["--phi", "(!O U A) & (!O U B)", "--psi", "!O U A"])
            .args(options)
            .args([
                "--engine",
                engine,
                &format!("--explain={state}"),
                CASE_STUDY,
            ])
            .output()
            .unwrap()
    };
    let stdout = |output: std::process::Output| {
        assert!(output.status.success(), "{output:?}");
        String::from_utf8(output.stdout).unwrap()
    };
    // The decision table: the text report's last section.
    let table = |text: String| {
        let at = text.find("decision table of").expect("a decision table");
        text[at..].to_string()
    };
    let exact = ["--discount", "1", "--sigma-l", "uniform"];
    let json =
        [&exact[..], RANDOM_SIGMA_L].map(|options| [options, &["--format", "json"]].concat());
    for state in ["h0", "((1,2),(4,2),0)|0|0", "((1,2),(4,2),1)|0|0"] {
        let explicit = table(stdout(run("explicit", &exact, state)));
        let implicit = table(stdout(run("implicit", &exact, state)));
        assert!(explicit.lines().count() > 1, "{explicit}");
        assert_eq!(implicit, explicit, "{state}");
        for options in &json {
            let explain = |engine| {
                let report: serde_json::Value =
                    serde_json::from_str(&stdout(run(engine, options, state))).unwrap();
                report["explain"].clone()
            };
            let (explicit, implicit) = (explain("explicit"), explain("implicit"));
            assert!(explicit.is_object(), "{explicit}");
            assert_close(&implicit, &explicit, &format!("{options:?} {state}"));
        }
    }
    let bad = "((1,2),(4,2),0)|0|7";
    let (explicit, implicit) = (run("explicit", &exact, bad), run("implicit", &exact, bad));
    assert_eq!(explicit.status.code(), Some(1), "{explicit:?}");
    assert_eq!(implicit.status.code(), explicit.status.code());
    assert!(implicit.stdout.is_empty() && !explicit.stderr.is_empty());
    assert_eq!(implicit.stderr, explicit.stderr);
}

/// `a` and `b` are the same JSON but for numbers, which are within a relative 2e-6.
fn assert_close(a: &serde_json::Value, b: &serde_json::Value, case: &str) {
    use serde_json::Value;
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => {
            let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
            assert!(
                (x - y).abs() <= 2e-6 * x.abs().max(1.0),
                "{case}: {x} against {y}"
            );
        }
        (Value::Array(x), Value::Array(y)) => {
            assert_eq!(x.len(), y.len(), "{case}: {a} against {b}");
            x.iter().zip(y).for_each(|(x, y)| assert_close(x, y, case));
        }
        (Value::Object(x), Value::Object(y)) => {
            assert!(x.keys().eq(y.keys()), "{case}: {a} against {b}");
            x.values()
                .zip(y.values())
                .for_each(|(x, y)| assert_close(x, y, case));
        }
        _ => assert_eq!(a, b, "{case}"),
    }
}

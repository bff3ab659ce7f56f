//! The general form on the command line (`--task`, `--payoff`, `--believed`, `--risk`):
//! the paper's special case gives the paper form's report, hand-solved games give their values,
//! and every bad option gets one located error line.

use crate::common;

use assert_cmd::Command;

const CASE_STUDY: &str = "specs/case-study/arena.txt";

fn hypersynth(args: &[&str]) -> std::process::Output {
    Command::cargo_bin("hypersynth")
        .unwrap()
        .arg("-q")
        .args(args)
        .output()
        .unwrap()
}

fn stdout(output: &std::process::Output) -> String {
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    String::from_utf8(output.stdout.clone()).unwrap()
}

fn error(output: &std::process::Output) -> (i32, String) {
    assert!(
        !output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stdout)
    );
    (
        output.status.code().unwrap(),
        String::from_utf8(output.stderr.clone()).unwrap(),
    )
}

#[test]
fn the_papers_special_case_gives_the_paper_forms_report() {
    for extra in [&[][..], &["--discount", "0.99", "--sigma-l", "uniform"]] {
        let paper = hypersynth(
            &[
                &["--phi", "(!O U A) & (!O U B)", "--psi", "!O U A"][..],
                extra,
                &["--explain", CASE_STUDY],
            ]
            .concat(),
        );
        let general = hypersynth(
            &[
                common::DECOY_TASKS,
                &["--believed", "!O U A"],
                extra,
                &["--explain", CASE_STUDY],
            ]
            .concat(),
        );
        assert_eq!(stdout(&general), stdout(&paper));
    }
}

/// The hand-solved decoy game of `mdp::subtasks`' tests as an arena file: one sub-task A, the
/// adversary's belief `F z` (a decoy) or `F a` (correct).
const DECOY: &str = "\
propositions a z
actions go toA toZ block
initial r0
state r0 robot {}
state c adversary {}
state ra robot {a}
state rz robot {z}
state rx robot {}
edge r0 go c
edge c toA ra
edge c toZ rz
edge c block rx
";

fn decoy(believed: &str, format: &[&str]) -> std::process::Output {
    let dir = tempfile::tempdir().unwrap();
    let arena = dir.path().join("decoy.txt");
    std::fs::write(&arena, DECOY).unwrap();
    hypersynth(
        &[
            &[
                "--task",
                "A=F a",
                "--payoff",
                "A=100",
                "--believed",
                believed,
                "--translator",
                "builtin",
                arena.to_str().unwrap(),
            ][..],
            format,
        ]
        .concat(),
    )
}

#[test]
fn a_decoy_belief_is_worth_half_the_task_and_a_correct_one_nothing() {
    // sigma_W in c: uniform over the actions that keep the play outside Win(psi).
    let json: serde_json::Value =
        serde_json::from_str(&stdout(&decoy("F z", &["--format", "json"]))).unwrap();
    assert_eq!(json["decision"]["value"], 50.0);
    assert_eq!(json["decision"]["action"], "go");
    assert_eq!(json["believed"]["tasks"], serde_json::Value::Null);
    assert_eq!(json["believed"]["automaton"]["states"], 2);
    assert_eq!(json["initial"]["guarantee"], 0.0);
    assert_eq!(json["settings"]["risk"], "paper");
    // The product has the psi automaton: 5 arena states x 2 x 2 DFA states.
    assert_eq!(json["product_states"], 20);
    let json: serde_json::Value =
        serde_json::from_str(&stdout(&decoy("F a", &["--format", "json"]))).unwrap();
    assert_eq!(json["decision"]["value"], 0.0);
    assert_eq!(json["believed"]["tasks"], serde_json::json!(["A"]));
    assert_eq!(json["product_states"], 10);
    // 2000 simulated runs: about half satisfy A (payoff 100), the others end with nothing.
    let json: serde_json::Value = serde_json::from_str(&stdout(&decoy(
        "F z",
        &["--simulate", "2000", "--format", "json"],
    )))
    .unwrap();
    let outcomes = json["simulation"]["outcomes"].as_array().unwrap();
    assert_eq!(outcomes[0]["outcome"], "A satisfied");
    let satisfied = outcomes[0]["count"].as_u64().unwrap();
    let none = outcomes.iter().find(|o| o["outcome"] == "none").unwrap()["count"]
        .as_u64()
        .unwrap();
    assert_eq!(satisfied + none, 2000);
    assert!((900..1100).contains(&satisfied), "{satisfied}");
    let mean = json["simulation"]["mean_payoff"].as_f64().unwrap();
    assert_eq!(mean, satisfied as f64 * 100.0 / 2000.0);
    let text = stdout(&decoy("F z", &["--trace"]));
    assert!(
        text.contains("trace\n     0  r0|0|0  {} | psi L gr 0  go"),
        "{text}"
    );
    let text = stdout(&decoy("F z", &[]));
    assert!(text.contains("value of h0    50 "), "{text}");
    assert!(text.contains("believed psi   Fz"), "{text}");
}

#[test]
fn three_tasks_with_a_bonus_run_and_the_label_table_adds_up() {
    let dir = tempfile::tempdir().unwrap();
    let drn = dir.path().join("mdp.drn");
    let output = hypersynth(&[
        "--task",
        "A=!O U A",
        "--task",
        "B=!O U B",
        "--task",
        "C=F A",
        "--payoff",
        "A,B,C=500",
        "--believed",
        "!O U B",
        "--risk",
        "strict",
        "--format",
        "json",
        "--export-mdp",
        drn.to_str().unwrap(),
        CASE_STUDY,
    ]);
    let json: serde_json::Value = serde_json::from_str(&stdout(&output)).unwrap();
    // The DRN export: product states, then one stop sink per set of sub-tasks.
    let drn = std::fs::read_to_string(&drn).unwrap();
    assert!(drn.contains("@type: MDP"));
    assert!(drn.contains("stop(A,B,C)"));
    let states = json["mdp"]["states"].as_u64().unwrap();
    assert_eq!(states, json["product_states"].as_u64().unwrap() + 7);
    let rows = json["partition"].as_array().unwrap();
    let total: u64 = rows.iter().map(|r| r["total"].as_u64().unwrap()).sum();
    assert_eq!(total, json["product_states"].as_u64().unwrap());
    assert_eq!(json["regions"].as_array().unwrap().len(), 7);
    assert_eq!(json["payoffs"][6]["payoff"], 500.0);
    let value = json["decision"]["value"].as_f64().unwrap();
    assert!(value >= json["initial"]["guarantee"].as_f64().unwrap());
    assert_eq!(json["decision"]["policy_value"], json["decision"]["value"]);
}

#[test]
fn bad_options_get_one_located_error() {
    let base = ["--believed", "F a", CASE_STUDY];
    for (args, expected) in [
        (
            vec!["--task", "1A=F a"],
            "--task:1:1: `1A` is not a sub-task name",
        ),
        (vec!["--task", "A"], "--task:1:2: expected NAME=VALUE"),
        (vec!["--task", "A=F (a"], "A: --task:1:"),
        (
            vec!["--task", "A=F a", "--payoff", "A,X=3"],
            "--payoff:1:3: no sub-task is named `X`",
        ),
        (
            vec!["--task", "A=F a", "--payoff", "A=-1"],
            "--payoff:1:3: invalid payoff `-1`",
        ),
        (
            vec!["--task", "A=F a", "--payoff", "A,A=3"],
            "--payoff:1:3: `A` is listed twice",
        ),
        (
            vec![
                "--task", "A=F a", "--task", "B=F b", "--payoff", "A=200", "--payoff", "A,B=100",
            ],
            "--payoff: payoffs must be monotone: a set of sub-tasks pays at least as much as \
             each of its subsets, but r(A) = 200 > r(A,B) = 100",
        ),
        (
            vec!["--task", "A=F a", "--task", "A=F b"],
            "sub-task `A` is given twice",
        ),
        (
            vec![
                "--task",
                "A=F a",
                "--task",
                "B=F b",
                "--risk",
                "strict",
                "--export-strategy",
                "/nonexistent/s.json",
            ],
            "cannot write /nonexistent/s.json",
        ),
    ] {
        let all: Vec<&str> = args.iter().copied().chain(base).collect();
        let (code, stderr) = error(&hypersynth(&all));
        assert_eq!(code, 1, "{args:?}: {stderr}");
        assert!(
            stderr.starts_with("hypersynth: error: ") && stderr.contains(expected),
            "{args:?}: {stderr}"
        );
    }
    // Usage errors (exit 2): no belief, the paper's options mixed in, general options alone.
    for args in [
        vec!["--task", "A=F a", CASE_STUDY],
        vec![
            "--task",
            "A=F a",
            "--phi",
            "F a",
            "--believed",
            "F a",
            CASE_STUDY,
        ],
        vec![
            "--phi", "F a", "--psi", "F a", "--payoff", "A=1", CASE_STUDY,
        ],
        vec![
            "--task",
            "A=F a",
            "--believed",
            "F a",
            "--r1",
            "5",
            CASE_STUDY,
        ],
    ] {
        let (code, stderr) = error(&hypersynth(&args));
        assert_eq!(code, 2, "{args:?}: {stderr}");
    }
}

/// The worked examples: their arena (shared) is what the generator makes of its `gridworld.args`,
/// and the figures each README states are the ones the tool computes.
#[test]
fn the_worked_examples_are_regenerable_and_their_readmes_tell_the_truth() {
    let args = std::fs::read_to_string("specs/decoy/gridworld.args").unwrap();
    let mut generate = vec!["gridworld"];
    generate.extend(args.split_whitespace());
    let generated = stdout(
        &Command::cargo_bin("hypersynth")
            .unwrap()
            .args(&generate)
            .output()
            .unwrap(),
    );
    let committed = std::fs::read_to_string("specs/decoy/arena.txt").unwrap();
    assert_eq!(
        generated, committed,
        "specs/decoy/arena.txt is stale: run make decoy"
    );
    // The map the pictures are drawn from is the same arena, byte for byte.
    let from_map = stdout(
        &Command::cargo_bin("hypersynth")
            .unwrap()
            .args(["gridworld", "--map", "specs/decoy/map.txt"])
            .output()
            .unwrap(),
    );
    assert_eq!(
        from_map, committed,
        "specs/decoy/map.txt and arena.txt differ"
    );
    let value = |args: &[&str]| -> (f64, f64, String) {
        let json: serde_json::Value = serde_json::from_str(&stdout(&hypersynth(
            &[args, &["--sigma-l", "uniform", "--format", "json"]].concat(),
        )))
        .unwrap();
        let d = &json["decision"];
        (
            d["value"].as_f64().unwrap(),
            d["expected_moves"].as_f64().unwrap(),
            d["action"].as_str().unwrap_or("none").to_string(),
        )
    };
    let readme = std::fs::read_to_string("specs/decoy/README.md").unwrap();
    let decoy = |believed: &str, g: &str| {
        value(
            &[
                common::DECOY_TASKS,
                &[
                    "--believed",
                    believed,
                    "--discount",
                    g,
                    "specs/decoy/arena.txt",
                ],
            ]
            .concat(),
        )
    };
    let informed = "(!O U A) & (!O U B)";
    let rounded = |(v, m, a): (f64, f64, String)| (format!("{v:.1}"), format!("{m:.1}"), a);
    let s = |x: &str| x.to_string();
    assert_eq!(rounded(decoy("F C", "1")), (s("300.0"), s("1.8"), s("N")));
    assert_eq!(
        rounded(decoy(informed, "1")),
        (s("200.0"), s("0.0"), s("none"))
    );
    assert_eq!(
        rounded(decoy("F C", "0.95")),
        (s("274.0"), s("1.8"), s("N"))
    );
    assert_eq!(
        rounded(decoy(informed, "0.95")),
        (s("200.0"), s("0.0"), s("none"))
    );
    assert!(
        readme.contains("| value of h0 | 200 (`Win{A}` only) | **300** | 200 | **274.0** | 200 |")
    );
    let readme = std::fs::read_to_string("specs/three-tasks/README.md").unwrap();
    let three = |risk: &str, g: &str| {
        rounded(value(
            &[
                common::THREE_TASKS,
                &["--risk", risk, "--discount", g, "specs/decoy/arena.txt"],
            ]
            .concat(),
        ))
    };
    for (risk, cells) in [
        ("paper", ["500", "4.9", "389.2", "4.9"]),
        ("strict", ["498.1", "7.6", "356.6", "6.5"]),
    ] {
        let (v1, m1, _) = three(risk, "1");
        let (v2, m2, _) = three(risk, "0.95");
        let v1 = v1.trim_end_matches(".0").to_string();
        assert_eq!([v1.as_str(), &m1, &v2, &m2], cells, "{risk}");
        let row = if risk == "paper" {
            format!(
                "| paper (default) | **{}** | {} | **{}** | {} |",
                cells[0], cells[1], cells[2], cells[3]
            )
        } else {
            format!(
                "| strict | {} | {} | {} | {} |",
                cells[0], cells[1], cells[2], cells[3]
            )
        };
        assert!(readme.contains(&row), "{row}");
    }
}

//! The main form end to end on the bundled case study: games, MDP, decision table, simulation.

use assert_cmd::Command;

use crate::common::CHANCE_CYCLE;

const ARENA: &str = "specs/case-study/arena.txt";

fn main_form(extra: &[&str]) -> std::process::Output {
    Command::cargo_bin("hypersynth")
        .unwrap()
        .args([
            "--phi",
            "(!O U A) & (!O U B)",
            "--psi",
            "!O U A",
            "--translator",
            "builtin",
            ARENA,
        ])
        .args(extra)
        .output()
        .unwrap()
}

/// Runs the main form expecting a failure (exit 1, nothing on stdout) and returns its one
/// `hypersynth: error:` line.
fn failure(extra: &[&str]) -> String {
    let output = main_form(extra);
    assert_eq!(output.status.code(), Some(1));
    assert!(output.stdout.is_empty());
    let stderr = String::from_utf8(output.stderr).unwrap();
    stderr
        .lines()
        .find(|l| l.starts_with("hypersynth: error:"))
        .expect(&stderr)
        .to_string()
}

#[test]
fn discounted_case_study_prefers_north_and_reports_the_mdp_as_json() {
    let output = main_form(&[
        "--discount",
        "0.99",
        "--sigma-l",
        "uniform",
        "--format",
        "json",
    ]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    // docs/semantics.md §11: 800 x 2 x 2 product states, 1600 decision nodes, h0 is (W, L, L), N best.
    assert_eq!(json["product_states"], 3200);
    assert_eq!(json["mdp"]["robot_states"], 1600);
    assert_eq!(json["initial"]["label"], "WLL");
    assert_eq!(json["initial"]["action"], "N");
    let value = json["initial"]["value"].as_f64().unwrap();
    // Bounded by the discounted full payoff after at least one move, and above stopping now.
    assert!(value > 0.99 * 200.0 && value <= 0.99 * 300.0, "{value}");
}

#[test]
fn the_same_seed_gives_byte_identical_simulations() {
    let args = ["--simulate", "500", "--seed", "7", "--explain"];
    let first = main_form(&args);
    let second = main_form(&args);
    assert!(first.status.success());
    assert_eq!(first.stdout, second.stdout);
    let text = String::from_utf8(first.stdout).unwrap();
    assert!(
        text.contains("decision table of ((0,2),(4,2),0)|"),
        "{text}"
    );
    assert!(text.contains("simulation     500 runs, seed 7"), "{text}");
}

#[test]
fn bad_payoffs_are_rejected_in_one_line() {
    let error = failure(&["--r", "250"]);
    assert!(error.contains("250"), "{error}");
}

#[test]
fn the_iteration_limit_is_an_error_that_names_its_option() {
    let error = failure(&["--max-iterations", "3"]);
    assert!(error.contains("within 3 iterations"), "{error}");
    assert!(error.contains("raise --max-iterations (now 3)"), "{error}");
}

#[test]
fn stats_report_every_stage_and_only_when_asked() {
    let plain = main_form(&["--format", "json"]);
    let value: serde_json::Value = serde_json::from_slice(&plain.stdout).unwrap();
    assert!(value.get("timings").is_none());
    let output = main_form(&["--format", "json", "--timings"]);
    assert!(output.status.success());
    let value: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    let timings = value["timings"].as_object().expect("timings");
    let keys: Vec<&str> = timings.keys().map(String::as_str).collect();
    let mut expected = [
        "parse",
        "translate",
        "product",
        "attractors",
        "adversary",
        "mdp_build",
        "solve",
        "robust_solve",
        "policy",
        "evaluation",
        "simulation",
        "total",
    ];
    expected.sort_unstable();
    assert_eq!(keys, expected);
    let sum: f64 = timings
        .iter()
        .filter(|(k, _)| *k != "total")
        .map(|(_, v)| v.as_f64().unwrap())
        .sum();
    assert!((sum - timings["total"].as_f64().unwrap()).abs() < 1e-9);
    let text = main_form(&["--timings"]);
    let stderr = String::from_utf8(text.stderr).unwrap();
    let line = stderr
        .lines()
        .find(|l| l.starts_with("hypersynth: timings: "))
        .expect(&stderr);
    assert!(line.contains("solve ") && line.ends_with(" s"), "{line}");
}

#[test]
fn a_translation_limit_is_located_in_the_option_of_its_formula() {
    // phi2 = F(A & X^12 B) needs 2^12 + 1 states, more than 1000; it comes from --phi.
    let output = Command::cargo_bin("hypersynth")
        .unwrap()
        .args([
            "--phi",
            "(!O U A) & F(A & XXXXXXXXXXXXB)",
            "--psi",
            "!O U A",
            "--translator",
            "builtin",
            "--max-states",
            "1000",
            ARENA,
        ])
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(1));
    assert!(output.stdout.is_empty());
    let stderr = String::from_utf8_lossy(&output.stderr);
    // F(A & X^12 B) needs 2^12 + 1 states; the message goes on with how far the exploration
    // had come and what raising the limit would cost, and ends with the option.
    assert!(
        stderr.starts_with(
            "hypersynth: error: --phi: the automaton needs more than 1000 states before \
             minimisation (the state limit); it had explored "
        ),
        "{stderr}"
    );
    assert!(
        stderr.ends_with("(raise it with --max-states)\n"),
        "{stderr}"
    );
}

/// An arena with quoted names (an action with a space, a state with an escaped line break):
/// robot `r` goes north to adversary `"a\nb"`, which moves `x` to `g` (A and B) or `y` back.
fn quoted_arena(dir: &std::path::Path) -> std::path::PathBuf {
    let arena = dir.join("arena.txt");
    std::fs::write(
        &arena,
        "initial r\n\
         state r robot {}\n\
         state \"a\\nb\" adversary {}\n\
         state g robot {A B}\n\
         edge r \"go north\" \"a\\nb\"\n\
         edge \"a\\nb\" x g\n\
         edge \"a\\nb\" y r\n\
         edge g stay g\n",
    )
    .unwrap();
    arena
}

/// One name rule: names the arena format accepts (an action with a space, a state with an
/// escaped line break) go through every stage, and the DRN export keeps them on their lines.
#[test]
fn quoted_arena_names_reach_the_report_and_the_drn_export() {
    let dir = tempfile::tempdir().unwrap();
    let arena = quoted_arena(dir.path());
    let drn = dir.path().join("mdp.drn");
    let output = Command::cargo_bin("hypersynth")
        .unwrap()
        .args(["-q", "--phi", "F A & F B", "--psi", "F A", "--export-mdp"])
        .arg(&drn)
        .arg(&arena)
        .output()
        .unwrap();
    assert!(output.status.success(), "{output:?}");
    let text = std::fs::read_to_string(&drn).unwrap();
    assert!(text.contains("\taction go\\u{20}north [0]\n"), "{text}");
    // The line break in the state's name is escaped in its comment line.
    assert!(text.contains("\n// a\\nb|0|0\n"), "{text}");
}

/// A weights file with several errors: every one is printed with its line and caret, those of
/// reading first (a file that does not read is not checked against the arena), then, once it
/// reads, those of its meaning. Tabs show as one space, names as the arena format writes them.
/// Both engines print the same.
#[test]
fn every_error_of_a_weights_file_is_printed_with_its_caret() {
    let dir = tempfile::tempdir().unwrap();
    let arena = quoted_arena(dir.path());
    let weights = dir.path().join("weights.txt");
    let run = |text: &str| {
        std::fs::write(&weights, text).unwrap();
        let stderr = ["explicit", "implicit"].map(|engine| {
            let output = Command::cargo_bin("hypersynth")
                .unwrap()
                .args([
                    "-q",
                    "--phi",
                    "F A & F B",
                    "--psi",
                    "F A",
                    "--engine",
                    engine,
                ])
                .arg("--adversary")
                .arg(&weights)
                .arg(&arena)
                .output()
                .unwrap();
            assert_eq!(output.status.code(), Some(1), "{engine}");
            assert!(output.stdout.is_empty(), "{engine}");
            String::from_utf8(output.stderr).unwrap()
        });
        assert_eq!(stderr[1], stderr[0], "the implicit engine's errors");
        stderr[0].clone()
    };
    let shown = weights.display();
    assert_eq!(
        run("\"a\\nb\" x\n# a comment\n\"a\\nb\"\ty two\n"),
        format!(
            "hypersynth: error: {shown}:1:1: expected `STATE ACTION WEIGHT`, found 2 field(s)\n    \
             \"a\\nb\" x\n    ^\n\
             hypersynth: error: {shown}:3:10: invalid weight `two` (a finite number >= 0)\n    \
             \"a\\nb\" y two\n             ^\n"
        )
    );
    assert_eq!(
        run("\"a\\nb\" x 1\n\"a\\nb\" q 2\nr \"go north\" 1\n\"b\" x 1\n"),
        format!(
            "hypersynth: error: {shown}:2:8: action `q` is not enabled in adversary state \
             `\"a\\nb\"`\n    \"a\\nb\" q 2\n           ^\n\
             hypersynth: error: {shown}:3:1: `r` is a robot state; weights apply to adversary \
             states\n    r \"go north\" 1\n    ^\n\
             hypersynth: error: {shown}:4:1: no arena state is named `b`\n    \"b\" x 1\n    ^\n"
        )
    );
}

/// sigma_L from a weights file (the learnt example's, on the case study's arena and map): the
/// implicit engine's report is the explicit one's but for the line that names the engine and
/// the solver's own line.
#[test]
fn a_weights_file_gives_the_same_report_on_both_engines() {
    for arena in ["specs/case-study/arena.txt", "specs/case-study/map.txt"] {
        let [explicit, implicit] = ["explicit", "implicit"].map(|engine| {
            let output = Command::cargo_bin("hypersynth")
                .unwrap()
                .args(["--phi", "(!O U A) & (!O U B)", "--psi", "!O U A"])
                .args(["--translator", "builtin", "--discount", "0.99"])
                .args(["--adversary", "specs/learnt/truth.txt", "--engine", engine])
                .arg(arena)
                .output()
                .unwrap();
            assert!(output.status.success(), "{engine}: {output:?}");
            String::from_utf8(output.stdout).unwrap()
        });
        let (explicit, implicit): (Vec<&str>, Vec<&str>) =
            (explicit.lines().collect(), implicit.lines().collect());
        assert_eq!(explicit.len(), implicit.len(), "{arena}");
        for (e, i) in explicit.iter().zip(&implicit) {
            if e.starts_with("product ") {
                assert_eq!(
                    i.replace("implicit engine", "explicit engine"),
                    *e,
                    "{arena}"
                );
            } else if !e.starts_with("solver ") {
                assert_eq!(i, e, "{arena}");
            }
        }
        assert!(
            explicit
                .iter()
                .any(|e| e.contains("sigma_L file:specs/learnt/truth.txt"))
        );
    }
}

/// `--explain=STATE` is read like any other text: an error shows its value with a caret.
#[test]
fn a_wrong_explained_state_is_located_in_the_option_with_a_caret() {
    let output = main_form(&["-q", "--explain=((0,2),(4,2),0)|0|9"]);
    assert_eq!(output.status.code(), Some(1));
    assert_eq!(
        String::from_utf8(output.stderr).unwrap(),
        "hypersynth: error: --explain:1:19: `9` is not a state of the automaton of phi2\n    \
         ((0,2),(4,2),0)|0|9\n                      ^\n"
    );
}

/// A weights file is named after its path, `file:PATH` in the report's settings and
/// `weights from PATH` in a picture's title, in both forms.
#[test]
fn a_weights_file_is_named_by_its_path_in_reports_and_pictures() {
    let dir = tempfile::tempdir().unwrap();
    let weights = dir.path().join("weights.txt");
    std::fs::write(&weights, "# every adversary state plays uniformly\n").unwrap();
    let svg = dir.path().join("value.svg");
    let paper = ["--phi", "(!O U A) & (!O U B)", "--psi", "!O U A"];
    let general = [
        "--task",
        "A=!O U A",
        "--task",
        "B=!O U B",
        "--believed",
        "!O U A",
    ];
    for tasks in [&paper[..], &general[..]] {
        let output = Command::cargo_bin("hypersynth")
            .unwrap()
            .arg("-q")
            .args(tasks)
            .args(["specs/case-study/map.txt", "--format", "json"])
            .args(["--picture", "value", "--adversary"])
            .arg(&weights)
            .arg("--svg")
            .arg(&svg)
            .output()
            .unwrap();
        assert!(output.status.success(), "{output:?}");
        let report: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
        let path = weights.display().to_string();
        assert_eq!(report["settings"]["sigma_l"], format!("file:{path}"));
        let picture = std::fs::read_to_string(&svg).unwrap();
        assert!(
            picture.contains(&format!("σ_L weights from {path},")),
            "{picture}"
        );
    }
}

#[test]
fn a_relative_epsilon_bounds_each_value_by_its_own_size() {
    let run = |precision: &[&str]| -> serde_json::Value {
        let mut args = vec![
            "--discount",
            "0.99",
            "--sigma-l",
            "uniform",
            "--format",
            "json",
        ];
        args.extend_from_slice(precision);
        let output = main_form(&args);
        assert!(
            output.status.success(),
            "{}",
            String::from_utf8_lossy(&output.stderr)
        );
        serde_json::from_slice(&output.stdout).unwrap()
    };
    let absolute = run(&["--epsilon", "1e-6"]);
    let relative = run(&["--relative-epsilon", "1e-3"]);
    // h0 is worth about 280: a relative 1e-3 lets its bounds be about 0.28 apart, far more
    // than the absolute 1e-6, so the solver stops sooner, and within that width.
    let iterations = |json: &serde_json::Value| json["solver"]["iterations"].as_u64().unwrap();
    assert!(
        iterations(&relative) < iterations(&absolute),
        "{} {}",
        iterations(&relative),
        iterations(&absolute)
    );
    let lower = relative["initial"]["value"].as_f64().unwrap();
    let upper = relative["initial"]["value_upper"].as_f64().unwrap();
    assert!(upper - lower <= 1e-3 * lower, "[{lower}, {upper}]");
    // The two precisions exclude each other.
    let output = main_form(&["--epsilon", "1e-6", "--relative-epsilon", "1e-6"]);
    assert_eq!(output.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("cannot be used with"), "{stderr}");
}

/// The decision table of h0 on [`CHANCE_CYCLE`] with `tasks`: per next state of `a`, its name
/// and probability.
fn next_states_of_a(tasks: &[&str]) -> Vec<(String, f64)> {
    let dir = tempfile::tempdir().unwrap();
    let arena = dir.path().join("arena.txt");
    std::fs::write(&arena, CHANCE_CYCLE).unwrap();
    let output = Command::cargo_bin("hypersynth")
        .unwrap()
        .args(tasks)
        .args(["--sigma-l", "uniform", "--explain", "--format", "json"])
        .arg(&arena)
        .output()
        .unwrap();
    assert!(output.status.success(), "{output:?}");
    let report: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    let row = report["explain"]["actions"]
        .as_array()
        .unwrap()
        .iter()
        .find(|row| row["action"] == "a")
        .unwrap()
        .clone();
    row["outcomes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|o| {
            let state = o["state"].as_str().unwrap();
            let arena_state = state.split('|').next().unwrap().to_string();
            (arena_state, o["probability"].as_f64().unwrap())
        })
        .collect()
}

#[test]
fn next_robot_states_are_reached_through_cycles_of_adversary_states_exactly() {
    // psi = F A: x0 and x1 are outside Win(F A) (the adversary can avoid r1 for ever), so the
    // adversary plays sigma_W there, uniform over the moves that stay outside: x0 never plays
    // c. From x0 the walk x0 ⇄ x1 ends in r2 with probability 1.
    let next = next_states_of_a(&["--phi", "F A & F B", "--psi", "F A"]);
    assert_eq!(next.len(), 1, "{next:?}");
    assert_eq!(next[0].0, "r2");
    assert!((next[0].1 - 1.0).abs() < 1e-12, "{next:?}");
    // psi = true (its own automaton, won everywhere): the adversary plays sigma_L, uniform over
    // a, b, c. With p0, p1 the probabilities of reaching r1 first from x0, x1:
    // p0 = (p0 + p1 + 1) / 3 and p1 = (p0 + p1) / 3, so p1 = p0 / 2 and p0 = 2/3.
    let next = next_states_of_a(&["--task", "A=F A", "--task", "B=F B", "--believed", "true"]);
    let names: Vec<&str> = next.iter().map(|(s, _)| s.as_str()).collect();
    assert_eq!(names, ["r1", "r2"], "{next:?}");
    assert!((next[0].1 - 2.0 / 3.0).abs() < 1e-12, "{next:?}");
    assert!((next[1].1 - 1.0 / 3.0).abs() < 1e-12, "{next:?}");
}

#[test]
fn no_reported_interval_has_its_lower_bound_above_its_upper_bound_or_the_largest_payoff() {
    // The default case study collects its full payoff at h0: the bounds meet at 300, where
    // rounding once reported 300.0000000000001 above an upper bound of 300.
    for extra in [&[][..], &["--discount", "0.99", "--sigma-l", "uniform"][..]] {
        let output = main_form(&[&["--format", "json"][..], extra].concat());
        let report: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
        let initial = &report["initial"];
        for (lower, upper) in [
            ("value", "value_upper"),
            ("policy_value", "policy_value_upper"),
        ] {
            let (lower, upper) = (
                initial[lower].as_f64().unwrap(),
                initial[upper].as_f64().unwrap(),
            );
            assert!(
                0.0 <= lower && lower <= upper && upper <= 300.0,
                "{initial}"
            );
        }
    }
}

/// A chain that leaves a loop with probability 1e-9 per visit: the robot moves `a` into the
/// adversary's state `x` (after C: the adversary believes it has lost and plays the weights
/// file), which stays with weight 1 and goes to the goal `g` {A} with weight 1e-9. At g = 1 the
/// run reaches g with probability 1, so both the value and the controller's evaluated value are
/// r = 300 and the expected number of robot moves is 1 (by hand). Iterating the loop would
/// need about 10^10 sweeps; the evaluation, like the solver, solves small components exactly
/// (found by the pipeline fuzz target, where random weights made such a loop).
#[test]
fn a_loop_left_with_probability_1e_9_is_evaluated_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let arena = dir.path().join("arena.txt");
    std::fs::write(
        &arena,
        "initial r0\nstate r0 robot {}\nstate x adversary {C}\nstate g robot {A}\n\
         edge r0 a x\nedge x stay x\nedge x go g\nedge g stay g\n",
    )
    .unwrap();
    let weights = dir.path().join("weights.txt");
    std::fs::write(&weights, "x stay 1\nx go 1e-9\n").unwrap();
    let output = Command::cargo_bin("hypersynth")
        .unwrap()
        .args(["--phi", "F C & F A", "--psi", "F C", "--format", "json"])
        .arg("--adversary")
        .arg(&weights)
        .arg(&arena)
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    let decision = &json["initial"];
    for key in ["value", "value_upper", "policy_value", "policy_value_upper"] {
        let v = decision[key].as_f64().unwrap();
        assert!((v - 300.0).abs() <= 1e-6, "{key} = {v}");
    }
    assert_eq!(decision["action"], "a");
    assert!((decision["expected_moves"].as_f64().unwrap() - 1.0).abs() < 1e-9);
}

/// `--explain STATE` (no `=`) is refused with the reason and the command corrected, not with
/// clap's reading of STATE as the arena and the arena as a subcommand.
#[test]
fn explain_with_a_separate_state_asks_for_the_equals_sign_and_shows_the_command() {
    let state = "((1,2),(4,1),0)|0|0";
    let output = Command::cargo_bin("hypersynth")
        .unwrap()
        .args([
            "--phi",
            "!O U A",
            "--psi",
            "!O U A",
            "--explain",
            state,
            ARENA,
        ])
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(2));
    assert!(output.stdout.is_empty());
    let stderr = String::from_utf8(output.stderr).unwrap();
    assert!(
        stderr.contains("--explain takes its state after `=`"),
        "{stderr}"
    );
    assert!(!stderr.contains("subcommand"), "{stderr}");
    let corrected = format!("hypersynth --phi '!O U A' --psi '!O U A' --explain='{state}' {ARENA}");
    assert!(stderr.contains(&corrected), "{stderr}");
}

/// `--simulate 0` is refused (it used to print a mean and a confidence interval of 0).
#[test]
fn simulating_no_run_is_refused() {
    let output = main_form(&["--simulate", "0"]);
    assert_eq!(output.status.code(), Some(2));
    assert!(output.stdout.is_empty());
    let stderr = String::from_utf8(output.stderr).unwrap();
    assert!(stderr.contains("'--simulate <N>'"), "{stderr}");
}

/// A DFA of one state, one edge is said in the singular (`phi2 = true`).
#[test]
fn a_one_state_automaton_is_counted_in_the_singular() {
    let output = Command::cargo_bin("hypersynth")
        .unwrap()
        .args(["--phi", "(!O U A) & true", "--psi", "!O U A"])
        .args(["--translator", "builtin", "--games-only", ARENA])
        .output()
        .unwrap();
    assert!(output.status.success());
    let text = String::from_utf8(output.stdout).unwrap();
    assert!(text.contains("DFA: 1 state, 1 edge (builtin)"), "{text}");
    assert!(text.contains("DFA: 3 states, 5 edges (builtin)"), "{text}");
}

/// Giving only an arena names every way of giving the tasks, the general form's `--task` too.
#[test]
fn an_arena_alone_names_every_form_of_the_tasks() {
    let output = Command::cargo_bin("hypersynth")
        .unwrap()
        .arg(ARENA)
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(2));
    let stderr = String::from_utf8(output.stderr).unwrap();
    for option in ["--phi", "--phi1-hoa", "--task"] {
        assert!(stderr.contains(option), "{option}: {stderr}");
    }
}

#[test]
fn nothing_is_drawn_on_standard_error_off_a_terminal_or_with_quiet() {
    let run = |quiet: bool| {
        let mut command = Command::cargo_bin("hypersynth").unwrap();
        if quiet {
            command.arg("-q");
        }
        let output = command
            .args(["--phi", "(!O U A) & (!O U B)", "--psi", "!O U A"])
            .args(["--translator", "builtin", "--simulate", "2000"])
            .arg("specs/case-study/arena.txt")
            .output()
            .unwrap();
        assert!(output.status.success());
        String::from_utf8(output.stderr).unwrap()
    };
    assert_eq!(run(true), "");
    let stderr = run(false);
    for mark in ["[", "%", "ETA", "\r", "\u{1b}"] {
        assert!(!stderr.contains(mark), "{mark:?} in {stderr:?}");
    }
}

/// The 8x8 gridworld on which the undiscounted controller used to wander to the step bound:
/// now every simulated run ends, and the confidence interval contains the value of h0.
#[test]
fn the_undiscounted_8x8_controller_reaches_its_payoff_in_simulation() {
    let dir = tempfile::tempdir().unwrap();
    let arena = dir.path().join("grid.txt");
    assert_cmd::Command::cargo_bin("hypersynth")
        .unwrap()
        .args([
            "gridworld",
            "--size",
            "8x8",
            "--obstacle",
            "2,2",
            "3,3",
            "5,6",
            "4,1",
        ])
        .args([
            "--robot",
            "0,4",
            "--adversary",
            "7,4",
            "--label",
            "A=0,7",
            "B=7,7",
            "-o",
        ])
        .arg(&arena)
        .assert()
        .success();
    let output = assert_cmd::Command::cargo_bin("hypersynth")
        .unwrap()
        .args([
            "--phi",
            "(!O U A) & (!O U B)",
            "--psi",
            "!O U A",
            "--format",
            "json",
        ])
        .args(["--simulate", "1000"])
        .arg(&arena)
        .assert()
        .success()
        .get_output()
        .stdout
        .clone();
    let report: serde_json::Value = serde_json::from_slice(&output).unwrap();
    let simulation = &report["simulation"];
    assert_eq!(simulation["outcomes"]["step_bound"], 0, "{simulation}");
    let value = report["initial"]["value"].as_f64().unwrap();
    let (low, high) = (
        simulation["ci_low"].as_f64().unwrap(),
        simulation["ci_high"].as_f64().unwrap(),
    );
    assert!(
        low <= value + 1e-9 && value <= high + 1e-9,
        "{value} vs [{low}, {high}]"
    );
    let collected = report["initial"]["policy_value"].as_f64().unwrap();
    assert!((collected - value).abs() <= 1e-6);
    assert!(report["initial"]["expected_moves"].as_f64().unwrap() > 0.0);
}

/// `--export-mdp` streams the DRN into its file on either engine: the same bytes, a file with
/// the permissions a new file gets, nothing left beside it; a file that cannot take it
/// (`/dev/full`) is one located error (exit 1), and without the MDP stage no file is made.
#[test]
fn the_drn_is_streamed_to_its_file_by_either_engine() {
    let dir = tempfile::tempdir().unwrap();
    let mut texts = Vec::new();
    for engine in ["explicit", "implicit"] {
        let path = dir.path().join(format!("{engine}.drn"));
        let path_text = path.to_str().unwrap();
        let output = main_form(
            &["--engine", engine, "--sigma-l", "uniform"]
                .into_iter()
                .chain(["--export-mdp", path_text])
                .collect::<Vec<_>>(),
        );
        assert!(output.status.success(), "{output:?}");
        texts.push(std::fs::read_to_string(&path).unwrap());
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt as _;
            let mode = std::fs::metadata(&path).unwrap().permissions().mode() & 0o777;
            // A new file's mode: 0666 minus the umask (the tests' umask leaves owner write).
            assert_eq!(mode & 0o600, 0o600, "{mode:o}");
            assert_eq!(mode & 0o111, 0, "{mode:o}");
        }
        if std::path::Path::new("/dev/full").exists() {
            let error = failure(&["--engine", engine, "--export-mdp", "/dev/full"]);
            assert!(
                error.starts_with("hypersynth: error: cannot write /dev/full: "),
                "{error}"
            );
        }
    }
    assert!(texts[0].starts_with("// hypersynth MDP"));
    assert_eq!(texts[0], texts[1]);
    let games = dir.path().join("games.drn");
    let output = main_form(&["--games-only", "--export-mdp", games.to_str().unwrap()]);
    assert!(output.status.success());
    assert!(!games.exists());
    assert_eq!(files_in(dir.path()), ["explicit.drn", "implicit.drn"]);
}

/// `--export-strategy` streams the strategies into their file beside the DRN on either engine,
/// with either enumeration: the same strategies and DRN byte for byte and the same report but
/// for the engine's and the solver's lines. The reachable states' entries are the full
/// enumeration's (the reachable states are closed under moves, so their ranks and allowed
/// actions are the same), for fewer states; the DRN lists the reported states and the stop
/// sinks. A file that cannot take the strategies (`/dev/full`) is one error naming it, and a
/// run failing after the strategies were written leaves no file.
#[test]
fn the_strategies_are_streamed_to_their_file_by_either_engine_with_either_enumeration() {
    let dir = tempfile::tempdir().unwrap();
    let mut entries: Vec<serde_json::Value> = Vec::new();
    for states in ["full", "reachable"] {
        let mut outputs = Vec::new();
        for engine in ["explicit", "implicit"] {
            let strategy = dir.path().join(format!("{states}-{engine}.json"));
            let drn = dir.path().join(format!("{states}-{engine}.drn"));
            let output = main_form(&[
                "--engine",
                engine,
                "--states",
                states,
                "--sigma-l",
                "uniform",
                "--discount",
                "0.99",
                "--export-strategy",
                strategy.to_str().unwrap(),
                "--export-mdp",
                drn.to_str().unwrap(),
                "--format",
                "json",
            ]);
            assert!(output.status.success(), "{output:?}");
            let report: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
            outputs.push((
                std::fs::read_to_string(&strategy).unwrap(),
                std::fs::read_to_string(&drn).unwrap(),
                report,
            ));
        }
        let [(e_strategy, e_drn, e_report), (i_strategy, i_drn, i_report)] = &outputs[..] else {
            unreachable!()
        };
        assert!(e_strategy == i_strategy, "{states}: the strategies differ");
        assert!(e_drn == i_drn, "{states}: the DRNs differ");
        for key in ["product_states", "partition", "mdp"] {
            assert_eq!(i_report[key], e_report[key], "{states}: {key}");
        }
        assert_eq!(i_report["initial"]["action"], e_report["initial"]["action"]);
        assert_eq!(e_report["states"], states);
        let strategy: serde_json::Value = serde_json::from_str(i_strategy).unwrap();
        assert_eq!(strategy["states"], states);
        // The DRN's states: the product's and the paper form's three stop sinks.
        let product = e_report["product_states"].as_u64().unwrap();
        let drn_states = e_drn.lines().filter(|l| l.starts_with("state ")).count();
        assert_eq!(drn_states as u64, product + 3, "{states}");
        entries.push(strategy);
    }
    let (full, reachable) = (&entries[0], &entries[1]);
    assert_eq!(full["initial"], reachable["initial"]);
    let mut listed = 0;
    for task in ["phi1", "phi2", "phi"] {
        for player in ["robot", "adversary"] {
            let (all, some) = (
                full["tasks"][task][player].as_object().unwrap(),
                reachable["tasks"][task][player].as_object().unwrap(),
            );
            assert!(some.len() <= all.len(), "{task} {player}");
            for (state, entry) in some {
                assert_eq!(all.get(state), Some(entry), "{task} {player} {state}");
            }
            listed += some.len();
        }
        assert_eq!(
            full["tasks"][task]["realizable"],
            reachable["tasks"][task]["realizable"]
        );
    }
    assert!(listed > 0);
    if std::path::Path::new("/dev/full").exists() {
        for engine in ["explicit", "implicit"] {
            let error = failure(&["--engine", engine, "--export-strategy", "/dev/full"]);
            assert!(
                error.starts_with("hypersynth: error: cannot write /dev/full: "),
                "{error}"
            );
        }
    }
    // The implicit engine writes the strategies before its solve, which fails here.
    let failed = dir.path().join("failed.json");
    let error = failure(&[
        "--engine",
        "implicit",
        "--discount",
        "0.999",
        "--sigma-l",
        "uniform",
        "--max-iterations",
        "2",
        "--export-strategy",
        failed.to_str().unwrap(),
    ]);
    assert!(!error.is_empty());
    assert!(!failed.exists());
    // Each run's strategies and DRN, nothing else.
    let left = files_in(dir.path());
    assert_eq!(left.len(), 8, "{left:?}");
}

/// The names of the files in `dir`, sorted.
fn files_in(dir: &std::path::Path) -> Vec<String> {
    let mut names: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    names
}

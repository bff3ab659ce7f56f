//! The explorer page (`--html`) in headless Chromium, driven by `tests/browser/explorer.mjs`
//! (Playwright): what the page shows is compared with what the command line prints for the
//! same problem: the decision tables with `--explain=STATE`, the run with `--trace`, the
//! answers of the play mode with `hypersynth execute` on the exported controller; and a hostile
//! file name shows verbatim and runs nothing.
//!
//! The tests need Node.js, `npm ci` in `tests/browser` and Chromium (`$CHROMIUM`, default
//! `/usr/bin/chromium`); `.ci/run` installs them. Where one is missing, each test says so on
//! standard error and passes without checking anything.

use std::path::{Path, PathBuf};
use std::process::Command as Process;

use assert_cmd::Command;
use serde_json::Value;

use crate::common::{CASE_STUDY_TASKS, DECOY_TASKS, THREE_TASKS, execute};

const CASE_STUDY_MAP: &str = "specs/case-study/map.txt";
const DECOY_MAP: &str = "specs/decoy/map.txt";

fn browser_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/browser")
}

/// Why the browser tests cannot run here, if they cannot.
fn missing() -> Option<String> {
    let chromium = std::env::var("CHROMIUM").unwrap_or_else(|_| "/usr/bin/chromium".into());
    if !Path::new(&chromium).exists() {
        return Some(format!("no Chromium at {chromium} (set CHROMIUM)"));
    }
    let node = Process::new("node").arg("--version").output();
    if !node.is_ok_and(|output| output.status.success()) {
        return Some("no node on the PATH".to_string());
    }
    if !browser_dir().join("node_modules/playwright-core").exists() {
        return Some("no tests/browser/node_modules (run `npm ci` there)".to_string());
    }
    None
}

/// Skips the calling test (with a message) when the browser tests cannot run.
macro_rules! needs_browser {
    () => {
        if let Some(why) = missing() {
            eprintln!("skipped: {why}");
            return;
        }
    };
}

/// Runs the driver's `command` on `page` with `args`: what the page showed.
fn drive(command: &str, page: &Path, args: &[String]) -> Value {
    let output = Process::new("node")
        .arg(browser_dir().join("explorer.mjs"))
        .arg(command)
        .arg(page)
        .args(args)
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "explorer.mjs {command}: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    serde_json::from_slice(&output.stdout).unwrap()
}

/// The main form on `map` with `options`; `outputs` are further arguments (files). Its
/// standard output.
fn hypersynth(map: &str, options: &[&str], outputs: &[&std::ffi::OsStr]) -> Vec<u8> {
    let output = Command::cargo_bin("hypersynth")
        .unwrap()
        .arg("-q")
        .args(options)
        .arg(map)
        .args(outputs)
        .output()
        .unwrap();
    assert!(output.status.success(), "{output:?}");
    output.stdout
}

/// The explorer page of `map` with `options`, in `dir`.
fn page(dir: &Path, map: &str, options: &[&str]) -> PathBuf {
    let html = dir.join("page.html");
    hypersynth(map, options, &["--html".as_ref(), html.as_os_str()]);
    html
}

fn case_study() -> Vec<&'static str> {
    let mut options = CASE_STUDY_TASKS.to_vec();
    options.extend([
        "--translator",
        "builtin",
        "--discount",
        "0.99",
        "--sigma-l",
        "uniform",
    ]);
    options
}

fn three_tasks() -> Vec<&'static str> {
    let mut options = THREE_TASKS.to_vec();
    options.extend(["--sigma-l", "uniform", "--discount", "0.95"]);
    options
}

fn decoy() -> Vec<&'static str> {
    let mut options = DECOY_TASKS.to_vec();
    options.extend(["--believed", "F C", "--sigma-l", "uniform"]);
    options
}

fn strings(cells: &[&str]) -> Vec<String> {
    cells.iter().map(|c| c.to_string()).collect()
}

/// The same number exactly (JSON writes 300 for the page's and 300.0 for the report's), or
/// both absent (an infinite expected number of moves).
fn same_number(shown: &Value, expected: &Value, state: &str) {
    assert_eq!(
        shown.as_f64(),
        expected.as_f64(),
        "{state}: {shown} and {expected}"
    );
}

/// Each clicked cell's decision table is `--explain` for its state: the same actions, values,
/// expected moves, next states with their labels and probabilities, the same choice, and the
/// numbers as the text report prints them.
fn tables_match_explain(map: &str, options: &[&str], cells: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let html = page(dir.path(), map, options);
    let shown = drive("inspect", &html, &strings(cells));
    let shown = shown.as_array().unwrap();
    assert_eq!(shown.len(), cells.len());
    for clicked in shown {
        let table = &clicked["table"];
        let state = table["state"]
            .as_str()
            .unwrap_or_else(|| panic!("{clicked}"));
        let explain = format!("--explain={state}");
        let mut json = options.to_vec();
        json.extend([explain.as_str(), "--format", "json"]);
        let report: Value = serde_json::from_slice(&hypersynth(map, &json, &[])).unwrap();
        let expected = &report["explain"];
        assert_eq!(table["label"], expected["label"], "{state}");
        assert_eq!(table["value"], expected["value"], "{state}");
        assert_eq!(
            table["expected_moves"], expected["expected_moves"],
            "{state}"
        );
        assert_eq!(table["chosen"], expected["chosen"], "{state}");
        let actions = table["actions"].as_array().unwrap();
        let expected_actions = expected["actions"].as_array().unwrap();
        assert_eq!(actions.len(), expected_actions.len(), "{state}");
        for (action, wanted) in actions.iter().zip(expected_actions) {
            assert_eq!(action["action"], wanted["action"], "{state}");
            same_number(&action["value"], &wanted["value"], state);
            same_number(&action["expected_moves"], &wanted["expected_moves"], state);
            let outcomes = action["outcomes"].as_array().unwrap();
            let wanted = wanted["outcomes"].as_array().unwrap();
            assert_eq!(outcomes.len(), wanted.len(), "{state}");
            for (outcome, wanted) in outcomes.iter().zip(wanted) {
                assert_eq!(outcome["state"], wanted["state"], "{state}");
                assert_eq!(outcome["label"], wanted["label"], "{state}");
                same_number(&outcome["probability"], &wanted["probability"], state);
                same_number(&outcome["value"], &wanted["value"], state);
            }
        }
        // The numbers as printed: each next state's line of the text report.
        let mut text_options = options.to_vec();
        text_options.push(explain.as_str());
        let text = String::from_utf8(hypersynth(map, &text_options, &[])).unwrap();
        for action in actions {
            for outcome in action["outcomes"].as_array().unwrap() {
                let printed = format!(
                    "p = {}  value {}",
                    outcome["shown"][0].as_str().unwrap(),
                    outcome["shown"][1].as_str().unwrap()
                );
                assert!(text.contains(&printed), "{state}: {printed} not in\n{text}");
            }
        }
    }
}

#[test]
fn decision_tables_are_those_of_explain() {
    needs_browser!();
    // h0's cell, a cell next to the adversary, and one from which A is in reach.
    tables_match_explain(CASE_STUDY_MAP, &case_study(), &["0,2", "3,2", "1,3", "2,0"]);
    tables_match_explain(DECOY_MAP, &three_tasks(), &["0,2", "2,2", "2,1"]);
}

/// The run player's steps are `--trace`'s, forward and back.
fn run_matches_trace(map: &str, options: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let html = page(dir.path(), map, options);
    let shown = drive("run", &html, &[]);
    let mut json = options.to_vec();
    json.extend(["--trace", "--format", "json"]);
    let report: Value = serde_json::from_slice(&hypersynth(map, &json, &[])).unwrap();
    let expected = report["trace"]["steps"].as_array().unwrap();
    let steps = shown["steps"].as_array().unwrap();
    assert_eq!(steps.len(), expected.len());
    for (k, (step, wanted)) in steps.iter().zip(expected).enumerate() {
        assert_eq!(step["step"], k);
        assert_eq!(step["state"], wanted["state"], "step {k}");
        assert_eq!(step["label"], wanted["label"], "step {k}");
        // The page writes `-` where the report has no action or set.
        let text = |value: &Value| match value.as_str() {
            None | Some("") => "-".to_string(),
            Some(text) => text.to_string(),
        };
        assert_eq!(text(&step["action"]), text(&wanted["action"]), "step {k}");
        assert_eq!(
            text(&step["committed"]),
            text(&wanted["committed"]),
            "step {k}"
        );
        // The robot is drawn on its cell of the state.
        assert!(step["robot"].is_object(), "step {k}: no robot drawn");
    }
    assert_eq!(shown["back"], 0);
}

#[test]
fn the_run_player_steps_through_trace() {
    needs_browser!();
    run_matches_trace(CASE_STUDY_MAP, &case_study());
    run_matches_trace(DECOY_MAP, &three_tasks());
}

/// Playing the adversary by clicking `clicks`: the page's answers are those of `hypersynth
/// execute` on the exported controller, fed the same states, and so are its warnings (an
/// adversary's move the model gives probability 0).
fn play_matches_execute(map: &str, options: &[&str], clicks: &[&str], at_least: usize) {
    let dir = tempfile::tempdir().unwrap();
    let html = page(dir.path(), map, options);
    let controller = dir.path().join("controller.json");
    hypersynth(
        map,
        options,
        &["--export-controller".as_ref(), controller.as_os_str()],
    );
    let shown = drive("play", &html, &strings(clicks));
    let log = shown["log"].as_array().unwrap();
    let play: String = log
        .iter()
        .map(|row| format!("{}\n", row["state"].as_str().unwrap()))
        .collect();
    let answers: Vec<String> = log
        .iter()
        .map(|row| row["answer"].as_str().unwrap().to_string())
        .filter(|answer| !answer.is_empty())
        .collect();
    assert!(
        shown["clicked"].as_array().unwrap().len() >= at_least,
        "the play stopped early: {shown}"
    );
    let output = execute(&controller, &play);
    assert!(output.status.success(), "{output:?}");
    let expected: Vec<String> = String::from_utf8(output.stdout)
        .unwrap()
        .lines()
        .map(str::to_string)
        .collect();
    let warnings = String::from_utf8(output.stderr).unwrap();
    assert_eq!(answers, expected, "{shown}");
    let shown_warnings: Vec<&str> = log
        .iter()
        .filter_map(|row| row["warning"].as_str())
        .collect();
    assert_eq!(
        shown_warnings.len(),
        warnings.lines().count(),
        "{shown}\n{warnings}"
    );
    for warning in shown_warnings {
        assert!(warnings.contains(warning), "{warning} not in {warnings}");
    }
}

#[test]
fn playing_the_adversary_gets_the_executors_answers() {
    needs_browser!();
    // The adversary walks west along y = 2 and 1, then north.
    play_matches_execute(
        CASE_STUDY_MAP,
        &case_study(),
        &["4,1", "3,1", "2,1", "2,2", "2,3"],
        3,
    );
    play_matches_execute(DECOY_MAP, &decoy(), &["4,1", "3,1", "3,2", "2,2"], 3);
}

#[test]
fn a_hostile_file_name_shows_verbatim_and_runs_nothing() {
    needs_browser!();
    let dir = tempfile::tempdir().unwrap();
    let parent = dir.path().join("<script>window.injected=1<");
    std::fs::create_dir(&parent).unwrap();
    let map = parent.join("script><img src=x onerror=\"window.injected=2\">'&amp;.txt");
    std::fs::copy(CASE_STUDY_MAP, &map).unwrap();
    let name = map.to_str().unwrap();
    let html = page(dir.path(), name, &case_study());
    let shown = drive("open", &html, &[]);
    assert_eq!(shown["heading"], name);
    assert_eq!(shown["title"], format!("Explorer: {name}"));
    assert_eq!(shown["injected"], Value::Null, "{shown}");
    assert_eq!(shown["scripts"], 2);
    assert_eq!(shown["dialogs"], serde_json::json!([]));
    assert_eq!(shown["errors"], serde_json::json!([]));
    assert_eq!(shown["requests"], serde_json::json!([]));
}

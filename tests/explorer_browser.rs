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
    drive_in_window(command, page, args, 1500)
}

/// [`drive`] in a window `width` pixels wide.
fn drive_in_window(command: &str, page: &Path, args: &[String], width: u32) -> Value {
    let output = Process::new("node")
        .env("VIEWPORT_WIDTH", width.to_string())
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

/// A box `[left, top, right, bottom]` of the driver's.
fn boxed(value: &Value) -> [f64; 4] {
    let v: Vec<f64> = value
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    [v[0], v[1], v[2], v[3]]
}

/// Whether two boxes share an area (touching edges do not).
fn meet(a: [f64; 4], b: [f64; 4]) -> bool {
    a[0] < b[2] && b[0] < a[2] && a[1] < b[3] && b[1] < a[3]
}

/// The layout invariant of the static pictures (render/figure.rs `overlaps`) on the page's
/// board: no text box (a cell's code or value, a proposition) meets a mark (the controller's,
/// a player) or another text, in both fills, in h0's slice and after each "visit"; and the
/// decision table fits a 1 280 pixel window with no state name wrapped.
#[test]
fn the_boards_texts_meet_no_mark_and_the_decision_table_fits_the_window() {
    needs_browser!();
    for (map, options, cell) in [
        (CASE_STUDY_MAP, case_study(), "1,2"),
        (DECOY_MAP, decoy(), "1,2"),
        (DECOY_MAP, three_tasks(), "2,3"),
    ] {
        let dir = tempfile::tempdir().unwrap();
        let html = page(dir.path(), map, &options);
        let shown = drive_in_window("geometry", &html, &strings(&[cell]), 1280);
        assert_eq!(shown["errors"], Value::Array(Vec::new()), "{map}");
        for view in shown["views"].as_array().unwrap() {
            let at = format!("{map} {} {}", view["shading"], view["slice"]);
            let texts: Vec<(&str, [f64; 4])> = view["texts"]
                .as_array()
                .unwrap()
                .iter()
                .map(|t| (t["text"].as_str().unwrap(), boxed(&t["box"])))
                .collect();
            let marks: Vec<[f64; 4]> = view["marks"]
                .as_array()
                .unwrap()
                .iter()
                .map(boxed)
                .collect();
            assert!(texts.len() > 10 && marks.len() > 10, "{at}");
            for (i, &(text, b)) in texts.iter().enumerate() {
                for &m in &marks {
                    assert!(!meet(b, m), "{at}: `{text}` {b:?} meets a mark {m:?}");
                }
                for &(other, c) in &texts[i + 1..] {
                    assert!(!meet(b, c), "{at}: `{text}` {b:?} meets `{other}` {c:?}");
                }
            }
        }
        let table = &shown["table"];
        let window = table["window"].as_f64().unwrap();
        assert!(table["right"].as_f64().unwrap() <= window, "{map}: {table}");
        assert!(
            table["scrollWidth"].as_f64().unwrap() <= window,
            "{map}: {table}"
        );
        assert_eq!(table["wrapped"], Value::Array(Vec::new()), "{map}");
    }
}

/// The value fill spans the positive values of the slice shown, as the static value picture's
/// scale does, with its colour bar: the lowest value shown gets the bar's bottom colour, the
/// highest its top, and the bar's end ticks are those values (a fixed 0 to payoff scale made the
/// case study's 290 to 300 look alike). Goal cells whose automata in the slice would already
/// have moved on (the robot on A with q1 = 0) are hatched: in h0's slice both goal cells, after
/// "visit A" only B's, after "visit B" only A's.
#[test]
fn the_value_fill_spans_the_slice_and_impossible_goal_cells_are_hatched() {
    needs_browser!();
    let dir = tempfile::tempdir().unwrap();
    let html = page(dir.path(), CASE_STUDY_MAP, &case_study());
    let shown = drive_in_window("geometry", &html, &strings(&["1,2"]), 1280);
    let views = shown["views"].as_array().unwrap();
    for view in views.iter().filter(|v| v["shading"] == "values") {
        let at = view["slice"].to_string();
        // Each robot cell's value, from its tooltip (`..., value 294.02`), and its fill.
        let valued: Vec<(f64, &str)> = view["cells"]
            .as_array()
            .unwrap()
            .iter()
            .filter_map(|c| {
                let title = c["title"].as_str().unwrap();
                let value: f64 = title
                    .split(", value ")
                    .nth(1)?
                    .split(' ')
                    .next()?
                    .parse()
                    .ok()?;
                (value > 0.0).then(|| (value, c["fill"].as_str().unwrap()))
            })
            .collect();
        let lo = valued.iter().map(|v| v.0).fold(f64::INFINITY, f64::min);
        let hi = valued.iter().map(|v| v.0).fold(f64::NEG_INFINITY, f64::max);
        assert!(hi > lo, "{at}");
        let bar: Vec<&str> = view["bar"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c.as_str().unwrap())
            .collect();
        for &(value, fill) in &valued {
            if value == lo {
                assert_eq!(fill, bar[0], "{at}: {value}");
            }
            if value == hi {
                assert_eq!(fill, *bar.last().unwrap(), "{at}: {value}");
            }
        }
        let ticks: Vec<f64> = view["ticks"]
            .as_array()
            .unwrap()
            .iter()
            .map(|t| t.as_str().unwrap().parse().unwrap())
            .collect();
        assert!(
            (ticks[0] - hi).abs() <= 0.5 && (ticks[2] - lo).abs() <= 0.5,
            "{at}: {ticks:?}"
        );
    }
    let hatched = |visited: Value| -> Vec<Value> {
        let view = views
            .iter()
            .find(|v| v["shading"] == "labels" && v["visited"] == visited)
            .unwrap();
        view["hatched"].as_array().unwrap().clone()
    };
    let (a, b) = (serde_json::json!([0, 3]), serde_json::json!([4, 4]));
    assert_eq!(hatched(Value::Null), [a.clone(), b.clone()]);
    assert_eq!(hatched("visit A".into()), [b]);
    assert_eq!(hatched("visit B".into()), [a]);
}

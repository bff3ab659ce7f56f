//! sigma_L learnt from observations (`--observations`, `--delta`): robust and nominal values
//! against hand computations, the robust controller's guarantee on the case study, runs
//! recorded by `--simulate --record`, and located errors for bad observation files.

use crate::common::drn::Drn;
use crate::common::run_hypersynth;
use hypersynth::testing::RETRY_ARENA;

const CASE_STUDY: &str = "specs/case-study/arena.txt";

fn files(observations: &str) -> (tempfile::TempDir, String, String) {
    let dir = tempfile::tempdir().unwrap();
    let arena = dir.path().join("arena.txt");
    let runs = dir.path().join("runs.txt");
    std::fs::write(&arena, RETRY_ARENA).unwrap();
    std::fs::write(&runs, observations).unwrap();
    let path = |p: std::path::PathBuf| p.to_str().unwrap().to_string();
    (dir, path(arena), path(runs))
}

/// The JSON report's `robust` object for the retry arena with these runs and extra options.
fn robust(observations: &str, extra: &[&str]) -> serde_json::Value {
    let (_dir, arena, runs) = files(observations);
    let args = [&["--observations", &runs][..], extra].concat();
    retry_report(&arena, &args)["robust"].clone()
}

/// The JSON report of the retry arena `arena` with extra options.
fn retry_report(arena: &str, extra: &[&str]) -> serde_json::Value {
    let args = [
        &["--task", "A=F A", "--payoff", "A=100", "--believed", "F C"][..],
        extra,
        &["--format", "json", arena],
    ]
    .concat();
    let output = run_hypersynth(&args);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    serde_json::from_slice(&output.stdout).unwrap()
}

fn retry_runs(hits: usize, misses: usize) -> String {
    "r go a x g\n".repeat(hits) + &"r go a y b back r go a x g\n".repeat(misses)
}

fn close(value: &serde_json::Value, expected: f64) {
    let value = value.as_f64().unwrap();
    assert!((value - expected).abs() < 1e-5, "{value} vs {expected}");
}

#[test]
fn robust_and_nominal_values_are_the_hand_computed_ones() {
    // 40 runs: `a` seen 50 times, x 40 times: p_hat = 0.8, K = 2 pairs, n = 50:
    // e = sqrt(ln(2 * 2 / 0.05) / 100) = sqrt(4.382027 / 100) = 0.209333, so x gets
    // [0.590667, 1]. With g = 0.9, V = 0.9 (100 p + (1 - p) 0.9 V), i.e.
    // V = 90 p / (1 - 0.81 (1 - p)), least at the least p: robust 53.160038 / 0.668440 =
    // 79.528471; nominal (p = 0.8) 72 / 0.838 = 85.918854.
    let r = robust(&retry_runs(30, 10), &["--discount", "0.9"]);
    assert_eq!(r["runs"], 40);
    assert_eq!(r["counted"], 50);
    assert_eq!(r["pairs"], 2);
    assert_eq!(r["never_observed"], 0);
    close(&r["value"], 79.528471);
    close(&r["nominal_value"], 85.918854);
    close(&r["choices"][0]["robust"], 79.528471);
    close(&r["choices"][0]["nominal"], 85.918854);
    // The robust controller's chain against the worst-case reply collects V.
    close(&r["worst_case_value"], 79.528471);
    assert_eq!(r["action"], "go");
}

#[test]
fn at_g_1_a_lower_bound_of_0_lets_the_adversary_refuse_forever() {
    // Undiscounted, the robot retries until x comes: worth 100 whenever x's lower bound is
    // positive (50 observations as above), but worth 0 when the interval starts at 0 (one
    // observation: e = sqrt(ln 80 / 2) > 1, so [0, 1]), though the estimate (x always) is 100.
    let r = robust(&retry_runs(30, 10), &[]);
    close(&r["value"], 100.0);
    let r = robust(&retry_runs(1, 0), &[]);
    close(&r["value"], 0.0);
    close(&r["value_upper"], 0.0);
    close(&r["nominal_value"], 100.0);
}

#[test]
fn a_smaller_delta_widens_the_region() {
    // delta = 0.001: e = sqrt(ln(4000) / 100) = sqrt(8.294050 / 100) = 0.287994, so
    // p = 0.512006 and V = 46.080540 / 0.605285 = 76.130...
    let r = robust(
        &retry_runs(30, 10),
        &["--discount", "0.9", "--delta", "0.001"],
    );
    let p: f64 = 0.8 - 0.287994;
    close(&r["value"], 90.0 * p / (1.0 - 0.81 * (1.0 - p)));
    assert!(r["value"].as_f64().unwrap() < 79.528471);
}

#[test]
fn bad_observation_files_get_located_errors() {
    let cases = [
        (
            "r go a x g\nr go\n",
            "2:3: a run alternates states and actions",
        ),
        ("r go a x q\n", "1:10: no arena state is named `q`"),
        (
            "r go a z g\n",
            "1:8: action `z` is not enabled in state `a`",
        ),
        ("r go a x b\n", "1:10: `a` `x` leads to `g`, not to `b`"),
        (
            "a x g\n",
            "1:1: a run starts at the initial state `r`, not at `a`",
        ),
        ("r go \"a\n", "1:6:"),
    ];
    for (text, expected) in cases {
        let (_dir, arena, runs) = files(text);
        let output = run_hypersynth(&[
            "--task",
            "A=F A",
            "--payoff",
            "A=100",
            "--believed",
            "F C",
            "--observations",
            &runs,
            &arena,
        ]);
        assert!(!output.status.success(), "{text:?}");
        assert!(output.stdout.is_empty(), "{text:?}: partial output");
        let stderr = String::from_utf8(output.stderr).unwrap();
        let located = format!("hypersynth: error: {runs}:{expected}");
        assert!(stderr.starts_with(&located), "{text:?}: {stderr}");
    }
    // A delta outside (0, 1).
    let (_dir, arena, runs) = files("r\n");
    let output = run_hypersynth(&[
        "--task",
        "A=F A",
        "--payoff",
        "A=100",
        "--believed",
        "F C",
        "--observations",
        &runs,
        "--delta",
        "1.5",
        &arena,
    ]);
    let stderr = String::from_utf8(output.stderr).unwrap();
    assert!(stderr.contains("--delta"), "{stderr}");
}

#[test]
fn on_the_case_study_recorded_runs_give_a_robust_value_the_true_adversary_honours() {
    let dir = tempfile::tempdir().unwrap();
    let runs = dir.path().join("runs.txt");
    let runs = runs.to_str().unwrap();
    let paper = [
        "--phi",
        "(!O U A) & (!O U B)",
        "--psi",
        "!O U A",
        "--discount",
        "0.99",
    ];
    // 300 runs of the controller against seeded random weights (the "truth").
    let output = run_hypersynth(
        &[
            &paper[..],
            &["--simulate", "300", "--record", runs, CASE_STUDY],
        ]
        .concat(),
    );
    assert!(output.status.success());
    let text = std::fs::read_to_string(runs).unwrap();
    assert_eq!(text.lines().count(), 300);
    assert!(text.starts_with("\"((0,2),(4,2),0)\" "));
    let output = run_hypersynth(
        &[
            &paper[..],
            &[
                "--observations",
                runs,
                "--simulate",
                "2000",
                "--format",
                "json",
            ],
            &[CASE_STUDY],
        ]
        .concat(),
    );
    assert!(output.status.success());
    let report: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    let r = &report["robust"];
    let (value, nominal) = (
        r["value"].as_f64().unwrap(),
        r["nominal_value"].as_f64().unwrap(),
    );
    assert!(
        0.0 < value && value <= nominal + 1e-6,
        "{value} > {nominal}"
    );
    assert!(r["worst_case_value"].as_f64().unwrap() >= value - 1e-6);
    assert_eq!(r["runs"], 300);
    // The guarantee: against the true adversary the robust controller collects at least V
    // (its simulated mean's confidence interval reaches V or above).
    assert!(r["simulation"]["ci_high"].as_f64().unwrap() >= value, "{r}");
    // Every robust choice value is at most its nominal one.
    for row in r["choices"].as_array().unwrap() {
        assert!(row["robust"].as_f64().unwrap() <= row["nominal"].as_f64().unwrap() + 1e-6);
    }
}

/// The retry arena with `--export-mdp` in `form`: the report and Storm's value of the written
/// model at its initial state (by the test's own reader and value iteration).
fn exported(observations: Option<&str>, form: &str, extra: &[&str]) -> (serde_json::Value, f64) {
    let (dir, arena, runs) = files(observations.unwrap_or(""));
    let model = dir.path().join("model.drn");
    let model = model.to_str().unwrap();
    let mut args = vec!["--export-mdp", model, "--drn-form", form];
    if observations.is_some() {
        args.extend(["--observations", &runs]);
    }
    args.extend(extra);
    let report = retry_report(&arena, &args);
    let text = std::fs::read_to_string(model).unwrap();
    assert_eq!(
        text.contains("@value_type: double-interval"),
        observations.is_some()
    );
    (report, Drn::parse(&text).initial_value())
}

#[test]
fn both_drn_forms_have_the_hand_computed_values_nominal_and_robust() {
    // Nominal, sigma_L uniform: p = 1/2, V = 90 p / (1 - 0.81 (1 - p)) = 45 / 0.595 at
    // g = 0.9, and 100 at g = 1 (the robot retries until x comes).
    let uniform = ["--sigma-l", "uniform"];
    for (g, expected) in [("0.9", 45.0 / 0.595), ("1", 100.0)] {
        for form in ["reward", "reachability"] {
            let extra = [&uniform[..], &["--discount", g]].concat();
            let (report, storm) = exported(None, form, &extra);
            assert!((storm - expected).abs() < 1e-6, "{form} g={g}: {storm}");
            close(&report["decision"]["value"], expected);
        }
    }
    // Robust, the region of 40 runs: 79.528471 at g = 0.9 (see above), 100 at g = 1; one
    // run gives x the interval [0, 1] and the value 0 at g = 1, which the reachability form's
    // value, from below, finds too.
    let cases = [
        (retry_runs(30, 10), "0.9", 79.528471),
        (retry_runs(30, 10), "1", 100.0),
        (retry_runs(1, 0), "1", 0.0),
    ];
    for (runs, g, expected) in cases {
        for form in ["reward", "reachability"] {
            let (report, storm) = exported(Some(&runs), form, &["--discount", g]);
            assert!((storm - expected).abs() < 1e-5, "{form} g={g}: {storm}");
            close(&report["robust"]["value"], expected);
        }
    }
}

//! The learning curve (`--learning-curve`, `--learning-curve-png`, `--learning-curve-runs`):
//! each point equals a separate run of the main form on the file's first runs (`head -n k`),
//! the picture has no overlapping text, and bad requests get clean errors and no file.

use crate::common::{self, run_hypersynth};

use hypersynth::render::figure;

const CASE_STUDY: &str = "specs/case-study/arena.txt";
const DISCOUNT: [&str; 2] = ["--discount", "0.99"];

/// `runs` runs on the case study recorded against seeded random weights, in `dir`.
fn recorded(dir: &std::path::Path, runs: u32) -> String {
    let path = dir.join("runs.txt").to_str().unwrap().to_string();
    let count = runs.to_string();
    let output = run_hypersynth(
        &[
            common::CASE_STUDY_TASKS,
            &DISCOUNT,
            &["--simulate", &count, "--record", &path, CASE_STUDY],
        ]
        .concat(),
    );
    assert!(output.status.success());
    path
}

/// The JSON report of the case study learnt from `observations`, with `extra` options.
fn report(observations: &str, extra: &[&str]) -> serde_json::Value {
    let output = run_hypersynth(
        &[
            common::CASE_STUDY_TASKS,
            &DISCOUNT,
            &["--observations", observations, "--format", "json"],
            extra,
            &[CASE_STUDY],
        ]
        .concat(),
    );
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{stderr}");
    serde_json::from_slice(&output.stdout).unwrap()
}

#[test]
fn every_point_is_the_main_form_on_the_first_runs_of_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let runs = recorded(dir.path(), 40);
    let text = std::fs::read_to_string(&runs).unwrap();
    let curve = report(&runs, &["--learning-curve-runs", "1,3,12,40"]);
    let points = curve["robust"]["learning_curve"].as_array().unwrap();
    assert_eq!(points.len(), 4);
    for (point, k) in points.iter().zip([1, 3, 12, 40]) {
        // `head -n k`: one run per line, no comments in a recorded file.
        let head: String = text.lines().take(k).map(|l| format!("{l}\n")).collect();
        let prefix = dir.path().join(format!("head-{k}.txt"));
        std::fs::write(&prefix, head).unwrap();
        let alone = report(prefix.to_str().unwrap(), &[]);
        let alone = &alone["robust"];
        assert_eq!(point["runs"], k, "{point}");
        for key in [
            "counted",
            "never_observed",
            "value",
            "value_upper",
            "nominal_value",
            "nominal_value_upper",
        ] {
            assert_eq!(point[key], alone[key], "{key} after {k} runs");
        }
    }
    // The last point uses every run: the report's own figures.
    let last = points.last().unwrap();
    assert_eq!(last["value"], curve["robust"]["value"]);
    assert_eq!(last["counted"], curve["robust"]["counted"]);
}

#[test]
fn by_default_the_curve_takes_one_two_five_runs_and_all_and_the_text_report_tabulates_it() {
    let dir = tempfile::tempdir().unwrap();
    let runs = recorded(dir.path(), 12);
    let svg = dir.path().join("curve.svg");
    let output = run_hypersynth(
        &[
            common::CASE_STUDY_TASKS,
            &DISCOUNT,
            &["--observations", &runs, CASE_STUDY],
            &["--learning-curve", svg.to_str().unwrap()],
        ]
        .concat(),
    );
    assert!(output.status.success());
    let text = String::from_utf8(output.stdout).unwrap();
    let table: Vec<u32> = text
        .lines()
        .skip_while(|l| !l.starts_with("learning curve"))
        .skip(2)
        .map_while(|l| l.split_whitespace().next()?.parse().ok())
        .collect();
    assert_eq!(table, [1, 2, 5, 10, 12], "{text}");
    // One format per column: the values with four decimals each (not `200`, `294.03` and
    // `205.999877` in one column).
    let rows = text
        .lines()
        .skip_while(|l| !l.starts_with("learning curve"))
        .skip(2)
        .take(table.len());
    for row in rows {
        for value in row.split_whitespace().skip(3) {
            let decimals = value.split_once('.').map(|(_, d)| d);
            assert!(
                decimals.is_some_and(|d| d.len() == 4 && d.bytes().all(|b| b.is_ascii_digit())),
                "{value} in {row:?}"
            );
        }
    }
    assert!(std::fs::read_to_string(&svg).unwrap().starts_with("<svg"));
}

/// Every text, line and mark of a drawn curve apart, also with crowded run counts (labels of
/// neighbouring ticks left out rather than overlapping) and without a title.
#[test]
fn the_curve_has_no_overlaps() {
    let dir = tempfile::tempdir().unwrap();
    let runs = recorded(dir.path(), 30);
    for (k, extra) in [
        &["--learning-curve-runs", "1,2,3,4,5,6,7,8,9,10,11,20,29,30"][..],
        &["--no-title"],
        &["--title", "Fig. 4\\nsecond line"],
    ]
    .into_iter()
    .enumerate()
    {
        let svg = dir.path().join(format!("curve-{k}.svg"));
        let svg_path = svg.to_str().unwrap();
        report(
            &runs,
            &[&["--learning-curve", svg_path][..], extra].concat(),
        );
        let items = figure::read(&std::fs::read_to_string(&svg).unwrap()).unwrap();
        let texts = items
            .iter()
            .filter(|i| i.role == figure::Role::Text)
            .count();
        assert!(texts > 10, "{texts} texts");
        assert_eq!(figure::overlaps(&items), Vec::<String>::new(), "{extra:?}");
    }
}

#[test]
fn bad_curve_requests_get_clean_errors_and_no_file() {
    let dir = tempfile::tempdir().unwrap();
    let runs = recorded(dir.path(), 5);
    let svg = dir.path().join("curve.svg");
    let png = dir.path().join("curve.png");
    let svg_path = svg.to_str().unwrap();
    let run = |extra: &[&str]| {
        run_hypersynth(&[common::CASE_STUDY_TASKS, &DISCOUNT, extra, &[CASE_STUDY]].concat())
    };
    let stderr =
        |output: &std::process::Output| String::from_utf8_lossy(&output.stderr).to_string();
    // No observations: a usage error naming the missing option.
    let output = run(&["--learning-curve", svg_path]);
    assert_eq!(output.status.code(), Some(2));
    assert!(
        stderr(&output).contains("--observations"),
        "{}",
        stderr(&output)
    );
    // More runs than the file has: one located message, no picture.
    let output = run(&[
        "--observations",
        &runs,
        "--learning-curve",
        svg_path,
        "--learning-curve-png",
        png.to_str().unwrap(),
        "--learning-curve-runs",
        "2,6",
    ]);
    assert_eq!(output.status.code(), Some(1));
    assert_eq!(
        stderr(&output),
        format!(
            "hypersynth: error: --learning-curve-runs: a learning curve point uses the first 6 \
             runs, but the observations have 5 (a point uses 1 to 5) in {runs}\n"
        )
    );
    // Not a list of increasing positive numbers: usage errors.
    for bad in ["0,3", "3,2", "1,x", ""] {
        let output = run(&["--observations", &runs, "--learning-curve-runs", bad]);
        assert_eq!(output.status.code(), Some(2), "{bad}");
        assert!(stderr(&output).contains("--learning-curve-runs"), "{bad}");
    }
    // A file without runs: nothing to draw.
    let empty = dir.path().join("empty.txt");
    std::fs::write(&empty, "# no run yet\n").unwrap();
    let empty = empty.to_str().unwrap();
    let output = run(&["--observations", empty, "--learning-curve", svg_path]);
    assert_eq!(output.status.code(), Some(1));
    assert_eq!(
        stderr(&output),
        format!(
            "hypersynth: error: {empty}: a learning curve needs observed runs, and the \
             observations have none\n"
        )
    );
    // With --games-only there is nothing to learn: an error, no picture.
    let output = run(&[
        "--observations",
        &runs,
        "--games-only",
        "--learning-curve",
        svg_path,
    ]);
    assert_eq!(output.status.code(), Some(1));
    assert!(
        stderr(&output).contains("drop --games-only"),
        "{}",
        stderr(&output)
    );
    assert!(!svg.exists() && !png.exists());
}

/// specs/learnt (`make learnt`) is current: the truth is the weighting its README states, on
/// every move of every adversary state of the case study, and the runs, report and curve are
/// what the Makefile's commands give now.
#[test]
fn the_worked_example_is_current() {
    let arena = std::fs::read_to_string(CASE_STUDY).unwrap();
    let expected: Vec<String> = arena
        .lines()
        .filter_map(|l| {
            let fields: Vec<&str> = l.split_whitespace().collect();
            (fields.first() == Some(&"edge") && fields[1].ends_with(",1)\"")).then(|| {
                let weight = match fields[2] {
                    "STAY" => 6,
                    "S" => 3,
                    _ => 1,
                };
                format!("{} {} {weight}", fields[1], fields[2])
            })
        })
        .collect();
    let truth = std::fs::read_to_string("specs/learnt/truth.txt").unwrap();
    assert_eq!(truth.lines().collect::<Vec<_>>(), expected);
    let stale = "specs/learnt is stale: run make learnt";
    let dir = tempfile::tempdir().unwrap();
    let options = [
        common::CASE_STUDY_TASKS,
        &DISCOUNT,
        &["--adversary", "specs/learnt/truth.txt"],
    ]
    .concat();
    let runs = dir.path().join("runs.txt");
    let output = run_hypersynth(
        &[
            &options[..],
            &["--seed", "1", "--simulate", "1000"],
            &["--record", runs.to_str().unwrap(), CASE_STUDY],
        ]
        .concat(),
    );
    assert!(output.status.success());
    let committed = |name: &str| std::fs::read_to_string(format!("specs/learnt/{name}")).unwrap();
    assert!(
        std::fs::read_to_string(&runs).unwrap() == committed("runs.txt"),
        "{stale}"
    );
    let (report, svg) = (dir.path().join("report.txt"), dir.path().join("curve.svg"));
    let output = run_hypersynth(
        &[
            &options[..],
            &[
                "--observations",
                "specs/learnt/runs.txt",
                "--simulate",
                "10000",
            ],
            &["--explain", "--learning-curve", svg.to_str().unwrap()],
            &[CASE_STUDY, "-o", report.to_str().unwrap()],
        ]
        .concat(),
    );
    assert!(output.status.success());
    assert_eq!(
        std::fs::read_to_string(&report).unwrap(),
        committed("report.txt"),
        "{stale}"
    );
    assert_eq!(
        std::fs::read_to_string(&svg).unwrap(),
        committed("curve.svg"),
        "{stale}"
    );
}

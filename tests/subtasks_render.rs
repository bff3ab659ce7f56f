//! Pictures of the general form (`--svg` with `--task`): the partition of the worked examples'
//! map, parsed and rasterised in process (resvg). Every free cell but the adversary's has one
//! robot cell; its colour and code agree with labels computed here from the strategy export
//! (which lists `Win(T)` state by state) and the report's payoffs, not from the renderer: the
//! fill is the documented colour of the best set the robot can force (by the tasks it holds),
//! the code the maximal winnable sets and whether psi is winnable.

use crate::common;

use assert_cmd::Command;
use resvg::{tiny_skia, usvg};
use serde_json::Value;

const MAP: &str = "specs/decoy/map.txt";

/// The colours docs/guide.md documents for the sets of the first three tasks, indexed by the set
/// as a mask (bit i: the i-th task); index 0, nothing, is the colour of guarantee 0.
const SET_COLOURS: [[u8; 3]; 8] = [
    [0xD5, 0x5E, 0x00],
    [0xF0, 0xE4, 0x42],
    [0xCC, 0x79, 0xA7],
    [0x00, 0x9E, 0x73],
    [0xE6, 0x9F, 0x00],
    [0x00, 0x72, 0xB2],
    [0xBB, 0xBB, 0xBB],
    [0x99, 0x99, 0x33],
];

/// The free cells of a map, read from its grid rows (north first).
fn free_cells(map: &str) -> Vec<(u32, u32)> {
    let rows: Vec<Vec<&str>> = map
        .lines()
        .skip_while(|line| line.trim() != "grid")
        .skip(1)
        .map(|line| line.split('#').next().unwrap().split_whitespace().collect())
        .filter(|row: &Vec<&str>| !row.is_empty())
        .collect();
    let height = rows.len() as u32;
    let mut cells = Vec::new();
    for (r, row) in rows.iter().enumerate() {
        for (x, cell) in row.iter().enumerate() {
            if *cell != "O" {
                cells.push((x as u32, height - 1 - r as u32));
            }
        }
    }
    cells
}

/// Runs the general form on the map with `tasks`, drawing the partition and exporting the
/// strategies; returns the JSON report, the export and the SVG.
fn run(tasks: &[&str]) -> (Value, Value, String) {
    let dir = tempfile::tempdir().unwrap();
    let (svg, export) = (dir.path().join("p.svg"), dir.path().join("s.json"));
    let output = Command::cargo_bin("hypersynth")
        .unwrap()
        .arg("-q")
        .args(tasks)
        .args(["--sigma-l", "uniform", "--format", "json", MAP, "--svg"])
        .arg(&svg)
        .arg("--export-strategy")
        .arg(&export)
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    (
        serde_json::from_slice(&output.stdout).unwrap(),
        serde_json::from_str(&std::fs::read_to_string(&export).unwrap()).unwrap(),
        std::fs::read_to_string(&svg).unwrap(),
    )
}

/// Checks every robot cell of the partition against the labels derived from the export.
fn check_partition(report: &Value, export: &Value, svg: &str) -> Vec<String> {
    // Well-formed: usvg parses it; rasterised to sample the fills.
    let tree = usvg::Tree::from_str(svg, &usvg::Options::default()).unwrap();
    let size = tree.size().to_int_size();
    let mut pixmap = tiny_skia::Pixmap::new(size.width(), size.height()).unwrap();
    resvg::render(&tree, tiny_skia::Transform::default(), &mut pixmap.as_mut());
    let pixel = |x: f64, y: f64| {
        let p = pixmap.pixel(x.round() as u32, y.round() as u32).unwrap();
        [p.red(), p.green(), p.blue()]
    };

    // One cell per free cell of the map but the adversary's (collisions are forbidden).
    let map = std::fs::read_to_string(MAP).unwrap();
    let mut free = free_cells(&map);
    assert_eq!(free.len(), 20);
    free.retain(|&cell| cell != (4, 2));
    let cells = common::svg_cells(svg);
    let mut drawn: Vec<(u32, u32)> = cells.iter().map(|cell| cell.cell).collect();
    drawn.sort();
    free.sort();
    assert_eq!(drawn, free);

    // The sets, their payoffs and the classes of distinct positive payoffs, largest first.
    let names: Vec<String> = report["tasks"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t["name"].as_str().unwrap().to_string())
        .collect();
    let sets: Vec<(Vec<String>, f64)> = report["payoffs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            let set = p["set"].as_array().unwrap();
            let set = set
                .iter()
                .map(|n| n.as_str().unwrap().to_string())
                .collect();
            (set, p["payoff"].as_f64().unwrap())
        })
        .collect();
    assert!(names.len() <= 3);
    let key = |set: &[String]| set.join(",");
    let wins =
        |set: &[String], state: &str| export["tasks"][key(set)]["robot"].get(state).is_some();
    let believed = &export["believed"];
    let psi_wins = |state: &str| match believed["tasks"].as_array() {
        Some(set) => {
            let set: Vec<String> = set.iter().map(|n| n.as_str().unwrap().into()).collect();
            wins(&set, state)
        }
        None => believed["robot"].get(state).is_some(),
    };

    // The automata's states of h0: the suffix of its name.
    let h0 = report["initial"]["state"].as_str().unwrap();
    let suffix = &h0[h0.find('|').unwrap()..];
    let single = names.iter().all(|n| n.len() == 1);
    let mut codes = Vec::new();
    for common::SvgCell {
        cell: (x, y),
        square: (left, top, side),
        code,
    } in &cells
    {
        let state = format!("(({x},{y}),(4,2),0){suffix}");
        let won: Vec<&(Vec<String>, f64)> = sets.iter().filter(|(s, _)| wins(s, &state)).collect();
        // In the report's order of sets (mask order), as the code lists them.
        let maximal: Vec<String> = won
            .iter()
            .filter(|(s, _)| {
                !won.iter()
                    .any(|(t, _)| t.len() > s.len() && s.iter().all(|n| t.contains(n)))
            })
            .map(|(s, _)| s.join(if single { "" } else { "," }))
            .collect();
        let psi = if psi_wins(&state) { "W" } else { "L" };
        let expected_code = if maximal.is_empty() {
            format!("-|{psi}")
        } else {
            format!("{}|{psi}", maximal.join(" "))
        };
        assert_eq!(code.as_deref(), Some(&*expected_code), "cell ({x},{y})");
        // The set of the largest payoff (no two of the examples' sets pay the same).
        let best = won
            .iter()
            .filter(|(_, p)| *p > 0.0)
            .max_by(|a, b| a.1.total_cmp(&b.1));
        let mask = best.map_or(0, |(set, _)| {
            set.iter()
                .map(|n| 1 << names.iter().position(|m| m == n).unwrap())
                .sum::<usize>()
        });
        // Left of the controller's mark, between the cell's text bands.
        let sample = (left + 5.0, top + side / 2.0);
        assert_eq!(
            pixel(sample.0, sample.1),
            SET_COLOURS[mask],
            "cell ({x},{y}): {expected_code}, best {best:?}"
        );
        codes.push(expected_code);
    }
    codes.sort();
    codes.dedup();
    codes
}

#[test]
fn the_decoy_partition_agrees_with_the_exported_regions() {
    let (report, export, svg) = run(&[common::DECOY_TASKS, &["--believed", "F C"]].concat());
    let codes = check_partition(&report, &export, &svg);
    assert!(codes.len() >= 3, "only codes {codes:?}: a weak check");
    // The legend names the sets some cell settles for, with their payoffs.
    assert!(svg.contains(">{A,B}: 300</text>") && svg.contains(">{A}: 200</text>"));
    assert!(svg.contains(">nothing: 0</text>"));
}

#[test]
fn the_three_tasks_partition_agrees_with_the_exported_regions() {
    let (report, export, svg) = run(common::THREE_TASKS);
    let codes = check_partition(&report, &export, &svg);
    assert!(codes.len() >= 4, "only codes {codes:?}: a weak check");
}

#[test]
fn every_general_picture_is_written_and_refusals_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let tasks = [
        "--task",
        "A=!O U A",
        "--task",
        "B=!O U B",
        "--believed",
        "F C",
    ];
    let main_form = |input: &str, extra: &[&str], svg: &std::path::Path| {
        Command::cargo_bin("hypersynth")
            .unwrap()
            .arg("-q")
            .args(tasks)
            .arg(input)
            .args(extra)
            .arg("--svg")
            .arg(svg)
            .assert()
    };
    for picture in ["map", "partition", "value", "trace"] {
        let svg = dir.path().join(format!("{picture}.svg"));
        main_form(MAP, &["--picture", picture], &svg).success();
        let text = std::fs::read_to_string(&svg).unwrap();
        usvg::Tree::from_str(&text, &usvg::Options::default()).unwrap();
        // The title names the sub-tasks and the belief.
        assert!(
            text.contains(">Tasks A: ¬O U A, B: ¬O U B;  believed ψ = FC</text>"),
            "{picture}"
        );
    }
    let trace = std::fs::read_to_string(dir.path().join("trace.svg")).unwrap();
    assert!(trace.contains("<title>step 0</title>") && trace.contains("risk paper"));
    // psi has its own automaton here, so the slice names three automata.
    let partition = std::fs::read_to_string(dir.path().join("partition.svg")).unwrap();
    assert!(partition.contains("automata as in h0: q_A = 0, q_B = 0, q_psi = 0"));
    let svg = dir.path().join("out.svg");
    for (input, extra, message) in [
        (
            "specs/decoy/arena.txt",
            &[][..],
            "specs/decoy/arena.txt: --svg: a picture needs a map",
        ),
        (
            MAP,
            &["--automata", "0,0"],
            "the product has 3 automata (A, B, psi), so a picture needs 3 automaton states, \
             not 2",
        ),
        (
            MAP,
            &["--games-only", "--picture", "value"],
            "need the opportunistic stage",
        ),
    ] {
        main_form(input, extra, &svg)
            .code(1)
            .stdout("")
            .stderr(predicates::str::contains(message));
        assert!(!svg.exists(), "{extra:?}");
    }
}

#[test]
fn the_committed_example_pictures_are_current() {
    // The Makefile's `decoy` and `three-tasks` options for each picture.
    let decoy = [common::DECOY_TASKS, &["--sigma-l", "uniform", "--explain"]].concat();
    let three = [common::THREE_TASKS, &["--sigma-l", "uniform", "--explain"]].concat();
    let informed = "(!O U A) & (!O U B)";
    let cases: [(&str, Vec<&str>); 7] = [
        (
            "specs/decoy/map.svg",
            [
                &decoy[..],
                &["--believed", "F C", "--games-only", "--picture", "map"],
            ]
            .concat(),
        ),
        (
            "specs/decoy/partition-decoy.svg",
            [&decoy[..], &["--believed", "F C", "--picture", "partition"]].concat(),
        ),
        (
            "specs/decoy/partition-informed.svg",
            [
                &decoy[..],
                &["--believed", informed, "--picture", "partition"],
            ]
            .concat(),
        ),
        (
            "specs/decoy/trace-decoy.svg",
            [&decoy[..], &["--believed", "F C", "--picture", "trace"]].concat(),
        ),
        (
            "specs/three-tasks/partition.svg",
            [&three[..], &["--picture", "partition"]].concat(),
        ),
        (
            "specs/three-tasks/trace.svg",
            [&three[..], &["--picture", "trace"]].concat(),
        ),
        (
            "specs/three-tasks/value-g0.95.svg",
            [&three[..], &["--discount", "0.95", "--picture", "value"]].concat(),
        ),
    ];
    let dir = tempfile::tempdir().unwrap();
    let svg = dir.path().join("p.svg");
    for (committed, args) in cases {
        Command::cargo_bin("hypersynth")
            .unwrap()
            .arg("-q")
            .args(&args)
            .arg(MAP)
            .arg("--svg")
            .arg(&svg)
            .assert()
            .success();
        assert!(
            std::fs::read(&svg).unwrap() == std::fs::read(committed).unwrap(),
            "{committed} is stale: run `make decoy three-tasks`"
        );
    }
}

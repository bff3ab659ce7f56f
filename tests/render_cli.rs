//! `--svg` on the main form: each picture is written, titles are readable and can be replaced
//! or left out, and every refusal leaves no file.

use assert_cmd::Command;
use predicates::prelude::*;

const TASKS: [&str; 6] = [
    "--phi",
    "(!O U A) & (!O U B)",
    "--psi",
    "!O U A",
    "--translator",
    "builtin",
];

fn main_form(input: &str, extra: &[&str], svg: &std::path::Path) -> assert_cmd::assert::Assert {
    Command::cargo_bin("hypersynth")
        .unwrap()
        .args(TASKS)
        .arg(input)
        .args(extra)
        .arg("--svg")
        .arg(svg)
        .assert()
}

#[test]
fn every_picture_is_written_whole() {
    let dir = tempfile::tempdir().unwrap();
    for picture in ["map", "partition", "value", "trace"] {
        let svg = dir.path().join(format!("{picture}.svg"));
        main_form("specs/case-study/map.txt", &["--picture", picture], &svg).success();
        let text = std::fs::read_to_string(&svg).unwrap();
        assert!(
            text.starts_with("<svg ") && text.ends_with("</svg>\n"),
            "{picture}"
        );
        // The title carries the formulas, with logical symbols, and no file path.
        assert!(
            text.contains(">φ = ¬O U A ∧ ¬O U B,  ψ = φ₁ = ¬O U A,  φ₂ = ¬O U B</text>"),
            "{picture}"
        );
        assert!(!text.contains("map.txt"), "{picture}");
    }
    let trace = std::fs::read_to_string(dir.path().join("trace.svg")).unwrap();
    assert!(trace.contains("<title>step 0</title>"));
    // The partition without the MDP stage has no controller marks: no arrows, rings, squares.
    let svg = dir.path().join("games.svg");
    main_form("specs/case-study/map.txt", &["--games-only"], &svg).success();
    let games = std::fs::read_to_string(&svg).unwrap();
    let partition = std::fs::read_to_string(dir.path().join("partition.svg")).unwrap();
    let marks = |text: &str| text.matches("class=\"mark\"").count();
    // One or more items per robot cell, and the legend's four.
    assert!(marks(&partition) > 19 + 4 && marks(&games) == 0);
    let legend = "Controller in each robot cell";
    assert!(partition.contains(legend) && !games.contains(legend));
}

#[test]
fn refusals_name_the_reason_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let svg = dir.path().join("out.svg");
    let cases: [(&str, &[&str], &str); 6] = [
        (
            "specs/case-study/arena.txt",
            &[],
            "specs/case-study/arena.txt: --svg: a picture needs a map",
        ),
        (
            "specs/case-study/map.txt",
            &["--games-only", "--picture", "trace"],
            "need the opportunistic stage",
        ),
        (
            "specs/case-study/map.txt",
            &["--adversary-at", "0,1"],
            "error: --adversary-at: the adversary's cell (0,1) is not a free cell of the map",
        ),
        (
            "specs/case-study/map.txt",
            &["--automata", "0,7"],
            "error: --automata: 7 is not an enumerated state of the automaton of phi2 (those are: 0 2)",
        ),
        (
            "specs/case-study/map.txt",
            &["--automata", "0,0,0"],
            "error: --automata: the product has 2 automata (phi1, phi2), so a picture needs 2 automaton \
             states",
        ),
        (
            "specs/case-study/map.txt",
            &["--discount", "2"],
            "--discount",
        ),
    ];
    for (input, extra, message) in cases {
        main_form(input, extra, &svg)
            .code(1)
            .stdout("")
            .stderr(predicate::str::contains(message));
        assert!(!svg.exists(), "{extra:?}");
    }
}

#[test]
fn the_committed_case_study_pictures_are_current() {
    // The Makefile's `case-study` options for each picture.
    let dir = tempfile::tempdir().unwrap();
    let discounted = ["--discount", "0.99", "--sigma-l", "uniform"];
    for (picture, extra) in [
        ("map", &["--games-only"][..]),
        ("partition", &discounted[..]),
        ("trace", &discounted[..]),
    ] {
        let svg = dir.path().join(format!("{picture}.svg"));
        let args = [extra, &["--picture", picture]].concat();
        main_form("specs/case-study/map.txt", &args, &svg).success();
        let committed = format!("specs/case-study/{picture}.svg");
        assert!(
            std::fs::read(&svg).unwrap() == std::fs::read(&committed).unwrap(),
            "{committed} is stale: run `make case-study`"
        );
    }
}

#[test]
fn a_title_can_be_replaced_or_left_out() {
    let dir = tempfile::tempdir().unwrap();
    let svg = dir.path().join("map.svg");
    let draw = |extra: &[&str]| {
        let args = [&["--games-only", "--picture", "map"], extra].concat();
        main_form("specs/case-study/map.txt", &args, &svg).success();
        std::fs::read_to_string(&svg).unwrap()
    };
    let default = draw(&[]);
    assert!(default.contains(">Map, 5 × 5 cells</text>"));
    let custom = draw(&["--title", "Fig. 2: the case study\\nR2D2 and IDroid"]);
    assert!(custom.contains(">Fig. 2: the case study</text>"));
    assert!(custom.contains(">R2D2 and IDroid</text>"));
    assert!(!custom.contains(">Map, 5 × 5 cells</text>"));
    let untitled = draw(&["--no-title"]);
    assert!(!untitled.contains(">Map, 5 × 5 cells</text>"));
    // The description stays the accessible name, whatever is shown.
    for text in [&default, &custom, &untitled] {
        assert!(text.contains("<title>Map, 5 × 5 cells. φ = ¬O U A ∧ ¬O U B"));
    }
    // Without a title the picture is shorter by the title's lines.
    let height = |text: &str| -> f64 {
        let start = text.find(" height=\"").unwrap() + 9;
        text[start..start + text[start..].find('"').unwrap()]
            .parse()
            .unwrap()
    };
    assert!(height(&untitled) < height(&default) - 30.0);
    Command::cargo_bin("hypersynth")
        .unwrap()
        .args(TASKS)
        .args(["specs/case-study/map.txt", "--svg"])
        .arg(&svg)
        .args(["--title", "x", "--no-title"])
        .assert()
        .code(2);
}

#[test]
fn picture_options_need_svg() {
    Command::cargo_bin("hypersynth")
        .unwrap()
        .args(TASKS)
        .args(["specs/case-study/map.txt", "--picture", "trace"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("--svg"));
}

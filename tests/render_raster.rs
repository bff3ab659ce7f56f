//! The case study's partition picture, rasterised in process (resvg): the colour at the centre
//! of every robot cell is that of its win-label, read from the strategy export of the games
//! stage, and h0's cell carries an arrow in the direction of the chosen first action.

use crate::common;

use assert_cmd::Command;
use resvg::{tiny_skia, usvg};
use serde_json::Value;

const MAP: &str = "specs/case-study/map.txt";

/// The Okabe–Ito colours docs/guide.md documents for each win-label.
fn documented_colour(label: &str) -> [u8; 3] {
    match label {
        "WWW" => [0x00, 0x9E, 0x73],
        "WWL" => [0x56, 0xB4, 0xE9],
        "WLL" => [0xF0, 0xE4, 0x42],
        "LWL" => [0xCC, 0x79, 0xA7],
        "LLL" => [0xD5, 0x5E, 0x00],
        other => panic!("unexpected label {other}"),
    }
}

#[test]
fn partition_colours_and_the_first_arrow_match_the_games_and_mdp_stages() {
    let dir = tempfile::tempdir().unwrap();
    let (svg_path, strategies) = (dir.path().join("p.svg"), dir.path().join("s.json"));
    let output = Command::cargo_bin("hypersynth")
        .unwrap()
        .args(["--phi", "(!O U A) & (!O U B)", "--psi", "!O U A", MAP])
        .args([
            "--translator",
            "builtin",
            "--discount",
            "0.99",
            "--sigma-l",
            "uniform",
        ])
        .args(["--format", "json", "--svg"])
        .arg(&svg_path)
        .arg("--export-strategy")
        .arg(&strategies)
        .output()
        .unwrap();
    assert!(output.status.success());
    let report: Value = serde_json::from_slice(&output.stdout).unwrap();
    let first_action = report["initial"]["action"].as_str().unwrap().to_string();
    let h0 = report["initial"]["state"].as_str().unwrap().to_string();
    assert_eq!(h0, "((0,2),(4,2),0)|0|0");
    let export: Value =
        serde_json::from_str(&std::fs::read_to_string(&strategies).unwrap()).unwrap();
    let wins = |task: &str, state: &str| export["tasks"][task]["robot"].get(state).is_some();

    let svg = std::fs::read_to_string(&svg_path).unwrap();
    let tree = usvg::Tree::from_str(&svg, &usvg::Options::default()).unwrap();
    let size = tree.size().to_int_size();
    let mut pixmap = tiny_skia::Pixmap::new(size.width(), size.height()).unwrap();
    resvg::render(&tree, tiny_skia::Transform::default(), &mut pixmap.as_mut());
    let pixel = |x: f64, y: f64| {
        let p = pixmap.pixel(x.round() as u32, y.round() as u32).unwrap();
        [p.red(), p.green(), p.blue()]
    };

    let cells = common::svg_cells(&svg);
    // The 20 free cells but the adversary's (4,2).
    assert_eq!(cells.len(), 19);
    let centre = |cell: (u32, u32)| {
        let (left, top, side) = cells.iter().find(|c| c.cell == cell).unwrap().square;
        (left + side / 2.0, top + side / 2.0, side)
    };
    // Left of the controller's mark, between the cell's text bands: the fill.
    let fill_at = |cell: (u32, u32)| {
        let (x, y, side) = centre(cell);
        (x - side / 2.0 + 5.0, y)
    };
    // North up, east right.
    assert!(centre((0, 4)).1 < centre((0, 2)).1 && centre((0, 2)).0 < centre((3, 2)).0);
    let mut seen = Vec::new();
    for &common::SvgCell { cell: (x, y), .. } in &cells {
        let state = format!("(({x},{y}),(4,2),0)|0|0");
        let label: String = ["phi1", "phi2", "phi"]
            .iter()
            .map(|task| if wins(task, &state) { 'W' } else { 'L' })
            .collect();
        let (fx, fy) = fill_at((x, y));
        assert_eq!(
            pixel(fx, fy),
            documented_colour(&label),
            "cell ({x},{y}) {label}"
        );
        seen.push(label);
    }
    seen.sort();
    seen.dedup();
    assert!(seen.len() >= 3, "only labels {seen:?}: a weak check");

    // h0's arrow (through the centre): black along the chosen action's direction, the cell's
    // colour elsewhere.
    let (cx, cy, side) = centre((0, 2));
    let (fx, fy) = fill_at((0, 2));
    let background = pixel(fx, fy);
    let directions = [
        ("N", (0.0, -1.0)),
        ("S", (0.0, 1.0)),
        ("E", (1.0, 0.0)),
        ("W", (-1.0, 0.0)),
        ("NE", (1.0, -1.0)),
        ("NW", (-1.0, -1.0)),
        ("SE", (1.0, 1.0)),
        ("SW", (-1.0, 1.0)),
    ];
    assert!(directions.iter().any(|(name, _)| *name == first_action));
    for (name, (dx, dy)) in directions {
        let norm = f64::hypot(dx, dy);
        let at = |distance: f64| {
            pixel(
                cx + dx / norm * side * distance,
                cy + dy / norm * side * distance,
            )
        };
        if name == first_action {
            for distance in [0.05, 0.12, 0.2] {
                assert_eq!(at(distance), [0, 0, 0], "no arrow {name} at {distance}");
            }
        } else {
            assert_eq!(at(0.2), background, "a stray mark towards {name}");
        }
    }
}

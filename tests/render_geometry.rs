//! Nothing overlaps in a picture the command draws: no text's box meets another text, a line, a
//! controller's mark or a marker (except the marker it is written in, which must hold it), and no
//! mark or marker meets another. Checked on every kind of picture of a 16x16 and a 24x24 map,
//! each read back from its SVG (`render::figure::read`: every element carries its role; a text
//! its exact width as `textLength`); the committed pictures in specs/ are checked by the
//! library's `tests/render/geometry.rs`.

use crate::common;

use assert_cmd::Command;
use hypersynth::render::figure::{self, Shape};
use hypersynth::testing::picture_overlaps;

/// A map of `side` × `side` cells whose free cells are the rows `y` divisible by `every` and
/// the first and last columns (few enough for the MDP stage to be quick), with A top left, B
/// bottom right, C in the middle of a row, the robot bottom left and the adversary top right.
fn comb_map(side: u32, every: u32) -> String {
    let mut text = String::from("hypersynth map v1\ngrid\n");
    for y in (0..side).rev() {
        let row: Vec<String> = (0..side)
            .map(|x| {
                let free = y % every == 0 || y == side - 1 || x == 0 || x == side - 1;
                let token = match (x, y) {
                    (0, 0) => "@r",
                    (0, y) if y == side - 1 => "A",
                    (x, y) if x == side - 1 && y == side - 1 => "@a",
                    (x, 0) if x == side - 1 => "B",
                    (x, y) if x == side / 2 && y == every => "C",
                    _ if free => ".",
                    _ => "O",
                };
                format!("{token:<2}")
            })
            .collect();
        text += &row.join(" ");
        text.push('\n');
    }
    text
}

#[test]
fn no_picture_of_a_16x16_or_24x24_map_has_overlaps() {
    let dir = tempfile::tempdir().unwrap();
    let (paper, three) = (common::CASE_STUDY_TASKS, common::THREE_TASKS);
    for (side, every) in [(16, 5), (24, 8)] {
        let map = dir.path().join(format!("m{side}.txt"));
        std::fs::write(&map, comb_map(side, every)).unwrap();
        // Discounted, with a uniform sigma_L: the MDP stage's quickest settings.
        let mdp = ["--discount", "0.95", "--sigma-l", "uniform", "--picture"];
        let runs: Vec<(&str, Vec<&str>)> = vec![
            (
                "map",
                [paper, &["--games-only", "--picture", "map"]].concat(),
            ),
            ("games", [paper, &["--games-only"]].concat()),
            ("general", [three, &["--games-only"]].concat()),
            ("partition", [paper, &mdp, &["partition"]].concat()),
            ("value", [paper, &mdp, &["value"]].concat()),
            ("trace", [paper, &mdp, &["trace"]].concat()),
        ];
        for (name, args) in runs {
            let svg = dir.path().join(format!("{name}{side}.svg"));
            Command::cargo_bin("hypersynth")
                .unwrap()
                .args(["-q", "--translator", "builtin"])
                .args(&args)
                .arg(&map)
                .arg("--svg")
                .arg(&svg)
                .assert()
                .success();
            let text = std::fs::read_to_string(&svg).unwrap();
            let overlaps = picture_overlaps(&text, &svg.display().to_string());
            assert_eq!(overlaps, Vec::<String>::new(), "{name} {side}");
            // The grid is the map's: as many cells across as it has columns.
            let labels = figure::read(&text)
                .unwrap()
                .into_iter()
                .filter(|i| {
                    matches!(&i.shape, Shape::Text { text, size, .. }
                        if *size == 11.0 && text == &(side - 1).to_string())
                })
                .count();
            assert_eq!(labels, 2, "{name} {side}: the last coordinate on both axes");
        }
    }
}

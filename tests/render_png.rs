//! `--png`: pictures rasterised at print resolution with the bundled font, the same bytes on
//! every run (the library's table of that font's metrics is checked against the font file by the
//! library's `tests/render/font.rs`).

use crate::common;

use assert_cmd::Command;
use predicates::prelude::*;

const MAP: &str = "specs/case-study/map.txt";

/// The chunks of a PNG file: (type, data).
fn chunks(png: &[u8]) -> Vec<(String, Vec<u8>)> {
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    let mut out = Vec::new();
    let mut at = 8;
    while at + 8 <= png.len() {
        let length = u32::from_be_bytes(png[at..at + 4].try_into().unwrap()) as usize;
        let kind = String::from_utf8_lossy(&png[at + 4..at + 8]).to_string();
        out.push((kind, png[at + 8..at + 8 + length].to_vec()));
        at += 12 + length;
    }
    out
}

fn u32_at(data: &[u8], at: usize) -> u32 {
    u32::from_be_bytes(data[at..at + 4].try_into().unwrap())
}

#[test]
fn a_png_is_the_svg_at_print_resolution_with_the_bundled_font() {
    let dir = tempfile::tempdir().unwrap();
    let (svg, png) = (dir.path().join("p.svg"), dir.path().join("p.png"));
    let draw = |png: &std::path::Path, dpi: &str| {
        Command::cargo_bin("hypersynth")
            .unwrap()
            .args(common::CASE_STUDY_TASKS)
            .args(["--translator", "builtin"])
            .args([MAP, "--games-only", "--picture", "map", "--svg"])
            .arg(&svg)
            .arg("--png")
            .arg(png)
            .args(["--dpi", dpi])
            .assert()
            .success();
        std::fs::read(png).unwrap()
    };
    let bytes = draw(&png, "300");
    // The SVG's size in pixels of 1/96 inch, at 300 dots per inch.
    let text = std::fs::read_to_string(&svg).unwrap();
    let attribute = |name: &str| -> f64 {
        let start = text.find(&format!(" {name}=\"")).unwrap() + name.len() + 3;
        text[start..start + text[start..].find('"').unwrap()]
            .parse()
            .unwrap()
    };
    let (width, height) = (attribute("width"), attribute("height"));
    let chunks = chunks(&bytes);
    let header = &chunks.iter().find(|(k, _)| k == "IHDR").unwrap().1;
    let scale = 300.0 / 96.0;
    assert_eq!(f64::from(u32_at(header, 0)), (width * scale).round());
    assert_eq!(f64::from(u32_at(header, 4)), (height * scale).round());
    // The physical size: 300 dpi is 11811 dots per metre, in both directions.
    let physical = &chunks.iter().find(|(k, _)| k == "pHYs").unwrap().1;
    assert_eq!(
        (u32_at(physical, 0), u32_at(physical, 4), physical[8]),
        (11811, 11811, 1)
    );
    // The same bytes again.
    assert!(draw(&dir.path().join("again.png"), "300") == bytes);

    // Decoded at 96 dpi, pixel for pixel the SVG's layout: the robot's marker is blue at its
    // centre, and the title line is written (dark pixels in its band).
    let small = draw(&dir.path().join("small.png"), "96");
    let decoder = png::Decoder::new(std::io::Cursor::new(small));
    let mut reader = decoder.read_info().unwrap();
    let mut pixels = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut pixels).unwrap();
    let pixel = |x: u32, y: u32| {
        let at = ((y * info.width + x) * 4) as usize;
        [pixels[at], pixels[at + 1], pixels[at + 2]]
    };
    let cells = hypersynth::render::figure::read(&text).unwrap();
    let robot = cells
        .iter()
        .find_map(|item| match &item.shape {
            hypersynth::render::figure::Shape::Circle { centre, .. }
                if item.fill.as_deref() == Some("#0072B2") =>
            {
                Some(*centre)
            }
            _ => None,
        })
        .unwrap();
    assert_eq!(pixel(robot.0 as u32, robot.1 as u32), [0x00, 0x72, 0xB2]);
    let dark = (16..400)
        .flat_map(|x| (16..34).map(move |y| (x, y)))
        .filter(|&(x, y)| pixel(x, y).iter().all(|&c| c < 96))
        .count();
    assert!(dark > 200, "only {dark} dark pixels in the title");
}

#[test]
fn png_options_are_checked() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("p.png");
    let run = |extra: &[&str]| {
        Command::cargo_bin("hypersynth")
            .unwrap()
            .args(common::CASE_STUDY_TASKS)
            .args(["--translator", "builtin"])
            .args([MAP, "--games-only"])
            .args(extra)
            .assert()
    };
    let path = png.to_str().unwrap();
    run(&["--png", path, "--dpi", "50"])
        .code(2)
        .stderr(predicate::str::contains("--dpi"));
    run(&["--dpi", "300"])
        .code(2)
        .stderr(predicate::str::contains("--png"));
    run(&["--picture", "map"])
        .code(2)
        .stderr(predicate::str::contains("--svg").and(predicate::str::contains("--png")));
    assert!(!png.exists());
    // A text arena cannot be drawn: no file.
    Command::cargo_bin("hypersynth")
        .unwrap()
        .args(common::CASE_STUDY_TASKS)
        .args(["--translator", "builtin"])
        .args(["specs/case-study/arena.txt", "--games-only", "--png", path])
        .assert()
        .code(1);
    assert!(!png.exists());
}

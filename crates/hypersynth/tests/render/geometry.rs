//! Nothing overlaps in a committed picture: no text's box meets another text, a line, a
//! controller's mark or a marker (except the marker it is written in, which must hold it), and no
//! mark or marker meets another. Checked on every picture in specs/, read back from its SVG
//! (`render::figure::read`: every element carries its role; a text its exact width as
//! `textLength`); the pictures the command draws of larger maps are the command's
//! `tests/render_geometry.rs`.

use std::path::PathBuf;

use hypersynth::testing::picture_overlaps;

/// Every SVG under specs/.
fn committed_pictures() -> Vec<PathBuf> {
    let mut found = Vec::new();
    let mut dirs = vec![PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../specs"
    ))];
    while let Some(dir) = dirs.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                dirs.push(path);
            } else if path.extension().is_some_and(|e| e == "svg") {
                found.push(path);
            }
        }
    }
    found.sort();
    found
}

#[test]
fn no_committed_picture_has_overlaps() {
    let pictures = committed_pictures();
    // case-study: map, partition, trace; decoy: map, two partitions, trace; three-tasks:
    // partition, trace, value; learnt: the learning curve.
    assert_eq!(pictures.len(), 11, "{pictures:?}");
    for path in pictures {
        let svg = std::fs::read_to_string(&path).unwrap();
        assert_eq!(
            picture_overlaps(&svg, &path.display().to_string()),
            Vec::<String>::new(),
            "{}",
            path.display()
        );
    }
}

//! `--html FILE` without a browser: the page is written whole and self-contained, user text
//! reaches it only escaped, and every refusal leaves no file. The page's behaviour in a browser
//! is tested in `explorer_browser`.

use assert_cmd::Command;
use predicates::prelude::*;

use crate::common::CASE_STUDY_TASKS;
use hypersynth::testing::explorer_data;

/// The case study's map, solved with the pictures' settings.
const SETTINGS: &[&str] = &["--translator", "builtin", "--discount", "0.99"];

fn page(map: &std::path::Path, html: &std::path::Path, extra: &[&str]) -> Command {
    let mut command = Command::cargo_bin("hypersynth").unwrap();
    command
        .args(CASE_STUDY_TASKS)
        .args(SETTINGS)
        .args(extra)
        .arg(map)
        .arg("--html")
        .arg(html);
    command
}

#[test]
fn the_page_is_one_self_contained_file() {
    let dir = tempfile::tempdir().unwrap();
    let html = dir.path().join("page.html");
    page("specs/case-study/map.txt".as_ref(), &html, &[])
        .assert()
        .success();
    let text = std::fs::read_to_string(&html).unwrap();
    assert!(text.starts_with("<!DOCTYPE html>"), "{}", &text[..40]);
    assert!(text.trim_end().ends_with("</html>"));
    // Its own script and its data, nothing loaded from elsewhere: no source, link or URL.
    assert_eq!(text.matches("<script").count(), 2);
    // The SVG namespace, in the markup and the script, is a name, not an address.
    let without_namespace = text.replace("http://www.w3.org/2000/svg", "");
    for outside in [
        "src=", "href=", "http:", "https:", "<link", "@import", "url(",
    ] {
        assert!(!without_namespace.contains(outside), "{outside}");
    }
    // The Content-Security-Policy forbids every network access and any other script.
    assert!(text.contains("default-src 'none'; script-src 'sha256-"));
}

#[test]
fn a_hostile_file_name_reaches_the_page_escaped() {
    let dir = tempfile::tempdir().unwrap();
    // `</script>` needs a slash: the name's first part is a directory.
    let parent = dir.path().join("<script>window.injected=1<");
    std::fs::create_dir(&parent).unwrap();
    let map = parent.join("script>'\"&amp;.txt");
    std::fs::copy("specs/case-study/map.txt", &map).unwrap();
    let html = dir.path().join("page.html");
    page(&map, &html, &[]).assert().success();
    let text = std::fs::read_to_string(&html).unwrap();
    assert_eq!(text.matches("<script").count(), 2);
    assert!(!text.contains("injected=1<"));
    assert!(text.contains("&lt;script&gt;window.injected=1&lt;/script&gt;'&quot;&amp;amp;.txt"));
}

#[test]
fn the_explorer_needs_a_map_and_refusals_leave_no_file() {
    let dir = tempfile::tempdir().unwrap();
    let html = dir.path().join("page.html");
    page("specs/case-study/arena.txt".as_ref(), &html, &[])
        .assert()
        .failure()
        .stderr(
            predicate::str::contains(
                "specs/case-study/arena.txt: --html: the explorer needs a map",
            )
            .and(predicate::str::contains("panicked").not()),
        );
    assert!(!html.exists());
    // An unwritable destination: one error, no partial file.
    let missing = dir.path().join("no such directory").join("page.html");
    page("specs/case-study/map.txt".as_ref(), &missing, &[])
        .assert()
        .failure()
        .stderr(predicate::str::contains("page.html"));
    assert!(!missing.exists());
}

#[test]
fn after_the_games_only_the_page_shows_the_labels() {
    let dir = tempfile::tempdir().unwrap();
    let html = dir.path().join("page.html");
    page(
        "specs/case-study/map.txt".as_ref(),
        &html,
        &["--games-only"],
    )
    .assert()
    .success();
    assert!(std::fs::read_to_string(&html).unwrap().contains("<script"));
}

#[test]
fn the_committed_example_pages_are_current() {
    // The Makefile's options for each page.
    let case_study = [
        CASE_STUDY_TASKS,
        &["--translator", "builtin", "--discount", "0.99"],
        &["--sigma-l", "uniform"],
    ]
    .concat();
    let decoy = [
        crate::common::DECOY_TASKS,
        &["--sigma-l", "uniform", "--explain", "--believed", "F C"],
    ]
    .concat();
    let three = [
        crate::common::THREE_TASKS,
        &["--sigma-l", "uniform", "--explain", "--discount", "0.95"],
    ]
    .concat();
    let cases = [
        (
            "specs/case-study/explorer.html",
            "specs/case-study/map.txt",
            case_study,
        ),
        ("specs/decoy/explorer.html", "specs/decoy/map.txt", decoy),
        (
            "specs/three-tasks/explorer.html",
            "specs/decoy/map.txt",
            three,
        ),
    ];
    let dir = tempfile::tempdir().unwrap();
    let html = dir.path().join("page.html");
    for (committed, map, args) in cases {
        Command::cargo_bin("hypersynth")
            .unwrap()
            .arg("-q")
            .args(&args)
            .arg(map)
            .arg("--html")
            .arg(&html)
            .assert()
            .success();
        assert!(
            std::fs::read(&html).unwrap() == std::fs::read(committed).unwrap(),
            "{committed} is stale: run `make case-study decoy three-tasks`"
        );
    }
}

#[test]
fn the_implicit_engine_draws_the_committed_pictures_and_page() {
    // The Makefile's options for the case study's pictures; its controllers decide alike on
    // both engines (`crates/hypersynth/tests/pipeline/engines.rs`), so the pictures are the
    // same bytes as the committed ones, drawn by the explicit engine.
    let dir = tempfile::tempdir().unwrap();
    let map = std::path::Path::new("specs/case-study/map.txt");
    let implicit = ["--engine", "implicit", "--sigma-l", "uniform"];
    for picture in ["map", "partition", "trace"] {
        let svg = dir.path().join(format!("{picture}.svg"));
        let png = dir.path().join(format!("{picture}.png"));
        let mut command = Command::cargo_bin("hypersynth").unwrap();
        command
            .args(CASE_STUDY_TASKS)
            .args(SETTINGS)
            .args(implicit)
            .arg(map)
            .args(["--picture", picture, "--svg"])
            .arg(&svg)
            .arg("--png")
            .arg(&png)
            .assert()
            .success()
            .stdout(predicate::str::contains("(full; implicit engine)"));
        let committed = format!("specs/case-study/{picture}.svg");
        assert!(
            std::fs::read(&svg).unwrap() == std::fs::read(&committed).unwrap(),
            "{committed}"
        );
        assert!(
            std::fs::read(&png)
                .unwrap()
                .starts_with(b"\x89PNG\r\n\x1a\n")
        );
    }
    // The page: the same slices, labels, values (in hundredths), adversary's moves and run as
    // the committed page. Its decisions agree but where uniform sigma_L leaves two moves of
    // equal value (ties, which the engines may break differently: docs/engines.md).
    let html = dir.path().join("page.html");
    page(map, &html, &implicit).assert().success();
    let data = explorer_data(&std::fs::read_to_string(&html).unwrap());
    let committed =
        explorer_data(&std::fs::read_to_string("specs/case-study/explorer.html").unwrap());
    for field in [
        "grid", "automata", "tuples", "start", "tags", "key", "choices", "sets", "run", "notes",
    ] {
        assert_eq!(data[field], committed[field], "{field}");
    }
    for field in ["tuples", "adversaries", "tags", "values", "adversary"] {
        assert_eq!(data["slices"][field], committed["slices"][field], "{field}");
    }
    let report = data["report"].as_str().unwrap();
    assert!(report.contains("(full; implicit engine)"), "{report}");
}

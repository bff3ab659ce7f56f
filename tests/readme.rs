//! The README's own commands and its contents list: the shell blocks marked runnable (an opening
//! fence "```sh runnable") run from the repository's root with the command under test first on
//! `PATH`, and the contents list names every heading with the anchor GitHub gives it.

#![cfg(unix)]

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::SystemTime;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

fn readme() -> String {
    std::fs::read_to_string(format!("{ROOT}/README.md")).unwrap()
}

/// Lines outside fenced code blocks, numbered from 1.
fn prose_lines(text: &str) -> Vec<(usize, &str)> {
    let mut fenced = false;
    let mut lines = Vec::new();
    for (i, line) in text.lines().enumerate() {
        if line.starts_with("```") {
            fenced = !fenced;
        } else if !fenced {
            lines.push((i + 1, line));
        }
    }
    lines
}

/// The runnable blocks, each with the line of its opening fence.
fn runnable_blocks(text: &str) -> Vec<(usize, String)> {
    let mut blocks = Vec::new();
    let mut current: Option<(usize, String)> = None;
    let mut fenced = false;
    for (i, line) in text.lines().enumerate() {
        if !line.starts_with("```") {
            if let Some((_, block)) = current.as_mut() {
                block.push_str(line);
                block.push('\n');
            }
            continue;
        }
        if fenced {
            blocks.extend(current.take());
        } else if line.split_whitespace().eq(["```sh", "runnable"]) {
            current = Some((i + 1, String::new()));
        }
        fenced = !fenced;
    }
    assert!(!fenced, "README.md: a code block is not closed");
    blocks
}

/// Every file under `dir` (but build output and version control) with its size and mtime.
fn files(dir: &Path, found: &mut BTreeMap<PathBuf, (u64, SystemTime)>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let entry = entry.unwrap();
        let path = entry.path();
        let name = entry.file_name();
        let metadata = entry.metadata().unwrap();
        if metadata.is_dir() {
            // Build products, and what a fuzzer running beside the tests writes (ignored by
            // git: fuzz/.gitignore).
            let fuzz_output = path.parent().is_some_and(|parent| parent.ends_with("fuzz"))
                && (name == "corpus" || name == "artifacts" || name == "logs");
            if name != "target" && name != ".git" && !fuzz_output {
                files(&path, found);
            }
        } else {
            found.insert(path, (metadata.len(), metadata.modified().unwrap()));
        }
    }
}

#[test]
fn every_runnable_block_succeeds_and_leaves_the_repository_as_it_was() {
    let text = readme();
    let blocks = runnable_blocks(&text);
    // The first command, the pipeline, the games report and the general form at least.
    assert!(
        blocks.len() >= 4,
        "only {} runnable blocks found",
        blocks.len()
    );
    let binary = Path::new(env!("CARGO_BIN_EXE_hypersynth"));
    let system_path = std::env::var_os("PATH").unwrap_or_default();
    let path = std::env::join_paths(
        std::iter::once(binary.parent().unwrap().to_path_buf())
            .chain(std::env::split_paths(&system_path)),
    )
    .unwrap();
    let scratch = tempfile::tempdir().unwrap();
    let mut before = BTreeMap::new();
    files(Path::new(ROOT), &mut before);
    for (line, block) in &blocks {
        let output = Command::new("bash")
            .args(["-euo", "pipefail", "-c", block])
            .current_dir(ROOT)
            .env("PATH", &path)
            .env("TMPDIR", scratch.path())
            .output()
            .unwrap();
        assert!(
            output.status.success(),
            "README.md:{line}: the block exited with {}:\n{block}\nstandard error:\n{}",
            output.status,
            String::from_utf8_lossy(&output.stderr)
        );
    }
    let mut after = BTreeMap::new();
    files(Path::new(ROOT), &mut after);
    let changed: Vec<_> = after
        .iter()
        .filter(|(path, stamp)| before.get(*path) != Some(stamp))
        .map(|(path, _)| path.display().to_string())
        .collect();
    assert!(
        changed.is_empty(),
        "the README's commands wrote into the repository: {changed:?}"
    );
}

#[test]
fn a_failing_block_is_found_and_only_marked_blocks_are_run() {
    let text = "```sh runnable\ntrue\n```\n```sh\nfalse\n```\n\n```sh runnable\nexit 3\n```\n";
    let blocks = runnable_blocks(text);
    assert_eq!(
        blocks,
        [(1, String::from("true\n")), (8, String::from("exit 3\n"))]
    );
    let status = Command::new("bash")
        .args(["-euo", "pipefail", "-c", &blocks[1].1])
        .status()
        .unwrap();
    assert_eq!(status.code(), Some(3));
}

/// GitHub's anchor of a heading: lower case, only letters, digits, `-` and `_` kept, spaces
/// turned into `-`.
fn anchor(heading: &str) -> String {
    heading
        .to_lowercase()
        .chars()
        .filter(|&c| c.is_alphanumeric() || c == '-' || c == '_' || c == ' ')
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

#[test]
fn anchors_are_made_as_github_makes_them() {
    assert_eq!(anchor("Pictures (`--svg FILE`)"), "pictures---svg-file");
    assert_eq!(
        anchor("DRN (Storm's explicit format)"),
        "drn-storms-explicit-format"
    );
    assert_eq!(
        anchor("Beyond the paper: k sub-tasks, payoffs on subsets, any believed task"),
        "beyond-the-paper-k-sub-tasks-payoffs-on-subsets-any-believed-task"
    );
}

#[test]
fn the_contents_list_every_heading_below_it_in_order() {
    let text = readme();
    let lines = prose_lines(&text);
    let start = lines
        .iter()
        .position(|(_, line)| *line == "## Contents")
        .expect("README.md has a `## Contents` heading");
    let listed: Vec<&str> = lines[start + 2..]
        .iter()
        .map(|(_, line)| *line)
        .take_while(|line| !line.is_empty())
        .collect();
    let mut expected = Vec::new();
    let mut anchors = std::collections::HashSet::new();
    for (number, line) in &lines[start + 1..] {
        let level = line.chars().take_while(|&c| c == '#').count();
        let Some(title) = line.get(level..).and_then(|rest| rest.strip_prefix(' ')) else {
            continue;
        };
        if !(2..=4).contains(&level) {
            continue;
        }
        let anchor = anchor(title);
        assert!(
            anchors.insert(anchor.clone()),
            "README.md:{number}: a second heading with the anchor #{anchor}"
        );
        expected.push(format!("{}- [{title}](#{anchor})", "  ".repeat(level - 2)));
    }
    assert_eq!(
        listed,
        expected,
        "README.md's contents should read:\n{}",
        expected.join("\n")
    );
    // Every link to an anchor of the README points at a heading.
    for (number, line) in &lines {
        for link in line.split("](#").skip(1) {
            let target = link.split(')').next().unwrap();
            assert!(
                anchors.contains(target),
                "README.md:{number}: no heading has the anchor #{target}"
            );
        }
    }
}

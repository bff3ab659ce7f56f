//! The documents' own commands, contents lists and links: the shell blocks marked runnable (an
//! opening fence "```sh runnable") of the README and of every `docs/*.md` run from the
//! repository's root with the command under test first on `PATH`; a document's contents list
//! names its headings with the anchors GitHub gives them; and every relative link of every
//! Markdown file of the repository resolves, to a file and, for a Markdown file, to a heading.

#![cfg(unix)]

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::SystemTime;

use crate::common::markdown::{self, fenced_blocks, headings, links};

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// The documents whose commands run and whose contents lists are checked: the README and every
/// Markdown file of `docs/`, by their paths from the root.
fn documents() -> Vec<String> {
    let mut found = vec![String::from("README.md")];
    let mut docs: Vec<String> = std::fs::read_dir(format!("{ROOT}/docs"))
        .unwrap()
        .map(|entry| entry.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|name| name.ends_with(".md"))
        .map(|name| format!("docs/{name}"))
        .collect();
    docs.sort();
    found.extend(docs);
    found
}

fn read(path: &str) -> String {
    std::fs::read_to_string(format!("{ROOT}/{path}")).unwrap()
}

/// The runnable blocks of a document, each with the line of its opening fence.
fn runnable_blocks(name: &str, text: &str) -> Vec<(usize, String)> {
    fenced_blocks(name, text)
        .into_iter()
        .filter(|block| block.info.split_whitespace().eq(["sh", "runnable"]))
        .map(|block| (block.line, block.body))
        .collect()
}

/// Every file under `dir` (but build output, version control and the browser tests'
/// dependencies) with its size and mtime.
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
            if name != "target" && name != ".git" && name != "node_modules" && !fuzz_output {
                files(&path, found);
            }
        } else {
            found.insert(path, (metadata.len(), metadata.modified().unwrap()));
        }
    }
}

#[test]
fn every_runnable_block_succeeds_and_leaves_the_repository_as_it_was() {
    let mut blocks = Vec::new();
    for document in documents() {
        let text = read(&document);
        let found = runnable_blocks(&document, &text);
        // The README: the first command and the tour at least.
        if document == "README.md" {
            assert!(
                found.len() >= 4,
                "README.md: only {} runnable blocks",
                found.len()
            );
        }
        blocks.extend(
            found
                .into_iter()
                .map(|(line, block)| (document.clone(), line, block)),
        );
    }
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
    for (document, line, block) in &blocks {
        let output = Command::new("bash")
            .args(["-euo", "pipefail", "-c", block])
            .current_dir(ROOT)
            .env("PATH", &path)
            .env("TMPDIR", scratch.path())
            .output()
            .unwrap();
        assert!(
            output.status.success(),
            "{document}:{line}: the block exited with {}:\n{block}\nstandard error:\n{}",
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
        "the documents' commands wrote into the repository: {changed:?}"
    );
}

#[test]
fn a_failing_block_is_found_and_only_marked_blocks_are_run() {
    let text = "```sh runnable\ntrue\n```\n```sh\nfalse\n```\n\n```sh runnable\nexit 3\n```\n";
    let blocks = runnable_blocks("test", text);
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

/// What is wrong with the contents list of `text` (nothing when it has none): it must list,
/// in order, every heading below it down to the deepest level it lists, each as
/// `- [TITLE](#ANCHOR)` indented two spaces per level below 2; no two headings may share an
/// anchor, and every link to an anchor of the document must find a heading.
fn contents_errors(name: &str, text: &str) -> Vec<String> {
    let mut errors = Vec::new();
    let all = headings(text);
    let Some(start) = all.iter().position(|heading| heading.title == "Contents") else {
        return errors;
    };
    let lines: Vec<&str> = text.lines().collect();
    let listed: Vec<&str> = lines[all[start].line + 1..]
        .iter()
        .copied()
        .take_while(|line| !line.is_empty())
        .collect();
    let depth = listed
        .iter()
        .map(|line| 2 + (line.len() - line.trim_start().len()) / 2)
        .max()
        .unwrap_or(2);
    let expected: Vec<String> = all[start + 1..]
        .iter()
        .filter(|heading| (2..=depth).contains(&heading.level))
        .map(|heading| {
            let indent = "  ".repeat(heading.level - 2);
            format!("{indent}- [{}](#{})", heading.title, heading.anchor)
        })
        .collect();
    if listed != expected {
        errors.push(format!(
            "{name}: the contents should read:\n{}",
            expected.join("\n")
        ));
    }
    let mut seen = std::collections::HashSet::new();
    for heading in &all {
        if !seen.insert(markdown::anchor(&heading.title)) {
            errors.push(format!(
                "{name}:{}: a second heading with the anchor #{}",
                heading.line,
                markdown::anchor(&heading.title)
            ));
        }
    }
    errors
}

#[test]
fn every_contents_list_names_every_heading_below_it_in_order() {
    let mut errors = Vec::new();
    let mut lists = 0;
    for document in documents() {
        let text = read(&document);
        lists += usize::from(headings(&text).iter().any(|h| h.title == "Contents"));
        errors.extend(contents_errors(&document, &text));
    }
    assert!(lists >= 4, "only {lists} documents have a contents list");
    assert!(errors.is_empty(), "{}", errors.join("\n"));
}

#[test]
fn a_wrong_contents_list_is_found() {
    let good = "# T\n\n## Contents\n\n- [A](#a)\n  - [B `x`](#b-x)\n\n## A\n\n### B `x`\n\n\
                #### C\n";
    assert_eq!(contents_errors("t", good), Vec::<String>::new());
    // The deepest level listed is the deepest required: here 3, so `C` need not be listed.
    let missing = good.replace("- [A](#a)\n", "");
    assert_eq!(contents_errors("t", &missing).len(), 1);
    let unlisted = good.replace("#### C", "### C");
    assert_eq!(contents_errors("t", &unlisted).len(), 1);
    let twice = format!("{good}\n## A\n");
    assert_eq!(contents_errors("t", &twice).len(), 2);
}

/// What is wrong with the relative links of the Markdown file `path` (from the root): each
/// must name a file or directory of the repository, and an anchor must name a heading of the
/// Markdown file it points into (the file itself for `#ANCHOR`).
fn link_errors(path: &Path, text: &str) -> Vec<String> {
    let name = path.strip_prefix(ROOT).unwrap_or(path).display();
    let mut errors = Vec::new();
    for (line, target) in links(text) {
        if target.contains("://") || target.starts_with("mailto:") {
            continue;
        }
        let (file, fragment) = match target.split_once('#') {
            Some((file, fragment)) => (file, Some(fragment)),
            None => (target.as_str(), None),
        };
        let resolved = path.parent().unwrap().join(file);
        if !file.is_empty() && !resolved.exists() {
            errors.push(format!("{name}:{line}: no file {target}"));
            continue;
        }
        if let Some(fragment) = fragment
            && (file.is_empty() || resolved.extension().is_some_and(|e| e == "md"))
        {
            let anchors = if file.is_empty() {
                markdown::anchors(text)
            } else {
                markdown::anchors(&std::fs::read_to_string(&resolved).unwrap())
            };
            if !anchors.contains(fragment) {
                errors.push(format!(
                    "{name}:{line}: no heading has the anchor of {target}"
                ));
            }
        }
    }
    errors
}

#[test]
fn every_relative_link_of_every_markdown_file_resolves() {
    let mut found = BTreeMap::new();
    files(Path::new(ROOT), &mut found);
    let documents: Vec<_> = found
        .into_keys()
        .filter(|path| path.extension().is_some_and(|extension| extension == "md"))
        .collect();
    // README, docs, the examples' and the Python package's READMEs among them.
    assert!(documents.len() >= 10, "{documents:?}");
    let errors: Vec<String> = documents
        .iter()
        .flat_map(|path| link_errors(path, &std::fs::read_to_string(path).unwrap()))
        .collect();
    assert!(errors.is_empty(), "{}", errors.join("\n"));
}

#[test]
fn a_broken_link_is_found() {
    let readme = Path::new(ROOT).join("README.md");
    let text = "[guide](docs/guide.md#conventions-shared-by-every-command) [no](docs/none.md) \
                [bad](docs/guide.md#no-such-heading) [web](https://example.org/x.md) [up](#x)\n\n\
                ## X\n";
    let errors = link_errors(&readme, text);
    assert_eq!(errors.len(), 2, "{errors:?}");
    assert!(errors[0].contains("docs/none.md") && errors[1].contains("no-such-heading"));
}

//! `docs/guide.md` is the command line's reference: it names every long option that `--help`
//! prints, for the main form and for every subcommand, and every option it names as
//! hypersynth's is one that some `--help` prints. The options come from the built command,
//! never from a list kept here.

use std::collections::BTreeSet;
use std::process::Command;

use crate::common::markdown::{fenced_blocks, inline};

/// The text `hypersynth ARGS --help` prints.
fn help(args: &[&str]) -> String {
    let output = Command::new(env!("CARGO_BIN_EXE_hypersynth"))
        .args(args)
        .arg("--help")
        .output()
        .unwrap();
    assert!(output.status.success(), "{args:?} --help failed");
    String::from_utf8(output.stdout).unwrap()
}

/// The subcommands the main form's help lists (`help` aside, which takes no option).
fn subcommands(main_help: &str) -> Vec<String> {
    main_help
        .lines()
        .skip_while(|line| *line != "Commands:")
        .skip(1)
        .take_while(|line| line.starts_with("  "))
        .filter_map(|line| line.split_whitespace().next())
        .filter(|name| *name != "help")
        .map(str::to_string)
        .collect()
}

/// The long options `--NAME` in `text`: `--` not preceded by a letter, digit or `-`, then a
/// lower-case letter or digit, then letters, digits and `-`.
fn long_options(text: &str) -> Vec<String> {
    let bytes = text.as_bytes();
    let mut found = Vec::new();
    let mut at = 0;
    while let Some(i) = text[at..].find("--").map(|i| at + i) {
        let before = i.checked_sub(1).map(|j| bytes[j]);
        let name: String = text[i + 2..]
            .chars()
            .take_while(|&c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-')
            .collect();
        let starts_well = name
            .chars()
            .next()
            .is_some_and(|c| c.is_ascii_lowercase() || c.is_ascii_digit());
        if starts_well && !before.is_some_and(|b| b.is_ascii_alphanumeric() || b == b'-') {
            found.push(format!("--{}", name.trim_end_matches('-')));
        }
        at = i + 2 + name.len();
    }
    found
}

/// The options a help text defines: the long option of each line that starts an option's
/// entry (two spaces and `-X, --NAME`, or six spaces and `--NAME`).
fn defined_options(help: &str) -> Vec<String> {
    help.lines()
        .filter_map(|line| {
            let entry = line
                .strip_prefix("  ")
                .filter(|rest| rest.starts_with('-'))
                .or_else(|| line.strip_prefix("      ").filter(|r| r.starts_with("--")))?;
            let first = entry
                .split_whitespace()
                .find(|word| word.starts_with("--"))?;
            long_options(first).into_iter().next()
        })
        .collect()
}

/// The long options a Markdown text names as hypersynth's: those of its prose, and those of
/// its code (each inline span, each line of a fenced block) unless the code is a command of
/// another program (its first word neither `hypersynth`, a subcommand nor an option, as in
/// `cargo bench --bench NAME`).
fn named_options(text: &str, subcommands: &[String]) -> BTreeSet<String> {
    let ours = |code: &str| {
        let first = code
            .trim_start()
            .trim_start_matches("$ ")
            .split_whitespace()
            .next()
            .unwrap_or("")
            .trim_end_matches(':');
        first == "hypersynth" || first.starts_with('-') || subcommands.iter().any(|s| s == first)
    };
    let mut found = BTreeSet::new();
    for piece in inline(text) {
        if !piece.code || ours(&piece.text) {
            found.extend(long_options(&piece.text));
        }
    }
    for block in fenced_blocks("docs/guide.md", text) {
        for line in block.body.lines().filter(|line| ours(line)) {
            found.extend(long_options(line));
        }
    }
    found
}

#[test]
fn options_are_found_in_help_and_in_prose() {
    let help = "Options:\n  -q, --quiet\n          Be quiet (unlike --loud)\n\n      \
                --phi <PHI>\n          The task\n  -o, --output <FILE>  Write\n      \
                --explain[=<STATE>]\n";
    assert_eq!(
        defined_options(help),
        ["--quiet", "--phi", "--output", "--explain"]
    );
    assert_eq!(
        long_options("a--b --x-y, `--z=1` --- -- --9 --Up"),
        ["--x-y", "--z", "--9"]
    );
    let subcommands = [String::from("translate")];
    let text = "Use `--phi` and --psi; `cargo bench --bench x`, `translate --stats`.\n\n\
                ```sh\nstorm --prop P\nhypersynth --trace \\\n    --seed 1\n```\n";
    let named: Vec<_> = named_options(text, &subcommands).into_iter().collect();
    assert_eq!(named, ["--phi", "--psi", "--seed", "--stats", "--trace"]);
}

#[test]
fn the_guide_names_every_option_of_help_and_no_other() {
    let main = help(&[]);
    let subcommands = subcommands(&main);
    assert!(
        subcommands.len() >= 8 && subcommands.iter().any(|s| s == "translate"),
        "{subcommands:?}"
    );
    let mut texts = vec![(String::from("hypersynth"), main)];
    for subcommand in &subcommands {
        texts.push((format!("hypersynth {subcommand}"), help(&[subcommand])));
    }
    let guide =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/guide.md")).unwrap();
    let named = named_options(&guide, &subcommands);
    let mut missing = Vec::new();
    // What the helps define, and every option they mention (an older name, say).
    let mut known = BTreeSet::new();
    for (command, text) in &texts {
        let defined = defined_options(text);
        assert!(
            defined.iter().any(|o| o == "--help"),
            "{command}: {defined:?}"
        );
        for option in defined {
            if !named.contains(&option) {
                missing.push(format!("{command} {option}"));
            }
            known.insert(option);
        }
        known.extend(long_options(text));
    }
    assert!(
        missing.is_empty(),
        "docs/guide.md does not name these options of --help: {missing:?}"
    );
    let unknown: Vec<_> = named.difference(&known).collect();
    assert!(
        unknown.is_empty(),
        "docs/guide.md names options no --help knows: {unknown:?}"
    );
}

/// `hypersynth help execute` lists every answer form of the guide's table of answers.
#[test]
fn the_execute_help_lists_every_answer_of_the_guide() {
    let guide = std::fs::read_to_string("docs/guide.md").unwrap();
    let forms: Vec<String> = guide
        .lines()
        .skip_while(|line| *line != "| answer | meaning |")
        .skip(2)
        .take_while(|line| line.starts_with('|'))
        .flat_map(|line| inline(line.split('|').nth(1).unwrap()))
        .filter(|piece| piece.code)
        .map(|piece| piece.text)
        .collect();
    assert!(forms.len() >= 6, "{forms:?}");
    let output = Command::new(env!("CARGO_BIN_EXE_hypersynth"))
        .args(["help", "execute"])
        .output()
        .unwrap();
    assert!(output.status.success());
    let help = String::from_utf8(output.stdout).unwrap();
    for form in forms {
        assert!(help.contains(&form), "{form} is missing from:\n{help}");
    }
}

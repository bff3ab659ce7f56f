//! `hypersynth completions SHELL` and `hypersynth man [SUBCOMMAND]`: scripts the shells accept
//! and pages groff renders without a warning (reading UTF-8 as `man` does, `-k`), naming every
//! subcommand and the options checked.

use std::io::Write as _;
use std::process::{Command as Process, Stdio};

use assert_cmd::Command;

const SUBCOMMANDS: [&str; 7] = [
    "ltl",
    "translate",
    "hoa",
    "arena",
    "gridworld",
    "completions",
    "man",
];

fn output(args: &[&str]) -> String {
    let output = Command::cargo_bin("hypersynth")
        .unwrap()
        .args(args)
        .output()
        .unwrap();
    assert!(output.status.success(), "{args:?}: {output:?}");
    assert!(output.stderr.is_empty(), "{args:?}: {output:?}");
    String::from_utf8(output.stdout).unwrap()
}

/// Runs `program args` with `input` on its standard input; `None` when it is not installed.
fn run_with_input(program: &str, args: &[&str], input: &str) -> Option<std::process::Output> {
    let mut child = match Process::new(program)
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
    {
        Ok(child) => child,
        Err(error) if error.kind() == std::io::ErrorKind::NotFound => {
            eprintln!("{program} is not installed: not checked");
            return None;
        }
        Err(error) => panic!("{program}: {error}"),
    };
    child
        .stdin
        .take()
        .unwrap()
        .write_all(input.as_bytes())
        .unwrap();
    Some(child.wait_with_output().unwrap())
}

#[test]
fn the_bash_completion_is_valid_bash_and_completes_every_subcommand() {
    let script = output(&["completions", "bash"]);
    for word in SUBCOMMANDS
        .iter()
        .chain(&["--phi", "--games-only", "--translator"])
    {
        assert!(script.contains(word), "the script lacks {word}");
    }
    let checked = run_with_input("bash", &["-n"], &script).unwrap();
    assert!(checked.status.success(), "{checked:?}");
    // Sourced, it registers a completion for the command.
    let registered =
        run_with_input("bash", &[], &format!("{script}\ncomplete -p hypersynth\n")).unwrap();
    assert!(registered.status.success(), "{registered:?}");
    assert!(String::from_utf8_lossy(&registered.stdout).contains("hypersynth"));
}

#[test]
fn zsh_and_fish_completions_name_the_command_and_its_subcommands() {
    let zsh = output(&["completions", "zsh"]);
    assert!(zsh.starts_with("#compdef hypersynth"), "{zsh}");
    let fish = output(&["completions", "fish"]);
    for word in SUBCOMMANDS {
        assert!(zsh.contains(word) && fish.contains(word), "{word}");
    }
    if let Some(checked) = run_with_input("zsh", &["-n"], &zsh) {
        assert!(checked.status.success(), "{checked:?}");
    }
    if let Some(checked) = run_with_input("fish", &["--no-execute"], &fish) {
        assert!(checked.status.success(), "{checked:?}");
    }
}

#[test]
fn the_man_pages_render_without_warnings_and_list_the_options() {
    let page = output(&["man"]);
    assert!(page.contains(".TH hypersynth 1"), "{page}");
    for word in SUBCOMMANDS {
        assert!(page.contains(&format!("hypersynth\\-{word}")), "{word}");
    }
    // roff writes a hyphen as `\-`.
    assert!(page.contains("\\-\\-phi"));
    let translate = output(&["man", "translate"]);
    assert!(
        translate.contains(".TH hypersynth-translate 1  \"hypersynth 0.1.0\""),
        "{translate}"
    );
    assert!(translate.contains("\\-\\-translator"));
    assert!(translate.contains("hypersynth translate"));
    for page in [&page, &translate] {
        if let Some(rendered) =
            run_with_input("groff", &["-k", "-man", "-Tutf8", "-ww", "-z"], page)
        {
            assert!(rendered.status.success(), "{rendered:?}");
            assert_eq!(String::from_utf8_lossy(&rendered.stderr), "");
        }
    }
    Command::cargo_bin("hypersynth")
        .unwrap()
        .args(["man", "nope"])
        .assert()
        .code(1)
        .stderr(predicates::str::contains("no subcommand `nope`"));
}

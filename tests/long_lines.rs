//! Errors quote their input briefly: every reader (arena, map, HOA, LTL, weights, observations,
//! controller, and `execute`'s standard input), fed a line of 1 MB that it refuses, gives an
//! error of a few hundred bytes, through the library and through the command line alike. The
//! messages quote at most 80 characters of the line, cut ones marked with `...`.

use assert_cmd::Command;
use hypersynth::diagnostic::{Diagnostics, QUOTE_WIDTH, Source};
use hypersynth::opportunistic::adversary::{WeightTable, WeightsFile};
use hypersynth::opportunistic::executor::Executor;
use hypersynth::opportunistic::observations::Observations;

use crate::common::{CASE_STUDY_TASKS, execute, exported_controllers};

/// The most bytes an error may take, whatever the length of the line it is about.
const MOST: usize = 512;

/// A name of a million `x`.
fn long() -> String {
    "x".repeat(1 << 20)
}

/// Whether `shown` is at most [`MOST`] bytes, quotes some of the line (a run of `x` or `9`)
/// and none of it longer than [`QUOTE_WIDTH`] characters, cut with `...`.
fn assert_brief(what: &str, shown: &str) {
    assert!(
        shown.len() <= MOST,
        "{what}: {} bytes: {shown:.600}",
        shown.len()
    );
    let quoted = ["x", "9"].iter().any(|c| shown.contains(&c.repeat(20)));
    let too_long = ["x", "9"]
        .iter()
        .any(|c| shown.contains(&c.repeat(QUOTE_WIDTH + 1)));
    assert!(
        quoted && !too_long && shown.contains("..."),
        "{what}: {shown}"
    );
}

/// `errors` as the command line shows them (rendered under their lines) and as their `Display`
/// gives them, each brief.
fn brief_diagnostics<M: std::fmt::Display>(what: &str, text: &str, errors: &Diagnostics<M>) {
    assert_brief(what, &Source::new("file", text).render(errors).join("\n"));
    assert_brief(what, &errors.to_string());
}

#[test]
fn the_librarys_readers_quote_a_long_line_briefly() {
    let x = long();
    let header = "propositions A\nactions a\ninitial s0\n";
    for text in [
        format!("{header}state s0 robot {{}}\nedge s0 a {x}\n"),
        format!("{header}{x}\n"),
        format!("{header}state s0 robot {{{x}}}\n"),
    ] {
        let errors = hypersynth::arena::parse(&text).unwrap_err();
        brief_diagnostics("arena", &text, &errors);
    }
    for text in [
        format!("hypersynth map v1\n{x}\n"),
        format!("hypersynth map v1\nrobot-moves {x}\n"),
        format!("hypersynth map {x}\n"),
        format!("hypersynth map v1\ngrid\n@r @a O+{x}\n"),
    ] {
        let errors = hypersynth::arena::map::parse(&text).unwrap_err();
        brief_diagnostics("map", &text, &errors);
    }
    for text in [
        format!("HOA: v1\n{x}\n"),
        format!("HOA: {x}\n"),
        format!("HOA: v1\nStates: {}\n", "9".repeat(1 << 20)),
        format!("HOA: v1\nAP: 2 \"{x}\" \"{x}\"\n"),
    ] {
        let errors = hypersynth::automata::hoa::parse(&text).unwrap_err();
        brief_diagnostics("HOA", &text, &errors);
    }
    for text in [format!("a {x}"), format!("{x} {x}")] {
        let errors = hypersynth::ltl::parse(&text).unwrap_err();
        brief_diagnostics("LTL", &text, &errors);
    }
    let weights = format!("s a {}x\n", "9".repeat(1 << 20));
    brief_diagnostics(
        "weights",
        &weights,
        &WeightTable::parse(&weights).unwrap_err(),
    );
    let arena = hypersynth::arena::parse(&format!("{header}state s0 adversary {{}}\n"))
        .unwrap()
        .arena;
    let weights = format!("{x} a 1\n");
    let errors = WeightsFile::parse(&weights)
        .unwrap()
        .check(&arena)
        .unwrap_err();
    brief_diagnostics("weights", &weights, &errors);
    let runs = format!("s0 {x}\n");
    brief_diagnostics(
        "observations",
        &runs,
        &Observations::parse(&runs).unwrap_err(),
    );

    let (_, text) = &exported_controllers()[1];
    let file: serde_json::Value = serde_json::from_str(text).unwrap();
    for (key, value) in [
        ("choices", serde_json::json!([{ "move": x }])),
        (x.as_str(), serde_json::json!(1)),
        ("risk", serde_json::json!(x)),
        ("format", serde_json::json!(x)),
        (
            "arena",
            serde_json::json!({ "map": format!("hypersynth map v1\n{x}\n") }),
        ),
    ] {
        let mut file = file.clone();
        file[key] = value;
        let error = Executor::from_json(&file.to_string()).err().unwrap();
        assert_brief("controller", &error.to_string());
    }
    let mut executor = Executor::from_json(text).unwrap();
    assert_brief("execute", &executor.observe(&x).unwrap_err().to_string());
}

/// Runs `hypersynth ARGS` in a directory holding `files`; its standard error.
fn stderr(args: &[&str], files: &[(&str, &str)]) -> String {
    let dir = tempfile::tempdir().unwrap();
    for (name, text) in files {
        std::fs::write(dir.path().join(name), text).unwrap();
    }
    let output = Command::cargo_bin("hypersynth")
        .unwrap()
        .current_dir(dir.path())
        .args(args)
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(1), "{args:?}");
    String::from_utf8(output.stderr).unwrap()
}

#[test]
fn the_commands_quote_a_long_line_briefly() {
    let x = long();
    let case_study = std::fs::read_to_string("specs/case-study/arena.txt").unwrap();
    let header = "propositions A\nactions a\ninitial s0\n";
    let arena = format!("{header}state s0 robot {{}}\nedge s0 a {x}\n");
    assert_brief("arena", &stderr(&["arena", "a.txt"], &[("a.txt", &arena)]));
    let map = format!("hypersynth map v1\nrobot-moves {x}\n");
    assert_brief("map", &stderr(&["arena", "m.txt"], &[("m.txt", &map)]));
    let hoa = format!("HOA: v1\n{x}\n");
    assert_brief("HOA", &stderr(&["hoa", "h.hoa"], &[("h.hoa", &hoa)]));
    let formulas = format!("a {x}\n");
    assert_brief(
        "LTL",
        &stderr(&["ltl", "-F", "f.ltl"], &[("f.ltl", &formulas)]),
    );
    let synthesis = |option: &str, text: &str| {
        let args = [CASE_STUDY_TASKS, &[option, "in.txt", "a.txt"]].concat();
        stderr(&args, &[("in.txt", text), ("a.txt", &case_study)])
    };
    assert_brief("weights", &synthesis("--adversary", &format!("{x} N 1\n")));
    assert_brief(
        "observations",
        &synthesis("--observations", &format!("{x}\n")),
    );

    let (_, text) = &exported_controllers()[1];
    let mut file: serde_json::Value = serde_json::from_str(text).unwrap();
    file["choices"][0] = serde_json::json!({ "move": x });
    let broken = file.to_string();
    assert_brief(
        "controller",
        &stderr(&["execute", "c.json"], &[("c.json", &broken)]),
    );

    let dir = tempfile::tempdir().unwrap();
    let controller = dir.path().join("c.json");
    std::fs::write(&controller, text).unwrap();
    for play in [format!("{x}\n"), format!("\"a\" {x}\n")] {
        let output = execute(&controller, &play);
        assert_eq!(output.status.code(), Some(1));
        assert_brief("execute", &String::from_utf8(output.stderr).unwrap());
    }
}

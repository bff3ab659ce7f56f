//! Conventions every command shares: outputs written with `-o` (permissions under the umask,
//! existing modes kept, symbolic links followed, devices and pipes written into, errors naming
//! the user's file), a closed standard output (`| head`) ending with status 0, `-q`, and the
//! argument traps (a misspelled subcommand, a missing `--psi`, `--explain` before ARENA).

#![cfg(unix)]

use std::io::{BufRead as _, BufReader};
use std::os::unix::fs::PermissionsExt as _;
use std::path::Path;
use std::process::{Command as Process, Stdio};

use assert_cmd::Command;
use assert_cmd::cargo::cargo_bin;

const ARENA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/specs/case-study/arena.txt");
const FORMULAS: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/fixtures/spot/formulas.ltl"
);
const TASKS: [&str; 6] = [
    "--phi",
    "(!O U A) & (!O U B)",
    "--psi",
    "!O U A",
    "--translator",
    "builtin",
];

fn mode(path: &Path) -> u32 {
    std::fs::metadata(path).unwrap().permissions().mode() & 0o7777
}

/// Runs `hypersynth ARGS` under `umask MASK` (through sh, since the umask is per process).
fn under_umask(mask: &str, args: &[&str]) {
    let status = Process::new("sh")
        .arg("-c")
        .arg(format!("umask {mask} && exec \"$0\" \"$@\""))
        .arg(cargo_bin("hypersynth"))
        .args(args)
        .stderr(Stdio::null())
        .status()
        .unwrap();
    assert!(status.success(), "{args:?}");
}

#[test]
fn new_outputs_get_the_permissions_the_umask_gives() {
    let dir = tempfile::tempdir().unwrap();
    for (mask, expected) in [("022", 0o644), ("027", 0o640), ("077", 0o600)] {
        let report = dir.path().join(format!("report-{mask}.txt"));
        let hoa = dir.path().join(format!("phi-{mask}.hoa"));
        let report_arg = report.to_str().unwrap();
        let mut args = TASKS.to_vec();
        args.extend(["--games-only", ARENA, "-o", report_arg]);
        under_umask(mask, &args);
        under_umask(
            mask,
            &["translate", "-f", "F a", "-o", hoa.to_str().unwrap()],
        );
        assert_eq!(mode(&report), expected, "umask {mask}");
        assert_eq!(mode(&hoa), expected, "umask {mask}");
    }
}

#[test]
fn the_main_form_writes_its_report_with_dash_o_and_keeps_an_existing_mode() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("report.json");
    std::fs::write(&path, "old").unwrap();
    std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o644)).unwrap();
    let output = Command::cargo_bin("hypersynth")
        .unwrap()
        .args(TASKS)
        .args(["-q", "--games-only", "--format", "json", ARENA, "-o"])
        .arg(&path)
        .output()
        .unwrap();
    assert!(output.status.success(), "{output:?}");
    assert!(output.stdout.is_empty());
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    assert_eq!(json["product_states"], 3200);
    assert_eq!(mode(&path), 0o644);
    // Nothing else was left in the directory.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

#[test]
fn dash_o_to_standard_output_writes_into_the_pipe() {
    // `/dev/stdout` is this process's pipe, which a rename cannot replace (and which must stay
    // what it is, as `/dev/null` must: renaming over it as root would make it a regular file).
    let to_stdout = |output_args: &[&str]| {
        let output = Command::cargo_bin("hypersynth")
            .unwrap()
            .args(["translate", "-q", "-f", "F a & X b"])
            .args(output_args)
            .output()
            .unwrap();
        assert!(output.status.success(), "{output:?}");
        output.stdout
    };
    let plain = to_stdout(&[]);
    assert!(plain.starts_with(b"HOA: v1"));
    assert_eq!(to_stdout(&["-o", "/dev/stdout"]), plain);
}

#[test]
fn writing_through_a_symbolic_link_replaces_its_target() {
    let dir = tempfile::tempdir().unwrap();
    let target = dir.path().join("automaton.hoa");
    let link = dir.path().join("latest.hoa");
    std::fs::write(&target, "old").unwrap();
    std::os::unix::fs::symlink("automaton.hoa", &link).unwrap();
    Command::cargo_bin("hypersynth")
        .unwrap()
        .args([
            "translate",
            "-q",
            "--translator",
            "builtin",
            "-f",
            "a U b",
            "-o",
        ])
        .arg(&link)
        .assert()
        .success();
    assert!(
        std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink()
    );
    assert!(
        std::fs::read_to_string(&target)
            .unwrap()
            .starts_with("HOA: v1\nname: \"a U b\"")
    );
}

#[test]
fn a_write_error_names_the_users_file_not_the_temporary_one() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("missing-directory").join("out.hoa");
    let output = Command::cargo_bin("hypersynth")
        .unwrap()
        .args(["translate", "-q", "-f", "F a", "-o"])
        .arg(&path)
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.starts_with(&format!(
            "hypersynth: error: cannot write {}: ",
            path.display()
        )),
        "{stderr}"
    );
    // The cause is the operating system's, without the temporary file's path.
    assert!(stderr.ends_with("(os error 2)\n"), "{stderr}");
    assert_eq!(stderr.matches(".tmp").count(), 1, "{stderr}");
}

/// Exit status 0 and nothing on stderr.
fn assert_silent_success(args: &[&str], output: &std::process::Output) {
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(0), "{args:?}: {stderr}");
    assert!(stderr.is_empty(), "{args:?}: {stderr}");
}

/// Every subcommand, with standard output a pipe whose reader is already closed: each write
/// fails with EPIPE, which must end the command quietly with status 0.
#[test]
fn a_closed_standard_output_ends_every_command_with_status_zero() {
    let hoa = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/spot/hoa/0001.hoa"
    );
    let mut main_form = TASKS.to_vec();
    main_form.push(ARENA);
    let commands: [&[&str]; 7] = [
        &main_form,
        &["ltl", "-F", FORMULAS],
        &["translate", "-F", FORMULAS],
        &["hoa", hoa],
        &["arena", ARENA],
        &[
            "gridworld",
            "--size",
            "3x3",
            "--robot",
            "0,0",
            "--adversary",
            "2,2",
        ],
        &["translate", "--stats", "%s", "-F", FORMULAS],
    ];
    for args in commands {
        let (reader, writer) = std::io::pipe().unwrap();
        drop(reader);
        let output = Process::new(cargo_bin("hypersynth"))
            .args(args)
            .arg("-q")
            .stdout(writer)
            .stderr(Stdio::piped())
            .output()
            .unwrap();
        assert_silent_success(args, &output);
    }
}

/// `| head -1` for real: read one line of a long output, then close the pipe.
#[test]
fn a_reader_that_stops_after_one_line_gets_status_zero() {
    for args in [
        &[
            "gridworld",
            "--size",
            "12x12",
            "--robot",
            "0,0",
            "--adversary",
            "11,11",
        ][..],
        &["ltl", "-F", FORMULAS, "-F", FORMULAS, "-F", FORMULAS][..],
    ] {
        let mut child = Process::new(cargo_bin("hypersynth"))
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let mut stdout = BufReader::new(child.stdout.take().unwrap());
        let mut line = String::new();
        stdout.read_line(&mut line).unwrap();
        assert!(!line.is_empty());
        drop(stdout);
        let output = child.wait_with_output().unwrap();
        assert_silent_success(args, &output);
    }
}

#[test]
fn dash_q_silences_warnings() {
    // The case study's tasks with a misspelt proposition (`Bee`, which the arena does not know).
    let run = |quiet: bool| {
        let mut command = Command::cargo_bin("hypersynth").unwrap();
        command
            .args(["--phi", "(!O U A) & (!O U Bee)", "--psi", "!O U A"])
            .args(["--translator", "builtin", "--games-only", ARENA]);
        if quiet {
            command.arg("--quiet");
        }
        command.output().unwrap()
    };
    let loud = run(false);
    assert!(String::from_utf8_lossy(&loud.stderr).contains("hypersynth: warning: "));
    let quiet = run(true);
    assert!(quiet.status.success());
    assert!(
        quiet.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&quiet.stderr)
    );
    assert_eq!(loud.stdout, quiet.stdout);
    // Also after a subcommand, and for its progress message.
    Command::cargo_bin("hypersynth")
        .unwrap()
        .args(["arena", "-q", ARENA])
        .assert()
        .success()
        .stderr("");
    Command::cargo_bin("hypersynth")
        .unwrap()
        .args(["translate", "-f", "F a", "-q"])
        .assert()
        .success()
        .stderr("");
}

#[test]
fn a_misspelled_subcommand_is_a_usage_error_with_a_suggestion() {
    let output = Command::cargo_bin("hypersynth")
        .unwrap()
        .args(["tranlsate", "-f", "F a"])
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("unknown subcommand 'tranlsate'"),
        "{stderr}"
    );
    assert!(
        stderr.contains("a similar subcommand exists: 'translate'"),
        "{stderr}"
    );
    // A word far from every subcommand gets no suggestion, but is still a usage error.
    let output = Command::cargo_bin("hypersynth")
        .unwrap()
        .arg("frobnicate")
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("unknown subcommand 'frobnicate'"),
        "{stderr}"
    );
    assert!(!stderr.contains("similar"), "{stderr}");
}

#[test]
fn a_missing_psi_is_a_usage_error_that_names_it() {
    let output = Command::cargo_bin("hypersynth")
        .unwrap()
        .args(["--phi", "(!O U A) & (!O U B)", ARENA])
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.starts_with("error: --psi PSI is missing"),
        "{stderr}"
    );
    assert!(output.stdout.is_empty());
    // And a missing ARENA or --phi likewise.
    let output = Command::cargo_bin("hypersynth")
        .unwrap()
        .args(["--phi", "F a", "--psi", "F a"])
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&output.stderr).contains("<ARENA>"));
    let output = Command::cargo_bin("hypersynth")
        .unwrap()
        .args(["--psi", "F a", ARENA])
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&output.stderr).contains("--phi PHI"));
}

#[test]
fn explain_before_the_arena_leaves_the_arena_alone() {
    let before = Command::cargo_bin("hypersynth")
        .unwrap()
        .args(TASKS)
        .args(["-q", "--explain", ARENA])
        .output()
        .unwrap();
    assert!(
        before.status.success(),
        "{}",
        String::from_utf8_lossy(&before.stderr)
    );
    let after = Command::cargo_bin("hypersynth")
        .unwrap()
        .args(TASKS)
        .args(["-q", ARENA, "--explain"])
        .output()
        .unwrap();
    assert_eq!(before.stdout, after.stdout);
    let text = String::from_utf8(before.stdout).unwrap();
    assert!(
        text.contains("decision table of ((0,2),(4,2),0)|0|0"),
        "{text}"
    );
    // A state is given with `=` (here h0 by name).
    let state = Command::cargo_bin("hypersynth")
        .unwrap()
        .args(TASKS)
        .args(["-q", "--explain=((0,2),(4,2),0)|0|0", ARENA])
        .output()
        .unwrap();
    assert!(
        state.status.success(),
        "{}",
        String::from_utf8_lossy(&state.stderr)
    );
    assert!(
        String::from_utf8_lossy(&state.stdout).contains("decision table of ((0,2),(4,2),0)|0|0")
    );
}

#[test]
fn dash_q_before_a_subcommand_is_the_subcommands() {
    // Without -q, translate says which translator it used; with -q before it, nothing.
    let quiet = Command::cargo_bin("hypersynth")
        .unwrap()
        .args(["-q", "translate", "--translator", "builtin", "-f", "F a"])
        .output()
        .unwrap();
    assert!(quiet.status.success(), "{quiet:?}");
    assert!(quiet.stderr.is_empty(), "{quiet:?}");
    assert!(quiet.stdout.starts_with(b"HOA: v1\nname: \"Fa\""));
    Command::cargo_bin("hypersynth")
        .unwrap()
        .args(["--quiet", "gridworld", "--size", "2x1"])
        .args(["--robot-start", "0,0", "--adversary-start", "1,0"])
        .assert()
        .success()
        .stderr("");
    // A misspelled subcommand after -q is still a usage error with a suggestion.
    Command::cargo_bin("hypersynth")
        .unwrap()
        .args(["-q", "tranlsate", "-f", "F a"])
        .assert()
        .code(2)
        .stderr(predicates::str::contains(
            "tip: a similar subcommand exists: 'translate'",
        ));
}

/// `--stats` on the main form is refused with a message naming `--timings` (its old meaning)
/// and the commands where Spot's `--stats FORMAT` lives, whether or not a format follows.
#[test]
fn stats_on_the_main_form_points_to_timings_and_to_spots_stats() {
    for extra in [&["--stats"][..], &["--stats", "%s"], &["--stats=%s"]] {
        let output = Command::cargo_bin("hypersynth")
            .unwrap()
            .args(TASKS)
            .args(extra)
            .arg(ARENA)
            .output()
            .unwrap();
        assert_eq!(output.status.code(), Some(2), "{extra:?}");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(
            stderr.contains("the main form has no --stats")
                && stderr.contains("--timings")
                && stderr.contains("hypersynth translate"),
            "{stderr}"
        );
    }
    // The subcommands keep Spot's --stats.
    Command::cargo_bin("hypersynth")
        .unwrap()
        .args(["translate", "-f", "F a", "--stats", "%s"])
        .assert()
        .success()
        .stdout("2\n");
}

/// The main form's help groups its options under headings, tasks first, and every example it
/// ends with runs (from the repository's root, the files it writes going to a temporary
/// directory; the one that reads a play from standard input is given one).
#[test]
fn the_main_forms_help_is_grouped_and_its_examples_run() {
    let output = Command::cargo_bin("hypersynth")
        .unwrap()
        .arg("--help")
        .output()
        .unwrap();
    let help = String::from_utf8(output.stdout).unwrap();
    let headings: Vec<&str> = help
        .lines()
        .filter(|l| !l.starts_with(' ') && l.ends_with(':'))
        .collect();
    let expected = [
        "Tasks (the paper's form):",
        "Tasks beyond the paper (k named sub-tasks):",
        "Translation:",
        "Arena and games:",
        "Adversary model:",
        "Payoffs and solver:",
        "Explanation and simulation:",
        "Output:",
        "Pictures (of a map):",
        "Limits:",
    ];
    let position = |h: &str| headings.iter().position(|x| *x == h);
    let found: Vec<Option<usize>> = expected.iter().map(|h| position(h)).collect();
    assert!(found.iter().all(Option::is_some), "{headings:?}");
    assert!(found.windows(2).all(|w| w[0] < w[1]), "{headings:?}");
    // Each example: a line `    hypersynth ...` and its `\`-continued lines.
    let examples = help.split("Examples").nth(1).expect("an examples section");
    let mut commands: Vec<String> = Vec::new();
    let mut continued = false;
    for line in examples.lines() {
        let line = line.trim();
        if continued {
            commands
                .last_mut()
                .unwrap()
                .push_str(line.trim_end_matches('\\'));
        } else if line.starts_with("hypersynth ") {
            commands.push(line.trim_end_matches('\\').to_string());
        } else {
            continue;
        }
        continued = line.ends_with('\\');
    }
    assert!(commands.len() >= 4, "{commands:?}");
    // The examples name `specs/...` from the repository's root: a link to it in the temporary
    // directory, where their outputs go.
    let dir = tempfile::tempdir().unwrap();
    let specs = Path::new(env!("CARGO_MANIFEST_DIR")).join("specs");
    std::os::unix::fs::symlink(specs, dir.path().join("specs")).unwrap();
    for command in &commands {
        let (command, input) = match command.split_once(" < ") {
            Some((command, _)) => (command, "((0,2),(4,2),0)\n"),
            None => (command.as_str(), ""),
        };
        let status = Process::new("sh")
            .arg("-c")
            .arg(format!("{command} > /dev/null"))
            .current_dir(dir.path())
            .env("PATH", path_with_hypersynth())
            .stdin(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .and_then(|mut child| {
                use std::io::Write as _;
                child.stdin.take().unwrap().write_all(input.as_bytes())?;
                child.wait_with_output()
            })
            .unwrap();
        assert!(
            status.status.success(),
            "{command}: {}",
            String::from_utf8_lossy(&status.stderr)
        );
    }
}

/// `PATH` with the freshly built `hypersynth` first.
fn path_with_hypersynth() -> String {
    let bin = cargo_bin("hypersynth");
    let dir = bin.parent().unwrap().display().to_string();
    format!("{dir}:{}", std::env::var("PATH").unwrap_or_default())
}

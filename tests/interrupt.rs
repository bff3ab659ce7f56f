//! Interruption: SIGINT ends hypersynth at once in every stage (it installs no handler while it
//! computes), and an interrupted run leaves no file, finished or temporary, in its output
//! directory. The children run long inputs and are interrupted at several moments; the bound
//! on how fast they end is generous (a loaded machine), and nothing here measures speed.
#![cfg(unix)]

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use std::os::unix::process::{CommandExt as _, ExitStatusExt as _};

/// How long an interrupted child may take to end: far more than it needs.
const BOUND: Duration = Duration::from_secs(5);

/// The command, with SIGINT and SIGTERM at their default disposition and unblocked in the
/// child, whatever the test process inherited: a non-interactive shell starts a background job
/// with SIGINT ignored, an ignored signal stays ignored across exec (POSIX), and the child would
/// then never see the interruption these tests send.
fn hypersynth() -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_hypersynth"));
    command
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null());
    // SAFETY: between fork and exec the hook calls only signal(2) and sigprocmask(2), which
    // are async-signal-safe, on the child's own dispositions and mask.
    unsafe {
        command.pre_exec(|| {
            for signal in [libc::SIGINT, libc::SIGTERM] {
                if libc::signal(signal, libc::SIG_DFL) == libc::SIG_ERR {
                    return Err(std::io::Error::last_os_error());
                }
            }
            let mut set: libc::sigset_t = std::mem::zeroed();
            libc::sigemptyset(&mut set);
            libc::sigaddset(&mut set, libc::SIGINT);
            libc::sigaddset(&mut set, libc::SIGTERM);
            if libc::sigprocmask(libc::SIG_UNBLOCK, &set, std::ptr::null_mut()) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
    command
}

/// Starts `command`, sends it SIGINT after `delay`, and checks that it ends within [`BOUND`],
/// killed by the signal (it was still running: the inputs take far longer than the delays),
/// leaving `directory` empty.
fn interrupt(mut command: Command, delay: Duration, directory: &Path, what: &str) {
    let mut child: Child = command.spawn().unwrap();
    std::thread::sleep(delay);
    // SAFETY: a plain kill(2) of our own child.
    assert_eq!(unsafe { libc::kill(child.id() as i32, libc::SIGINT) }, 0);
    let sent = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if sent.elapsed() > BOUND {
            let _ = child.kill();
            let _ = child.wait();
            panic!("{what}: still running {BOUND:?} after SIGINT at {delay:?}");
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    assert_eq!(
        status.signal(),
        Some(libc::SIGINT),
        "{what} at {delay:?}: {status}"
    );
    let left: Vec<_> = std::fs::read_dir(directory)
        .unwrap()
        .map(|entry| entry.unwrap().file_name())
        .collect();
    assert!(left.is_empty(), "{what} at {delay:?} left {left:?}");
}

#[test]
fn sigint_ends_a_long_translation_at_once_and_leaves_no_output() {
    // F(a & X^22 b) explores millions of states (seconds) before its state limit.
    let directory = tempfile::tempdir().unwrap();
    let output = directory.path().join("out.hoa");
    for delay in [100, 700] {
        let mut command = hypersynth();
        command
            .args([
                "translate",
                "--translator",
                "builtin",
                "--max-states",
                "3000000",
                "-o",
            ])
            .arg(&output)
            .arg(format!("F(a & {}b)", "X".repeat(22)));
        interrupt(
            command,
            Duration::from_millis(delay),
            directory.path(),
            "translate",
        );
    }
}

/// The 20x20 map of `benches/gridworld_40.rs`: robot west, adversary east, four obstacles
/// around the centre, A and B; with the map's default moves, 1.25 million product states.
fn map(n: usize) -> String {
    let (c, d) = (n / 2 - 1, n / 2 + 1);
    let mut rows = Vec::new();
    for y in (0..n).rev() {
        let row: Vec<&str> = (0..n)
            .map(|x| match (x, y) {
                _ if (x, y) == (0, n / 2) => "@r",
                _ if (x, y) == (n - 1, n / 2) => "@a",
                _ if (x == c || x == d) && (y == c || y == d) => "O",
                _ if (x, y) == (n / 4, n / 4) => "A",
                _ if (x, y) == (n - 1, n - 1) => "B",
                _ => ".",
            })
            .collect();
        rows.push(row.join(" "));
    }
    format!(
        "hypersynth map v1\ncollision forbidden\nfirst robot\ngrid\n{}\n",
        rows.join("\n")
    )
}

#[test]
fn sigint_ends_the_main_form_in_any_stage_and_leaves_no_output() {
    // Reading the map and the product come first (about a second), then the attractors, the
    // MDP and the solver (several seconds): interrupted early, midway and late.
    let inputs = tempfile::tempdir().unwrap();
    let map_file = inputs.path().join("map.txt");
    std::fs::write(&map_file, map(20)).unwrap();
    let directory = tempfile::tempdir().unwrap();
    let out = |name: &str| directory.path().join(name);
    for delay in [200, 800, 2000] {
        let mut command = hypersynth();
        command
            .args(["--phi", "(!O U A) & (!O U B)", "--psi", "!O U A"])
            .args(["--translator", "builtin", "-o"])
            .arg(out("report.txt"))
            .arg("--export-mdp")
            .arg(out("mdp.drn"))
            .arg("--export-strategy")
            .arg(out("strategy.json"))
            .arg(&map_file);
        interrupt(
            command,
            Duration::from_millis(delay),
            directory.path(),
            "the main form",
        );
    }
}

//! The translation by Spot's `ltl2tgba`, run as an external process.
//!
//! `ltl2tgba -D -C -S -B -H -f FORMULA` prints a deterministic, complete, state-based terminal
//! Büchi automaton in HOA; [`crate::automata::hoa`] reads it as the DFA of good prefixes (final
//! states: those whose reachable states are all accepting), and the result is minimised.
//!
//! Safety and robustness:
//! - the process gets an argument vector, never a shell: the formula, printed in Spot's syntax,
//!   is one argument, so quoted propositions such as `"$(touch x)"` reach it untouched;
//! - standard input is closed; standard output and error are read by two threads (so a chatty
//!   process cannot block on a full pipe) while the caller waits for both pipes to close and
//!   then polls for the exit status; the process is killed when the timeout expires;
//! - a process that exits non-zero, times out, or prints anything but one deterministic
//!   terminal automaton is an error that quotes its standard error.
//!
//! Finding the executable: an explicit path, else the `HYPERSYNTH_LTL2TGBA` environment
//! variable, else `ltl2tgba` on `PATH` ([`locate_ltl2tgba`] takes their values as arguments,
//! so it reads no environment itself).

use std::ffi::OsStr;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::sync::{Arc, Mutex, mpsc};
use std::thread;
use std::time::{Duration, Instant};

use super::builtin::minimising_stopped;
use super::{Limit, LimitError, Phase, Progress, TranslateError, TranslationLimits, Translator};
use crate::automata::{Dfa, DfaState, hoa, minimize_within};
use crate::limits::{Deadline, Work};
use crate::ltl::{self, Formula};

/// The environment variable naming the `ltl2tgba` executable.
pub const LTL2TGBA_VARIABLE: &str = "HYPERSYNTH_LTL2TGBA";

/// How long `ltl2tgba` may run before it is killed, unless told otherwise.
pub const DEFAULT_TIMEOUT: Duration = Duration::from_secs(60);

/// The executable to run: `explicit` if given, else `from_variable` (the value of
/// [`LTL2TGBA_VARIABLE`]) if set and non-empty, else the first `ltl2tgba` executable file in
/// the directories of `search_path` (the value of `PATH`). An explicit path or variable is
/// returned as given, without checking it: running it reports the problem.
pub fn locate_ltl2tgba(
    explicit: Option<&Path>,
    from_variable: Option<&OsStr>,
    search_path: Option<&OsStr>,
) -> Option<PathBuf> {
    if let Some(path) = explicit {
        return Some(path.to_path_buf());
    }
    if let Some(path) = from_variable.filter(|value| !value.is_empty()) {
        return Some(PathBuf::from(path));
    }
    std::env::split_paths(search_path?)
        .map(|directory| directory.join("ltl2tgba"))
        .find(|candidate| is_executable_file(candidate))
}

#[cfg(unix)]
fn is_executable_file(path: &Path) -> bool {
    use std::os::unix::fs::PermissionsExt;
    path.metadata()
        .is_ok_and(|m| m.is_file() && m.permissions().mode() & 0o111 != 0)
}

#[cfg(not(unix))]
fn is_executable_file(path: &Path) -> bool {
    path.is_file()
}

/// Why running `ltl2tgba` gave no automaton. Multi-line messages put the process's standard
/// error on indented lines after the first.
#[derive(Debug, thiserror::Error)]
pub enum SpotError {
    /// Spot was asked for, but no `ltl2tgba` executable was found (given, in the environment
    /// variable, or on `PATH`).
    #[error(
        "Spot's ltl2tgba was not found: give its path, set {LTL2TGBA_VARIABLE}, or put it on PATH"
    )]
    NotFound,
    /// The process could not be started (or waited for).
    #[error("cannot run {program}: {source}")]
    Start {
        /// The executable's path, as shown in messages.
        program: String,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// The process exited unsuccessfully.
    #[error("{program} failed ({status}){}", indented(stderr))]
    Failed {
        /// The executable's path, as shown in messages.
        program: String,
        /// How it exited.
        status: ExitStatus,
        /// What it printed on standard error.
        stderr: String,
    },
    /// The process ran longer than the timeout and was killed.
    #[error("{program} did not finish within {:.3} s and was killed{}", timeout.as_secs_f64(), indented(stderr))]
    Timeout {
        /// The executable's path, as shown in messages.
        program: String,
        /// The time limit it exceeded, as set: the translator's timeout, or the deadline of its
        /// limits (which may have been shared with earlier translations) when that came first.
        timeout: Duration,
        /// What it printed on standard error before it was killed.
        stderr: String,
    },
    /// The process's output is not a deterministic terminal automaton in HOA that can be read as a
    /// DFA.
    #[error("{program} did not print a deterministic terminal automaton: {reason}")]
    Output {
        /// The executable's path, as shown in messages.
        program: String,
        /// What is wrong with the output.
        reason: String,
    },
}

/// `text` as context lines after an error's first line: each line indented, blank lines and
/// trailing white space dropped.
fn indented(text: &str) -> String {
    text.lines()
        .map(str::trim_end)
        .filter(|line| !line.is_empty())
        .map(|line| format!("\n  {line}"))
        .collect()
}

/// Translation by running `ltl2tgba`.
#[derive(Clone, Debug)]
pub struct Spot {
    executable: PathBuf,
    timeout: Duration,
    limits: TranslationLimits,
    name: String,
}

impl Spot {
    /// Translation by running the `ltl2tgba` at `executable`, killed when it runs longer than
    /// `timeout`, with the default limits ([`with_limits`](Spot::with_limits) changes them).
    pub fn new(executable: PathBuf, timeout: Duration) -> Spot {
        let name = format!("spot ({})", executable.display());
        Spot {
            executable,
            timeout,
            limits: TranslationLimits::default(),
            name,
        }
    }

    /// The same translator refusing automata of more than `max_states` states (as read, before
    /// minimisation; the HOA reader never reads more than [`hoa::MAX_STATES`]).
    pub fn with_max_states(self, max_states: usize) -> Spot {
        let limits = TranslationLimits {
            max_states,
            ..self.limits
        };
        Spot { limits, ..self }
    }

    /// The same translator under `limits`: the process is killed at their deadline (or after
    /// the timeout, whichever comes first), automata of more than `max_states` states are
    /// refused as read, and minimisation counts its work and bytes against theirs.
    pub fn with_limits(self, limits: TranslationLimits) -> Spot {
        Spot { limits, ..self }
    }

    /// Runs `ltl2tgba` on `formula` (Spot syntax) and returns its standard output.
    fn run(&self, formula: &str) -> Result<String, SpotError> {
        let program = self.executable.display().to_string();
        let mut child = Command::new(&self.executable)
            .args(["-D", "-C", "-S", "-B", "-H", "-f", formula])
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|source| SpotError::Start {
                program: program.clone(),
                source,
            })?;
        // Each reader thread reports on `closed` when its pipe reaches end of file.
        let (closing, closed) = mpsc::channel();
        let stdout = Drain::spawn(child.stdout.take(), closing.clone());
        let stderr = Drain::spawn(child.stderr.take(), closing);
        // Beyond a century the deadline could overflow `Instant`; no run is that long anyway.
        let timeout = self.timeout.min(Duration::from_secs(100 * 365 * 86_400));
        let deadline = Deadline::after(timeout).min(self.limits.deadline);
        // What the user set: a message names that, not the part of it left when Spot started.
        let limit = deadline.limit().unwrap_or(timeout);
        let deadline = deadline
            .instant()
            .expect("a timeout under a century gives a deadline");
        let timed_out = |child: &mut std::process::Child| {
            // Killing a process that has just exited fails harmlessly; `wait` reaps it.
            let _ = child.kill();
            let _ = child.wait();
            SpotError::Timeout {
                program: program.clone(),
                timeout: limit,
                stderr: stderr.text(),
            }
        };
        // The output is complete once both pipes are closed, which normally comes with the exit.
        for _ in 0..2 {
            match closed.recv_timeout(deadline.saturating_duration_since(Instant::now())) {
                Ok(()) | Err(mpsc::RecvTimeoutError::Disconnected) => {}
                Err(mpsc::RecvTimeoutError::Timeout) => return Err(timed_out(&mut child)),
            }
        }
        let mut pause = Duration::from_millis(1);
        let status = loop {
            match child.try_wait() {
                Ok(Some(status)) => break status,
                Ok(None) if Instant::now() >= deadline => return Err(timed_out(&mut child)),
                Ok(None) => {}
                Err(source) => {
                    return Err(SpotError::Start {
                        program: program.clone(),
                        source,
                    });
                }
            }
            thread::sleep(pause.min(deadline.saturating_duration_since(Instant::now())));
            pause = (pause * 2).min(Duration::from_millis(50));
        };
        if !status.success() {
            return Err(SpotError::Failed {
                program,
                status,
                stderr: stderr.text(),
            });
        }
        Ok(stdout.text())
    }
}

/// A pipe read to its end by a thread of its own, into a buffer the caller can look at any
/// time (so that the standard error of a process killed at the timeout can still be shown).
struct Drain {
    buffer: Arc<Mutex<Vec<u8>>>,
}

impl Drain {
    /// Starts reading `pipe`; sends on `closed` at its end (at once if there is no pipe).
    fn spawn(pipe: Option<impl Read + Send + 'static>, closed: mpsc::Sender<()>) -> Drain {
        let buffer = Arc::new(Mutex::new(Vec::new()));
        let Some(mut pipe) = pipe else {
            let _ = closed.send(());
            return Drain { buffer };
        };
        let shared = Arc::clone(&buffer);
        // The thread is not joined: after a timeout, a pipe held open by a grandchild would
        // block it, and it ends by itself when the pipe closes.
        thread::spawn(move || {
            let mut chunk = [0u8; 8192];
            loop {
                match pipe.read(&mut chunk) {
                    Ok(0) => break,
                    Ok(count) => {
                        if let Ok(mut buffer) = shared.lock() {
                            buffer.extend_from_slice(&chunk[..count]);
                        }
                    }
                    Err(error) if error.kind() == std::io::ErrorKind::Interrupted => {}
                    // Any other error ends the output like end of file; what was read is kept.
                    Err(_) => break,
                }
            }
            // The receiver is gone only if the caller has already given up.
            let _ = closed.send(());
        });
        Drain { buffer }
    }

    /// What was read so far, as text (invalid UTF-8 replaced).
    fn text(&self) -> String {
        self.buffer
            .lock()
            .map(|buffer| String::from_utf8_lossy(&buffer).into_owned())
            .unwrap_or_default()
    }
}

impl Translator for Spot {
    fn name(&self) -> &str {
        &self.name
    }

    fn translate(&self, formula: &Formula) -> Result<Dfa, TranslateError> {
        let started = Instant::now();
        ltl::check_co_safe(formula)?;
        let hoa = self.run(&formula.to_string())?;
        let aps = ltl::atomic_propositions(formula);
        let dfa = read_automaton(&hoa, aps).map_err(|reason| SpotError::Output {
            program: self.executable.display().to_string(),
            reason,
        })?;
        let limits = self.limits;
        if dfa.num_states() > limits.max_states {
            return Err(LimitError {
                limit: Limit::States(limits.max_states),
                span: None,
                phase: Phase::Reading,
                progress: Progress {
                    found: dfa.num_states(),
                    edges: dfa.num_edges(),
                    ..Progress::default()
                },
                limits,
                note: None,
            }
            .into());
        }
        let mut work = Work::new(limits.max_steps, limits.deadline);
        minimize_within(&dfa, &mut work, limits.max_bytes)
            .map_err(|stop| minimising_stopped(stop, &dfa, limits, started).into())
    }
}

/// The one automaton of `hoa`, as a DFA over `aps` (the formula's propositions, in its order:
/// Spot may order them otherwise, or drop some that its simplifications remove).
fn read_automaton(hoa: &str, aps: Vec<String>) -> Result<Dfa, String> {
    let mut automata = hoa::parse(hoa).map_err(|errors| {
        let first = errors.first();
        format!("at {} of its output: {}", first.position, first.message)
    })?;
    let dfa = match automata.len() {
        1 => automata.swap_remove(0).dfa,
        n => return Err(format!("{n} automata instead of one")),
    };
    let mut positions = Vec::with_capacity(dfa.aps().len());
    for name in dfa.aps() {
        match aps.iter().position(|ap| ap == name) {
            Some(index) => positions.push(index as u32),
            None => return Err(format!("proposition `{name}` is not in the formula")),
        }
    }
    let edges = (0..dfa.num_states() as DfaState)
        .map(|q| {
            dfa.edges(q)
                .map(|(guard, target)| (guard.remap(&positions), target))
                .collect()
        })
        .collect();
    Dfa::new(aps, dfa.initial(), dfa.finals().clone(), edges).map_err(|error| error.to_string())
}

#[cfg(all(test, unix))]
mod tests {
    use std::os::unix::fs::PermissionsExt;

    use super::*;

    #[test]
    fn the_executable_is_the_explicit_path_else_the_variable_else_the_first_on_path() {
        let root = tempfile::tempdir().unwrap();
        let [plain, directory, runnable] = ["plain", "directory", "runnable"].map(|name| {
            let dir = root.path().join(name);
            std::fs::create_dir(&dir).unwrap();
            dir
        });
        // Not executable, a directory, and finally a real candidate.
        std::fs::write(plain.join("ltl2tgba"), "").unwrap();
        std::fs::create_dir(directory.join("ltl2tgba")).unwrap();
        let found = runnable.join("ltl2tgba");
        std::fs::write(&found, "#!/bin/sh\n").unwrap();
        std::fs::set_permissions(&found, std::fs::Permissions::from_mode(0o755)).unwrap();
        let path = std::env::join_paths([&plain, &directory, &runnable, &runnable]).unwrap();
        let path = Some(path.as_os_str());

        assert_eq!(locate_ltl2tgba(None, None, path), Some(found.clone()));
        assert_eq!(
            locate_ltl2tgba(None, Some(OsStr::new("")), path),
            Some(found)
        );
        let from_variable = Some(OsStr::new("/from/variable"));
        assert_eq!(
            locate_ltl2tgba(None, from_variable, path),
            Some(PathBuf::from("/from/variable"))
        );
        assert_eq!(
            locate_ltl2tgba(Some(Path::new("given")), from_variable, path),
            Some(PathBuf::from("given"))
        );
        let without = std::env::join_paths([&plain, &directory]).unwrap();
        assert_eq!(locate_ltl2tgba(None, None, Some(without.as_os_str())), None);
        assert_eq!(locate_ltl2tgba(None, None, None), None);
    }
}

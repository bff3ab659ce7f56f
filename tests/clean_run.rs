//! A new user's first runs print no warning: the README's first command and the commands of
//! `make case-study`, `make decoy`, `make three-tasks` and `make learnt` (without their `-q`,
//! outputs into a temporary directory). The bundled arenas have stuck and unreachable states by
//! design and declare `O` though no state carries it; none of that is worth a warning when
//! solving.

use crate::common;

use assert_cmd::Command;

const CASE_ARENA: &str = "specs/case-study/arena.txt";
const CASE_MAP: &str = "specs/case-study/map.txt";
const DECOY_ARENA: &str = "specs/decoy/arena.txt";
const DECOY_MAP: &str = "specs/decoy/map.txt";

/// Runs hypersynth with `args` (`{}` in an argument is replaced by the temporary directory) and
/// returns its standard error, after checking that it succeeded.
fn stderr_of(args: &[&str], dir: &std::path::Path) -> String {
    let args: Vec<String> = args
        .iter()
        .map(|arg| arg.replace("{}", &dir.display().to_string()))
        .collect();
    let output = Command::cargo_bin("hypersynth")
        .unwrap()
        .args(&args)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr).to_string();
    assert!(output.status.success(), "{args:?}: {stderr}");
    stderr
}

#[test]
fn the_readme_and_makefile_commands_print_no_warning() {
    let dir = tempfile::tempdir().unwrap();
    let decoy = [common::DECOY_TASKS, &["--sigma-l", "uniform", "--explain"]].concat();
    let three = [common::THREE_TASKS, &["--sigma-l", "uniform", "--explain"]].concat();
    let discounted = ["--discount", "0.99", "--sigma-l", "uniform"];
    let runs: Vec<Vec<&str>> = vec![
        // README: the first command.
        [common::CASE_STUDY_TASKS, &[CASE_ARENA, "--explain"]].concat(),
        // make case-study
        [
            common::CASE_STUDY_TASKS,
            &[
                CASE_MAP,
                "--games-only",
                "--svg",
                "{}/map.svg",
                "--picture",
                "map",
            ],
        ]
        .concat(),
        [
            common::CASE_STUDY_TASKS,
            &[CASE_MAP],
            &discounted,
            &["--svg", "{}/partition.svg", "--picture", "partition"],
        ]
        .concat(),
        [
            common::CASE_STUDY_TASKS,
            &[CASE_MAP],
            &discounted,
            &["--svg", "{}/trace.svg", "--picture", "trace"],
        ]
        .concat(),
        [
            common::CASE_STUDY_TASKS,
            &[
                CASE_ARENA,
                "--explain",
                "--simulate",
                "10000",
                "-o",
                "{}/r.txt",
            ],
        ]
        .concat(),
        [
            common::CASE_STUDY_TASKS,
            &[CASE_ARENA],
            &discounted,
            &["--explain", "--simulate", "10000"],
            &["--export-mdp", "{}/m.drn", "-o", "{}/rd.txt"],
        ]
        .concat(),
        // make decoy
        [
            &decoy[..],
            &["--believed", "F C", "--discount", "1", DECOY_ARENA],
        ]
        .concat(),
        [
            &decoy[..],
            &["--believed", "(!O U A) & (!O U B)", "--discount", "0.95"],
            &[DECOY_ARENA],
        ]
        .concat(),
        [
            &decoy[..],
            &["--believed", "F C", DECOY_MAP, "--games-only"],
            &["--svg", "{}/dm.svg", "--picture", "map"],
        ]
        .concat(),
        [
            &decoy[..],
            &["--believed", "F C", DECOY_MAP],
            &["--svg", "{}/dt.svg", "--picture", "trace"],
        ]
        .concat(),
        // make three-tasks
        [
            &three[..],
            &["--risk", "strict", "--discount", "0.95", DECOY_ARENA],
        ]
        .concat(),
        [
            &three[..],
            &[DECOY_MAP, "--svg", "{}/tp.svg", "--picture", "partition"],
        ]
        .concat(),
        [
            &three[..],
            &["--discount", "0.95", DECOY_MAP],
            &["--svg", "{}/tv.svg", "--picture", "value"],
        ]
        .concat(),
        // make learnt
        [
            common::CASE_STUDY_TASKS,
            &[
                "--discount",
                "0.99",
                "--adversary",
                "specs/learnt/truth.txt",
            ],
            &[
                "--observations",
                "specs/learnt/runs.txt",
                "--explain",
                CASE_ARENA,
            ],
            &["--learning-curve-png", "{}/curve.png", "-o", "{}/lr.txt"],
        ]
        .concat(),
    ];
    for args in runs {
        let stderr = stderr_of(&args, dir.path());
        assert!(!stderr.contains("warning"), "{args:?}:\n{stderr}");
    }
}

#[test]
fn a_proposition_the_arena_does_not_know_still_warns() {
    let dir = tempfile::tempdir().unwrap();
    let args = [
        "--phi",
        "(!O U A) & (!O U Bee)",
        "--psi",
        "!O U A",
        "--translator",
        "builtin",
        "--games-only",
        CASE_ARENA,
    ];
    let stderr = stderr_of(&args, dir.path());
    assert_eq!(
        stderr,
        "hypersynth: warning: proposition `Bee` is not a proposition of \
         specs/case-study/arena.txt (no state carries it and the arena does not declare it): it \
         is always false\n"
    );
}

//! Helpers shared by the command's integration tests: the examples' options and exported
//! controllers, the robot cells of a picture, an arena of adversary states leading into each
//! other, running the binary, a DRN reader with Storm's value of the model (`drn`) and enough
//! Markdown to check the documents (`markdown`). The helpers the library's tests use too are the
//! library's `hypersynth::testing`, re-exported here.

pub mod drn;
pub mod markdown;

pub use hypersynth::testing::{PAPER_TASKS, avoid_until, paper_regions};

/// The case study's tasks in the paper's form (specs/case-study): phi and psi = phi1.
pub const CASE_STUDY_TASKS: &[&str] = &["--phi", "(!O U A) & (!O U B)", "--psi", "!O U A"];

/// The three-tasks example's options (specs/three-tasks): sub-tasks A, B, C with their payoffs
/// and a bonus for all three; the adversary believes the task is A's.
pub const THREE_TASKS: &[&str] = &[
    "--task",
    "A=!O U A",
    "--task",
    "B=!O U B",
    "--task",
    "C=F C",
    "--payoff",
    "A=200",
    "--payoff",
    "B=100",
    "--payoff",
    "C=50",
    "--payoff",
    "A,B,C=500",
    "--believed",
    "!O U A",
];

/// The decoy example's sub-tasks and payoffs (specs/decoy), without the believed task: A pays
/// 200, B 100, and both together 300.
pub const DECOY_TASKS: &[&str] = &[
    "--task", "A=!O U A", "--task", "B=!O U B", "--payoff", "A=200", "--payoff", "B=100",
];

/// A robot cell as the SVG of a gridworld picture draws it: `<g><title>robot at (x,y): ...`
/// followed by its `<rect>` and, in the general form's partition, a `<text>` code.
#[derive(Clone, Debug, PartialEq)]
pub struct SvgCell {
    /// The cell `(x, y)`.
    pub cell: (u32, u32),
    /// Its square on screen `(left, top, side)`.
    pub square: (f64, f64, f64),
    /// The code written in it, if any.
    pub code: Option<String>,
}

/// Every robot cell of a picture, in document order.
pub fn svg_cells(svg: &str) -> Vec<SvgCell> {
    let attribute = |element: &str, name: &str| -> f64 {
        let start = element.find(&format!(" {name}=\"")).unwrap() + name.len() + 3;
        let end = start + element[start..].find('"').unwrap();
        element[start..end].parse().unwrap()
    };
    svg.split("<g><title>robot at (")
        .skip(1)
        .map(|group| {
            let group = &group[..group.find("</g>").unwrap()];
            let (cell, rest) = group.split_once(')').unwrap();
            let (x, y) = cell.split_once(',').unwrap();
            let rect = &rest[rest.find("<rect").unwrap()..];
            let rect = &rect[..rect.find("/>").unwrap()];
            let side = attribute(rect, "width");
            assert_eq!(side, attribute(rect, "height"), "{rect}");
            let code = rest.find("<text").map(|start| {
                let text = &rest[start..];
                text[text.find('>').unwrap() + 1..text.find("</text>").unwrap()].to_string()
            });
            SvgCell {
                cell: (x.parse().unwrap(), y.parse().unwrap()),
                square: (attribute(rect, "x"), attribute(rect, "y"), side),
                code,
            }
        })
        .collect()
}

/// Robot `r0` moves `a` to adversary `x0`, which moves `a` to itself, `b` to `x1` or `c` to `r1`
/// (A holds); `x1` moves `a` to `x0`, `b` to itself, `c` to `r2` (B holds): adversary states
/// that lead into each other. With psi = F A, `x0` and `x1` are outside Win(F A) (the adversary
/// can avoid `r1` for ever) and play sigma_W: at `x0`, `c` leads into Win(F A), so the model
/// gives it probability 0.
pub const CHANCE_CYCLE: &str = "initial r0
state r0 robot {}
state x0 adversary {}
state x1 adversary {}
state r1 robot {A}
state r2 robot {B}
edge r0 a x0
edge x0 a x0
edge x0 b x1
edge x0 c r1
edge x1 a x0
edge x1 b x1
edge x1 c r2
";

/// Runs the `hypersynth` binary quietly with `args` and `stdin` as its standard input.
pub fn run_hypersynth(args: &[&str]) -> std::process::Output {
    assert_cmd::Command::cargo_bin("hypersynth")
        .unwrap()
        .arg("-q")
        .args(args)
        .output()
        .unwrap()
}

/// Runs `hypersynth execute CONTROLLER` with `play` piped to its standard input.
pub fn execute(controller: &std::path::Path, play: &str) -> std::process::Output {
    use std::io::Write as _;
    use std::process::{Command, Stdio};
    let mut child = Command::new(assert_cmd::cargo::cargo_bin("hypersynth"))
        .arg("execute")
        .arg(controller)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // A command that stops reading at an error closes its input: what it printed is the test.
    let _ = child.stdin.take().unwrap().write_all(play.as_bytes());
    child.wait_with_output().unwrap()
}

/// The controllers of the bundled examples as `--export-controller` writes them, by name: the
/// case study from its arena text (sigma_L random) and from its map (g = 0.99, uniform), the
/// decoy (psi with its own automaton, g = 0.95, sigma_L the weights of specs/learnt), the three
/// tasks (risk strict) and the case study learnt from specs/learnt's runs (g = 0.99).
pub fn exported_controllers() -> Vec<(&'static str, String)> {
    let dir = tempfile::tempdir().unwrap();
    let examples: [(&str, Vec<&str>, &str); 5] = [
        (
            "case study",
            CASE_STUDY_TASKS.to_vec(),
            "specs/case-study/arena.txt",
        ),
        (
            "case study map",
            [
                CASE_STUDY_TASKS,
                &["--discount", "0.99", "--sigma-l", "uniform"],
            ]
            .concat(),
            "specs/case-study/map.txt",
        ),
        (
            "decoy",
            [
                DECOY_TASKS,
                &["--believed", "F C", "--discount", "0.95"],
                &["--adversary", "specs/learnt/truth.txt"],
            ]
            .concat(),
            "specs/decoy/map.txt",
        ),
        (
            "three tasks",
            [THREE_TASKS, &["--risk", "strict", "--sigma-l", "uniform"]].concat(),
            "specs/decoy/map.txt",
        ),
        (
            "learnt",
            [
                CASE_STUDY_TASKS,
                &[
                    "--discount",
                    "0.99",
                    "--observations",
                    "specs/learnt/runs.txt",
                ],
            ]
            .concat(),
            "specs/case-study/map.txt",
        ),
    ];
    examples
        .into_iter()
        .map(|(name, options, arena)| {
            let file = dir.path().join("controller.json");
            let output = assert_cmd::Command::cargo_bin("hypersynth")
                .unwrap()
                .args(&options)
                .args(["-q", "--export-controller"])
                .arg(&file)
                .arg(arena)
                .output()
                .unwrap();
            assert!(output.status.success(), "{name}: {output:?}");
            (name, std::fs::read_to_string(&file).unwrap())
        })
        .collect()
}

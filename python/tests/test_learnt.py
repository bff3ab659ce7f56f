"""The learnt adversary from Python (solve(observations=..., delta=...)): its report, robust
summary, learning curve and picture equal the command line's on the same files."""

import json
import pathlib

import pytest

import hypersynth as hs
from conftest import CASE_STUDY, PHI, PSI, ROOT, case_study_problem

LEARNT = ROOT / "specs" / "learnt"
RUNS = str(LEARNT / "runs.txt")
TRUTH = LEARNT / "truth.txt"
FLAGS = ["--phi", PHI, "--psi", PSI, "--translator", "builtin", str(CASE_STUDY / "arena.txt"),
         "--discount", "0.99", "--adversary", str(TRUTH), "--observations", RUNS]


@pytest.mark.parametrize("delta", [0.05, 0.2])
def test_the_learnt_report_equals_the_command_lines(cli, delta):
    report = cli(*FLAGS, "--delta", str(delta), "--explain")
    solution = case_study_problem().solve(discount=0.99, sigma_l=pathlib.Path(TRUTH),
                                          observations=RUNS, delta=delta)
    assert json.loads(solution.report(format="json", explain="h0")) == report
    robust = solution.robust
    assert robust == report["robust"]
    # Nominal and robust values at h0, and the decision table with both.
    assert robust["value"] <= robust["nominal_value"]
    assert {row["action"] for row in robust["choices"]} == {"N", "E", "NE", "stop"}
    assert all(row["robust"] <= row["nominal"] + 1e-9 for row in robust["choices"])


def test_the_learning_curve_and_its_picture_equal_the_command_lines(cli, tmp_path):
    svg = tmp_path / "curve.svg"
    report = cli(*FLAGS, "--learning-curve", str(svg), "--learning-curve-runs", "1,10,100,1000")
    solution = case_study_problem().solve(discount=0.99, sigma_l=pathlib.Path(TRUTH),
                                          observations=RUNS)
    curve = solution.learning_curve([1, 10, 100, 1000])
    assert curve == report["robust"]["learning_curve"]
    assert [point["runs"] for point in curve] == [1, 10, 100, 1000]
    assert solution.learning_curve_svg([1, 10, 100, 1000]) == svg.read_text()
    # The default runs: 1, 2, 5, 10, ... then all of them.
    assert [p["runs"] for p in solution.learning_curve()] == [1, 2, 5, 10, 20, 50, 100, 200,
                                                             500, 1000]


def test_learnt_errors_are_located_and_files_are_os_errors(tmp_path):
    problem = case_study_problem()
    bad = tmp_path / "bad.txt"
    bad.write_text('"((0,2),(4,2),0)" N\n')
    with pytest.raises(hs.ParseError) as caught:
        problem.solve(observations=str(bad))
    assert (caught.value.file, caught.value.line) == (str(bad), 1)
    with pytest.raises(FileNotFoundError):
        problem.solve(observations=str(tmp_path / "missing.txt"))
    with pytest.raises(hs.SolveError, match="between 0 and 1"):
        problem.solve(observations=RUNS, delta=1.5)
    with pytest.raises(hs.OptionsError, match="learnt from observations"):
        problem.solve().learning_curve()
    with pytest.raises(hs.OptionsError):
        problem.solve(observations=3)
    # A weights file's errors are located in it.
    weights = tmp_path / "w.txt"
    weights.write_text("nowhere N 1\n")
    with pytest.raises(hs.OptionsError) as caught:
        problem.solve(sigma_l=weights)
    assert (caught.value.file, caught.value.line, caught.value.column) == (str(weights), 1, 1)

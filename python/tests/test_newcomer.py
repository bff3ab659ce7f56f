"""What a newcomer tripped on, each fixed: file errors are OSErrors, the version, the
controller's repr, its answers as typed values, and one convention for values."""

import errno
import pathlib
import re

import pytest

import hypersynth as hs
from conftest import ROOT, case_study_problem, tiny_arena
from test_gym import two_goals


def test_a_missing_file_is_a_file_not_found_error_and_a_hypersynth_error(tmp_path):
    missing = tmp_path / "missing.txt"
    with pytest.raises(FileNotFoundError) as caught:
        hs.Arena.from_file(missing)
    error = caught.value
    assert isinstance(error, hs.FileError) and isinstance(error, hs.Error)
    assert (error.errno, error.filename, error.file) == (errno.ENOENT, str(missing), str(missing))
    assert str(error).startswith(f"{missing}: cannot read: ")
    # Another cause, another OSError: a directory.
    with pytest.raises(IsADirectoryError):
        hs.Arena.from_file(tmp_path)
    with pytest.raises(OSError):
        case_study_problem().solve(sigma_l=missing)


def test_the_version_is_the_packages():
    pyproject = (ROOT / "python" / "pyproject.toml").read_text()
    cargo = (ROOT / "python" / "Cargo.toml").read_text()
    version = re.search(r'^version = "(.*)"$', pyproject, re.M).group(1)
    assert hs.__version__ == version == re.search(r'^version = "(.*)"$', cargo, re.M).group(1)


def test_the_controller_says_where_its_play_is():
    controller = two_goals().controller()
    assert repr(controller) == "<hypersynth.Controller (paper form, phi1, phi2): step 0, uncommitted>"
    controller.step("r")
    controller.step("a")
    controller.step("g2")
    assert repr(controller) == ("<hypersynth.Controller (paper form, phi1, phi2): step 3, "
                                "committed to phi, done>")


def test_answers_are_typed_values():
    # On two_goals (g = 0.9): at r the controller moves (225 > 200); at g1 it stops for phi1,
    # which already holds; at g2 it commits to phi (absorbing), which holds too.
    solution = two_goals()
    controller = solution.controller()
    answer = controller.step("r")
    assert (answer.kind, answer.action, answer.set, str(answer)) == ("move", "go", None, "go")
    assert answer == hs.Controller.from_json(solution.controller_json()).step("r")
    assert controller.step("a") is None
    answer = controller.step("g1")
    assert (answer.kind, answer.action, answer.set, str(answer)) == ("stop", None, "phi1",
                                                                    "stop phi1 done")
    assert controller.step("g1").kind == "done"
    controller.reset()
    for state in ["r", "a"]:
        controller.step(state)
    answer = controller.step("g2")
    assert (answer.kind, answer.action, answer.set, str(answer)) == ("commit", None, "phi",
                                                                    "commit phi done")
    assert repr(answer) == "Answer('commit', set='phi', action=None)".replace(", action=None", "")
    # Nothing can be gained on the tiny arena (the adversary sends the robot back): give up.
    hopeless = hs.Problem(tiny_arena(), phi="F A & F B", psi="F A").solve().controller()
    answer = hopeless.step("r")
    assert (answer.kind, answer.action, answer.set, str(answer)) == ("give up", None, None,
                                                                    "give up")


def test_a_value_is_a_float_and_its_upper_bound_is_named_upper():
    solution = case_study_problem().solve(discount=0.99, sigma_l="uniform")
    state = solution.state_name(5)
    assert isinstance(solution.state_value(state), float)
    assert solution.state_value(state) == solution.values[5]
    assert solution.state_value_upper(state) == solution.values_upper[5]
    assert (solution.state_value(), solution.state_value_upper()) == (solution.value,
                                                                     solution.value_upper)

"""``hypersynth.check`` (docs/semantics.md §9.4): an exported controller's certificate checks,
with bounds around a value computed by hand; a file changed so that a bound is false is refused
with ``CertificateError`` naming the bound and a state; files that are no certified controller
raise the package's other errors."""

import json

import pytest

import hypersynth as hs
from conftest import case_study_problem

# r (robot) -go-> a (adversary) -on-> g (A, B hold), or a -back-> r; g loops; d (C holds) is
# never reached, so the adversary, believing F C, thinks it is winning everywhere and plays
# uniformly over its two moves (both keep the robot out of Win(F C) = {d}).
G = 0.9


def loop_arena():
    builder = hs.ArenaBuilder()
    builder.add_state("r", "robot")
    builder.add_state("a", "adversary")
    builder.add_state("g", "robot", ["A", "B"])
    builder.add_state("d", "robot", ["C"])
    builder.add_transition("r", "go", "a")
    builder.add_transition("a", "on", "g")
    builder.add_transition("a", "back", "r")
    builder.add_transition("g", "stay", "g")
    builder.add_transition("d", "stay", "d")
    builder.set_initial("r")
    return builder.build("loop")


def loop_solution(discount=G):
    problem = hs.Problem(loop_arena(), tasks={"A": "F A", "B": "F B"},
                         payoffs={"A": 200, "B": 100, ("A", "B"): 300}, believed="F C",
                         translator="builtin")
    return problem.solve(discount=discount)


def write(tmp_path, name, file):
    path = tmp_path / name
    path.write_text(file if isinstance(file, str) else json.dumps(file))
    return path


def test_check_certifies_bounds_around_the_hand_computed_value(tmp_path):
    # At g the robot stops for {A, B} and collects 300 at once; from r each round trip costs
    # one robot move: x = g (300 / 2 + x / 2), so x = 150 g / (1 - g / 2).
    value = 150 * G / (1 - G / 2)
    solution = loop_solution()
    path = write(tmp_path, "loop.json", solution.controller_json(certificate=True))
    bounds = hs.check(path)
    assert bounds["lower"] <= value + 1e-9 and value - 1e-9 <= bounds["upper"]
    assert bounds["upper"] - bounds["lower"] <= 1e-6
    # D_L is r, a and g; D_U too (every enabled choice leads there alone).
    assert (bounds["lower_states"], bounds["upper_states"]) == (3, 3)
    # A str path, as the command line takes it, gives the same.
    assert hs.check(str(path)) == bounds


def test_the_case_study_certifies_the_solutions_value(tmp_path):
    solution = case_study_problem().solve(discount=0.99, sigma_l="uniform")
    bounds = hs.check(write(tmp_path, "c.json", solution.controller_json(certificate=True)))
    assert bounds["lower"] <= solution.policy_value <= bounds["upper"]
    assert bounds["lower"] <= solution.value_upper and solution.value <= bounds["upper"]
    assert bounds["upper"] - bounds["lower"] <= 1e-6


@pytest.mark.parametrize("change, bound", [
    # Payoffs halved: the controller collects half of x(r), below the certified L.
    ("halve", "lower"),
    # Undiscounted the robot collects 300 at r, above the certified U (about 245.45).
    ("undiscount", "upper"),
])
def test_a_file_whose_bound_is_false_is_refused(tmp_path, change, bound):
    file = json.loads(loop_solution().controller_json(certificate=True))
    if change == "halve":
        file["payoffs"] = [p / 2 for p in file["payoffs"]]
        file["value"] = [v / 2 for v in file["value"]]
    else:
        file["discount"] = 1.0
    path = write(tmp_path, "changed.json", file)
    with pytest.raises(hs.CertificateError) as raised:
        hs.check(path)
    error = raised.value
    assert error.certificate == bound
    # The state is a product state of the loop: an arena state and the automata's states.
    assert error.state.split("|")[0] in {"r", "a", "g"}
    assert error.inequality
    assert str(error).startswith(f"{path}: the {bound} certificate fails at state `{error.state}`")
    assert isinstance(error, hs.Error)


def test_files_that_are_no_certified_controller_raise(tmp_path):
    solution = loop_solution()
    bare = write(tmp_path, "bare.json", solution.controller_json())
    with pytest.raises(hs.ControllerError, match="has no certificate"):
        hs.check(bare)
    with pytest.raises(hs.ControllerError, match="^" + str(tmp_path)):
        hs.check(write(tmp_path, "empty.json", "{}"))
    with pytest.raises(FileNotFoundError):
        hs.check(tmp_path / "missing.json")


def test_a_learnt_solution_certifies_its_robust_controller(tmp_path):
    # With observations the exported controller is the robust one: its file names the learnt
    # counts and delta, and its certified bounds enclose the robust value (not the nominal
    # one of the options' model).
    solution = case_study_problem().solve(discount=0.99,
                                          observations="specs/learnt/runs.txt", delta=0.05)
    text = solution.controller_json(certificate=True)
    learnt = json.loads(text)["sigma_l"]["learnt"]
    robust = solution.robust
    assert learnt["delta"] == 0.05
    assert sum(c["count"] for c in learnt["counts"]) == robust["counted"]
    bounds = hs.check(write(tmp_path, "robust.json", text))
    assert bounds["lower"] <= robust["value_upper"] and robust["value"] <= bounds["upper"]
    assert bounds["upper"] - bounds["lower"] <= 1e-6
    assert bounds["upper"] < solution.value

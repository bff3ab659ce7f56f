"""``Problem.solve(engine="implicit")`` (docs/python.md): the implicit engine's solution, solved
once, answers every question of the explicit engine's solution alike (values within the
solver's precision, the same states index for index), on the case study (its arena and its
map), a small map and the decoy's general form, at g = 1 and 0.99, sigma_L uniform and
random, with the full and the reachable enumeration and with observations; what it cannot
answer (``Dynamics``) is refused naming the engine."""

import json
import pickle

import numpy as np
import pytest

import hypersynth as hs
from conftest import CASE_STUDY, PHI, PSI, ROOT, case_study_problem

EPS = 2e-6
RUNS = ROOT / "specs" / "learnt" / "runs.txt"
TRUTH = ROOT / "specs" / "learnt" / "truth.txt"

# A small map: A and B in the top corners, an obstacle between the players.
SMALL_MAP = """hypersynth map v1
robot-moves N S E W
adversary-moves N S E W STAY
collision forbidden
first robot
grid
A   .   B
@r  O   .
.   .   @a
"""


def problem_of(name, states="full"):
    if name == "small":
        arena = hs.Arena.from_string(SMALL_MAP, name="small")
        return hs.Problem(arena, phi="F A & F B", psi="F A", translator="builtin",
                          states=states)
    if name == "decoy":
        arena = hs.Arena.from_file(str(ROOT / "specs" / "decoy" / "map.txt"))
        return hs.Problem(arena, tasks={"A": "!O U A", "B": "!O U B", "C": "F C"},
                          payoffs={"A": 200, "B": 100, "C": 50}, believed="F C",
                          translator="builtin", states=states)
    arena = hs.Arena.from_file(str(CASE_STUDY / name))
    return hs.Problem(arena, phi=PHI, psi=PSI, translator="builtin", states=states)


def both(problem, **options):
    implicit = problem.solve(engine="implicit", **options)
    explicit = problem.solve(engine="explicit", **options)
    return implicit, explicit


def close(mine, theirs, where="report"):
    """Equal but for floats, which agree within the precision (expected moves, evaluated to
    a relative precision, within 0.2%)."""
    if isinstance(theirs, float) and isinstance(mine, float):
        rel = 2e-3 if where.endswith("expected_moves") else None
        assert mine == pytest.approx(theirs, abs=EPS, rel=rel), where
    elif isinstance(theirs, dict):
        assert isinstance(mine, dict) and mine.keys() == theirs.keys(), where
        for key in theirs:
            close(mine[key], theirs[key], f"{where}.{key}")
    elif isinstance(theirs, list):
        assert isinstance(mine, list) and len(mine) == len(theirs), where
        for i, (a, b) in enumerate(zip(mine, theirs)):
            close(a, b, f"{where}[{i}]")
    else:
        assert mine == theirs, where


def same_report(mine, theirs):
    """The JSON reports agree but for the engine and the solver's own line; values within the
    precision."""
    mine, theirs = json.loads(mine), json.loads(theirs)
    assert (mine.pop("engine"), theirs.pop("engine")) == ("implicit", "explicit")
    mine.pop("solver", None), theirs.pop("solver", None)
    close(mine, theirs)


def same_table(mine, theirs):
    assert [row["action"] for row in mine["actions"]] == [
        row["action"] for row in theirs["actions"]]
    for a, b in zip(mine["actions"], theirs["actions"]):
        assert a["value"] == pytest.approx(b["value"], abs=EPS)
        assert [o["state"] for o in a["outcomes"]] == [o["state"] for o in b["outcomes"]]
        for x, y in zip(a["outcomes"], b["outcomes"]):
            assert x["probability"] == pytest.approx(y["probability"], abs=1e-12)
            assert x["value"] == pytest.approx(y["value"], abs=EPS)


PROBLEMS = ["arena.txt", "map.txt", "small", "decoy"]
SETTINGS = [(1.0, "uniform"), (0.99, "uniform"), (1.0, "random"), (0.99, "random")]


@pytest.mark.parametrize("name", PROBLEMS)
@pytest.mark.parametrize("discount, sigma_l", SETTINGS)
@pytest.mark.parametrize("states", ["full", "reachable"])
def test_both_engines_solutions_answer_alike(name, discount, sigma_l, states):
    problem = problem_of(name, states)
    implicit, explicit = both(problem, discount=discount, sigma_l=sigma_l)
    assert (implicit.engine, explicit.engine) == ("implicit", "explicit")
    # h0's decision.
    for key in ("value", "value_upper", "policy_value"):
        assert getattr(implicit, key) == pytest.approx(getattr(explicit, key), abs=EPS), key
    assert implicit.value <= implicit.value_upper
    assert implicit.action == explicit.action
    assert implicit.commits_to == explicit.commits_to
    assert implicit.expected_moves == pytest.approx(explicit.expected_moves, rel=2e-3)
    assert implicit.initial_state == explicit.initial_state
    assert implicit.task_names == explicit.task_names
    # The same states, index for index, with the same facts and values.
    assert len(implicit) == len(explicit)
    names = [explicit.state_name(i) for i in range(len(explicit))]
    assert [implicit.state_name(i) for i in range(len(implicit))] == names
    for i in range(0, len(names), max(1, len(names) // 40)):
        assert implicit.state_index(names[i]) == i
    assert implicit.state_index("h0") == explicit.state_index("h0")
    for array in ("is_robot", "arena_states", "best", "guarantees"):
        assert np.array_equal(getattr(implicit, array), getattr(explicit, array)), array
    assert implicit.values.dtype == explicit.values.dtype
    np.testing.assert_allclose(implicit.values, explicit.values, rtol=0, atol=EPS)
    np.testing.assert_allclose(implicit.values_upper, explicit.values_upper, rtol=0, atol=EPS)
    assert implicit.labels == explicit.labels
    # Per state, as the arrays have it.
    for state in ["h0", names[len(names) // 2], names[-1]]:
        i = explicit.state_index(state)
        assert implicit.state_value(state) == pytest.approx(explicit.state_value(state),
                                                            abs=EPS)
        assert implicit.state_value(state) == implicit.values[i]
        assert implicit.state_value_upper(state) == implicit.values_upper[i]
        assert implicit.label(state) == explicit.label(state)
    same_table(implicit.decision_table("h0"), explicit.decision_table("h0"))
    # The reports, the games section and the MDP.
    same_report(implicit.report(format="json"), explicit.report(format="json"))
    games = [json.loads(s.games_json()) for s in (implicit, explicit)]
    assert games[0].pop("engine") == "implicit" and games[1].pop("engine") == "explicit"
    assert games[0] == games[1]
    assert implicit.to_drn() == explicit.to_drn()
    assert implicit.to_drn(form="reachability") == explicit.to_drn(form="reachability")
    assert implicit.robust is None


def test_the_implicit_solution_is_solved_once():
    # Its report is Problem.report's (the same implementation), answered from the kept
    # solution: the solver's figures of one solve, whatever is asked in between.
    problem = case_study_problem("map.txt")
    solution = problem.solve(engine="implicit", discount=0.99, sigma_l="uniform")
    first = solution.report(format="json")
    solution.decision_table("h0"), solution.simulate(50), solution.svg("value")
    assert solution.report(format="json") == first
    assert first == problem.report(format="json", engine="implicit", discount=0.99,
                                   sigma_l="uniform")


# The case study at g = 0.95 with sigma_L random: no two choices tie along the plays, so both
# engines decide alike everywhere (test_engines.py).
DECIDED_ALIKE = {"discount": 0.95, "sigma_l": "random"}


@pytest.mark.parametrize("name", ["arena.txt", "map.txt"])
def test_both_engines_solutions_play_export_and_draw_alike(name, tmp_path):
    problem = problem_of(name)
    implicit, explicit = both(problem, **DECIDED_ALIKE)
    assert implicit.simulate(200, seed=7) == explicit.simulate(200, seed=7)
    assert implicit.simulate(20) == explicit.simulate(20)
    assert implicit.trace(seed=3, max_steps=50) == explicit.trace(seed=3, max_steps=50)
    assert implicit.to_drn(induced=True) == explicit.to_drn(induced=True)
    options = dict(explain="h0", simulate=100, trace=True, max_steps=200)
    same_report(implicit.report(format="json", **options),
                explicit.report(format="json", **options))
    mine = json.loads(implicit.report(format="json", **options))
    theirs = json.loads(explicit.report(format="json", **options))
    assert mine["simulation"] == theirs["simulation"] and mine["trace"] == theirs["trace"]
    # The text report but for the engine's and the solver's lines.
    texts = [[line for line in s.report().splitlines()
              if not line.startswith(("product", "solver"))] for s in (implicit, explicit)]
    assert texts[0] == texts[1]
    # The controller's file, but for its value; both certificates check.
    files = [json.loads(s.controller_json()) for s in (implicit, explicit)]
    assert files[0].keys() == files[1].keys()
    for key in files[1]:
        if key == "value":
            assert files[0][key] == pytest.approx(files[1][key], abs=EPS)
        else:
            assert files[0][key] == files[1][key], key
    for engine, solution in [("implicit", implicit), ("explicit", explicit)]:
        path = tmp_path / f"{engine}.json"
        path.write_text(solution.controller_json(certificate=True))
        certified = hs.check(path)
        assert certified["lower"] == pytest.approx(explicit.value, abs=1e-4)
        answer = solution.controller().step("((0,2),(4,2),0)")
        assert (answer.kind, answer.action) == ("move", "N")
    if name == "map.txt":
        for picture in ["map", "partition", "value", "trace"]:
            assert implicit.svg(picture) == explicit.svg(picture), picture
        assert implicit._repr_svg_() == explicit._repr_svg_()
    else:
        assert implicit._repr_svg_() is None


@pytest.mark.parametrize("name", ["arena.txt", "map.txt"])
@pytest.mark.parametrize("discount", [0.99, 1.0])
def test_both_engines_solutions_learn_alike(name, discount, tmp_path):
    problem = problem_of(name)
    options = dict(discount=discount, sigma_l=TRUTH, observations=RUNS)
    implicit, explicit = both(problem, **options)
    mine, theirs = implicit.robust, explicit.robust
    assert mine.keys() == theirs.keys()
    for key in ("value", "value_upper", "nominal_value", "nominal_value_upper",
                "worst_case_value"):
        assert mine[key] == pytest.approx(theirs[key], abs=EPS), key
    for key in ("runs", "counted", "pairs", "sigma_l_states", "never_observed", "action",
                "nominal_action"):
        assert mine[key] == theirs[key], key
    # The nominal solution under sigma_L alike.
    assert implicit.value == pytest.approx(explicit.value, abs=EPS)
    np.testing.assert_allclose(implicit.values, explicit.values, rtol=0, atol=EPS)
    assert implicit.to_drn() == explicit.to_drn()
    curves = [s.learning_curve([1, 10, 1000]) for s in (implicit, explicit)]
    assert [p["runs"] for p in curves[0]] == [p["runs"] for p in curves[1]] == [1, 10, 1000]
    for a, b in zip(*curves):
        for key in ("value", "nominal_value"):
            assert a[key] == pytest.approx(b[key], abs=EPS), key
    assert implicit.learning_curve_svg([1, 1000])[:4] == "<svg"
    assert implicit.learning_curve([]) == explicit.learning_curve([])
    # The robust controller, certified to collect the robust value.
    path = tmp_path / "robust.json"
    path.write_text(implicit.controller_json(certificate=True))
    certified = hs.check(path)
    assert certified["lower"] >= mine["value"] - EPS
    assert certified["upper"] <= mine["value_upper"] + EPS


def test_both_engines_refuse_alike():
    implicit, explicit = both(case_study_problem(), discount=0.99, sigma_l="uniform")
    for state in ["nowhere", "((9,9),(4,2),0)|0|0", "((0,2),(4,2),0)|7|0", "((0,2),(4,2),0)"]:
        errors = []
        for solution in (implicit, explicit):
            with pytest.raises(hs.ParseError) as error:
                solution.state_value(state)
            errors.append(str(error.value))
            with pytest.raises(hs.ParseError):
                solution.decision_table(state)
        assert errors[0] == errors[1], state
    for solution in (implicit, explicit):
        with pytest.raises(IndexError, match="out of range"):
            solution.state_name(len(solution))
        with pytest.raises(hs.OptionsError, match="^a learning curve needs"):
            solution.learning_curve()
        with pytest.raises(hs.OptionsError, match="^a learning curve needs"):
            solution.learning_curve_svg()
        with pytest.raises(hs.OptionsError, match="^form: "):
            solution.to_drn(form="sideways")
        with pytest.raises(hs.OptionsError, match="^picture: "):
            solution.svg("sideways")
    with pytest.raises(hs.OptionsError, match="^engine: `sideways` is not one of"):
        case_study_problem().solve(engine="sideways")


def test_dynamics_needs_the_explicit_engines_solution():
    solution = case_study_problem().solve(engine="implicit", discount=0.99)
    with pytest.raises(hs.OptionsError, match='^engine: Dynamics needs .*engine="explicit"'):
        hs.Dynamics(solution)


def test_an_implicit_solution_pickles_as_one():
    solution = case_study_problem("map.txt").solve(engine="implicit", discount=0.99,
                                                   sigma_l="uniform")
    again = pickle.loads(pickle.dumps(solution))
    assert again.engine == "implicit"
    assert again.value == solution.value
    assert json.loads(again.report(format="json"))["engine"] == "implicit"
    assert case_study_problem().solve().engine == "explicit"

"""``Problem.report(engine=...)`` (docs/engines.md): the implicit engine's report of the case
study, on its arena and on its map, equals the explicit engine's but for the engine's name and
the solver's own line, values within the solver's precision; what the implicit engine does not
make is refused naming it; bad options are refused naming the argument."""

import json

import pytest

import hypersynth as hs
from conftest import case_study_problem


def reports(problem, **options):
    implicit = json.loads(problem.report(format="json", engine="implicit", **options))
    explicit = json.loads(problem.report(format="json", engine="explicit", **options))
    return implicit, explicit


@pytest.mark.parametrize("arena", ["arena.txt", "map.txt"])
@pytest.mark.parametrize("discount, sigma_l", [(0.99, "uniform"), (1.0, "random")])
def test_both_engines_report_the_same(arena, discount, sigma_l):
    problem = case_study_problem(arena)
    implicit, explicit = reports(problem, discount=discount, sigma_l=sigma_l)
    assert (implicit["engine"], explicit["engine"]) == ("implicit", "explicit")
    for key in explicit:
        if key in ("engine", "solver", "initial"):
            continue
        assert implicit[key] == explicit[key], key
    mine, theirs = implicit["initial"], explicit["initial"]
    for key in ("state", "label", "ranks", "action", "adversary_first"):
        assert mine[key] == theirs[key], key
    for key in ("value", "value_upper", "policy_value", "policy_value_upper"):
        assert mine[key] == pytest.approx(theirs[key], abs=1e-6), key
    assert mine["expected_moves"] == pytest.approx(theirs["expected_moves"], rel=2e-3)
    # The explicit engine's report is the solution's.
    solution = problem.solve(discount=discount, sigma_l=sigma_l)
    assert theirs["value"] == solution.value and theirs["action"] == solution.action


def test_games_only_leaves_the_mdp_stage_out():
    implicit, explicit = reports(case_study_problem("map.txt"), games_only=True)
    assert "settings" not in implicit and "settings" not in explicit
    assert implicit["partition"] == explicit["partition"]
    text = case_study_problem().report(games_only=True)
    product = next(line for line in text.splitlines() if line.startswith("product"))
    assert product.endswith("(full; implicit engine)")


def test_what_the_implicit_engine_does_not_make_is_refused():
    problem = case_study_problem()
    weights = {"((4,4),(0,2),1)": {"N": 1.0}}
    with pytest.raises(hs.OptionsError, match="^engine: the implicit engine does not support "
                                              "a weight table"):
        problem.report(discount=0.99, sigma_l=weights)
    # The explicit engine makes it.
    assert problem.report(engine="explicit", discount=0.99, sigma_l=weights)


@pytest.mark.parametrize("options, argument", [
    ({"engine": "sideways"}, "engine"),
    ({"format": "yaml"}, "format"),
    ({"discount": 1.5}, "discount"),
    ({"discount": 0.99, "epsilon": -1.0}, "epsilon"),
])
def test_bad_options_name_their_argument(options, argument):
    with pytest.raises(hs.OptionsError, match=f"^{argument}: "):
        case_study_problem().report(**options)


def test_a_solve_past_its_sweep_limit_raises_solve_error():
    # The implicit solve at g = 0.999 needs more than two sweeps of the case study's cycles.
    with pytest.raises(hs.SolveError):
        case_study_problem().report(discount=0.999, sigma_l="uniform", max_iterations=2)

"""``Problem.report(engine=...)`` (docs/engines.md): the implicit engine's report of the case
study, on its arena and on its map, equals the explicit engine's but for the engine's name and
the solver's own line, values within the solver's precision, sigma_L a weight table included
(given as values or as a file, and refused alike when bad); bad options are refused naming the
argument."""

import json

import pytest

import hypersynth as hs
from conftest import CASE_STUDY, PHI, PSI, ROOT, case_study_problem

# sigma_L from a weight table: values on two of the case study's adversary states (a weight 0
# and an unlisted action among them), and the learnt example's file.
WEIGHTS = {"((4,4),(0,2),1)": {"N": 1.0, "E": 0.0}, "((0,2),(4,2),1)": {"S": 2.0, "STAY": 0.5}}
TRUTH = ROOT / "specs" / "learnt" / "truth.txt"


def reports(problem, **options):
    implicit = json.loads(problem.report(format="json", engine="implicit", **options))
    explicit = json.loads(problem.report(format="json", engine="explicit", **options))
    return implicit, explicit


@pytest.mark.parametrize("arena", ["arena.txt", "map.txt"])
@pytest.mark.parametrize("discount, sigma_l", [
    (0.99, "uniform"), (1.0, "random"), (0.99, WEIGHTS), (1.0, TRUTH),
])
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


@pytest.mark.parametrize("arena", ["arena.txt", "map.txt"])
def test_both_engines_report_the_same_on_the_reachable_states(arena):
    problem = hs.Problem(hs.Arena.from_file(str(CASE_STUDY / arena)), phi=PHI, psi=PSI,
                         translator="builtin", states="reachable")
    implicit, explicit = reports(problem, discount=0.99, sigma_l="uniform")
    full, _ = reports(case_study_problem(arena), discount=0.99, sigma_l="uniform")
    assert implicit["states"] == explicit["states"] == "reachable"
    assert 0 < implicit["product_states"] < full["product_states"]
    for key in explicit:
        if key in ("engine", "solver", "initial"):
            continue
        assert implicit[key] == explicit[key], key
    assert implicit["initial"]["action"] == explicit["initial"]["action"] == "N"
    # The reachable states are closed under moves: h0's value is the full enumeration's.
    assert implicit["initial"]["value"] == pytest.approx(full["initial"]["value"], abs=2e-6)


def test_games_only_leaves_the_mdp_stage_out():
    implicit, explicit = reports(case_study_problem("map.txt"), games_only=True)
    assert "settings" not in implicit and "settings" not in explicit
    assert implicit["partition"] == explicit["partition"]
    text = case_study_problem().report(games_only=True)
    product = next(line for line in text.splitlines() if line.startswith("product"))
    assert product.endswith("(full; implicit engine)")


@pytest.mark.parametrize("arena", ["arena.txt", "map.txt"])
def test_both_engines_refuse_a_bad_weight_table_alike(arena):
    problem = case_study_problem(arena)
    for weights in [{"((4,4),(0,2),1)": {"NE": 1.0}}, {"((0,2),(4,2),0)": {"N": 1.0}},
                    {"nowhere": {"N": 1.0}}]:
        errors = []
        for engine in ["implicit", "explicit"]:
            with pytest.raises(hs.OptionsError) as error:
                problem.report(engine=engine, discount=0.99, sigma_l=weights)
            errors.append(str(error.value))
        assert errors[0] == errors[1]
        state = next(iter(weights))
        assert errors[0].startswith(f'sigma_l["{state}"]'), errors[0]


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


# The case study at g = 0.95 with sigma_L random: no two choices tie along the plays, so both
# engines decide alike everywhere (tests/controller_export.rs finds the same file but for the
# value on the command line).
DECIDED_ALIKE = {"discount": 0.95, "sigma_l": "random"}


@pytest.mark.parametrize("arena", ["arena.txt", "map.txt"])
def test_both_engines_export_the_same_controller(arena, tmp_path):
    problem = case_study_problem(arena)
    files = {engine: json.loads(problem.controller_json(engine=engine, **DECIDED_ALIKE))
             for engine in ["implicit", "explicit"]}
    implicit, explicit = files["implicit"], files["explicit"]
    assert implicit.keys() == explicit.keys()
    for key in explicit:
        if key == "value":
            assert implicit[key] == pytest.approx(explicit[key], abs=2e-6)
        else:
            assert implicit[key] == explicit[key], key
    # Both play alike, step by step, and their certificates check.
    for engine in ["implicit", "explicit"]:
        controller = problem.controller(engine=engine, **DECIDED_ALIKE)
        answer = controller.step("((0,2),(4,2),0)")
        assert (answer.kind, answer.action) == ("move", "N")
        path = tmp_path / f"{engine}.json"
        path.write_text(problem.controller_json(engine=engine, certificate=True,
                                                **DECIDED_ALIKE))
        certified = hs.check(path)
        assert certified["lower"] <= implicit["value"][1] + 2e-6
        assert certified["upper"] >= implicit["value"][0] - 2e-6


def test_both_engines_explain_simulate_and_trace_alike():
    problem = case_study_problem("map.txt")
    options = dict(DECIDED_ALIKE, explain="h0", simulate=100, trace=True, max_steps=200)
    implicit, explicit = reports(problem, **options)
    assert implicit["simulation"] == explicit["simulation"]
    assert implicit["trace"] == explicit["trace"]
    mine, theirs = implicit["explain"], explicit["explain"]
    assert [row["action"] for row in mine["actions"]] == [row["action"]
                                                         for row in theirs["actions"]]
    for a, b in zip(mine["actions"], theirs["actions"]):
        assert a["value"] == pytest.approx(b["value"], abs=2e-6)
    # The explicit engine's report is the solution's.
    solution = problem.solve(**DECIDED_ALIKE)
    assert json.loads(solution.report(format="json", simulate=100, trace=True,
                                      max_steps=200))["simulation"] == explicit["simulation"]



RUNS = ROOT / "specs" / "learnt" / "runs.txt"


@pytest.mark.parametrize("arena", ["arena.txt", "map.txt"])
@pytest.mark.parametrize("discount", [0.99, 1.0])
def test_both_engines_learn_the_same_robust_stage(arena, discount, tmp_path):
    # The learnt example: the case study with its true sigma_L and the 1000 runs recorded
    # against it.
    problem = case_study_problem(arena)
    options = dict(discount=discount, sigma_l=TRUTH, observations=RUNS)
    implicit, explicit = reports(problem, simulate=200, **options)
    mine, theirs = implicit["robust"], explicit["robust"]
    for key in ("observations", "delta", "runs", "counted", "sigma_w_steps", "misfits", "pairs",
                "sigma_l_states", "never_observed", "action", "nominal_action"):
        assert mine[key] == theirs[key], key
    for key in ("value", "value_upper", "nominal_value", "nominal_value_upper",
                "worst_case_value"):
        assert mine[key] == pytest.approx(theirs[key], abs=2e-6), key
    assert [c["action"] for c in mine["choices"]] == [c["action"] for c in theirs["choices"]]
    # The explicit engine's robust stage is the solution's.
    solution = problem.solve(**options)
    assert theirs["value"] == solution.robust["value"]
    # The implicit engine's robust controller collects the robust value, certified.
    path = tmp_path / "robust.json"
    path.write_text(problem.controller_json(engine="implicit", certificate=True, **options))
    certified = hs.check(path)
    assert certified["lower"] >= mine["value"] - 2e-6
    assert certified["upper"] <= mine["value_upper"] + 2e-6
    answer = problem.controller(engine="implicit", **options).step("((0,2),(4,2),0)")
    assert answer.kind == "move"

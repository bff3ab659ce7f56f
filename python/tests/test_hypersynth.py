"""The Python package against the command line's JSON reports, hand-checked tiny arenas, its
errors, interruption and threads."""

import json
import os
import shlex
import signal
import threading
import time

import numpy as np
import pytest

import hypersynth as hs
from conftest import CASE_STUDY, PHI, PSI, ROOT, tiny_arena


def case_study(**solve):
    arena = hs.Arena.from_file(str(CASE_STUDY / "arena.txt"))
    return hs.Problem(arena, phi=PHI, psi=PSI, translator="builtin").solve(**solve)


@pytest.mark.parametrize(
    "options, flags",
    [
        ({}, []),
        ({"discount": 0.99, "sigma_l": "uniform"}, ["--discount", "0.99", "--sigma-l", "uniform"]),
    ],
)
def test_case_study_equals_the_command_line(cli, options, flags):
    report = cli(
        "--phi", PHI, "--psi", PSI, "--translator", "builtin",
        str(CASE_STUDY / "arena.txt"), "--explain", *flags,
    )
    solution = case_study(**options)
    initial = report["initial"]
    assert solution.value == initial["value"]
    assert solution.value_upper == initial["value_upper"]
    assert solution.policy_value == initial["policy_value"]
    assert solution.expected_moves == initial["expected_moves"]
    assert solution.action == initial["action"]
    assert solution.initial_state == initial["state"]
    # The decision table of h0, row by row.
    assert solution.decision_table("h0") == report["explain"]
    # The win-labels: the partition's counts per label, from the labels of every state.
    robot = solution.is_robot
    counts = {}
    for label, is_robot in zip(solution.labels, robot):
        key = label.strip("()").replace(", ", "")
        side = "robot" if is_robot else "adversary"
        counts.setdefault(key, {"robot": 0, "adversary": 0})[side] += 1
    for key, expected in report["partition"].items():
        got = counts.get(key, {"robot": 0, "adversary": 0})
        assert (got["robot"], got["adversary"]) == (expected["robot"], expected["adversary"])
    # The whole JSON report is the command line's.
    ours = json.loads(solution.report(format="json", explain="h0"))
    assert ours == report


def test_the_discounted_case_study_as_the_readme_states_it():
    # docs/guide.md, the case study: value of h0 294.02 with N (E and NE 290.77; stop 200), 2.0 expected robot moves.
    solution = case_study(discount=0.99, sigma_l="uniform")
    assert round(solution.value, 2) == 294.02
    table = {row["action"]: row["value"] for row in solution.decision_table()["actions"]}
    assert {a: round(v, 2) for a, v in table.items()} == {
        "N": 294.02, "E": 290.77, "NE": 290.77, "stop": 200.0
    }
    assert solution.label() == "(W, L, L)"


def test_the_general_form_equals_the_command_line(cli):
    arena = str(ROOT / "specs" / "decoy" / "arena.txt")
    report = cli(
        arena, "--translator", "builtin", "--task", "A=!O U A", "--task", "B=!O U B",
        "--task", "C=F C", "--payoff", "A=200", "--payoff", "B=100", "--payoff", "C=50",
        "--payoff", "A,B=350", "--believed", "!O U A", "--discount", "0.95", "--explain",
    )
    problem = hs.Problem(
        hs.Arena.from_file(arena),
        tasks={"A": "!O U A", "B": "!O U B", "C": "F C"},
        payoffs={"A": 200, "B": 100, "C": 50, ("A", "B"): 350},
        believed="!O U A",
        translator="builtin",
    )
    assert problem.form == "general"
    solution = problem.solve(discount=0.95)
    assert json.loads(solution.report(format="json", explain="h0")) == report


def test_weights_given_as_values_equal_the_command_lines_weights_file(cli):
    # One problem through both faces: sigma_L's weights as the file the command line reads,
    # and as a dict of the same entries (read here with the file format's quoting rules).
    weights = ROOT / "specs" / "learnt" / "truth.txt"
    table = {}
    for line in weights.read_text().splitlines():
        fields = shlex.split(line, comments=True)
        if fields:
            state, action, weight = fields
            table.setdefault(state, {})[action] = float(weight)
    report = cli(
        "--phi", PHI, "--psi", PSI, "--translator", "builtin", str(CASE_STUDY / "arena.txt"),
        "--discount", "0.99", "--adversary", str(weights), "--explain",
    )
    solution = case_study(discount=0.99, sigma_l=table)
    ours = json.loads(solution.report(format="json", explain="h0"))
    # Only where sigma_L comes from differs: the file, or the argument.
    assert report["settings"].pop("sigma_l") == f"file:{weights}"
    assert ours["settings"].pop("sigma_l") == "file:sigma_l"
    assert ours == report


def test_hoa_tasks_equal_the_command_lines_hoa_files(cli, tmp_path):
    phi1 = hs.translate(PSI, translator="builtin")
    phi2 = hs.translate("!O U B", translator="builtin")
    files = []
    for name, automaton in [("phi1.hoa", phi1), ("phi2.hoa", phi2)]:
        files.append(tmp_path / name)
        files[-1].write_text(automaton.hoa)
    arena = str(CASE_STUDY / "arena.txt")
    report = cli(
        "--phi1-hoa", str(files[0]), "--phi2-hoa", str(files[1]), arena, "--explain",
        "--sigma-l", "uniform",
    )
    solution = hs.Problem(hs.Arena.from_file(arena), psi=phi1.hoa, phi2=phi2.hoa).solve(
        sigma_l="uniform")
    ours = json.loads(solution.report(format="json", explain="h0"))
    # The automata are named after their files on the command line, after the arguments here.
    for key in ("phi", "automata"):
        report.pop(key), ours.pop(key)
    assert ours == report


def test_the_tasks_errors_name_the_python_argument():
    arena = tiny_arena()
    general = {"tasks": {"A": "F A", "B": "F B"}, "believed": "F A"}
    error = located(hs.ParseError, lambda: hs.Problem(
        arena, tasks={"A": "F A", "B": "F (B"}, believed="F A"))
    assert (error.file, error.line, error.column) == ("tasks[B]", 1, 5)
    error = located(hs.TranslationError, lambda: hs.Problem(
        arena, tasks={"A": "F A", "B": "F B | G A"}, believed="F A"))
    assert (error.file, error.line, error.column) == ("tasks[B]", 1, 7)
    error = located(hs.ParseError, lambda: hs.Problem(
        arena, tasks={"A": "F A"}, believed="HOA: v1\nStates: x\n"))
    assert (error.file, error.line) == ("believed", 2)
    error = located(hs.TaskError, lambda: hs.Problem(
        arena, tasks={"A": "F A", "1B": "F B"}, believed="F A"))
    assert str(error).startswith("`1B` is not a sub-task name")
    error = located(hs.TaskError, lambda: hs.Problem(
        arena, tasks={f"T{i}": "F A" for i in range(9)}, believed="F A"))
    assert str(error) == "at most 8 sub-tasks are supported, got 9"
    for payoffs, message in [
        ({"A,X": 3}, "payoffs: no sub-task is named `X` (give it in tasks)"),
        ({("A", "A"): 3}, "payoffs: `A` is listed twice"),
        ({(): 3}, "payoffs: a key names no sub-task"),
        ({"A": -1.0}, "payoffs: invalid payoff `-1` (a finite number >= 0)"),
        ({"A,B": 1, ("B", "A"): 2}, "payoffs: the payoff of this set is given twice"),
        ({"A": 200, "A,B": 100}, "payoffs: payoffs must be monotone: a set of sub-tasks pays "
                                 "at least as much as each of its subsets, but r(A) = 200 > "
                                 "r(A,B) = 100"),
    ]:
        error = located(hs.TaskError, lambda: hs.Problem(arena, payoffs=payoffs, **general))
        assert str(error) == message, payoffs
    error = located(hs.TaskError, lambda: hs.Problem(arena, phi="F A & F B", psi="F A", r=250))
    assert str(error).startswith("payoffs must be positive with r >= r1 + r2")
    problem = hs.Problem(arena, **general)
    error = located(hs.OptionsError, lambda: problem.solve(epsilon=0))
    assert str(error) == "epsilon: invalid precision 0: epsilon must be a positive finite number"


def test_a_tiny_arena_by_hand():
    arena = tiny_arena()
    assert len(arena) == 3
    assert arena.names == ["r", "a", "g"]
    assert arena.owners == ["robot", "adversary", "robot"]
    assert arena.labels == [set(), set(), {"A", "B"}]
    # phi1 = F A cannot be forced (the adversary sends the robot back forever), so the
    # adversary, believing phi1, thinks it is winning everywhere the robot is not at g and
    # plays uniformly among the moves that keep the robot from A: only `back`. Nothing is
    # gained from r.
    solution = hs.Problem(arena, phi="F A & F B", psi="F A", translator="builtin").solve()
    assert (solution.value, solution.value_upper) == (0.0, 0.0)
    assert solution.label() == "(L, L, L)"
    # At g both tasks hold: value r = 300 (phi1's and phi2's DFAs both in their final state).
    values = solution.values
    names = [solution.state_name(i) for i in range(len(solution))]
    final = [i for i, n in enumerate(names) if n.startswith("g|1|1")]
    assert final and all(values[i] == 300.0 for i in final)


def test_arrays_are_numpy_buffers_of_every_product_state():
    solution = case_study(discount=0.99, sigma_l="uniform")
    n = len(solution)
    for array, dtype in [
        (solution.values, np.float64), (solution.values_upper, np.float64),
        (solution.is_robot, np.bool_), (solution.best, np.uint8),
        (solution.guarantees, np.float64), (solution.arena_states, np.uint32),
    ]:
        assert isinstance(array, np.ndarray) and array.dtype == dtype and array.shape == (n,)
    h0 = solution.state_index("h0")
    assert solution.values[h0] == solution.value
    # One convention: a value is its lower bound, a float; the upper bound is `_upper`.
    assert solution.state_value("h0") == solution.value
    assert isinstance(solution.state_value("h0"), float)
    assert solution.state_value_upper("h0") == solution.value_upper
    assert np.all(solution.values <= solution.values_upper)


def test_simulation_trace_drn_svg_and_controller():
    solution = case_study(discount=0.99, sigma_l="uniform")
    simulation = solution.simulate(200, seed=7)
    assert simulation["runs"] == 200
    assert sum(simulation["satisfied"].values()) + simulation["none"] + simulation[
        "step_bound"] + simulation["adversary_stuck"] == 200
    trace = solution.trace(seed=7)
    assert trace["steps"][0]["state"] == solution.initial_state
    assert trace["steps"][0]["action"] == "N"
    # The DRN is the one `make case-study` exports with the same options.
    assert solution.to_drn() == (CASE_STUDY / "mdp-discounted.drn").read_text()
    # The reachability form: no reward model, goal and fail instead of the sink, r_max = 300.
    reward = solution.to_drn(form="reward")
    reachability = solution.to_drn(form="reachability")
    assert reachability.startswith("// hypersynth MDP, reachability form: 300 * Pmax=? [F \"goal\"]")
    assert "@reward_models\n\n@nr_states" in reachability
    assert reachability.count("\nstate ") == reward.count("\nstate ") + 1
    assert " goal\n" in reachability and " fail\n" in reachability
    with pytest.raises(hs.OptionsError):
        solution.to_drn(form="rewards")
    with pytest.raises(hs.OptionsError):
        solution.svg("partition")  # a text arena, not a map
    controller = solution.controller()
    # The controller's first answer at h0's arena state is the solution's action.
    assert str(controller.step("((0,2),(4,2),0)")) == "N"
    controller.reset()
    assert str(controller.step("((0,2),(4,2),0)")) == "N"


def test_a_map_arena_draws():
    arena = hs.Arena.from_file(str(CASE_STUDY / "map.txt"))
    assert arena._repr_svg_().startswith("<svg")
    solution = hs.Problem(arena, phi=PHI, psi=PSI, translator="builtin").solve(
        discount=0.99, sigma_l="uniform")
    assert solution._repr_svg_().startswith("<svg")


def test_hoa_text_is_a_task():
    phi1 = hs.translate("!O U A", translator="builtin")
    phi2 = hs.translate("!O U B", translator="builtin")
    assert (phi1.num_states, phi1.propositions) == (3, ["O", "A"])
    arena = hs.Arena.from_file(str(CASE_STUDY / "arena.txt"))
    from_hoa = hs.Problem(arena, psi=phi1.hoa, phi2=phi2.hoa).solve(discount=0.99)
    from_formulas = hs.Problem(arena, phi=PHI, psi=PSI, translator="builtin").solve(discount=0.99)
    assert from_hoa.value == from_formulas.value


def located(kind, call):
    with pytest.raises(kind) as caught:
        call()
    assert isinstance(caught.value, hs.Error)
    return caught.value


def test_errors_are_located():
    bad_arena = "propositions A\nstate x robot {A}\nstate y sideways {}\n"
    error = located(hs.ParseError, lambda: hs.Arena.from_string(bad_arena, name="bad.txt"))
    assert (error.file, error.line, error.column) == ("bad.txt", 3, 9)
    assert str(error).startswith("bad.txt:3:9: ")
    arena = tiny_arena()
    error = located(hs.ParseError, lambda: hs.Problem(arena, phi="F (A", psi="F A"))
    assert (error.file, error.line) == ("phi", 1)
    error = located(hs.TaskError, lambda: hs.Problem(arena, phi="F A & F B", psi="F C"))
    assert (error.file, error.line, error.column) == ("psi", 1, 1)
    problem = hs.Problem(arena, phi="F A & F B", psi="F A")
    located(hs.OptionsError, lambda: problem.solve(discount=1.5))
    located(hs.OptionsError, lambda: problem.solve(sigma_l="sometimes"))
    error = located(hs.OptionsError, lambda: problem.solve(sigma_l={"nowhere": {"on": 1}}))
    # Weights are values, not a text: the error names the entry.
    assert (error.file, error.line) == ("sigma_l", None)
    assert str(error) == 'sigma_l["nowhere"]["on"]: no arena state is named `nowhere`'
    error = located(hs.OptionsError, lambda: problem.solve(sigma_l={"a": {"on": -1}}))
    assert str(error) == 'sigma_l["a"]["on"]: invalid weight `-1` (a finite number >= 0)'
    located(hs.TaskError, lambda: hs.Problem(
        arena, tasks={"A": "F A", "B": "F B"}, payoffs={"A": 300, ("A", "B"): 200},
        believed="F A"))
    solution = problem.solve()
    error = located(hs.ParseError, lambda: solution.decision_table("nowhere|0|0"))
    assert (error.file, error.line, error.column) == ("state", 1, 1)
    located(hs.ArenaError, lambda: hs.ArenaBuilder().add_transition("x", "go", "y"))
    located(hs.ControllerError, lambda: hs.Controller.from_json("{}"))


def gridworld_map(size):
    """A `size`×`size` map: the robot at the south-west corner, the adversary at the north-east
    one, A at the north-west corner and B at the south-east one."""
    rows = []
    for y in reversed(range(size)):
        row = ["."] * size
        if y == size - 1:
            row[0], row[-1] = "A", "@a"
        if y == 0:
            row[0], row[-1] = "@r", "B"
        rows.append(" ".join(row))
    header = ["hypersynth map v1", "robot-moves N S E W NE NW SE SW",
              "adversary-moves N S E W STAY", "collision forbidden", "first robot", "grid"]
    return "\n".join(header + rows) + "\n"


def large_problem(size):
    return hs.Problem(hs.Arena.from_map(gridworld_map(size), name=f"{size}x{size}"),
                      phi="(!O U A) & (!O U B)", psi="!O U A", translator="builtin")


def test_ctrl_c_stops_a_long_solve_within_a_second():
    # A shell that starts the suite in the background starts it with SIGINT ignored, and Python
    # then installs no handler of its own: install Python's, as an interactive start would have.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        ctrl_c_stops_a_long_solve_within_a_second()
    finally:
        signal.signal(signal.SIGINT, previous)


def ctrl_c_stops_a_long_solve_within_a_second():
    problem = large_problem(30)
    sent = []

    def interrupt():
        time.sleep(1.0)
        sent.append(time.monotonic())
        os.kill(os.getpid(), signal.SIGINT)

    threading.Thread(target=interrupt).start()
    start = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        problem.solve(discount=0.999, epsilon=1e-12)
    stopped = time.monotonic()
    assert sent, f"the solve ended after {stopped - start:.1f} s, before the interruption"
    assert stopped - sent[0] < 1.0
    # The interpreter is usable, and so is the problem.
    assert hs.Problem(tiny_arena(), phi="F A & F B", psi="F A").solve().value == 0.0


def test_two_threads_solve_as_one():
    alone = case_study(discount=0.99, sigma_l="uniform")
    results = [None, None]

    def solve(i):
        results[i] = case_study(discount=0.99, sigma_l="uniform")

    threads = [threading.Thread(target=solve, args=(i,)) for i in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for solution in results:
        assert solution.value == alone.value
        assert np.array_equal(solution.values, alone.values)


def test_the_drn_in_stormpy_gives_the_value(tmp_path):
    stormpy = pytest.importorskip("stormpy", reason="stormpy is not installed")
    solution = case_study(discount=0.99, sigma_l="uniform")
    path = tmp_path / "mdp.drn"
    path.write_text(solution.to_drn())
    model = stormpy.build_model_from_drn(str(path))
    formula = stormpy.parse_properties('R{"r"}max=? [C]')[0]
    result = stormpy.model_checking(model, formula)
    value = result.at(model.initial_states[0])
    assert solution.value - 1e-6 <= value <= solution.value_upper + 1e-6
    # The reachability form: r_max times the probability of reaching goal.
    path.write_text(solution.to_drn(form="reachability"))
    model = stormpy.build_model_from_drn(str(path))
    formula = stormpy.parse_properties('Pmax=? [F "goal"]')[0]
    value = 300 * stormpy.model_checking(model, formula).at(model.initial_states[0])
    assert abs(value - solution.value) <= 1e-6 * solution.value

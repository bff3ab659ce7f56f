"""The Gymnasium environment (hypersynth.gym, over hypersynth.Dynamics): its dynamics by hand on
a tiny arena, its draws against the library's simulation, returns against the controller's
value, Gymnasium's checker, the registered ids, and runs recorded for the learnt adversary."""

import math
import pathlib

import numpy as np
import pytest

import hypersynth as hs
from conftest import CASE_STUDY, PHI, PSI, ROOT, case_study_problem, needs

gymnasium = needs("gymnasium")
from gymnasium.utils.env_checker import check_env  # noqa: E402

import hypersynth.gym as hgym  # noqa: E402

TRUTH = ROOT / "specs" / "learnt" / "truth.txt"


def two_goals(initial="r"):
    """r -go-> a (adversary); a -x-> g1 (A holds), a -y-> g2 (A and B hold); g1, g2 loop.

    With phi = F A & F B and psi = F A, a is in Win(psi) (both moves reach A), so the adversary
    plays sigma_L there; g2 is (W,W,W) (commits, r = 300), g1 is (W,L,L) (stop pays r1 = 200;
    looping gains nothing). With g = 0.9 and sigma_L uniform, v(r) = max(200, 0.9 * (0.5 * 200
    + 0.5 * 300)) = 225, by `go`.
    """
    builder = hs.ArenaBuilder()
    builder.add_state("r", "robot")
    builder.add_state("a", "adversary")
    builder.add_state("g1", "robot", ["A"])
    builder.add_state("g2", "robot", ["A", "B"])
    builder.add_transition("r", "go", "a")
    builder.add_transition("a", "x", "g1")
    builder.add_transition("a", "y", "g2")
    builder.add_transition("g1", "stay", "g1")
    builder.add_transition("g2", "stay", "g2")
    builder.set_initial(initial)
    arena = builder.build("two goals")
    return hs.Problem(arena, phi="F A & F B", psi="F A", translator="builtin").solve(
        discount=0.9, sigma_l="uniform")


def episode(env, policy, seed=None):
    """One episode of `policy(observation, info)`: its discounted return (gamma = the solve's
    discount), the arena states it passed, and the last info."""
    observation, info = env.reset(seed=seed)
    passed = list(info["passed"])
    total, weight, done = 0.0, 1.0, False
    while not done:
        observation, reward, terminated, truncated, info = env.step(policy(observation, info))
        assert env.observation_space.contains(observation)
        total += weight * reward
        weight *= env.unwrapped.discount
        passed += info["passed"]
        done = terminated or truncated
    return total, passed, info


def test_the_dynamics_by_hand():
    solution = two_goals()
    assert abs(solution.value - 225.0) < 1e-5
    stop = lambda actions: actions.index("stop")  # noqa: E731
    # The adversary answers y: the move into g2's absorption pays g * 300 at once.
    env = hgym.HypergameEnv(solution, adversary=lambda state, actions: "y")
    assert env.actions == ("go", "x", "y", "stay", "stop")
    observation, info = env.reset()
    assert info["passed"] == ("r",) and info["moves"] == 0
    # At r (W,L,L): go and stop.
    assert list(info["action_mask"]) == [1, 0, 0, 0, 1]
    observation, reward, terminated, truncated, info = env.step(0)
    assert (reward, terminated, truncated) == (pytest.approx(0.9 * 300), True, False)
    assert info["passed"] == ("a", "g2") and info["outcome"] == "absorbed"
    assert env.unwrapped.dynamics.run == "r go a y g2"
    # The adversary answers x: g1, where stop pays 200 at once (after one move: 0.9 * 200).
    env = hgym.HypergameEnv(solution, adversary=lambda state, actions: {"x": 2.0, "y": 0.0})
    total, passed, info = episode(env, lambda o, i: 0 if i["moves"] == 0 else stop(env.actions))
    assert total == pytest.approx(0.9 * 200) and passed == ["r", "a", "g1"]
    assert info["outcome"] == "stop"
    # The model (uniform at a): the mean return is v(r) = 225, within its 99% interval.
    env = hgym.HypergameEnv(solution)
    returns = [episode(env, lambda o, i: 0 if i["moves"] == 0 else 4, seed=s)[0]
               for s in range(2000)]
    assert set(np.round(returns, 9)) == {round(0.9 * 300, 9), round(0.9 * 200, 9)}
    mean, half = np.mean(returns), 2.576 * np.std(returns, ddof=1) / math.sqrt(len(returns))
    assert abs(mean - 225.0) <= half


def test_a_masked_action_ends_the_episode_with_nothing():
    env = hgym.HypergameEnv(two_goals())
    env.reset(seed=0)
    observation, reward, terminated, truncated, info = env.step(env.actions.index("stay"))
    assert (reward, terminated, truncated) == (0.0, True, False)
    assert info["outcome"] == "masked action" and not info["action_mask"].any()
    with pytest.raises(hs.OptionsError, match="reset"):
        env.step(0)


def test_a_play_absorbed_before_the_robot_moves_offers_only_stop():
    # h0 at g2 (W,W,W) commits without moving: stop collects r = 300, undiscounted.
    env = hgym.HypergameEnv(two_goals(initial="g2"))
    observation, info = env.reset()
    assert list(info["action_mask"]) == [0, 0, 0, 0, 1]
    assert env.step(4)[1:3] == (300.0, True)


def test_the_step_bound_truncates():
    # go (a move), x (a move), then stay: the third move reaches max_steps = 3.
    env = hgym.HypergameEnv(two_goals(), adversary=lambda s, a: "x", max_steps=3)
    env.reset()
    assert env.step(0)[2:4] == (False, False)
    observation, reward, terminated, truncated, info = env.step(env.actions.index("stay"))
    assert (reward, terminated, truncated) == (0.0, False, True)
    assert info["outcome"] == "step bound"


def test_a_bad_adversary_answer_is_an_options_error():
    solution = two_goals()
    for answer, message in [("z", "`z`"), ({"x": -1}, "weight -1"), ({"x": 0}, "all 0"),
                            (3, "3")]:
        env = hgym.HypergameEnv(solution, adversary=lambda s, a, answer=answer: answer)
        env.reset()
        with pytest.raises(hs.OptionsError, match=message):
            env.step(0)
    with pytest.raises(hs.OptionsError):
        hs.Dynamics(solution, adversary="uniform")


def test_seeded_episodes_draw_as_the_librarys_simulation():
    # One u64 of ChaCha8 per adversary move, as Solution.trace draws it: until the controller
    # commits (where the environment ends), the episode under the controller is the trace.
    solution = case_study_problem().solve(discount=0.99, sigma_l="uniform")
    env = hgym.HypergameEnv(solution)
    policy = solution.controller().as_policy()
    compared = 0
    for seed in range(30):
        _, passed, info = episode(env, policy, seed=seed)
        traced = [step["state"].rsplit("|", 2)[0] for step in solution.trace(seed=seed)["steps"]]
        common = min(len(passed), len(traced))
        assert passed[:common] == traced[:common], seed
        compared += common
        # The same seed gives the same episode.
        assert episode(env, policy, seed=seed)[1] == passed
    assert compared > 30 * 5


@pytest.mark.parametrize("discount", [0.99, 1.0])
def test_the_controllers_returns_average_its_policy_value(discount):
    solution = case_study_problem().solve(discount=discount, sigma_l="uniform")
    env = hgym.HypergameEnv(solution)
    policy = solution.controller().as_policy()
    returns = [episode(env, policy, seed=1 if i == 0 else None)[0] for i in range(2000)]
    mean = float(np.mean(returns))
    half = 2.576 * float(np.std(returns, ddof=1)) / math.sqrt(len(returns))
    # At g = 1 every episode collects 300 (the robot can wait for its chance): the interval is
    # a point, and the certified value is 300 within rounding.
    tolerance = max(half, 1e-9 * 300)
    assert abs(mean - solution.policy_value) <= tolerance, (mean, half, solution.policy_value)


def test_gymnasiums_checker_passes():
    check_env(hgym.HypergameEnv(case_study_problem().solve(discount=0.99)), skip_render_check=True)
    for name in ["CaseStudy", "Decoy", "ThreeTasks"]:
        env = gymnasium.make(f"hypersynth/{name}-v0", render_mode="ansi")
        check_env(env.unwrapped)


def test_registered_ids_observe_cells_on_maps():
    env = gymnasium.make("hypersynth/CaseStudy-v0", max_steps=50)
    assert env.unwrapped.dynamics.max_steps == 50
    assert round(env.unwrapped.solution.value, 2) == 294.02
    names = env.unwrapped.solution.problem.arena.names
    observation, info = env.reset(seed=3)
    done = False
    while not done:
        robot, adversary = observation["robot"], observation["adversary"]
        assert names[observation["arena_state"]].startswith(
            f"(({robot[0]},{robot[1]}),({adversary[0]},{adversary[1]}),")
        mask = info["action_mask"]
        observation, _, terminated, truncated, info = env.step(int(np.flatnonzero(mask)[0]))
        done = terminated or truncated
    # Overrides reach the solve.
    assert gymnasium.make("hypersynth/CaseStudy-v0", discount=1.0).unwrapped.discount == 1.0


def test_recorded_runs_learn_as_the_command_line(cli, tmp_path):
    # The loop closed: episodes against a weights-file truth, recorded, then learnt from by
    # Problem.solve(observations=...) and by the command line from the same file.
    problem = case_study_problem()
    truth = problem.solve(discount=0.99, sigma_l=pathlib.Path(TRUTH))
    env = hgym.RecordRuns(hgym.HypergameEnv(truth))
    policy = truth.controller().as_policy()
    for i in range(300):
        episode(env, policy, seed=i)
    runs = tmp_path / "runs.txt"
    env.write(runs)
    assert len(runs.read_text().splitlines()) == 300
    learnt = problem.solve(discount=0.99, sigma_l=pathlib.Path(TRUTH), observations=str(runs))
    report = cli("--phi", PHI, "--psi", PSI, "--translator", "builtin",
                 str(CASE_STUDY / "arena.txt"), "--discount", "0.99", "--adversary", str(TRUTH),
                 "--observations", str(runs))
    robust = report["robust"]
    assert robust["runs"] == 300 and robust["counted"] > 0
    assert abs(learnt.robust["value"] - robust["value"]) <= 1e-9
    assert learnt.robust == robust
    # Runs given as lines learn the same, named <observations>.
    again = problem.solve(discount=0.99, sigma_l=pathlib.Path(TRUTH), observations=env.runs)
    assert again.robust["value"] == robust["value"]
    assert again.robust["observations"] == "<observations>"


def test_the_bundled_maps_are_the_specs():
    maps = ROOT / "python" / "hypersynth" / "maps"
    for name in ["case-study", "decoy"]:
        assert (maps / f"{name}.txt").read_text() == (ROOT / "specs" / name / "map.txt").read_text()

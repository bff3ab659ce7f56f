"""A Gymnasium environment of a problem: ``HypergameEnv`` (needs ``pip install hypersynth[gym]``).

One step is one robot move. The adversary answers by its model (sigma_W where it believes it
is winning, sigma_L elsewhere: the solve's ``sigma_l``, uniform, random or a weights table) or
by a callable, until the robot's turn or absorption. The rules are the hypergame MDP's (see
``hypersynth.Dynamics``, which this wraps): the reward is ``g * payoff`` on the move into an
absorbing state and the payoff at once on ``stop``, so that the expected return with gamma = g
(the solve's discount) is the MDP's value of the policy; ``Controller.as_policy()`` collects
``Solution.policy_value``.

Registered ids (``gymnasium.make(ID, **overrides)`` once ``hypersynth.gym`` is imported, or
``gymnasium.make("hypersynth.gym:ID")``): ``hypersynth/CaseStudy-v0`` (the paper's case study
on its map, discount 0.99, uniform sigma_L), ``hypersynth/Decoy-v0`` (the decoy example: the
adversary believes the robot heads for C) and ``hypersynth/ThreeTasks-v0`` (three sub-tasks
and a bonus).
"""

import os
import tempfile
from importlib import resources
from typing import Any, Callable, Dict, List, Mapping, Optional, Tuple, Union

import numpy as np

try:
    import gymnasium
    from gymnasium import spaces
except ImportError:  # pragma: no cover - exercised without the extra
    raise ImportError("hypersynth.gym needs Gymnasium: pip install 'hypersynth[gym]'") from None

from ._hypersynth import Arena, Dynamics, Problem, Solution

Observation = Dict[str, Any]
Adversary = Callable[[str, Tuple[str, ...]], Union[str, Mapping[str, float]]]


class HypergameEnv(gymnasium.Env):  # type: ignore[misc]
    """The Gymnasium environment of a solved problem (a ``Solution``, or a ``Problem`` solved
    with ``solve_options``).

    - Observations (a ``Dict`` space, Markov: the product state): ``arena_state`` (the arena
      state's index in ``Arena.names``), ``automata`` (the automata's states, one per automaton
      of the product), and on a map ``robot`` and ``adversary`` (their cells ``(x, y)``).
    - Actions (``Discrete``): the arena's actions, then ``stop`` (``actions`` names them).
      ``info["action_mask"]`` (and ``action_masks()``) says which are enabled. A masked action
      ends the episode with reward 0 (``info["outcome"] == "masked action"``), as giving up
      does: no policy gains by it, and ``check_env``'s random actions are answered.
    - Rewards: ``g * payoff`` on the move into absorption (a commitment, a stuck player), the
      payoff at once on ``stop``, 0 otherwise. ``terminated`` at absorption and after
      ``stop``; ``truncated`` when ``max_steps`` moves (of either player) were made.
    - ``info``: ``action_mask``, ``passed`` (the arena states entered since the last
      observation, the current last: what a controller is told), ``moves`` (robot moves so
      far), ``state`` (the product state's name), ``outcome`` (how the episode ended: ``stop``,
      ``absorbed``, ``masked action``, ``step bound``; None before).
    - Randomness: ``reset(seed=s)`` seeds the stream of adversary moves (ChaCha8, one draw per
      move, as ``Solution.simulate`` draws); ``reset()`` goes on with it; never seeded, it
      starts from the solve's seed.
    - ``adversary``: a callable ``adversary(state, actions)`` replacing the model (see
      ``hypersynth.Dynamics``).

    >>> env = hs.gym.HypergameEnv(solution)
    >>> observation, info = env.reset(seed=1)
    >>> observation["arena_state"] == problem.arena.names.index("((0,2),(4,2),0)")
    True
    >>> [a for a, m in zip(env.actions, info["action_mask"]) if m]
    ['N', 'E', 'NE', 'stop']
    >>> env.step(env.actions.index("stop"))[1:3]
    (200.0, True)
    """

    metadata = {"render_modes": ["ansi"]}

    def __init__(
        self,
        solution: Union[Solution, Problem],
        *,
        adversary: Optional[Adversary] = None,
        max_steps: int = 1000,
        render_mode: Optional[str] = None,
        **solve_options: Any,
    ) -> None:
        """The environment of ``solution`` (a ``Problem`` is solved with ``solve_options``).

        >>> hs.gym.HypergameEnv(problem, discount=0.99, sigma_l="uniform").discount
        0.99
        """
        if isinstance(solution, Problem):
            solution = solution.solve(**solve_options)
        elif solve_options:
            raise TypeError("solve options are for a Problem, not a Solution")
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode {render_mode!r} is not one of {self.metadata['render_modes']}")
        self.solution = solution
        self.dynamics = Dynamics(solution, adversary=adversary, max_steps=max_steps)
        self.actions: Tuple[str, ...] = tuple(self.dynamics.actions)
        self.discount: float = self.dynamics.discount
        self.render_mode = render_mode
        self.action_space = spaces.Discrete(len(self.actions))
        observation: Dict[str, spaces.Space[Any]] = {
            "arena_state": spaces.Discrete(self.dynamics.num_arena_states),
            "automata": spaces.MultiDiscrete(np.array(self.dynamics.automata_sizes, dtype=np.int64)),
        }
        grid = self.dynamics.grid
        if grid is not None:
            observation["robot"] = spaces.MultiDiscrete(np.array(grid, dtype=np.int64))
            observation["adversary"] = spaces.MultiDiscrete(np.array(grid, dtype=np.int64))
        self.observation_space = spaces.Dict(observation)

    def _observation(self) -> Observation:
        dynamics = self.dynamics
        observation: Observation = {
            "arena_state": dynamics.arena_state,
            "automata": np.array(dynamics.automata, dtype=np.int64),
        }
        cells = dynamics.cells
        if cells is not None:
            observation["robot"] = np.array(cells[:2], dtype=np.int64)
            observation["adversary"] = np.array(cells[2:], dtype=np.int64)
        return observation

    def _info(self) -> Dict[str, Any]:
        dynamics = self.dynamics
        return {
            "action_mask": dynamics.action_mask,
            "passed": tuple(dynamics.passed),
            "moves": dynamics.moves,
            "state": dynamics.state,
            "outcome": dynamics.outcome,
        }

    def reset(
        self, *, seed: Optional[int] = None, options: Optional[Dict[str, Any]] = None
    ) -> Tuple[Observation, Dict[str, Any]]:
        """Starts an episode in h0 (the adversary moving first if it owns h0); ``seed`` seeds
        the stream of adversary moves.

        >>> env = hs.gym.HypergameEnv(solution)
        >>> env.reset(seed=1)[1]["passed"]
        ('((0,2),(4,2),0)',)
        """
        super().reset(seed=seed)
        self.dynamics.reset(seed=seed)
        return self._observation(), self._info()

    def step(self, action: Any) -> Tuple[Observation, float, bool, bool, Dict[str, Any]]:
        """Plays the robot's ``action`` (an index of ``actions``) and the adversary's answer.

        >>> env = hs.gym.HypergameEnv(solution)
        >>> _ = env.reset(seed=1)
        >>> observation, reward, terminated, truncated, info = env.step(env.actions.index("N"))
        >>> reward, terminated, info["passed"]
        (0.0, False, ('((0,3),(4,2),1)', '((0,3),(3,2),0)'))
        """
        reward, terminated, truncated = self.dynamics.step(int(action))
        return self._observation(), float(reward), bool(terminated), bool(truncated), self._info()

    def action_masks(self) -> "np.ndarray[Any, np.dtype[np.bool_]]":
        """The enabled actions as booleans (the method sb3-contrib's ``MaskablePPO`` asks).

        >>> env = hs.gym.HypergameEnv(solution)
        >>> _ = env.reset(seed=1)
        >>> int(env.action_masks().sum())
        4
        """
        return np.asarray(self.dynamics.action_mask, dtype=bool)

    def render(self) -> Optional[str]:
        """With ``render_mode="ansi"``: the product state, the robot moves so far and the
        outcome, as a line.

        >>> env = hs.gym.HypergameEnv(solution, render_mode="ansi")
        >>> _ = env.reset(seed=1)
        >>> env.render()
        '((0,2),(4,2),0)|0|0 after 0 robot moves'
        """
        if self.render_mode != "ansi":
            return None
        dynamics = self.dynamics
        line = f"{dynamics.state} after {dynamics.moves} robot moves"
        if dynamics.outcome is not None:
            line += f": {dynamics.outcome}"
        return line


class RecordRuns(gymnasium.Wrapper):  # type: ignore[misc]
    """Records every episode of a ``HypergameEnv`` as one run of the observations format
    (arena states and both players' actions; ``stop`` left out), so that
    ``Problem.solve(observations=recorder.runs)`` (or a file ``write`` wrote) learns sigma_L
    from them. An episode is recorded when it ends, or when ``reset`` starts another.

    >>> env = hs.gym.RecordRuns(hs.gym.HypergameEnv(solution))
    >>> policy = solution.controller().as_policy()
    >>> for episode in range(3):
    ...     observation, info = env.reset(seed=episode)
    ...     done = False
    ...     while not done:
    ...         observation, reward, terminated, truncated, info = env.step(policy(observation, info))
    ...         done = terminated or truncated
    >>> len(env.runs)
    3
    """

    def __init__(self, env: gymnasium.Env) -> None:
        """Records the episodes of ``env`` (a ``HypergameEnv``, perhaps wrapped).

        >>> hs.gym.RecordRuns(hs.gym.HypergameEnv(solution)).runs
        []
        """
        super().__init__(env)
        self.runs: List[str] = []
        self._open = False

    def reset(self, **kwargs: Any) -> Tuple[Observation, Dict[str, Any]]:
        """Starts an episode (recording the one that was going on, if any).

        >>> env = hs.gym.RecordRuns(hs.gym.HypergameEnv(solution))
        >>> _ = env.reset(seed=1)
        >>> _ = env.reset(seed=2)
        >>> env.runs
        ['"((0,2),(4,2),0)"']
        """
        if self._open:
            self.runs.append(self._dynamics().run)
        result = self.env.reset(**kwargs)
        self._open = True
        return result  # type: ignore[no-any-return]

    def step(self, action: Any) -> Tuple[Observation, float, bool, bool, Dict[str, Any]]:
        """Steps the environment; an episode that ends is recorded.

        >>> env = hs.gym.RecordRuns(hs.gym.HypergameEnv(solution))
        >>> _ = env.reset(seed=1)
        >>> _ = env.step(env.unwrapped.actions.index("stop"))
        >>> env.runs
        ['"((0,2),(4,2),0)"']
        """
        observation, reward, terminated, truncated, info = self.env.step(action)
        if terminated or truncated:
            self.runs.append(self._dynamics().run)
            self._open = False
        return observation, float(reward), terminated, truncated, info

    def _dynamics(self) -> Dynamics:
        unwrapped = self.env.unwrapped
        if not isinstance(unwrapped, HypergameEnv):
            raise TypeError("RecordRuns records a hypersynth.gym.HypergameEnv")
        return unwrapped.dynamics

    def write(self, path: Union[str, "os.PathLike[str]"]) -> None:
        """Writes the runs recorded to ``path`` in the observations format, atomically (a
        temporary file renamed over it).

        >>> import tempfile, pathlib
        >>> env = hs.gym.RecordRuns(hs.gym.HypergameEnv(solution))
        >>> _ = env.reset(seed=1)
        >>> _ = env.step(env.unwrapped.actions.index("stop"))
        >>> path = pathlib.Path(tempfile.mkdtemp()) / "runs.txt"
        >>> env.write(path)
        >>> path.read_text()
        '"((0,2),(4,2),0)"\\n'
        """
        text = "".join(run + "\n" for run in self.runs)
        directory = os.path.dirname(os.path.abspath(os.fspath(path)))
        handle, temporary = tempfile.mkstemp(dir=directory, prefix=".runs-")
        try:
            with os.fdopen(handle, "w") as file:
                file.write(text)
            os.replace(temporary, path)
        except BaseException:
            os.unlink(temporary)
            raise


def _map(name: str) -> Arena:
    text = resources.files("hypersynth").joinpath("maps", f"{name}.txt").read_text()
    return Arena.from_map(text, name=f"{name} map")


def case_study(**options: Any) -> HypergameEnv:
    """The paper's case study on its map (``specs/case-study/map.txt``): phi = (!O U A) &
    (!O U B), the adversary believing psi = !O U A, discount 0.99, uniform sigma_L; keyword
    arguments override the solve's options and the environment's.

    >>> env = hs.gym.case_study()
    >>> round(env.solution.value, 2)
    294.02
    """
    return _environment(
        Problem(_map("case-study"), phi="(!O U A) & (!O U B)", psi="!O U A", translator="builtin"),
        options,
    )


def decoy(**options: Any) -> HypergameEnv:
    """The decoy example (``specs/decoy``): tasks A = !O U A (200) and B = !O U B (100), the
    adversary believing the robot heads for C (F C), discount 0.95, uniform sigma_L.

    >>> hs.gym.decoy().solution.problem.task_names
    ['A', 'B']
    """
    problem = Problem(
        _map("decoy"),
        tasks={"A": "!O U A", "B": "!O U B"},
        payoffs={"A": 200, "B": 100},
        believed="F C",
        translator="builtin",
    )
    return _environment(problem, {"discount": 0.95, **options})


def three_tasks(**options: Any) -> HypergameEnv:
    """Three sub-tasks with a bonus (``specs/three-tasks``): A (200), B (100), C = F C (50), all
    three 500, the adversary believing !O U A, discount 0.95, uniform sigma_L.

    >>> hs.gym.three_tasks().solution.problem.task_names
    ['A', 'B', 'C']
    """
    problem = Problem(
        _map("decoy"),
        tasks={"A": "!O U A", "B": "!O U B", "C": "F C"},
        payoffs={"A": 200, "B": 100, "C": 50, ("A", "B", "C"): 500},
        believed="!O U A",
        translator="builtin",
    )
    return _environment(problem, {"discount": 0.95, **options})


_ENVIRONMENT_OPTIONS = ("adversary", "max_steps", "render_mode")


def _environment(problem: Problem, options: Dict[str, Any]) -> HypergameEnv:
    options = {"discount": 0.99, "sigma_l": "uniform", **options}
    environment = {k: options.pop(k) for k in _ENVIRONMENT_OPTIONS if k in options}
    return HypergameEnv(problem.solve(**options), **environment)


for _id, _entry in [
    ("hypersynth/CaseStudy-v0", "case_study"),
    ("hypersynth/Decoy-v0", "decoy"),
    ("hypersynth/ThreeTasks-v0", "three_tasks"),
]:
    if _id not in gymnasium.registry:
        gymnasium.register(id=_id, entry_point=f"hypersynth.gym:{_entry}")

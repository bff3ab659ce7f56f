"""Sweeps: ``solve_many`` solves problems on any ``concurrent.futures`` executor, and
``Result`` is what a solve sends back (small, picklable)."""

import dataclasses
import json
from concurrent.futures import Executor
from typing import Any, Dict, Iterable, List, Mapping, Optional, Tuple, Union

from ._hypersynth import Problem, Solution


@dataclasses.dataclass(frozen=True)
class Result:
    """What ``solve_many`` gives for one problem: the problem, ``solve``'s options, and the
    command line's JSON report of the solution (a dict), with its key figures as attributes.
    Results pickle (they hold no solved state) and compare by options and report. Fields:
    ``problem`` (the problem solved), ``options`` (what ``Problem.solve`` was given),
    ``report`` (the JSON report, ``Solution.report(format="json")``, parsed).

    >>> result = hs.solve_many([problem], discount=0.99, sigma_l="uniform")[0]
    >>> round(result.value, 2), result.action, result.options
    (294.02, 'N', {'discount': 0.99, 'sigma_l': 'uniform'})
    >>> result.report["initial"]["action"]
    'N'
    """

    problem: Problem = dataclasses.field(compare=False, repr=False)
    options: Dict[str, Any]
    report: Dict[str, Any] = dataclasses.field(repr=False)

    @property
    def value(self) -> float:
        """The value of h0 (its certified lower bound).

        >>> round(hs.solve_many([problem], discount=0.99, sigma_l="uniform")[0].value, 2)
        294.02
        """
        return float(self.report["initial"]["value"])

    @property
    def value_upper(self) -> float:
        """The certified upper bound of the value of h0.

        >>> result = hs.solve_many([problem], discount=0.99)[0]
        >>> result.value <= result.value_upper
        True
        """
        return float(self.report["initial"]["value_upper"])

    @property
    def policy_value(self) -> float:
        """What the controller collects from h0 (lower bound).

        >>> result = hs.solve_many([problem], discount=0.99)[0]
        >>> abs(result.policy_value - result.value) < 1e-5
        True
        """
        return float(self.report["initial"]["policy_value"])

    @property
    def action(self) -> Optional[str]:
        """The controller's action at h0.

        >>> hs.solve_many([problem], discount=0.99, sigma_l="uniform")[0].action
        'N'
        """
        action = self.report["initial"].get("action")
        return None if action is None else str(action)

    @property
    def robust(self) -> Optional[Dict[str, Any]]:
        """The robust stage's summary when sigma_L was learnt from observations
        (``Solution.robust``), else None.

        >>> hs.solve_many([problem], discount=0.99)[0].robust is None
        True
        """
        robust = self.report.get("robust")
        return None if robust is None else dict(robust)

    def solution(self) -> Solution:
        """Solves the problem again here, with the same options: the whole ``Solution``.

        >>> result = hs.solve_many([problem], discount=0.99)[0]
        >>> result.solution().value == result.value
        True
        """
        return self.problem.solve(**self.options)


def _solve(problem: Problem, options: Mapping[str, Any]) -> Result:
    """Solves one problem and keeps its report: what runs on a worker."""
    solution = problem.solve(**options)
    report = json.loads(solution.report(format="json"))
    return Result(problem=problem, options=dict(options), report=report)


Task = Union[Problem, Tuple[Problem, Mapping[str, Any]]]


def solve_many(
    problems: Iterable[Task], executor: Optional[Executor] = None, **options: Any
) -> List[Result]:
    """Solves each problem (a ``Problem``, or a ``(Problem, options)`` pair whose options
    override ``options``) with ``Problem.solve(**options)``, and returns their ``Result``s in
    order. ``executor`` is any ``concurrent.futures.Executor``: a thread pool (solves release
    the GIL), a process pool, or Dask's ``Client.get_executor()`` to solve on a cluster (problems
    and results are pickled there and back); None solves here, one after the other.

    >>> sweep = [(problem, {"discount": g}) for g in (0.9, 0.99)]
    >>> [round(r.value, 2) for r in hs.solve_many(sweep, sigma_l="uniform")]
    [232.2, 294.02]
    """
    tasks: List[Tuple[Problem, Dict[str, Any]]] = []
    for task in problems:
        if isinstance(task, tuple):
            problem, given = task
            tasks.append((problem, {**options, **given}))
        else:
            tasks.append((task, dict(options)))
    if executor is None:
        return [_solve(problem, given) for problem, given in tasks]
    futures = [executor.submit(_solve, problem, given) for problem, given in tasks]
    return [future.result() for future in futures]

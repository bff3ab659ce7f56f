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
    Results pickle (they hold no solved state) and compare by everything but the problem.
    Fields: ``problem`` (the problem solved), ``options`` (what ``Problem.solve`` was given),
    ``report`` (the JSON report, ``Solution.report(format="json")``, parsed), and the
    solution's ``value``, ``value_upper``, ``policy_value``, ``action`` and ``robust`` (see
    ``Solution``).

    >>> result = hs.solve_many([problem], discount=0.99, sigma_l="uniform")[0]
    >>> round(result.value, 2), result.action, result.options
    (294.02, 'N', {'discount': 0.99, 'sigma_l': 'uniform'})
    >>> result.report["initial"]["action"]
    'N'
    """

    problem: Problem = dataclasses.field(compare=False, repr=False)
    options: Dict[str, Any]
    report: Dict[str, Any] = dataclasses.field(repr=False)
    value: float
    value_upper: float
    policy_value: float
    action: Optional[str]
    robust: Optional[Dict[str, Any]] = dataclasses.field(repr=False)

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
    return Result(
        problem=problem,
        options=dict(options),
        report=json.loads(solution.report(format="json")),
        value=solution.value,
        value_upper=solution.value_upper,
        policy_value=solution.policy_value,
        action=solution.action,
        robust=solution.robust,
    )


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
    [244.08, 294.02]
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

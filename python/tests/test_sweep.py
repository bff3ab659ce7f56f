"""Sweeps past one machine: problems, arenas, automata, solutions and results pickle; solve_many
on a thread pool and on a Dask LocalCluster gives the sequential results."""

import pickle
from concurrent.futures import ThreadPoolExecutor

import hypersynth as hs
from conftest import CASE_STUDY, PHI, PSI, ROOT, case_study_problem, needs, tiny_arena


def test_arenas_automata_and_problems_pickle_through_their_inputs():
    for arena in [hs.Arena.from_file(str(CASE_STUDY / "arena.txt")),
                  hs.Arena.from_file(str(CASE_STUDY / "map.txt")), tiny_arena()]:
        again = pickle.loads(pickle.dumps(arena))
        assert (again.name, again.is_map, again.to_text()) == (arena.name, arena.is_map,
                                                              arena.to_text())
    for automaton in [hs.translate(PSI, translator="builtin"),
                      hs.Automaton.from_hoa(hs.translate("F A", translator="builtin").hoa, "f")]:
        again = pickle.loads(pickle.dumps(automaton))
        assert (again.hoa, again.name, again.translator) == (automaton.hoa, automaton.name,
                                                             automaton.translator)
    arena = hs.Arena.from_file(str(ROOT / "specs" / "decoy" / "arena.txt"))
    problems = [
        case_study_problem(),
        hs.Problem(arena, tasks={"A": "!O U A", "B": hs.translate("!O U B", "builtin")},
                   payoffs={("A", "B"): 350}, believed="!O U A", risk="strict",
                   translator="builtin", states="reachable"),
        hs.Problem(arena, psi=hs.translate(PSI, "builtin"), phi2="!O U B", r1=150),
    ]
    for problem in problems:
        again = pickle.loads(pickle.dumps(problem))
        ours, theirs = (p.solve(discount=0.95, sigma_l="uniform") for p in (problem, again))
        assert repr(again) == repr(problem)
        assert ours.report(format="json") == theirs.report(format="json")


def test_solutions_and_results_pickle():
    solution = case_study_problem().solve(discount=0.99, sigma_l="random", seed=5)
    again = pickle.loads(pickle.dumps(solution))
    assert again.report(format="json") == solution.report(format="json")
    [result] = hs.solve_many([case_study_problem()], discount=0.99)
    assert pickle.loads(pickle.dumps(result)) == result


def sweep():
    """8 problems: the case study and the decoy's general form at four discounts."""
    decoy = hs.Problem(hs.Arena.from_file(str(ROOT / "specs" / "decoy" / "arena.txt")),
                       tasks={"A": "!O U A", "B": "!O U B"}, payoffs={"A": 200, "B": 100},
                       believed="F C", translator="builtin")
    return [(problem, {"discount": g}) for problem in (case_study_problem(), decoy)
            for g in (0.9, 0.95, 0.99, 1.0)]


def test_a_thread_pool_gives_the_sequential_results():
    sequential = hs.solve_many(sweep(), sigma_l="uniform")
    assert len(sequential) == 8 and len({r.value for r in sequential}) > 4
    with ThreadPoolExecutor(max_workers=4) as pool:
        assert hs.solve_many(sweep(), executor=pool, sigma_l="uniform") == sequential
    # Each result is what the problem's own solve reports.
    problem, options = sweep()[2]
    assert sequential[2].value == problem.solve(sigma_l="uniform", **options).value


def test_a_dask_cluster_gives_the_sequential_results():
    needs("dask")
    distributed = needs("distributed")
    sequential = hs.solve_many(sweep(), sigma_l="uniform")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            results = hs.solve_many(sweep(), executor=client.get_executor(), sigma_l="uniform")
    assert results == sequential

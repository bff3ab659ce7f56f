"""The README's case study from Python: the paper's 5x5 gridworld, phi = (!O U A) & (!O U B),
the adversary believing psi = !O U A, discounted by 0.99 against a uniform sigma_L.

    python python/examples/case_study.py        # from the repository's root
"""

import pathlib

import hypersynth as hs

ROOT = pathlib.Path(__file__).resolve().parents[2]

arena = hs.Arena.from_file(ROOT / "specs" / "case-study" / "arena.txt")
problem = hs.Problem(arena, phi="(!O U A) & (!O U B)", psi="!O U A")
solution = problem.solve(discount=0.99, sigma_l="uniform")

print(f"h0 = {solution.initial_state}, win-label {solution.label()}")
print(f"value of h0 in [{solution.value:.6f}, {solution.value_upper:.6f}]")
print(f"first move {solution.action}, {solution.expected_moves:.1f} expected robot moves")
for row in solution.decision_table()["actions"]:
    print(f"  {row['action']:>4}  value {row['value']:8.2f}  moves {row['expected_moves']:.1f}")
simulation = solution.simulate(10_000)
print(f"10 000 runs: mean payoff {simulation['mean_payoff']:.2f} "
      f"[{simulation['ci_low']:.2f}, {simulation['ci_high']:.2f}]")
robot = solution.is_robot
print(f"{robot.sum()} robot product states, {(solution.values[robot] > 0).sum()} of positive value")

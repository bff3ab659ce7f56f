"""The value of h0 in the case study as the discount varies, plotted with matplotlib when it is
installed (to discount_sweep.png), printed otherwise.

    python python/examples/discount_sweep.py
"""

import pathlib

import hypersynth as hs

ROOT = pathlib.Path(__file__).resolve().parents[2]

arena = hs.Arena.from_file(ROOT / "specs" / "case-study" / "arena.txt")
problem = hs.Problem(arena, phi="(!O U A) & (!O U B)", psi="!O U A")
discounts = [0.80, 0.85, 0.90, 0.93, 0.95, 0.97, 0.98, 0.99, 0.995, 1.0]
values = []
for discount in discounts:
    solution = problem.solve(discount=discount, sigma_l="uniform")
    values.append(solution.value)
    print(f"discount {discount:<6} value {solution.value:8.3f}  first move {solution.action}")

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    print("(matplotlib is not installed: no plot)")
else:
    figure, axes = plt.subplots(figsize=(5, 3.5))
    axes.plot(discounts, values, marker="o")
    axes.set_xlabel("discount")
    axes.set_ylabel("value of h0")
    axes.set_title("Case study, uniform sigma_L")
    figure.tight_layout()
    figure.savefig("discount_sweep.png", dpi=150)
    print("wrote discount_sweep.png")

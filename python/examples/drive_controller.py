"""Drives the exported controller step by step against a simulated adversary, as a robot's
control loop would: observe the arena state, ask the controller, play its action.

The adversary here plays uniformly at random among its moves (it need not follow the model the
controller was computed for: the controller says when a move was off its model).

    python python/examples/drive_controller.py [SEED]
"""

import pathlib
import random
import sys

import hypersynth as hs

ROOT = pathlib.Path(__file__).resolve().parents[2]

arena = hs.Arena.from_file(ROOT / "specs" / "case-study" / "arena.txt")
problem = hs.Problem(arena, phi="(!O U A) & (!O U B)", psi="!O U A")
solution = problem.solve(discount=0.99, sigma_l="uniform")
# The controller travels as a file (format hypersynth-controller/2); read it back to run it.
controller = hs.Controller.from_json(solution.controller_json())

rng = random.Random(int(sys.argv[1]) if len(sys.argv) > 1 else 1)
owners = dict(zip(arena.names, arena.owners))
state = arena.initial
for step in range(200):
    answer = controller.step(state)
    if controller.off_model:
        print(f"  ({controller.off_model})")
    moves = dict(arena.transitions(state))
    if owners[state] == "robot":
        print(f"{step:3}  robot at {state}: {answer}")
        if answer.action is None:  # done, giving up, or a commitment already satisfied
            break
        action = answer.action
    else:
        action = rng.choice(sorted(moves))
        print(f"{step:3}  adversary at {state} plays {action}")
    state = moves[action]
print(f"committed to {controller.committed}, done: {controller.is_done}")

"""Shared fixtures: the repository's paths and the command line whose reports the bindings must
equal."""

import json
import os
import pathlib
import subprocess

import pytest

import hypersynth as hs

ROOT = pathlib.Path(__file__).resolve().parents[2]
CASE_STUDY = ROOT / "specs" / "case-study"
PHI = "(!O U A) & (!O U B)"
PSI = "!O U A"


@pytest.fixture(scope="session")
def cli():
    """Runs the command line (``$HYPERSYNTH_BIN``, else the release binary, built if needed)
    and returns its JSON report."""
    binary = os.environ.get("HYPERSYNTH_BIN")
    if not binary:
        subprocess.run(
            ["cargo", "build", "--release", "--quiet", "--bin", "hypersynth"],
            cwd=ROOT,
            check=True,
        )
        binary = str(ROOT / "target" / "release" / "hypersynth")

    def run(*args):
        done = subprocess.run(
            [binary, "--quiet", "--format", "json", *args],
            cwd=ROOT,
            check=True,
            capture_output=True,
            text=True,
        )
        return json.loads(done.stdout)

    return run


def case_study_problem(arena="arena.txt"):
    """The case study's problem (phi, psi, the built-in translator) on its arena or map."""
    return hs.Problem(hs.Arena.from_file(str(CASE_STUDY / arena)), phi=PHI, psi=PSI,
                      translator="builtin")


def tiny_arena():
    """r (robot) -go-> a (adversary) -on-> g (A, B hold), or a -back-> r; g loops."""
    builder = hs.ArenaBuilder()
    builder.add_state("r", "robot")
    builder.add_state("a", "adversary")
    builder.add_state("g", "robot", ["A", "B"])
    builder.add_transition("r", "go", "a")
    builder.add_transition("a", "on", "g")
    builder.add_transition("a", "back", "r")
    builder.add_transition("g", "stay", "g")
    builder.set_initial("r")
    return builder.build("tiny")


def needs(module):
    """The optional module `module`, or the test skipped with the extra that installs it."""
    extra = {"gymnasium": "gym", "dask": "dask", "distributed": "dask", "nbclient": "notebook",
             "matplotlib": "notebook"}[module]
    return pytest.importorskip(
        module, reason=f"{module} is not installed: pip install 'hypersynth[{extra}]'")

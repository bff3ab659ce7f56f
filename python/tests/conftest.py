"""Shared fixtures: the repository's paths and the command line whose reports the bindings must
equal."""

import json
import os
import pathlib
import subprocess

import pytest

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

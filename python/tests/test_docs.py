"""Every public name of the package is documented with an example, and every example runs:
the docstrings' examples are doctests, run from the repository's root with ``hs`` (the
package), and ``problem`` and ``solution`` the case study's (docs/python.md, "A first solve")."""

import doctest
import inspect
import os

import pytest

import hypersynth as hs
from conftest import ROOT

try:
    import gymnasium  # noqa: F401
except ImportError:
    gym = None
else:
    import hypersynth.gym as gym


def public_names():
    """(qualified name, object) of every public class, function, method and property of the
    package (and of hypersynth.gym when Gymnasium is installed)."""
    modules = [(hs, hs.__all__)]
    if gym is not None:
        names = [n for n, v in vars(gym).items() if not n.startswith("_")
                 and getattr(v, "__module__", None) == gym.__name__]
        modules.append((gym, names))
    for module, names in modules:
        for name in names:
            value = getattr(module, name)
            if not (inspect.isclass(value) or callable(value)):
                continue
            qualified = f"{module.__name__}.{name}"
            yield qualified, value
            if not inspect.isclass(value):
                continue
            for member, attribute in vars(value).items():
                if member.startswith("_"):
                    continue  # dunders: construction and calls are documented on the class
                if isinstance(attribute, (staticmethod, classmethod)):
                    attribute = attribute.__func__
                if callable(attribute) or isinstance(attribute, property) or \
                        inspect.isgetsetdescriptor(attribute) or inspect.ismethoddescriptor(attribute):
                    if member in ("metadata",):
                        continue
                    yield f"{qualified}.{member}", attribute


NAMES = dict(public_names())


def test_the_public_names_are_found():
    for name in ["hypersynth.Problem.solve", "hypersynth.Solution.values",
                 "hypersynth.Controller.as_policy", "hypersynth.solve_many",
                 "hypersynth.Result.solution", "hypersynth.FileError", "hypersynth.Dynamics.step"]:
        assert name in NAMES
    if gym is not None:
        assert "hypersynth.gym.HypergameEnv.step" in NAMES


@pytest.mark.parametrize("name", sorted(NAMES))
def test_each_public_name_has_an_example(name):
    doc = inspect.getdoc(NAMES[name]) or ""
    assert doc.strip(), f"{name} has no docstring"
    assert ">>> " in doc, f"{name}'s docstring has no example"


@pytest.fixture(scope="module")
def globs():
    # As docs/python.md's first solve makes them, from the repository's root.
    here = os.getcwd()
    os.chdir(ROOT)
    try:
        arena = hs.Arena.from_file("specs/case-study/arena.txt")
    finally:
        os.chdir(here)
    problem = hs.Problem(arena, phi="(!O U A) & (!O U B)", psi="!O U A", translator="builtin")
    return {"hs": hs, "problem": problem,
            "solution": problem.solve(discount=0.99, sigma_l="uniform")}


@pytest.mark.parametrize("name", sorted(NAMES))
def test_each_example_runs(name, globs, monkeypatch):
    monkeypatch.chdir(ROOT)
    doc = inspect.getdoc(NAMES[name]) or ""
    flags = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE
    parser = doctest.DocTestParser()
    test = parser.get_doctest(doc, dict(globs), name, None, 0)
    runner = doctest.DocTestRunner(optionflags=flags)
    output = []
    runner.run(test, out=output.append)
    assert runner.failures == 0, "".join(output)

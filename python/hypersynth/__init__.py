"""hypersynth from Python: opportunistic synthesis for hypergames (Kulkarni & Fu, CDC 2019).

The pipeline of the command line as objects: an ``Arena`` (from a file, a map, a string or an
``ArenaBuilder``), tasks (``translate`` a co-safe LTL formula, or read an ``Automaton`` from HOA),
a ``Problem`` in the paper's form (``phi``, ``psi``) or the general one (``tasks``, ``payoffs``,
``believed``, ``risk``), and its ``Solution`` (values, labels, decision tables, simulations,
reports, pictures, the DRN, the exported ``Controller``, and with observations the robust stage and
its learning curve); ``check`` checks an exported controller's certificate. ``Dynamics`` plays a
solution one robot move at a time; ``hypersynth.gym`` wraps it as a Gymnasium environment (``pip
install hypersynth[gym]``). ``solve_many`` solves problems on any ``concurrent.futures`` executor
(Dask's included); problems and solutions pickle.

Every error is a ``hypersynth.Error`` (``ParseError``, ``ArenaError``, ``TranslationError``,
``TaskError``, ``OptionsError``, ``SolveError``, ``ControllerError``, ``CertificateError``, and
``FileError``, which is also an ``OSError``) with ``file``, ``line`` and ``column`` set when it is
located in a text.
"""

from typing import Any

from ._errors import FileError
from ._hypersynth import (
    Answer,
    Arena,
    ArenaBuilder,
    ArenaError,
    Automaton,
    CertificateError,
    Controller,
    ControllerError,
    ControllerPolicy,
    Dynamics,
    Error,
    OptionsError,
    ParseError,
    Problem,
    Solution,
    SolveError,
    TaskError,
    TranslationError,
    __version__,
    check,
    translate,
)
from ._sweep import Result, solve_many

__all__ = [
    "Answer",
    "Arena",
    "ArenaBuilder",
    "ArenaError",
    "Automaton",
    "CertificateError",
    "Controller",
    "ControllerError",
    "ControllerPolicy",
    "Dynamics",
    "Error",
    "FileError",
    "OptionsError",
    "ParseError",
    "Problem",
    "Result",
    "Solution",
    "SolveError",
    "TaskError",
    "TranslationError",
    "__version__",
    "check",
    "solve_many",
    "translate",
]


def __getattr__(name: str) -> Any:
    # `hs.gym` imports the Gymnasium environment (and Gymnasium) on first use.
    if name == "gym":
        import importlib

        return importlib.import_module(".gym", __name__)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")

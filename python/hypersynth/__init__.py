"""hypersynth from Python: opportunistic synthesis for hypergames (Kulkarni & Fu, CDC 2019).

The pipeline of the command line as objects: an ``Arena`` (from a file, a map, a string or an
``ArenaBuilder``), tasks (``translate`` a co-safe LTL formula, or read an ``Automaton`` from
HOA), a ``Problem`` in the paper's form (``phi``, ``psi``) or the general one (``tasks``,
``payoffs``, ``believed``, ``risk``), and its ``Solution`` (values, labels, decision tables,
simulations, reports, pictures, the DRN and the exported ``Controller``).

Every error is a ``hypersynth.Error`` (``ParseError``, ``ArenaError``, ``TranslationError``,
``TaskError``, ``OptionsError``, ``SolveError``, ``ControllerError``) with ``file``, ``line``
and ``column`` set when it is located in a text.
"""

from ._hypersynth import (
    Arena,
    ArenaBuilder,
    ArenaError,
    Automaton,
    Controller,
    ControllerError,
    Error,
    OptionsError,
    ParseError,
    Problem,
    Solution,
    SolveError,
    TaskError,
    TranslationError,
    translate,
)

__all__ = [
    "Arena",
    "ArenaBuilder",
    "ArenaError",
    "Automaton",
    "Controller",
    "ControllerError",
    "Error",
    "OptionsError",
    "ParseError",
    "Problem",
    "Solution",
    "SolveError",
    "TaskError",
    "TranslationError",
    "translate",
]

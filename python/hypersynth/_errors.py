"""``FileError``: a file that cannot be read, both a ``hypersynth.Error`` and the ``OSError`` of
its cause, so that ``except FileNotFoundError`` (or ``except OSError``) catches it too."""

from typing import Dict, Optional, Type

from ._hypersynth import Error


class FileError(Error, OSError):
    """A file cannot be read (``Arena.from_file``, ``solve(observations=PATH)``): a
    ``hypersynth.Error`` with the command line's message, and an ``OSError`` whose ``errno``,
    ``strerror`` and ``filename`` say why; each is also an instance of the ``OSError`` subclass
    of its cause (``FileNotFoundError``, ``PermissionError``, ``IsADirectoryError``...).

    >>> try:
    ...     hs.Arena.from_file("missing.txt")
    ... except FileNotFoundError as error:
    ...     print(error)
    missing.txt: cannot read: No such file or directory (os error 2)
    """

    message: str

    def __str__(self) -> str:
        return self.message


_KINDS: Dict[Type[OSError], Type[FileError]] = {}


def file_error(errno: Optional[int], strerror: str, filename: str, message: str) -> FileError:
    """The ``FileError`` of ``filename``, of the class that is also the ``OSError`` subclass
    Python gives ``errno`` (plain ``FileError`` without one)."""
    kind: Type[FileError] = FileError
    if errno is not None:
        builtin = type(OSError(errno, strerror))
        if builtin is not OSError:
            kind = _KINDS.get(builtin) or _KINDS.setdefault(
                builtin,
                type("FileError", (FileError, builtin), {"__module__": "hypersynth",
                                                        "__doc__": FileError.__doc__}),
            )
    error = kind(errno, strerror, filename) if errno is not None else kind(strerror)
    error.message = message
    error.file = filename
    error.line = None
    error.column = None
    return error

"""The exceptions wiperlab raises.

Every message is the one the ``wiperlab`` command-line tool prints for the same failure.

* ``WiperlabError``: the base class of all of them.
* ``InputError`` (also a ``ValueError``): a file, a job or a setting is not usable.
* ``ParseError`` (an ``InputError``): a value in a file is not what was expected; ``path``,
  ``line`` and ``column`` (1-based; column 0 means the whole line) say where.
* ``RecordingError`` (an ``InputError``): a tracking export cannot be imported.
* ``SimulationError``: a simulation failed numerically (lost contact, a singular slip system); the
  message names the time and state.
* ``FitError``: a fit failed (an optimiser failure, a best fit that cannot be simulated again).

A missing file raises the built-in ``FileNotFoundError`` (other I/O failures ``OSError``), Ctrl-C
raises ``KeyboardInterrupt``, and a bad argument of a call (an unknown option name) raises
``ValueError``.
"""

from __future__ import annotations


class WiperlabError(Exception):
    """Base class of wiperlab's exceptions."""


class InputError(WiperlabError, ValueError):
    """A file, a job or a setting that is not usable."""


class ParseError(InputError):
    """A value in a file that is not what was expected.

    Attributes: ``path`` (str), ``line`` and ``column`` (int, 1-based; column 0: the whole line).
    """

    def __init__(self, message: str, path: str = "", line: int = 0, column: int = 0):
        super().__init__(message)
        self.path = path
        self.line = line
        self.column = column


class RecordingError(InputError):
    """A tracking export that cannot be imported."""


class SimulationError(WiperlabError):
    """A simulation that failed numerically."""


class FitError(WiperlabError):
    """A fit that failed."""


__all__ = [
    "WiperlabError",
    "InputError",
    "ParseError",
    "RecordingError",
    "SimulationError",
    "FitError",
]

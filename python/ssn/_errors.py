"""The exceptions of the ``ssn`` package, by kind; each carries the numbers that explain it.

- ``SsnError``: the base of every exception raised by the package;
- ``SceneError`` (a ``ValueError``): a scene, a value or a study that cannot be used, with
  the command line's message (file, key, value, what is allowed; exit code 2 of ``ssn``);
- ``SceneTypeError`` (a ``SceneError`` and a ``TypeError``): a value of the wrong type
  (a string for a number, an object for a matrix), named with its key or entry;
- ``TooLargeError`` (a ``SceneError``): a run refused before it starts because its memory or
  work estimate is above the limit (the message gives the estimate and how to lift it);
- ``SolveError`` (a ``RuntimeError``): the input was accepted but the computation could not
  be carried out;
- ``NotConvergedError`` (a ``SolveError``): a result that needs a converged solve did not
  get one: ``termination``, ``iterations``, ``residual_norm``.
"""


class SsnError(Exception):
    """Base of the exceptions of the ``ssn`` package."""


class SceneError(SsnError, ValueError):
    """A scene, a value or a study that cannot be used: the file, the key, the value and
    what is allowed (the command line's exit code 2)."""


class SceneTypeError(SceneError, TypeError):
    """A value of the wrong type: its key or entry, its type and what is allowed."""


class TooLargeError(SceneError):
    """A run refused up front: its memory or work estimate is above the limit."""


class SolveError(SsnError, RuntimeError):
    """The input was accepted, but the computation could not be carried out."""


class NotConvergedError(SolveError):
    """A result that needs a converged solve did not get one; ``termination``,
    ``iterations`` and ``residual_norm`` are the solve's."""

    termination: str
    iterations: int
    residual_norm: float

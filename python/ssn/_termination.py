"""Why a solve stopped, as an enum (``Solution.termination_kind``).

Members compare equal to the first word of the command line's termination text
(``Termination.CONVERGED == "converged"``); the text itself, with its numbers, stays in
``Solution.termination``.
"""

import enum
import re


class Termination(str, enum.Enum):
    """The kind of a solve's termination (the first word of ``ssn solve``'s text)."""

    CONVERGED = "converged"
    MAX_ITERATIONS = "max-iterations"
    STAGNATED = "stagnated"
    STALLED = "stalled"
    LINE_SEARCH_FAILED = "line-search-failed"
    SINGULAR_JACOBIAN = "singular-jacobian"
    OUT_OF_MEMORY = "out-of-memory"
    INDEX_OVERFLOW = "index-overflow"
    KRYLOV_NOT_CONVERGED = "krylov-not-converged"
    LINEAR_SOLVE_FAILED = "linear-solve-failed"
    NON_FINITE = "non-finite"
    OUTSIDE_DOMAIN = "outside-domain"
    PROBLEM_ERROR = "problem-error"
    RAY = "ray"
    PIVOT_LIMIT = "pivot-limit"
    LEMKE_STOPPED = "lemke-stopped"
    NOT_STEADY = "not-steady"

    @classmethod
    def of(cls, text: str) -> "Termination":
        """The kind of a termination text; ``ValueError`` for a text of no known kind."""
        word = re.match(r"[a-z]+(?:-[a-z]+)*", text)
        return cls(word.group(0) if word else text)

"""Outcome enums whose members carry their message (after optimistix's ``RESULTS``).

Every result type of rigidfold (a solve of problem (6), a mechanism analysis, a development
diagram, a large-deformation check, a folding motion, a generation run) reports how it ended
as a member of an :class:`Outcome` subclass. A member is a ``str`` (its value, which is what
JSON files and study databases hold, so files written by earlier versions read the same) and
carries a human-readable ``message``. Run-specific details (a number, the solver's own
words) go into a separate field of the result, never into the member.

::

    class Status(Outcome):
        CONVERGED = "converged", "F <= F_tol and every constraint met"
        FAILED = "failed", "the solver failed"

    Status.CONVERGED == "converged"   # True: a str
    Status.CONVERGED.message          # "F <= F_tol and every constraint met"
    Status("failed")                  # Status.FAILED (look-up by value)
"""

from __future__ import annotations

import enum


class Outcome(enum.StrEnum):
    """Base of rigidfold's outcome enums: ``NAME = "value", "message"``."""

    message: str

    def __new__(cls, value: str, message: str = "") -> Outcome:
        member = str.__new__(cls, value)
        member._value_ = value
        member.message = message
        return member

    def describe(self, detail: str | None = None) -> str:
        """The message, followed by a run-specific detail when there is one."""
        return f"{self.message} ({detail})" if detail else self.message

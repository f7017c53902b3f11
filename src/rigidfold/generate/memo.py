"""Nothing solved twice: the attempts of a run by the shape they started from and the fix.

The search comes back to shapes it has reduced before: backtracking returns to a shape and
goes down again, the one-crease chain after the sets and every later round of the search
start again from the initial shape (:mod:`rigidfold.generate.chains`), and a retracted
solution's children are met again below it. Every solve starts from the last accepted
shape and is deterministic (one BLAS thread, :func:`rigidfold.config.one_blas_thread`), so
the same fix from the same shape under the same bound gives the same solution, mechanism
and verdict. On Origami Simulator's patterns on the dome, a run that backtracks and starts
rounds again meets hundreds of them (``dome:reschTriTessellation.svg``: 268 of its 762
attempts; ``dome:huffmanWaterbomb.svg``: 367 of 1195 in its 3 minutes; docs/broad_set.md,
session 39).

A repeat is recorded as an attempt of its own (the search's decisions are those it made
before: the same outcome, counted the same way) with ``Attempt.solve_from`` naming the
attempt it repeats and no seconds of solve, analysis or check. The key is the starting
shape bitwise (its coordinates and fixed creases), the fix, the fold limit of the chain's
solves and whether the solution is polished; solves the time limit cut are not kept. The
mechanisms of solutions above ``Settings.generation.reuse_max_dof`` are not kept (their
bases fill memory, and their solves take hundredths of a second).
"""

from __future__ import annotations

import hashlib
from dataclasses import replace
from typing import Generic, TypeVar

from rigidfold.generate.records import Attempt, AttemptOutcome
from rigidfold.mesh import CreasePattern

T = TypeVar("T")

Key = tuple[bytes, tuple[int, ...], float | None, bool]


def attempt_key(
    start: CreasePattern, fix: tuple[int, ...], fold_limit: float | None, polish: bool
) -> Key:
    """The key of an attempt: the starting shape (a digest of its coordinates (V, 3) and
    fixed creases (E,), bitwise), the fix (its creases, sorted), the bound (12) of the solve
    (radians; None: none) and whether its solution is polished."""
    digest = hashlib.blake2b(start.coords.tobytes(), digest_size=20)
    digest.update(start.fixed.tobytes())
    return digest.digest(), tuple(sorted(int(e) for e in fix)), fold_limit, polish


class AttemptMemo(Generic[T]):
    """The attempts of a run by :func:`attempt_key`, each with what its solve produced
    (``T``: the search's trial); ``max_dof`` (``Settings.generation.reuse_max_dof``):
    solutions of more DOF are not kept; 0: nothing is kept."""

    def __init__(self, max_dof: int) -> None:
        self.max_dof = max_dof
        self._seen: dict[Key, tuple[Attempt, T]] = {}

    def __len__(self) -> int:
        return len(self._seen)

    def keep(self, key: Key, rec: Attempt, trial: T) -> None:
        """Keep attempt ``rec`` (a copy, as it is now: before a retraction makes it a dead
        end) with its trial, unless the time limit cut it or its shape has more than
        ``max_dof`` DOF."""
        if self.max_dof <= 0 or rec.outcome is AttemptOutcome.TIME_LIMIT:
            return
        if rec.dof is not None and rec.dof > self.max_dof:
            return
        self._seen.setdefault(key, (replace(rec), trial))

    def repeat(self, key: Key, index: int, search_round: int) -> tuple[Attempt, T] | None:
        """The earlier attempt of ``key`` as attempt ``index`` of round ``search_round``
        (``solve_from`` naming it, no seconds of its own; the look-ahead's fields as the
        search sets them anew) with its trial; None where there is none."""
        seen = self._seen.get(key)
        if seen is None:
            return None
        first, trial = seen
        rec = replace(
            first,
            index=index,
            search_round=search_round,
            solve_time=0.0,
            analysis_time=0.0,
            selection_time=0.0,
            path_time=0.0,
            solve_from=first.index,  # only attempts that were computed are kept
        )
        return rec, trial

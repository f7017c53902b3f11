"""The deployability check of a run's candidates (Step 5 beyond the paper, issue 29): whether
an accepted solution's rigid-folding path reaches the flat state, and why not.

A candidate's solution of at most ``Settings.generation.deploy_check_max_dof`` (or the
target DOF) is tested at second order first (``Settings.generation.second_order_first``): a
second-order rigid shape cannot fold at all and is rejected without a trace; otherwise its
path is traced (:func:`rigidfold.mechanism.path.trace_path`) to the search's deadline, and a
path that does not reach the flat state is tested at second order if not tested yet. Every
rejection is kept, so that a candidate whose solution is the same shape (the same fixed
creases and DOF, every vertex within ``Settings.generation.same_shape_tol`` mean edge
lengths) is rejected as before without a trace: a restart at a fold limit keeps the
solutions within its bound and meets their candidates again (docs/deployability.md,
session 33).

:class:`DeployCheck` holds one run's rejections; the steps of the run
(:mod:`rigidfold.generate.steps`) ask it.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace

import numpy as np

from rigidfold.config import Settings
from rigidfold.frame.model import default_support_face
from rigidfold.generate.options import GenerateOptions
from rigidfold.generate.records import AttemptOutcome
from rigidfold.mechanism import Mechanism
from rigidfold.mechanism.path import FoldingPath, trace_path
from rigidfold.mechanism.second_order import ChildForecast, Obstruction, obstruction
from rigidfold.mesh import CreasePattern


@dataclass(frozen=True)
class Checked:
    """What the check of one candidate's solution found.

    outcome : ACCEPTED, PATH, RIGID or TIME_LIMIT (a trace the deadline cut: no verdict)
    path : the path traced for it (None: no trace, a rigid shape or a verdict repeated)
    path_record, second_record : the attempt's ``path`` and ``second_order``
        (:meth:`FoldingPath.to_dict`, :meth:`Obstruction.to_dict`; None where not made)
    path_from : the earlier attempt whose verdict is repeated (None: checked now)
    """

    outcome: AttemptOutcome
    path: FoldingPath | None
    path_record: dict | None
    second_record: dict | None
    path_from: int | None = None


@dataclass(frozen=True)
class Verdict:
    """A candidate's solution rejected by the deployability check, kept so that the same
    shape met again is not traced again: its shape ``coords`` (V, 3) float64 and what the
    check of attempt ``index`` recorded (its records, not the traced points, which a long
    run's hundreds of rejections would keep in memory)."""

    coords: np.ndarray
    index: int
    checked: Checked


class DeployCheck:
    """The deployability check of one run's candidates, with the rejections it made."""

    def __init__(self, options: GenerateOptions, settings: Settings) -> None:
        self.options, self.settings = options, settings
        # the rejected candidates' verdicts, by fixed creases and DOF
        self.verdicts: dict[tuple[bytes, int], list[Verdict]] = {}

    def applies(self, mech: Mechanism | None) -> bool:
        """Whether the check runs on an accepted solution with this mechanism: with
        ``GenerateOptions.deploy_check``, at most ``Settings.generation.deploy_check_max_dof``
        or the target DOF (0: every solution)."""
        limit = self.settings.generation.deploy_check_max_dof
        return (
            self.options.deploy_check
            and mech is not None
            and (limit <= 0 or mech.dof <= max(limit, self.options.target_dof))
        )

    def checks_children(self, dof: int) -> bool:
        """Whether the children of a shape of DOF ``dof`` (one DOF fewer) get the check
        (:meth:`applies`)."""
        limit = self.settings.generation.deploy_check_max_dof
        return self.options.deploy_check and (
            limit <= 0 or dof - 1 <= max(limit, self.options.target_dof)
        )

    def check(
        self, pattern: CreasePattern, dof: int, index: int, deadline: float | None
    ) -> Checked:
        """The check of the solution ``pattern`` (first-order DOF ``dof``) of attempt
        ``index``: a shape rejected before (:meth:`seen`) is rejected as then, with no
        trace; otherwise the second-order test (with ``second_order_first``, of a shape not flat
        already: a rigid one is RIGID without a trace, its path None), then its path traced
        to ``deadline`` (of ``time.monotonic()``; None: none), and where that does not reach
        the flat state, the second-order test if not made yet (and the deadline has not
        passed). The outcome ACCEPTED, PATH, RIGID or TIME_LIMIT (a trace the deadline cut:
        no verdict). A rejection is kept for :meth:`seen`."""
        seen = self.seen(pattern, dof)
        if seen is not None:
            return replace(seen.checked, path_from=seen.index)
        settings = self.settings
        second = None
        if settings.generation.second_order_first and not flat(pattern, settings):
            second = self.obstruction(pattern, dof)
        path = None
        if second is None or not second.rigid:
            path = trace_path(
                pattern,
                dof=dof,
                support_face=self.options.support_face,
                settings=settings,
                deadline=deadline,
            )
            if path.cut or path.deploys:
                outcome = AttemptOutcome.TIME_LIMIT if path.cut else AttemptOutcome.ACCEPTED
                return Checked(outcome, path, path.to_dict(), None)
            if second is None and not (deadline is not None and time.monotonic() > deadline):
                second = self.obstruction(pattern, dof)
        outcome = (
            AttemptOutcome.RIGID if second is not None and second.rigid else AttemptOutcome.PATH
        )
        checked = Checked(
            outcome,
            path,
            None if path is None else path.to_dict(),
            None if second is None else second.to_dict(),
        )
        verdict = Verdict(pattern.coords.copy(), index, replace(checked, path=None))
        self.verdicts.setdefault((pattern.fixed.tobytes(), dof), []).append(verdict)
        return checked

    def seen(self, pattern: CreasePattern, dof: int) -> Verdict | None:
        """The verdict on an earlier candidate's solution of the same fixed creases and DOF
        whose shape lies within ``Settings.generation.same_shape_tol`` mean edge lengths of
        ``pattern``'s (every vertex), None where there is none."""
        tol = self.settings.generation.same_shape_tol
        earlier = self.verdicts.get((pattern.fixed.tobytes(), dof), ())
        if tol <= 0 or not earlier:
            return None
        reach = tol * float(pattern.edge_lengths.mean())
        return next((v for v in earlier if np.abs(pattern.coords - v.coords).max() <= reach), None)

    def support_face(self, pattern: CreasePattern) -> int:
        """The gauge triangle of the path and the second-order test (the options', or the
        one nearest the centroid)."""
        face = self.options.support_face
        return default_support_face(pattern) if face is None else int(face)

    def obstruction(self, pattern: CreasePattern, dof: int) -> Obstruction | None:
        """The second-order test of a checked solution (``Settings.generation.
        second_order``); None where it is not made."""
        settings = self.settings
        if (
            not settings.generation.second_order
            or pattern.n_vertices > settings.mechanism.second_order_vertices
        ):
            return None
        return obstruction(pattern, self.support_face(pattern), dof, settings)

    def child_forecast(self, pattern: CreasePattern, dof: int) -> ChildForecast | None:
        """At a shape of DOF ``dof`` whose children get the check: the second-order forecast
        of its candidates (None where it is not made)."""
        settings = self.settings
        if (
            not (self.checks_children(dof) and settings.generation.second_order)
            or dof < 2
            or pattern.n_vertices > settings.mechanism.second_order_vertices
        ):
            return None
        return ChildForecast.at(pattern, self.support_face(pattern), dof, settings)


def flat(pattern: CreasePattern, settings: Settings) -> bool:
    """Whether every free crease of ``pattern`` is within ``Settings.path.flat_tol`` of flat
    (its path has reached the flat state at its start)."""
    free = ~pattern.fixed & ~pattern.is_boundary_edge
    rho = pattern.fold_angles[free]
    return not rho.size or float(np.abs(rho).max()) <= settings.path.flat_tol

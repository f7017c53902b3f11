"""The verdict on a run that falls short says what the run ran into: where most of its
solves after the first found no shape within dz of the surface (``N_exceed``), that the
pattern reaches the surface only with more DOF, with what to try."""

from __future__ import annotations

from pathlib import Path

from rigidfold.config import DEFAULTS
from rigidfold.generate import AttemptOutcome, GenerateOptions, Stop, generate
from rigidfold.generate.specs import case_from_specs
from rigidfold.pipeline.verdict import SOLVE_HINT, run_verdict
from rigidfold.rundir import SolutionRecord

DATA = Path(__file__).parent / "data" / "origami_simulator"
OPTIONS = GenerateOptions(criterion="shat", seed=4648, lookahead=True, deform=False)


def _verdict(run, settings=DEFAULTS):
    records = [SolutionRecord(s.step, s.mechanism.dof) for s in run.solutions]
    files = [
        Path(f"solutions/step_{s.step:02d}_dof_{s.mechanism.dof:02d}.fold") for s in run.solutions
    ]
    return run_verdict(run, records, files, 1, settings)


def test_a_pattern_that_cannot_reach_the_surface_with_fewer_dof_is_told_so():
    """Origami Simulator's single vertex on the dome: a handful of panels, DOF 5 at the
    start; with more creases fixed most solves find no shape within dz of the dome."""
    case = case_from_specs("dome", str(DATA / "simpleVertex.svg"), seed=4648)
    run = generate(case, OPTIONS)
    assert run.stop is not Stop.TARGET_REACHED
    later = run.attempts[1:]
    missed = [a for a in later if a.outcome is AttemptOutcome.EXCEED]
    assert 2 * len(missed) >= len(later) and len(missed) == run.n_exceed
    line = [s for s in _verdict(run).shortfalls if "no shape within dz" in s]
    assert len(line) == 1
    assert line[0].startswith(f"{len(missed)} of the {len(later)} solves after the first")
    assert SOLVE_HINT in line[0]
    # the share that makes the line (Settings.generation.exceed_share): above this run's
    share = len(missed) / len(later)
    above = DEFAULTS.with_(exceed_share=min(1.0, share + 0.01))
    assert not [s for s in _verdict(run, above).shortfalls if "no shape within dz" in s]


def test_a_run_that_falls_short_otherwise_is_not_told_so():
    """A run whose candidates' paths do not reach the flat state (pattern 1 on Bezier, the
    later rounds' case of ``tests/test_reseed.py``): no such line."""
    settings = DEFAULTS.with_(deploy_max_candidates=1, backtrack_max=0, fold_limits=())
    case = case_from_specs("bezier", "1", seed=102, settings=settings)
    run = generate(case, OPTIONS.replace(seed=102, batch="off"))
    assert run.stop is Stop.NO_DEPLOYABLE
    assert not [s for s in _verdict(run).shortfalls if "no shape within dz" in s]

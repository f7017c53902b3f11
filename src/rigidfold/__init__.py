"""rigidfold: form generation of rigid-foldable origami approximating a curved surface.

The method of Hayakawa and Ohsaki in a few lines of Python: a case (target surface and
crease pattern, Step 1), then :func:`rigidfold.generate.generate` (Steps 2-7: solve problem
(6), fix the crease the criterion ranks first, solve again, down to the target DOF)::

    from rigidfold.generate.specs import case_from_specs
    from rigidfold.generate import generate

    case = case_from_specs("bezier", "1", seed=1)  # surface, pattern; symmetry, size, Settings
    run = generate(case, criterion="shat", seed=1)
    print(run.stop_reason, run.n_lock)  # "target DOF 1 reached", the paper's counters
    design = run.final.result.pattern  # the final design: a CreasePattern (coords, faces)

:func:`~rigidfold.generate.specs.case_from_specs` reads the texts the command line takes;
:func:`rigidfold.generate.case.make_case` takes the typed specs
(``make_case(SurfaceSpec(SurfaceKind.BEZIER, seed=1), PaperPattern("1"))``).

:func:`rigidfold.deform.verify` checks a design (Steps 8-9 and its folding motion);
``rigidfold generate`` is :func:`rigidfold.pipeline.run` with the run directory's sink
(:class:`rigidfold.pipeline.RunWriter`), each other command a function of
:mod:`rigidfold.pipeline.workflows` that writes the same files (``optimize_case``,
``export_file``, ...); every tolerance and
default is a field of :class:`rigidfold.config.Settings`. What the library cannot use (a
spec, a file, an option value) raises :class:`RigidfoldError`, a ``ValueError`` whose
message names what was received.

Importing the package pins the BLAS kernel and NumPy's SIMD dispatch while NumPy is not yet
loaded, so that a design is the same on every x86-64 CPU (:mod:`rigidfold.runtime.numerics`).
"""

from importlib.metadata import version as _v

from rigidfold.errors import RigidfoldError
from rigidfold.runtime.numerics import pin_in_process as _pin

_pin()
__version__ = _v("rigidfold")
__all__ = ["RigidfoldError", "__version__"]

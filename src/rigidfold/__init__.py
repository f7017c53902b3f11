"""rigidfold: form generation of rigid-foldable origami approximating a curved surface.

Importing the package pins the BLAS kernel and NumPy's SIMD dispatch while NumPy is not yet
loaded, so that a design is the same on every x86-64 CPU (:mod:`rigidfold.numerics`).
"""

from importlib.metadata import version as _v

from rigidfold.numerics import pin_in_process as _pin

_pin()
__version__ = _v("rigidfold")

"""The drive that deploys a design from flat to built under its own weight (issue 48).

:mod:`~rigidfold.drive.options` (the options as given, :class:`DriveOptions`),
:mod:`~rigidfold.drive.motion` (the refined motion from flat, DOF 1),
:mod:`~rigidfold.drive.mass` (panels, hinge hardware, point masses),
:mod:`~rigidfold.drive.energy` (U(s) and its derivative, every base at once),
:mod:`~rigidfold.drive.actuators` (creases, pairs, cables: torques by virtual work, dead
points, sign changes, brake zones, the ranking),
:mod:`~rigidfold.drive.base` (the clamped panel, the ground, the bases ranked),
:mod:`~rigidfold.drive.equilibria` (the released structure),
:mod:`~rigidfold.drive.check` (the independent OpenSees check),
:mod:`~rigidfold.drive.result` (:class:`DriveResult`, :class:`DriveStatus`),
:mod:`~rigidfold.drive.deploy` (:func:`deploy_design`, the one entry) and the writers of
:mod:`~rigidfold.drive.files` and :mod:`~rigidfold.drive.figure`. OpenSees and matplotlib
are imported only when used.
"""

from rigidfold.drive.deploy import deploy_design
from rigidfold.drive.files import DEPLOY_FILES, write_drive
from rigidfold.drive.options import AUTO, Base, DriveOptions
from rigidfold.drive.result import DriveResult, DriveStatus

__all__ = [
    "AUTO",
    "DEPLOY_FILES",
    "Base",
    "DriveOptions",
    "DriveResult",
    "DriveStatus",
    "deploy_design",
    "write_drive",
]

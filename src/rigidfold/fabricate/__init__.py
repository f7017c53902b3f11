"""Thick panels that deploy without collision: solids, hinges and the files a workshop needs.

:mod:`~rigidfold.fabricate.panels` (panels, hinges, who meets whom),
:mod:`~rigidfold.fabricate.motion` (the folding motion as rigid motions of the panels),
:mod:`~rigidfold.fabricate.solids` (tapered solids: bevels, reliefs; Tachi's thick panels),
:mod:`~rigidfold.fabricate.collision` (every pair over the whole motion),
:mod:`~rigidfold.fabricate.build` (the verdict, :class:`Fabrication`),
:mod:`~rigidfold.fabricate.options` (the options as given, :class:`FabricateOptions`),
and the writers of :mod:`~rigidfold.fabricate.files` and
:mod:`~rigidfold.fabricate.cutsheets`. manifold3d,
python-fcl, trimesh, rhino3dm, rectpack and ezdxf are imported only when used.
"""

from rigidfold.fabricate.build import Fabrication, FabricationStatus, fabricate_panels
from rigidfold.fabricate.collision import Clearance, Meeting, check_clearance
from rigidfold.fabricate.motion import PanelMotion, design_motion, panel_motion
from rigidfold.fabricate.options import FabricateOptions
from rigidfold.fabricate.panels import Panels
from rigidfold.fabricate.solids import Solids, bevel_angles, thicken

__all__ = [
    "Clearance",
    "FabricateOptions",
    "Fabrication",
    "FabricationStatus",
    "Meeting",
    "PanelMotion",
    "Panels",
    "Solids",
    "bevel_angles",
    "check_clearance",
    "design_motion",
    "fabricate_panels",
    "panel_motion",
    "thicken",
]

"""One set of options per check of the final design (issue: generate's checks take every
option of ``rigidfold fabricate`` and ``rigidfold structure``): ``FabricateOptions`` and
``StructureOptions`` refuse bad values in one line; ``GenerateOptions`` holds them (None: the
check does not run) and still takes and records the keywords of earlier versions; every
option ``generate`` gained reaches its check."""

from __future__ import annotations

import json
import pickle
from pathlib import Path

import pytest

from conftest import main_code
from rigidfold.cli.structure_specs import read_structure_options
from rigidfold.cli.units import parse_length, parse_sheet
from rigidfold.errors import RigidfoldError
from rigidfold.fabricate import FabricateOptions
from rigidfold.generate import GenerateOptions
from rigidfold.io import read_fold
from rigidfold.material import MATERIALS, Material
from rigidfold.structure import Pins, Point, Pressure, Service, StructureOptions, Uniform
from test_generate_integration import FAST as INTEGRATION_FAST

FAST = [*INTEGRATION_FAST, "--no-report"]
"""A short run: three creases fixed on the paper's pattern 1 (seconds), without its report."""


# ------------------------------------------------------------------------- the options
@pytest.mark.parametrize(
    "changes",
    [
        {"thickness": "thick"},
        {"thickness": 0.0},
        {"thickness": True},
        {"side": "left"},
        {"clearance_angle_deg": 95.0},
        {"clearance_angle_deg": "2"},
        {"density": -1.0},
        {"sheet": "2440by1220"},
        {"sheet": (0.0, 1220.0)},
        {"min_thickness": 0.05},
        {"min_thickness": "thin"},
    ],
)
def test_fabricate_options_refuse_bad_values_in_one_line(changes):
    with pytest.raises(RigidfoldError) as info:
        FabricateOptions(**{"thickness": 0.02, **changes})
    message = str(info.value)
    assert "\n" not in message and message


@pytest.mark.parametrize(
    "changes",
    [
        {"thickness": -0.01},
        {"thickness": "18mm"},
        {"material": "cheese"},
        {"supports": "a,b"},
        {"supports": ""},  # no support and nothing clamped
        {"candidates": "lowest"},
        {"clamped": "0;1"},
        {"actuators": "x"},
        {"hinge_stiffness": -1.0},
        {"loads": ("snow=1",)},
        {"loads": "uniform=1"},
        {"self_weight": "no"},
        {"limit": "L/0"},
        {"nonlinear": 1},
        {"modes": -1},
    ],
)
def test_structure_options_refuse_bad_values_in_one_line(changes):
    """The command line's texts (read by rigidfold.cli.structure_specs) and the typed
    values, each refused in one line."""
    with pytest.raises(RigidfoldError) as info:
        read_structure_options(**changes)
    message = str(info.value)
    assert "\n" not in message and message


@pytest.mark.parametrize(
    "changes",
    [
        {"supports": "auto"},
        {"loads": ("uniform=1",)},
        {"limit": "L/250"},
        {"clamped": "0,6"},
        {"candidates": "0,1"},
        {"candidates": "Ground"},
        {"actuators": "1"},
        {"material": "steel"},
        {"thickness": "18mm"},
    ],
)
def test_the_record_takes_typed_values_not_texts(changes):
    """StructureOptions holds typed values: a text where one is due is refused in one line,
    naming it (the command line reads its texts first)."""
    with pytest.raises(RigidfoldError) as info:
        StructureOptions(**changes)
    message = str(info.value)
    (value,) = changes.values()
    shown = repr(value[0] if isinstance(value, tuple) else value)
    assert "\n" not in message and f"got {shown}" in message


def test_options_keep_what_the_user_gave():
    fab = FabricateOptions(
        parse_length("18mm"), sheet=parse_sheet("3050x1525"), min_thickness=parse_length("5mm")
    )
    assert fab.thickness == pytest.approx(0.018) and fab.sheet == (3050.0, 1525.0)
    assert fab.min_thickness == pytest.approx(0.005)
    assert FabricateOptions.from_dict(json.loads(json.dumps(fab.to_dict()))) == fab
    assert read_structure_options(supports="", clamped="0,6").clamped == (0, 6)
    st = read_structure_options(supports="0, 4,9", loads=["uniform=0.5"], limit="L/300")
    assert st.loads == (Uniform(0.5),) and st.limit == 300.0
    assert st.supports == Pins((0, 4, 9))
    assert StructureOptions.from_dict(json.loads(json.dumps(st.to_dict()))) == st
    other = read_structure_options(
        supports="service",
        candidates=" Ground",
        actuators="3, 1",
        loads=["pressure=-500Pa", "point=2:0,0,-2kN", "self_weight"],
        material="10e9,0.3,700",
        limit=300,
    )
    assert other.candidates == "ground" and other.actuators == (3, 1)
    assert other.loads == (Pressure(-0.5), Point(2, (0.0, 0.0, -2000.0)))
    assert other.material == Material(10e9, 0.3, 700.0) and other.supports == Service()
    data = json.loads(json.dumps(other.to_dict()))
    assert data["supports"] == "service" and data["actuators"] == "3,1"
    assert data["loads"] == ["pressure=-0.5", "point=2:0.0,0.0,-2000.0"]
    assert StructureOptions.from_dict(data) == other
    candidates = StructureOptions(candidates=(1, 5), material=MATERIALS["steel"])
    data = json.loads(json.dumps(candidates.to_dict()))
    assert data["candidates"] == "1,5" and data["material"] == "steel"
    assert StructureOptions.from_dict(data) == candidates
    with pytest.raises(RigidfoldError, match="cannot read"):
        StructureOptions.from_dict({"loads": ["snow=1"]})
    with pytest.raises(RigidfoldError, match="clamped vertices: 9 is out of range"):
        StructureOptions(clamped=(9,)).check_indices(n_vertices=9, n_edges=20)
    with pytest.raises(RigidfoldError, match="actuators: 20 is out of range"):
        StructureOptions(actuators=(20,)).check_indices(n_vertices=9, n_edges=20)


def test_generate_options_hold_the_checks():
    fab = FabricateOptions(0.02, clearance_angle_deg=3.0)
    st = StructureOptions(thickness=0.02, nonlinear=True, clamped=(0,))
    opts = GenerateOptions(fabricate=fab, structure=st, material=MATERIALS["plywood"])
    assert opts.panel_thickness == 0.02
    data = json.loads(json.dumps(opts.to_dict()))
    assert data["fabricate"]["thickness"] == 0.02 and data["structure"]["nonlinear"] is True
    assert GenerateOptions.from_dict(data) == opts
    assert pickle.loads(pickle.dumps(opts)) == opts  # a study hands it to its workers
    assert GenerateOptions.from_dict({"structure": None, "fabricate": None}) == GenerateOptions()
    moved = opts.replace(material=MATERIALS["steel"])  # a new material is the structure's too
    assert moved.structure.material == MATERIALS["steel"] and moved.structure.nonlinear


@pytest.mark.parametrize(
    "options",
    [
        {
            "material": MATERIALS["steel"],
            "structure": StructureOptions(material=MATERIALS["plywood"]),
        },
        {"fabricate": FabricateOptions(0.02), "structure": StructureOptions(thickness=0.018)},
        {"structure": "yes"},
    ],
)
def test_generate_options_refuse_two_panels(options):
    """A run's panels have one material and one thickness."""
    with pytest.raises(RigidfoldError):
        GenerateOptions(**options)


def test_generate_and_the_commands_share_each_option():
    """Every option of fabricate and structure is generate's too, with the same help (less
    the check it belongs to) and default, but the thickness, material and density (their
    generate meanings are in the help)."""
    from rigidfold.cli.commands import build_parser

    parser = build_parser()
    sub = next(a for a in parser._actions if a.dest == "command").choices
    gen = {a.option_strings[0]: a for a in sub["generate"]._actions if a.option_strings}
    own = {"--thickness", "--material", "--density", "--help", "--out", "--up", "--json"}
    for name in ("fabricate", "structure"):
        for action in sub[name]._actions:
            flag = action.option_strings[0] if action.option_strings else None
            if flag is None or flag in own or flag == "--overwrite":
                continue
            other = gen[flag]
            assert other.default == action.default, flag
            assert other.help.endswith(action.help), flag


# --------------------------------------------------------- each new flag reaches its check
@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """Thick panels and the structure with every new option of generate."""
    out = tmp_path_factory.mktemp("genopt")
    argv = [
        *FAST,
        "--thickness",
        "20mm",
        "--clearance-angle",
        "5",
        "--density",
        "450",
        "--sheet",
        "3050x1525",
        "--min-thickness",
        "5mm",
        "--structure",
        "--clamped",
        "0",
        "--hinge-stiffness",
        "1000",
        "--no-self-weight",
        "--load",
        "uniform=0.5",
        "--nonlinear",
        "--modes",
        "0",
        "--out",
        str(out),
    ]
    main_code(argv)
    summary = json.loads((out / "summary.json").read_text())
    return out, summary, summary["per_solution"][summary["final_step"]]


def test_new_fabricate_flags_reach_the_thick_panels(built):
    out, summary, record = built
    fab = record["fabrication"]
    assert fab["clearance_angle_deg"] == pytest.approx(5.0)
    assert fab["density_kg_m3"] == 450.0
    assert fab["mass_kg"] == pytest.approx(450.0 * fab["volume_m3"])
    assert fab["min_thickness_m"] == pytest.approx(0.005)
    sheets = sorted((out / "final" / "thick").glob("*_sheet_*.svg"))
    stock = '<rect x="0" y="0" width="3050.000" height="1525.000"'  # the legend goes below
    assert sheets and all(stock in p.read_text() for p in sheets)
    assert summary["options"]["fabricate"]["sheet"] == [3050.0, 1525.0]


def test_new_structure_flags_reach_the_structure(built):
    out, summary, record = built
    saved = json.loads((out / "final" / "structure" / "structure.json").read_text())
    assert saved["analysis"] == "nonlinear"
    assert saved["hinge_stiffness_Nm_per_rad_per_m"] == 1000.0
    assert saved["self_weight"] is False
    assert saved["supports"]["clamped"] == [0] and saved["supports"]["chosen"] == "auto"
    assert saved["thickness_m"] == pytest.approx(0.02)  # --thickness is the structure's too
    if "frequencies_Hz" in saved:  # analysed: no natural frequencies with --modes 0
        assert saved["frequencies_Hz"] == []
    assert record["structure"]["analysis"] == "nonlinear"
    assert summary["options"]["structure"]["nonlinear"] is True


def test_support_candidates_and_actuators_reach_the_structure(built, tmp_path):
    """Auto supports chosen among --support-candidates only, with a free crease of the
    final design held by --actuators (the same generation as ``built``: same design)."""
    out, summary, _ = built
    design = read_fold(out / summary["solutions"][summary["final_step"]]).pattern
    crease = int(design.free_creases[0])
    run = tmp_path / "run"
    argv = [*FAST, "--structure", "--support-candidates", "1,2,3", "--actuators", str(crease)]
    main_code([*argv, "--out", str(run)])
    saved = json.loads((run / "final" / "structure" / "structure.json").read_text())
    assert set(saved["supports"]["pinned"]) <= {1, 2, 3}
    assert saved["supports"]["actuated_creases"] == [crease]


@pytest.mark.parametrize(
    "extra",
    [
        ["--clamped", "9999"],
        ["--actuators", "9999"],
        ["--actuators", "0"],  # a boundary edge: never a free crease
        ["--support-candidates", "0,9999"],
        ["--support-candidates", "lowest"],
        ["--modes", "-1"],
        ["--hinge-stiffness", "-5"],
        ["--thickness", "20mm", "--clearance-angle", "95"],
        ["--thickness", "20mm", "--min-thickness", "30mm"],
        ["--thickness", "20mm", "--sheet", "3050by1525"],
    ],
)
def test_bad_new_flags_exit_2_in_one_line_before_the_run(tmp_path, capsys, extra):
    structure = [] if extra[0] == "--thickness" else ["--structure"]
    code = main_code([*FAST, *structure, *extra, "--out", str(tmp_path / "x")])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and "Traceback" not in err
    assert not Path(tmp_path / "x" / "summary.json").exists()

"""Settings: frozen groups whose fields are documented where they are defined, one flat name
per setting (``with_``, error messages, a study's stored configuration), and the flat view
a study stores."""

import dataclasses
import math
import pickle
from pathlib import Path

import pytest

from rigidfold.config import DEFAULTS, FLAT_NAMES, GROUPS, DesignSettings, Settings
from rigidfold.errors import RigidfoldError

DATA = Path(__file__).parent / "data"


@pytest.mark.parametrize("group", sorted(GROUPS))
def test_every_field_is_documented_where_it_is_defined(group):
    cls = GROUPS[group]
    assert dataclasses.is_dataclass(cls) and cls.__dataclass_params__.frozen
    assert cls.__doc__ and cls.__doc__.strip()
    for f in dataclasses.fields(cls):
        doc = f.metadata.get("doc", "")
        assert len(doc.split()) >= 3, f"{group}.{f.name} has no documentation"
        assert f.default is not dataclasses.MISSING, f"{group}.{f.name} has no default"


def test_every_setting_has_one_flat_name_that_reaches_it():
    names = [flat for cls in GROUPS.values() for flat, _ in cls.flat_names()]
    assert len(names) == len(set(names)) == len(FLAT_NAMES)
    flat = DEFAULTS.flat()
    assert list(flat) == names
    for name, (group, attr) in FLAT_NAMES.items():
        assert flat[name] == getattr(getattr(DEFAULTS, group), attr)
    assert Settings.docs().keys() == flat.keys()


def test_the_flat_view_round_trips():
    assert DEFAULTS.with_(**DEFAULTS.flat()) == DEFAULTS
    changed = DEFAULTS.with_(dz=0.1, path_tol=1e-12, mechanism_rank_tol=1e-8, tube_wall=0.002)
    assert changed.design.dz == 0.1 and changed.path.tol == 1e-12
    assert changed.mechanism.rank_tol == 1e-8 and changed.deformation.tube_wall == 0.002
    assert DEFAULTS.with_(**changed.flat()) == changed
    assert pickle.loads(pickle.dumps(changed)) == changed  # handed to Dask workers
    assert hash(changed) != hash(DEFAULTS)


def test_with_changes_a_copy_and_checks_it_again():
    assert DEFAULTS.design.dz == 0.30  # the paper's value, untouched by the copies above
    with pytest.raises(RigidfoldError, match="dz must be a positive number of metres, got -1"):
        DEFAULTS.with_(dz=-1.0)
    with pytest.raises(RigidfoldError, match="projection_tol must be a positive number"):
        DEFAULTS.with_(projection_tol=0.0)
    with pytest.raises(
        RigidfoldError, match="fabricate_relief_rounds must be an integer >= 0, got -1"
    ):
        DEFAULTS.with_(fabricate_relief_rounds=-1)
    with pytest.raises(RigidfoldError, match="path_pace_steps must be an integer >= 1, got 0"):
        DEFAULTS.with_(path_pace_steps=0)
    with pytest.raises(RigidfoldError, match="path_pace_margin must be a positive number"):
        DEFAULTS.with_(path_pace_margin=0.0)
    with pytest.raises(RigidfoldError, match="exceed_share must be a fraction from 0 to 1"):
        DEFAULTS.with_(exceed_share=1.5)
    with pytest.raises(RigidfoldError, match="fabricate_side must be one of bottom, top"):
        DEFAULTS.with_(fabricate_side="left")
    with pytest.raises(dataclasses.FrozenInstanceError):
        DEFAULTS.design.dz = 1.0  # type: ignore[misc]


def test_a_whole_group_or_a_group_and_its_fields():
    design = DesignSettings(dz=0.2)
    assert DEFAULTS.with_(design=design).design is design
    both = DEFAULTS.with_(design=design, theta_min=math.radians(20))
    assert both.design.dz == 0.2 and both.design.theta_min == math.radians(20)
    assert DEFAULTS.design.with_(dz=0.2) == design
    with pytest.raises(RigidfoldError, match=r"Settings\.design must be a DesignSettings, got int"):
        Settings(design=3)  # type: ignore[arg-type]


def test_an_unknown_name_is_refused_with_the_closest_ones():
    with pytest.raises(TypeError, match=r"no setting 'path_tols' \(did you mean path_tol"):
        DEFAULTS.with_(path_tols=1.0)
    with pytest.raises(TypeError, match="no setting 'target_dof'"):
        DEFAULTS.with_(target_dof=1)  # an option of a run (GenerateOptions), not a setting


def test_a_flat_name_read_as_an_attribute_says_where_it_lives():
    with pytest.raises(AttributeError, match=r"the setting is settings\.path\.tol"):
        _ = DEFAULTS.path_tol
    with pytest.raises(AttributeError, match=r"settings\.mechanism\.rank_tol"):
        _ = DEFAULTS.mechanism_rank_tol


def test_from_degrees_keeps_the_defaults_exactly():
    assert Settings.from_degrees() == DEFAULTS
    s = Settings.from_degrees(theta_min_deg=20, rho_max_deg=150, dz=0.25, svg_snap_tol=0.0)
    assert (
        s.design.theta_min == math.radians(20) and s.design.theta_max == DEFAULTS.design.theta_max
    )
    assert s.design.rho_max == math.radians(150) and s.design.dz == 0.25
    assert s.inputs.svg_snap_tol == 0.0


def test_a_study_stores_the_flat_view():
    """The configuration a study stores is the flat view (the names every version wrote)."""
    from rigidfold.study.runner import StudyConfig

    assert StudyConfig().as_dict()["settings"] == DEFAULTS.flat()

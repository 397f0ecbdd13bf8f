import json
from importlib import resources

import numpy as np
import pytest

from facsim.timeline.easing import EASINGS, ease, get_easing

HALFWAY = {"linear": 0.5, "ease-in": 0.25, "ease-out": 0.75, "smoothstep": 0.5, "sigmoid": 0.5}


def test_registry_names():
    assert set(EASINGS) == set(HALFWAY)


def test_schema_enum_matches_registry():
    schema = json.loads(resources.files("facsim").joinpath("data", "timeline.schema.json").read_text())
    assert schema["$defs"]["easing"]["enum"] == list(EASINGS)


@pytest.mark.parametrize("name, halfway", HALFWAY.items())
def test_values_at_0_half_1(name, halfway):
    values = EASINGS[name](np.array([0.0, 0.5, 1.0]))
    np.testing.assert_allclose(values, [0.0, halfway, 1.0], atol=1e-12)


@pytest.mark.parametrize("name", EASINGS)
def test_monotonic_and_bounded(name):
    u = np.linspace(0.0, 1.0, 1001)
    values = EASINGS[name](u)
    assert np.all(np.diff(values) >= 0.0)
    assert values.min() >= 0.0 and values.max() <= 1.0


@pytest.mark.parametrize("name", EASINGS)
def test_clips_outside_unit_interval(name):
    np.testing.assert_allclose(EASINGS[name](np.array([-1.0, 2.0])), [0.0, 1.0], atol=1e-12)


@pytest.mark.parametrize("name", EASINGS)
def test_vectorised_keeps_shape(name):
    assert EASINGS[name](np.zeros((3, 4))).shape == (3, 4)


@pytest.mark.parametrize("name", ["ease-in", "ease-out", "smoothstep", "sigmoid"])
def test_non_linear_easings_differ_from_linear(name):
    u = np.array([0.2])
    assert not np.allclose(EASINGS[name](u), u)


def test_ease_by_name():
    assert float(ease("ease-out", 0.5)) == 0.75


def test_unknown_easing():
    with pytest.raises(ValueError, match=r"unknown easing 'bounce'; choose one of linear"):
        get_easing("bounce")

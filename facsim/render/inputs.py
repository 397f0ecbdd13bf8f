"""What the renderer is given: mesh topology, appearance, lighting and the brow UV frame.

Plain data checked as it is built, with no GL: :class:`RenderTopology` (the static mesh,
its UVs and regions, uploaded once per renderer), :class:`Appearance` (colours and paint
masks), :class:`Lighting` (the studio rig fixed to the camera) and the tables that go with
them (:data:`REGIONS`, :data:`COLOR_NAMES`, :data:`DEFAULT_COLORS`, the eyebrow-stroke UV
frames). :class:`~facsim.render.Renderer` draws with them.

Colour conventions: :class:`Appearance` colours are display sRGB values in [0, 1] (what a
colour picker shows); :func:`srgb_to_linear` turns them into the linear light the shaders
work in.

Examples
--------
>>> Appearance().colors["skin"]
(0.85, 0.68, 0.6)
>>> float(srgb_to_linear(0.5)) > 0.2
True
"""
from __future__ import annotations

from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Mapping

import numpy as np

from facsim.render.camera import Camera, camera_basis

#: Region names; ``RenderTopology.region`` holds indices into this tuple.
REGIONS = ("skin", "mouth_interior", "teeth", "tongue", "eyeball", "lashes")

#: Colour names an :class:`Appearance` must give (display sRGB, 0..1).
COLOR_NAMES = ("skin", "lips", "brows", "lashes", "sclera", "iris", "pupil", "teeth", "tongue",
               "mouth_interior", "eyelid", "cheek")

#: A plausible default appearance (light-medium skin, brown eyes), display sRGB.
DEFAULT_COLORS: Mapping[str, tuple[float, float, float]] = MappingProxyType({
    "skin": (0.85, 0.68, 0.60),
    "lips": (0.72, 0.42, 0.40),
    "brows": (0.22, 0.15, 0.11),
    "lashes": (0.07, 0.05, 0.04),
    "sclera": (0.90, 0.88, 0.85),
    "iris": (0.36, 0.24, 0.14),
    "pupil": (0.02, 0.02, 0.02),
    "teeth": (0.90, 0.87, 0.78),
    "tongue": (0.76, 0.40, 0.40),
    "mouth_interior": (0.36, 0.11, 0.11),
    "eyelid": (0.78, 0.58, 0.52),
    "cheek": (0.90, 0.56, 0.52),
})

#: Eyebrow strokes for hm08's raw UV layout, where the head's island is turned 90 degrees:
#: the brows run along v (strokes ~3 mm long) and u runs up the face (strands ~0.5 mm apart).
HM08_BROW_UV_FRAME = ((0.0, 160.0), (1600.0, 0.0))


def brow_uv_frame(uv_box=None, frame=HM08_BROW_UV_FRAME) -> np.ndarray:
    """The brow-stroke frame for UVs normalised to ``uv_box = (u0, v0, u1, v1)``.

    A head whose UVs are ``u' = (u - u0) / (u1 - u0)`` (same for v) needs the raw frame's
    columns scaled by the box's size; ``uv_box=None`` returns the raw frame.
    """
    m = np.asarray(frame, dtype=float)
    if uv_box is None:
        return m
    u0, v0, u1, v1 = (float(x) for x in uv_box)
    return m * np.array([u1 - u0, v1 - v0])[None, :]


#: The default: facsim's head model, whose UVs are normalised to ``facsim.assets.PAINT_UV_BOX``
#: (0.60, 0.10, 1.00, 0.90) (a test checks the two agree).
DEFAULT_BROW_UV_FRAME = ((0.0, 128.0), (640.0, 0.0))


@dataclass(frozen=True, eq=False)
class RenderTopology:
    """Static mesh description, uploaded once per :class:`~facsim.render.Renderer`.

    Parameters
    ----------
    faces : (M, 3) uint32
        Triangles as indices into render vertices.
    render_to_geo : (R,) int
        Render vertex -> geometry vertex. Render vertices are split at UV seams; normals are
        computed on geometry vertices so seams do not show.
    uv : (R, 2) float32
        Skin UVs (MakeHuman layout, v up, [0, 1]); unused (zeros, say) for non-skin.
    region : (R,) uint8
        Index into :data:`REGIONS` per render vertex. A triangle takes the region most of
        its vertices have (the first vertex's when all three differ).
    eye_coord : (R, 3) float32
        For eyeball vertices, the unit direction from the eye centre in the eye's own
        (unrotated) frame, +Z = gaze; zeros elsewhere.
    """

    faces: np.ndarray
    render_to_geo: np.ndarray
    uv: np.ndarray
    region: np.ndarray
    eye_coord: np.ndarray

    def __post_init__(self):
        faces = np.ascontiguousarray(self.faces, dtype=np.uint32)
        r2g = np.ascontiguousarray(self.render_to_geo, dtype=np.int64)
        if faces.ndim != 2 or faces.shape[1] != 3 or len(faces) == 0:
            raise ValueError(f"faces must be a non-empty (M, 3) array, got shape {faces.shape}")
        if r2g.ndim != 1 or len(r2g) == 0:
            raise ValueError(f"render_to_geo must be a non-empty (R,) array, got {r2g.shape}")
        n = len(r2g)
        if faces.max() >= n:
            raise ValueError(f"faces index render vertex {faces.max()}, but there are only "
                             f"{n} (len(render_to_geo))")
        if r2g.min() < 0:
            raise ValueError("render_to_geo must be >= 0")
        uv = np.ascontiguousarray(self.uv, dtype=np.float32)
        region = np.ascontiguousarray(self.region, dtype=np.uint8)
        eye = np.ascontiguousarray(self.eye_coord, dtype=np.float32)
        for name, arr, shape in (("uv", uv, (n, 2)), ("region", region, (n,)),
                                 ("eye_coord", eye, (n, 3))):
            if arr.shape != shape:
                raise ValueError(f"{name} must have shape {shape} (one row per render vertex), "
                                 f"got {arr.shape}")
        if region.max() >= len(REGIONS):
            raise ValueError(f"region values must index REGIONS (0..{len(REGIONS) - 1}), "
                             f"got {region.max()}")
        for name, arr in (("faces", faces), ("render_to_geo", r2g), ("uv", uv),
                          ("region", region), ("eye_coord", eye)):
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)

    @property
    def n_render(self) -> int:
        """Number of render vertices R."""
        return len(self.render_to_geo)

    @property
    def n_geo(self) -> int:
        """Number of geometry vertices referenced (positions need at least this many rows)."""
        return int(self.render_to_geo.max()) + 1

    @property
    def geo_faces(self) -> np.ndarray:
        """(M, 3) the triangles as geometry-vertex indices."""
        return self.render_to_geo[self.faces]

    def face_regions(self) -> np.ndarray:
        """(M,) region index of each triangle (majority of its vertices)."""
        r = self.region[self.faces]
        return np.where((r[:, 1] == r[:, 2]) & (r[:, 0] != r[:, 1]), r[:, 1], r[:, 0])


@dataclass(frozen=True, eq=False)
class Appearance:
    """How a character looks: colours and a paint texture in skin-UV space.

    Parameters
    ----------
    colors : mapping name -> (r, g, b)
        Display sRGB in [0, 1] for every name in :data:`COLOR_NAMES` (extra names are an
        error, to catch typos). See :data:`DEFAULT_COLORS`.
    paint : (H, W, 4) uint8, optional
        R = eyebrow hair density, G = lip mask, B = eyelid mask, A = cheek/blush mask.
        Rows run with v UPWARD: row 0 is v = 0 (GL texture order, as ``facsim.assets``
        stores its masks; flip an image file's rows with ``paint[::-1]``). Each mask is the
        weight of its colour over the skin colour (255 = the colour itself), so the blush
        or eyelid strength is painted into the mask. ``None`` = no paint.
    """

    colors: Mapping[str, tuple[float, float, float]] = field(default_factory=lambda: DEFAULT_COLORS)
    paint: np.ndarray | None = None

    def __post_init__(self):
        colors = dict(self.colors)
        missing = [k for k in COLOR_NAMES if k not in colors]
        extra = [k for k in colors if k not in COLOR_NAMES]
        if missing or extra:
            raise ValueError(f"colors must give exactly {COLOR_NAMES}; missing {missing}, "
                             f"unknown {extra}")
        clean = {}
        for k in COLOR_NAMES:
            c = np.asarray(colors[k], dtype=float).reshape(-1)
            if c.shape != (3,) or not np.all((c >= 0) & (c <= 1)):
                raise ValueError(f"colors[{k!r}] must be 3 numbers in [0, 1], got {colors[k]!r}")
            clean[k] = tuple(float(v) for v in c)
        object.__setattr__(self, "colors", MappingProxyType(clean))
        if self.paint is not None:
            paint = np.asarray(self.paint)
            if paint.ndim != 3 or paint.shape[2] != 4 or paint.dtype != np.uint8:
                raise ValueError(f"paint must be an (H, W, 4) uint8 array, got "
                                 f"{paint.dtype} {paint.shape}")
            object.__setattr__(self, "paint", paint)


@dataclass(frozen=True)
class Lighting:
    """A studio light rig fixed to the camera.

    Directions are in CAMERA space (x right, y up, z from the subject toward the camera)
    and point toward the light; they need not be unit length. Colours are linear RGB with
    the intensity folded in. ``sky``/``ground`` are the hemispheric ambient for world-up and
    world-down facing surfaces. ``exposure`` scales everything before tone mapping.
    """

    key_direction: tuple[float, float, float] = (-0.6, 0.55, 0.6)
    key_color: tuple[float, float, float] = (1.3, 1.24, 1.15)
    fill_direction: tuple[float, float, float] = (0.8, -0.05, 0.6)
    fill_color: tuple[float, float, float] = (0.22, 0.21, 0.22)
    rim_direction: tuple[float, float, float] = (0.35, 0.55, -0.75)
    rim_color: tuple[float, float, float] = (0.55, 0.55, 0.58)
    sky: tuple[float, float, float] = (0.22, 0.22, 0.23)
    ground: tuple[float, float, float] = (0.11, 0.08, 0.065)
    exposure: float = 1.0

    def world_uniforms(self, camera: Camera) -> dict[str, tuple[float, ...]]:
        """The ``u_*`` shader uniforms for this rig seen from ``camera``."""
        right, up, back = camera_basis(camera.yaw, camera.pitch)
        rot = np.stack([right, up, back], axis=1)  # camera -> world

        def direction(d):
            w = rot @ np.asarray(d, dtype=float)
            return tuple(float(x) for x in w / np.linalg.norm(w))

        return {
            "u_key_dir": direction(self.key_direction), "u_key_col": tuple(self.key_color),
            "u_fill_dir": direction(self.fill_direction), "u_fill_col": tuple(self.fill_color),
            "u_rim_dir": direction(self.rim_direction), "u_rim_col": tuple(self.rim_color),
            "u_sky_col": tuple(self.sky), "u_ground_col": tuple(self.ground),
            "u_exposure": float(self.exposure),
            "u_cam_pos": tuple(float(x) for x in camera.position),
        }


def srgb_to_linear(c) -> np.ndarray:
    """Display sRGB in [0, 1] -> linear light (the exact IEC 61966-2-1 curve)."""
    c = np.asarray(c, dtype=float)
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
